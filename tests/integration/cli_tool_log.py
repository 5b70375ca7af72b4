"""`pointhaptics run --tool-log FILE` (issue 47): each posed tool's force at the start and after every step, as
CSV rows t, tool, fx, fy, fz, friction, contacts, penetration. On the shipped pinch-and-lift scene: two rows a
step in time order, the jaws open at the start (no contact), and at the end carrying the sample's weight between
them by friction, as the result JSON's tools block says.
Usage: cli_tool_log.py CLI SCENES WORK
"""
import csv
import json
import os
import subprocess
import sys

cli, scenes, work = sys.argv[1:4]
os.makedirs(work, exist_ok=True)
log, result = os.path.join(work, "tools.csv"), os.path.join(work, "tools.json")
subprocess.run([cli, "run", os.path.join(scenes, "pinch_and_lift.toml"), "--quiet", "--tool-log", log, "--json", result],
               check=True, timeout=300)
rows = list(csv.DictReader(open(log)))
doc = json.load(open(result))
steps = doc["solver"]["steps"]
assert len(rows) == 2 * (steps + 1), (len(rows), steps)
assert [r["tool"] for r in rows[:2]] == ["left", "right"], rows[:2]
times = [float(r["t"]) for r in rows[::2]]
assert times == sorted(times) and times[0] == 0.0 and abs(times[-1] - 0.4) < 1e-9, times[:3] + times[-3:]
assert all(int(r["contacts"]) == 0 for r in rows[:2]), rows[:2]
weight = 0.02**3 * 1000.0 * 9.81
last = {r["tool"]: r for r in rows[-2:]}
lift = -(float(last["left"]["fy"]) + float(last["right"]["fy"]))
assert abs(lift - weight) < 0.01 * weight, (lift, weight)
assert abs(float(last["left"]["fy"]) - doc["tools"]["left"]["force"][1]) < 1e-9, last["left"]
assert float(last["left"]["friction_y"]) < 0, last["left"]
print(f"tool log: {len(rows)} rows over {steps} steps; the jaws carry {lift:.5g} N of the {weight:.5g} N weight")
