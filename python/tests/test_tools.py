"""Named tools from Python (issue 47): two jaws pinch a sample on a table and lift it off by friction, each read by
name from sim.tools as the result JSON's tools block has it."""
import os

import pointhaptics as ph

SCENES = os.environ.get("PH_SCENES", os.path.join(os.path.dirname(__file__), "..", "..", "scenes"))


def test_two_jaws_lift_the_sample_and_carry_its_weight():
    sim = ph.Simulation.from_scene(os.path.join(SCENES, "pinch_and_lift.toml"), threads=2)
    assert sorted(sim.tools) == ["left", "right"]
    assert sim.tools["left"]["contacts"] == 0  # open at the start
    sim.run(0.4)
    summary = sim.summary()
    assert summary["solver"]["converged"]
    weight = 0.02**3 * 1000.0 * 9.81
    left, right = sim.tools["left"], sim.tools["right"]
    assert left["kind"] == "capsule"
    assert abs(left["force"][1] + right["force"][1] + weight) < 0.01 * weight, (left, right)
    assert abs(left["force"][0] + right["force"][0]) < 1e-6 * abs(right["force"][0])
    assert abs(left["position"][1] - 0.0225) < 1e-12  # where its keyframes put it at the end
    assert sim.obstacles["table"]["contacts"] == 0
    assert summary["tools"]["right"]["force"] == right["force"]
