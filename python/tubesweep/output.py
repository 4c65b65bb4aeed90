"""Results as meshes, files and pictures.

* :func:`triangulate` — a mesh of the surface a solution lives on: the surface's own
  ``triangulation()`` (meshes read with :func:`tubesweep.surfaces.from_mesh`, library and
  closest-point surfaces that provide one), otherwise marching cubes (3D) / marching squares (2D)
  of the level set φ = 0 restricted to the band (scikit-image).
* :func:`export` — that mesh with the solution ``u`` as point data, as ``.vtu`` / ``.vtk`` /
  ``.ply`` / ``.obj`` (meshio) or ``.vtp`` (VTK XML PolyData, written here), for ParaView.
* :func:`plot` — a matplotlib :class:`~matplotlib.figure.Figure` (in :mod:`tubesweep._plot`).

Optional dependencies are imported lazily: meshio and scikit-image (the ``mesh`` extra) and
matplotlib (the ``plot`` extra): ``pip install 'tubesweep[mesh,plot]'``, or ``pip install
'.[mesh,plot]'`` in a checkout.
"""

from __future__ import annotations

import base64
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any, Dict, Optional, Tuple, Union
from xml.sax.saxutils import quoteattr

import numpy as np

from ._validate import real_array
from ._triangulate import _need, check_surface_solution, triangulate

__all__ = ["triangulate", "export", "plot", "read_vtp", "EXPORT_FORMATS"]

#: File suffixes :func:`export` writes.
EXPORT_FORMATS = (".vtu", ".vtp", ".vtk", ".ply", ".obj")


# ---------------------------------------------------------------------------------------------
# export
# ---------------------------------------------------------------------------------------------
def _write_vtp(path: Path, points: np.ndarray, cells: np.ndarray, point_data: Dict[str, np.ndarray]) -> None:
    """VTK XML PolyData (inline base64 binary): polygons for triangles, lines for segments, vertices
    for points."""
    n, m, k = len(points), len(cells), cells.shape[1]
    kind = "Polys" if k >= 3 else "Lines" if k == 2 else "Verts"

    def arr(a: np.ndarray, dtype: str) -> str:
        # VTK's inline binary: the byte count (UInt64, header_type; UInt32 overflows past 4 GiB) and
        # the little-endian values, each in base64.
        # Binary, not ASCII: VTK's ASCII reader stops at a NaN (an unreached node), which ParaView
        # then fails to read
        data = np.ascontiguousarray(a, dtype=dtype).tobytes()
        return (base64.b64encode(np.uint64(len(data)).tobytes()) + base64.b64encode(data)).decode("ascii")

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
    except OSError as e:  # named by the path given, not by the temporary file's name
        raise OSError(e.errno, f"cannot write {path} ({e.strerror})") from None
    part = Path(name) if name else target
    if fd >= 0:
        os.close(fd)
    try:
        with open(part, "w") as fh:
            fh.write(
                '<?xml version="1.0"?>\n<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n'
                "<PolyData>\n"
            )
            fh.write(
                f'<Piece NumberOfPoints="{n}" NumberOfVerts="{m if kind == "Verts" else 0}" NumberOfLines="{m if kind == "Lines" else 0}" '
                f'NumberOfStrips="0" NumberOfPolys="{m if kind == "Polys" else 0}">\n'
            )
            names = list(point_data)
            fh.write(f"<PointData Scalars={quoteattr(str(names[0]))}>\n" if names else "<PointData>\n")
            for name, a in point_data.items():
                comps = f' NumberOfComponents="{a.shape[1]}"' if a.ndim == 2 else ""
                fh.write(
                    f'<DataArray type="Float64" Name={quoteattr(str(name))}{comps} format="binary">\n'
                    f"{arr(a, '<f8')}\n</DataArray>\n"
                )
            fh.write("</PointData>\n<Points>\n")
            fh.write(
                f'<DataArray type="Float64" NumberOfComponents="3" format="binary">\n{arr(points, "<f8")}\n</DataArray>\n'
            )
            fh.write(f"</Points>\n<{kind}>\n")
            fh.write(
                f'<DataArray type="Int64" Name="connectivity" format="binary">\n{arr(cells, "<i8")}\n</DataArray>\n'
            )
            fh.write(
                f'<DataArray type="Int64" Name="offsets" format="binary">\n{arr(np.arange(1, m + 1) * k, "<i8")}\n</DataArray>\n'
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
    """Reads a ``.vtp`` file written by :func:`export` (inline binary or ASCII data arrays).

    Parameters
    ----------
    path : str or pathlib.Path
        The file.

    Returns
    -------
    points : numpy.ndarray
        ``(n, 3)`` vertices.
    cells : numpy.ndarray
        ``(m, k)`` polygons, lines, or ``(m, 1)`` vertices (a point cloud).
    point_data : dict
        Name → per-vertex array.

    Raises
    ------
    ValueError
        If the file is not VTK XML PolyData.

    Examples
    --------
    >>> from tubesweep.output import read_vtp
    >>> points, cells, data = read_vtp("sphere.vtp")  # doctest: +SKIP
    """
    try:
        root = ET.parse(str(path)).getroot()
    except ET.ParseError as e:
        raise ValueError(f"{path}: not an XML VTK file ({e})") from None
    piece = root.find("PolyData/Piece")
    if piece is None:
        raise ValueError(f"{path}: not a VTK PolyData file")

    def values(el: Any, dtype: Any) -> np.ndarray:
        text = (el.text or "").strip()
        if el.get("format", "ascii") != "binary":
            return np.array(text.split(), dtype=dtype)
        # the byte count (UInt32 or UInt64, the file's header_type: 8 or 12 base64 characters), then
        # the values
        wide = root.get("header_type", "UInt32") == "UInt64"
        head = 12 if wide else 8
        size = int(np.frombuffer(base64.b64decode(text[:head]), "<u8" if wide else "<u4")[0])
        raw = base64.b64decode(text[head:])
        if len(raw) != size:
            raise ValueError(f"{path}: a DataArray holds {len(raw)} bytes where its header says {size}")
        return np.frombuffer(raw, "<f8" if dtype is float else "<i8").astype(dtype)

    points = values(piece.find("Points/DataArray"), float).reshape(-1, 3)
    # the cells' section: polygons (a surface), lines (a curve) or vertices (a point cloud)
    kind = next((k for k in ("Polys", "Lines", "Verts") if int(piece.get(f"NumberOf{k}", "0")) > 0), "Polys")
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
        data[el.get("Name")] = a.reshape(-1, int(el.get("NumberOfComponents"))) if el.get("NumberOfComponents") else a  # type: ignore[arg-type]
    return points, conn.reshape(-1, k), data  # type: ignore[return-value]


def export_format(path: Union[str, Path], curve: bool = False) -> str:
    """The format of an export path (its suffix, lower case), or a ValueError naming the ones known;
    ``curve``: the mesh is of line cells (a 2D curve), which ``.ply`` and ``.obj`` cannot hold."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in EXPORT_FORMATS:
        raise ValueError(
            f"export: unknown format {path.suffix!r} of {str(path)!r}; use one of {', '.join(EXPORT_FORMATS)}"
        )
    if curve and suffix in (".ply", ".obj"):
        raise ValueError(f"export: {suffix} holds surfaces only; write a 2D curve as .vtu, .vtp or .vtk")
    return suffix


def export(
    sol: Any,
    path: Union[str, Path],
    *,
    mesh: Optional[Tuple[Any, Any]] = None,
    point_data: Optional[Dict[str, Any]] = None,
) -> Path:
    """Writes the surface of a solution with the solution ``u`` at its vertices, for ParaView.

    ``u`` is :meth:`Solution.on_mesh` at the vertices (``inf`` where never reached becomes NaN).
    With several sources and an isotropic Hamiltonian, ``nearest_source`` (the label of
    :meth:`Solution.nearest_source`, -1 where no front arrives) is written too. 2D curves are
    written as line cells with z = 0. A point cloud (:func:`tubesweep.surfaces.from_points`) is
    written as its samples (vertex cells, ``.vtp`` or ``.ply``), with the ``normals`` given to
    ``from_points`` if any.

    Parameters
    ----------
    sol : Solution
        A :func:`tubesweep.solve` result.
    path : str or pathlib.Path
        Ending in ``.vtu``, ``.vtp``, ``.vtk``, ``.ply`` or ``.obj``. ``.vtp`` is VTK XML PolyData
        written here; the others go through meshio (``pip install 'tubesweep[mesh]'``, or
        ``pip install '.[mesh]'`` in a checkout); ``.obj`` keeps no point data.
    mesh : (vertices, faces), optional
        The mesh to write instead of :func:`triangulate`'s.
    point_data : dict, optional
        Further per-vertex arrays (name → ``(n,)`` or ``(n, k)``) to write beside ``u``.

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    TypeError
        If ``sol`` is not a solution on a surface (a ``ts.travel_time`` box solution, say).
    ValueError
        For an unknown suffix, a 2D curve as ``.ply``, or point data of the wrong length or name.
    ImportError
        If the format needs meshio and it is not installed.
    OSError
        If the file cannot be written (a half-written file is not left behind).

    Examples
    --------
    >>> import tubesweep as ts
    >>> s = ts.surfaces.Sphere(0.5)
    >>> sol = ts.solve(s, ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41)), [s.default_source])
    >>> ts.export(sol, "sphere.vtp")  # doctest: +SKIP
    PosixPath('sphere.vtp')
    """
    check_surface_solution(sol, "export")
    path = Path(path)
    suffix = export_format(path)
    cloud = mesh is None and hasattr(sol.surface, "rim") and hasattr(sol.surface, "points")
    if cloud:
        # a point cloud (surfaces.from_points): the samples, as vertices, with u at them
        v = np.asarray(sol.surface.points, dtype=float)
        cells = np.arange(len(v)).reshape(-1, 1)
        if suffix not in (".vtp", ".ply"):
            raise ValueError(f"a point cloud is written as .vtp or .ply; got {suffix}")
    else:
        v, cells = triangulate(sol, mesh=mesh)
    u = sol.on_mesh(v) if not cloud else sol(v)
    u = np.where(np.isfinite(u), u, np.nan)
    data: Dict[str, np.ndarray] = {"u": u}
    if cloud and getattr(sol.surface, "normals", None) is not None:
        data["normals"] = np.asarray(sol.surface.normals, dtype=float)  # given to from_points: kept for this
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
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as e:  # a file where a folder of the path should be: named by the path given
        raise OSError(e.errno, f"cannot write {path}: its folder {path.parent} cannot be made ({e.strerror})") from None
    if suffix == ".vtp":
        _write_vtp(path, pts, cells, data)
        return path
    meshio = _need("meshio", "mesh", f"writing {suffix} files")
    kind = {1: "vertex", 2: "line", 3: "triangle", 4: "quad"}[cells.shape[1]]
    export_format(path, curve=kind == "line")
    if suffix == ".ply":
        if len(pts) < 2**31:
            cells = cells.astype(np.int32)  # PLY has no 64-bit integers
        # PLY's vertex properties are scalars: meshio skipped a vector field (a cloud's normals,
        # dropped with only a line on stdout; a review); its components are written instead, the
        # normals as PLY's nx, ny, nz
        flat: Dict[str, np.ndarray] = {}
        for name, a in data.items():
            if a.ndim == 2:
                names = (
                    ["nx", "ny", "nz"]
                    if name == "normals" and a.shape[1] == 3
                    else [f"{name}_{i}" for i in range(a.shape[1])]
                )
                flat.update({c: np.ascontiguousarray(a[:, i]) for i, c in enumerate(names)})
            else:
                flat[name] = a
        data = flat
    m = meshio.Mesh(pts, [] if kind == "vertex" else [(kind, cells)], point_data={} if suffix == ".obj" else data)
    meshio.write(str(path), m, file_format={".vtk": "vtk", ".vtu": "vtu", ".ply": "ply", ".obj": "obj"}[suffix])
    return path


# pictures: tubesweep._plot (kept importable from here)
from ._plot import plot  # noqa: E402
