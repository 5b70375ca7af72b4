"""Tests of studies and identification on Dask (docs/studies.md): scene settings and scene text, a study's table
on a local cluster and on a real scheduler with two worker processes (the same table; a worker killed mid-study
loses no run; a failing run is reported, not fatal), and fits that recover a known material and CalculiX's."""
# Tier: long (label `long`, scripts/test --long): it starts several local Dask clusters and a scheduler with
# worker processes (about 125 s); `cli_study` runs a 64-run study on Dask through the same package in the
# default tier.
import json
import os
import pickle
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import pointhaptics as ph
from pointhaptics import runs, studies

SCENES = os.path.abspath(os.environ.get("PH_SCENES", os.path.join(os.path.dirname(__file__), "..", "..", "scenes")))
DATA = os.path.join(os.path.dirname(__file__), "data")
SMALL_STUDY = os.path.join(DATA, "cantilever_small_study.toml")


def scene(name):
    return os.path.join(SCENES, name)


def test_settings_change_the_scene_and_text_travels_instead_of_objects():
    base = ph.Simulation.from_scene(scene("cantilever_static.toml"), threads=1)
    stiffer = ph.Simulation.from_scene(scene("cantilever_static.toml"), threads=1, settings={"material.young": 2 * 1e5})
    base.run_scene()
    stiffer.run_scene()
    tip = base.reference[:, 0] > 0.15 - 1e-9
    ratio = stiffer.displacement[tip, 1].mean() / base.displacement[tip, 1].mean()
    assert 0.45 < ratio < 0.55  # twice as stiff, about half the sag (the static solve is geometrically nonlinear)
    with open(scene("cantilever_static.toml")) as f:
        text = f.read()
    again = ph.Simulation.from_scene_text(text, base_dir=SCENES, threads=1)
    again.run_scene()
    np.testing.assert_array_equal(again.displacement, base.displacement)
    with pytest.raises(ph.Error, match=r"material.young \(set to -1\): -1 is out of range"):
        ph.Simulation.from_scene(scene("cantilever_static.toml"), settings={"material.young": -1})
    # inline tables and NumPy values too
    lod = ph.Simulation.from_scene(scene("half_sphere_lod.toml"), threads=1,
                                   settings={"lod.levels": [{"distance": 4.0, "K": np.int64(7)}], "lod.k1": np.float64(1.2)})
    assert "lod" in lod.summary()
    with pytest.raises(ph.Error, match="lod.levels"):
        ph.Simulation.from_scene(scene("half_sphere_lod.toml"), settings={"lod.levels": [{"distance": 4.0, "K": 11}]})
    with pytest.raises(ph.Error, match="material.young: a value of type object is not a scene value"):
        ph.Simulation.from_scene(scene("cantilever_static.toml"), settings={"material.young": object()})
    with pytest.raises(ph.Error, match="does not travel to another process"):
        pickle.dumps(base)
    # the functions a worker runs travel by reference
    assert pickle.loads(pickle.dumps(runs.simulate)) is runs.simulate


def test_a_held_tool_is_moved_and_read_from_python():
    sim = ph.Simulation.from_scene(scene("indentation.toml"), threads=1)
    tool = sim.tool
    assert tool["kind"] == "sphere" and tool["direction"] == [0.0, -1.0, 0.0] and tool["start"] == [0.0, 0.03, 0.0]
    forces = []
    for depth in (0.0005, 0.001):
        sim.hold_tool([0.0, 0.03 - depth, 0.0])
        sim.step()
        forces.append(sim.tool["force"][1])
        assert sim.tool["position"][1] == pytest.approx(0.03 - depth)
    assert 0 < forces[0] < forces[1]  # the object pushes the tool up, harder deeper
    assert sim.tool["penetration"] < 1e-4 * 0.01 * 1.01
    no_tool = ph.Simulation.from_scene(scene("cantilever_static.toml"), threads=1)
    assert no_tool.tool is None
    with pytest.raises(ph.Error, match="holds no tool"):
        no_tool.hold_tool([0, 0, 0])


def test_a_study_gathers_its_runs_reports_a_failing_one_and_writes_its_outputs(tmp_path):
    table = ph.study(SMALL_STUDY, out=str(tmp_path), workers=2, progress=False)
    assert list(table.index) == [0, 1, 2, 3, 4]
    bad = table.loc[2]
    assert "material.young (set to -1)" in bad["error"] and np.isnan(bad["tip"])
    good = table.drop(index=2)
    assert (good["error"] == "").all() and np.all(np.isfinite(good["tip"]))
    # the stiffer, the less it sags; the run at the reference's modulus has no error against it
    assert np.all(np.diff(good["tip"].to_numpy()) > 0)
    assert good.loc[1, "tip_error"] == 0.0
    assert good.loc[0, "tip_error"] > 0.5  # half as stiff: about twice the sag
    assert (good["steps"] == 1000).all()
    t = json.load(open(tmp_path / "study.json"))
    assert t["runs"] == 5 and t["failed"] == 1 and t["workers"] == 2 and t["reference"]["error"] == ""
    assert (tmp_path / "study.csv").read_text().startswith("run,material.young,solver.duration,tip,tip_error,steps,error,seconds")
    for png in ("tip.png", "tip_error.png", "steps.png"):
        assert (tmp_path / png).stat().st_size > 1000


def test_bad_study_files_are_named(tmp_path):
    def error_of(text):
        path = tmp_path / "s.toml"
        path.write_text(text)
        with pytest.raises(ValueError) as e:
            studies.load_study(str(path))
        return str(e.value)

    head = f'[study]\nscene = "{scene("cantilever.toml")}"\n'
    param = '[[study.parameter]]\nkey = "material.young"\nvalues = [1e5]\n'
    output = '[[study.output]]\nname = "tip"\nkind = "displacement"\nat = [0.15, 0.015, 0.015]\n'
    assert "at least one [[study.parameter]]" in error_of(head + output)
    assert "at least one [[study.output]]" in error_of(head + param)
    assert "unknown kind 'strain'" in error_of(head + param + '[[study.output]]\nname = "a"\nkind = "strain"\n')
    assert "study.kind: unknown 'sobol'" in error_of(head.replace("[study]\n", '[study]\nkind = "sobol"\n') + param + output)
    assert "needs a [study.reference]" in error_of(head + param + output + '[[study.output]]\nname = "e"\nkind = "error"\nof = "tip"\n')
    assert "count = N" in error_of(head + '[[study.parameter]]\nkey = "material.young"\nrange = [1e4, 1e5]\n' + output)
    assert "does not exist" in error_of('[study]\nscene = "nowhere.toml"\n' + param + output)
    assert "TOML syntax error" in error_of("[study\n")


def _start(command, env):
    return subprocess.Popen(command, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)


@pytest.fixture
def dask_cluster(tmp_path):
    """A real Dask scheduler and two workers (one process, one thread each, no nanny: a killed worker stays
    dead), as separate processes on 127.0.0.1."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in [os.path.dirname(os.path.dirname(ph.__file__)), env.get("PYTHONPATH", "")] if p)
    scheduler_file = tmp_path / "scheduler.json"
    bin_dir = os.path.dirname(sys.executable)
    scheduler = _start([os.path.join(bin_dir, "dask-scheduler") if os.path.exists(os.path.join(bin_dir, "dask-scheduler")) else "dask-scheduler",
                        "--host", "127.0.0.1", "--port", "0", "--no-dashboard", "--scheduler-file", str(scheduler_file)], env)
    for _ in range(300):
        if scheduler_file.exists() and scheduler_file.stat().st_size > 0:
            break
        time.sleep(0.1)
    address = json.loads(scheduler_file.read_text())["address"]
    worker_command = [os.path.join(bin_dir, "dask-worker") if os.path.exists(os.path.join(bin_dir, "dask-worker")) else "dask-worker",
                      address, "--nthreads", "1", "--no-nanny", "--no-dashboard", "--host", "127.0.0.1"]
    workers = [_start(worker_command, env) for _ in range(2)]
    from distributed import Client

    with Client(address, timeout="60s") as client:
        client.wait_for_workers(2, timeout=120)
    yield address, workers
    for p in workers + [scheduler]:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGTERM)
    for p in workers + [scheduler]:
        try:
            p.wait(timeout=20)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)


def test_a_study_on_a_separate_scheduler_and_workers_gives_the_local_table(dask_cluster, tmp_path):
    address, _ = dask_cluster
    remote = ph.study(SMALL_STUDY, out=str(tmp_path), scheduler=address, progress=False)
    local = ph.study(SMALL_STUDY, workers=1, progress=False)
    columns = ["material.young", "solver.duration", "tip", "tip_error", "steps", "error"]
    assert remote[columns].equals(local[columns])
    assert remote.attrs["timing"]["workers"] == 2 and remote.attrs["timing"]["scheduler"] == address


def test_a_worker_killed_mid_study_loses_no_run(dask_cluster, tmp_path):
    address, workers = dask_cluster
    study = tmp_path / "long.toml"
    study.write_text(f'[study]\nscene = "{scene("cantilever.toml")}"\nkind = "grid"\n'
                     '[[study.parameter]]\nkey = "material.young"\nrange = [5e4, 4e5]\ncount = 16\nscale = "log"\n'
                     '[[study.parameter]]\nkey = "solver.duration"\nvalues = [4.0]\n'
                     '[[study.output]]\nname = "tip"\nkind = "displacement"\nat = [0.15, 0.015, 0.015]\ncomponent = "y"\n')
    # the study in its own process, as a user's would be: a second client in this process (the watcher below)
    # would share Dask's event loop with it, and closing one while the other gathers the killed worker's
    # rescheduled results made the study fail now and then
    out = tmp_path / "out"
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in [os.path.dirname(os.path.dirname(ph.__file__)), env.get("PYTHONPATH", "")] if p)
    runner = subprocess.Popen([sys.executable, "-c", "import sys, pointhaptics as ph; "
                               "ph.study(sys.argv[1], out=sys.argv[2], scheduler=sys.argv[3], progress=False)",
                               str(study), str(out), address], env=env)
    from distributed import Client

    # mid-study: some runs done (16 of about 0.6 s each on 2 workers), the rest to come
    with Client(address, timeout="60s") as watcher:
        def done(dask_scheduler):
            return sum(ts.state == "memory" for ts in dask_scheduler.tasks.values())

        deadline = time.monotonic() + 120
        while watcher.run_on_scheduler(done) < 2 and time.monotonic() < deadline:
            time.sleep(0.05)
    assert runner.poll() is None, "the study ended before a worker was killed"
    os.killpg(workers[0].pid, signal.SIGKILL)
    assert runner.wait(timeout=300) == 0
    assert workers[0].poll() is not None  # it is gone
    import pandas as pd

    table = pd.read_csv(out / "study.csv", keep_default_na=False)
    assert len(table) == 16 and (table["error"] == "").all() and np.all(np.isfinite(table["tip"].astype(float)))
    assert np.all(np.diff(table["tip"].to_numpy(dtype=float)) > 0)


def _measured_csv(path, depths, forces):
    np.savetxt(path, np.column_stack([depths, forces]), delimiter=",", header="depth,force", comments="")
    return str(path)


def test_a_fit_recovers_a_known_modulus_from_a_noisy_curve(tmp_path):
    truth = 1.5e5
    depths = np.linspace(0.0005, 0.003, 6)
    r = runs.simulate(runs.scene_task(scene("indentation.toml"), {"material.young": truth}),
                      [{"name": "force", "kind": "tool_force", "depths": list(depths)}])
    assert r["error"] == ""
    noisy = np.asarray(r["values"]["force"]) * (1 + 0.02 * np.random.default_rng(3).standard_normal(depths.size))
    measured = _measured_csv(tmp_path / "measured.csv", depths, noisy)
    fit = ph.fit(measured, scene("indentation.toml"), ["material.young"], out=str(tmp_path / "fit"), workers=2, progress=False)
    assert fit["converged"]
    assert fit["params"]["material.young"] == pytest.approx(truth, rel=0.03)
    low, high = fit["ci"]["material.young"]
    assert low < fit["params"]["material.young"] < high and low < truth * 1.03 and high > truth * 0.97
    assert 0 < fit["residual"] < 0.05 * np.abs(noisy).max() and fit["runs"] >= 4
    saved = json.load(open(tmp_path / "fit" / "fit.json"))
    assert saved["params"] == fit["params"] and set(saved) >= {"params", "ci", "residual", "runs"}
    assert (tmp_path / "fit" / "fit.png").stat().st_size > 1000


def test_a_fit_to_calculix_finds_its_material(tmp_path):
    # CalculiX's curve for the scene's block (a cylinder of the block's top area, 20 mm high, held at its
    # bottom) and sphere, neo-Hookean E = 1e5 Pa, nu = 0.3
    depths = np.linspace(0.0005, 0.003, 6)
    forces = ph.calculix_indentation(list(depths), sphere_radius=0.01, block_radius=0.04 / np.sqrt(np.pi), height=0.02,
                                     young=1e5, poisson=0.3, model="neo_hookean", elements_per_radius=10, threads=2)
    measured = _measured_csv(tmp_path / "calculix.csv", depths, forces)
    fit = ph.fit(measured, scene("indentation.toml"), "material.young", out=str(tmp_path / "fit"), workers=2, progress=False)
    # the point model refined to R/8 under the sphere is within 5% of CalculiX from 0.1 R to 0.3 R (docs/haptics.md)
    assert fit["params"]["material.young"] == pytest.approx(1e5, rel=0.05)
    assert fit["relative_residual"] < 0.05


def test_bad_fits_are_named(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("d,f\n0.001,1\n")
    with pytest.raises(ValueError, match="the columns depth, force"):
        ph.fit(str(bad), scene("indentation.toml"), ["material.young"], workers=1)
    good = _measured_csv(tmp_path / "m.csv", [0.001, 0.002, 0.003], [0.5, 1.5, 3.0])
    with pytest.raises(ValueError, match="material.yung has no number"):
        ph.fit(good, scene("indentation.toml"), ["material.yung"], workers=1)
    with pytest.raises(ValueError, match="scene holds no tool"):
        ph.fit(good, scene("cantilever_static.toml"), ["material.young"], workers=1, progress=False)
