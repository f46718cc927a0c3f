"""The three contact methods on one recording: the knee's palpation recorded once from Python,
its inputs replayed into worlds built with the exact BVH, sphere trees and the knee paper's
groups; the plot shows each method's force over time and its difference from the exact one.

    PYTHONPATH=build/release/python python3 examples/python/contact_methods.py \
        [--scene scenes/knee_paper.json] [--out docs/images] [--quick]
"""

import argparse
import pathlib
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import hapsim  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
METHODS = ("exact", "spheretree", "knee")


def record(scene, seconds, path):
    world = hapsim.World(scene)
    world.record(str(path))
    for i in range(int(round(seconds / world.dt_s))):
        world.step(world.script_input(i * world.dt_s))
    return world.stop_recording()


def replay_forces(scene, recording, method):
    world = hapsim.World(scene, method=method)
    forces = np.empty(len(recording))
    for i in range(len(recording)):
        world.step(recording.input(i))
        forces[i] = np.linalg.norm(world.force_world_n)
    return forces


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default=str(ROOT / "scenes" / "knee_paper.json"))
    parser.add_argument("--out", default=str(ROOT / "docs" / "images"))
    parser.add_argument("--quick", action="store_true", help="the first 1.5 s only (tests)")
    args = parser.parse_args()
    scene = hapsim.load_scene(args.scene)  # read once: every world below copies it
    seconds = 1.5 if args.quick else hapsim.World(scene).duration_s
    with tempfile.TemporaryDirectory() as tmp:
        path = pathlib.Path(tmp) / "palpation.rec"
        record(scene, seconds, path)
        recording = hapsim.read_recording(str(path))
    t = recording.time_s
    forces = {m: replay_forces(scene, recording, m) for m in METHODS}

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 6), dpi=110, sharex=True,
                                      gridspec_kw={"height_ratios": [2, 1]})
    styles = {"exact": ("k", 1.6), "spheretree": ("tab:blue", 1.0), "knee": ("tab:orange", 1.0)}
    for m in METHODS:
        colour, width = styles[m]
        top.plot(t, forces[m], color=colour, lw=width, label=m)
        if m != "exact":
            diff = forces[m] - forces["exact"]
            rms = np.sqrt(np.mean(diff**2))
            bottom.plot(t, diff, color=colour, lw=1,
                        label=f"{m} − exact (rms {rms * 1e3:.1f} mN, max {np.abs(diff).max():.3f} N)")
            print(f"{m:10s} rms difference from exact {rms * 1e3:.2f} mN, "
                  f"max {np.abs(diff).max():.4f} N")
    top.set_ylabel("force on the device (N)")
    top.set_title(f"Contact methods on one recording ({len(recording)} steps of "
                  f"{pathlib.Path(args.scene).name}'s palpation)")
    top.legend(fontsize=8)
    top.grid(alpha=0.3)
    bottom.set_xlabel("time (s)")
    bottom.set_ylabel("difference (N)")
    bottom.legend(fontsize=8)
    bottom.grid(alpha=0.3)
    out = pathlib.Path(args.out) / "python_contact_methods.png"
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
