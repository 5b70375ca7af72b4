"""PointHaptics: meshless (MLS) deformable objects for haptic rendering, from Python.

    import pointhaptics as ph
    sim = ph.Simulation.from_scene("scenes/cantilever.toml")
    sim.run(1.0)
    print(sim.displacement[:5])       # an (n, 3) view into the simulation, in metres
"""
from ._pointhaptics import Error, Simulation, __version__  # noqa: F401

__all__ = ["Error", "Simulation", "__version__"]
