#!/usr/bin/env python3
"""Plots of `pointhaptics experiment propagation` (seed Fig. 8-9): the displacement of every point per index,
and the object coloured by displacement, for the full model and each propagation setup.

usage: plot_propagation.py OUT
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(out):
    with open(os.path.join(out, "propagation.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    runs = [k[2:] for k in rows[0] if k.startswith("u_")]
    index = [int(r["index"]) for r in rows]
    fig, ax = plt.subplots(figsize=(9, 4))
    for name in runs:
        ax.plot(index, [1e3 * float(r["u_" + name]) for r in rows], lw=1.2 if name == "full" else 0.9,
                color="k" if name == "full" else None, label=name.replace("_", " weight "))
    ax.set_xlabel("point index")
    ax.set_ylabel("|u| at the end (mm)")
    ax.set_title("Displacement of every point (seed Fig. 8-9, third row)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "propagation.png"), dpi=120)

    # the object per run: a grid of panels that fill the figure (2 rows from 4 runs up), each a full-size 3-D
    # view; the colour scale is logarithmic from 1% of the largest displacement, so that the pulled point
    # does not saturate it and the propagation into the object shows
    x = [float(r["x"]) for r in rows]
    y = [float(r["y"]) for r in rows]
    z = [float(r["z"]) for r in rows]
    from matplotlib.colors import LogNorm  # noqa: E402

    vmax = max(float(r["u_" + n]) for r in rows for n in runs) * 1e3
    norm = LogNorm(vmin=max(vmax * 1e-2, 1e-12), vmax=max(vmax, 1e-12), clip=True)
    ncols = len(runs) if len(runs) <= 3 else (len(runs) + 1) // 2
    nrows = (len(runs) + ncols - 1) // ncols
    fig = plt.figure(figsize=(4.2 * ncols + 1.2, 4.0 * nrows))
    grid = fig.add_gridspec(nrows, ncols + 1, width_ratios=[1] * ncols + [0.06], wspace=0.02, hspace=0.08,
                            left=0.01, right=0.93, top=0.93, bottom=0.02)
    sc = None
    for k, name in enumerate(runs):
        ax = fig.add_subplot(grid[k // ncols, k % ncols], projection="3d")
        u = [max(1e3 * float(r["u_" + name]), 1e-15) for r in rows]
        sel = [r["selected_" + name] == "1" for r in rows]
        sc = ax.scatter([a for a, s in zip(x, sel) if s], [c for c, s in zip(z, sel) if s], [b for b, s in zip(y, sel) if s],
                        c=[v for v, s in zip(u, sel) if s], cmap="viridis", norm=norm, s=30, depthshade=False)
        ax.scatter([a for a, s in zip(x, sel) if not s], [c for c, s in zip(z, sel) if not s],
                   [b for b, s in zip(y, sel) if not s], c="0.75", s=8, depthshade=False)
        ax.set_title(name.replace("_", " weight "), fontsize=12)
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_zticks([])
        ax.set_box_aspect((max(x) - min(x), max(z) - min(z), max(y) - min(y)), zoom=1.25)
        ax.view_init(elev=25, azim=-60)
    fig.colorbar(sc, cax=fig.add_subplot(grid[:, ncols]), label="|u| (mm, log scale); grey: not simulated")
    fig.suptitle("The pulled half-sphere, coloured by displacement (seed Fig. 8-9)", fontsize=13)
    fig.savefig(os.path.join(out, "propagation-3d.png"), dpi=110)


if __name__ == "__main__":
    main(sys.argv[1])
