"""One simulation of a study or a fit, as a worker runs it: a scene (its text, so that it travels to any
machine), settings over it, and the outputs to read from it. Nothing here holds a live object between runs:
a task is plain data in, plain data out, so Dask can send it to another process or machine and run it again
there if a worker dies.

Outputs (each a dict with `name` and `kind`):
- displacement: the displacement of the point nearest `at` ([x, y, z], reference, m); `component` x, y, z or
  norm (default norm), m;
- result: a value of the result JSON (`pointhaptics run --json`, Simulation.summary()) by its dotted `key`,
  e.g. timing.steps_per_s, solver.iterations, tool.force.1;
- tool_force: a held tool's force against its [probe] direction, N (the force the object pushes it back
  with); with `depths` ([m, ...], increasing) the tool is moved that far along the direction from its
  [probe] position and the scene solved at each in turn (a static scene: a force-depth curve), the value
  then a list with one force per depth.
"""
from __future__ import annotations

import math
import os
import time
import traceback

import numpy as np


def scene_task(scene_path: str, settings: dict | None = None) -> dict:
    """The scene of a run as a task carries it: its text, the folder its relative paths are taken from (which
    must exist where the task runs, with the files it names), and its name for messages."""
    with open(scene_path, encoding="utf-8") as f:
        text = f.read()
    return {"text": text, "base_dir": os.path.dirname(os.path.abspath(scene_path)), "name": scene_path,
            "settings": dict(settings or {})}


def _nearest_point(reference: np.ndarray, at) -> int:
    return int(np.argmin(np.linalg.norm(reference - np.asarray(at, dtype=float), axis=1)))


def _result_value(summary: dict, key: str):
    value = summary
    for part in key.split("."):
        if isinstance(value, list):
            try:
                value = value[int(part)]
            except (ValueError, IndexError):
                raise KeyError(f"result {key}: {part} is not an index of a list of {len(value)}") from None
        elif isinstance(value, dict) and part in value:
            value = value[part]
        else:
            raise KeyError(f"result {key}: no {part!r} in the result (it has {', '.join(value) if isinstance(value, dict) else 'a value'})")
    if isinstance(value, bool):
        return float(value)
    if not isinstance(value, (int, float)):
        raise KeyError(f"result {key}: not a number ({type(value).__name__})")
    return float(value)


def _tool_force(sim, depth=None) -> float:
    tool = sim.tool
    if tool is None or "direction" not in tool:
        raise ValueError("tool_force: the scene holds no tool ([probe] position = [x, y, z])")
    direction = np.asarray(tool["direction"])
    if depth is not None:
        sim.hold_tool(np.asarray(tool["start"]) + depth * direction)
        sim.step()
        tool = sim.tool
    return float(-np.dot(tool["force"], direction))


def check_outputs(outputs: list[dict]) -> None:
    """Raises ValueError naming the output whose description is wrong (before any run starts)."""
    names = set()
    for k, o in enumerate(outputs):
        name = o.get("name")
        if not name:
            raise ValueError(f"output {k}: a name is needed")
        if name in names:
            raise ValueError(f"output {name}: the name is given twice")
        names.add(name)
        kind = o.get("kind")
        if kind == "displacement":
            at = o.get("at")
            if not (isinstance(at, (list, tuple)) and len(at) == 3):
                raise ValueError(f"output {name}: a displacement needs at = [x, y, z] (m)")
            if o.get("component", "norm") not in ("x", "y", "z", "norm"):
                raise ValueError(f"output {name}: component must be x, y, z or norm")
        elif kind == "result":
            if not o.get("key"):
                raise ValueError(f"output {name}: a result needs key = \"block.key\" (e.g. timing.steps_per_s)")
        elif kind == "tool_force":
            depths = o.get("depths")
            if depths is not None:
                if not (isinstance(depths, (list, tuple)) and depths and all(isinstance(d, (int, float)) and math.isfinite(d) and d >= 0 for d in depths)):
                    raise ValueError(f"output {name}: depths must be a list of numbers >= 0 (m)")
                if list(depths) != sorted(depths):
                    raise ValueError(f"output {name}: depths must increase (each solve starts from the last)")
        elif kind == "error":
            if o.get("of") not in names:
                raise ValueError(f"output {name}: an error needs of = \"<an output named before it>\"")
        else:
            raise ValueError(f"output {name}: unknown kind {kind!r} (expected displacement, result, tool_force or error)")
    curves = [o for o in outputs if o.get("kind") == "tool_force" and o.get("depths") is not None]
    if len(curves) > 1 and any(list(c["depths"]) != list(curves[0]["depths"]) for c in curves):
        raise ValueError("outputs: tool_force outputs with depths must share them (one curve per run)")


def simulate(task: dict, outputs: list[dict], threads: int = 1) -> dict:
    """Runs one simulation and returns {"values": {name: value}, "error": "", "seconds": s, "worker": pid}.
    A failure (a bad setting, a solve that fails) is returned as its message in "error", never raised: one
    bad run of a study must not stop the others."""
    from . import Simulation  # in the worker's process

    start = time.perf_counter()
    values: dict = {}
    error = ""
    try:
        sim = Simulation.from_scene_text(task["text"], base_dir=task["base_dir"], threads=threads,
                                         settings=task.get("settings") or None, name=task.get("name", "<scene>"))
        curve = next((o for o in outputs if o["kind"] == "tool_force" and o.get("depths") is not None), None)
        if curve is not None:
            forces = [_tool_force(sim, d) for d in curve["depths"]]
        else:
            sim.run_scene()
        summary = sim.summary()
        for o in outputs:
            kind = o["kind"]
            if kind == "displacement":
                u = np.asarray(sim.displacement[_nearest_point(np.asarray(sim.reference), o["at"])])
                c = o.get("component", "norm")
                values[o["name"]] = float(np.linalg.norm(u)) if c == "norm" else float(u["xyz".index(c)])
            elif kind == "result":
                values[o["name"]] = _result_value(summary, o["key"])
            elif kind == "tool_force":
                values[o["name"]] = list(forces) if o.get("depths") is not None else _tool_force(sim)
        for v in values.values():
            if not np.all(np.isfinite(v)):
                raise ValueError("an output is not finite")
    except Exception as e:  # noqa: BLE001 - every failure of a run is its row's error
        error = f"{type(e).__name__}: {e}" if not isinstance(e, ValueError) else str(e)
        if not isinstance(e, (ValueError, KeyError, RuntimeError)):
            error += "\n" + traceback.format_exc(limit=3)
        values = {}
    return {"values": values, "error": error, "seconds": time.perf_counter() - start, "worker": os.getpid()}
