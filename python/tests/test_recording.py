"""Recordings from Python: a replay through Python equals the recording bit for bit, the module's
replay() agrees, and a recording made from Python replays through the CLI."""

import numpy as np

import hapsim
from conftest import SCENES, run_cli

KNEE = SCENES / "knee_procedural.json"
STEPS = 1500


def test_a_python_replay_equals_the_recording(tmp_path, hapsim_bin):
    rec = tmp_path / "cli.rec"
    cli = run_cli(hapsim_bin, "run", KNEE, "--duration", STEPS / 1000, "--record", rec, "-q")
    assert cli.returncode == 0, cli.stderr
    recorded = hapsim.read_recording(str(rec))
    assert len(recorded) == STEPS
    assert recorded.p_world.shape == (STEPS, 3) and recorded.time_s.shape == (STEPS,)
    assert recorded.q_world.shape == (STEPS, 4) and recorded.finger_rad.shape == (STEPS, 5)
    assert not recorded.p_world.flags.writeable  # a view of the recording's frames

    # Step by step: the recorded inputs into a fresh world, re-recorded from Python.
    world = hapsim.World(str(KNEE))
    assert world.content_hash == recorded.scene_hash
    again = tmp_path / "python.rec"
    world.record(str(again))
    forces = np.empty((STEPS, 3))
    for i in range(STEPS):
        world.step(recorded.input(i))
        forces[i] = world.force_world_n
    assert world.stop_recording() == STEPS
    np.testing.assert_array_equal(forces, recorded.force_world_n)
    assert hapsim.compare_recordings(str(rec), str(again)) is None

    # The module's replay runs the session's own loop on the recording.
    summary = hapsim.replay(str(KNEE), rec)
    assert summary["replay_identical"] is True and summary["ok"] is True
    assert summary["steps"] == STEPS


def test_a_changed_input_is_a_difference(tmp_path):
    world = hapsim.World(str(KNEE))
    a, b = tmp_path / "a.rec", tmp_path / "b.rec"
    for path, dz in ((a, 0.0), (b, 1e-9)):
        world.reset()
        world.record(str(path))
        for i in range(50):
            inp = world.script_input(i * world.dt_s)
            if i == 30:
                inp.p_world = inp.p_world + [0.0, 0.0, dz]
            world.step(inp)
        world.stop_recording()
    difference = hapsim.compare_recordings(str(a), str(b))
    assert difference is not None and "frame 30" in difference


def test_a_python_recording_replays_through_the_cli(tmp_path, hapsim_bin):
    world = hapsim.World(str(KNEE))
    rec = tmp_path / "python.rec"
    world.record(str(rec))
    for i in range(STEPS):
        world.step(world.script_input(i * world.dt_s))
    world.stop_recording()
    cli = run_cli(hapsim_bin, "run", KNEE, "--replay", rec, "-q")
    assert cli.returncode == 0, cli.stdout + cli.stderr
    assert "identical" in cli.stdout


def test_a_non_finite_input_is_refused_and_never_recorded(tmp_path):
    """A NaN or inf device input through World.step raises ValueError naming the field; the
    world is not stepped and the recording keeps the good frames only (it reads back whole)."""
    world = hapsim.World(str(KNEE))
    rec = tmp_path / "nan.rec"
    world.record(str(rec))
    good = world.script_input(0.0)
    for _ in range(10):
        world.step(good)
    bad_inputs = {
        "input.p_world[1] is nan": hapsim.DeviceInput(p_world=(0.0, float("nan"), 0.0)),
        "input.time_s is -inf": hapsim.DeviceInput(time_s=float("-inf")),
        "input.finger_rad[1] is nan": hapsim.DeviceInput(finger_rad=(0.1, float("nan"))),
    }
    for field, bad in bad_inputs.items():
        time_before = world.time_s
        try:
            world.step(bad)
        except ValueError as e:
            assert field in str(e), str(e)
        else:
            raise AssertionError(f"World.step accepted {field}")
        assert world.time_s == time_before  # not stepped
    # DeviceInput itself refuses a quaternion that is not unit (an inf one included).
    try:
        hapsim.DeviceInput(q_world=(float("inf"), 0.0, 0.0, 0.0))
    except ValueError as e:
        assert "q_world" in str(e), str(e)
    else:
        raise AssertionError("DeviceInput accepted an inf quaternion")
    world.step(good)
    assert world.stop_recording() == 11
    recorded = hapsim.read_recording(str(rec))
    assert len(recorded) == 11
    assert np.isfinite(recorded.p_world).all()
