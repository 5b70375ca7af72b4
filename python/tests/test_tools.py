"""Named tools from Python (issue 47): two jaws pinch a sample on a table and lift it off by friction, each read by
name from sim.tools as the result JSON's tools block has it; two hands on two devices, each with its own force."""
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


TWO_HANDS = """
[material]
young = 1e5
poisson = 0.3
density = 1000.0
damping = 20.0
[[object]]
name = "left"
shape = "box"
size = [0.04, 0.02, 0.04]
spacing = 0.005
[[object]]
name = "right"
shape = "box"
origin = [0.06, 0.0, 0.0]
size = [0.04, 0.02, 0.04]
spacing = 0.005
[[fixed]]
object = "left"
box = { min = [-1.0, -1.0, -1.0], max = [1.0, 0.001, 1.0] }
[[fixed]]
object = "right"
box = { min = [-1.0, -1.0, -1.0], max = [1.0, 0.001, 1.0] }
[solver]
kind = "explicit"
dt = 1e-3
duration = 0.4
[[device]]
name = "left_hand"
[[device]]
name = "right_hand"
[[tool]]
name = "a"
radius = 0.005
device = "left_hand"
origin = [0.02, 0.03, 0.02]
keyframes = [[0.0, 0.0, 0.0, 0.0], [0.3, 0.0, -0.016, 0.0], [0.4, 0.0, -0.016, 0.0]]
[[tool]]
name = "b"
radius = 0.005
device = "right_hand"
origin = [0.08, 0.03, 0.02]
keyframes = [[0.0, 0.0, 0.0, 0.0], [0.3, 0.0, -0.008, 0.0], [0.4, 0.0, -0.008, 0.0]]
"""


def test_two_hands_each_feel_their_own_block(tmp_path):
    scene = tmp_path / "two_hands.toml"
    scene.write_text(TWO_HANDS)
    sim = ph.Simulation.from_scene(str(scene), threads=2)
    sim.run_scene()
    a, b = sim.tools["a"], sim.tools["b"]
    assert a["haptic"]["ticks"] == 400 and b["haptic"]["ticks"] == 400, (a, b)
    assert a["force"][1] > 0.2 and b["force"][1] > 0.05, (a, b)
    assert a["force"][1] > b["force"][1], "a presses twice as deep as b"

