"""Scenes from Python: good and bad files (the exception names file and pointer), and run()
giving the same summary as `hapsim run --json`."""

import json

import pytest

import hapsim
from conftest import SCENES, run_cli

KNEE = SCENES / "knee_procedural.json"


def write_scene(tmp_path, text):
    path = tmp_path / "scene.json"
    path.write_text(text)
    return path


def bad_material_scene(tmp_path):
    scene = json.loads(KNEE.read_text())
    scene["bodies"][0]["materials"]["by_tissue"]["ligament"] = "no_such_tissue"
    return write_scene(tmp_path, json.dumps(scene))


def test_a_good_scene_loads():
    scene = hapsim.load_scene(str(KNEE))
    assert scene.file == str(KNEE)
    assert isinstance(scene.warnings, list)


def test_a_bad_material_names_file_and_pointer(tmp_path, hapsim_bin):
    path = bad_material_scene(tmp_path)
    with pytest.raises(hapsim.SceneError) as caught:
        hapsim.load_scene(str(path))
    e = caught.value
    assert isinstance(e, hapsim.Error) and isinstance(e, ValueError)
    assert e.file == str(path)
    assert e.pointer == "/bodies/0/materials/by_tissue/ligament"
    assert "no_such_tissue" in str(e)
    # The CLI says the same thing in its one line.
    cli = run_cli(hapsim_bin, "run", path, "--duration", "0.01")
    assert cli.returncode == 2
    assert f"{path}:{e.pointer}" in cli.stderr


def test_a_json_syntax_error_names_line_and_column(tmp_path):
    path = write_scene(tmp_path, '{"bodies": [\n  {"name": "x",,}\n]}')
    with pytest.raises(hapsim.SceneError) as caught:
        hapsim.load_scene(str(path))
    assert caught.value.file == str(path)
    assert caught.value.pointer == "2:16"


def test_a_missing_scene_is_a_scene_error(tmp_path):
    with pytest.raises(hapsim.SceneError) as caught:
        hapsim.load_scene(str(tmp_path / "absent.json"))
    assert "absent.json" in str(caught.value)


def test_world_and_run_raise_the_same_error(tmp_path):
    path = bad_material_scene(tmp_path)
    for call in (lambda: hapsim.World(str(path)), lambda: hapsim.run(str(path), duration=0.01)):
        with pytest.raises(hapsim.SceneError) as caught:
            call()
        assert caught.value.pointer == "/bodies/0/materials/by_tissue/ligament"


def test_bad_arguments_are_errors_not_crashes():
    with pytest.raises(hapsim.Error, match="duration"):
        hapsim.run(str(KNEE), duration=-1.0)
    with pytest.raises(hapsim.Error, match="method"):
        hapsim.run(str(KNEE), duration=0.01, method="fastest")


# Figures that depend on the wall clock or the machine, not on what was simulated.
TIMING_KEYS = {"wall_s", "step_us", "world_build_ms"}


def test_run_gives_the_cli_summary(tmp_path, hapsim_bin):
    cli_json = tmp_path / "cli.json"
    cli = run_cli(hapsim_bin, "run", KNEE, "--duration", "1.5", "--json", cli_json, "-q")
    assert cli.returncode == 0, cli.stderr
    expected = json.loads(cli_json.read_text())
    got = hapsim.run(str(KNEE), duration=1.5)
    assert set(got) == set(expected)
    for key in set(expected) - TIMING_KEYS:
        assert got[key] == expected[key], key
    assert got["steps"] == 1500 and got["ok"] is True
    assert max(t["peak_force_n"] for t in got["tools"]) > 0.5  # it touched the knee


def test_run_takes_a_scene_object_and_a_method():
    scene = hapsim.load_scene(str(KNEE))
    summary = hapsim.run(scene, duration=0.2, method="spheretree")
    assert summary["steps"] == 200
    assert set(summary["methods"]) == {"spheretree"}
