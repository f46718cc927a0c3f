#!/usr/bin/python3
"""Force-depth curves at the knee's landmarks: a 7 mm fingertip pressed slowly along each
landmark's palpation direction (the scene's own targets), from first touch of the skin to a depth
or a force, through the Python module's World (the FEM updates in the step: no timing effect).

usage: knee-force-depth.py SCENE.json [SCENE.json ...] --out CSV [--depth-mm 12] [--speed-mm-s 5]
CSV columns: scene, landmark, depth_mm (past first touch), force_n (along the press direction).
"""
import argparse
import csv
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "build", "release", "python"))
import hapsim  # noqa: E402

# The knee's landmarks in the scene frame (x medial, y anterior, z proximal; joint line near z = 0):
# where the press aims and where it comes from, as scenes/knee.json's palpation targets.
LANDMARKS = {
    "LCL": ([-0.0428, -0.0270, -0.0065], [-1.0, 0.0, 0.0]),
    "lateral joint line": ([-0.037, 0.001, -0.003], [-0.7, 0.7, 0.0]),
    "tibial tuberosity": ([-0.005, 0.014, -0.047], [0.0, 1.0, -0.35]),
    "medial joint line": ([0.035, 0.012, -0.003], [0.7, 0.7, 0.0]),
    "MCL": ([0.0364, -0.0022, -0.0061], [1.0, 0.0, 0.0]),
    "patellar tendon": ([-0.0157, 0.0327, -0.0162], [0.0, 1.0, 0.0]),
    "patella": ([-0.01, 0.054, 0.028], [0.0, 1.0, 0.0]),
    "quadriceps": ([-0.0449, 0.0094, 0.0925], [-0.6, 0.8, 0.0]),
}


def press(scene, toward, frm, depth_m, speed_m_s, max_force_n):
    """Moves the fingertip in along -frm from outside; returns [(depth past touch, force)]."""
    world = hapsim.World(scene)
    dt = world.dt_s
    frm = np.asarray(frm, float) / np.linalg.norm(frm)
    toward = np.asarray(toward, float)
    # From 60 mm out, fast until the skin is touched, then slowly.
    s = 0.06
    touched_at = None
    out = []
    while s > -0.1:
        p = toward + frm * s
        world.step(hapsim.DeviceInput(p_world=p.tolist()))
        f_along = float(np.dot(world.force_world_n, frm))
        if touched_at is None:
            if f_along > 0.005:
                touched_at = s
            s -= 0.05 * dt  # 50 mm/s in free space
            continue
        depth = touched_at - s
        out.append((depth, f_along))
        if depth >= depth_m or f_along >= max_force_n:
            break
        s -= speed_m_s * dt
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scenes", nargs="+")
    ap.add_argument("--out", required=True)
    ap.add_argument("--depth-mm", type=float, default=12.0)
    ap.add_argument("--speed-mm-s", type=float, default=5.0)
    ap.add_argument("--max-force-n", type=float, default=11.0)
    ap.add_argument("--landmarks", default=",".join(LANDMARKS))
    a = ap.parse_args()
    with open(a.out, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scene", "landmark", "depth_mm", "force_n"])
        for scene in a.scenes:
            for name in a.landmarks.split(","):
                toward, frm = LANDMARKS[name]
                rows = press(scene, toward, frm, a.depth_mm * 1e-3, a.speed_mm_s * 1e-3,
                             a.max_force_n)
                for d, fn in rows[:: max(1, len(rows) // 200)]:
                    w.writerow([os.path.basename(scene), name, f"{d * 1e3:.3f}", f"{fn:.4f}"])
                last = rows[-1] if rows else (0.0, 0.0)
                at = {mm: next((fn for d, fn in rows if d >= mm * 1e-3), float("nan"))
                      for mm in (2, 4, 6, 8)}
                print(f"{os.path.basename(scene):16s} {name:20s} "
                      + " ".join(f"{mm}mm {v:5.2f}N" for mm, v in at.items())
                      + f"  end {last[0] * 1e3:.1f} mm {last[1]:.2f} N", flush=True)


if __name__ == "__main__":
    main()
