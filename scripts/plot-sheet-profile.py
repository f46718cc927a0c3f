#!/usr/bin/python3
"""Plots `hapsim sheet-profile`'s CSV as paper 000's Fig. 3 (the Gauss deformation model): the
sheet's depth against the distance from the contact, both sides of it, per force, the model's
curve and the grid nodes of the scene's sheet under the same push.

usage: plot-sheet-profile.py PROFILE.csv OUT.png
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")  # no display
import matplotlib.pyplot as plt  # noqa: E402


def main(csv_path: str, png_path: str) -> None:
    with open(csv_path, newline="") as f:
        lines = f.readlines()
    header = next((line for line in lines if line.startswith("#")), "")
    rows = list(csv.DictReader(line for line in lines if not line.startswith("#")))
    params = dict(kv.split("=") for kv in header.split(":", 1)[1].split()) if header else {}
    forces = sorted({float(r["force_n"]) for r in rows})
    fig, ax = plt.subplots(figsize=(12.8, 7.2), dpi=100)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, force in enumerate(forces):
        c = colours[i % len(colours)]
        curve = [(float(r["distance_mm"]), float(r["depth_mm"])) for r in rows
                 if r["kind"] == "profile" and float(r["force_n"]) == force]
        d = [-x for x, _ in reversed(curve)] + [x for x, _ in curve]
        z = [-y for _, y in reversed(curve)] + [-y for _, y in curve]
        ax.plot(d, z, color=c, linewidth=2, label=f"F = {force:g} N: model z(d, F)")
        grid = [(float(r["distance_mm"]), float(r["depth_mm"])) for r in rows
                if r["kind"] == "grid" and float(r["force_n"]) == force]
        ax.scatter([x for x, _ in grid] + [-x for x, _ in grid],
                   [-y for _, y in grid] * 2, color=c, s=14, alpha=0.6,
                   label=f"F = {force:g} N: the sheet's grid nodes")
    if "d0_mm" in params:
        d0 = float(params["d0_mm"])
        for x in (-d0, d0):
            ax.axvline(x, color="0.4", linestyle="--", linewidth=1)
        ax.text(d0, 0.0, " d0", color="0.3", va="top")
        ax.set_title(
            "Gauss deformation model of the virtual sheet (paper 000, Fig. 3): "
            f"z(d, F) = (F/F0)(exp(-(d/\u03be)\u00b2) - exp(-(d0/\u03be)\u00b2)),\n"
            f"d0 = {params['d0_mm']} mm, \u03be = {params['xi_mm']} mm, "
            f"F0 = {params['F0_n_per_mm']} N/mm; dots: the {params['nodes']}\u00d7"
            f"{params['nodes']} grid over {params['side_mm']} mm pushed at its centre")
    ax.axhline(0.0, color="0.2", linewidth=0.8)
    ax.set_xlabel("offset from the contact point d (mm)")
    ax.set_ylabel("sheet displacement (mm, down negative)")
    ax.grid(True, alpha=0.3)
    deepest = min(-float(r["depth_mm"]) for r in rows)
    ax.set_ylim(1.4 * deepest, -0.1 * deepest)  # room for the legend under the curves
    ax.legend(loc="lower center", fontsize=9, ncol=3)
    fig.tight_layout()
    fig.savefig(png_path)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
