"""Parameter studies: a scene, parameters to vary over any of its keys, and the outputs of each run gathered
into one table (docs/studies.md). Every run is a task on Dask (pointhaptics.cluster).

    pointhaptics study study.toml --out DIR [--scheduler tcp://HOST:PORT] [--workers N]

or from Python, pointhaptics.study("study.toml", out="DIR") -> a pandas DataFrame. A study file:

    [study]
    scene = "../scenes/cantilever.toml"    # relative to the study file
    kind = "grid"                          # grid (every combination) | list (the i-th values together) | random
    samples = 16                           # random: how many runs
    seed = 1                               # random: the generator's seed

    [[study.parameter]]
    key = "material.young"                 # any scene key, as `pointhaptics run --set` takes it
    values = [5e4, 1e5, 2e5]               # or range = [low, high] with count = N (grid) and scale = "log"

    [[study.output]]
    name = "tip_deflection"
    kind = "displacement"                  # displacement | result | tool_force | error (pointhaptics.runs)
    at = [0.15, 0.015, 0.015]
    component = "y"

    [study.reference]                      # optional: a run with these settings, for outputs of kind "error"
    "object.spacing" = 0.00375
"""
from __future__ import annotations

import argparse
import itertools
import json
import math
import os
import sys
import time
import tomllib

import numpy as np

from . import cluster, runs


def _fail(path: str, what: str):
    raise ValueError(f"{path}: {what}")


def _parameter_values(path: str, p: dict, kind: str) -> dict:
    key = p.get("key")
    if not isinstance(key, str) or not key:
        _fail(path, "study.parameter: key = \"section.key\" is needed (e.g. material.young)")
    unknown = set(p) - {"key", "values", "range", "count", "scale"}
    if unknown:
        _fail(path, f"study.parameter {key}: unknown key {sorted(unknown)[0]}")
    scale = p.get("scale", "linear")
    if scale not in ("linear", "log"):
        _fail(path, f"study.parameter {key}: scale must be linear or log")
    if "values" in p:
        if "range" in p:
            _fail(path, f"study.parameter {key}: give values or range, not both")
        values = p["values"]
        if not isinstance(values, list) or not values:
            _fail(path, f"study.parameter {key}: values must be a non-empty list")
        return {"key": key, "values": values, "scale": scale}
    rng = p.get("range")
    if not (isinstance(rng, list) and len(rng) == 2 and all(isinstance(v, (int, float)) for v in rng) and rng[0] < rng[1]):
        _fail(path, f"study.parameter {key}: values = [...] or range = [low, high] (low < high) is needed")
    if scale == "log" and rng[0] <= 0:
        _fail(path, f"study.parameter {key}: a log scale needs a range above 0")
    if kind == "random":
        return {"key": key, "range": rng, "scale": scale}
    count = p.get("count")
    if not (isinstance(count, int) and count >= 1):
        _fail(path, f"study.parameter {key}: a range on a {kind} needs count = N (N >= 1)")
    values = np.geomspace(*rng, count) if scale == "log" else np.linspace(*rng, count)
    return {"key": key, "values": [float(v) for v in values], "scale": scale}


def load_study(path: str) -> dict:
    """Reads and checks a study file; raises ValueError naming the file and the problem."""
    try:
        with open(path, "rb") as f:
            doc = tomllib.load(f)
    except FileNotFoundError:
        _fail(path, "no such study file")
    except tomllib.TOMLDecodeError as e:
        _fail(path, f"TOML syntax error: {e}")
    s = doc.get("study")
    if not isinstance(s, dict) or set(doc) != {"study"}:
        _fail(path, "a study file has one [study] table (with [[study.parameter]] and [[study.output]])")
    unknown = set(s) - {"scene", "kind", "samples", "seed", "parameter", "output", "reference"}
    if unknown:
        _fail(path, f"study: unknown key {sorted(unknown)[0]}")
    if not isinstance(s.get("scene"), str):
        _fail(path, "study.scene = \"scene.toml\" is needed (relative to the study file)")
    scene = os.path.join(os.path.dirname(os.path.abspath(path)), s["scene"])
    if not os.path.isfile(scene):
        _fail(path, f"study.scene: {scene} does not exist")
    kind = s.get("kind", "grid")
    if kind not in ("grid", "list", "random"):
        _fail(path, f"study.kind: unknown {kind!r} (expected grid, list or random)")
    parameters = [_parameter_values(path, p, kind) for p in s.get("parameter", [])]
    if not parameters:
        _fail(path, "study: at least one [[study.parameter]] is needed")
    if len({p["key"] for p in parameters}) != len(parameters):
        _fail(path, "study.parameter: a key is varied twice")
    outputs = s.get("output", [])
    if not outputs:
        _fail(path, "study: at least one [[study.output]] is needed")
    try:
        runs.check_outputs(outputs)
    except ValueError as e:
        _fail(path, f"study.{e}")
    reference = s.get("reference")
    if any(o["kind"] == "error" for o in outputs) and reference is None:
        _fail(path, "study: an output of kind error needs a [study.reference] (settings of the reference run; may be empty)")
    study = {"path": path, "scene": scene, "kind": kind, "parameters": parameters, "outputs": outputs,
             "reference": reference, "samples": s.get("samples"), "seed": s.get("seed", 0)}
    study["runs"] = _combinations(study)
    return study


def _combinations(study: dict) -> list[dict]:
    params = study["parameters"]
    kind = study["kind"]
    if kind == "grid":
        return [dict(zip([p["key"] for p in params], combo)) for combo in itertools.product(*[p["values"] for p in params])]
    if kind == "list":
        lengths = {len(p["values"]) for p in params if "values" in p}
        if len(lengths) != 1:
            _fail(study["path"], "study: a list study's parameters need values lists of one length")
        n = lengths.pop()
        return [{p["key"]: p["values"][i] for p in params} for i in range(n)]
    samples = study["samples"]
    if not (isinstance(samples, int) and samples >= 1):
        _fail(study["path"], "study.samples = N (N >= 1) is needed for a random study")
    rng = np.random.default_rng(study["seed"])
    out = []
    for _ in range(samples):
        row = {}
        for p in params:
            if "values" in p:
                row[p["key"]] = p["values"][int(rng.integers(len(p["values"])))]
            elif p["scale"] == "log":
                row[p["key"]] = float(math.exp(rng.uniform(math.log(p["range"][0]), math.log(p["range"][1]))))
            else:
                row[p["key"]] = float(rng.uniform(*p["range"]))
        out.append(row)
    return out


def _columns(outputs: list[dict]) -> list[tuple[str, str, int | None]]:
    """(column, output name, index in its curve) for every value a run gives."""
    cols = []
    for o in outputs:
        if o["kind"] == "tool_force" and o.get("depths") is not None:
            cols += [(f"{o['name']}@{d:g}", o["name"], k) for k, d in enumerate(o["depths"])]
        else:
            cols.append((o["name"], o["name"], None))
    return cols


def _row_values(outputs: list[dict], result: dict, reference: dict | None) -> dict:
    values = result["values"]
    row = {}
    for col, name, k in _columns(outputs):
        o = next(o for o in outputs if o["name"] == name)
        if o["kind"] == "error":
            v = values.get(o["of"])
            ref = reference["values"].get(o["of"]) if reference else None
            row[col] = (v - ref) / ref if v is not None and ref not in (None, 0) else math.nan
        elif name in values:
            row[col] = values[name][k] if k is not None else values[name]
        else:
            row[col] = math.nan
    return row


def run_study(path: str, out: str | None = None, scheduler: str | None = None, workers: int | None = None,
              progress: bool = True):
    """Runs a study file on Dask (a local cluster of `workers` processes, or the cluster at `scheduler`) and
    returns its table (a pandas DataFrame: one row per run, its parameters, outputs, `error` and `seconds`). With
    `out`: writes out/study.csv, out/study.json (the timing) and a PNG per output against each parameter."""
    import pandas as pd

    study = load_study(path)
    if out:
        os.makedirs(out, exist_ok=True)
    outputs = [o for o in study["outputs"] if o["kind"] != "error"]
    calls = [(runs.scene_task(study["scene"], settings), outputs) for settings in study["runs"]]
    if study["reference"] is not None:
        calls.append((runs.scene_task(study["scene"], study["reference"]), outputs))
    with cluster.dask_client(scheduler, workers) as client:
        n_workers = cluster.workers_of(client)
        start = time.perf_counter()
        results = cluster.run_all(client, runs.simulate, calls, label="study", progress=progress)
        wall = time.perf_counter() - start
    reference = results.pop() if study["reference"] is not None else None
    if reference is not None and reference["error"]:
        print(f"study: the reference run failed: {reference['error']}", file=sys.stderr)
    rows = []
    for k, (settings, result) in enumerate(zip(study["runs"], results)):
        row = {"run": k, **settings, **_row_values(study["outputs"], result, reference)}
        row["error"] = result["error"]
        row["seconds"] = result["seconds"]
        rows.append(row)
    table = pd.DataFrame(rows).set_index("run")
    task_seconds = sum(r["seconds"] for r in results) + (reference["seconds"] if reference else 0)
    n_tasks = len(calls)
    timing = {"runs": len(rows), "failed": int((table["error"] != "").sum()), "workers": n_workers,
              "scheduler": scheduler or "local", "wall_s": wall, "task_s_total": task_seconds,
              "task_s_mean": task_seconds / n_tasks,
              # what a task cost beyond its simulation: the workers' time not spent simulating, per task
              "overhead_per_task_s": max(0.0, (wall * n_workers - task_seconds) / n_tasks),
              "speedup": task_seconds / wall if wall > 0 else math.nan}
    if reference is not None:
        timing["reference"] = {"settings": study["reference"], "values": reference["values"], "error": reference["error"]}
    table.attrs["timing"] = timing
    if out:
        table.to_csv(os.path.join(out, "study.csv"))
        with open(os.path.join(out, "study.json"), "w", encoding="utf-8") as f:
            json.dump(timing, f, indent=2)
        _plot(study, table, out)
    return table


def _plot(study: dict, table, out: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ok = table[table["error"] == ""]
    params = study["parameters"]
    for col, _, _ in _columns(study["outputs"]):
        fig, axes = plt.subplots(1, len(params), figsize=(4.5 * len(params), 3.6), squeeze=False)
        for ax, p in zip(axes[0], params):
            others = [q["key"] for q in params if q is not p]
            # a grid: one line per combination of the other parameters; else the runs as points
            groups = (list(ok.groupby(others if len(others) > 1 else others[0])) if others and study["kind"] == "grid"
                      else [(None, ok)])
            for label, group in groups:
                group = group.sort_values(p["key"])
                x = group[p["key"]]
                numeric = np.issubdtype(np.asarray(x).dtype, np.number)
                ax.plot(x if numeric else x.astype(str), group[col], "o-" if label is not None else "o", ms=3.5, lw=1,
                        label=None if label is None else ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                                                                  for k, v in zip(others, np.atleast_1d(label))))
            if p.get("scale") == "log":
                ax.set_xscale("log")
            if 1 < len(groups) <= 8:
                ax.legend(fontsize=7)
            ax.set_xlabel(p["key"])
            ax.set_ylabel(col)
            ax.grid(alpha=0.3)
        failed = int((table["error"] != "").sum())
        fig.suptitle(f"{col} ({len(ok)} runs" + (f", {failed} failed" if failed else "") + ")")
        fig.tight_layout()
        safe = "".join(c if c.isalnum() or c in "-_.@" else "_" for c in col)
        fig.savefig(os.path.join(out, f"{safe}.png"), dpi=110)
        plt.close(fig)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="pointhaptics study", description="Run a parameter study on Dask (docs/studies.md)")
    parser.add_argument("study", help="the study file (TOML)")
    parser.add_argument("--out", required=True, help="output folder: study.csv, study.json, a PNG per output")
    cluster.add_arguments(parser)
    a = parser.parse_args(argv)
    try:
        table = run_study(a.study, out=a.out, scheduler=a.scheduler, workers=a.workers, progress=not a.quiet)
    except (ValueError, OSError) as e:
        print(f"pointhaptics: error: {e}", file=sys.stderr)
        return 1
    t = table.attrs["timing"]
    if not a.quiet:
        print(f"study: {t['runs']} runs ({t['failed']} failed) on {t['workers']} workers in {t['wall_s']:.1f} s; "
              f"{t['task_s_mean']:.3f} s per run, {t['overhead_per_task_s'] * 1e3:.1f} ms overhead per task; {a.out}/study.csv")
    return 0 if t["failed"] == 0 else 2


if __name__ == "__main__":
    sys.exit(main())
