"""A surface moved by a law of its own surface solution (docs/moving-surfaces.md): the level set
φ advanced in time with the normal speed V = g(u), u the first-arrival time from sources on the
surface — the coupling the paper's conclusion plans.

Each step: φ re-distanced in its band (``LevelSet(phi, redistance=True)``), the sources projected
onto the surface, the surface solve on the moved tube started warm from the previous steps
(:mod:`tubesweep.moving`), V = g(u) at the band's nodes (u is the normal extension of the surface
solution there: V is constant along the normals, which keeps φ close to a signed distance), and one
forward Euler step φ ← φ − Δt·V|∇φ| (φ_t + V|∇φ| = 0, |∇φ| by central differences) on φ itself,
or on the band's re-distanced values where |∇φ| strays beyond a factor 1.25 of 1 (a mask, or a φ far
from a distance) and at the band's edge (whose neighbours beyond it hold only a bound). First order
in time, second order in space where the surface solve is; the CFL condition Δt·max|V| ≤ cfl·Δx
(cfl ≤ 1, default 0.5) is checked at every step. Beyond the band φ is only a bound: its magnitude is lowered by Δt·max|V| per
step, so that it never overstates the distance to the moved surface and the next band holds every
node it should (work O(N^d) per step there, a few array operations).
"""

from __future__ import annotations

import dataclasses
import inspect
import warnings
from pathlib import Path
from typing import Any, Callable, List, Optional, Tuple, Union

import numpy as np
from xml.sax.saxutils import quoteattr

from ._paths import writable
from .checkpoint import write_checkpoint
from ._validate import as_grid, as_sources, real_array, real_scalar
from ._box_cut import cut_extent
from ._sources import check_on_surface
from .solution import Solution
from ._step_warnings import StepWarnings
from ._warn import user_stacklevel
from .output import export
from .surface import LevelSet, Surface
from .tube import Tube

__all__ = ["evolve", "Evolution", "EvolutionStopped"]


@dataclasses.dataclass
class Evolution:
    """The frames of :func:`evolve`: per kept step its time, φ and surface solution.

    Attributes
    ----------
    times : list of float
    phis : list of numpy.ndarray
        φ on the grid at each kept time (the band re-distanced; a bound beyond it). To solve on a
        frame again, pass it as ``ts.LevelSet(phi, redistance=True)``: beyond the band the bound
        falls towards one grid spacing, which ``ts.Tube(phi, grid)`` refuses as not a distance.
    solutions : list of Solution
        The surface solution at each kept time (on that time's surface).
    warm_starts, cold_starts : int
        Steps whose surface solve ran warm, and cold (the first, any whose warm start was refused,
        and any that started again cold when a safeguard fired: ``order2["warm"]["restarted"]``).

    Examples
    --------
    >>> import numpy as np, tubesweep as ts
    >>> grid = ts.Grid((-1, -1, -1), (1, 1, 1), (31, 31, 31))
    >>> phi = np.linalg.norm(np.stack(grid.meshgrid(), -1), axis=-1) - 0.5
    >>> ev = ts.evolve(phi, grid, [(0, 0, 0.5)], lambda u: 0.2 + 0 * u, dt=0.05, steps=2)
    >>> [round(t, 2) for t in ev.times], ev.warm_starts + ev.cold_starts
    ([0.0, 0.05, 0.1], 3)
    """

    times: List[float]
    phis: List[np.ndarray]
    solutions: List[Solution]
    warm_starts: int = 0
    cold_starts: int = 0

    def export(self, path: Union[str, Path]) -> Path:
        """Writes the frames as a ParaView time series: one ``.vtp`` per frame (the surface
        triangulated, u on it; :func:`tubesweep.export`) and the ``.pvd`` collection ``path``
        that lists them with their times.

        Parameters
        ----------
        path : str or Path
            The ``.pvd`` file; the frames go beside it as ``<stem>_0000.vtp``, ...

        Returns
        -------
        Path
            ``path``.

        Raises
        ------
        ValueError
            If ``path`` does not end in ``.pvd``.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> grid = ts.Grid((-1, -1, -1), (1, 1, 1), (31, 31, 31))
        >>> phi = np.linalg.norm(np.stack(grid.meshgrid(), -1), axis=-1) - 0.5
        >>> ev = ts.evolve(phi, grid, [(0, 0, 0.5)], lambda u: 0.2 + 0 * u, dt=0.05, steps=2)
        >>> ev.export("growth.pvd")  # doctest: +SKIP
        """
        path = Path(path)
        if path.suffix.lower() != ".pvd":
            raise ValueError(
                f"Evolution.export writes a ParaView collection: the path must end in .pvd; got {str(path)!r}"
            )
        rows = []
        for k, (t, sol) in enumerate(zip(self.times, self.solutions)):
            frame = path.with_name(f"{path.stem}_{k:04d}.vtp")
            export(sol, frame)
            # the name as an XML attribute: '&', '<' and quotes escaped
            rows.append(f'    <DataSet timestep="{t:.17g}" group="" part="0" file={quoteattr(frame.name)}/>')
        path.write_text(
            '<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
            "  <Collection>\n" + "\n".join(rows) + "\n  </Collection>\n</VTKFile>\n"
        )
        return path


class EvolutionStopped(ValueError):
    """:func:`evolve` could not go on: the surface vanished or shrank below the grid, the part
    that carries a source did, a step broke the CFL condition or the speed law's values, or a
    surface solve failed to converge, the speed law or ``progress`` raised, or a checkpoint could
    not be written. The message names the step, the time and the cause (the exception it came from
    is chained as ``__cause__``).

    Attributes
    ----------
    evolution : Evolution
        The frames computed before it stopped.
    step : int
        The step at which it stopped.
    time : float
        The time of that step.

    Examples
    --------
    A sphere of radius 0.3 shrinking at speed 1 falls below the grid at t = 0.24 (N = 31):

    >>> import warnings
    >>> import numpy as np, tubesweep as ts
    >>> grid = ts.Grid((-1, -1, -1), (1, 1, 1), (31, 31, 31))
    >>> phi = np.linalg.norm(np.stack(grid.meshgrid(), -1), axis=-1) - 0.3
    >>> try:
    ...     with warnings.catch_warnings():
    ...         warnings.simplefilter("ignore")  # the narrow gaps across its centre, on the way
    ...         ts.evolve(phi, grid, [(0, 0, 0.3)], lambda u: -1 + 0 * u, dt=0.03, steps=20)
    ... except ts.EvolutionStopped as e:
    ...     print(e.step, len(e.evolution.times), round(e.time, 2))
    8 8 0.24
    """

    def __init__(self, message: str, evolution: "Evolution", step: int, time: float) -> None:
        super().__init__(f"{message}. The frames so far are in this exception's evolution attribute")
        self.evolution = evolution
        self.step = step
        self.time = time


#: φ is advanced as it is (φ ← φ − Δt·V|∇φ|) while |∇φ| stays within this factor of 1 over the
#: band; beyond it, the band's re-distanced values take its place (re-initialisation).
GRADIENT_DRIFT = 1.25


def _advanced(arr: np.ndarray, linear: np.ndarray, signed: np.ndarray, move: np.ndarray, h: float) -> np.ndarray:
    """φ − Δt·V|∇φ| at the band's nodes (``move`` = Δt·V): from φ itself, whose samples are smooth
    where φ is, with |∇φ| by central differences; from the re-distanced values (|∇φ| = 1) where φ is
    far from a distance. Advancing the re-distanced values at every step would replace φ by the
    distances to its multilinear interpolant's zero set at each step: an O(Δx²) change that is not
    smooth at grid scale, which the next step's curvatures see as noise (V = 0 moved distances by
    0.45Δx in one step at N = 31).

    Beyond the band φ is only a bound (:func:`evolve` puts values in the band's nodes that held
    one). A node with a neighbour outside the band or the box takes its re-distanced value:
    central differences across the edge would read the bound as a distance (on a sphere moved by a
    V that varies, they strayed beyond the drift test's factor at the band's edge and sent the
    whole band to the re-distanced values from the second step on). Such nodes lie about ``outer``
    spacings from the surface."""
    shape = arr.shape
    idx = np.unravel_index(linear, shape)
    flags = np.zeros(arr.size, dtype=bool)
    flags[linear] = True
    in_band = flags.reshape(shape)
    grad2 = np.zeros(len(linear))
    interior = np.ones(len(linear), dtype=bool)
    for k in range(arr.ndim):
        lo = tuple(np.maximum(i - 1, 0) if j == k else i for j, i in enumerate(idx))
        hi = tuple(np.minimum(i + 1, shape[k] - 1) if j == k else i for j, i in enumerate(idx))
        interior &= (idx[k] > 0) & (idx[k] < shape[k] - 1) & in_band[lo] & in_band[hi]
        grad2 += ((arr[hi] - arr[lo]) / (2 * h)) ** 2
    grad = np.sqrt(grad2)
    drift = interior & ((grad < 1 / GRADIENT_DRIFT) | (grad > GRADIENT_DRIFT))
    if np.any(drift):
        return signed - move
    edge = ~interior & (move != 0)  # unmoved, a node keeps its value (V = 0 leaves φ as it was)
    out = arr.reshape(-1)[linear] - move * grad
    out[edge] = signed[edge] - move[edge]
    return out


def _warn_left_box(cut: dict) -> None:
    """The warning for a surface that grew out of the grid box during the evolution (the box held
    it at the start): a sampled φ says nothing beyond the box, so the solve itself cannot tell a
    bounded surface cut by it from one meant to go on beyond (``_box_cut.looks_bounded``)."""
    size = cut_extent(cut)
    warnings.warn(
        f"evolve: the surface grew out of the grid box (it crosses {', '.join(cut['faces'])} {size}): from then "
        "on the distances are those of the part inside the box and paths through the part outside are not found. "
        "Enlarge the box to hold the surface's whole motion with a margin of outer·Δx",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )


def _speed_values(speed: Callable[[np.ndarray], Any], u: np.ndarray, step: int) -> np.ndarray:
    try:
        raw = speed(u.copy())  # a copy: a law that writes to u leaves the solution alone
    except TypeError as e:
        if "positional argument" not in str(e):
            raise
        raise TypeError(
            f"evolve: speed is called as speed(u), with the band's values alone ({e}); a law that depends on time "
            "or on the step can read a variable of yours or count its calls (one per step, in order)"
        ) from e
    if raw is None:
        raise TypeError(
            "evolve: speed(u) returned None; it must return the normal speed V: an array like u, or a number"
        )
    if np.ma.isMaskedArray(raw) and np.ma.count_masked(raw):
        raise ValueError(
            f"evolve: at step {step} speed(u) returned a masked array with {np.ma.count_masked(raw)} masked values, "
            "whose values would be taken as speeds; fill them (V.filled(value)) or return a plain array"
        )
    a = np.asarray(raw)
    if np.iscomplexobj(a) or not (np.issubdtype(a.dtype, np.number) or a.dtype == np.bool_):
        raise TypeError(f"evolve: speed(u) must return real numbers (the normal speed V); got dtype {a.dtype}")
    v = a.astype(float)
    if v.ndim == 0:
        v = np.full(u.shape, float(v))
    if v.shape != u.shape:
        raise ValueError(
            f"evolve: speed(u) must return one normal speed per value of u (shape {u.shape}); got shape {v.shape}"
        )
    bad = ~np.isfinite(v)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"evolve: at step {step} speed(u) returned {v[i]} (NaN or inf) at {int(np.count_nonzero(bad))} band nodes, "
            f"first where u = {u[i]:.6g}; the speed law must give a finite speed for every u ≥ 0 reached on the surface "
            "(u is +inf on parts no source reaches)"
        )
    return v


def _fresh_nodes_filled(
    arr: np.ndarray, linear: np.ndarray, signed: np.ndarray, previous_band: Optional[np.ndarray]
) -> np.ndarray:
    """φ with the band's nodes that lay beyond the previous band, which hold a bound, given their
    re-distanced values ``signed`` instead (a copy: the solved tube's LevelSet keeps the array it
    was given); ``arr`` itself where there are none."""
    if previous_band is None:
        return arr
    fresh = ~np.isin(linear, previous_band)
    if not np.any(fresh):
        return arr
    arr = arr.copy()
    arr.reshape(-1)[linear[fresh]] = signed[fresh]
    return arr


def _warm_start(older: Optional[Solution], prev: Optional[Solution]) -> Any:
    """The warm start of a step's surface solve (``Tube.solve(warm=...)``) from the previous
    step's solution ``prev`` and the one before, ``older``: none at the first step; extrapolated
    from the two where both ran second order; a step that fell back to first order starts the next
    one cold and the one after from it alone. (:func:`evolve` solves a step that writes a
    checkpoint cold, and passes no ``older`` to the next: a run continued from the checkpoint, cold
    with no older step, then repeats the uninterrupted one bit for bit; warm, its first solve
    differed by 2.9 tolerances, its φ by 5e-8 after four more steps. A warm solve costs as much as
    a cold one here, docs/moving-surfaces.md.)"""
    if prev is None:
        return None
    pair = older is not None and getattr(older, "order", 1) == 2
    return (older, prev) if pair else prev


def _count_start(out: Evolution, sol: Solution) -> None:
    """Counts the step's solve as warm (its warm start used to the end) or cold."""
    info = (sol.stats.order2 or {}).get("warm")
    if info is not None and "refused" not in info and info.get("restarted") is None:
        out.warm_starts += 1
    else:
        out.cold_starts += 1


def _record(out: Evolution, step: int, t: float, arr: np.ndarray, sol: Solution, inputs: _Inputs, sources: Any) -> None:
    """A frame kept (t, φ, the solution) and, with ``inputs.checkpoint``, written there with the
    step's ``sources`` as given to its projection (and the grid, ``dt`` and ``every``, which
    :func:`~tubesweep.read_checkpoint` checks), or :class:`EvolutionStopped` when it cannot be."""
    out.times.append(t)
    out.phis.append(arr)
    out.solutions.append(sol)
    checkpoint = inputs.checkpoint
    if checkpoint is None:
        return
    try:
        write_checkpoint(checkpoint, inputs.grid, inputs.dt, inputs.every, phi=arr, t=t, step=step, sources=sources)
    except OSError as e:
        raise EvolutionStopped(
            f"evolve stopped at step {step} (t = {t:.6g}): the checkpoint {str(checkpoint)!r} could not "
            f"be written ({e})",
            out,
            step,
            t,
        ) from e


def _law(
    speed: Callable[[np.ndarray], Any],
    u: np.ndarray,
    step: int,
    t: float,
    out: Evolution,
    dt: float,
    limit: float,
) -> Tuple[np.ndarray, float]:
    """The normal speed V = speed(u) at the band's nodes and its largest magnitude, or the error
    (raised as it is at step 0, as :class:`EvolutionStopped` with the frames so far ``out``
    after): the law's own errors, its values checked (:func:`_speed_values`), and the CFL
    condition Δt·max|V| ≤ ``limit`` = cfl·Δx."""
    try:
        v = _speed_values(speed, u, step)
    except Exception as e:  # the law's own errors too: the frames so far are kept
        if step == 0:
            raise
        if isinstance(e, (ValueError, TypeError)) and str(e).startswith("evolve:"):
            raise EvolutionStopped(str(e), out, step, t) from e
        raise EvolutionStopped(
            f"evolve stopped at step {step} (t = {t:.6g}): speed(u) raised {type(e).__name__}: {e}",
            out,
            step,
            t,
        ) from e
    vmax = float(np.max(np.abs(v)))
    if dt * vmax > limit:
        message = (
            f"evolve: the CFL condition fails at step {step} (t = {t:.6g}): dt·max|V| = {dt * vmax:.4g} > "
            f"cfl·Δx = {limit:.4g} (max|V| = {vmax:.4g}); take dt ≤ {limit / vmax:.4g}"
        )
        if step == 0:
            raise ValueError(message)
        raise EvolutionStopped(message, out, step, t)
    return v, vmax


@dataclasses.dataclass
class _Inputs:
    """:func:`evolve`'s arguments, checked: the grid, φ as a C-ordered copy, the sources, and the
    time stepping (``dt``, ``steps``, ``cfl``, ``every``, ``t0``, the checkpoint's path or None)."""

    grid: Any
    arr: np.ndarray
    src: np.ndarray
    dt: float
    steps: int
    cfl: float
    every: int
    t0: float
    checkpoint: Optional[Path]


def _phi_array(phi: Any) -> Any:
    """The φ array that :func:`evolve` advances, from what the user gave: an array as it is, a
    boolean mask (True inside) as 0.5 − mask (re-distanced at the first step, as any φ far from a
    distance), a :class:`LevelSet` of an array (``LevelSet.from_mask`` too) as its array; a
    TypeError for a callable or another surface, a ValueError for a 0/1 array that is not boolean
    (a mask or a φ ≥ 0?), each saying what to pass."""
    if isinstance(phi, LevelSet) and getattr(phi, "_array", None) is not None:
        return phi._array
    if isinstance(phi, Surface) or callable(phi):
        values = (
            "surface.signed_distance(grid.node_points(np.arange(grid.size))).reshape(grid.shape)"
            if hasattr(phi, "signed_distance")
            else "phi_function(grid.node_points(np.arange(grid.size))).reshape(grid.shape), φ < 0 inside"
        )
        raise TypeError(
            f"evolve: phi must be an array of φ at the grid's nodes, which evolve advances; got {type(phi).__name__}. "
            f"Pass its values: {values} (a LevelSet of an array, a boolean mask and any array of φ are taken as they are)"
        )
    arr = np.asarray(phi)
    if arr.dtype == bool:
        return 0.5 - arr  # True inside: negative there, as φ
    if arr.size and arr.dtype.kind in "iuf":
        distinct = np.unique(arr)
        if distinct.size <= 2 and distinct[0] >= 0:  # (0 and 1, 0 and 255: a mask)
            shown = " and ".join(f"{v:g}" for v in distinct.tolist())
            raise ValueError(
                f"evolve: phi holds only the values {shown}, a mask, not a φ with a sign change: pass the mask as a "
                "boolean array (True inside, e.g. mask > 0), or φ = 0.5 − (mask > 0) (negative inside)"
            )
    return phi


def _checked_inputs(
    phi: Any,
    grid: Any,
    sources: Any,
    speed: Any,
    dt: Any,
    steps: Any,
    cfl: Any,
    every: Any,
    progress: Any,
    checkpoint: Any,
    t0: Any,
) -> _Inputs:
    """:func:`evolve`'s arguments checked in order, or the first one's error (the argument named,
    and the fix)."""
    grid = as_grid(grid)
    # a copy in C order: the caller's array is left alone, and the band's nodes are written
    # through its flat view (of a Fortran-ordered array, a copy that dropped the step's motion)
    arr = np.array(real_array(_phi_array(phi), "evolve: phi"), dtype=float, order="C")
    if arr.shape != tuple(grid.shape):
        raise ValueError(f"evolve: phi must be an array of the grid's shape {tuple(grid.shape)}; got {arr.shape}")
    unfinite = np.flatnonzero(~np.isfinite(arr.reshape(-1)))
    if unfinite.size:
        # (each step re-distances φ, LevelSet(phi, redistance=True), which reads it at every node)
        where = tuple(round(float(c), 6) for c in grid.node_points(unfinite[:1])[0])
        raise ValueError(
            f"evolve: phi is NaN or inf at {unfinite.size} of {arr.size} nodes (the first at {where}); evolve "
            "re-distances φ at every step, which reads every node. Replace them by a value of their side's sign "
            "farther from the surface than the band (e.g. np.where(np.isfinite(phi), phi, ±1))"
        )
    src = as_sources(sources, grid)
    dt = real_scalar(dt, "evolve: dt", "a positive time step")
    if not (np.isfinite(dt) and dt > 0):
        raise ValueError(f"evolve: dt must be a positive time step; got {dt!r}")
    if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or steps < 1:
        raise ValueError(f"evolve: steps must be a positive integer; got {steps!r}")
    cfl = real_scalar(cfl, "evolve: cfl", "a number in (0, 1]")
    if not 0 < cfl <= 1:
        raise ValueError(
            f"evolve: cfl must be in (0, 1] (the surface moves at most cfl grid spacings per step); got {cfl!r}"
        )
    if isinstance(every, bool) or not isinstance(every, (int, np.integer)) or every < 1:
        raise ValueError(f"evolve: every must be a positive integer; got {every!r}")
    t0 = real_scalar(t0, "evolve: t0", "the time of phi")
    if not np.isfinite(t0):
        raise ValueError(f"evolve: t0 must be a finite time; got {t0!r}")
    if checkpoint is not None and Path(checkpoint).suffix.lower() != ".npz":
        raise ValueError(
            f"evolve: checkpoint is written with numpy.savez and must end in .npz; got {str(checkpoint)!r}"
        )
    if checkpoint is not None and Path(checkpoint).is_dir():
        raise ValueError(f"evolve: checkpoint={str(checkpoint)!r} is a folder; give a file name ending in .npz")
    if checkpoint is not None:
        # a missing folder is made at the first write, as Evolution.export makes its own; one that
        # could not be (a file in the way, no permission) is refused now, before the first solve
        checkpoint = Path(checkpoint).expanduser()
        writable(checkpoint, f"evolve: checkpoint={str(checkpoint)!r}:")
    if not callable(speed):
        raise TypeError(f"evolve: speed must be a callable speed(u) -> V; got {type(speed).__name__}")
    if progress is not None and not callable(progress):
        raise TypeError(
            f"evolve: progress must be None or a callable progress(step, steps, t); got {type(progress).__name__}"
        )
    if progress is not None:
        # a progress that cannot take (step, steps, t) stopped the run after its first step's solve
        try:
            signature = inspect.signature(progress)
        except (TypeError, ValueError):  # a callable without one (some builtins): called as it is
            signature = None
        if signature is not None:
            try:
                signature.bind(1, int(steps), t0)
            except TypeError as e:
                raise TypeError(
                    f"evolve: progress is called as progress(step, steps, t), which its signature {signature} "
                    f"does not accept ({e})"
                ) from None
    return _Inputs(grid, arr, src, dt, int(steps), cfl, int(every), t0, checkpoint)


def evolve(
    phi: Any,
    grid: Any,
    sources: Any,
    speed: Callable[[np.ndarray], Any],
    *,
    dt: float,
    steps: int,
    cfl: float = 0.5,
    every: int = 1,
    progress: Optional[Callable[[int, int, float], Any]] = None,
    checkpoint: Optional[Union[str, Path]] = None,
    tol: Optional[float] = None,
    t0: float = 0.0,
) -> Evolution:
    """Moves the zero level set of ``phi`` with the normal speed ``speed(u)``, u the surface
    solution (the geodesic distance) from ``sources`` (docs/moving-surfaces.md).

    Parameters
    ----------
    phi : numpy.ndarray or LevelSet
        φ on ``grid`` (a signed distance, or any φ with a sign change: it is re-distanced), a
        boolean mask of the grid's shape (True inside), or a :class:`LevelSet` of an array
        (``LevelSet.from_mask`` too).
    grid : Grid
        The grid.
    sources : array_like
        ``(K, d)`` points on the initial surface; at each step they are projected onto the
        current surface.
    speed : callable
        ``speed(u)`` → the outward normal speed V at each value of u (an array of the band's
        values; a scalar for a constant speed). Positive V grows the surface. It takes u alone: a
        law that also depends on time or on the step can count its calls or read a variable of
        yours (one call per step, in order).
    dt : float
        The time step.
    steps : int
        The number of steps.
    cfl : float
        Δt·max|V| must stay below ``cfl``·Δx at every step (0 < cfl ≤ 1; default 0.5).
    every : int
        Keep every ``every``-th step as a frame (and the first and last).
    progress : callable, optional
        Called as ``progress(step, steps, t)`` after each step.
    checkpoint : str or Path, optional
        A ``.npz`` file rewritten at each kept frame with ``phi``, ``t``, ``step`` and
        ``sources`` (its folder made if missing, a leading ``~`` expanded; written beside it and renamed, so that an interrupted write leaves the last
        one whole), with the grid, ``dt`` and ``every``: ``c = ts.read_checkpoint(path, grid,
        dt=dt, every=every)``, then ``evolve(c.phi, grid, c.sources, speed, dt=dt, ..., t0=c.t)``
        continues from it. From a checkpoint written at a multiple of ``every`` steps, a run
        continued with the same ``dt``, ``every`` and a ``checkpoint`` repeats the uninterrupted
        one bit for bit (such a step solves cold; the sources are kept as they were before that
        step projected them); from the last step's, when ``steps`` is not such a multiple, to a
        few times the solver's tolerance.
    tol : float, optional
        The surface solves' tolerance (the default of :func:`tubesweep.solve`).
    t0 : float
        The time of ``phi`` (default 0): the frames' times start there.

    Returns
    -------
    Evolution
        The kept frames (times, φ, solutions); ``.export("run.pvd")`` writes them for ParaView.

    Raises
    ------
    ValueError
        If ``dt``, ``steps``, ``cfl``, ``every`` or the checkpoint's folder is not valid, or, at
        the first step, the speed law returns NaN or inf or the wrong shape, the CFL condition
        fails (the message gives the largest Δt allowed) or :func:`tubesweep.solve` refuses the
        surface or the sources (they must lie on it).
    EvolutionStopped
        A ``ValueError`` raised at a later step: the surface or the part that carries a source
        vanished, shrank below the grid or left its box, the speed law or the CFL condition failed,
        a surface solve did not converge, or the checkpoint could not be written. It names the step and the time, and its ``evolution`` holds the
        frames computed before.
    TypeError
        If ``phi`` is not an array (a surface or a function: pass its values at the nodes),
        ``speed`` or ``progress`` is not callable, or ``speed`` returns None or values that are not
        real numbers.

    Examples
    --------
    >>> import numpy as np, tubesweep as ts
    >>> grid = ts.Grid((-1, -1, -1), (1, 1, 1), (31, 31, 31))
    >>> phi = np.linalg.norm(np.stack(grid.meshgrid(), -1), axis=-1) - 0.5
    >>> ev = ts.evolve(phi, grid, [(0, 0, 0.5)], lambda u: 0.2 + 0 * u, dt=0.05, steps=2)
    >>> round(float(ev.solutions[-1].sources[0][2]), 2)  # the pole, at 0.5 + 2 * 0.05 * 0.2
    0.52
    """
    inputs = _checked_inputs(phi, grid, sources, speed, dt, steps, cfl, every, progress, checkpoint, t0)
    grid, arr, src, dt, steps, cfl = inputs.grid, inputs.arr, inputs.src, inputs.dt, inputs.steps, inputs.cfl
    every, t0, checkpoint = inputs.every, inputs.t0, inputs.checkpoint
    h = grid.spacing
    out = Evolution([], [], [])
    tube: Optional[Any] = None
    older: Optional[Solution] = None

    def checkpointed(step: int) -> bool:
        # a step that writes a checkpoint at a multiple of every: solved cold, the next from it alone
        return checkpoint is not None and step % every == 0

    prev: Optional[Solution] = None
    previous_band: Optional[np.ndarray] = None
    t = t0
    cut_at_start = False  # whether the grid box cut the surface at step 0 (then nothing new to say)
    said = StepWarnings()  # the steps' warnings, once per kind when the evolution ends
    try:
        for step in range(steps + 1):
            try:
                with said.step(step):
                    surf = LevelSet(arr, redistance=True)
                    tube = Tube(surf, grid) if tube is None else tube.moved(surf)
                    # onto the surface: at step 0 the caller's sources, refused as ts.solve refuses
                    # them when off it by more than the inner tube; later, carried onto the moved surface
                    dist, feet = surf.project(src, grid)
                    if step == 0:
                        check_on_surface(src, dist, tube.inner * grid.spacing)
                    # (the checkpoint keeps the sources before this projection: a continued run
                    # projects them again, onto the same surface, to the same bits)
                    unprojected, src = src, np.ascontiguousarray(feet)
                    warm = None if checkpointed(step) else _warm_start(older, prev)
                    sol = tube.solve(src, warm=warm, warm_refused="cold", tol=tol)
                    cut = sol.stats.box_cut
                    if step == 0:
                        cut_at_start = bool(cut and cut["surface_cut"])
                    elif cut and cut["surface_cut"] and not cut_at_start:
                        _warn_left_box(cut)
            except ValueError as e:
                if step == 0:
                    raise  # the caller's surface or sources, refused as by ts.solve
                raise EvolutionStopped(
                    f"evolve stopped at step {step} (t = {t:.6g}): the surface, or the part of it that carries a source, "
                    f"vanished, shrank below a few grid spacings or left the grid box: {e}",
                    out,
                    step,
                    t,
                ) from e
            if not sol.stats.converged:
                raise EvolutionStopped(
                    f"evolve stopped at step {step} (t = {t:.6g}): the surface solve did not converge (its last change "
                    f"{sol.stats.last_change:.3g}); advancing φ with its values would move the surface by a wrong law. A "
                    "finer grid, a looser tol or a smaller dt may help",
                    out,
                    step,
                    t,
                )
            linear = tube._tube.linear
            geom = tube._tube.geom
            assert geom is not None  # a Tube keeps its geometry
            signed = np.asarray(geom.signed, dtype=float)  # the band's re-distanced φ
            arr = _fresh_nodes_filled(arr, linear, signed, previous_band)
            previous_band = linear
            _count_start(out, sol)
            if step % every == 0 or step == steps:
                _record(out, step, t, arr, sol, inputs, unprojected)
            if step == steps:
                break
            v, vmax = _law(speed, sol.values, step, t, out, dt, cfl * h)
            new = np.sign(arr) * np.maximum(np.abs(arr) - dt * vmax, h)  # a bound beyond the band
            new.reshape(-1)[linear] = _advanced(arr, linear, signed, dt * v, h)
            arr = new
            older, prev = (None if checkpointed(step) else prev), sol
            t = t0 + (step + 1) * dt  # not a running sum: no rounding carried from step to step
            if progress is not None:
                try:
                    progress(step + 1, steps, t)
                except Exception as e:  # the frames so far are kept
                    raise EvolutionStopped(
                        f"evolve stopped at step {step + 1} (t = {t:.6g}): progress raised {type(e).__name__}: {e}",
                        out,
                        step + 1,
                        t,
                    ) from e
        return out
    except KeyboardInterrupt as e:
        # Ctrl-C: the frames so far ride on the interrupt, as on EvolutionStopped (they were lost)
        e.evolution = out  # type: ignore[attr-defined]
        raise
    finally:
        said.say()
