"""Material identification from an indentation curve (docs/studies.md): the material parameters of a scene are
fitted by least squares (SciPy) until its simulated force-depth curve matches a measured one. Every simulation
is a task on Dask (pointhaptics.cluster): at each iterate the curve and its finite-difference neighbours (one per
parameter) run in parallel.

    pointhaptics fit measured.csv --scene indent.toml --params material.young,material.poisson \\
        [--model neo_hookean] --out DIR

The CSV has columns depth, force (m, N). The scene holds a tool at a static [probe] position, the tool at zero
depth, and [probe] direction (default [0, -1, 0]) is the direction it presses in; the simulated force is the tool
force's component against that direction. DIR/fit.json holds params (name: value), ci (name: [low, high], 95%),
residual (the RMS of simulated minus measured force, N), runs (simulations), and DIR/fit.png the curves.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
import tomllib

import numpy as np

from . import cluster, runs

# the simulated curve's depths: the measured ones when there are at most this many, else this many evenly
# spread over them (then interpolated, monotone cubic), as each depth is one equilibrium solve
MAX_SIMULATED_DEPTHS = 12
# finite-difference step of the Jacobian, in the fitted variable (log of a positive parameter: 0.1%; a
# Poisson's ratio itself: 0.001)
FD_STEP = 1e-3


def read_measured(path: str) -> tuple[np.ndarray, np.ndarray]:
    """depth, force from a CSV with those columns (m, N); raises ValueError naming the file and the problem."""
    import pandas as pd

    try:
        table = pd.read_csv(path)
    except FileNotFoundError:
        raise ValueError(f"{path}: no such file") from None
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as e:
        raise ValueError(f"{path}: not a CSV file ({e})") from None
    table.columns = [str(c).strip() for c in table.columns]
    missing = [c for c in ("depth", "force") if c not in table.columns]
    if missing:
        raise ValueError(f"{path}: the columns depth, force (m, N) are needed; {', '.join(missing)} missing "
                         f"(it has {', '.join(table.columns)})")
    try:
        depth = table["depth"].to_numpy(dtype=float)
        force = table["force"].to_numpy(dtype=float)
    except ValueError:
        raise ValueError(f"{path}: depth and force must be numbers") from None
    if not (np.all(np.isfinite(depth)) and np.all(np.isfinite(force))):
        raise ValueError(f"{path}: a depth or force is not a finite number")
    keep = depth > 0  # zero depth carries no information (zero force by definition)
    depth, force = depth[keep], force[keep]
    if len(depth) < 2:
        raise ValueError(f"{path}: at least 2 rows with depth > 0 are needed")
    order = np.argsort(depth)
    return depth[order], force[order]


def _scene_value(scene_path: str, key: str, settings: dict):
    if key in settings:
        return settings[key]
    with open(scene_path, "rb") as f:
        value = tomllib.load(f)
    for part in key.split("."):
        if not isinstance(value, dict) or part not in value:
            return None
        value = value[part]
    return value


class _Parameter:
    """A fitted parameter in the variable the optimiser sees: its logarithm (positive parameters, whose scale
    is unknown) or itself (a Poisson's ratio, bounded to (-1, 0.5))."""

    def __init__(self, key: str, start: float):
        self.key = key
        self.log = not key.endswith("poisson")
        if self.log and not start > 0:
            raise ValueError(f"{key}: its starting value {start} must be > 0 (it is fitted on a log scale)")
        self.x0 = math.log(start) if self.log else float(start)
        self.bounds = (-math.inf, math.inf) if self.log else (-0.99, 0.499)
        if not self.log and not self.bounds[0] < start < self.bounds[1]:
            raise ValueError(f"{key}: its starting value {start} must lie in (-0.99, 0.499)")

    def value(self, x: float) -> float:
        return math.exp(x) if self.log else x


def fit_indentation(measured, scene: str, params, model: str | None = None, out: str | None = None,
                    scheduler: str | None = None, workers: int | None = None, settings: dict | None = None,
                    start: dict | None = None, progress: bool = True) -> dict:
    """Fits `params` (scene keys, e.g. ["material.young", "material.poisson"]) so that the scene's simulated
    indentation curve matches `measured` (a CSV path, or (depth, force) arrays in m and N). `model` sets
    material.model; `settings` other keys; `start` starting values (default: the scene's). Returns the fit as
    fit.json holds it; with `out`, writes out/fit.json, out/fit.csv and out/fit.png."""
    from scipy import optimize, stats
    from scipy.interpolate import PchipInterpolator

    if isinstance(params, str):
        params = [p.strip() for p in params.split(",") if p.strip()]
    if not params:
        raise ValueError("fit: --params names the scene keys to fit (e.g. material.young,material.poisson)")
    if len(set(params)) != len(params):
        raise ValueError("fit: a parameter is named twice")
    source = measured if isinstance(measured, str) else "the measured curve"
    depth, force = read_measured(measured) if isinstance(measured, str) else (np.asarray(measured[0], float), np.asarray(measured[1], float))
    if len(depth) <= len(params):
        raise ValueError(f"fit: {source} has {len(depth)} points for {len(params)} parameters; more points than parameters are needed")
    if not os.path.isfile(scene):
        raise ValueError(f"fit: --scene {scene}: no such file")
    base = dict(settings or {})
    if model:
        base["material.model"] = model
    fitted = []
    for key in params:
        s = (start or {}).get(key, _scene_value(scene, key, base))
        if not isinstance(s, (int, float)) or isinstance(s, bool):
            raise ValueError(f"fit: {key} has no number in {scene} to start from; set it there, or give a start value")
        fitted.append(_Parameter(key, float(s)))
    if depth.size <= MAX_SIMULATED_DEPTHS:
        simulated_depths = depth.copy()
    else:
        simulated_depths = np.linspace(depth[0], depth[-1], MAX_SIMULATED_DEPTHS)
    output = [{"name": "force", "kind": "tool_force", "depths": [float(d) for d in simulated_depths]}]

    task = runs.scene_task(scene, base)
    cache: dict = {}
    n_runs = 0

    def settings_of(x) -> dict:
        return {**base, **{p.key: p.value(v) for p, v in zip(fitted, x)}}

    def curve(result) -> np.ndarray:
        if result["error"]:
            raise ValueError(f"fit: a simulation failed: {result['error']}")
        f = np.asarray(result["values"]["force"])
        return f if np.array_equal(simulated_depths, depth) else PchipInterpolator(simulated_depths, f)(depth)

    t0 = time.perf_counter()
    with cluster.dask_client(scheduler, workers) as client:
        def evaluate(x) -> None:
            """The residual at x and the Jacobian's neighbours, in parallel."""
            nonlocal n_runs
            key = tuple(np.round(x, 14))
            if key in cache:
                return
            points = [np.array(x, float)]
            for i, p in enumerate(fitted):
                step = FD_STEP if x[i] + FD_STEP <= p.bounds[1] else -FD_STEP
                xi = np.array(x, float)
                xi[i] += step
                points.append(xi)
            calls = [({**task, "settings": settings_of(xp)}, output) for xp in points]
            results = cluster.run_all(client, runs.simulate, calls, progress=False)
            n_runs += len(calls)
            r0 = curve(results[0]) - force
            J = np.column_stack([(curve(r) - force - r0) / (xp[i] - x[i]) for i, (r, xp) in enumerate(zip(results[1:], points[1:]))])
            cache[key] = (r0, J)
            if progress:
                shown = ", ".join(f"{p.key} = {p.value(v):.6g}" for p, v in zip(fitted, x))
                print(f"fit: {shown}: residual {math.sqrt(np.mean(r0 ** 2)):.4g} N ({n_runs} runs, "
                      f"{time.perf_counter() - t0:.1f} s)", file=sys.stderr, flush=True)

        def residual(x):
            evaluate(x)
            return cache[tuple(np.round(x, 14))][0]

        def jacobian(x):
            evaluate(x)
            return cache[tuple(np.round(x, 14))][1]

        x0 = np.array([p.x0 for p in fitted])
        lower = np.array([p.bounds[0] for p in fitted])
        upper = np.array([p.bounds[1] for p in fitted])
        solution = optimize.least_squares(residual, x0, jac=jacobian, bounds=(lower, upper), method="trf",
                                          x_scale=1.0, xtol=1e-6, ftol=1e-8, gtol=1e-8, max_nfev=60)
        r, J = cache[tuple(np.round(solution.x, 14))]
        n_workers = cluster.workers_of(client)
    m, n = len(depth), len(fitted)
    rms = math.sqrt(float(np.mean(r ** 2)))
    # 95% confidence intervals from the Jacobian at the solution: cov = s^2 (J^T J)^-1, s^2 = |r|^2 / (m - n),
    # Student's t with m - n degrees of freedom, in the fitted variable (so a log parameter's is asymmetric)
    ci = {}
    conditioning = float(np.linalg.cond(J))
    try:
        covariance = float(r @ r) / (m - n) * np.linalg.inv(J.T @ J)
        half = stats.t.ppf(0.975, m - n) * np.sqrt(np.maximum(np.diag(covariance), 0))
    except np.linalg.LinAlgError:
        half = np.full(n, math.inf)
    for p, x, h in zip(fitted, solution.x, half):
        low, high = (p.value(x - h), p.value(x + h)) if math.isfinite(h) else (-math.inf, math.inf)
        ci[p.key] = [low, high]
    fitted_curve = r + force
    result = {
        "params": {p.key: p.value(x) for p, x in zip(fitted, solution.x)},
        "ci": ci,
        "residual": rms,
        "relative_residual": rms / float(np.sqrt(np.mean(force ** 2))),
        "runs": n_runs,
        "start": {p.key: p.value(p.x0) for p in fitted},
        "model": model or _scene_value(scene, "material.model", base) or "svk",
        "scene": scene,
        "settings": base,
        "measured": source,
        "points": m,
        "simulated_depths": [float(d) for d in simulated_depths],
        "converged": bool(solution.success),
        "message": solution.message,
        "iterations": int(solution.nfev),
        "jacobian_condition": conditioning,
        "workers": n_workers,
        "wall_s": time.perf_counter() - t0,
    }
    if out:
        os.makedirs(out, exist_ok=True)
        with open(os.path.join(out, "fit.json"), "w", encoding="utf-8") as f:
            json.dump(result, f, indent=2)
        with open(os.path.join(out, "fit.csv"), "w", encoding="utf-8") as f:
            f.write("depth_m,measured_n,fitted_n\n")
            for d, fm, fs in zip(depth, force, fitted_curve):
                f.write(f"{d:.9g},{fm:.9g},{fs:.9g}\n")
        _plot(depth, force, fitted_curve, result, os.path.join(out, "fit.png"))
    return result


def _plot(depth, force, fitted, result, path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.5, 4))
    ax.plot(depth * 1e3, force, "o", ms=4, label="measured")
    label = ", ".join(f"{k.split('.')[-1]} = {v:.4g}" for k, v in result["params"].items())
    ax.plot(depth * 1e3, fitted, "-", label=f"fitted: {label}")
    ax.set_xlabel("depth (mm)")
    ax.set_ylabel("force (N)")
    ax.set_title(f"{result['model']}: RMS residual {result['residual']:.3g} N ({100 * result['relative_residual']:.1f}%)", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="pointhaptics fit",
                                     description="Fit material parameters to a measured indentation curve (docs/studies.md)")
    parser.add_argument("measured", help="CSV with columns depth, force (m, N)")
    parser.add_argument("--scene", required=True, help="the indentation scene: a held tool at [probe] position, static solver")
    parser.add_argument("--params", required=True, help="scene keys to fit, comma-separated (material.young,material.poisson)")
    parser.add_argument("--model", help="material.model to fit (svk, neo_hookean, mooney_rivlin, corotated)")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="other scene keys (repeatable)")
    parser.add_argument("--out", required=True, help="output folder: fit.json, fit.csv, fit.png")
    cluster.add_arguments(parser)
    a = parser.parse_args(argv)
    try:
        settings = {}
        for s in a.set:
            key, eq, value = s.partition("=")
            if not eq or not key:
                raise ValueError(f"--set {s}: expected KEY=VALUE")
            try:
                settings[key] = json.loads(value)
            except json.JSONDecodeError:
                settings[key] = value
        result = fit_indentation(a.measured, a.scene, a.params, model=a.model, out=a.out, scheduler=a.scheduler,
                                 workers=a.workers, settings=settings, progress=not a.quiet)
    except (ValueError, OSError) as e:
        print(f"pointhaptics: error: {e}", file=sys.stderr)
        return 1
    if not a.quiet:
        for k, v in result["params"].items():
            low, high = result["ci"][k]
            print(f"fit: {k} = {v:.6g} (95%: {low:.6g} .. {high:.6g})")
        print(f"fit: RMS residual {result['residual']:.4g} N ({100 * result['relative_residual']:.2f}%), {result['runs']} runs, "
              f"{result['wall_s']:.1f} s; {a.out}/fit.json")
    return 0 if result["converged"] else 2


if __name__ == "__main__":
    sys.exit(main())
