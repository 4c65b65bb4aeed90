"""Implicit surfaces as the solver sees them.

A surface hands the solver, for the grid nodes within a half-width of it (the band):

* an unsigned distance-like value (``|φ|`` for a level set, ``|x − cp(x)|`` for a closest-point
  surface) that decides inner tube versus extension layer;
* the outward extension direction ``sgn(φ) n`` (paper Eq. (8)), or ``(x − cp(x)) / |x − cp(x)|``
  for a closest-point surface (Sect. 5.2);
* closest points on the surface, used to initialise point sources.

:class:`LevelSet` is defined here; ``ClosestPoint`` and the library surfaces of
``tubesweep.surfaces`` subclass :class:`Surface` the same way.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any, Callable, Iterator, List, Optional, Tuple, Union

import numpy as np

from .grid import Grid
from ._validate import call_on_points, real_array, real_scalar
from ._warn import user_stacklevel

__all__ = ["Surface", "LevelSet", "BandGeometry", "as_surface"]

#: Evaluate user callables on at most this many points at a time.
EVAL_CHUNK = 1 << 18

# |∇φ| outside [GRAD_ERROR_LOW, GRAD_ERROR_HIGH] on the inner tube is an error, outside
# [GRAD_WARN_LOW, GRAD_WARN_HIGH] a warning: the method needs φ close to a signed distance.
GRAD_ERROR_LOW, GRAD_ERROR_HIGH = 1.0 / 3.0, 3.0
GRAD_WARN_LOW, GRAD_WARN_HIGH = 0.6, 1.8

#: A band node whose central-difference |∇φ| is below this fraction of the median over the band
#: (sampled) and of the largest among its neighbours straddles a kink of φ where the gradient turns by more than about 140°
#: (|n₁ + n₂|/2 < 0.35 for unit gradients): the ridge between two parts of the surface that face
#: each other. A convex edge of 90° gives 0.71, and the double torus's creases stay above it from
#: N = 61 on (at 0.5 they counted as gaps up to N = 81); two spheres min(d₁, d₂) 4.5–5.5 spacings
#: apart were all found with it, one in 8 missed at 0.25.
KINK_FRACTION = 0.35


def band_neighbours(
    grid: Grid, band: Any, linear: np.ndarray, nodes: np.ndarray
) -> Iterator[Tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """For each axis and side in turn, the neighbours of the band nodes ``nodes`` (band positions;
    ``linear`` the band's linear indices): their grid indices ``(M, d)``, whether each lies in the
    grid, and its band position (-1 off the grid or off the band)."""
    idx = grid.unravel(linear[nodes])
    for k in range(grid.ndim):
        for side in (1, -1):
            moved = idx.copy()
            moved[:, k] += side
            inside = (moved[:, k] >= 0) & (moved[:, k] < grid.shape[k])
            pos = np.full(len(moved), -1, np.int64)
            pos[inside] = band.find(np.ascontiguousarray(moved[inside], dtype=np.int64))
            yield moved, inside, pos


def _kinks(norm: np.ndarray, grid: Grid, linear: np.ndarray, band: Any) -> np.ndarray:
    """The band nodes whose |∇φ| (``norm``, one per node of ``band``) marks a kink (see
    :data:`KINK_FRACTION`): below the fraction of the band's typical value (the median over a
    stride of about 4,096 nodes) and of the largest among the node's neighbours. The second test
    keeps a φ whose |∇φ| merely varies (a scaled ellipsoid's quadric: 0.36 to 1.56) from counting
    its flat parts as kinks; across a ridge the neighbour beyond it has the full gradient."""
    kink = np.zeros(norm.size, bool)
    if norm.size == 0:
        return kink
    typical = float(np.median(norm[:: max(1, norm.size // 4096)]))
    cand = np.flatnonzero(norm < KINK_FRACTION * typical)
    if cand.size == 0:
        return kink
    largest = np.zeros(cand.size)
    for _, _, pos in band_neighbours(grid, band, linear, cand):
        found = pos >= 0
        largest[found] = np.maximum(largest[found], norm[pos[found]])
    kink[cand[norm[cand] < KINK_FRACTION * largest]] = True
    return kink


@dataclass
class BandGeometry:
    """What a surface tells the solver about the nodes within ``half_width`` of it.

    Attributes
    ----------
    linear : (K,) int64, sorted C-order linear node indices
    distance : (K,) float, unsigned distance to the surface (``|φ|`` or ``|x − cp(x)|``), or None
        where it is ``|signed|`` (level sets: not stored, 8 bytes per node less; see
        :meth:`unsigned`)
    signed : (K,) float, ``φ`` for level sets, equal to ``distance`` for closest-point surfaces
    direction : (K, d) float32, outward unit extension direction (zero where undefined)
    consumable : bool
        True when the arrays were made for this solve alone (every built-in surface): the solver
        then overwrites ``direction`` with the extension weights instead of copying it (12 bytes
        per node in 3D). A user's :meth:`Surface.band` may leave it False (the default) and
        return cached arrays: they are copied, never modified.
    native_band : tubesweep._native.Band or None
        The band structure of ``linear`` when the surface already built it (level sets; for a
        callable φ its neighbours give the outward directions): the solver uses it instead of
        building it again. None (the default) otherwise.
    kink : (K,) bool or None
        For a level set, the nodes whose central differences of φ straddle a kink where φ's
        gradient turns by more than about 140° (``|∇φ|`` below :data:`KINK_FRACTION` of the
        band's typical value): a ridge between two parts of the surface that face each other,
        where the direction is not reliable (see ``solve._warn_if_tubes_touch``). None otherwise.
    """

    linear: np.ndarray
    distance: Optional[np.ndarray]
    signed: np.ndarray
    direction: np.ndarray
    consumable: bool = False
    native_band: Any = None
    kink: Optional[np.ndarray] = None

    def directions_for_solver(self) -> np.ndarray:
        """``direction`` as the C-ordered float32 array the solver overwrites with the extension
        weights: the array itself when :attr:`consumable`, otherwise a copy."""
        d = self.direction
        if self.consumable and d.dtype == np.float32 and d.flags.c_contiguous and d.flags.writeable:
            return d
        return np.array(d, dtype=np.float32, order="C")

    def unsigned(self, lo: int = 0, hi: Optional[int] = None) -> np.ndarray:
        """The unsigned distance at band nodes ``lo:hi`` (computed from ``signed`` where
        ``distance`` is not stored)."""
        if self.distance is not None:
            return self.distance[lo:hi]
        return np.abs(self.signed[lo:hi])


class Surface:
    """Base class of implicit curves and surfaces: what :func:`tubesweep.solve` needs of one.

    A surface gives its band on a grid (:meth:`band`: the nodes within a distance, with φ and the
    extension directions) and projects points onto itself (:meth:`project`). :class:`LevelSet`,
    :class:`ClosestPoint` and the meshes of :func:`tubesweep.surfaces.from_mesh` are surfaces;
    subclass one of them rather than this class.

    Attributes
    ----------
    ndim : int or None
        2 (a curve) or 3 (a surface); None until known.

    Examples
    --------
    >>> import tubesweep as ts
    >>> isinstance(ts.surfaces.Sphere(0.5), ts.Surface)
    True
    """

    #: dimension of the embedding space, or None if it follows the grid
    ndim: Optional[int] = None

    def band(self, grid: Grid, half_width: float) -> BandGeometry:  # pragma: no cover - interface
        """The band of the surface on a grid: the nodes within ``half_width`` of it.

        Parameters
        ----------
        grid : Grid
            The grid.
        half_width : float
            The band's half-width (a distance, not grid spacings).

        Returns
        -------
        BandGeometry
            The band's nodes (C-order linear indices), φ there and the outward extension directions
            ``n`` of Eq. (8); the solver's input.

        Raises
        ------
        ValueError
            If the surface is of the wrong dimension for the grid, or (level sets) φ is far from a
            distance function near the surface.

        Examples
        --------
        >>> import tubesweep as ts
        >>> grid = ts.Grid((-1, -1), (1, 1), (41, 41))
        >>> geometry = ts.surfaces.Circle(0.5).band(grid, 4 * grid.spacing)
        """
        raise NotImplementedError

    def project(self, points: np.ndarray, grid: Grid) -> Tuple[np.ndarray, np.ndarray]:  # pragma: no cover
        """Closest points on the surface, and the distance to them.

        Parameters
        ----------
        points : numpy.ndarray
            ``(M, d)`` points near the surface.
        grid : Grid
            The grid (a sampled φ is interpolated on it).

        Returns
        -------
        distance : numpy.ndarray
            ``(M,)`` unsigned distances.
        closest : numpy.ndarray
            ``(M, d)`` the closest points.

        Raises
        ------
        ValueError
            If the points have the wrong shape or the surface's function returns non-finite values.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> grid = ts.Grid((-1, -1), (1, 1), (41, 41))
        >>> d, cp = ts.surfaces.Circle(0.5).project(np.array([[0.6, 0.0]]), grid)
        >>> np.round(cp, 6).tolist()
        [[0.5, 0.0]]
        """
        raise NotImplementedError

    def check_grid(self, grid: Grid) -> None:
        """Checks that the grid suits the surface (its dimension; for a φ array, its shape).

        Parameters
        ----------
        grid : Grid
            The grid to solve on.

        Raises
        ------
        ValueError
            If the dimensions or shapes differ; the message says which.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> ts.LevelSet(np.zeros((5, 5))).check_grid(ts.Grid((-1, -1), (1, 1), (5, 5)))
        """
        if self.ndim is not None and self.ndim != grid.ndim:
            raise ValueError(f"surface is {self.ndim}D but the grid is {grid.ndim}D")


def _evaluate(
    fn: Callable[[np.ndarray], Any], points: np.ndarray, name: str, out_shape: Tuple[int, ...] = (), finite: bool = True
) -> np.ndarray:
    """Calls a user's vectorised function in chunks and checks what comes back (NaN and inf are
    refused unless ``finite`` is False: the band search's samples far from the surface)."""
    m = points.shape[0]
    out = np.empty((m,) + out_shape)
    for s in range(0, m, EVAL_CHUNK):
        chunk = points[s : s + EVAL_CHUNK]
        v = call_on_points(fn, chunk, f"the values of the {name}")
        if v.shape != (chunk.shape[0],) + out_shape:
            raise ValueError(
                f"{name} must map points of shape (M, {points.shape[1]}) to an array of shape (M{''.join(', ' + str(n) for n in out_shape)}); "
                f"it returned shape {v.shape} for M = {chunk.shape[0]}"
            )
        out[s : s + EVAL_CHUNK] = v
    if finite and not np.all(np.isfinite(out)):
        bad = np.flatnonzero(~np.isfinite(out.reshape(m, -1)).all(axis=1))[0]
        raise ValueError(
            f"{name} returned NaN or inf at {tuple(float(x) for x in points[bad])}; it must be finite near the surface"
        )
    return out


def coarse_to_fine_candidates(
    grid: Grid,
    half_width: float,
    lipschitz: float,
    distance: Callable[[np.ndarray, float], np.ndarray],
    within: Optional[Callable[[np.ndarray, np.ndarray], np.ndarray]] = None,
) -> np.ndarray:
    """Sorted C-order linear indices of the grid nodes that may lie within ``half_width`` of a
    surface, found without visiting the box.

    Blocks of 2^L × … nodes are kept only if ``distance(centre) ≤ half_width + lipschitz · radius``
    (exact when the distance is ``lipschitz``-Lipschitz, as a distance function is with constant
    1), then split in 2^d children, down to single nodes. ``distance(points, reach)`` returns the
    unsigned distance of the points; it may return anything larger than ``reach`` for points
    farther than ``reach`` (a spatial index can stop its search there). ``within(points,
    thresholds)``, if given, is used instead and answers ``distance(points) <= thresholds`` itself
    (a spatial index can stop at the first thing within the threshold). Work and memory are
    O(N^(d−1) log N); the single nodes of the last level are produced in C order as linear indices
    (8 bytes each, :func:`tubesweep._native.split_pair_blocks`), so the candidate list is the
    largest array this allocates.
    """
    from . import _native

    shape = list(grid.shape)
    d = grid.ndim
    h = grid.spacing
    lower = [float(x) for x in grid.lower]
    block = 1 << max(0, int(np.floor(np.log2(max(grid.shape) / 4))))
    if block == 1:  # a tiny grid: every node is a candidate
        return np.arange(grid.size, dtype=np.int64)
    # the first level, blocks of `block` nodes on the lattice of that spacing, is made as the
    # children of the lattice of twice the spacing; every level is then the children of the blocks
    # the previous one kept. The children, their centres and radii come from Rust
    # (:func:`tubesweep._native.block_children`), a slice of parents at a time so that the
    # temporaries (and the callable's own) stay O(EVAL_CHUNK); only the kept blocks are stored.
    parents = (
        np.stack(np.meshgrid(*[np.arange(0, n, 2 * block) for n in grid.shape], indexing="ij"), axis=-1)
        .reshape(-1, d)
        .astype(np.int64)
    )
    step = max(1, EVAL_CHUNK >> d)  # parents per slice: at most EVAL_CHUNK children
    while True:
        radius_max = 0.5 * h * _native.children_radius_max(shape, parents, block)
        reach = half_width + lipschitz * radius_max + 1e-12
        kept = []
        for s0 in range(0, len(parents), step):
            o, centres, radius = _native.block_children(shape, parents[s0 : s0 + step], block, lower, h)
            if within is not None:
                kept.append(o[within(centres, half_width + lipschitz * radius + 1e-12)])
            else:
                dist = distance(centres, reach)
                kept.append(o[dist <= half_width + lipschitz * radius + 1e-12])
        parents = kept[0] if len(kept) == 1 else np.concatenate(kept) if kept else parents[:0]
        block //= 2
        if block == 1:
            break
    # the last split (blocks of 2 nodes per axis → single nodes), in Rust: straight to sorted
    # linear indices (8 bytes per candidate, no sort, no (M, 2^d, d) temporaries)
    origins = np.ascontiguousarray(parents, dtype=np.int64)
    linear = _native.split_pair_blocks(shape, origins)
    return linear.view(np.int64)  # below 2^63: the same bits


def discover_band(
    fn: Callable[[np.ndarray], np.ndarray], grid: Grid, half_width: float, lipschitz: float, name: str = "phi callable"
) -> Tuple[np.ndarray, np.ndarray]:
    """Grid nodes with ``|fn| ≤ half_width`` for a level set function ``fn``, found coarse-to-fine
    (:func:`coarse_to_fine_candidates`). Returns sorted linear indices and the values of ``fn``
    there."""

    # φ may be NaN or inf far from the surface (undefined there): a block whose centre has no
    # finite value may still hold band nodes, so it is kept and split (the search's work then grows
    # with the volume where φ is not finite), and the nodes without a value are left out at the
    # end; the nodes next to the band are checked at its rim (LevelSet.band)
    def distance(p: np.ndarray, reach: float) -> np.ndarray:
        v = np.abs(_evaluate(fn, p, name, finite=False))
        return np.where(np.isfinite(v), v, 0.0)

    candidates = coarse_to_fine_candidates(grid, half_width, lipschitz, distance)
    from . import _native

    shape, lower = list(grid.shape), [float(x) for x in grid.lower]
    # the kept nodes are written straight to arrays of the candidates' length and then cut to
    # size in place (a shrinking realloc: no copy, and only the pages written are ever touched)
    linear = np.empty(len(candidates), np.int64)
    values = np.empty(len(candidates))
    kept = 0
    lin = candidates[:0]
    for s0 in range(0, len(candidates), EVAL_CHUNK):
        lin = candidates[s0 : s0 + EVAL_CHUNK]
        # the node coordinates in Rust (the bits of Grid.points, without the (M, d) int64 indices)
        v = _evaluate(fn, _native.node_points(shape, lin.view(np.uint64), lower, grid.spacing), name, finite=False)
        # the nodes with |φ| ≤ half_width, copied in order to the fronts of the outputs (in Rust)
        kept += _native.keep_within(lin.view(np.uint64), v, half_width, linear[kept:].view(np.uint64), values[kept:])
    del candidates, lin  # (lin is a view of them)
    linear.resize(kept, refcheck=False)  # sorted, as the candidates are
    values.resize(kept, refcheck=False)
    return linear, values


def _norm_bounds(values: np.ndarray, norm: np.ndarray, half_width: float) -> Tuple[float, float, bool]:
    """The range of |∇φ| (``norm``) over the band nodes within half the band of the surface
    (``|φ| ≤ half_width/2``), and True; over all of them, and False, when there are none.
    Chunk by chunk: a temporary of the band's size (8 bytes per node for ``|φ|``) would raise
    the set-up's peak memory."""
    lo, hi, lo_all, hi_all, any_near = np.inf, -np.inf, np.inf, -np.inf, False
    for start in range(0, len(values), EVAL_CHUNK):
        v, g = values[start : start + EVAL_CHUNK], norm[start : start + EVAL_CHUNK]
        # np.minimum and np.maximum pass a NaN on, as the minimum over the whole band would
        lo_all, hi_all = float(np.minimum(lo_all, g.min())), float(np.maximum(hi_all, g.max()))
        near = g[np.abs(v) <= 0.5 * half_width]
        if near.size:
            any_near = True
            lo, hi = float(np.minimum(lo, near.min())), float(np.maximum(hi, near.max()))
    if any_near:
        return lo, hi, True
    return lo_all, hi_all, False


class LevelSet(Surface):
    """A curve or surface given as the zero level set of φ, close to a signed distance function.

    Parameters
    ----------
    phi : ndarray of ``grid.shape`` or callable ``phi(points (M, d)) -> (M,)``
        The level set function sampled on the grid, or a vectorised function. Only the band is
        evaluated for a callable (found coarse-to-fine, never the whole box). A C-ordered float64
        array is used in place, not copied (no second array of the grid's size): do not change it
        while a solution or a :class:`~tubesweep.Tube` built from it is in use (a Tube refuses to
        solve after a change, and a solution to trace geodesic paths, whose projections use it);
        pass ``phi.copy()`` to keep it free.
    lipschitz : float, optional
        Bound on ``|∇φ|`` used by the coarse-to-fine band search (1 for an exact distance; the
        default 1.5 leaves room for near-distance functions). With ``redistance=True`` the default
        is estimated from |∇φ| on a coarse lattice of the grid box for a callable and then from
        |∇φ| at the band's candidates, and for an array bounded near each node from the
        differences of the samples (a bound given here applies to the whole box instead).
    redistance : bool
        For φ that is *not* a distance function (e.g. ``x² + y² − r²``): in the band only, replace
        φ by the signed distance to its zero level set — first ``φ/|∇φ|`` (a Newton step onto the
        surface), then closest-point projection iterations (:mod:`tubesweep.redistance`). The tube
        widths are then true distances and the extension direction is ``(x − cp(x))/|x − cp(x)|``.
        Costs a few dozen φ evaluations per band node.

    Raises
    ------
    ValueError
        If a φ array is not 2D or 3D or holds NaN or inf, or ``lipschitz`` is not a valid bound.
    TypeError
        If φ is neither an array nor a callable.

    Notes
    -----
    The outward normal ``n = ∇φ / |∇φ|`` comes from central differences of φ at the band nodes, as
    in the paper (Sect. 4). The method needs φ close to a signed distance function (``|∇φ| ≈ 1``
    near the surface); far from it the solver raises an error that says so.

    Examples
    --------
    >>> import numpy as np, tubesweep as ts
    >>> grid = ts.Grid((-1, -1), (1, 1), (101, 101))
    >>> X, Y = grid.meshgrid()
    >>> circle = ts.LevelSet(np.hypot(X, Y) - 0.5)                   # a signed distance, sampled
    >>> squashed = ts.LevelSet(X**2 + Y**2 - 0.25, redistance=True)   # not a distance: re-distanced
    >>> sol = ts.solve(squashed, grid, [(0.5, 0.0)])
    """

    def __init__(
        self,
        phi: Union[np.ndarray, Callable[[np.ndarray], np.ndarray]],
        *,
        lipschitz: Optional[float] = None,
        redistance: bool = False,
    ):
        self._non_finite: Optional[tuple] = None
        if callable(phi):
            self._fn: Optional[Callable[[np.ndarray], np.ndarray]] = phi
            self._array: Optional[np.ndarray] = None
        else:
            from . import _native

            # C order, as the core reads it (no copy for a C-ordered float64 array)
            arr = real_array(phi, "phi array")
            if arr.ndim not in (2, 3):  # before ascontiguousarray, which makes a 0-d array 1-d
                raise ValueError(
                    f"phi array must be 2D or 3D (the grid's shape); got {arr.ndim} dimensions (shape {arr.shape})"
                )
            arr = np.ascontiguousarray(arr)
            # NaN or inf far from the surface (φ undefined there) is fine: the band never reads it,
            # and the band's search checks that none lies next to the band (see band())
            bad = _native.first_non_finite(arr)
            self._non_finite = None if bad is None else tuple(int(x) for x in np.unravel_index(bad, arr.shape))
            if self._non_finite is not None and redistance:
                raise ValueError(
                    f"phi contains NaN or inf (first at index {self._non_finite}); with redistance=True "
                    "φ must be finite everywhere"
                )
            self._fn = None
            self._array = arr
            self.ndim = arr.ndim
        self.redistance = bool(redistance)
        if lipschitz is not None:
            lipschitz = real_scalar(lipschitz, "lipschitz", "a real number (a bound on |∇φ|)")
        if lipschitz is None:
            self.lipschitz: Optional[float] = None if self.redistance else 1.5
        elif self.redistance:
            if not (np.isfinite(lipschitz) and lipschitz > 0):
                raise ValueError(f"lipschitz must be a positive bound on |∇φ|; got {lipschitz}")
            self.lipschitz = float(lipschitz)
        else:
            if not (np.isfinite(lipschitz) and lipschitz >= 1.0):
                raise ValueError(f"lipschitz must be >= 1 (a distance function has |∇φ| = 1); got {lipschitz}")
            self.lipschitz = float(lipschitz)

    @property
    def is_dense(self) -> bool:
        return self._array is not None

    def check_grid(self, grid: Grid) -> None:
        """Checks that the grid suits the surface (its dimension; for a φ array, its shape).

        Parameters
        ----------
        grid : Grid
            The grid to solve on.

        Raises
        ------
        ValueError
            If the dimensions or shapes differ; the message says which.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> ts.LevelSet(np.zeros((5, 5))).check_grid(ts.Grid((-1, -1), (1, 1), (5, 5)))
        """
        super().check_grid(grid)
        if self._array is not None and self._array.shape != grid.shape:
            raise ValueError(
                f"phi has shape {self._array.shape} but the grid has shape {grid.shape}; sample φ on the grid's nodes"
            )

    def phi(self, points: np.ndarray, grid: Grid) -> np.ndarray:
        """φ at arbitrary points: the callable, or the multilinear interpolation of the samples.

        Parameters
        ----------
        points : numpy.ndarray
            ``(M, d)`` points.
        grid : Grid
            The grid a sampled φ lives on.

        Returns
        -------
        numpy.ndarray
            ``(M,)`` values of φ.

        Raises
        ------
        ValueError
            If the callable returns values of the wrong shape or non-finite values.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> ls = ts.LevelSet(lambda p: np.linalg.norm(p, axis=1) - 0.5)
        >>> ls.phi(np.array([[1.0, 0.0]]), ts.Grid((-1, -1), (1, 1), (5, 5))).tolist()
        [0.5]
        """
        if self._fn is not None:
            return _evaluate(self._fn, points, "phi callable")
        from .euclidean import _interp_dense

        assert self._array is not None
        return _interp_dense(self._array, grid, points)

    def _outward_directions(
        self, grid: Grid, linear: np.ndarray, values: np.ndarray, lo: int, hi: int, direction: np.ndarray, band: Any
    ) -> np.ndarray:
        """For a callable φ: ``sgn(φ) ∇φ/|∇φ|`` at band nodes ``lo:hi`` into ``direction`` (float32)
        by central differences, in Rust (``tubesweep._native.Band.outward_directions``); returns
        ``|∇φ|``. φ at a neighbour that is itself a band node is already known; the callable is
        evaluated only at the others (the band's outer rim), one batch per axis and side.
        ``band`` is the native band of ``linear``, whose neighbours give the rim places."""
        # the neighbours come from the band's own table (no search)
        pos, counts = band.rim_nodes(lo, hi)
        rim_phi = self._phi_at_rim_places(grid, linear, pos, counts)
        return band.outward_directions(grid.spacing, values, lo, hi, rim_phi, direction)

    def _phi_at_rim_places(self, grid: Grid, linear: np.ndarray, pos: np.ndarray, counts: List[int]) -> np.ndarray:
        """The callable φ at the places ``Band.rim_nodes`` lists (``pos``, ``counts``): for group
        ``g`` (axis ``g // 2``, side +1 for even ``g``) at ``x ± Δx e_k`` of its band nodes, group
        after group, one batch each."""
        from . import _native

        h = grid.spacing
        ulinear = linear.view(np.uint64)  # non-negative int64: the same bits
        parts = []
        start = 0
        for group, count in enumerate(counts):
            if count:
                x = _native.node_points(
                    list(grid.shape), ulinear[pos[start : start + count]], [float(c) for c in grid.lower], h
                )
                x[:, group // 2] += (1 if group % 2 == 0 else -1) * h
                parts.append(_evaluate(self._fn, x, "phi callable"))  # type: ignore[arg-type]
            start += count
        return np.concatenate(parts) if parts else np.zeros(0)

    def band(self, grid: Grid, half_width: float) -> BandGeometry:
        """The band of the surface on a grid: the nodes within ``half_width`` of it.

        Parameters
        ----------
        grid : Grid
            The grid.
        half_width : float
            The band's half-width (a distance, not grid spacings).

        Returns
        -------
        BandGeometry
            The band's nodes (C-order linear indices), φ there and the outward extension directions
            ``n`` of Eq. (8); the solver's input.

        Raises
        ------
        ValueError
            If the surface is of the wrong dimension for the grid, or (level sets) φ is far from a
            distance function near the surface.

        Examples
        --------
        >>> import tubesweep as ts
        >>> grid = ts.Grid((-1, -1), (1, 1), (41, 41))
        >>> geometry = ts.surfaces.Circle(0.5).band(grid, 4 * grid.spacing)
        """
        self.check_grid(grid)
        if self.redistance:
            from .redistance import redistanced_band

            return redistanced_band(self, grid, half_width)
        from . import _native

        native_phi = self._native_phi() if self._fn is not None else None
        if native_phi is not None:
            # a library surface whose φ is evaluated in Rust: the search, the band structure, φ at
            # its rim and the directions in one call, with no call back into Python (the same
            # nodes and bits as the callable route below)
            kind, parameters = native_phi
            ulinear, values, native_band, direction, norm = _native.analytic_level_set_band(
                kind,
                [float(p) for p in parameters],
                list(grid.shape),
                [float(x) for x in grid.lower],
                grid.spacing,
                float(half_width),
                float(self.lipschitz),
            )  # type: ignore[arg-type]
            linear = ulinear.view(np.int64)
            if linear.size == 0:
                return BandGeometry(linear, values, values, direction)
            self._check_distance_like(*_norm_bounds(values, norm, half_width)[:2])
            return BandGeometry(
                linear,
                None,
                values,
                direction,
                consumable=True,
                native_band=native_band,
                kink=_kinks(norm, grid, linear, native_band),
            )
        if self._array is not None:
            # one pass over the samples in Rust, on all threads, with no temporary of the grid's
            # size (tubesweep_core::sampled)
            ulinear, values = _native.band_of_samples(self._array, half_width)
            linear = ulinear.view(np.int64)  # below 2^63: the same bits
        else:
            linear, values = discover_band(self._fn, grid, half_width, self.lipschitz)  # type: ignore[arg-type]
        if linear.size == 0:
            if self._non_finite is not None:
                raise ValueError(
                    f"phi contains NaN or inf (first at index {self._non_finite}) and no grid node with a "
                    "finite φ lies within the tube: φ must be finite near the surface"
                )
            return BandGeometry(linear, values, values, np.zeros((0, grid.ndim), np.float32))
        # the solver's band structure, built now: the solver takes it over (and for a callable φ
        # its neighbours give the outward directions, no separate neighbour search)
        native_band = _native.Band.from_linear(list(grid.shape), linear.view(np.uint64))
        # the outward direction sgn(φ) ∇φ/|∇φ|, chunk by chunk (temporaries stay O(chunk))
        direction = np.empty((len(linear), grid.ndim), np.float32)
        norms = np.empty(len(linear), np.float32)
        for lo in range(0, len(linear), EVAL_CHUNK):
            hi = min(len(linear), lo + EVAL_CHUNK)
            if self._array is not None:
                # central differences of the samples, one-sided at the grid's faces
                norm = _native.outward_directions_of_samples(
                    self._array, grid.spacing, linear[lo:hi].view(np.uint64), direction[lo:hi]
                )
            else:
                norm = self._outward_directions(grid, linear, values, lo, hi, direction[lo:hi], native_band)
            norms[lo:hi] = norm
        if self._non_finite is not None and not np.all(np.isfinite(norms)):
            # a NaN or inf sample next to a band node (its central differences read it)
            at = int(np.flatnonzero(~np.isfinite(norms))[0])
            where = tuple(int(x) for x in np.unravel_index(int(linear[at]), grid.shape))
            raise ValueError(
                f"phi contains NaN or inf next to the surface: a neighbour of the band node at index {where} (within "
                f"{half_width / grid.spacing:g} grid spacings of the surface) is not finite. φ may be NaN far from the "
                "surface, but must be finite within the tube and one grid spacing beyond it"
            )
        # bounded in single precision, as the library surfaces' band call returns |∇φ|
        self._check_distance_like(*_norm_bounds(values, norms, half_width)[:2])
        # distance = |φ|, not stored
        kink = _kinks(norms, grid, linear, native_band)
        del norms
        return BandGeometry(linear, None, values, direction, consumable=True, native_band=native_band, kink=kink)

    def __repr__(self) -> str:
        if self._array is not None:
            what = "array " + "×".join(map(str, self._array.shape))
        else:
            what = "callable " + getattr(self._fn, "__name__", type(self._fn).__name__)
        return f"LevelSet({what}{', redistance=True' if self.redistance else ''})"

    def _native_phi(self) -> Optional[Tuple[str, List[float]]]:
        """For a library surface whose φ is evaluated in Rust (and not replaced by a subclass):
        its kind and parameters for ``tubesweep._native.analytic_level_set_band``; else None."""
        return None

    def _check_distance_like(self, lo: float, hi: float) -> None:
        """``lo``, ``hi``: the range of |∇φ| at the nodes within half the band of the surface."""
        if (lo < GRAD_ERROR_LOW or hi > GRAD_ERROR_HIGH) and self._native_phi() is not None:
            # a library surface's φ is an exact distance: only the grid can be at fault
            raise ValueError(
                f"the grid is too coarse for this surface: its tube (outer × grid spacing on each side) reaches a point "
                f"where φ's gradient vanishes (|∇φ| ranges over [{lo:.3g}, {hi:.3g}] near the surface, ≈ 1 expected), "
                "such as the centre of a sphere not much larger than the tube or the core of a thin torus: refine the "
                "grid, or make the surface larger than a few grid spacings"
            )
        if lo < GRAD_ERROR_LOW or hi > GRAD_ERROR_HIGH:
            raise ValueError(
                f"surface: φ is not close to a signed distance function: |∇φ| ranges over [{lo:.3g}, {hi:.3g}] near the "
                "surface (it should be ≈ 1). Use ts.LevelSet(phi, redistance=True) (on the command line: --redistance), which "
                "re-distances φ in the band, "
                "or pass a signed distance function; the tube widths are measured in units of φ. If φ is a distance "
                "function, the grid is too coarse for the surface: the tube (outer × grid spacing on each side) "
                "reaches a point where ∇φ vanishes, such as the centre of a sphere not much larger than the tube, "
                "the core of a thin tube, or the middle of a gap between two parts of the surface that face each "
                "other; refine the grid"
            )
        if lo < GRAD_WARN_LOW or hi > GRAD_WARN_HIGH:
            warnings.warn(
                f"φ is only roughly a distance function: |∇φ| ranges over [{lo:.3g}, {hi:.3g}] near the surface; "
                "the tube is measured in units of φ, so its real width varies accordingly",
                RuntimeWarning,
                stacklevel=user_stacklevel(),
            )

    def project(self, points: np.ndarray, grid: Grid) -> Tuple[np.ndarray, np.ndarray]:
        """Closest points on the surface, and the distance to them.

        Parameters
        ----------
        points : numpy.ndarray
            ``(M, d)`` points near the surface.
        grid : Grid
            The grid (a sampled φ is interpolated on it).

        Returns
        -------
        distance : numpy.ndarray
            ``(M,)`` unsigned distances.
        closest : numpy.ndarray
            ``(M, d)`` the closest points.

        Raises
        ------
        ValueError
            If the points have the wrong shape or the surface's function returns non-finite values.

        Examples
        --------
        >>> import numpy as np, tubesweep as ts
        >>> grid = ts.Grid((-1, -1), (1, 1), (41, 41))
        >>> d, cp = ts.surfaces.Circle(0.5).project(np.array([[0.6, 0.0]]), grid)
        >>> np.round(cp, 6).tolist()
        [[0.5, 0.0]]
        """
        if self.redistance:
            from .redistance import redistanced_project

            return redistanced_project(self, points, grid)
        phi = self.phi(points, grid)
        h = grid.spacing
        d = points.shape[1]
        g = np.empty_like(points)
        for k in range(d):
            e = np.zeros(d)
            e[k] = h
            g[:, k] = (self.phi(points + e, grid) - self.phi(points - e, grid)) / (2 * h)
        n2 = np.maximum(np.sum(g * g, axis=1), 1e-24)
        closest = points - (phi / n2)[:, None] * g
        return np.abs(phi), closest


def as_surface(surface: Any) -> Surface:
    """Accepts a Surface, a φ array, or a φ callable."""
    if isinstance(surface, Surface):
        return surface
    if callable(surface) or isinstance(surface, np.ndarray):
        return LevelSet(surface)
    raise TypeError(
        "surface must be a tubesweep.LevelSet / ClosestPoint / library surface, a φ array of grid.shape, "
        f"or a callable phi(points) -> values; got {type(surface).__name__}"
    )
