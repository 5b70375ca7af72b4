#!/usr/bin/env python3
"""Plot of `pointhaptics experiment lod-table` (seed Table 1): steps per second against object size.

usage: plot_lod.py OUT
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import FixedLocator, NullFormatter, NullLocator, StrMethodFormatter  # noqa: E402


def main(out):
    with open(os.path.join(out, "lod-table.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    fig, ax = plt.subplots(figsize=(8, 4.5))
    sizes = sorted({int(r["points"]) for r in rows})
    full = [float(next(r for r in rows if int(r["points"]) == n and r["mode"] == "full")["steps_per_s"]) for n in sizes]
    ax.plot(sizes, full, "k-o", label="full model")
    markers = ["s", "^", "D"]
    bands = sorted({(r["tr1"], r["tr2"]) for r in rows if r["mode"] == "lod"})
    for k, (tr1, tr2) in enumerate(bands):
        sel = [r for r in rows if r["mode"] == "lod" and (r["tr1"], r["tr2"]) == (tr1, tr2)]
        sel.sort(key=lambda r: int(r["points"]))
        line, = ax.plot([int(r["points"]) for r in sel], [float(r["steps_per_s"]) for r in sel], "-" + markers[k % 3],
                        label=f"LOD, T_r1 = {tr1}h, T_r2 = {tr2}h")
        seed = [(int(r["points"]), float(r["seed_fps"])) for r in sel if r["seed_fps"]]
        if seed:
            ax.plot([p for p, _ in seed], [v for _, v in seed], markers[k % 3], mfc="none", color=line.get_color(), ms=9,
                    label=f"seed Table 1 (fps, Pentium 4), {tr1}h, {tr2}h")
    ax.set_xscale("log")
    ax.set_yscale("log")
    # plain labels at the object sizes run (not 3 x 10^2), thousands separated
    ax.xaxis.set_major_locator(FixedLocator(sizes))
    ax.xaxis.set_minor_locator(NullLocator())
    ax.xaxis.set_major_formatter(StrMethodFormatter("{x:,.0f}"))
    ax.yaxis.set_major_formatter(StrMethodFormatter("{x:,.0f}"))
    ax.yaxis.set_minor_formatter(NullFormatter())
    plt.setp(ax.get_xticklabels(), rotation=30, ha="right")
    ax.set_xlabel("points in the object")
    ax.set_ylabel("explicit steps per second")
    ax.set_title("Levels of detail: steps per second (seed Table 1)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "lod-table.png"), dpi=120)


if __name__ == "__main__":
    main(sys.argv[1])
