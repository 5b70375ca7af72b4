"""Several bodies (issue 47): sim.bodies keyed by name, with views of each body's rows and its contact force."""
import os

import numpy as np
import pointhaptics as ph

SCENES = os.path.join(os.path.dirname(__file__), "..", "..", "scenes")


def test_the_layers_are_bodies_with_views_of_their_rows():
    sim = ph.Simulation.from_scene(os.path.join(SCENES, "layers_on_table.toml"), threads=1)
    bodies = sim.bodies
    assert sorted(bodies) == ["lower", "upper"]
    lower, upper = bodies["lower"], bodies["upper"]
    assert lower["first_point"] == 0 and upper["first_point"] == lower["points"]
    assert lower["points"] + upper["points"] == sim.n_points
    assert abs(upper["mass"] - 0.06 * 0.015 * 0.06 * 1000.0) < 1e-9
    np.testing.assert_array_equal(upper["reference"], sim.reference[upper["first_point"]:])
    assert upper["reference"][:, 1].min() >= 0.015 - 1e-12  # the upper layer's rows
    sim.step()
    # a view: it follows the state as the simulation steps
    np.testing.assert_array_equal(upper["displacement"], sim.displacement[upper["first_point"]:])
    assert np.abs(upper["displacement"]).max() > 0
    force = sim.bodies["upper"]["contact_force"]
    assert force[1] > 0, "the lower layer pushes the upper up"
    assert abs(force[1] + sim.bodies["lower"]["contact_force"][1]) < 1e-9 * abs(force[1])


def test_one_object_has_no_bodies():
    sim = ph.Simulation.from_scene(os.path.join(SCENES, "block_on_table.toml"), threads=1)
    assert sim.bodies == {}


def test_a_body_at_rest_sleeps():
    # two blocks standing apart on a table, explicit: once settled, both sleep (their material forces are skipped)
    text = """
[material]
young = 1e5
poisson = 0.3
density = 1000.0
damping = 20.0
[[object]]
name = "a"
shape = "box"
size = [0.02, 0.01, 0.02]
spacing = 0.005
[[object]]
name = "b"
shape = "box"
origin = [0.03, 0.0, 0.0]
size = [0.02, 0.01, 0.02]
spacing = 0.005
[[load]]
kind = "gravity"
[[obstacle]]
name = "table"
plane = { point = [0.0, 0.0, 0.0], normal = [0.0, 1.0, 0.0] }
[solver]
kind = "explicit"
dt = 1e-3
"""
    sim = ph.Simulation.from_scene_text(text, threads=1)
    assert not sim.bodies["a"]["asleep"]
    sim.run(0.8)
    for name in ("a", "b"):
        assert sim.bodies[name]["asleep"], name
        assert sim.bodies[name]["slept_steps"] > 0, name
