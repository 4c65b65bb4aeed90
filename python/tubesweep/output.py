"""Results as meshes, files and pictures.

* :func:`triangulate` — a mesh of the surface a solution lives on: the surface's own
  ``triangulation()`` (meshes read with :func:`tubesweep.surfaces.from_mesh`, library and
  closest-point surfaces that provide one), otherwise marching cubes (3D) / marching squares (2D)
  of the level set φ = 0 restricted to the band (scikit-image).
* :func:`export` — that mesh with the solution ``u`` as point data, as ``.vtu`` / ``.vtk`` /
  ``.ply`` / ``.obj`` (meshio) or ``.vtp`` (VTK XML PolyData, written here), for ParaView.
* :func:`plot` — a matplotlib :class:`~matplotlib.figure.Figure`: the solution as a colour map,
  iso-distance lines and the sources marked; 2D curves and 3D surfaces. It uses no pyplot
  state, so it displays inline in notebooks and never changes the backend.

Optional dependencies are imported lazily: ``pip install 'tubesweep[mesh]'`` (meshio,
scikit-image) and ``pip install 'tubesweep[plot]'`` (matplotlib).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from xml.sax.saxutils import quoteattr
from typing import Any, Dict, Optional, Sequence, Tuple, Union

import numpy as np

from ._validate import real_array, whole_indices
from .surface import LevelSet

__all__ = ["triangulate", "export", "plot", "read_vtp", "EXPORT_FORMATS"]

#: File suffixes :func:`export` writes.
EXPORT_FORMATS = (".vtu", ".vtp", ".vtk", ".ply", ".obj")


def _need(module: str, extra: str, what: str) -> Any:
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise ImportError(
            f"{what} needs the optional package {module.split('.')[0]!r}: pip install 'tubesweep[{extra}]'"
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


def triangulate(sol: Any, *, mesh: Optional[Tuple[Any, Any]] = None) -> Tuple[np.ndarray, np.ndarray]:
    """A mesh of the surface of a solution: ``(vertices (n, d), cells)``.

    Cells are triangles (m, 3) in 3D and line segments (m, 2) in 2D.

    Parameters
    ----------
    sol : Solution
    mesh : (vertices, faces), optional
        Use this mesh instead (it is returned unchanged).

    The surface's own ``triangulation()`` is used when it has one (the input mesh for
    :func:`~tubesweep.surfaces.from_mesh`). Otherwise a level set is contoured at φ = 0 inside
    the band: marching cubes (scikit-image, Lewiner) in 3D, with φ's sign continued from the
    nearest band node off the band (so the band's edge makes no spurious pieces), marching squares
    in 2D (off-band nodes are NaN there). A surface with neither (a bare closest-point function) needs ``mesh=``.
    """
    if mesh is not None:
        return _checked_mesh(mesh)
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


# ---------------------------------------------------------------------------------------------
# export
# ---------------------------------------------------------------------------------------------
def _write_vtp(path: Path, points: np.ndarray, cells: np.ndarray, point_data: Dict[str, np.ndarray]) -> None:
    """VTK XML PolyData (ASCII): polygons for triangles, lines for segments."""
    n, m, k = len(points), len(cells), cells.shape[1]
    kind = "Polys" if k >= 3 else "Lines"

    def arr(a: np.ndarray, fmt: str) -> str:
        return "\n".join(" ".join(fmt % x for x in row) for row in np.atleast_2d(a).reshape(len(a), -1))

    # written to a temporary file next to the target (through symlinks) and renamed over it when
    # complete, with the target's mode: an error half-way leaves no truncated file behind. A
    # read-only target is refused as open() would; where no file can be created next to it (a
    # read-only directory holding a writable file), the file is written in place.
    import os
    import shutil
    import tempfile

    target = Path(os.path.realpath(path))
    if target.is_dir():
        raise IsADirectoryError(f"{path} is a directory")
    if target.exists() and not os.access(target, os.W_OK):
        raise PermissionError(f"{path} is not writable")
    try:
        fd, name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=target.parent)
    except PermissionError:
        fd, name = -1, ""
    part = Path(name) if name else target
    if fd >= 0:
        os.close(fd)
    try:
        with open(part, "w") as fh:
            fh.write(
                '<?xml version="1.0"?>\n<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian">\n<PolyData>\n'
            )
            fh.write(
                f'<Piece NumberOfPoints="{n}" NumberOfVerts="0" NumberOfLines="{m if kind == "Lines" else 0}" '
                f'NumberOfStrips="0" NumberOfPolys="{m if kind == "Polys" else 0}">\n'
            )
            names = list(point_data)
            fh.write(f"<PointData Scalars={quoteattr(str(names[0]))}>\n" if names else "<PointData>\n")
            for name, a in point_data.items():
                comps = f' NumberOfComponents="{a.shape[1]}"' if a.ndim == 2 else ""
                fh.write(
                    f'<DataArray type="Float64" Name={quoteattr(str(name))}{comps} format="ascii">\n'
                    f"{arr(a, '%.17g')}\n</DataArray>\n"
                )
            fh.write("</PointData>\n<Points>\n")
            fh.write(
                f'<DataArray type="Float64" NumberOfComponents="3" format="ascii">\n{arr(points, "%.17g")}\n</DataArray>\n'
            )
            fh.write(f"</Points>\n<{kind}>\n")
            fh.write(f'<DataArray type="Int64" Name="connectivity" format="ascii">\n{arr(cells, "%d")}\n</DataArray>\n')
            fh.write(
                f'<DataArray type="Int64" Name="offsets" format="ascii">\n{arr(np.arange(1, m + 1) * k, "%d")}\n</DataArray>\n'
            )
            fh.write(f"</{kind}>\n</Piece>\n</PolyData>\n</VTKFile>\n")
        if part != target:
            if target.exists():
                shutil.copymode(target, part)
            else:
                os.chmod(part, 0o666 & ~_umask())
            os.replace(part, target)
    finally:
        if part != target:
            part.unlink(missing_ok=True)


def _umask() -> int:
    """The process's file-creation mask (mkstemp creates files 0600; a new export gets the mode
    open() would give it)."""
    import os

    mask = os.umask(0)
    os.umask(mask)
    return mask


def read_vtp(path: Union[str, Path]) -> Tuple[np.ndarray, np.ndarray, Dict[str, np.ndarray]]:
    """Reads an ASCII ``.vtp`` written by :func:`export`: points (n, 3), cells, point data."""
    try:
        root = ET.parse(str(path)).getroot()
    except ET.ParseError as e:
        raise ValueError(f"{path}: not an XML VTK file ({e})") from None
    piece = root.find("PolyData/Piece")
    if piece is None:
        raise ValueError(f"{path}: not a VTK PolyData file")

    def values(el: Any, dtype: Any) -> np.ndarray:
        return np.array((el.text or "").split(), dtype=dtype)

    points = values(piece.find("Points/DataArray"), float).reshape(-1, 3)
    kind = "Polys" if int(piece.get("NumberOfPolys", "0")) > 0 else "Lines"
    conn = offs = None
    for el in piece.findall(f"{kind}/DataArray"):
        if el.get("Name") == "connectivity":
            conn = values(el, np.int64)
        elif el.get("Name") == "offsets":
            offs = values(el, np.int64)
    if conn is None or offs is None:
        raise ValueError(f"{path}: no {kind} connectivity")
    k = int(offs[0]) if len(offs) else 3
    data = {}
    for el in piece.findall("PointData/DataArray"):
        a = values(el, float)
        data[el.get("Name")] = a.reshape(-1, int(el.get("NumberOfComponents"))) if el.get("NumberOfComponents") else a
    return points, conn.reshape(-1, k), data


def export_format(path: Union[str, Path], curve: bool = False) -> str:
    """The format of an export path (its suffix, lower case), or a ValueError naming the ones known;
    ``curve``: the mesh is of line cells (a 2D curve), which ``.ply`` cannot hold."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in EXPORT_FORMATS:
        raise ValueError(
            f"export: unknown format {path.suffix!r} of {str(path)!r}; use one of {', '.join(EXPORT_FORMATS)}"
        )
    if curve and suffix == ".ply":
        raise ValueError("export: .ply holds surfaces only; write a 2D curve as .vtu, .vtp or .vtk")
    return suffix


def export(
    sol: Any,
    path: Union[str, Path],
    *,
    mesh: Optional[Tuple[Any, Any]] = None,
    point_data: Optional[Dict[str, Any]] = None,
) -> Path:
    """Writes the surface of ``sol`` with the solution ``u`` at its vertices, for ParaView.

    Parameters
    ----------
    sol : Solution
    path : str or Path ending in ``.vtu``, ``.vtp``, ``.vtk``, ``.ply`` or ``.obj``
        ``.vtp`` is VTK XML PolyData written here; the others go through meshio
        (``pip install 'tubesweep[mesh]'``). ``.obj`` keeps no point data.
    mesh : (vertices, faces), optional
        The mesh to write instead of :func:`triangulate`'s.
    point_data : dict, optional
        Further per-vertex arrays to write beside ``u``.

    ``u`` is :meth:`Solution.on_mesh` at the vertices (``inf`` where never reached becomes NaN).
    With several sources and an isotropic Hamiltonian, ``nearest_source``
    (:meth:`Solution.nearest_source` at the vertices, -1 where no front arrives) is written too.
    2D curves are written as line cells with z = 0.
    """
    path = Path(path)
    suffix = export_format(path)
    v, cells = triangulate(sol, mesh=mesh)
    u = sol.on_mesh(v)
    u = np.where(np.isfinite(u), u, np.nan)
    data: Dict[str, np.ndarray] = {"u": u}
    if len(sol.sources) > 1 and sol._isotropic:
        data["nearest_source"] = sol.nearest_source(v).astype(float)
    if point_data is not None and not isinstance(point_data, dict):
        raise TypeError(f"point_data must be a dict of name -> values per vertex; got {type(point_data).__name__}")
    for name, a in (point_data or {}).items():
        if not isinstance(name, str) or not name or any(ord(ch) < 32 for ch in name):
            raise ValueError(f"point_data names must be non-empty strings without control characters; got {name!r}")
        if name in data:
            raise ValueError(
                f"point_data[{name!r}]: the name {name!r} is the solution's own field; choose another name"
            )
        a = real_array(a, f"point_data[{name!r}]")
        if a.ndim not in (1, 2) or (a.ndim == 2 and not 1 <= a.shape[1] <= 9):
            raise ValueError(
                f"point_data[{name!r}] must have shape (n,) or (n, k) with k at most 9 (one value or "
                f"vector per vertex); got {a.shape}"
            )
        if a.shape[0] != len(v):
            raise ValueError(f"point_data[{name!r}] has {a.shape[0]} entries but the mesh has {len(v)} vertices")
        data[name] = a
    pts = v if v.shape[1] == 3 else np.column_stack([v, np.zeros(len(v))])
    path.parent.mkdir(parents=True, exist_ok=True)
    if suffix == ".vtp":
        _write_vtp(path, pts, cells, data)
        return path
    meshio = _need("meshio", "mesh", f"writing {suffix} files")
    kind = {2: "line", 3: "triangle", 4: "quad"}[cells.shape[1]]
    export_format(path, curve=kind == "line")
    if suffix == ".ply" and len(pts) < 2**31:
        cells = cells.astype(np.int32)  # PLY has no 64-bit integers
    m = meshio.Mesh(pts, [(kind, cells)], point_data={} if suffix == ".obj" else data)
    meshio.write(str(path), m, file_format={".vtk": "vtk", ".vtu": "vtu", ".ply": "ply", ".obj": "obj"}[suffix])
    return path


# ---------------------------------------------------------------------------------------------
# pictures
# ---------------------------------------------------------------------------------------------
def _iso_segments(v: np.ndarray, f: np.ndarray, u: np.ndarray, level: float) -> Tuple[np.ndarray, np.ndarray]:
    """Marching triangles: segments (s, 2, 3) of the piecewise-linear level line u = level and the
    faces (s,) they cross."""
    uf = u[f] - level
    pts = []
    for i, j in ((0, 1), (1, 2), (2, 0)):
        a, b = uf[:, i], uf[:, j]
        cross = (a * b < 0) & np.isfinite(a) & np.isfinite(b)
        t = np.where(cross, a / np.where(cross, a - b, 1.0), np.nan)
        p = v[f[:, i]] + t[:, None] * (v[f[:, j]] - v[f[:, i]])
        pts.append(np.where(cross[:, None], p, np.nan))
    pts = np.stack(pts, axis=1)  # (m, 3 edges, 3)
    have = np.isfinite(pts[:, :, 0])
    two = have.sum(1) == 2
    seg = pts[two][have[two]].reshape(-1, 2, 3)
    return seg, np.flatnonzero(two)


def _orientation(f: np.ndarray, v: np.ndarray) -> float:
    """+1 / −1 if the faces are consistently oriented with normals pointing out / in (by the sign
    of the enclosed volume), 0 if not consistently oriented (e.g. a Möbius band)."""
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]).astype(np.int64)
    if len(np.unique(e[:, 0] * len(v) + e[:, 1])) != len(e):
        return 0.0
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    vol = float(np.einsum("ij,ij->i", a - v.mean(0), np.cross(b - a, c - a)).sum())
    return 1.0 if vol >= 0 else -1.0


def _nearest_face(points: np.ndarray, centroids: np.ndarray) -> np.ndarray:
    """Index of the face whose centroid is nearest to each point: a k-d tree where SciPy is
    installed, else in chunks of points small enough that the table of differences stays near a
    million entries."""
    if len(points) == 0:
        return np.zeros(0, dtype=np.int64)
    try:
        from scipy.spatial import cKDTree
    except ImportError:
        chunk = max(1, 1_000_000 // (3 * max(len(centroids), 1)))
        out = np.empty(len(points), dtype=np.int64)
        for lo in range(0, len(points), chunk):
            p = points[lo : lo + chunk]
            out[lo : lo + chunk] = np.argmin(((p[:, None, :] - centroids[None, :, :]) ** 2).sum(-1), axis=1)
        return out
    return np.asarray(cKDTree(centroids).query(points)[1], dtype=np.int64)


def plot(
    sol: Any,
    *,
    ax: Any = None,
    mesh: Optional[Tuple[Any, Any]] = None,
    levels: Union[int, Sequence[float]] = 12,
    cmap: str = "viridis",
    views: Sequence[Tuple[float, float]] = ((20.0, -60.0), (20.0, 120.0)),
    title: Optional[str] = None,
    sources: bool = True,
    colorbar: bool = True,
    up: str = "z",
    paths: Optional[Sequence[Any]] = None,
) -> Any:
    """A picture of a solution: a matplotlib :class:`~matplotlib.figure.Figure`.

    2D: the band coloured by ``u``, iso-distance lines, the curve φ = 0 (white) and the sources
    (red stars). 3D: :func:`triangulate`'s surface coloured by ``u`` (shaded), iso-distance lines,
    the sources, one panel per ``(elevation, azimuth)`` in ``views``.

    Parameters
    ----------
    sol : Solution
    ax : matplotlib Axes, optional
        Draw into this axes (a 3D axes for surfaces; only the first view is drawn); default: a
        new figure.
    mesh : (vertices, faces), optional — the surface mesh to draw (3D)
    levels : int or sequence — number of iso-lines, or their values
    cmap, title, sources, colorbar : as usual
    up : {"x", "y", "z"}
        The axis drawn vertically in 3D (many mesh files, the bunny and spot among them, are "y").
    paths : sequence of (P, d) arrays, optional
        Polylines drawn in red over the surface, e.g. :meth:`Solution.geodesic_paths` (in 3D a
        segment on the far side of an oriented surface is drawn faint).

    Returns the Figure (``fig.savefig("u.png")`` to save; it displays inline in notebooks).
    """
    _need("matplotlib", "plot", "plotting")
    from matplotlib.figure import Figure
    from matplotlib import cm, colors as mcolors
    from matplotlib.ticker import MaxNLocator

    grid = sol.grid
    lines = [real_array(q, f"paths[{i}]") for i, q in enumerate(paths or [])]
    for i, q in enumerate(lines):
        if q.ndim != 2 or q.shape[1] != grid.ndim or len(q) < 1:
            raise ValueError(f"paths[{i}] must be an array of shape (P, {grid.ndim}); got shape {q.shape}")
    finite = sol.values[np.isfinite(sol.values)]
    umax = float(finite.max()) if finite.size else 1.0
    if np.ndim(levels) == 0:
        if isinstance(levels, np.ndarray):
            levels = levels.item()
        if (
            isinstance(levels, (bool, np.bool_))
            or not isinstance(levels, (int, float, np.integer, np.floating))
            or not (float(levels).is_integer() and 0 <= levels <= 1000)
        ):
            raise ValueError(
                f"levels must be a number of iso-lines (an integer from 0 to 1000) or a sequence of their values; "
                f"got {levels!r}"
            )
        lv = MaxNLocator(int(levels) + 1).tick_values(0.0, umax) if levels > 0 else np.zeros(0)
    else:
        lv = real_array(levels, "levels").reshape(-1)
        if not np.all(np.isfinite(lv)):
            raise ValueError(f"levels must be finite values of the solution; got {levels!r}")
    lv = lv[(lv > 0) & (lv < umax)]
    import matplotlib

    cmap_obj = matplotlib.colormaps[cmap] if isinstance(cmap, str) else cmap
    norm = mcolors.Normalize(0.0, umax)
    if grid.ndim == 2:
        if ax is None:
            fig = Figure(figsize=(6, 5.4))
            ax = fig.add_subplot(1, 1, 1)
        fig = ax.figure
        dense = sol.to_dense()
        dense = np.where(np.isfinite(dense), dense, np.nan)
        X, Y = grid.meshgrid()
        m = ax.pcolormesh(X, Y, dense, shading="auto", cmap=cmap_obj, norm=norm)
        phi = np.full(grid.size, np.nan)
        phi[sol.linear] = sol.phi
        if isinstance(sol.surface, LevelSet):
            ax.contour(X, Y, phi.reshape(grid.shape), levels=[0.0], colors="w", linewidths=1.0)
        if lv.size:
            ax.contour(X, Y, dense, levels=lv, colors="k", linewidths=0.5)
        for q in lines:
            ax.plot(q[:, 0], q[:, 1], "r-", lw=1.5)
        if sources:
            ax.plot(sol.sources[:, 0], sol.sources[:, 1], "r*", ms=13, mec="k", mew=0.5)
        ax.set_aspect("equal")
        p = sol.points
        lo, hi = p.min(0), p.max(0)
        pad = 0.05 * float((hi - lo).max())
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
        if colorbar:
            fig.colorbar(m, ax=ax, label="u")
        if title:
            ax.set_title(title)
        return fig

    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    if up not in ("x", "y", "z"):
        raise ValueError(f"up must be 'x', 'y' or 'z'; got {up!r}")
    v, f = triangulate(sol, mesh=mesh)
    if f.shape[1] == 4:  # quads as two triangles each: the shading and the iso-lines walk triangles
        f = np.vstack([f[:, [0, 1, 2]], f[:, [0, 2, 3]]])
    u = sol.on_mesh(v)
    # a cyclic permutation of the axes (keeps orientation) puts `up` last, mplot3d's vertical
    perm = {"x": [1, 2, 0], "y": [2, 0, 1], "z": [0, 1, 2]}[up]
    v = v[:, perm]
    src = sol.sources[:, perm]
    tri = v[f]
    finite = np.isfinite(u[f])
    # the mean of the reached corners (NaN for a face none of whose corners was reached)
    uface = np.where(finite, u[f], 0.0).sum(axis=1) / np.where(finite.any(axis=1), finite.sum(axis=1), np.nan)
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    base = cmap_obj(norm(np.nan_to_num(uface, nan=umax)))
    base[~np.isfinite(uface)] = (0.7, 0.7, 0.7, 1.0)
    iso = [_iso_segments(v, f, u, c) for c in lv]
    seg_all = np.concatenate([s for s, _ in iso]) if iso else np.zeros((0, 2, 3))
    seg_face = np.concatenate([t for _, t in iso]) if iso else np.zeros(0, np.int64)
    orient = _orientation(f, v)
    centroids = tri.mean(1)
    # the paths' segments, and the face next to each (to draw those on the far side faint)
    segs = [np.stack([q[:-1], q[1:]], axis=1)[:, :, perm] for q in lines if len(q) >= 2]
    seg = np.concatenate(segs) if segs else np.zeros((0, 2, 3))
    seg_near = _nearest_face(seg.mean(1), centroids)
    src_near = _nearest_face(src, centroids)
    if ax is not None:
        axes = [ax]
        fig = ax.figure
        views = views[:1]
    else:
        fig = Figure(figsize=(5.2 * len(views) + 1.0, 5.0))
        axes = [
            fig.add_subplot(1, len(views), i + 1, projection="3d", computed_zorder=False) for i in range(len(views))
        ]
    ext = np.ptp(v, axis=0)
    for a, (elev, azim) in zip(axes, views):
        e, z = np.radians(elev), np.radians(azim)
        eye = np.array([np.cos(e) * np.cos(z), np.cos(e) * np.sin(z), np.sin(e)])
        light = eye + np.array([0.3, 0.3, 0.6])
        light /= np.linalg.norm(light)
        shade = 0.45 + 0.55 * np.abs(n @ light)
        fc = base.copy()
        fc[:, :3] *= shade[:, None]
        a.add_collection3d(Poly3DCollection(tri, facecolors=fc, edgecolors=fc, linewidths=0.2, zorder=1))
        # iso-lines drawn over the surface; on an oriented mesh only those on faces that face the eye
        seen = (n[seg_face] @ eye) * orient > 0 if orient != 0 else np.ones(len(seg_face), bool)
        if np.any(seen):
            a.add_collection3d(Line3DCollection(seg_all[seen], colors="k", linewidths=0.6, zorder=2))
        if len(seg):
            front = (n[seg_near] @ eye) * orient >= 0 if orient != 0 else np.ones(len(seg), bool)
            for sel, alpha in ((front, 1.0), (~front, 0.3)):
                if np.any(sel):
                    a.add_collection3d(Line3DCollection(seg[sel], colors="r", linewidths=1.6, alpha=alpha, zorder=3))
        if sources:
            # a source on the far side of an oriented mesh is drawn faint
            front = (n[src_near] @ eye) * orient >= 0 if orient != 0 else np.ones(len(src_near), bool)
            for sel, alpha in ((front, 1.0), (~front, 0.3)):
                if np.any(sel):
                    a.scatter(
                        *src[sel].T,
                        c="r",
                        marker="*",
                        s=160,
                        edgecolors="k",
                        linewidths=0.5,
                        depthshade=False,
                        zorder=3,
                        alpha=alpha,
                    )
        lo, hi = v.min(0), v.max(0)
        a.set_xlim(lo[0], hi[0])
        a.set_ylim(lo[1], hi[1])
        a.set_zlim(lo[2], hi[2])
        a.set_box_aspect(tuple(np.maximum(ext, 1e-9 * ext.max())))
        a.view_init(elev, azim)
        a.set_axis_off()
    if colorbar:
        sm = cm.ScalarMappable(norm=norm, cmap=cmap_obj)
        sm.set_array([])
        fig.colorbar(sm, ax=axes, shrink=0.7, label="u")
    if title:
        fig.suptitle(title)
    return fig
