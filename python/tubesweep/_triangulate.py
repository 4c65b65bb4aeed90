"""A triangle mesh (or polyline) of the surface carrying the solution, for export and pictures:
:func:`triangulate` (public as ``tubesweep.triangulate`` and ``tubesweep.output.triangulate``),
used by :mod:`tubesweep.output` and :mod:`tubesweep._plot`."""

from __future__ import annotations

from typing import Any, Optional, Tuple

import numpy as np

from ._validate import real_array, whole_indices
from .surface import LevelSet


#: File suffixes :func:`export` writes.
__all__ = ["triangulate"]


def _need(module: str, extra: str, what: str) -> Any:
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise ImportError(
            f"{what} needs the optional package {module.split('.')[0]!r}: pip install 'tubesweep[{extra}]', "
            f"or pip install '.[{extra}]' in a checkout"
        ) from None


# ---------------------------------------------------------------------------------------------
# triangulation
# ---------------------------------------------------------------------------------------------
def _band_box(sol: Any) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The band's bounding sub-box: index origin, shape, and the band nodes' φ on it (NaN off band)."""
    idx = sol.indices
    lo = idx.min(0)
    shape = idx.max(0) - lo + 1
    arr = np.full(tuple(shape), np.nan)
    arr[tuple((idx - lo).T)] = sol.phi
    return lo, shape, arr


def _checked_mesh(mesh: Tuple[Any, Any]) -> Tuple[np.ndarray, np.ndarray]:
    """A user's ``mesh=(vertices, faces)``: finite vertices ``(n, 2 or 3)`` and faces ``(m, 2 or 3)``
    of whole numbers indexing them, so that no written file points at a vertex that is not there."""
    try:
        v_in, f_in = mesh
    except (TypeError, ValueError):
        raise ValueError("mesh must be a pair (vertices (n, 3), faces (m, 3))") from None
    v = real_array(v_in, "mesh vertices")
    if v.ndim != 2 or v.shape[1] not in (2, 3) or not np.all(np.isfinite(v)):
        raise ValueError(
            f"mesh vertices must be finite coordinates of shape (n, 2) or (n, 3); got shape {v.shape}"
            + ("" if v.ndim != 2 or np.all(np.isfinite(v)) else " with NaN or inf")
        )
    f = np.asarray(f_in)
    if f.ndim != 2 or f.shape[1] not in (2, 3, 4) or (f.size and not np.issubdtype(f.dtype, np.number)):
        raise ValueError(
            f"mesh faces must be an integer array of shape (m, 3) (or (m, 4) quads, (m, 2) segments); "
            f"got shape {f.shape}"
        )
    if len(v) == 0 or f.size == 0:
        raise ValueError(f"mesh must have vertices and faces; got {len(v)} vertices and {len(f)} faces")
    try:
        f = whole_indices(f, "mesh faces")
    except TypeError as e:
        raise ValueError(str(e)) from None
    if f.size and (f.min() < 0 or f.max() >= len(v)):
        bad = int(f.min()) if f.min() < 0 else int(f.max())
        raise ValueError(f"mesh faces index vertex {bad}, but there are vertices 0..{len(v) - 1}")
    return v, f


def check_surface_solution(sol: Any, what: str) -> None:
    """Refuses anything but a solution on a surface (:func:`tubesweep.solve`, ``Tube.solve``) as
    ``sol`` of ``what``: a ``ts.travel_time`` box solution or a number raised AttributeError."""
    if hasattr(sol, "surface") and hasattr(sol, "on_mesh"):
        return
    box = hasattr(sol, "values") and hasattr(sol, "grid")
    raise TypeError(
        f"{what}: sol must be a solution on a surface (from ts.solve or Tube.solve); got {type(sol).__name__}"
        + (
            ": a solution over the whole box has no surface to mesh; save its values (np.save(path, sol.values)) "
            "or solve on a surface"
            if box
            else ""
        )
    )


def triangulate(sol: Any, *, mesh: Optional[Tuple[Any, Any]] = None) -> Tuple[np.ndarray, np.ndarray]:
    """A mesh of the surface a solution lives on.

    The surface's own ``triangulation()`` where it has one (the input mesh of
    :func:`~tubesweep.surfaces.from_mesh`, the library's surfaces). Otherwise a level set is
    contoured at φ = 0 inside the band: marching cubes (scikit-image) in 3D, with φ's sign
    continued from the nearest band node off the band (so that the band's edge makes no spurious
    pieces), marching squares in 2D.

    Parameters
    ----------
    sol : Solution
        A :func:`tubesweep.solve` result.
    mesh : (vertices, faces), optional
        Use this mesh instead (checked and returned).

    Returns
    -------
    vertices : numpy.ndarray
        ``(n, d)`` points.
    cells : numpy.ndarray
        ``(m, 3)`` triangles in 3D, ``(m, 2)`` line segments in 2D.

    Raises
    ------
    TypeError
        If ``sol`` is not a solution on a surface (a ``ts.travel_time`` box solution, say).
    ValueError
        For a surface with neither a triangulation nor a level set (a bare closest-point function:
        pass ``mesh=``), or a ``mesh`` whose faces index vertices that are not there.
    ImportError
        If contouring a level set needs scikit-image and it is not installed.

    Examples
    --------
    >>> import tubesweep as ts
    >>> s = ts.surfaces.Sphere(0.5)
    >>> sol = ts.solve(s, ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41)), [s.default_source])
    >>> v, f = ts.triangulate(sol)
    >>> v.shape[1], f.shape[1]
    (3, 3)
    """
    if mesh is not None:
        return _checked_mesh(mesh)
    check_surface_solution(sol, "triangulate")
    surf = sol.surface
    tri = getattr(surf, "triangulation", None)
    if callable(tri):
        v, f = tri()
        return np.asarray(v, dtype=float), np.asarray(f, dtype=np.int64)
    if not isinstance(surf, LevelSet):
        raise ValueError(
            f"cannot triangulate a {type(surf).__name__}: it is not a level set and has no triangulation(); "
            "pass mesh=(vertices, faces) of the surface"
        )
    grid = sol.grid
    h = grid.spacing
    lo, shape, arr = _band_box(sol)
    inb = np.isfinite(arr)
    d = grid.ndim
    origin = grid.lower + h * lo
    if d == 3:
        measure = _need("skimage.measure", "mesh", "triangulating a level set")
        ndimage = _need("scipy.ndimage", "mesh", "triangulating a level set")
        # off the band, continue φ's sign from the nearest band node, so that the only zero
        # crossings are those of the surface
        _, nearest = ndimage.distance_transform_edt(~inb, return_indices=True)
        sign = np.sign(arr[tuple(nearest)])
        vol = np.where(inb, arr, sign * (sol.outer + 2) * h)
        del nearest
        verts, faces, _, _ = measure.marching_cubes(vol, level=0.0, spacing=(h, h, h), allow_degenerate=False)
        return verts + origin, faces.astype(np.int64)
    measure = _need("skimage.measure", "mesh", "contouring a level set")
    img = np.where(inb, arr, np.nan)
    pieces = measure.find_contours(img, 0.0)
    verts, segs, n0 = [], [], 0
    for c in pieces:
        if len(c) < 2:
            continue
        closed = np.allclose(c[0], c[-1])
        pts = c[:-1] if closed else c
        m = len(pts)
        e = (
            np.stack([np.arange(m), np.arange(1, m + 1) % m], axis=1)
            if closed
            else np.stack([np.arange(m - 1), np.arange(1, m)], axis=1)
        )
        verts.append(pts * h + origin)
        segs.append(e + n0)
        n0 += m
    if not verts:
        raise ValueError("found no zero level set of φ in the band")
    return np.concatenate(verts), np.concatenate(segs).astype(np.int64)
