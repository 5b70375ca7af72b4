"""PointHaptics: meshless (MLS) deformable objects for haptic rendering, from Python.

    import pointhaptics as ph
    sim = ph.Simulation.from_scene("scenes/cantilever.toml")
    sim.run(1.0)
    print(sim.displacement[:5])       # an (n, 3) view into the simulation, in metres

Studies and material identification run their simulations on Dask (docs/studies.md):

    table = ph.study("examples/cantilever_study.toml", out="study")      # a pandas DataFrame
    result = ph.fit("measured.csv", scene="scenes/indentation.toml", params=["material.young"], out="fit")
"""
from ._pointhaptics import Error, Simulation, __version__, calculix_indentation  # noqa: F401


def study(path, out=None, scheduler=None, workers=None, progress=True):
    """Run a study file (pointhaptics.studies.run_study): its table as a pandas DataFrame."""
    from .studies import run_study

    return run_study(path, out=out, scheduler=scheduler, workers=workers, progress=progress)


def fit(measured, scene, params, model=None, out=None, scheduler=None, workers=None, settings=None, progress=True):
    """Fit material parameters to a measured indentation curve (pointhaptics.identification.fit_indentation)."""
    from .identification import fit_indentation

    return fit_indentation(measured, scene, params, model=model, out=out, scheduler=scheduler, workers=workers,
                           settings=settings, progress=progress)


__all__ = ["Error", "Simulation", "__version__", "calculix_indentation", "study", "fit"]
