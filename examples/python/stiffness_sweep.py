"""Force against depth per tissue on the knee: the scene's own palpation stepped from Python.

Each step, every contact's tissue (its segment's material), depth below the rest surface and force
are kept; the plot draws force against depth for each tissue the probe pressed, beside the
line k·depth of the stiffness the world renders it with (no stiffer than the device's rating).

    PYTHONPATH=build/release/python python3 examples/python/stiffness_sweep.py \
        [--scene scenes/knee_paper.json] [--out docs/images] [--quick]
"""

import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import hapsim  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]


def sweep(scene, seconds):
    """{tissue: (depths_m, forces_n)} over the palpation's first `seconds`."""
    world = hapsim.World(scene)
    samples = {}
    steps = int(round(seconds / world.dt_s))
    for i in range(steps):
        world.step(world.script_input(i * world.dt_s))
        c = world.contacts()
        for k in range(len(c["depth_m"])):
            tissue = world.segment_material(int(c["body"][k]), int(c["segment"][k]))
            samples.setdefault(tissue, []).append((c["depth_m"][k], c["force_n"][k]))
    curves = {t: np.array(v).T for t, v in samples.items()}
    stiffness = {t: world.effective_stiffness_n_per_m(t) for t in curves}
    described = {t: world.stiffness_n_per_m(t) for t in curves}
    return curves, stiffness, described, world.time_s


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default=str(ROOT / "scenes" / "knee_paper.json"))
    parser.add_argument("--out", default=str(ROOT / "docs" / "images"))
    parser.add_argument("--quick", action="store_true", help="the first 1.5 s only (tests)")
    args = parser.parse_args()
    scene = hapsim.load_scene(args.scene)
    world_seconds = 1.5 if args.quick else hapsim.World(scene).duration_s
    curves, stiffness, described, ran_s = sweep(scene, world_seconds)

    fig, ax = plt.subplots(figsize=(8, 5), dpi=110)
    colours = plt.get_cmap("tab10")
    for i, (tissue, (depth, force)) in enumerate(sorted(curves.items())):
        colour = colours(i)
        k = stiffness[tissue]
        label = f"{tissue}: k = {k:.0f} N/m"
        if described[tissue] > k:
            label += f" (described {described[tissue]:.0f}, clamped to the device)"
        ax.plot(depth * 1e3, force, ".", ms=3, color=colour, label=label)
        d = np.linspace(0.0, depth.max(), 20)
        ax.plot(d * 1e3, k * d, "--", lw=1, color=colour)
    ax.set_xlabel("depth below the rest surface (mm)")
    ax.set_ylabel("contact force (N)")
    ax.set_title(f"Knee palpation: force against depth per tissue ({ran_s:.1f} s, "
                 f"{pathlib.Path(args.scene).name})")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    ax.text(0.99, 0.02, "dots: every contact of every step; dashed: k·depth", ha="right",
            va="bottom", transform=ax.transAxes, fontsize=8, color="0.4")
    out = pathlib.Path(args.out) / "python_stiffness_sweep.png"
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(out)
    for tissue, (depth, force) in sorted(curves.items()):
        print(f"{tissue:10s} {len(depth):5d} steps, depth up to {depth.max() * 1e3:.2f} mm, "
              f"force up to {force.max():.2f} N")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
