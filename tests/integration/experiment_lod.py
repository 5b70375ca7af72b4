#!/usr/bin/env python3
"""End to end: the levels-of-detail experiments (--quick) write their CSV, markdown and plots, with the
contract's columns; levels of detail simulate fewer points; the dithered selection is more accurate than the
seed's random one at equal weights."""
import csv
import os
import subprocess
import sys

exe, out = sys.argv[1], sys.argv[2]


def rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def run(name, folder, files):
    subprocess.run([exe, "experiment", name, "--out", folder, "--quick", "--seconds", "0.15"], check=True)
    for f in files:
        assert os.path.getsize(os.path.join(folder, f)) > 100, f"{name}: {f} missing or empty"


# seed Table 1
table_dir = os.path.join(out, "lod-table")
run("lod-table", table_dir, ("lod-table.csv", "lod-table.md", "lod-table.png"))
table = rows(os.path.join(table_dir, "lod-table.csv"))
assert list(table[0].keys())[:7] == ["points", "tr1", "tr2", "mode", "selected", "steps_per_s", "seed_fps"], table[0].keys()
for n in {r["points"] for r in table}:
    full = [r for r in table if r["points"] == n and r["mode"] == "full"]
    lod = [r for r in table if r["points"] == n and r["mode"] == "lod"]
    assert len(full) == 1 and len(lod) == 3, n
    for r in lod:
        assert 0 < int(r["selected"]) < int(n), r
        assert float(r["steps_per_s"]) > 0 and r["seed_fps"], r
    # wider bands select more points
    assert int(lod[0]["selected"]) < int(lod[1]["selected"]) < int(lod[2]["selected"]), lod
seed_rows = sorted({int(r["points"]) for r in table})
assert abs(seed_rows[0] - 224) < 15 and abs(seed_rows[1] - 500) < 25 and abs(seed_rows[2] - 1200) < 50, seed_rows

# seed Fig. 8-9
prop_dir = os.path.join(out, "propagation")
run("propagation", prop_dir, ("propagation.csv", "propagation-runs.csv", "summary.md", "propagation.png", "propagation-3d.png"))
runs = {r["run"]: r for r in rows(os.path.join(prop_dir, "propagation-runs.csv"))}
assert set(runs) == {"full", "random 0.4", "random 0.2", "dither 0.4", "dither 0.2"}, runs.keys()
assert float(runs["full"]["error_near_pct"]) == 0
for name in ("random 0.4", "random 0.2", "dither 0.4", "dither 0.2"):
    assert int(runs[name]["selected"]) < int(runs["full"]["selected"]), name
    assert 0 < float(runs[name]["error_near_pct"]) < 50, runs[name]
assert int(runs["random 0.2"]["selected"]) < int(runs["random 0.4"]["selected"])

# error against speed-up
err_dir = os.path.join(out, "lod-error")
run("lod-error", err_dir, ("lod-error.csv", "lod-error.md", "lod-error.png"))
err = rows(os.path.join(err_dir, "lod-error.csv"))


def mean_error(scheme, k, key):
    v = [float(r[key]) for r in err if r["scheme"] == scheme and r["K"] == k and float(r["level_distance_h"]) > 5]
    assert v, (scheme, k)
    return sum(v) / len(v)


for k in ("4", "6", "8", "9"):
    d, r = mean_error("dither", k, "error_near_pct"), mean_error("random", k, "error_near_pct")
    assert d < r, f"K={k}: dither {d:.2f}% is not below random {r:.2f}%"
print("lod experiments: ok")
