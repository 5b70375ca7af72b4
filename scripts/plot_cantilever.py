#!/usr/bin/env python3
"""Plots of `pointhaptics experiment cantilever` (seed Fig. 3-4): reads the CSV files in OUT, writes PNGs there.

usage: plot_cantilever.py OUT
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import math  # noqa: E402

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import FixedLocator, NullLocator, ScalarFormatter  # noqa: E402


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def main(out):
    data = rows(os.path.join(out, "cantilever.csv"))
    cases = list(dict.fromkeys(r["case"] for r in data))
    ref = {r["case"]: float(r["d_centre_m"]) for r in data if r["method"] == "calculix_extrapolated"}
    points = [r for r in data if r["method"] == "point"]
    spacings = sorted({float(r["spacing_m"]) for r in points}, reverse=True)
    factors = sorted({float(r["support_factor"]) for r in points})

    # seed Fig. 4: grouped bars of the tip deflection per load case, normalised by CalculiX
    series = [("CalculiX NLGEOM", lambda c: ref[c])]
    series.append(("Timoshenko", lambda c: next(float(r["d_centre_m"]) for r in data if r["case"] == c and r["method"] == "timoshenko")))
    series.append(("seed h = 0.1 m, s = 15 mm", lambda c: next(float(r["d_centre_m"]) for r in data if r["case"] == c and r["method"] == "point_seed_h")))
    for s in spacings:
        series.append((f"point h = 2s, s = {s * 1e3:g} mm",
                       lambda c, s=s: next(float(r["d_centre_m"]) for r in points if r["case"] == c and float(r["spacing_m"]) == s and float(r["support_factor"]) == 2.0)))
    fig, ax = plt.subplots(figsize=(10, 4.5))
    width = 0.8 / len(series)
    for k, (label, value) in enumerate(series):
        xs = [i + (k - len(series) / 2 + 0.5) * width for i in range(len(cases))]
        ax.bar(xs, [value(c) / ref[c] for c in cases], width, label=label)
    ax.axhline(1.0, color="k", lw=0.8)
    ax.set_xticks(range(len(cases)), cases)
    ax.set_ylabel("tip deflection / CalculiX NLGEOM")
    ax.set_title("Cantilever tip deflection (seed Fig. 4)")
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "deflection-bars.png"), dpi=120)
    plt.close(fig)

    # convergence: |relative error| against spacing, log-log, per support factor and load case; the axes in
    # mm and % with plain tick labels at the spacings run, and the observed order of each line in its label
    fig, ax = plt.subplots(figsize=(6.5, 4.8))
    for f in factors:
        for c in cases:
            pts = sorted((float(r["spacing_m"]) * 1e3, abs(float(r["error_centre_pct"])))
                         for r in points if r["case"] == c and float(r["support_factor"]) == f)
            if not pts:
                continue
            order = ""
            if len(pts) >= 2 and pts[0][1] > 0 and pts[-1][1] > 0:
                order = f", order {math.log(pts[-1][1] / pts[0][1]) / math.log(pts[-1][0] / pts[0][0]):.1f}"
            ax.loglog([p[0] for p in pts], [max(p[1], 1e-3) for p in pts], "o-" if f == 2.0 else "s--",
                      label=f"h = {f:g}s, {c}{order}", lw=1, ms=4)
    ticks = sorted({s * 1e3 for s in spacings})
    ax.xaxis.set_major_locator(FixedLocator(ticks))
    ax.xaxis.set_minor_locator(NullLocator())
    ax.xaxis.set_major_formatter(ScalarFormatter())
    ax.yaxis.set_major_formatter(ScalarFormatter())
    ax.yaxis.set_minor_formatter(ScalarFormatter())
    ax.tick_params(axis="y", which="minor", labelsize=7)
    ax.set_xlabel("spacing s (mm)")
    ax.set_ylabel("|error| of the tip deflection vs CalculiX (%)")
    note = " (--quick: two spacings)" if len(ticks) < 3 else ""
    ax.set_title("Convergence under refinement" + note)
    ax.grid(True, which="both", lw=0.3, alpha=0.5)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "convergence.png"), dpi=120)
    plt.close(fig)

    # seed Fig. 3: the deformed beams side by side (largest tip load), in mm, the colour bar beside them
    deformed = rows(os.path.join(out, "deformed.csv"))
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.4), sharey=True, layout="constrained")
    for ax, model, title in ((axes[0], "point", "point model (s = 7.5 mm)"), (axes[1], "calculix", "CalculiX NLGEOM")):
        sel = [r for r in deformed if r["model"] == model]
        x = [1e3 * (float(r["x"]) + float(r["ux"])) for r in sel]
        y = [1e3 * (float(r["y"]) + float(r["uy"])) for r in sel]
        mag = [1e3 * (float(r["ux"]) ** 2 + float(r["uy"]) ** 2 + float(r["uz"]) ** 2) ** 0.5 for r in sel]
        ax.scatter([1e3 * float(r["x"]) for r in sel], [1e3 * float(r["y"]) for r in sel], s=3, c="0.8")
        sc = ax.scatter(x, y, s=6, c=mag, cmap="viridis")
        ax.set_title(title)
        ax.set_aspect("equal")
        ax.set_xlabel("x (mm)")
    axes[0].set_ylabel("y (mm)")
    fig.colorbar(sc, ax=axes, label="|u| (mm); grey: the beam at rest", shrink=0.9)
    fig.savefig(os.path.join(out, "deformed.png"), dpi=120)
    plt.close(fig)

    # the point-load profile down the depth, in mm
    profile = rows(os.path.join(out, "point-load.csv"))
    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    ys = [float(r["y_m"]) * 1e3 for r in profile]
    ax.plot([-float(r["point_uy_m"]) * 1e3 for r in profile], ys, "o-", label="point model")
    ax.plot([-float(r["calculix_uy_m"]) * 1e3 for r in profile], ys, "s--", label="CalculiX (load on one cell)")
    ax.xaxis.set_major_locator(plt.MaxNLocator(5))
    ax.xaxis.set_major_formatter(ScalarFormatter(useOffset=False))
    ax.set_xlabel("downward displacement (mm)")
    ax.set_ylabel("height y (mm), the load on the top face")
    ax.set_title("Point load at mid-span: profile below the load")
    ax.grid(True, lw=0.3, alpha=0.5)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "point-load.png"), dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
