"""Tests of the Python bindings: scenes and arrays in, NumPy views and copies out, the GIL released during
long runs, the probe, and errors as pointhaptics.Error."""
import os
import threading
import time

import numpy as np
import pytest

import pointhaptics as ph

SCENES = os.environ.get("PH_SCENES", os.path.join(os.path.dirname(__file__), "..", "..", "scenes"))


def scene(name):
    return os.path.join(SCENES, name)


def test_a_scene_runs_and_its_arrays_are_views_of_the_simulation():
    sim = ph.Simulation.from_scene(scene("cantilever_static.toml"), threads=1)
    u = sim.displacement
    assert u.shape == (sim.n_points, 3) and u.dtype == np.float64
    assert not u.flags.owndata and not u.flags.writeable  # a view, read-only
    assert np.all(u == 0)
    sim.step()  # the static solve
    # the same view now shows the solution: the tip sags (the beam is loaded downwards at x = 0.15)
    tip = sim.reference[:, 0] > 0.15 - 1e-9
    assert u[tip, 1].mean() < -0.01
    summary = sim.summary()
    assert summary["solver"]["converged"] and summary["solver"]["kind"] == "static"
    assert "points" not in summary and summary["energy"]["strain"] > 0
    np.testing.assert_allclose(sim.positions, sim.reference + u)
    assert sim.fixed.sum() == 25
    e = sim.energy()
    assert e["strain"] > 0 and e["kinetic"] == 0
    with pytest.raises(ValueError):
        u[0, 0] = 1.0  # read-only


def test_the_surface_follows_the_points():
    sim = ph.Simulation.from_scene(scene("cantilever_static.toml"), threads=1)
    triangles = sim.surface_triangles
    y = sim.surface_vertices
    assert triangles.shape[1] == 3 and triangles.min() == 0 and triangles.max() == len(y) - 1
    assert not y.flags.owndata and not y.flags.writeable  # a view
    # at rest: the box's exact boundary, [0, 0.15] x [0, 0.03] x [0, 0.03]
    np.testing.assert_allclose(y.min(axis=0), [0, 0, 0], atol=1e-15)
    np.testing.assert_allclose(y.max(axis=0), [0.15, 0.03, 0.03], atol=1e-15)
    # closed: every edge in two triangles
    edges = np.sort(np.concatenate([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]]), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert np.all(counts == 2)
    sim.step()
    # the same view has moved with the points: the tip's bottom edge sags as the lowest point does
    lowest_point = sim.positions[:, 1].min()
    assert lowest_point < -0.01
    assert abs(y[:, 1].min() - lowest_point) < 0.03 * abs(lowest_point)
    # from points: a surface reconstructed from them, closed, around them
    cloud = ph.Simulation.from_points(sim.reference, 0.0075)
    t = cloud.surface_triangles
    edges = np.sort(np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]]), axis=1)
    assert np.all(np.unique(edges, axis=0, return_counts=True)[1] == 2)
    v = cloud.surface_vertices
    assert np.all(v.min(axis=0) < sim.reference.min(axis=0) + 0.0075) and np.all(v.max(axis=0) > sim.reference.max(axis=0) - 0.0075)


def test_a_model_from_arrays_matches_forces_and_energy():
    # a 6 x 3 x 3 bar, 1 cm spacing, held at x = 0, pulled along x at the far end
    g = np.stack(np.meshgrid(np.arange(6), np.arange(3), np.arange(3), indexing="ij"), axis=-1).reshape(-1, 3) * 0.01
    fixed = g[:, 0] == 0
    forces = np.zeros_like(g)
    forces[g[:, 0] == 0.05, 0] = 0.01
    sim = ph.Simulation.from_points(g, spacing=0.01, fixed=fixed, forces=forces, young=1e5, solver="static", threads=1)
    assert sim.n_points == 54
    sim.step()
    u = sim.displacement
    assert np.all(u[fixed] == 0)
    assert u[g[:, 0] == 0.05, 0].mean() > 0  # stretched
    # at equilibrium the internal forces balance the external ones on the free points
    f = sim.forces
    np.testing.assert_allclose(f[~fixed] + forces[~fixed], 0, atol=1e-8 * np.abs(forces).max())


def test_the_material_models_and_regions_are_the_scene_files_keys():
    # the punch scene (neo-Hookean) solves; the same points with each model from arrays differ as the models do
    sim = ph.Simulation.from_scene(scene("punch.toml"), threads=1)
    sim.step()
    summary = sim.summary()
    assert summary["solver"]["converged"] and summary["solver"]["inverted"] == 0
    assert -summary["constraints"][1]["reaction"][1] > 0.5  # the punch pushes down
    g = np.stack(np.meshgrid(np.arange(6), np.arange(3), np.arange(3), indexing="ij"), axis=-1).reshape(-1, 3) * 0.01
    forces = np.zeros_like(g)
    forces[g[:, 0] == 0.05, 0] = 0.05
    stretch = {}
    for model in ("svk", "neo_hookean", "mooney_rivlin", "corotated"):
        s = ph.Simulation.from_points(g, spacing=0.01, fixed=g[:, 0] == 0, forces=forces, young=1e4, solver="static",
                                      threads=1, model=model)
        s.step()
        stretch[model] = s.displacement[g[:, 0] == 0.05, 0].mean()
    assert all(v > 0 for v in stretch.values())
    assert stretch["svk"] != stretch["neo_hookean"]
    with pytest.raises(ph.Error, match="model"):
        ph.Simulation.from_points(g, spacing=0.01, model="jelly")


def test_from_points_takes_a_prony_series():
    # a viscoelastic block under a constant pull creeps: its stretch grows toward the long-term one
    g = np.stack(np.meshgrid(*[np.arange(0, 0.051, 0.01)] * 3, indexing="ij"), -1).reshape(-1, 3)
    forces = np.zeros_like(g)
    forces[g[:, 0] == 0.05, 0] = 0.05
    sim = ph.Simulation.from_points(g, spacing=0.01, fixed=g[:, 0] == 0, forces=forces, young=1e4, solver="implicit",
                                    dt=0.01, threads=1, model="neo_hookean", damping=20.0, prony=[(0.5, 0.2)])
    tip = g[:, 0] == 0.05
    sim.run(0.3)
    early = sim.displacement[tip, 0].mean()
    sim.run(1.7)
    late = sim.displacement[tip, 0].mean()
    assert late > 1.3 * early > 0
    with pytest.raises(ph.Error, match="prony"):
        ph.Simulation.from_points(g, spacing=0.01, prony=[(0.7, 1.0), (0.4, 1.0)])  # the shares sum above 1


def test_long_runs_release_the_gil():
    sim = ph.Simulation.from_scene(scene("beam_fixed_both_ends.toml"), threads=1)
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    start = time.perf_counter()
    sim.run(10.0)  # long enough (about 0.1 s of wall time) for the other thread to tick many times
    end = time.perf_counter()
    done.set()
    t.join()
    inside = [x for x in ticks if start < x < end]
    # the other Python thread kept running while the simulation stepped
    assert end - start > 0.02 and len(inside) >= 5, (end - start, len(inside))
    assert abs(sim.time - 10.0) < 1e-9


@pytest.mark.parametrize("solver", ["explicit", "implicit", "static"])
def test_the_displacement_view_follows_every_solver(solver):
    # issue 14: the implicit and static solvers swapped buffers with the state, so the view went stale
    g = np.stack(np.meshgrid(np.arange(6), np.arange(3), np.arange(3), indexing="ij"), axis=-1).reshape(-1, 3) * 0.01
    forces = np.zeros_like(g)
    forces[g[:, 0] > 0.049, 1] = -0.01
    sim = ph.Simulation.from_points(g, spacing=0.01, fixed=g[:, 0] < 1e-9, forces=forces, damping=5.0,
                                    solver=solver, dt=2e-3, threads=1)
    u = sim.displacement
    for _ in range(3):
        sim.step()
        np.testing.assert_allclose(u, sim.positions - sim.reference, atol=1e-15)
    assert u[:, 1].min() < -1e-6


def test_calls_from_several_threads_follow_each_other():
    # issue 21: probe() in one thread while another stepped or read forces crashed the interpreter, and two
    # threads stepping one simulation gave wrong results; each object now serialises its calls
    reference = ph.Simulation.from_scene(scene("beam_probe.toml"), threads=1)
    for _ in range(40):
        reference.step()
    sim = ph.Simulation.from_scene(scene("beam_probe.toml"), threads=1)
    errors = []

    def stepper():
        try:
            for _ in range(20):
                sim.step()
        except Exception as e:  # noqa: BLE001 - reported below
            errors.append(e)

    threads = [threading.Thread(target=stepper) for _ in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    # 40 steps in all, whichever thread made them: the same state as 40 steps on one thread
    assert abs(sim.time - reference.time) < 1e-12
    np.testing.assert_array_equal(sim.displacement, reference.displacement)

    # the probe on one thread while another steps and reads
    def prober():
        try:
            sim.probe([[0, 0, 0, 0, 0], [0.2, 0, -0.03, 0, 0]], radius=0.01, duration=0.2)
        except Exception as e:  # noqa: BLE001
            errors.append(e)

    def reader():
        try:
            for _ in range(50):
                sim.step()
                assert np.all(np.isfinite(sim.forces))
                sim.energy()
                sim.summary()
        except Exception as e:  # noqa: BLE001
            errors.append(e)

    threads = [threading.Thread(target=prober), threading.Thread(target=reader)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    assert np.all(np.isfinite(sim.displacement))


def test_the_probe_pushes_and_the_log_comes_back():
    sim = ph.Simulation.from_scene(scene("beam_fixed_both_ends.toml"), threads=1)
    # press 2.5 cm down from two radii above the middle of the top face, hold
    r = sim.probe([[0, 0, 0, 0, 0], [0.5, 0, -0.025, 0, 0], [1.0, 0, -0.025, 0, 0]], radius=0.01, duration=1.0)
    log = r["log"]
    assert log.shape == (1000, 14)  # the columns of --force-log: t, x, y, z, vx, vy, vz, buttons, fx, fy, fz, tx, ty, tz
    assert r["max_contacts"] > 0 and r["max_force"] > 0.05
    assert log[-1, 9] > 0  # the object pushes the device up
    assert sim.displacement[:, 1].min() < -0.002


def test_with_levels_of_detail_the_surface_follows_the_active_points():
    sim = ph.Simulation.from_scene(scene("half_sphere_lod.toml"), threads=1)
    y = sim.surface_vertices
    y0 = np.array(y)
    # press 16 mm down from two radii above the dome's top (4 mm into it), hold
    sim.probe([[0, 0, 0, 0], [0.3, 0, -0.016, 0], [0.6, 0, -0.016, 0]], radius=0.006, duration=0.6)
    lod = sim.summary()["lod"]
    assert lod["enabled"] and lod["selected"] < sim.n_points
    top_vertex = np.argmax(y0[:, 1])
    # the point under the probe: the nearest to the dome's apex
    top_point = np.argmin(np.linalg.norm(sim.reference - [0.0, 0.05, 0.0], axis=1))
    u_top = sim.displacement[top_point, 1]
    assert u_top < -1e-3, u_top
    # the vertex on top was carried down with the dimple (the map over the full displacement: the simulated
    # points near the contact), by at least half the top point's displacement, and stays above that point
    top_now = sim.reference[top_point, 1] + u_top
    assert y[top_vertex, 1] - y0[top_vertex, 1] < 0.5 * u_top
    assert top_now < y[top_vertex, 1] < y0[top_vertex, 1]
    # far from the contact (the rim) the surface stays where it was
    rim = y0[:, 1] < 0.005
    assert np.abs(y[rim] - y0[rim]).max() < 0.1 * abs(u_top)


def test_a_stranger_can_find_their_way():
    # issue 21: docstrings with units and shapes, a repr, a version, keyframes as in scene files
    assert ph.__version__ == "0.1.0"
    doc = ph.Simulation.__doc__
    assert "SI" in doc and "one row per point" in doc
    for name in ["step", "run", "probe", "summary", "energy", "displacement", "velocity", "reference", "positions", "forces",
                 "fixed", "time", "n_points", "from_scene", "from_points"]:
        assert getattr(ph.Simulation, name).__doc__, name
    sim = ph.Simulation.from_scene(scene("beam_probe.toml"), threads=1)
    assert repr(sim).startswith("<pointhaptics.Simulation: ") and "explicit solver" in repr(sim)
    r = sim.probe([[0, 0, 0, 0], [0.2, 0, -0.02, 0]], radius=0.01, duration=0.2)  # 4 values, as in scene files
    assert r["log"].shape[1] == 14 and abs(sim.time - 0.2) < 1e-9  # probe() advances the simulation
    with pytest.raises(ph.Error, match="keyframe 1 has 3 values"):
        sim.probe([[0, 0, 0, 0], [0.2, 0, 0]], duration=0.1)
    assert sim.forces.shape == (sim.n_points, 3)


def test_bad_input_is_a_named_error():
    with pytest.raises(ph.Error, match="no-such.toml"):
        ph.Simulation.from_scene("no-such.toml")
    with pytest.raises(ph.Error, match="expected an \\(n, 3\\) array"):
        ph.Simulation.from_points(np.zeros((4, 2)), spacing=0.01)
    with pytest.raises(ph.Error, match="not finite"):
        ph.Simulation.from_points(np.array([[0, 0, 0], [np.nan, 0, 0]]), spacing=0.01)
    cube = np.stack(np.meshgrid(np.arange(3), np.arange(3), np.arange(3), indexing="ij"), axis=-1).reshape(-1, 3) * 0.01
    with pytest.raises(ph.Error, match="unknown kind"):
        ph.Simulation.from_points(cube, spacing=0.01, solver="magic")
    # issue 21: the same rules as scene files and the readers
    for kwargs, words in [({"dt": 0.0}, "dt"), ({"dt": -1e-3}, "dt"), ({"threads": -2}, "threads"),
                          ({"support_factor": 1.0}, "support_factor"), ({"support_factor": 1e6}, "support_factor")]:
        with pytest.raises(ph.Error, match=words):
            ph.Simulation.from_points(cube, spacing=0.01, **kwargs)
    with pytest.raises(ph.Error, match="no solid"):
        ph.Simulation.from_points(np.eye(3) * 0.01, spacing=0.01)
    with pytest.raises(ph.Error, match="lie on a plane"):
        ph.Simulation.from_points(cube[cube[:, 2] == 0], spacing=0.01)
    with pytest.raises(ph.Error, match="no neighbour"):
        ph.Simulation.from_points(cube * 10, spacing=0.01)
    # a divergence is an error, and the summary says it did not converge
    loads = np.zeros_like(cube)
    loads[-1] = [1e9, 0, 0]
    wild = ph.Simulation.from_points(cube, spacing=0.01, forces=loads, threads=1)
    with pytest.raises(ph.Error, match="diverged"):
        wild.run(0.1)
    summary = wild.summary()
    assert not summary["solver"]["converged"] and "diverged" in summary["solver"]["failure"], summary
    sim = ph.Simulation.from_scene(scene("beam_fixed_both_ends.toml"), threads=1)
    with pytest.raises(ph.Error, match="duration"):
        sim.run(-1)


def test_a_scripted_cut_parts_the_beam_and_the_summary_says_so():
    sim = ph.Simulation.from_scene(scene("cantilever_cut.toml"), threads=1)
    sim.run_scene()
    cut = sim.summary()["cut"]
    assert cut["pieces"] == 2 and cut["piece_points"] == [125, 400]
    assert cut["cut_pairs"] > 0 and cut["max_update_ms"] > 0
    # the free piece has fallen; the stump has not
    free = sim.reference[:, 0] > 0.034
    assert sim.displacement[free, 1].mean() < -0.05
    assert np.abs(sim.displacement[~free]).max() < 1e-4
    # the surface split along the cut: the faces of the cut close both pieces, so its volume is the beam's,
    # and no triangle spans the gap (the uncut surface's do)
    vertices, triangles, cut_faces = sim.cut_surface()
    assert cut_faces > 0 and len(vertices) > len(sim.surface_vertices)

    def volume(v, t):
        return np.einsum("ij,ij->i", v[t[:, 0]], np.cross(v[t[:, 1]], v[t[:, 2]])).sum() / 6

    def longest(v, t):
        return max(np.linalg.norm(v[t[:, k]] - v[t[:, (k + 1) % 3]], axis=1).max() for k in range(3))

    assert abs(volume(vertices, triangles) - 0.15 * 0.03 * 0.03) < 0.01 * 0.15 * 0.03 * 0.03
    assert longest(vertices, triangles) < 0.02 < longest(sim.surface_vertices, sim.surface_triangles)


def test_a_reduced_scene_runs_and_its_arrays_show_the_whole_object():
    # issue 49: [reduction] from Python: the static solve in a basis of 12 vectors, read as a full model's
    with open(scene("cantilever_static.toml")) as f:
        text = f.read()
    full = ph.Simulation.from_scene_text(text, threads=1)
    full.step()
    sim = ph.Simulation.from_scene_text(text + '\n[reduction]\nmodes = 12\ncache = "none"\n', threads=1)
    sim.step()
    tip = sim.reference[:, 0] > 0.15 - 1e-9
    reduced_tip, full_tip = sim.displacement[tip, 1].mean(), full.displacement[tip, 1].mean()
    # 0.3 N: 31% of the length; a subspace of the full model's is stiffer, by a few percent at r = 12
    assert full_tip < reduced_tip < 0.9 * full_tip, (reduced_tip, full_tip)
    np.testing.assert_allclose(sim.positions, sim.reference + sim.displacement)
    np.testing.assert_allclose(sim.displacement[sim.fixed], 0, atol=0)  # held exactly
    summary = sim.summary()
    assert summary["solver"]["converged"]
    reduction = summary["reduction"]
    assert reduction["modes"] == 12 and reduction["derivatives"] > 0 and reduction["first_frequency_hz"] > 0
    assert not reduction["from_cache"] and reduction["cache_file"] == ""
    assert "reduction" not in full.summary()
