#!/usr/bin/env python3
"""The picture of `pointhaptics experiment contact-pairs`: each quantity's relative error against its tolerance
(contact-pairs.csv) as contact-pairs.png; the yes-or-no checks as a column of marks."""
import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(out: Path):
    rows = list(csv.DictReader((out / "contact-pairs.csv").open()))
    measured = [r for r in rows if float(r["tolerance"]) > 0]
    checks = [r for r in rows if float(r["tolerance"]) == 0]
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(14, 0.45 * max(len(measured), len(checks)) + 1.6),
                                 gridspec_kw={"width_ratios": [3, 2]})
    labels = [f'{r["pair"]}: {r["quantity"]}' for r in measured]
    errors = [max(float(r["relative_error"]), 1e-12) for r in measured]
    tolerances = [float(r["tolerance"]) for r in measured]
    y = range(len(measured))
    ax.barh(y, errors, color=["tab:green" if r["holds"] == "1" else "tab:red" for r in measured], label="relative error")
    ax.scatter(tolerances, y, marker="|", s=300, color="black", label="tolerance", zorder=3)
    ax.set_xscale("log")
    ax.set_yticks(list(y), labels, fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel("|measured - expected| / |expected|")
    ax.legend(fontsize=8, loc="lower right")
    ax.set_title("what each pair carries, against statics", fontsize=10)
    bx.axis("off")
    for k, r in enumerate(checks):
        mark, colour = ("holds", "tab:green") if r["holds"] == "1" else ("FAILS", "tab:red")
        bx.text(0.0, 1 - (k + 0.5) / max(len(checks), 1), f'{mark}  {r["pair"]}: {r["quantity"]}', color=colour,
                fontsize=8, va="center", transform=bx.transAxes)
    bx.set_title("checks", fontsize=10)
    fig.tight_layout()
    fig.savefig(out / "contact-pairs.png", dpi=110)


if __name__ == "__main__":
    main(Path(sys.argv[1]))
