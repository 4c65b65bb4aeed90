"""Input checks shared by the solvers. Every error names the argument and says how to fix it."""

from __future__ import annotations

import os
import warnings
from typing import Any, Callable, Optional

import numpy as np

from ._numbers import ArgumentTypeError, _type_name, whole_number
from .grid import Grid
from ._interpolation import interpolate_dense
from ._warn import user_stacklevel

HAMILTONIANS = ("godunov", "lxf")

#: Changes smaller than this fraction of ``tol`` do not re-activate a node's neighbours (see
#: docs/architecture.md): 20–25% fewer local updates, results within 1e-2·tol of plain sweeps.
ACTIVATION_FRACTION = 0.01

#: Godunov sweeps on surfaces (3D bands) run behind a front window ``FRONT_WINDOW·h·s̄·sqrt(H)``
#: wide (``H``: the longest grid path from a source in steps; the Rust
#: ``SolveOptions::front_window``, docs/architecture.md): the same solution to about
#: ``tol`` with 3× (N = 201) to 5× (N = 1001) fewer local updates on the sphere.
#: ``paper_sweeps=True`` switches it off.
FRONT_WINDOW = 2.0


#: The largest magnitude of a travel time, a numerical infinity, a grid coordinate or a spacing,
#: and the smallest spacing: the local updates square travel times across a cell (Lax–Friedrichs
#: squares differences of neighbouring values, which overflow beyond about 1e154) and distances
#: between coordinates (squares of 1e-200 underflow to 0), so the valid range keeps those squares,
#: divided or multiplied by a spacing, inside the float64 range.
MAX_MAGNITUDE = 1e100
MIN_SPACING = 1e-100


def as_grid(grid: Any) -> Grid:
    if not isinstance(grid, Grid):
        raise TypeError(
            f"grid must be a tubesweep.Grid, got {type(grid).__name__}; build one with ts.Grid(lower, upper, shape)"
        )
    return grid


def real_array(value: Any, name: str) -> np.ndarray:
    """``value`` as a float64 array; complex values are refused (NumPy would drop the imaginary
    part with only a ``ComplexWarning``) with a ``TypeError`` that names the argument. A masked
    array with masked entries is refused (``np.asarray`` drops the mask: a speed masked where it
    was set to 0.01 was taken as 0.01 there, silently; a review)."""
    if np.ma.isMaskedArray(value) and np.ma.count_masked(value):
        raise ValueError(
            f"{name} is a masked array with {int(np.ma.count_masked(value))} masked entries, whose values would be "
            f"taken as they are; fill them ({name.split()[0]}.filled(value)) or pass the entries to use as a plain array"
        )
    try:
        a = np.asarray(value)
    except ValueError:  # ragged nesting
        raise TypeError(f"{name} must be an array of real numbers; got {type(value).__name__}") from None
    complex_values = np.iscomplexobj(a) or (
        a.dtype == object and any(isinstance(x, (complex, np.complexfloating)) for x in a.reshape(-1))
    )
    if complex_values:
        raise TypeError(
            f"{name} must hold real numbers; got complex values (dtype {a.dtype}). Pass the real part "
            f"(x.real) if the imaginary part is zero"
        )
    try:
        return a.astype(float, copy=False)
    except (TypeError, ValueError, OverflowError):
        raise TypeError(f"{name} must be an array of real numbers; got {type(value).__name__}") from None


def real_scalar(value: Any, name: str, what: str = "a real number") -> float:
    """``value`` as a float: one real number (a NumPy scalar or 0-d array too; beyond the float
    range, ±inf). None, a bool, a string, a sequence or a complex number is a ``TypeError`` that
    says ``name`` must be ``what``."""
    if (
        value is None
        or isinstance(value, (bool, np.bool_, str, bytes))
        or np.ndim(value) != 0
        or np.iscomplexobj(value)
        or np.asarray(value).dtype == bool
    ):
        raise ArgumentTypeError(f"{name} must be {what}; got {value!r} ({_type_name(value)})")
    try:
        return float(value)
    except OverflowError:
        return float("inf") if value > 0 else float("-inf")
    except (TypeError, ValueError):
        raise ArgumentTypeError(f"{name} must be {what}; got {value!r} ({_type_name(value)})") from None


def call_on_points(fn: Callable[[np.ndarray], Any], points: np.ndarray, name: str) -> np.ndarray:
    """A user's vectorised callable (φ, closest point, speed, flow, metric) at ``points``, as a
    float array of its own. The callable gets a private copy of the points, so one that modifies
    its argument in place cannot change the solver's coordinates (or the sources' closest points
    they may be views of); what it returns is copied, so a view of its argument or an array it
    keeps and changes later cannot change the solver's values; integers become floats. ``name``
    (e.g. "cp's values") names it in the errors of :func:`real_array`."""
    out = fn(np.array(points, dtype=float, copy=True))
    return np.array(real_array(out, name), dtype=float, copy=True)


def whole_indices(value: Any, name: str) -> np.ndarray:
    """Indices (faces of a mesh): an int64 array of whole numbers. Floats with a fraction, NaN,
    bools and anything not numeric are refused (they were truncated or read as 0/1)."""
    f = np.asarray(value)
    if f.size and (f.dtype == bool or not np.issubdtype(f.dtype, np.number) or np.iscomplexobj(f)):
        raise TypeError(f"{name} must hold whole-number vertex indices; got dtype {f.dtype}")
    if f.size and (not np.all(np.isfinite(f)) or np.any(f != np.round(f))):
        raise ValueError(f"{name} must hold whole-number vertex indices")
    return f.astype(np.int64)


def _bool_valued(value: Any) -> bool:
    """Whether ``value`` (an array, or a nested sequence) holds Python or NumPy booleans only."""
    try:
        return np.asarray(value).dtype == bool
    except ValueError:  # ragged: real_array names it
        return False


def as_points(points: Any, ndim: int, name: str) -> np.ndarray:
    """Converts to a float (M, ndim) array; rejects complex values, True/False, NaN/inf and wrong
    shapes."""
    if _bool_valued(points):
        # (taken as 1.0 and 0.0 before, where Grid refuses bools)
        raise TypeError(f"{name} must hold coordinates (numbers); got True/False values")
    try:
        p = real_array(points, name)
    except TypeError as e:
        if "complex" in str(e):
            raise
        raise TypeError(f"{name} must be an array-like of shape (M, {ndim}) of numbers") from None
    if p.ndim == 1 and p.size == ndim:
        p = p.reshape(1, ndim)
    if p.size == 0 and p.ndim <= 1:
        raise ValueError(f"{name} is empty: give at least one point, as an array of shape (M, {ndim})")
    if p.ndim != 2 or p.shape[1] != ndim:
        # (whole numbers alone: indices, as a mesh's vertex or a cloud's sample, which are points there)
        index = p.ndim <= 1 and p.size > 0 and bool(np.all(p == np.round(p)))
        raise ValueError(
            f"{name} must have shape (M, {ndim}) for a {ndim}D grid; got shape {p.shape}"
            + (
                " (to start at vertex i of a mesh or sample i of a point cloud, pass its point: "
                "surface.vertices[i] or surface.points[i])"
                if index
                else ""
            )
        )
    if not np.all(np.isfinite(p)):
        bad = np.flatnonzero(~np.all(np.isfinite(p), axis=1))
        raise ValueError(f"{name} contains NaN or inf (row {bad[0]}); every coordinate must be finite")
    return np.ascontiguousarray(p)


def as_sources(sources: Any, grid: Grid) -> np.ndarray:
    s = as_points(sources, grid.ndim, "sources").copy()  # kept by the solution: not the caller's array
    if s.shape[0] == 0:
        raise ValueError("sources is empty; give at least one source point")
    inside = grid.contains(s)
    if not np.all(inside):
        i = int(np.flatnonzero(~inside)[0])
        raise ValueError(
            f"sources[{i}] = {tuple(float(x) for x in s[i])} lies outside the grid "
            f"[{tuple(float(x) for x in grid.lower)}, {tuple(float(x) for x in grid.upper)}]; move it inside or enlarge the grid"
        )
    return s


def check_hamiltonian(hamiltonian: str) -> str:
    if not isinstance(hamiltonian, str) or hamiltonian.lower() not in HAMILTONIANS:
        raise ValueError(f"hamiltonian must be 'godunov' (Eq. 3) or 'lxf' (Eq. 4); got {hamiltonian!r}")
    return hamiltonian.lower()


MAX_ITERATIONS_LIMIT = 10**9


def check_flag(value: Any, name: str, none: bool = False) -> Any:
    """``value`` when it is True or False (or None, with ``none``), else a TypeError naming
    ``name``: a truthy string such as ``'no'`` read as True (``signed='no'`` signed a mesh)."""
    if isinstance(value, (bool, np.bool_)) or (none and value is None):
        return value if value is None else bool(value)
    raise TypeError(f"{name} must be True or False{' or None' if none else ''}; got {value!r}")


def check_tolerance(tol: Optional[float], max_iterations: int) -> None:
    """Refuses a ``tol`` that is not a positive finite number (None stands for the scheme's own
    default) and a ``max_iterations`` out of range."""
    what = "a positive finite number (the sweeps stop once no value changes by more in an iteration)"
    if tol is not None:
        t = real_scalar(tol, "tol", what)
        if not (np.isfinite(t) and t > 0):
            raise ValueError(f"tol must be {what}; got {tol!r}")
    m = whole_number(max_iterations, "max_iterations", f"an integer from 1 to {MAX_ITERATIONS_LIMIT:,}")
    if not 1 <= m <= MAX_ITERATIONS_LIMIT:
        raise ValueError(
            f"max_iterations must be an integer from 1 to {MAX_ITERATIONS_LIMIT:,}; got {max_iterations!r}"
        )


#: The first-order sweeps' default ``tol`` (``tol=None``) at travel times across the grid of 1 or
#: more; below, that share of them (:func:`first_order_tol`).
FIRST_ORDER_TOL = 1e-10


def first_order_tol(tol: Optional[float], spacing: float, mean_slowness: float, cells: int) -> float:
    """``tol``, or when None the first-order sweeps' default: :data:`FIRST_ORDER_TOL` times the
    travel time across the grid's longest side (``spacing`` × ``mean_slowness`` × ``cells``), at
    most :data:`FIRST_ORDER_TOL`. An absolute 1e-10 stopped the sweeps early where travel times
    are small (a speed of 1e8 on the unit sphere: 1.9e-4 off in relative terms, ``converged=True``;
    a grid in units of 1e-9: 9.7e-4), and refused a grid in units of 1e-10 for a ``tol`` the
    caller never gave; now the result scales with the units."""
    if tol is not None:
        return tol
    return FIRST_ORDER_TOL * min(1.0, spacing * mean_slowness * cells)


def check_tolerance_scale(
    tol: float,
    spacing: float,
    mean_slowness: float,
    cells: int,
    cell_time: str = "spacing × mean slowness",
    rescale: str = "the speed",
    front_slowness: Optional[float] = None,
) -> None:
    """Refuses a ``tol`` that is not small against the travel time across one grid cell: the stopping
    test compares absolute changes with it, so a ``tol`` of that size (short travel times: a large
    speed, or a grid in small units) stops the sweeps before the front has crossed the band, with
    nodes still at the numerical infinity. ``cell_time`` says in the message how the travel time
    across a cell was found, ``rescale`` what else the user may rescale besides the grid;
    ``front_slowness``: the slowness where the fronts travel (:func:`tolerance_slowness`, which an
    obstacle does not pull up), for the ``tol`` against the travel times (default the mean)."""
    cell = spacing * mean_slowness
    scale = cell * cells  # about the travel time across the grid's longest side
    if not scale < 1e100:
        # the local updates square travel times across a cell: beyond about 1e154 they overflow
        raise ValueError(
            f"the travel times of this problem are too large to compute (about {scale:.3g} across the grid, "
            f"{cell:.3g} across one grid cell: {cell_time}); rescale the units of the grid or {rescale} so that "
            f"they are below about 1e100"
        )
    if not scale > 1.0 / MAX_MAGNITUDE:
        # their squares underflow: the Godunov update loses them (at speed 1e300 it was 15× short)
        raise ValueError(
            f"the travel times of this problem are too small to compute (about {scale:.3g} across the grid, "
            f"{cell:.3g} across one grid cell: {cell_time}); rescale the units of the grid or {rescale} so that "
            f"they are above about {1.0 / MAX_MAGNITUDE:g}"
        )
    if front_slowness is not None and front_slowness < mean_slowness:
        # (an obstacle at speed 1e-20 made the mean 1e19 and let tol=1e6 through, 13% off where
        # the travel times are 1.5; a helper's review)
        cell = spacing * front_slowness
        scale = cell * cells
        cell_time = "spacing × the slowness where the fronts travel, not the slow regions'"
    if tol >= 1e-2 * scale:
        raise ValueError(
            f"tol={tol:g} is not small against the travel times of this problem (about {scale:.3g} across the grid, "
            f"{cell:.3g} across one grid cell: {cell_time}): the sweeps would stop before the front "
            f"crosses the band. Pass a tol relative to them, e.g. tol=1e-10 * {cell:.3g} or tol=1e-3 * {cell:.3g} "
            f"(or rescale the units of the grid or {rescale})"
        )


#: ``order=2``'s default tolerances scale with the slowness where the fronts travel: the mean
#: slowness, but at most ``TOL_SLOWNESS_CAP`` times its lower quartile. A smooth speed leaves the
#: mean below that cap (a constant speed gives the same tolerance, bit for bit, as the mean); an
#: obstacle (a region or a single node far slower than the rest, which the fronts go around)
#: pulls the mean up by its slowness times its share of the nodes, and the tolerance with it: on
#: the sphere at N = 41 with the cap x > 0.3 at speed 1e-6 the sweeps stopped after one
#: iteration, 0.12 off on the circle x = 0 (docs/second-order.md, "Obstacles").
TOL_SLOWNESS_QUANTILE = 0.25
TOL_SLOWNESS_CAP = 2.0


def tolerance_slowness(slowness: Any) -> float:
    """The slowness that scales ``order=2``'s default tolerances: the mean of ``slowness`` (a
    number or one value per node), capped at ``TOL_SLOWNESS_CAP`` times its lower quartile so
    that slow outliers (obstacles) do not loosen the tolerance where the fronts travel."""
    if np.ndim(slowness) == 0:
        return float(slowness)
    s = np.asarray(slowness, dtype=float).reshape(-1)
    mean = float(np.mean(s))
    if s.size == 0:
        return mean
    # the quartile of at most about a million of them (a strided sample: no copy of a large band)
    cap = TOL_SLOWNESS_CAP * float(np.quantile(s[:: max(1, s.size // 1_000_000)], TOL_SLOWNESS_QUANTILE))
    return mean if mean <= cap else cap


def speed_at_points(speed: Any, points: np.ndarray, what: str) -> np.ndarray:
    """A speed callable's values at ``points`` (source points, their closest points), checked as
    the values at the nodes are: one per point, finite and positive."""
    vals = call_on_points(speed, points, "speed callable's values")
    if vals.shape != (points.shape[0],):
        raise ValueError(
            f"speed callable must map points of shape (M, {points.shape[1]}) to values of shape (M,); "
            f"returned shape {vals.shape} for M = {points.shape[0]} ({what})"
        )
    return checked_point_speeds(vals, points, what)


def checked_point_speeds(vals: np.ndarray, points: np.ndarray, what: str) -> np.ndarray:
    """Speeds at ``points`` (one each), refused where they are not finite and positive."""
    bad = ~(np.isfinite(vals) & (vals > 0))
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        p = tuple(float(x) for x in points[i])
        raise ValueError(
            f"speed is {vals[i]} at {p} ({what}); it must be positive and finite everywhere the solution reaches"
        )
    return vals


#: A speed array that differs by more than this share from its value at the closest point on the
#: surface over a tenth of the inner tube is warned of (:func:`speed_on_surface`).
NORMAL_SPEED_RTOL = 0.01
#: ... read at this quantile of the inner nodes: an obstacle (a region or a node far slower than
#: the rest) differs at its boundary only, which is where the fronts go around it anyway.
NORMAL_SPEED_QUANTILE = 0.9


def speed_on_surface(
    speed: Any, grid: Grid, linear: np.ndarray, phi: np.ndarray, direction: np.ndarray, inner_width: float
) -> "float | np.ndarray":
    """Speed F at the band nodes ``linear`` for a solve on a surface: a callable at the nodes'
    closest points cp(x) = x − |φ|·d (``phi`` the signed or unsigned distance, ``direction`` d the
    unit direction away from the surface, per node), an array at the nodes, a float as it is. An
    array that varies along the normals by more than :data:`NORMAL_SPEED_RTOL` across a tenth of
    the inner tube (``inner_width``, inner·Δx) is warned of with the share: the front runs along
    the tube's faster side, early by up to about that share of the travel times.

    The speed lives on the surface (the paper's |∇_Σ u| = 1/F on Σ) and is extended constantly
    along the normals, as the solution is (the corrected equation of docs/second-order.md) and as
    a flow is (``hamiltonians``). Read at the nodes, a speed that varies along the normal made the
    front run along the tube's faster side: F = exp(k(|x| − 0.5)) on the sphere of radius 0.5
    (1 on it) came out 0.6–0.7Δx early on average at N = 41–121 for k = 1 and 2.2–2.6Δx for
    k = 3, at ``order=2``, not converging (a helper's review; ``tests/test_solve.py``)."""
    if not callable(speed):
        values = speed_values(speed, grid, np.empty((len(linear), 0)), linear)
        if isinstance(values, np.ndarray):
            _warn_normal_variation(speed, values, grid, linear, phi, direction, inner_width)
        return values
    return speed_values(speed, grid, _feet(grid, linear, phi, direction), linear)


def _feet(grid: Grid, linear: np.ndarray, phi: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """The closest points x − |φ|·d of the band nodes ``linear``."""
    feet = grid.node_points(linear)
    feet -= np.abs(np.asarray(phi, dtype=float))[:, None] * np.asarray(direction, dtype=float).reshape(len(feet), -1)
    return feet


def _warn_normal_variation(
    speed: Any,
    values: np.ndarray,
    grid: Grid,
    linear: np.ndarray,
    phi: np.ndarray,
    direction: np.ndarray,
    inner_width: float,
) -> None:
    """The warning of :func:`speed_on_surface` for a speed array (``values`` at the nodes)."""
    inner = np.flatnonzero(np.abs(phi) <= inner_width)
    if inner.size == 0:
        return
    array = np.asarray(speed, dtype=float)
    feet = _feet(grid, linear[inner], phi[inner], direction[inner])
    on_surface = interpolate_dense(array, grid, feet, "linear")
    ok = np.isfinite(on_surface) & (on_surface > 0)
    if not np.any(ok):
        return
    # less what the multilinear interpolation at the foot may miss, Σ|Δ²F|/8 over the axes (the
    # array's second differences at the node): an array that varies fast along the surface only,
    # 1 + 0.5 sin(8x/|x|) on the sphere, read 3% and 1.4% at N = 41 and 61 without it (a review)
    idx = grid.unravel(linear[inner])
    shape = np.asarray(grid.shape)
    missed = np.zeros(len(inner))
    for k in range(grid.ndim):
        lo, hi = idx.copy(), idx.copy()
        lo[:, k] -= 1
        hi[:, k] += 1
        edge = (idx[:, k] == 0) | (idx[:, k] == shape[k] - 1)
        lo[edge, k], hi[edge, k] = idx[edge, k], idx[edge, k]
        missed += np.abs(array[tuple(lo.T)] + array[tuple(hi.T)] - 2.0 * array[tuple(idx.T)]) / 8.0
    off = np.maximum(np.abs(values[inner] - on_surface) - missed, 0.0)
    share = float(np.quantile(off[ok] / on_surface[ok], NORMAL_SPEED_QUANTILE))
    if share > NORMAL_SPEED_RTOL:
        warnings.warn(
            f"the speed array varies along the surface's normals: at a tenth of the inner tube's nodes it differs from its "
            f"value at the closest point on the surface by {100 * share:.2g}% or more. An array is read at the nodes, so "
            f"the front runs along the tube's faster side and arrives early, by up to about {100 * share:.2g}% of the "
            "travel times "
            "(first order in Δx, whatever the order). Pass the speed as a callable (it is evaluated at the nodes' "
            "closest points, on the surface), or make the array constant along the normals",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )


def speed_values(speed: Any, grid: Grid, points: np.ndarray, linear: Optional[np.ndarray]) -> "float | np.ndarray":
    """Speed F at the given nodes: a positive float, or an array of one value per node.

    ``speed`` may be a scalar, an array of ``grid.shape`` (indexed at ``linear``), or a vectorised
    callable ``f(points (M, d)) -> (M,)``.
    """
    if callable(speed):
        vals = call_on_points(speed, points, "speed callable's values")
        if vals.shape != (points.shape[0],):
            raise ValueError(
                f"speed callable must map points of shape (M, {grid.ndim}) to values of shape (M,); "
                f"returned shape {vals.shape} for M = {points.shape[0]}"
            )
    elif np.ndim(speed) == 0:
        f = real_scalar(speed, "speed", "a real number > 0, an array of grid.shape or a callable")
        if not np.isfinite(f) or f <= 0:
            raise ValueError(
                f"speed must be positive and finite; got {f}. The speed F(x) > 0 is the wave speed in |∇u| = 1/F"
            )
        return f
    else:
        arr = real_array(speed, "speed array")
        if arr.shape != grid.shape:
            raise ValueError(f"speed array must have the grid's shape {grid.shape}; got {arr.shape}")
        vals = arr.reshape(-1)[linear] if linear is not None else arr.reshape(-1)

    def where(i: int) -> tuple:
        if points.shape[1] == grid.ndim and len(points) > i:
            p = points[i]
        else:  # coordinates not built (speed given as an array): recover them from the index
            idx = linear[i] if linear is not None else i
            p = grid.points(grid.unravel(np.array([idx])))[0]
        return tuple(float(x) for x in p)

    bad = ~np.isfinite(vals)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise ValueError(f"speed is NaN or inf at {where(i)}; it must be finite everywhere")
    nonpos = vals <= 0
    if np.any(nonpos):
        i = int(np.flatnonzero(nonpos)[0])
        raise ValueError(
            f"speed must be positive; got {vals[i]:.6g} at {where(i)}. "
            "A zero or negative speed means the wave never arrives there"
        )
    return np.ascontiguousarray(vals)


def available_memory_bytes() -> Optional[int]:
    """Memory the process can still get: the least of the machine's available memory
    (/proc/meminfo), the address space left under the process's limit (``ulimit -v``,
    RLIMIT_AS, against its VmSize) and the memory left in its control group (cgroup v2
    ``memory.max`` or v1 ``memory.limit_in_bytes``, as in containers and batch jobs); None when
    none is known. (The machine's alone let a sphere at N = 4000 under ``ulimit -v 8000000``
    abort in an allocation instead of raising ``MemoryError``: a helper's review.)"""
    found = [v for v in (_machine_available(), _address_space_left(), _cgroup_left()) if v is not None]
    return min(found) if found else None


def _machine_available() -> Optional[int]:
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return int(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return None


def _address_space_left() -> Optional[int]:
    """RLIMIT_AS's soft limit less the process's VmSize (None without a limit, or off Linux)."""
    try:
        import resource  # (POSIX only)

        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
        if soft == resource.RLIM_INFINITY or soft < 0:
            return None
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmSize:"):
                    return max(0, int(soft) - int(line.split()[1]) * 1024)
    except (ImportError, OSError, ValueError):
        pass
    return None


def _cgroup_left() -> Optional[int]:
    """The memory left in the process's control group (v2, then v1), None without a limit."""
    for limit_file, usage_file in (
        ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
        ("/sys/fs/cgroup/memory/memory.limit_in_bytes", "/sys/fs/cgroup/memory/memory.usage_in_bytes"),
    ):
        try:
            with open(limit_file) as f:
                text = f.read().strip()
            if text == "max":
                return None
            limit = int(text)
            if limit >= 2**60:  # v1's "no limit"
                return None
            with open(usage_file) as f:
                usage = int(f.read().strip())
            return max(0, limit - usage)
        except (OSError, ValueError):
            continue
    return None


def check_memory(nbytes: float, what: str, fix: str) -> None:
    """Raises MemoryError before an allocation that would not fit in the machine's memory."""
    avail = available_memory_bytes()
    if avail is not None and nbytes > 0.9 * avail:
        raise MemoryError(
            f"{what} needs about {nbytes / 2**30:.1f} GiB but only {avail / 2**30:.1f} GiB is available; {fix}"
        )


def warn_unconverged(stats: dict, tol: float, max_iterations: int) -> None:
    if not stats["converged"]:
        edge = stats["window_edge"]
        behind = (
            f"; the sweeps' front window had reached u = {edge:.4g}: the nodes above it are not reached "
            "yet (inf), and the values just below it are not converged"
            if edge < float("inf")
            else ""
        )
        warnings.warn(
            f"the sweeps did not converge in max_iterations={max_iterations}: the largest change in the last "
            f"iteration was {stats['last_change']:.3g} (tol={tol:g}){behind}. Increase max_iterations or tol; "
            "the values returned are the last iterate",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )


def progress_callback(progress: Any) -> Optional[Callable[[int, float, int], None]]:
    if progress is None or progress is False:
        return None
    if not callable(progress):
        raise TypeError("progress must be a callable (iteration, max_change, updates) -> None, or None")
    return progress


def check_infinity(infinity: Optional[float]) -> Optional[float]:
    """The numerical infinity to use: None (derived from the band by the core), or a user value
    that must be positive and finite."""
    if infinity is None:
        return None
    what = f"a positive finite number up to {MAX_MAGNITUDE:g} (a 'numerical infinity' above every travel time)"
    v = real_scalar(infinity, "infinity", what)
    if not (np.isfinite(v) and 0 < v <= MAX_MAGNITUDE):
        raise ValueError(
            f"infinity must be {what}; got {infinity!r}. The Lax–Friedrichs update squares differences of "
            f"values (beyond about 1e154 they overflow); leave it None for a safe bound derived from the band"
        )
    return v


def check_threads(threads: int) -> int:
    n = whole_number(threads, "threads", "a non-negative integer (0 = all cores)")
    if n < 0:
        raise ValueError(f"threads must be a non-negative integer (0 = all cores); got {threads!r}")
    threads = n
    # more threads than cores gain nothing (and thousands take minutes to start); the result is the
    # same bits for any count, so a larger request runs on all cores
    return min(int(threads), os.cpu_count() or 1)
