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
