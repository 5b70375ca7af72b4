"""The command line's outputs under failure (issue 21, items 2 and 3b): a full disk, a missing folder, a folder
or a read-only file given as an output, and SIGINT/SIGTERM during a run.

- every output is checked before the first step: a long run fails at once, not after the work;
- a full disk (/dev/full) is a named error with the path, never an abort, and the other outputs (the result
  JSON above all) are still written;
- a run interrupted by SIGINT or SIGTERM stops at the next step, writes its outputs for the state reached
  (marked "interrupted" in the result JSON) and exits with 130;
- no half-written file is ever left: files are written beside the target and renamed.
Usage: cli_outputs.py CLI SCENES WORK
"""
import json
import os
import re
import signal
import subprocess
import sys
import time

cli, scenes, work = sys.argv[1:4]
os.makedirs(work, exist_ok=True)
beam = os.path.join(scenes, "beam_fixed_both_ends.toml")
long_run = os.path.join(work, "long.toml")
with open(os.path.join(scenes, "cantilever.toml")) as f:
    text = f.read()
open(long_run, "w").write(re.sub(r"(?m)^duration = .*$", "duration = 10000.0", text))


def run(*args, timeout=120):
    start = time.monotonic()
    p = subprocess.run([cli, "run", *args, "--quiet"], capture_output=True, text=True, timeout=timeout)
    return p, time.monotonic() - start


def expect_error(args, words, fast=False):
    p, elapsed = run(*args)
    err = p.stderr.strip()
    assert p.returncode == 1, (args, p.returncode, err)
    assert "terminate" not in err and "internal error" not in err, err
    for w in words:
        assert w in err, (args, w, err)
    if fast:
        assert elapsed < 10, f"{args}: failed only after {elapsed:.1f} s"
    print(f"ok: {' '.join(args[1:])}: {err}")


# 3b: bad outputs are refused before anything is computed (the long run would take hours)
expect_error([long_run, "--json", os.path.join(work, "no-such-folder", "r.json")], ["--json", "no-such-folder", "does not exist"], fast=True)
expect_error([long_run, "--csv", work], ["--csv", "is a folder"], fast=True)
read_only = os.path.join(work, "read-only.json")
open(read_only, "w").write("{}")
os.chmod(read_only, 0o444)
if os.geteuid() != 0:  # root writes anyway
    expect_error([long_run, "--json", read_only], ["--json", "cannot be written"], fast=True)
expect_error([long_run, "--force-log", os.path.join(work, "missing", "f.csv")], ["--force-log", "does not exist"], fast=True)

# 2: a full disk is a named error; the result JSON is still written, and no partial file is left
result = os.path.join(work, "full.json")
if os.path.exists(result):
    os.remove(result)
expect_error([beam, "--csv", "/dev/full", "--json", result], ["--csv /dev/full", "No space left on device"])
assert json.load(open(result))["solver"]["converged"]
expect_error([beam, "--json", "/dev/full"], ["/dev/full", "No space left on device"])
probe = os.path.join(scenes, "beam_probe.toml")
expect_error([probe, "--deterministic", "--force-log", "/dev/full", "--json", result], ["--force-log /dev/full", "No space left"])
assert json.load(open(result))["haptic"]["ticks"] > 0
assert not [f for f in os.listdir(work) if f.endswith(".partial")], os.listdir(work)

# 4 (part): SIGINT and SIGTERM stop the run at the next step; the outputs hold the state reached
for sig in (signal.SIGINT, signal.SIGTERM):
    result = os.path.join(work, f"interrupted-{sig.name}.json")
    csv = os.path.join(work, f"interrupted-{sig.name}.csv")
    proc = subprocess.Popen([cli, "run", long_run, "--json", result, "--csv", csv, "--quiet"], stderr=subprocess.PIPE, text=True)
    time.sleep(1.5)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, (sig.name, proc.returncode, err)
    assert "interrupted at t =" in err, err
    doc = json.load(open(result))
    assert doc["solver"]["interrupted"] is True and doc["solver"]["steps"] > 0, doc["solver"]
    assert len(open(csv).read().splitlines()) == len(doc["points"]["reference"]) + 1
    print(f"ok: {sig.name} stopped the run after {doc['solver']['steps']} steps: {err.strip()}")
assert not [f for f in os.listdir(work) if f.endswith(".partial")], os.listdir(work)

# 6: the force log is streamed: a run of a million seconds logs in bounded memory (it reserved a row per
# tick up front and failed with bad_alloc at once); interrupted, the file holds every tick so far
endless = os.path.join(work, "endless_probe.toml")
with open(probe) as f:
    text = f.read()
text = re.sub(r"(?m)^duration = .*$", "duration = 1e6", text)
open(endless, "w").write(text)
log = os.path.join(work, "endless.csv")
proc = subprocess.Popen([cli, "run", endless, "--deterministic", "--quiet", "--force-log", log], stderr=subprocess.PIPE, text=True)
time.sleep(3)
proc.send_signal(signal.SIGINT)
_, err = proc.communicate(timeout=60)
assert proc.returncode == 130, (proc.returncode, err)
rows = open(log).read().splitlines()
assert rows[0].startswith("t,x,y,z") and len(rows) > 1000, (len(rows), err)
times = [float(r.split(",")[0]) for r in rows[1:]]
assert all(b > a for a, b in zip(times, times[1:])), "rows out of order"
print(f"ok: an endless run streamed {len(rows) - 1} rows to its force log before SIGINT")
# 4: a run that cannot finish in reasonable time says so after a second, and suggests the implicit solver
stiff = os.path.join(work, "stiff.toml")
open(stiff, "w").write('[object]\nshape = "box"\nsize = [0.1, 0.03, 0.03]\nspacing = 0.005\n[material]\nyoung = 1e12\n'
                       '[[fixed]]\nbox = { min = [-1, -1, -1], max = [0.0, 1, 1] }\n[solver]\nkind = "explicit"\nduration = 100.0\n')
proc = subprocess.Popen([cli, "run", stiff, "--quiet"], stderr=subprocess.PIPE, text=True)
time.sleep(4)
proc.send_signal(signal.SIGINT)
_, err = proc.communicate(timeout=60)
assert proc.returncode == 130 and "this run will take about" in err and "implicit" in err, (proc.returncode, err)
print("ok: " + err.splitlines()[0])

# 12b: --vtk-every animates an interactive run (only its first and last frames were written)
frames = os.path.join(work, "probe_frames")
probe_json = os.path.join(work, "probe.json")
p, _ = run(probe, "--deterministic", "--vtk", frames, "--vtk-every", "100", "--json", probe_json)
assert p.returncode == 0, p.stderr
tool = json.load(open(probe_json))["tool"]  # issue 16: every run with a tool has its block
assert tool["kind"] == "sphere" and len(tool["position"]) == 3 and len(tool["force"]) == 3, tool
vtp = [f for f in os.listdir(frames) if f.endswith(".vtp") and "_surface_" not in f]
assert len(vtp) == 3000 // 100 + 2, len(vtp)  # every 100 of 3000 steps, the first and the last state
surfaces = [f for f in os.listdir(frames) if f.endswith(".vtp") and "_surface_" in f]
assert len(surfaces) == len(vtp), (len(surfaces), len(vtp))  # each with the object's surface
print(f"ok: --vtk-every 100 wrote {len(vtp)} frames of a probe run")
print("outputs ok")
