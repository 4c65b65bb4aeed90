"""tubesweep — distances and first-arrival times on implicit curves and surfaces.

Implements the fast sweeping method of T. Wong and S. Leung, *A Fast Sweeping Method for Eikonal
Equations on Implicit Surfaces*, J. Sci. Comput. (2016), with a Rust core.

Quick start::

    import numpy as np, tubesweep as ts
    grid = ts.Grid(lower=(-1, -1, -1), upper=(1, 1, 1), shape=(101, 101, 101))
    sphere = lambda p: np.linalg.norm(p, axis=1) - 0.5
    sol = ts.solve(sphere, grid, sources=[(-0.5, 0, 0)])
    sol([(0.5, 0, 0)])            # ≈ π/2 · 0.5

Main entry points: :func:`solve` (surfaces, Algorithms 2 and 3), :class:`Tube` (the same band
solved on many times: other sources, speeds, Hamiltonians; :meth:`Tube.solve_many` for many sources at once),
:func:`distance_matrix` and :func:`farthest_point_sampling` (geodesic, on all cores or a Dask cluster), :func:`travel_time` (the whole
box, Algorithm 1), :class:`Grid`, :class:`LevelSet`, :class:`ClosestPoint` (open and non-orientable surfaces,
Sect. 5.2) and the library :mod:`tubesweep.surfaces`; meshes in, results out: :func:`surfaces.from_mesh`,
:func:`triangulate`, :func:`export`, :func:`plot`.
"""

from ._native import __version__ as _core_version  # noqa: F401  (fails early without the compiled core)
from . import flows, hamiltonians
from .closest_point import ClosestPoint
from .box_solution import BoxSolution
from .euclidean import travel_time
from .checkpoint import Checkpoint, read_checkpoint
from .evolve import Evolution, EvolutionStopped, evolve
from .grid import Grid
from .output import export, plot, triangulate
from .solve import Solution, solve
from .tube import Tube
from .distances import distance_matrix, farthest_point_sampling
from .stats import SolveStats
from .surface import LevelSet, Surface
from . import data, moving, surfaces

__version__ = "0.1.0"

__all__ = [
    "BoxSolution",
    "ClosestPoint",
    "distance_matrix",
    "farthest_point_sampling",
    "Grid",
    "LevelSet",
    "Solution",
    "SolveStats",
    "Surface",
    "data",
    "evolve",
    "read_checkpoint",
    "Checkpoint",
    "Evolution",
    "EvolutionStopped",
    "export",
    "flows",
    "hamiltonians",
    "moving",
    "plot",
    "solve",
    "surfaces",
    "travel_time",
    "triangulate",
    "Tube",
    "__version__",
]
