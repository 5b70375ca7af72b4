#!/usr/bin/env python3
"""Plots of `pointhaptics experiment contact`: force against depth beside CalculiX and Hertz, and the sliding forces.

usage: plot_contact.py OUT
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def main(out):
    force = read(os.path.join(out, "contact-force.csv"))
    sliding = read(os.path.join(out, "contact-sliding.csv"))
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4))
    def label(r):
        n, m = int(r["spacing_over_r"]), int(r.get("refine_over_r", 0) or 0)
        return f"R/{n}, R/{m} near the contact" if m else f"R/{n}"

    samplings = list(dict.fromkeys(label(r) for r in force))
    for name in samplings:
        rows = [r for r in force if label(r) == name]
        left.plot([float(r["depth_over_r"]) for r in rows], [float(r["force_n"]) for r in rows], "o-", label=f"points, {name}")
    rows = [r for r in force if label(r) == samplings[0]]
    left.plot([float(r["depth_over_r"]) for r in rows], [float(r["calculix_n"]) for r in rows], "k-", lw=2, label="CalculiX (converged)")
    left.plot([float(r["depth_over_r"]) for r in rows], [float(r["hertz_n"]) for r in rows], "k--", label="Hertz (half-space)")
    left.set_xlabel("depth / R")
    left.set_ylabel("force on the sphere (N)")
    left.set_title("Sphere pressed into the block")
    left.legend()
    for name in dict.fromkeys(label(r) for r in sliding):
        rows = [r for r in sliding if label(r) == name]
        x = [float(r["x_over_spacing"]) for r in rows]
        right.plot(x, [float(r["normal_n"]) for r in rows], "o-", label=f"normal, {name}")
        right.plot(x, [float(r["tangential_n"]) for r in rows], "s--", label=f"tangential, {name}")
    right.set_xlabel("tool position along x / spacing")
    right.set_ylabel("force (N)")
    right.set_title("Sliding at 0.1 R deep, frictionless")
    right.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "contact.png"), dpi=120)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
