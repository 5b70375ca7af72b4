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

    x = [float(r["x"]) for r in rows]
    y = [float(r["y"]) for r in rows]
    z = [float(r["z"]) for r in rows]
    vmax = max(float(r["u_" + n]) for r in rows for n in runs) * 1e3
    fig = plt.figure(figsize=(3.2 * len(runs), 3.6))
    for k, name in enumerate(runs):
        ax = fig.add_subplot(1, len(runs), k + 1, projection="3d")
        u = [1e3 * float(r["u_" + name]) for r in rows]
        sel = [r["selected_" + name] == "1" for r in rows]
        sc = ax.scatter([a for a, s in zip(x, sel) if s], [c for c, s in zip(z, sel) if s], [b for b, s in zip(y, sel) if s],
                        c=[v for v, s in zip(u, sel) if s], cmap="viridis", vmin=0, vmax=vmax, s=14, depthshade=False)
        ax.scatter([a for a, s in zip(x, sel) if not s], [c for c, s in zip(z, sel) if not s],
                   [b for b, s in zip(y, sel) if not s], c="0.8", s=4, depthshade=False)
        ax.set_title(name.replace("_", " weight "), fontsize=9)
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_zticks([])
        ax.view_init(elev=25, azim=-60)
    fig.colorbar(sc, ax=fig.axes, shrink=0.6, label="|u| (mm); grey: not simulated")
    fig.savefig(os.path.join(out, "propagation-3d.png"), dpi=110)


if __name__ == "__main__":
    main(sys.argv[1])
