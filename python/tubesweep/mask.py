"""Surfaces from voxel masks (segmentations): :meth:`tubesweep.LevelSet.from_mask`.

A mask gives each grid node a side, inside (True / 1) or outside (False / 0). The surface is the
zero level set of ``0.5 − mask`` interpolated multilinearly between the nodes — half-way between an
inside and an outside node on every grid edge that joins them, much as marching cubes places it — and
the level set function in the band is the signed distance to it, found by the sub-cell re-distancing
of :mod:`tubesweep.redistance` (``LevelSet(phi, redistance=True)``).

A mask knows its surface only to about half a voxel: on the sphere of radius 0.5 in [−1, 1]³ the
travel times along a meridian are off by about one grid spacing at N = 61 and half of one at
N = 121 (falling at first order), and a Gaussian smoothing of the mask (``smooth=σ`` in voxels)
removes the voxel steps at the price of moving curved parts inward by about ``σ² κ / 2`` (κ the sum of the principal
curvatures, ``σ`` in length units): docs/surfaces.md has the measured figures.
"""

from __future__ import annotations

import os

import re
import warnings
from typing import Any, Optional, Tuple

import numpy as np

from ._validate import real_scalar
from ._warn import user_stacklevel
from .grid import Grid

__all__ = ["level_set_function_of_mask"]


def _checked_mask(mask: Any, grid: Grid) -> np.ndarray:
    """The mask as a boolean array of the grid's shape, or a ValueError naming what is wrong."""
    if not isinstance(grid, Grid):
        raise TypeError(
            f"grid must be a ts.Grid (the grid whose nodes are the mask's voxels); got {type(grid).__name__}"
        )
    if isinstance(mask, (str, bytes, os.PathLike)):
        # ("mask has shape ()" before: a helper's review)
        raise TypeError(
            f"mask must be an array of the grid's shape; got the path {os.fspath(mask)!r}: load it first "
            "(np.load for .npy, or an image reader such as skimage.io.imread or nibabel for a volume)"
        )
    arr = np.asarray(mask)
    if arr.shape != grid.shape:
        raise ValueError(
            f"mask has shape {arr.shape} but the grid has shape {grid.shape}: the mask's voxels are the grid's nodes; "
            "build the grid with ts.Grid(lower, upper, mask.shape) where upper = lower + (mask.shape − 1)·voxel size "
            "(a padded mask moves lower and upper out by the padding, keeping the voxel size)"
        )
    if arr.dtype == bool:
        return arr
    if not (np.issubdtype(arr.dtype, np.integer) or np.issubdtype(arr.dtype, np.floating)):
        raise ValueError(
            f"mask must be a boolean array or hold only 0 and 1; got dtype {arr.dtype}. For a label image pass "
            "labels == k"
        )
    inside = arr == 1
    if not np.all(inside | (arr == 0)):
        bad = tuple(int(i) for i in np.argwhere(~(inside | (arr == 0)))[0])
        raise ValueError(
            f"mask must hold only 0 and 1 (or be boolean); got {arr[bad].item()!r} at index {bad}. For a label image "
            "pass labels == k; for a soft mask or a probability map p in [0, 1] pass "
            "ts.LevelSet(0.5 - p, redistance=True)"
        )
    return inside


def _touching_the_box(inside: np.ndarray) -> Any:
    """The index of an inside voxel on the box's faces, or None."""
    for axis in range(inside.ndim):
        for end in (0, -1):
            face = np.take(inside, end, axis=axis)
            if face.any():
                at = list(np.argwhere(face)[0])
                at.insert(axis, 0 if end == 0 else inside.shape[axis] - 1)
                return tuple(int(i) for i in at)
    return None


def _thinnest_extent(inside: np.ndarray) -> int:
    """Voxels across the object's bounding box along its thinnest axis."""
    spans = []
    for axis in range(inside.ndim):
        others = tuple(k for k in range(inside.ndim) if k != axis)
        occupied = np.flatnonzero(inside.any(axis=others))
        spans.append(int(occupied[-1] - occupied[0]) + 1)
    return min(spans)


def level_set_function_of_mask(mask: Any, grid: Grid, smooth: float = 0.0) -> np.ndarray:
    """The φ of :meth:`tubesweep.LevelSet.from_mask` (see there): ``0.5 − mask``, smoothed, negative
    inside, after the checks of the mask."""
    inside = _checked_mask(mask, grid)
    sigma = real_scalar(smooth, "smooth", "a width in voxels (0 for none)")
    if not (np.isfinite(sigma) and sigma >= 0):
        raise ValueError(f"smooth must be a Gaussian width in voxels, 0 or more; got {smooth}")
    count = int(np.count_nonzero(inside))
    if count == 0 or count == inside.size:
        raise ValueError(
            f"mask is all {'True' if count else 'False'}: there is no surface between inside and outside voxels. "
            "Pass a mask that holds both (True or 1 inside the object)"
        )
    touching = _touching_the_box(inside)
    if touching is not None:
        raise ValueError(
            f"mask: the object touches the grid's boundary (an inside voxel at index {touching}), so its surface "
            "is cut open by the box there. Pad the mask with outside voxels, e.g. np.pad(mask, 6), and widen the grid "
            "by as many spacings on each side"
        )
    extent = _thinnest_extent(inside)
    if sigma > extent:
        # the smoothed mask is at most erf(t/(2√2σ)) < 1/2 for an object t voxels thick once
        # σ > 0.75t: refused before a filter that wide runs (its cost grows with σ)
        raise ValueError(
            f"smooth = {sigma:g} voxels erases the object: it is only {extent} voxels across along its thinnest "
            "axis, and a Gaussian wider than that leaves no voxel above one half. Use a smooth of a few voxels"
        )
    if sigma > 0:
        try:
            from scipy.ndimage import gaussian_filter
        except ImportError:  # pragma: no cover - scipy is a test dependency
            raise ImportError(
                "smooth needs the optional package 'scipy': pip install 'tubesweep[mesh]', "
                "or pip install '.[mesh]' in a checkout"
            ) from None
        phi = 0.5 - gaussian_filter(inside.astype(np.float64), sigma=sigma, mode="nearest")
        if not (np.any(phi <= 0) and np.any(phi > 0)):
            raise ValueError(
                f"smooth = {sigma:g} voxels erases the object (no voxel stays above one half after smoothing): "
                "use a smaller smooth, or none"
            )
        warn_one_voxel_parts_smoothed_away(inside, phi <= 0, grid, sigma)
    else:
        phi = np.where(inside, -0.5, 0.5)
    warn_small_cavities(phi <= 0, grid)
    return phi


#: Cavities (outside voxels enclosed by the object) of at most this many voxels, within
#: :data:`CAVITY_REACH` spacings of the object's outer surface, are warned about: a surface of their
#: own whose tube (2 + 4 spacings around it) meets the outer surface's and the other cavities', so
#: that fronts run through the object. A ball of radius 0.5 at N = 53 with 24 single voxels left
#: out of it within 0.4 of its centre: the antipode 1.20 from the source instead of 1.52 (1.05 at
#: N = 41, the straight chord), converged, warned only of narrow gaps and creases (a review).
SMALL_CAVITY = 64
#: ... the reach: two tubes of the default outer width (4 spacings) meet across 8.
CAVITY_REACH = 8.0


def small_cavities(inside: np.ndarray) -> Tuple[int, int, Optional[Tuple[int, ...]]]:
    """The outside voxels of ``inside`` that no path of outside voxels (through faces, edges or
    corners: a pit of a rough surface that opens to the outside at an edge is no cavity) joins to
    the box's faces, in connected parts (cavities): how many parts of at most
    :data:`SMALL_CAVITY` voxels lie within :data:`CAVITY_REACH` spacings of the outside, how many
    parts in all, and a voxel of the first such part. (0, 0, None) without scipy, which finds
    them."""
    try:
        from scipy import ndimage
    except ImportError:  # pragma: no cover - scipy is a test dependency
        return 0, 0, None
    labels, count = ndimage.label(~inside, structure=np.ones((3,) * inside.ndim, dtype=bool))
    if count <= 1:
        return 0, 0, None
    faces = np.zeros(count + 1, dtype=bool)
    for axis in range(inside.ndim):
        for end in (0, -1):
            faces[np.take(labels, end, axis=axis)] = True
    faces[0] = False
    enclosed = np.flatnonzero(~faces[1:]) + 1
    if enclosed.size == 0:
        return 0, 0, None
    sizes = np.bincount(labels.ravel(), minlength=count + 1)
    small = enclosed[sizes[enclosed] <= SMALL_CAVITY]
    if small.size == 0:
        return 0, int(enclosed.size), None
    # each small cavity's nearest voxel to the outside (the outer surface's side)
    far = ndimage.distance_transform_edt(~faces[labels])
    nearest = ndimage.minimum(far, labels, small)
    near = small[np.asarray(nearest) <= CAVITY_REACH]
    if near.size == 0:
        return 0, int(enclosed.size), None
    at = tuple(int(i) for i in np.argwhere(labels == near[0])[0])
    return int(near.size), int(enclosed.size), at


def warn_small_cavities(inside: np.ndarray, grid: Grid) -> None:
    """A RuntimeWarning for the mask's small cavities near its outer surface
    (:func:`small_cavities`), with how many and where, and the cure."""
    small, enclosed, at = small_cavities(inside)
    if not small or at is None:
        return
    where = ", ".join(f"{c:.3g}" for c in np.asarray(grid.lower, dtype=float) + np.asarray(at) * grid.spacing)
    warnings.warn(
        f"mask: {small} cavit{'y' if small == 1 else 'ies'} of at most {SMALL_CAVITY} voxels inside the object within "
        f"{CAVITY_REACH:g} voxels of its outer surface ({enclosed} enclosed in all; e.g. at index {at}, near "
        f"({where})): outside voxels that no path of outside voxels joins to the box's faces. Each is a surface of its "
        "own, whose tube meets the outer surface's and the other cavities', so fronts can run through the object there "
        "and distances come out short. If they are holes of the segmentation, fill them: "
        "LevelSet.from_mask(scipy.ndimage.binary_fill_holes(mask), grid) (smooth=1 closes those of one voxel)",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )


def _one_voxel_sheet(inside: np.ndarray, after: np.ndarray) -> Tuple[int, Optional[Tuple[int, ...]]]:
    """The voxels of ``inside`` that lie between two of the other side along an axis (a gap one
    voxel wide in the object, or a wall one voxel thick) and that ``after`` puts on the other side,
    where they form a sheet (at least 2(d − 1) such neighbours: a crease's ring has 2); their
    number and one of them."""
    sheet = np.zeros(inside.shape, dtype=bool)
    for axis in range(inside.ndim):  # (the object does not touch the box: rolling wraps nothing in)
        sheet |= inside & ~np.roll(inside, 1, axis) & ~np.roll(inside, -1, axis)
    sheet &= after != inside
    neighbours = np.zeros(inside.shape, dtype=np.int8)
    for axis in range(inside.ndim):
        neighbours += np.roll(sheet, 1, axis).astype(np.int8) + np.roll(sheet, -1, axis).astype(np.int8)
    sheet &= neighbours >= 2 * (inside.ndim - 1)
    count = int(np.count_nonzero(sheet))
    return count, (tuple(int(i) for i in np.argwhere(sheet)[0]) if count else None)


def warn_one_voxel_parts_smoothed_away(inside: np.ndarray, smoothed: np.ndarray, grid: Grid, sigma: float) -> None:
    """A RuntimeWarning where the smoothing closed a gap one voxel wide (a slot: the smoothed mask
    stays above one half across it) or opened a wall one voxel thick, over a sheet of voxels: the
    surface then has no gap or no wall there, and paths run across it (a ball with a slot one
    voxel wide through half of it, N = 61, ``smooth=1``: 29 spacings short beyond the slot, points
    in it off the band; a helper's review)."""
    for what, count_at in (
        ("closed a gap one voxel wide", _one_voxel_sheet(~inside, ~smoothed)),
        ("opened a wall one voxel thick", _one_voxel_sheet(inside, smoothed)),
    ):
        count, at = count_at
        if at is None:
            continue
        where = ", ".join(f"{c:.3g}" for c in np.asarray(grid.lower, dtype=float) + np.asarray(at) * grid.spacing)
        warnings.warn(
            f"smooth = {sigma:g} voxels {what} over {count} voxels (e.g. at index {at}, near ({where})): the smoothed "
            "surface has no such gap or wall there, and paths run across it. Pass a smaller smooth (a one-voxel part "
            "keeps its side up to smooth = 0.75), or smooth=0 (the voxels' steps, first order)",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )


#: What the second-order geometry says of a φ whose |∇φ| is off 1 (``tubesweep_core::second_order``'s
#: ``check_geometry_of``): advice that a re-distanced φ has taken already.
PASS_REDISTANCE = "φ is not a signed distance there: pass redistance=True"
_REDISTANCE_CURE = re.compile(r"ts\.LevelSet\(phi, redistance=True\) re-distances φ( \(or divide φ by [^)]*\))?")

#: ... and what :func:`mask_advice` says instead for a re-distanced φ (``_fallback`` reads it).
ROUGH_REDISTANCED = "φ was re-distanced already (redistance=True) and still is not a distance at the grid's scale"


def mask_advice(surface: Any, reason: str) -> str:
    """``reason`` (why ``order=2`` does not apply) with the advice for a raw voxel mask: its
    staircase is the unresolved curvature, and smoothing it (``smooth=1``) is the fix, not a finer
    grid (docs/surfaces.md, "From a voxel mask"). For a re-distanced φ (a mask too), the advice to
    re-distance φ becomes what does help: its zero level set is rough at the grid's scale (a
    sphere's φ with noise of a spacing at N = 81 was told to "pass redistance=True", which it had;
    a helper's review)."""
    if getattr(surface, "redistance", False):
        reason = reason.replace(PASS_REDISTANCE, "the re-distanced φ is not a signed distance there")
        reason = _REDISTANCE_CURE.sub(
            f"{ROUGH_REDISTANCED}: its zero level set is rough at the grid's scale (noise of about a spacing or more); "
            "smoothing φ over a spacing or two before re-distancing (scipy.ndimage.gaussian_filter(phi, 1)) or a "
            "coarser grid",
            reason,
        )
    if getattr(surface, "_mask_smoothing", None) != 0.0 or "curvature the tube does not resolve" not in reason:
        return reason
    return (
        reason + ". This surface is a raw voxel mask, whose staircase is that curvature at any grid: "
        "LevelSet.from_mask(mask, grid, smooth=1) smooths it over a voxel and runs second order on objects many voxels "
        "across (a ball 10 voxels in radius; not one of 5, whose curvature the grid barely resolves)"
    )
