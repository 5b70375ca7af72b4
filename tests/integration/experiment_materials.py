#!/usr/bin/env python3
"""End to end: `pointhaptics experiment materials --quick` writes its CSVs, summary and plots, and each model that
CalculiX has agrees with CalculiX's own on the cantilever (within 2% at 5 mm spacing, tip load and gravity). The
punch's quick CalculiX mesh (10 x 5 x 10) is too coarse to hold the point model to 3% (docs/materials.md says
why); here the punch must solve at every depth without inverting, stiffen with depth, and show St.
Venant-Kirchhoff softening against neo-Hookean as CalculiX's does."""
import csv
import os
import subprocess
import sys

exe, out = sys.argv[1], sys.argv[2]
subprocess.run([exe, "experiment", "materials", "--quick", "--threads", "2", "--out", out], check=True)
for name in ("materials.csv", "punch.csv", "punch-calculix.csv", "summary.md", "cantilever-materials.png", "punch.png"):
    path = os.path.join(out, name)
    assert os.path.getsize(path) > 100, f"{name} missing or empty"
with open(os.path.join(out, "materials.csv"), newline="") as f:
    rows = list(csv.DictReader(f))
models = {r["model"] for r in rows}
assert models == {"svk", "neo_hookean", "mooney_rivlin"}, models
fine = [r for r in rows if r["method"] == "point" and float(r["spacing_or_elements"]) == 0.005]
assert len(fine) == 6, fine
for r in fine:
    assert r["converged"] == "true", r
    assert abs(float(r["error_pct"])) < 2.0, f"{r['model']} {r['case']}: {r['error_pct']}% at 5 mm"
with open(os.path.join(out, "punch.csv"), newline="") as f:
    punch = list(csv.DictReader(f))
force = {}
for model in models:
    series = sorted((float(r["depth_m"]), float(r["point_n"]), float(r["calculix_n"]), r) for r in punch if r["model"] == model)
    assert [round(d, 4) for d, *_ in series] == [0.001, 0.002, 0.003, 0.004, 0.005], series
    for _, point, fem, r in series:
        assert r["point_converged"] == "true" and r["point_inverted"] == "false", r
        assert 0 < fem < point < 1.6 * fem, r  # the coarse CalculiX mesh is softer (docs/materials.md)
    assert all(b[1] > a[1] for a, b in zip(series, series[1:])), f"{model}: the force must grow with depth"
    force[model] = series[-1][1], series[-1][2]
# CalculiX's own table (its quarter model with mirror planes) holds the forces compared against
with open(os.path.join(out, "punch-calculix.csv"), newline="") as f:
    fem = {(r["model"], round(float(r["depth_m"]), 4)): float(r["force_n"]) for r in csv.DictReader(f) if r["elements"] == "10"}
for r in punch:
    assert abs(fem[(r["model"], round(float(r["depth_m"]), 4))] / float(r["calculix_n"]) - 1) < 1e-5, r
# at 5 mm St. Venant-Kirchhoff is the softest in both codes
assert force["svk"][0] < force["neo_hookean"][0] and force["svk"][1] < force["neo_hookean"][1], force
print("experiment materials: ok")
