#!/usr/bin/env python3
"""The seed's cantilever from Python: load the scene, solve, read the displacements as a NumPy view,
then poke the beam fixed at both ends with a probe and look at the force felt.

    PYTHONPATH=build/release/python /usr/bin/python3 examples/python_cantilever.py
"""
import os

import numpy as np

import pointhaptics as ph

scenes = os.path.join(os.path.dirname(__file__), "..", "scenes")

sim = ph.Simulation.from_scene(os.path.join(scenes, "cantilever_static.toml"))
sim.step()  # a static scene: one step is the equilibrium
u = sim.displacement  # (n, 3) view into the simulation, metres
tip = sim.reference[:, 0] > 0.15 - 1e-9
print(f"{sim.n_points} points; mean tip deflection {-1e3 * u[tip, 1].mean():.2f} mm; {sim.summary()['solver']['iterations']} Newton iterations")

beam = ph.Simulation.from_scene(os.path.join(scenes, "beam_fixed_both_ends.toml"))
result = beam.probe([[0, 0, 0, 0, 0], [0.5, 0, -0.025, 0, 0], [1.0, 0, -0.025, 0, 0]], radius=0.01, duration=1.0)
force = np.linalg.norm(result["log"][:, 4:7], axis=1)
print(f"probe: {result['ticks']} haptic ticks, largest force {force.max():.3f} N, {result['max_contacts']} points touched")
