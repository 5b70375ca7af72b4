#!/usr/bin/env python3
"""Plot of `pointhaptics experiment lod-error`: displacement error against speed-up, per selection scheme.

usage: plot_lod_error.py OUT
"""
import csv
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(out):
    with open(os.path.join(out, "lod-error.csv"), newline="") as f:
        rows = [r for r in csv.DictReader(f) if r["scheme"] != "full"]
    groups = defaultdict(list)
    for r in rows:
        groups[(r["scheme"], r["level_distance_h"], r["K"])].append(r)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), sharex=True)
    style = {"random": "tab:red", "dither": "tab:blue", "all": "k"}
    for (scheme, dist, k), rs in sorted(groups.items()):
        sp = sum(float(r["speedup"]) for r in rs) / len(rs)
        near = sum(float(r["error_near_pct"]) for r in rs) / len(rs)
        whole = sum(float(r["error_whole_pct"]) for r in rs) / len(rs)
        marker = "o" if float(dist) < 5 else "s"
        for ax, e in zip(axes, (near, whole)):
            ax.plot(sp, e, marker, color=style.get(scheme, "g"), mfc="none" if float(dist) < 5 else None)
            ax.annotate(f"K={k}", (sp, e), fontsize=6, xytext=(3, 2), textcoords="offset points")
    from matplotlib.ticker import LogLocator, NullFormatter, StrMethodFormatter  # noqa: E402

    for ax, title in zip(axes, ("largest error inside T_r1 (%)", "RMS error over the object (%)")):
        ax.set_xscale("log")
        ax.set_yscale("log")
        # plain labels (0.3, 1, 2; 5, 10, 50), not 3 x 10^-1 running into each other
        for axis in (ax.xaxis, ax.yaxis):
            axis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
            axis.set_major_formatter(StrMethodFormatter("{x:g}"))
            axis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("speed-up of the explicit step")
        ax.set_title(title, fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
    handles = [plt.Line2D([], [], color=c, marker="o", ls="", label=s) for s, c in style.items()]
    handles += [plt.Line2D([], [], color="0.3", marker="o", mfc="none", ls="", label="level to 3h"),
                plt.Line2D([], [], color="0.3", marker="s", ls="", label="level over the whole object")]
    axes[0].legend(handles=handles, fontsize=7)
    fig.suptitle("Levels of detail: error against speed-up (random: mean of 3 seeds)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "lod-error.png"), dpi=120)


if __name__ == "__main__":
    main(sys.argv[1])
