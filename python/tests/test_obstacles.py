"""Obstacles from Python (issue 47): a block resting on a table by contact and friction alone, its weight carried
by the table, read by name from sim.obstacles."""
import os

import pointhaptics as ph

SCENES = os.environ.get("PH_SCENES", os.path.join(os.path.dirname(__file__), "..", "..", "scenes"))


def test_a_block_resting_on_a_table_is_carried_by_it():
    sim = ph.Simulation.from_scene(os.path.join(SCENES, "block_on_table.toml"), threads=1)
    assert list(sim.obstacles) == ["table"]
    sim.run(0.0)
    assert sim.summary()["solver"]["converged"]
    table = sim.obstacles["table"]
    weight = 0.04 * 0.02 * 0.04 * 1000.0 * 9.81
    assert table["kind"] == "plane"
    assert abs(table["force"][1] + weight) < 0.005 * weight, table
    assert abs(table["force"][0]) < 1e-3 * weight and abs(table["force"][2]) < 1e-3 * weight, table
    assert table["penetration"] < 0.01 * 0.005
    assert sim.summary()["obstacles"]["table"]["force"] == table["force"]
