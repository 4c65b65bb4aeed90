"""Parts of a level set's inside thinner than two grid spacings (a plate, a flat ellipsoid, a thin
wall of a voxel mask), warned about like a mesh's thin parts (``surfaces._mesh_checks``).

Where the inside of the surface is a slab at most two nodes thick along a grid axis, the tube's
two sides are one: the front crosses the slab, and the narrow-gap test, which looks for pairs of
nodes farther than 0.75Δx from the surface on either side, finds none (an oblate spheroid of
radius 0.6 and thickness 0.06, 1.2 spacings at N = 41: the far pole 1.18 short, 23.5 spacings,
with the gap warning only from N = 61 on and two warnings that pointed elsewhere; a helper's
sweep). :func:`thin_share` reads φ on the band: an inside node (φ < 0) whose neighbour on one side
along an axis and, on the other, its neighbour or the one after it are outside, with φ rising
on both sides by more than :data:`BEND` spacings over the run (a slab's two faces; a node just
inside a convex surface also has outside neighbours along a tangent, but φ rises there only by
about h²/R: a sphere of radius 5 spacings gave 2% of its surface, falsely), and with
:data:`SHEET` such neighbours.
"""

from __future__ import annotations

import math
import warnings
from typing import Any, Optional, Tuple

import numpy as np

from .grid import Grid
from ._warn import user_stacklevel

#: The warning is given from this share of the nodes next to the surface (the spheroid 1.2
#: spacings thick: 41%; spheres, tori, a box and their voxel masks at N = 21–81: none).
THIN_SHARE = 0.05
#: Where the surface also faces itself across narrow gaps (said by their own warning, with no
#: size), from this share: a plate 1.2 spacings thick tilted off the grid's planes, 14% of its
#: surface in gaps, is 26% thin (its far side 95% short); a lens's or two fused balls' thin wedges
#: at their sharp rims, where the way round is short, and a rough re-distanced φ show 7–8%.
THIN_SHARE_BESIDE_GAPS = 0.12
#: ... and where φ rises on both sides of the run by more than this many grid spacings together
#: (across a slab of thickness t < 2h at least 2h − t; grazing a convex surface of radius R about
#: h²/R).
BEND = 0.75
#: ... counted where at least this many of a thin node's neighbours are thin too (a sheet of them:
#: a noisy sphere's bumps, 0.3 spacings of noise, re-distanced, showed 5% alone).
SHEET = 2
#: Band nodes per block of the neighbour lookups (bounds the memory).
CHUNK = 1 << 16
#: A node this many spacings from the surface or nearer lies on it (a face on the grid's nodes).
ON_SURFACE = 1e-9


def thin_share(grid: Grid, band: Any, linear: np.ndarray, phi: np.ndarray) -> Tuple[float, Optional[np.ndarray]]:
    """The share of the band nodes next to the surface (within half a cell's diagonal) that lie
    on an inside slab at most two nodes thick along an axis (module notes), and a point there
    (None where there is none). A node on the surface (|φ| within :data:`ON_SURFACE` spacings of 0)
    counts once as outside and once as inside: a plate two spacings thick whose faces lie on the
    grid's planes is one inside node between two nodes on its faces, and one a spacing thick there
    is two nodes on its faces (re-distanced at N = 61: 25 and 24 spacings short across the plate,
    unwarned; in 2D 48; a helper's review). O(band): the neighbours of the inside nodes are looked
    up once, for the three readings of the nodes on the surface together (looked up per reading
    and per axis, the test took longer than the sweeps of the sphere at N = 121)."""
    n = len(linear)
    h = grid.spacing
    phi = np.asarray(phi, dtype=float)
    near = np.abs(phi) <= 0.5 * math.sqrt(grid.ndim) * h
    zero = np.abs(phi) <= ON_SURFACE * h
    neg, pos = phi < 0, phi > 0
    thin = np.zeros(n, bool)
    # (padded once, position n: no neighbour, never outside; padded per block they made the test
    # quadratic in the band: 87 s at N = 2001)
    readings = [
        (np.r_[out, False], inside)
        for out, inside in ((pos, ~zero & neg), (pos | zero, neg), (~zero & pos, neg | zero))
    ]
    maybe_out = np.r_[pos | zero, False]  # outside in some reading
    for s in range(0, n, CHUNK):
        at = np.arange(s, min(s + CHUNK, n), dtype=np.int64)
        at = at[neg[at] | zero[at]]  # (inside in one of the readings)
        if at.size:
            thin[at] = _slab_nodes(band, grid.ndim, h, phi, at, readings, maybe_out)
    # a plate's thin nodes lie in a sheet; a bump of noise or a mask's corner is one or two alone
    at = np.flatnonzero(thin)
    if at.size:
        nb = band.neighbours_of_nodes(at).reshape(at.size, -1)
        flagged = np.r_[thin, False]
        thin[at] = np.count_nonzero(flagged[np.where(nb < n, nb, n)], axis=1) >= SHEET
    # with the nodes on the surface beside them: the faces of a slab whose inside node lies a
    # spacing from both (farther than the near layer's half diagonal)
    at = np.flatnonzero(thin)
    if at.size:
        nb = band.neighbours_of_nodes(at).ravel()
        nb = nb[nb < n]
        thin[nb[zero[nb]]] = True
    total = int(np.count_nonzero(near))
    hits = near & thin
    if total == 0 or not np.any(hits):
        return 0.0, None
    return float(np.count_nonzero(hits)) / total, grid.node_points(linear[np.flatnonzero(hits)[:1]])[0]


def _slab_nodes(
    band: Any, ndim: int, h: float, phi: np.ndarray, at: np.ndarray, readings: Any, maybe_out: np.ndarray
) -> np.ndarray:
    """Which of the band nodes ``at`` are, in one of the ``readings`` (pairs of masks: outside,
    padded with False at position n, and inside), an inside node on a run of one or two of them
    along an axis between outside nodes, with φ rising by more than
    :data:`BEND` spacings over the run (module notes); ``maybe_out``: outside in some reading."""
    n = len(phi)
    nb = band.neighbours_of_nodes(at).reshape(len(at), ndim, 2)
    nb = np.where(nb < n, nb, n)
    # a thin node has an outside neighbour: the others (most of the inside) are not
    full = np.zeros(len(at), bool)
    keep = np.flatnonzero(np.any(maybe_out[nb.reshape(len(at), -1)], axis=1))
    at, nb = at[keep], nb[keep]
    # the next node along the axis beyond a neighbour, looked up only where a run of two can
    # start: its other neighbour may be outside (one lookup for all axes)
    rows, ends = [], []
    for k in range(ndim):
        for j in (0, 1):
            r = np.flatnonzero(maybe_out[nb[:, k, 1 - j]] & (nb[:, k, j] < n))
            rows.append(r)
            ends.append(nb[r, k, j])
    ends_all = np.concatenate(ends)
    beyond = band.neighbours_of_nodes(ends_all).reshape(len(ends_all), 2 * ndim)
    second = np.full((2 * ndim, len(at)), n, dtype=np.int64)
    start = 0
    for r, side in zip(rows, range(2 * ndim)):
        b = beyond[start : start + r.size, side]
        second[side, r] = np.where(b < n, b, n)
        start += r.size
    here = phi[at]

    def value(i: np.ndarray) -> np.ndarray:  # φ at positions, any at n (no neighbour: never outside)
        return phi[np.minimum(i, n - 1)]

    thin = np.zeros(len(at), bool)
    for k in range(ndim):
        lo, hi = nb[:, k, 0], nb[:, k, 1]
        lo2, hi2 = second[2 * k], second[2 * k + 1]
        one_rise = value(lo) + value(hi) - 2 * here > BEND * h
        up_rise = value(lo) + value(hi2) - here - value(hi) > BEND * h
        down_rise = value(hi) + value(lo2) - here - value(lo) > BEND * h
        for outside, inside in readings:
            one = outside[lo] & outside[hi] & one_rise
            # a run of two inside nodes: this one and the one above (or below) it
            up = (hi < n) & ~outside[hi] & outside[lo] & outside[hi2] & up_rise
            down = (lo < n) & ~outside[lo] & outside[hi] & outside[lo2] & down_rise
            thin |= inside[at] & (one | up | down)
    full[keep] = thin
    return full


def warn_thin(share: float, where: Optional[np.ndarray], h: float, inner: float, gaps: bool = False) -> None:
    """A RuntimeWarning when :func:`thin_share` is over :data:`THIN_SHARE`, or over
    :data:`THIN_SHARE_BESIDE_GAPS` where narrow ``gaps`` were found too."""
    if share < (THIN_SHARE_BESIDE_GAPS if gaps else THIN_SHARE) or where is None:
        return
    at = ", ".join(f"{float(x):.3g}" for x in where)
    warnings.warn(
        f"about {share:.0%} of the surface lies on a part of φ's inside at most two grid spacings thick (a plate or a "
        f"thin wall, e.g. near ({at})): there the tube cannot keep the two sides apart and the front crosses between "
        "them, so distances past such parts can come out short by as much as the way around the part (a flat "
        "spheroid 1.2 spacings thick: its far pole 23 spacings short). A grid spacing below the part's thickness "
        f"divided by {2 * inner + 2:g} (now {h:.3g}) resolves it",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )
