"""The band as the solver receives it from a surface (:class:`BandGeometry`), and the
coarse-to-fine search that finds the nodes within a half-width of a surface given by a
distance-like callable without evaluating it on the whole box (:func:`discover_band`).

Used by :mod:`tubesweep.surface` (level sets), :mod:`tubesweep.closest_point` and
:mod:`tubesweep.redistance`; it imports none of them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Iterator, Optional, Tuple

import numpy as np

from ._validate import call_on_points
from .grid import Grid

__all__ = ["BandGeometry", "band_neighbours", "coarse_to_fine_candidates", "discover_band", "EVAL_CHUNK"]


#: Evaluate user callables on at most this many points at a time.
EVAL_CHUNK = 1 << 18


#: A band node whose central-difference |∇φ| is below this fraction of the median over the band
#: (sampled) and of the largest among its neighbours straddles a kink of φ where the gradient turns by more than about 140°
#: (|n₁ + n₂|/2 < 0.35 for unit gradients): the ridge between two parts of the surface that face
#: each other. A convex edge of 90° gives 0.71, and the double torus's creases stay above it from
#: N = 61 on (at 0.5 they counted as gaps up to N = 81); two spheres min(d₁, d₂) 4.5–5.5 spacings
#: apart were all found with it, one in 8 missed at 0.25.
KINK_FRACTION = 0.35


def band_edges(band: Any, n: int, chunk: int = 1 << 18) -> Iterator[Tuple[np.ndarray, np.ndarray]]:
    """The edges of ``band`` (``n`` nodes) in its own neighbour table (a cut edge is none), each
    once, as pairs of band positions ``(node, neighbour)`` with ``node < neighbour``, ``chunk``
    nodes at a time."""
    for s in range(0, n, chunk):
        at = np.arange(s, min(s + chunk, n), dtype=np.int64)
        nb = band.neighbours_of_nodes(at).reshape(len(at), -1)
        node = np.repeat(at, nb.shape[1])
        other = nb.ravel()
        keep = (other < n) & (other > node)
        yield node[keep], other[keep]


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
        where the direction is not reliable (see ``_facing._warn_if_tubes_touch``). None otherwise.
    inside : callable or None
        For a closest-point surface whose ``signed`` is unsigned but which has an inside (a closed
        mesh's smooth map): given band positions (int64), whether those nodes lie inside it. The
        facing test runs once more with φ signed by it, which finds gaps of one to two spacings
        that an unsigned φ shows as one sheet; it asks only for the few nodes whose sign that test
        can read (``_facing.facing_gaps``). None otherwise.
    """

    linear: np.ndarray
    distance: Optional[np.ndarray]
    signed: np.ndarray
    direction: np.ndarray
    consumable: bool = False
    native_band: Any = None
    kink: Optional[np.ndarray] = None
    inside: Optional[Callable[[np.ndarray], np.ndarray]] = None

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
