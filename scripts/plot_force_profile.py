#!/usr/bin/env python3
"""Plot of `pointhaptics experiment force-profile` (seed Fig. 2c): force magnitude over time.

usage: plot_force_profile.py OUT
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(out):
    with open(os.path.join(out, "force-profile.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    t = [float(r["t_s"]) for r in rows]
    force = [float(r["force_n"]) for r in rows]
    held = [float(r["button"]) > 0 for r in rows]
    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.plot(t, force, lw=1, label="|F| at the device")
    lo = min(t[i] for i in range(len(t)) if held[i]) if any(held) else None
    hi = max(t[i] for i in range(len(t)) if held[i]) if any(held) else None
    if lo is not None:
        ax.axvspan(lo, hi, color="0.9", label="button held (point grabbed)")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("force (N)")
    ax.set_title("Force felt while dragging a point of the beam (seed Fig. 2c)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "force-profile.png"), dpi=120)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
