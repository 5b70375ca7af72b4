#!/usr/bin/env python3
"""End to end: `pointhaptics experiment contact --quick` writes its CSVs, summary and plot; the force rises
with depth, within 25% of CalculiX's (today 10-20% above it at spacing R/4, neo-Hookean), whose own force lies
between Hertz's and 1.2 times it (the block's finite depth); refined to R/8 near the contact, within 8%; no surface vertex ends deeper in the
sphere than 1% of the depth; first contact is within 0.05 R of the true surface; frictionless sliding keeps
the normal force's ripple under 5% and the tangential force under 2% of it. Then a scene with a tool held
at a position, solved statically, writes the result JSON's tool block."""
# Tier: long (label `long`, scripts/test --long). Its mesh-converged CalculiX contact model takes about 300 s of
# a 2-core machine, more than the rest of the optimised suite; the contact's force and depth stay guarded in the
# default tier by ProbeOnSurface.* and SurfaceContact.* and by experiment_materials_quick's punch.
import csv
import json
import os
import re
import subprocess
import sys

exe, out = sys.argv[1], sys.argv[2]
subprocess.run([exe, "experiment", "contact", "--quick", "--drag-steps", "16", "--out", out], check=True)
for name in ("contact-force.csv", "contact-calculix.csv", "contact-sliding.csv", "contact-friction.csv", "summary.md", "contact.png"):
    assert os.path.getsize(os.path.join(out, name)) > 100, f"{name} missing or empty"
with open(os.path.join(out, "contact-force.csv"), newline="") as f:
    rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
refined = [r for r in rows if r["refine_over_r"] > 0]
rows = [r for r in rows if r["refine_over_r"] == 0]
assert [r["depth_over_r"] for r in rows] == [0.1, 0.2, 0.3], rows
assert [r["depth_over_r"] for r in refined] == [0.1, 0.2, 0.3], refined
# refined to R/8 near the contact: within 8% of CalculiX (today 0-6% on its R/10 mesh)
for r in refined:
    assert abs(r["ratio_to_calculix"] - 1) < 0.08, r
    assert r["penetration_m"] < 0.01 * r["depth_m"] and r["physical"] == 1, r
forces = [r["force_n"] for r in rows]
assert forces == sorted(forces) and forces[0] > 0, forces
for r in rows:
    assert 0.8 < r["ratio_to_calculix"] < 1.25, r
    assert 1.0 < r["calculix_n"] / r["hertz_n"] < 1.2, r
    assert r["penetration_m"] < 0.01 * r["depth_m"], r
    assert r["physical"] == 1, r
summary = open(os.path.join(out, "summary.md")).read()
offset = float(re.search(r"\| R/4 \| (-?[0-9.]+) R \(", summary).group(1))
assert abs(offset) < 0.05, offset
with open(os.path.join(out, "contact-sliding.csv"), newline="") as f:
    sliding = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
sliding = [r for r in sliding if r["refine_over_r"] == 0]
normal = [r["normal_n"] for r in sliding]
mean = sum(normal) / len(normal)
ripple = (sum((n - mean) ** 2 for n in normal) / len(normal)) ** 0.5 / mean
assert ripple < 0.05, ripple
assert max(r["tangential_n"] for r in sliding) < 0.02 * mean, sliding

# friction (mu = 0.3): nudged, the contact sticks; dragged in quasi-static steps of a 16th of the spacing (the
# experiment's default 32nd takes twice as long), the friction's part of the force is within 5% of mu times the
# pressure's at every equilibrium of the second spacing (today 1-3.7% short: a vertex whose pressure grows
# during a step sticks a little short of its cone; 1-2% at a 32nd)
with open(os.path.join(out, "contact-friction.csv"), newline="") as f:
    friction = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
assert all(r["steps_per_spacing"] == 16 for r in friction), {r["steps_per_spacing"] for r in friction}
assert friction[1]["friction_over_pressure"] < 0.1 * 0.3, friction[1]
sliding_friction = [r["friction_over_pressure"] for r in friction if r["x_over_spacing"] > 1.0]
assert len(sliding_friction) == 16 and all(abs(m / 0.3 - 1) < 0.05 for m in sliding_friction), sliding_friction

# a static indentation from a scene file: the tool block
scene = os.path.join(out, "indent.toml")
with open(scene, "w") as f:
    f.write("""[object]
shape = "box"
size = [0.04, 0.02, 0.04]
origin = [-0.02, 0.0, -0.02]
spacing = 0.005
[material]
young = 1e5
poisson = 0.3
[[fixed]]
box = { min = [-1.0, -1.0, -1.0], max = [1.0, 0.0, 1.0] }
[probe]
radius = 0.01
position = [0.0, 0.029, 0.0]
[solver]
kind = "static"
""")
result = os.path.join(out, "indent.json")
subprocess.run([exe, "run", scene, "--json", result, "--quiet"], check=True)
doc = json.load(open(result))
tool = doc["tool"]
assert tool["kind"] == "sphere" and tool["position"] == [0.0, 0.029, 0.0], tool
assert tool["force"][1] > 0 and abs(tool["force"][0]) < 1e-6 * tool["force"][1], tool
assert tool["contacts"] > 0 and tool["penetration"] < 1e-5, tool
assert abs(doc["constraints"][0]["reaction"][1] - tool["force"][1]) < 1e-3 * tool["force"][1], (doc["constraints"], tool)
print("contact: ok", forces, f"offset {offset} R, ripple {ripple:.4f}")
