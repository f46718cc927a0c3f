#!/usr/bin/env python3
"""Derives the two-user scenes from their one-user originals (run from the repository's root).

scenes/knee_two_users.json             the trainee's fingertip (the default scene's examination)
                                       and the instructor's probe on the same FEM knee
scenes/knee_two_users_instructor.json  the instructor's script: the probe held on the
                                       quadriceps tendon just above the patella
tests/data/two_users/*.json            the same pair on the FEM block, for the process test

    python3 scripts/make-two-user-scenes.py
"""
import copy
import json
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def write(path, scene):
    path.write_text(json.dumps(scene, indent=2) + "\n")
    print("wrote", path.relative_to(ROOT))


def probe(radius_m):
    return {"name": "probe", "radius_m": radius_m, "offset_m": [0.0, 0.0, 0.0], "finger": -1}


def held_press(body, toward_m, from_dir, depth_m, hold_s, approach_s, press_s, move_s):
    return {"standoff_m": 0.015, "move_s": move_s, "around_axis": [0.0, 0.0, 1.0],
            "approach_s": approach_s, "press_s": press_s, "release_s": 0.4,
            "targets": [{"body": body, "toward_m": toward_m, "from": from_dir,
                         "depth_m": depth_m, "hold_s": hold_s}]}


def knee():
    knee = json.loads((ROOT / "scenes/knee.json").read_text())
    # Over the quadriceps tendon, 15 mm proximal of the trainee's last target (the patella).
    instructor_target = [-0.01, 0.054, 0.043]

    two = copy.deepcopy(knee)
    two["description"] = (
        "Two users on one FEM knee (hapsim serve with two device hosts: docs/architecture.md, "
        "'Several users in one world'). The trainee's fingertip runs the default scene's "
        "examination (scenes/knee.json, whose script and assessment this scene keeps); the "
        "instructor's probe, on a second device host, presses the quadriceps tendon just above "
        "the patella and holds it (scenes/knee_two_users_instructor.json is its script: hapsim "
        "device --name instructor --scene scenes/knee_two_users_instructor.json). Each feels the "
        "other's dent: the tissue is one FEM body. Derived by scripts/make-two-user-scenes.py.")
    two["world"]["name"] = "knee_two_users"
    two["tools"] = [dict(knee["tools"][0], device_host="trainee"),
                    dict(probe(0.005), device_host="instructor")]
    write(ROOT / "scenes/knee_two_users.json", two)

    inst = copy.deepcopy(knee)
    inst["description"] = (
        "The instructor's script for scenes/knee_two_users.json: the same knee, the probe "
        "pressed 3 mm into the quadriceps tendon just above the patella and held for a minute "
        "(hapsim device --name instructor --scene scenes/knee_two_users_instructor.json). "
        "Derived by scripts/make-two-user-scenes.py.")
    inst["world"]["name"] = "knee_two_users_instructor"
    inst["tools"] = [probe(0.005)]
    inst["device"]["palpation"] = held_press("knee", instructor_target, [0.0, 1.0, 0.0], 0.003,
                                             60.0, 0.3, 0.6, 0.6)
    inst.pop("assessment", None)
    inst["run"] = {"duration_s": 62.0, "dt_s": 0.001}
    write(ROOT / "scenes/knee_two_users_instructor.json", inst)


def block():
    block = json.loads((ROOT / "scenes/fem_block.json").read_text())
    top_z = 0.03

    two = copy.deepcopy(block)
    two["description"] = (
        "Test scene: the FEM block with two users. The trainee's fingertip comes in slowly and "
        "presses the middle of the top 8 mm (full depth at about 3 s) and holds; the instructor's "
        "probe (its script: fem_block_instructor.json) presses 12 mm beside it. Derived by "
        "scripts/make-two-user-scenes.py.")
    two["world"]["name"] = "fem_block_two_users"
    two["tools"] = [dict(block["tools"][0], device_host="trainee"),
                    dict(probe(0.005), device_host="instructor")]
    two["device"]["palpation"] = held_press("block", [0.0, 0.0, top_z], [0.0, 0.0, 1.0], 0.003,
                                            2.0, 0.6, 1.4, 1.0)
    two["run"] = {"duration_s": 5.0, "dt_s": 0.001}
    write(ROOT / "tests/data/two_users/fem_block_two_users.json", two)

    inst = copy.deepcopy(block)
    inst["description"] = (
        "Test scene: the instructor's script for fem_block_two_users.json, the probe pressed 10 mm "
        "into the top 12 mm beside the trainee's spot within 1 s, held for 20 s. Derived by "
        "scripts/make-two-user-scenes.py.")
    inst["world"]["name"] = "fem_block_instructor"
    inst["tools"] = [probe(0.005)]
    inst["device"]["palpation"] = held_press("block", [0.012, 0.0, top_z], [0.0, 0.0, 1.0], 0.012,
                                             20.0, 0.2, 0.5, 0.3)
    inst["run"] = {"duration_s": 21.5, "dt_s": 0.001}
    write(ROOT / "tests/data/two_users/fem_block_instructor.json", inst)


if __name__ == "__main__":
    knee()
    block()
