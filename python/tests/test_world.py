"""The world stepped from Python: array shapes, dtypes and lifetimes, device input checks, and a
Python-driven palpation giving the forces of the CLI's run of the same scene."""

import numpy as np
import pytest

import hapsim
from conftest import SCENES, run_cli

KNEE = SCENES / "knee_procedural.json"
HAND = SCENES / "knee_hand.json"


@pytest.fixture(scope="module")
def knee():
    return hapsim.World(str(KNEE))


def drive_script(world, steps):
    """Steps `world` with its scene's own script from Python, as run_session does."""
    forces = np.empty((steps, 3))
    for i in range(steps):
        world.step(world.script_input(i * world.dt_s))
        forces[i] = world.force_world_n
    return forces


def test_arrays_have_their_shapes_and_dtypes(knee):
    knee.reset()
    drive_script(knee, 900)  # into the first target
    tools = len(knee.tool_names)
    for name in ("tool_p_world", "tool_proxy_world", "tool_force_world_n"):
        a = getattr(knee, name)
        assert a.shape == (tools, 3) and a.dtype == np.float64, name
        assert not a.flags.writeable, name
    assert knee.force_world_n.shape == (3,)
    c = knee.contacts()
    n = len(c["depth_m"])
    assert n >= 1, "the script presses the knee by 0.9 s"
    assert c["point_world"].shape == (n, 3) and c["normal_world"].shape == (n, 3)
    assert c["tool"].dtype == np.int32 and c["proxy"].dtype == np.bool_
    assert c["force_n"].dtype == np.float64
    np.testing.assert_allclose(np.linalg.norm(c["normal_world"], axis=1), 1.0, rtol=1e-12)
    vertices, triangles = knee.surface(0, 0)
    assert vertices.shape[1] == 3 and vertices.dtype == np.float64
    assert triangles.shape[1] == 3 and triangles.dtype == np.uint32
    assert triangles.max() < len(vertices)
    d = knee.deflection_m(0, 0)
    assert d is not None and d.shape == (len(vertices),)
    assert knee.body_pose(0).shape == (4, 4)


def test_tool_views_follow_the_world_in_place(knee):
    knee.reset()
    view = knee.tool_p_world
    p = np.array([0.3, -0.2, 0.25])
    knee.step(hapsim.DeviceInput(p_world=p))
    before = view.copy()
    knee.step(hapsim.DeviceInput(p_world=p + [0.0, 0.0, 0.01]))
    assert view[0, 2] == pytest.approx(before[0, 2] + 0.01, abs=1e-12)
    np.testing.assert_array_equal(view, knee.tool_p_world)


def test_bad_inputs_are_errors():
    with pytest.raises(hapsim.Error, match="p_world"):
        hapsim.DeviceInput(p_world=[1.0, 2.0])
    with pytest.raises(hapsim.Error, match="unit quaternion"):
        hapsim.DeviceInput(q_world=[2.0, 0.0, 0.0, 0.0])
    with pytest.raises(hapsim.Error, match="finger_rad"):
        hapsim.DeviceInput(finger_rad=np.zeros(6))
    inp = hapsim.DeviceInput(finger_rad=[0.1, 0.2], joint_rad=np.arange(3.0))
    assert inp.finger_rad.tolist() == [0.1, 0.2] and inp.joint_rad.shape == (3,)


def test_python_palpation_gives_the_cli_forces(tmp_path, hapsim_bin):
    """The scene's palpation stepped from Python and by `hapsim run` give the same forces (1e-12)
    at every step: the CLI's recording holds each cycle's command."""
    steps = 2500
    rec = tmp_path / "cli.rec"
    cli = run_cli(hapsim_bin, "run", KNEE, "--duration", steps / 1000, "--record", rec, "-q")
    assert cli.returncode == 0, cli.stderr
    recorded = hapsim.read_recording(str(rec))
    assert len(recorded) == steps
    world = hapsim.World(str(KNEE))
    forces = drive_script(world, steps)
    assert np.abs(forces).max() > 1.0  # the palpation pressed
    np.testing.assert_allclose(forces, recorded.force_world_n, rtol=0, atol=1e-12)


def test_a_glove_scene_reports_finger_forces():
    world = hapsim.World(str(HAND))
    peak = np.zeros(len(world.tool_names))
    for i in range(1800):
        world.step(world.script_input(i * world.dt_s))
        f = np.linalg.norm(world.tool_force_world_n, axis=1)
        peak = np.maximum(peak, f)
    assert world.finger_force_n.dtype == np.float64
    assert peak.max() > 0.1  # the index or middle finger pressed


def test_a_glove_pressed_too_hard_reads_the_device_clamp(tmp_path):
    # The knee_hand script's hand pushed 30 mm further down: the world asks for over 9 N on a
    # finger of the Rutgers Master (4 N). Python reads what the device renders and the recording
    # holds (4.0 N), and says the clamp once.
    world = hapsim.World(str(HAND))
    rec = tmp_path / "pressed.rec"
    world.record(str(rec))
    read = []
    with pytest.warns(RuntimeWarning, match="rutgers_master.*4.0 N per finger") as said:
        for i in range(3000):
            inp = world.script_input(i * world.dt_s)
            p = np.array(inp.p_world)
            p[1] -= 0.03 * min(i / 1500, 1.0)
            inp.p_world = p
            world.step(inp)
            read.append(np.array(world.finger_force_n))
    world.stop_recording()
    assert len([w for w in said if w.category is RuntimeWarning]) == 1
    assert world.clamped_steps > 0
    read = np.array(read)
    assert read.max() == pytest.approx(4.0)
    recorded = hapsim.read_recording(str(rec))
    np.testing.assert_array_equal(read, recorded.finger_force_n[:, : read.shape[1]])
