"""Where the grid box cuts the surface or its tube (issue 44): the distances are those of the part
of the surface inside the box, so a surface that leaves the box is reported in
``sol.stats.box_cut``, and a bounded one (not a plane meant to go on) with a ``RuntimeWarning``
that says how much is cut; a tube cut by the box around a surface that is inside it is recorded
only (the solvers handle it)."""

from __future__ import annotations

import math
import re
import warnings
from typing import Any, Dict, List, Optional

import numpy as np

from .closest_point import ClosestPoint
from .grid import Grid
from .surface import LevelSet
from ._warn import user_stacklevel

__all__ = ["box_cut", "looks_bounded", "warn_box_cut", "box_reason"]

_AXES = "xyz"


def _face_name(grid: Grid, axis: int, upper: bool) -> str:
    bound = (grid.upper if upper else grid.lower)[axis]
    return f"{_AXES[axis]} = {float(bound):g}"


def box_cut(
    grid: Grid, linear: np.ndarray, phi: np.ndarray, inner_width: float, directions: Optional[np.ndarray] = None
) -> Optional[Dict[str, Any]]:
    """How the grid box cuts the band of ``linear`` (sorted linear indices, ``phi`` their φ: signed
    for a level set, the unsigned distance for a closest-point surface, ``directions`` their unit
    (x − cp(x))/|x − cp(x)| where known), or None when no band node lies on the box's boundary.

    Returns a dict: ``surface_cut`` (the surface itself crosses the boundary: φ changes sign between
    neighbouring nodes of a boundary face, or for an unsigned distance a boundary node lies within
    half a spacing of the surface and, where the directions are given, some such node's closest
    point lies on the face or beyond it: a closed mesh 0.005 inside the box was said to cross all
    six faces), ``faces`` (the faces it crosses, or that the tube touches),
    ``cut_length`` (3D: the length of the curve along which the surface crosses them, from the
    number of face cells crossed, times π/4 for the average direction) or ``cut_points`` (2D: the
    number of crossings), ``inner_on_boundary`` (inner-tube nodes on the boundary faces) and
    ``gap`` (the smallest |φ| on the boundary: how close the surface comes to it)."""
    shape = grid.shape
    d = grid.ndim
    h = grid.spacing
    strides = [int(np.prod(shape[k + 1 :], dtype=np.int64)) for k in range(d)]
    if len(linear) == 0:
        return None
    # one division over the band: its rows (runs along the last axis); the other axes are read
    # from the distinct rows only (a band is sorted)
    n_last = shape[-1]
    row, last = np.divmod(linear, n_last)
    on = (last == 0) | (last == n_last - 1)
    starts = np.flatnonzero(np.concatenate(([True], row[1:] != row[:-1])))
    rows = row[starts]
    row_on = np.zeros(len(rows), dtype=bool)
    rest = rows
    for k in range(d - 2, -1, -1):
        c = rest % shape[k]
        rest = rest // shape[k]
        row_on |= (c == 0) | (c == shape[k] - 1)
    if np.any(row_on):
        on |= np.repeat(row_on, np.diff(np.r_[starts, len(linear)]))
    if not np.any(on):
        return None
    b = np.flatnonzero(on)
    idx = np.stack([(linear[b] // strides[k]) % shape[k] for k in range(d)], axis=1)
    phib = np.asarray(phi[b], dtype=float)
    signed = bool(np.min(phi) < 0)
    crossed = 0  # face edges (2D: boundary segments) across which φ changes sign
    near = 0  # unsigned φ: boundary nodes within half a spacing of the surface
    faces: List[str] = []
    touched: List[str] = []
    for k in range(d):
        others = [j for j in range(d) if j != k]
        for upper in (False, True):
            sel = idx[:, k] == (shape[k] - 1 if upper else 0)
            if not np.any(sel):
                continue
            touched.append(_face_name(grid, k, upper))
            if signed:
                face = np.full([shape[j] for j in others], np.nan)
                face[tuple(idx[sel][:, j] for j in others)] = phib[sel]
                n = 0
                for a in range(d - 1):
                    lo = np.take(face, np.arange(face.shape[a] - 1), axis=a)
                    hi = np.take(face, np.arange(1, face.shape[a]), axis=a)
                    # (strictly: a surface that only touches the face, φ = 0 at a node and above it around,
                    # was said to cross it "along a curve about 0.105 long")
                    n += int(np.count_nonzero(np.isfinite(lo) & np.isfinite(hi) & ((lo < 0) != (hi < 0))))
                crossed += n
            else:
                close = sel & (np.abs(phib) <= 0.5 * h)
                n = int(np.count_nonzero(close))
                if n and directions is not None:
                    # the closest points of those nodes: on the face or beyond it where the surface
                    # goes on outside the box, all inside where it only comes near
                    bound = float((grid.upper if upper else grid.lower)[k])
                    x_k = float(grid.lower[k]) + idx[close][:, k] * h
                    cp_k = x_k - np.abs(phib[close]) * np.asarray(directions[b[close], k], dtype=float)
                    slack = 1e-9 * h
                    beyond = cp_k >= bound - slack if upper else cp_k <= bound + slack
                    if not np.any(beyond):
                        n = 0
                near += n
            if n:
                faces.append(_face_name(grid, k, upper))
    surface_cut = bool(faces)
    out: Dict[str, Any] = {
        "surface_cut": surface_cut,
        "faces": faces if surface_cut else touched,
        "inner_on_boundary": int(np.count_nonzero(np.abs(phib) <= inner_width)),
        "gap": float(np.min(np.abs(phib))),
    }
    if d == 3:
        out["cut_length"] = (crossed * h * math.pi / 4) if signed else near * h
    else:
        # a crossing of a boundary line is one sign change (or about one node within h/2)
        out["cut_points"] = crossed if signed else near
    return out


#: The probe of :func:`looks_bounded`: the box scaled by this factor about its centre, a lattice of
#: ``PROBE_POINTS`` points per side on each of its faces.
PROBE_SCALE = 3.0
PROBE_POINTS = 9


def _probe_points(grid: Grid) -> np.ndarray:
    """A lattice on the faces of the grid box scaled by ``PROBE_SCALE`` about its centre."""
    lo, hi = np.asarray(grid.lower, float), np.asarray(grid.upper, float)
    centre, half = 0.5 * (lo + hi), 0.5 * PROBE_SCALE * (hi - lo)
    d = grid.ndim
    t = np.linspace(-1.0, 1.0, PROBE_POINTS)
    lattice = np.stack(np.meshgrid(*([t] * (d - 1)), indexing="ij"), axis=-1).reshape(-1, d - 1)
    faces = []
    for k in range(d):
        for side in (-1.0, 1.0):
            p = np.insert(lattice, k, side, axis=1)
            faces.append(centre + half * p)
    return np.concatenate(faces)


def looks_bounded(surface: Any, grid: Grid) -> bool:
    """Whether a surface that crosses the grid box is a bounded one cut by the box (warned), rather
    than one meant to go on beyond it (a plane or a line given as a level set: the values are right
    for the part inside, and the paper's own examples are such). The library's surfaces and meshes
    are bounded; a φ callable whose sign does not change on the faces of the box scaled by
    ``PROBE_SCALE`` closes within it; a closest-point map whose closest points of those faces lie
    within the box scaled by ``PROBE_SCALE - 1``; a sampled φ says nothing beyond the box (not
    warned)."""
    if type(surface).__module__.startswith("tubesweep.surfaces"):
        return True
    p = _probe_points(grid)
    try:
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            if isinstance(surface, LevelSet):
                if surface._fn is None:
                    return False
                phi = np.asarray(surface._fn(p), dtype=float).reshape(-1)
                return bool(np.all(np.isfinite(phi)) and (np.all(phi > 0) or np.all(phi < 0)))
            if isinstance(surface, ClosestPoint):
                cp = np.asarray(surface.closest_point(p), dtype=float)
                lo, hi = np.asarray(grid.lower, float), np.asarray(grid.upper, float)
                centre, half = 0.5 * (lo + hi), 0.5 * (PROBE_SCALE - 1.0) * (hi - lo)
                return bool(np.all(np.isfinite(cp)) and np.all(np.abs(cp - centre) <= half))
    except Exception:  # φ or the map undefined far from the box: nothing known
        return False
    return False


def cut_extent(cut: Dict[str, Any]) -> str:
    """Where the surface crosses the box's boundary, for a message: along a curve of its length
    (3D) or at its points (2D)."""
    if "cut_length" in cut:
        return f"along a curve about {cut['cut_length']:.3g} long"
    return f"at {cut['cut_points']} point{'s' if cut['cut_points'] != 1 else ''}"


def warn_box_cut(cut: Optional[Dict[str, Any]], inner_points: int, surface: Any, grid: Grid) -> None:
    """The warning for a bounded surface that leaves the grid box, with how much is cut."""
    if cut is None or not cut["surface_cut"] or not looks_bounded(surface, grid):
        return
    where = ", ".join(cut["faces"])
    size = cut_extent(cut)
    share = cut["inner_on_boundary"] / max(inner_points, 1)
    warnings.warn(
        f"the grid box cuts the surface: it crosses the box's boundary {where} {size} ({share:.1%} of the inner "
        "tube's nodes lie on the boundary). The distances are those of the part of the surface inside the box: "
        "paths through the part outside it are not found. Enlarge the box to hold the whole surface with a margin of "
        "outer·Δx if it goes on beyond; sol.stats.box_cut records the cut",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )


def box_reason(cut: Optional[Dict[str, Any]], reason: str, outer_width: float) -> str:
    """``order=2``'s refusal of the geometry, naming the grid box when the box cuts the tube (its
    nodes on the boundary lack the neighbours the Hessian of φ needs, which the core reports as φ
    not being a distance or the grid being too coarse)."""
    found = re.search(r"(\d+) inner-tube nodes lack a neighbour", reason)
    if cut is None or found is None:
        return reason
    lacking = int(found.group(1))
    where = ", ".join(cut["faces"])
    what = "the surface crosses it" if cut["surface_cut"] else f"the surface comes within {cut['gap']:.3g} of it"
    text = (
        f"order=2: the grid box cuts the tube at {where} ({what}): {lacking} inner-tube nodes on the boundary lack "
        f"the neighbours outside the box that the second-order geometry needs. Enlarge the box so that it holds the "
        f"surface with a margin of outer·Δx = {outer_width:.3g}, or use order=1"
    )
    if lacking > cut["inner_on_boundary"]:
        # nodes inside the box lack neighbours too: the geometry check's own reason holds for them
        text += f". Besides: {reason}"
    return text
