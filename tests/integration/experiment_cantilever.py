#!/usr/bin/env python3
"""End to end: `pointhaptics experiment cantilever --quick` writes its CSV, summary and plots, and the point
model agrees with CalculiX as physics.md says it should (h = 2s: within 2% at s = 7.5 mm for every load)."""
import csv
import os
import subprocess
import sys

exe, out = sys.argv[1], sys.argv[2]
subprocess.run([exe, "experiment", "cantilever", "--quick", "--threads", "2", "--out", out], check=True)
for name in ("cantilever.csv", "point-load.csv", "deformed.csv", "summary.md", "deflection-bars.png",
             "convergence.png", "deformed.png", "point-load.png"):
    path = os.path.join(out, name)
    assert os.path.getsize(path) > 100, f"{name} missing or empty"
with open(os.path.join(out, "cantilever.csv"), newline="") as f:
    rows = list(csv.DictReader(f))
point = [r for r in rows if r["method"] == "point" and float(r["spacing_m"]) == 0.0075]
assert len(point) == 2, point
for r in point:
    err = float(r["error_centre_pct"])
    assert abs(err) < 2.0, f"{r['case']}: {err}% at s = 7.5 mm"
seed = [r for r in rows if r["method"] == "point_seed_h"]
assert all(float(r["error_centre_pct"]) > 25 for r in seed), "the seed's h = 0.1 m should be far too soft"
with open(os.path.join(out, "point-load.csv"), newline="") as f:
    profile = list(csv.DictReader(f))
bottom_point, bottom_fem = float(profile[-1]["point_uy_m"]), float(profile[-1]["calculix_uy_m"])
assert abs(bottom_point / bottom_fem - 1) < 0.03, (bottom_point, bottom_fem)
# the speed at equal accuracy: both within 1% of the reference, the point model faster
with open(os.path.join(out, "summary.md")) as f:
    summary = f.read()
speed = [line for line in summary.splitlines() if line.startswith("the cheapest point model within 1%")]
assert len(speed) == 1, summary
ratio = float(speed[0].split("the point model is ")[1].split("x faster")[0])
assert ratio > 1, speed[0]
print("experiment cantilever: ok")
