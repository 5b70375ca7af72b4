#!/usr/bin/env python3
"""End to end: `pointhaptics experiment force-profile` writes its CSV, summary and plot; the force rises while
the point is dragged, stays while it is held, and falls to nothing once it is let go (seed Fig. 2c)."""
import csv
import os
import subprocess
import sys

exe, out = sys.argv[1], sys.argv[2]
subprocess.run([exe, "experiment", "force-profile", "--out", out], check=True)
for name in ("force-profile.csv", "summary.md", "force-profile.png"):
    assert os.path.getsize(os.path.join(out, name)) > 100, f"{name} missing or empty"
with open(os.path.join(out, "force-profile.csv"), newline="") as f:
    rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
assert len(rows) == 4000, len(rows)
before = max(r["force_n"] for r in rows if r["t_s"] < 0.2)
held = [r["force_n"] for r in rows if 1.5 < r["t_s"] < 1.95]
after = max(r["force_n"] for r in rows if r["t_s"] > 3.0)
assert before < 1e-6, before
assert min(held) > 0.5 and max(held) <= 3.3, (min(held), max(held))
assert after < 0.05, after
print("force profile: ok")
