"""`pointhaptics run --tool-log FILE` (issue 47): each posed tool's force at the start and after every step, as
CSV rows t, tool, fx, fy, fz, friction, contacts, penetration. On the shipped pinch-and-lift scene: two rows a
step in time order, the jaws open at the start (no contact), and at the end carrying the sample's weight between
them by friction, as the result JSON's tools block says.
With two hands, `--force-log FILE` writes one log per hand (FILE, and FILE-HAND beside it).
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

# two hands, each with its own force log: --force-log FILE writes the first hand's to FILE and the other's beside it
# under FILE's stem and its name (the shipped two-hands scene for 0.1 s, deterministic: 100 ticks each)
force = os.path.join(work, "force.csv")
subprocess.run([cli, "run", os.path.join(scenes, "two_hands_two_layers.toml"), "--quiet", "--deterministic",
                "--set", "solver.duration=0.1", "--force-log", force, "--json", result], check=True, timeout=300)
doc = json.load(open(result))
for path, hand in ((force, "finger"), (os.path.join(work, "force-probe.csv"), "probe")):
    ticks = list(csv.DictReader(open(path)))
    assert len(ticks) == doc["tools"][hand]["haptic"]["ticks"] == 100, (path, len(ticks))
    largest = max((float(r["fx"])**2 + float(r["fy"])**2 + float(r["fz"])**2)**0.5 for r in ticks)
    assert abs(largest - doc["tools"][hand]["haptic"]["max_force_n"]) < 1e-6, (path, largest)
print("force logs: one per hand, each its own loop's ticks")
