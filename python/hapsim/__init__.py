"""hapsim: real-time haptic simulation, from Python (docs/python.md).

Load a scene, build its world, step it with a device input and read tools, contacts, forces and
deformation as NumPy arrays; run a scene's own device to the end and get the summary
`hapsim run --json` writes; read recordings and replay them; load meshes and query them; forward
and inverse kinematics of a URDF chain; FEM bodies' nodes and stresses, and tet meshes read,
generated and measured.

Python never runs inside the 1 kHz haptic loop: `World.step` is a script's or a test's step on
the calling thread, and `run()` runs the loop's own C++ code with the GIL released.
"""

from ._hapsim import (
    Chain,
    DeviceInput,
    Error,
    Mesh,
    Recording,
    Scene,
    SceneError,
    TetMesh,
    World,
    compare_recordings,
    load_chain,
    load_mesh,
    load_scene,
    make_tet_block,
    read_recording,
    read_tet_mesh,
    run,
    tet_mesh_quality,
)


def replay(scene, recording, **kwargs):
    """Runs `scene` with `recording`'s inputs (run(..., replay=recording)) and returns the summary,
    whose `replay_identical` says whether the run reproduced the recording bit for bit."""
    return run(scene, replay=str(recording), **kwargs)


__all__ = [
    "Chain",
    "DeviceInput",
    "Error",
    "Mesh",
    "Recording",
    "Scene",
    "SceneError",
    "TetMesh",
    "World",
    "compare_recordings",
    "load_chain",
    "load_mesh",
    "load_scene",
    "make_tet_block",
    "read_recording",
    "read_tet_mesh",
    "replay",
    "run",
    "tet_mesh_quality",
]
