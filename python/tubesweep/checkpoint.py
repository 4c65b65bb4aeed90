"""The checkpoints of :func:`tubesweep.evolve` (docs/moving-surfaces.md, "Frames and
checkpoints"): written at each kept frame, and read back with the grid and time step they were
written with checked, so that a run is continued on the problem it was started on."""

from __future__ import annotations

import os
import warnings
from pathlib import Path
from typing import Any, NamedTuple, Optional, Union

import numpy as np

from ._validate import as_grid
from ._warn import user_stacklevel
from .grid import Grid

__all__ = ["Checkpoint", "read_checkpoint"]


class Checkpoint(NamedTuple):
    """What :func:`read_checkpoint` returns: ``evolve(c.phi, grid, c.sources, speed, dt=dt,
    steps=..., every=every, t0=c.t, checkpoint=path)`` continues the run.

    Attributes
    ----------
    phi : numpy.ndarray
        φ at the checkpoint's step, on the grid it was written on.
    sources : numpy.ndarray
        The sources as that step was given them, before its projection onto the surface.
    t : float
        The time of ``phi``.
    step : int
        The step, counted from the start of the run that wrote it.

    Examples
    --------
    >>> import numpy as np, tubesweep as ts
    >>> c = ts.Checkpoint(np.zeros((3, 3, 3)), np.zeros((1, 3)), 0.5, 10)
    >>> c.t, c.step
    (0.5, 10)
    """

    phi: np.ndarray
    sources: np.ndarray
    t: float
    step: int


def write_checkpoint(
    path: Path, grid: Grid, dt: float, every: int, *, phi: np.ndarray, t: float, step: int, sources: Any
) -> None:
    """``numpy.savez`` to a file beside ``path``, then renamed onto it: a write interrupted by a
    crash or a kill leaves the previous checkpoint whole. Keeps the grid, ``dt`` and ``every``
    for :func:`read_checkpoint` to check."""
    partial = path.with_name(path.name + ".partial.npz")
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez(
        partial,
        phi=phi,
        t=t,
        step=step,
        sources=sources,
        lower=np.asarray(grid.lower, float),
        upper=np.asarray(grid.upper, float),
        shape=np.asarray(grid.shape, np.int64),
        dt=dt,
        every=every,
    )
    os.replace(partial, path)


def read_checkpoint(
    path: Union[str, Path], grid: Any, *, dt: Optional[float] = None, every: Optional[int] = None
) -> Checkpoint:
    """A checkpoint of :func:`tubesweep.evolve`, checked against the run that continues it.

    Parameters
    ----------
    path : str or Path
        The ``.npz`` file that ``evolve(..., checkpoint=path)`` wrote.
    grid : Grid
        The grid the run continues on: it must be the one the checkpoint was written on (φ is an
        array of its nodes; read on another box of the same shape it would place the surface
        elsewhere, without an error).
    dt : float, optional
        The continued run's time step, checked against the checkpoint's when given: a run
        continued with the same ``dt`` and ``every`` repeats the uninterrupted one.
    every : int, optional
        The continued run's ``every``, checked likewise when given.

    Returns
    -------
    Checkpoint
        ``phi``, ``sources``, ``t`` and ``step``.

    Raises
    ------
    ValueError
        If the checkpoint was written on another grid, or with another ``dt`` or ``every``
        than those given; the message names both.

    Warns
    -----
    RuntimeWarning
        If the checkpoint holds no grid (written before checkpoints kept it): it cannot be
        checked.

    Examples
    --------
    >>> import numpy as np, tubesweep as ts
    >>> grid = ts.Grid((-1, -1, -1), (1, 1, 1), (31, 31, 31))
    >>> phi = np.linalg.norm(np.stack(grid.meshgrid(), -1), axis=-1) - 0.5
    >>> law = lambda u: 0.2 + 0 * u
    >>> ev = ts.evolve(phi, grid, [(0, 0, 0.5)], law, dt=0.05, steps=2, checkpoint="out/run.npz")
    >>> c = ts.read_checkpoint("out/run.npz", grid, dt=0.05, every=1)
    >>> rest = ts.evolve(c.phi, grid, c.sources, law, dt=0.05, steps=1, t0=c.t)
    >>> c.step, round(rest.times[-1], 2)
    (2, 0.15)
    """
    g = as_grid(grid)
    with np.load(Path(path).expanduser()) as c:
        keys = set(c.files)
        missing = {"phi", "t", "step", "sources"} - keys
        if missing:
            raise ValueError(
                f"read_checkpoint: {str(path)!r} is not a checkpoint of ts.evolve (it lacks {', '.join(sorted(missing))})"
            )
        out = Checkpoint(np.array(c["phi"]), np.array(c["sources"]), float(c["t"]), int(c["step"]))
        if not {"lower", "upper", "shape"} <= keys:
            warnings.warn(
                f"read_checkpoint: {str(path)!r} holds no grid, dt or every (written before checkpoints kept them): they "
                "cannot be checked; continue on the grid and with the dt it was written with",
                RuntimeWarning,
                stacklevel=user_stacklevel(),
            )
            return out
        lower, upper, shape = np.array(c["lower"]), np.array(c["upper"]), tuple(int(n) for n in c["shape"])
        written_dt, written_every = float(c["dt"]), int(c["every"])
    if shape != tuple(g.shape) or not (np.array_equal(lower, g.lower) and np.array_equal(upper, g.upper)):
        raise ValueError(
            f"read_checkpoint: {str(path)!r} was written on the grid from {tuple(lower.tolist())} to "
            f"{tuple(upper.tolist())} with shape {shape}, not on grid={g!r}; φ is an array of that grid's nodes. "
            f"Continue on that grid: ts.Grid({tuple(lower.tolist())}, {tuple(upper.tolist())}, {shape})"
        )
    if dt is not None and float(dt) != written_dt:
        raise ValueError(
            f"read_checkpoint: {str(path)!r} was written with dt = {written_dt!r}, not dt = {dt!r}; a run continued "
            "with another dt is another run (pass dt=None to continue it anyway)"
        )
    if every is not None and int(every) != written_every:
        raise ValueError(
            f"read_checkpoint: {str(path)!r} was written with every = {written_every}, not every = {every}; a run "
            "continued with another every solves other steps cold (pass every=None to continue it anyway)"
        )
    return out
