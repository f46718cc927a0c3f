#!/usr/bin/python3
"""Plots scripts/knee-force-depth.py's CSV: force against depth at each knee landmark, the
paper's model beside the FEM knee, over the band a published in-vivo range gives for a 7 mm
fingertip on a half-space: Zheng & Mak 1999 (lower-limb soft tissue, initial modulus 0.22-58.4
kPa), as Hertz's F = 4/3 E/(1 - nu^2) sqrt(R) d^1.5 with nu = 0.45. The band is the thick-tissue
reference: over bone, ligament and tendon the tissue is thin and stiffer by nature.

usage: plot-knee-force-depth.py FORCE_DEPTH.csv OUT.png
"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")  # no display
import matplotlib.pyplot as plt  # noqa: E402

R_M = 0.007
NU = 0.45


def hertz_n(e_pa, d_m):
    return 4.0 / 3.0 * e_pa / (1.0 - NU * NU) * math.sqrt(R_M) * d_m ** 1.5


def main(csv_path, png_path):
    rows = list(csv.DictReader(open(csv_path, newline="")))
    scenes = sorted({r["scene"] for r in rows})
    landmarks = list(dict.fromkeys(r["landmark"] for r in rows))
    cols = 4
    nrows = math.ceil(len(landmarks) / cols)
    fig, axes = plt.subplots(nrows, cols, figsize=(16, 4.2 * nrows), dpi=100, sharey=True)
    axes = [a for row in (axes if nrows > 1 else [axes]) for a in row]
    depths = [i * 0.1 for i in range(0, 121)]
    styles = {"knee_paper.json": ("#c0504d", "paper model (capped springs)"),
              "knee.json": ("#1f77b4", "FEM knee, 24k tets"),
              "knee_fem_80k.json": ("#2ca02c", "FEM knee, 86k tets")}
    for ax, name in zip(axes, landmarks):
        lo = [hertz_n(220.0, d * 1e-3) for d in depths]
        hi = [hertz_n(58400.0, d * 1e-3) for d in depths]
        ax.fill_between(depths, lo, hi, color="#999999", alpha=0.25,
                        label="in vivo initial modulus 0.22-58.4 kPa (Zheng & Mak 1999), Hertz")
        for scene in scenes:
            pts = [(float(r["depth_mm"]), float(r["force_n"])) for r in rows
                   if r["scene"] == scene and r["landmark"] == name]
            colour, label = styles.get(scene, ("#333333", scene))
            ax.plot([d for d, _ in pts], [f for _, f in pts], color=colour, linewidth=2, label=label)
        ax.set_title(name)
        ax.set_xlim(0, 12)
        ax.set_ylim(0, 12)
        ax.set_xlabel("depth past first touch of the skin (mm)")
        ax.grid(alpha=0.3)
    for ax in axes[len(landmarks):]:
        ax.axis("off")
    for row in range(nrows):
        axes[row * cols].set_ylabel("force along the press (N)")
    # One legend for all, under the title: inside a panel it covers a curve.
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", ncol=len(labels), fontsize=10,
               bbox_to_anchor=(0.5, 0.955), frameon=False)
    fig.suptitle("Pressing a 7 mm fingertip into the knee at 5 mm/s: the paper's model and the "
                 "FEM knee against the published in-vivo range", fontsize=13)
    fig.tight_layout(rect=(0, 0, 1, 0.92))
    fig.savefig(png_path)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
