#!/usr/bin/env python3
"""Plots of `pointhaptics experiment materials`: the flat punch's force against depth per model (point model
and CalculiX), and the cantilever's deflection error per model.

usage: plot_materials.py OUT
"""
import csv
import math
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

COLOURS = {"svk": "tab:red", "neo_hookean": "tab:blue", "mooney_rivlin": "tab:green"}


def number(text):
    try:
        value = float(text)
    except ValueError:
        return math.nan
    return value


def main(out):
    with open(os.path.join(out, "punch.csv"), newline="") as f:
        punch = list(csv.DictReader(f))
    by_model = defaultdict(list)
    for r in punch:
        by_model[(r["model"], r["spacing_m"])].append(r)
    fig, ax = plt.subplots(figsize=(6, 4.5))
    drawn = set()
    for (model, spacing), rows in by_model.items():
        depth = [1e3 * number(r["depth_m"]) for r in rows]
        colour = COLOURS.get(model, "k")
        if model not in drawn:
            ax.plot(depth, [number(r["calculix_n"]) for r in rows], "-", color=colour, label=f"{model}, CalculiX")
            drawn.add(model)
        marker = "o" if number(spacing) >= 0.005 else "s"
        ax.plot(depth, [number(r["point_n"]) if r["point_converged"] == "true" else math.nan for r in rows], marker,
                color=colour, mfc="none", label=f"{model}, point model {1e3 * number(spacing):g} mm")
        bad = [(d, number(r["point_n"])) for d, r in zip(depth, rows) if r["point_converged"] != "true"]
        if bad:
            ax.plot(*zip(*bad), "x", color=colour, label=f"{model}, point model: not physical")
    ax.set_xlabel("punch depth (mm)")
    ax.set_ylabel("punch force (N)")
    ax.set_title("Flat punch, E = 1e4 Pa, nu = 0.45")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "punch.png"), dpi=120)

    with open(os.path.join(out, "materials.csv"), newline="") as f:
        rows = [r for r in csv.DictReader(f) if r["method"] == "point"]
    fig, ax = plt.subplots(figsize=(6, 4))
    labels, values, colours = [], [], []
    for r in rows:
        labels.append(f"{r['model']}\n{r['case']}\n{1e3 * number(r['spacing_or_elements']):g} mm")
        values.append(number(r["error_pct"]))
        colours.append(COLOURS.get(r["model"], "k"))
    ax.bar(range(len(values)), values, color=colours)
    ax.set_xticks(range(len(values)))
    ax.set_xticklabels(labels, fontsize=6)
    ax.axhline(2, color="k", lw=0.5, ls="--")
    ax.axhline(-2, color="k", lw=0.5, ls="--")
    ax.set_ylabel("tip deflection error vs CalculiX (%)")
    ax.set_title("Seed cantilever per model (dashed: the 2% goal)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "cantilever-materials.png"), dpi=120)


if __name__ == "__main__":
    main(sys.argv[1])
