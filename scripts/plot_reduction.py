#!/usr/bin/env python3
"""Plot of `pointhaptics experiment reduction`: the reduced model's error against the number of modes, per beam:
static tip displacement at each load (against the full point model, solid; against CalculiX NLGEOM, dashed), the
sudden load's history and the first natural frequency (against the full model).

usage: plot_reduction.py OUT
"""
import csv
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import NullFormatter, StrMethodFormatter  # noqa: E402


def main(out):
    with open(os.path.join(out, "reduction.csv"), newline="") as f:
        rows = [r for r in csv.DictReader(f) if int(r["modes"]) > 0]
    beams = sorted({r["beam"] for r in rows}, key=lambda b: b != "seed")
    fig, axes = plt.subplots(1, len(beams), figsize=(5.5 * len(beams), 4.2), squeeze=False)
    floor = 1e-4  # % (an error of zero drawn at the bottom)
    for ax, beam in zip(axes[0], beams):
        series = defaultdict(list)
        for r in rows:
            if r["beam"] != beam:
                continue
            m = int(r["modes"])
            if r["quantity"] == "tip_static":
                series[("static", r["load_N"], "full")].append((m, abs(float(r["error_vs_full_pct"]))))
                series[("static", r["load_N"], "calculix")].append((m, abs(float(r["error_vs_calculix_pct"]))))
            elif r["quantity"] == "tip_dynamic":
                series[("dynamic", r["load_N"], "full")].append((m, abs(float(r["error_vs_full_pct"]))))
            elif r["quantity"] == "first_frequency":
                series[("frequency", "", "full")].append((m, abs(float(r["error_vs_full_pct"]))))
        loads = sorted({k[1] for k in series if k[0] == "static"}, key=float)
        colours = plt.cm.viridis([i / max(len(loads) - 1, 1) for i in range(len(loads))])
        for (kind, load, against), points in sorted(series.items()):
            points.sort()
            x = [p[0] for p in points]
            y = [max(p[1], floor) for p in points]
            if kind == "static":
                c = colours[loads.index(load)]
                ls = "-" if against == "full" else "--"
                label = f"static {load} N" + (" vs full" if against == "full" else " vs CalculiX")
                ax.plot(x, y, ls, color=c, marker="o", ms=3, label=label)
            elif kind == "dynamic":
                ax.plot(x, y, "-", color="tab:red", marker="s", ms=4, label=f"sudden {load} N: history vs full")
            else:
                ax.plot(x, y, "-", color="k", marker="^", ms=4, label="first frequency vs full")
        ax.axhline(2, color="0.5", lw=0.8, ls=":")
        ax.axhline(1, color="0.5", lw=0.8, ls=":")
        ax.set_yscale("log")
        ax.yaxis.set_major_formatter(StrMethodFormatter("{x:g}"))
        ax.yaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("modes r")
        ax.set_ylabel("error (%)")
        ax.set_title(f"{beam} beam", fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6)
    fig.suptitle("Reduced model: error against the number of modes (goals: 2% static and dynamic, 1% frequency)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "reduction.png"), dpi=120)


if __name__ == "__main__":
    main(sys.argv[1])
