"""Reading mesh files so that nothing is lost without a word.

OBJ and OFF are text formats that files in the wild write loosely (indented lines, tabs, comments
after the numbers, polygons, relative indices, colours after a face's indices); the general
readers drop such lines or refuse the file. They are read here line by line with numpy only:
every record is accounted for, and a face record that cannot be used (fewer than three vertices)
is reported with a warning that says how many were dropped; a vertex record that cannot be read
is an error (dropping it would renumber every vertex after it). PLY and STL go to trimesh (or
meshio), and the counts their headers declare are checked against what the reader returned.
"""

from __future__ import annotations

import gzip
import struct
import warnings
from pathlib import Path
from typing import List, Optional, Tuple, Union

import numpy as np

from .._warn import user_stacklevel

MESH_EXTRA = "pip install 'tubesweep[mesh]', or pip install '.[mesh]' in a checkout"


def _open_text(path: Path) -> List[str]:
    """The lines of a text mesh file (gzip-compressed when it ends in .gz); a file with NUL bytes
    (binary) is refused."""
    raw = gzip.open(path, "rb").read() if path.suffix.lower() == ".gz" else path.read_bytes()
    if b"\0" in raw[:65536]:
        raise ValueError(
            f"{path}: not a text mesh file (it holds binary data); tubesweep reads text OBJ and OFF files, "
            "and PLY and STL (text or binary)"
        )
    # (a byte-order mark, as Windows editors write it, is not part of the first line: its 'v'
    # record was dropped and every face index shifted by one, unwarned)
    text = raw.decode("utf-8-sig", errors="replace")
    # a backslash at the end of a line continues it (OBJ)
    return text.replace("\\\r\n", " ").replace("\\\n", " ").splitlines()


def _numbers(tokens: List[str], path: Path, line_no: int, what: str) -> List[float]:
    try:
        return [float(t) for t in tokens]
    except ValueError:
        raise ValueError(
            f"{path}, line {line_no}: {what} has a value that is not a number: {' '.join(tokens)!r}"
        ) from None


def _fan(poly: List[int]) -> List[List[int]]:
    return [[poly[0], poly[k], poly[k + 1]] for k in range(1, len(poly) - 1)]


def _warn_dropped(path: Path, dropped: int, what: str) -> None:
    if dropped:
        warnings.warn(f"{path}: {dropped} {what} dropped", RuntimeWarning, stacklevel=user_stacklevel())


def read_obj_file(path: Path) -> Tuple[np.ndarray, np.ndarray]:
    """Vertices (n, 3) and triangles (m, 3) of a Wavefront OBJ file (plain or .gz), in the file's
    vertex order; polygons fan-triangulated, relative (negative) indices resolved, texture and
    normal indices after ``/`` ignored."""
    verts: List[List[float]] = []
    tris: List[List[int]] = []
    short_faces = 0
    other = 0  # line and point elements (l, p): not part of a surface
    for line_no, line in enumerate(_open_text(path), 1):
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        tokens = line.split()
        key = tokens[0]
        if key == "v":
            xyz = _numbers(tokens[1:4], path, line_no, "a vertex")
            if len(xyz) < 3:
                raise ValueError(f"{path}, line {line_no}: a vertex needs three coordinates; got {line!r}")
            verts.append(xyz)
        elif key == "f":
            try:
                idx = [int(t.split("/")[0]) for t in tokens[1:]]
            except ValueError:
                raise ValueError(
                    f"{path}, line {line_no}: a face's vertex indices must be whole numbers; got {line!r}"
                ) from None
            n = len(verts)
            if any(i == 0 for i in idx):
                raise ValueError(
                    f"{path}, line {line_no}: OBJ vertex indices start at 1 (negative ones count back); got 0"
                )
            idx = [i - 1 if i > 0 else n + i for i in idx]
            if len(idx) < 3:
                short_faces += 1
                continue
            tris.extend(_fan(idx))
        elif key in ("l", "p"):
            other += 1
    if not verts:
        raise ValueError(f"{path}: no vertices found: not an OBJ mesh")
    if not tris:
        raise ValueError(f"{path}: no faces found (is it a point cloud or a set of lines?)")
    _warn_dropped(path, short_faces, "face records with fewer than three vertices (not triangles or polygons) were")
    _warn_dropped(path, other, "line and point elements (l, p: not part of a surface) were")
    return _checked(path, np.asarray(verts, dtype=float), np.asarray(tris, dtype=np.int64))


def read_off_file(path: Path) -> Tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of an OFF file (text; the COFF/NOFF/STOFF variants' extra columns
    ignored); polygons fan-triangulated. The counts the header declares are checked."""
    lines = []
    for line_no, line in enumerate(_open_text(path), 1):
        line = line.split("#", 1)[0].strip()
        if line:
            lines.append((line_no, line.split()))
    if not lines or not lines[0][1][0].upper().endswith("OFF"):
        raise ValueError(f"{path}: not an OFF file (it must start with 'OFF')")
    head = lines[0][1]
    if len(head) > 1 and head[1].upper() == "BINARY":
        raise ValueError(f"{path}: binary OFF files are not read; convert it to text OFF, OBJ or PLY")
    rest = lines[1:]
    counts = head[1:4] if len(head) >= 3 else (rest.pop(0)[1] if rest else [])
    try:
        nv, nf = int(counts[0]), int(counts[1])
    except (IndexError, ValueError):
        raise ValueError(f"{path}: the OFF header must give the numbers of vertices and faces") from None
    if nv < 0 or nf < 0 or len(rest) != nv + nf:
        # (more records than declared: the rest were dropped, unwarned; an OFF file holds no other records)
        raise ValueError(
            f"{path}: the header declares {nv} vertices and {nf} faces ({nv + nf} records) but the file holds "
            f"{len(rest)}; correct the header's counts"
        )
    verts = []
    for line_no, tokens in rest[:nv]:
        xyz = _numbers(tokens[:3], path, line_no, "a vertex")
        if len(xyz) < 3:
            raise ValueError(f"{path}, line {line_no}: a vertex needs three coordinates")
        verts.append(xyz)
    tris: List[List[int]] = []
    short_faces = 0
    for line_no, tokens in rest[nv : nv + nf]:
        try:
            k = int(tokens[0])
            idx = [int(t) for t in tokens[1 : 1 + k]]
        except ValueError:
            raise ValueError(f"{path}, line {line_no}: a face must be a count followed by vertex indices") from None
        if len(idx) != k:
            raise ValueError(f"{path}, line {line_no}: the face declares {k} vertices but lists {len(idx)}")
        if k < 3:
            short_faces += 1
            continue
        tris.extend(_fan(idx))
    if not tris:
        raise ValueError(f"{path}: no faces found (is it a point cloud?)")
    _warn_dropped(path, short_faces, "faces with fewer than three vertices were")
    return _checked(path, np.asarray(verts, dtype=float), np.asarray(tris, dtype=np.int64))


def _checked(path: Path, v: np.ndarray, f: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    if f.size and (f.min() < 0 or f.max() >= len(v)):
        bad = int(f.max()) if f.max() >= len(v) else int(f.min())
        raise ValueError(
            f"{path}: a face refers to vertex {bad} (0-based), which does not exist: the file has {len(v)} vertices"
        )
    return v, f


def _ply_counts(path: Path) -> Tuple[Optional[int], Optional[int]]:
    """The vertex and face counts a PLY header declares (None where absent or unreadable)."""
    nv = nf = None
    with open(path, "rb") as fh:
        for _ in range(200):
            line = fh.readline()
            if not line:
                break
            words = line.decode("ascii", errors="replace").split()
            if words[:2] == ["element", "vertex"] and len(words) > 2 and words[2].isdigit():
                nv = int(words[2])
            elif words[:2] == ["element", "face"] and len(words) > 2 and words[2].isdigit():
                nf = int(words[2])
            elif words[:1] == ["end_header"]:
                break
    return nv, nf


def _stl_count(path: Path) -> Optional[int]:
    """The number of triangles an STL file holds (binary: its header's count, when the file's
    size matches it; text: its ``facet`` records), None when it cannot tell."""
    data = path.read_bytes()
    if len(data) >= 84:
        (n,) = struct.unpack("<I", data[80:84])
        if len(data) == 84 + 50 * n:
            return n
    if data.lstrip()[:5].lower() == b"solid":
        return sum(1 for line in data.decode("ascii", errors="replace").splitlines() if line.split()[:1] == ["facet"])
    return None


def read_with_library(path: Path) -> Tuple[np.ndarray, np.ndarray]:
    """PLY and STL (and any other format) through trimesh, else meshio; the counts their headers
    declare are checked against what came back."""
    try:
        import trimesh
    except ImportError:
        trimesh = None  # type: ignore[assignment]
    meshio = None
    if trimesh is None:
        try:
            import meshio  # type: ignore[no-redef]
        except ImportError:
            raise ImportError(f"reading {path.suffix or 'mesh'} files needs trimesh or meshio: {MESH_EXTRA}") from None
    try:
        if trimesh is not None:
            m = trimesh.load(str(path), force="mesh", process=False, maintain_order=True)
            v = np.asarray(m.vertices, dtype=float)  # type: ignore[attr-defined, type-var]
            f = np.asarray(m.faces, dtype=np.int64)  # type: ignore[attr-defined]
        else:
            m = meshio.read(str(path))
            v = np.asarray(m.points, dtype=float)[:, :3]
            tris = []
            for block in m.cells:
                data = np.asarray(block.data, dtype=np.int64)
                if data.ndim == 2 and data.shape[1] >= 3:
                    tris.extend(data[:, [0, k, k + 1]] for k in range(1, data.shape[1] - 1))
            f = np.concatenate(tris) if tris else np.zeros((0, 3), np.int64)
    except MemoryError:
        raise
    except Exception as e:  # the readers raise anything on a file that is not a mesh
        raise ValueError(
            f"{path}: not a readable triangle mesh ({type(e).__name__}: {e}); tubesweep reads OBJ, PLY, "
            "STL and OFF files"
        ) from None
    if f.size == 0 or f.ndim != 2:
        truncated = ""
        if path.suffix.lower() == ".stl":
            data = path.read_bytes()
            if len(data) >= 84 and not data.lstrip()[:5].lower() == b"solid":
                (n,) = struct.unpack("<I", data[80:84])
                if len(data) < 84 + 50 * n:
                    truncated = (
                        f" its header declares {n} triangles, {84 + 50 * n} bytes, but the file holds {len(data)}: it "
                        "is cut short (an interrupted download or copy?)"
                    )
        raise ValueError(f"{path}: no triangles found" + (f";{truncated}" if truncated else " (is it a point cloud?)"))
    suffix = path.suffix.lower()
    if suffix == ".ply":
        nv, nf = _ply_counts(path)
        if nv is not None and nv != len(v):
            raise ValueError(f"{path}: the header declares {nv} vertices but {len(v)} were read")
        if nf is not None and len(f) < nf:
            warnings.warn(
                f"{path}: the header declares {nf} faces but only {len(f)} triangles were read "
                f"({nf - len(f)} or more faces lost)",
                RuntimeWarning,
                stacklevel=user_stacklevel(),
            )
    elif suffix == ".stl":
        n = _stl_count(path)
        if n is not None and n != len(f):
            warnings.warn(
                f"{path}: the file holds {n} triangles but {len(f)} were read ({abs(n - len(f))} "
                f"{'lost' if n > len(f) else 'extra'})",
                RuntimeWarning,
                stacklevel=user_stacklevel(),
            )
        return welded(*_checked(path, v, f))
    return _checked(path, v, f)


def welded(v: np.ndarray, f: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """An STL file's triangle soup (three vertices of its own per triangle) with the vertices of
    equal coordinates made one, in the order of their coordinates: the triangles' shared edges are
    what makes a mesh closed and its smooth map possible (read as it was, a closed icosphere had
    960 boundary edges and the exact map's errors, 2–3 times the merged mesh's)."""
    uniq, inverse = np.unique(v, axis=0, return_inverse=True)
    return np.ascontiguousarray(uniq), np.ascontiguousarray(inverse.reshape(-1)[f], dtype=f.dtype)


def read_mesh(path: Union[str, Path]) -> Tuple[np.ndarray, np.ndarray]:
    """Vertices (n, 3) float64 and triangles (m, 3) int64 of an OBJ / PLY / STL / OFF file.

    OBJ and OFF (also gzip-compressed, ``.obj.gz``) are read with numpy only, line by line
    (:mod:`tubesweep.surfaces._mesh_files`: indentation, tabs, comments, polygons and relative
    indices are fine, and a record that cannot be used is an error or a warning that says how many
    were dropped); PLY and STL need trimesh or meshio (the ``mesh`` extra), and the counts their
    headers declare are checked. Vertex indices are those of the file; polygons are
    fan-triangulated.

    Parameters
    ----------
    path : str or pathlib.Path
        The file.

    Returns
    -------
    vertices : numpy.ndarray
        ``(n, 3)`` float64.
    faces : numpy.ndarray
        ``(m, 3)`` int64.

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    IsADirectoryError
        If the path is a directory.
    ValueError
        If the file holds no triangles or cannot be read as a mesh.
    ImportError
        If neither trimesh nor meshio is installed.

    Examples
    --------
    >>> import tubesweep as ts
    >>> from tubesweep.surfaces.mesh import read_mesh
    >>> v, f = read_mesh(ts.data.spot())
    """
    path = Path(path)
    if path.is_dir():
        raise IsADirectoryError(f"mesh file {str(path)!r} is a directory, not a mesh file")
    if not path.is_file():
        raise FileNotFoundError(f"mesh file {str(path)!r} does not exist")
    name = path.name.lower()
    if name.endswith(".obj") or name.endswith(".obj.gz"):
        return read_obj_file(path)
    if name.endswith(".off") or name.endswith(".off.gz"):
        return read_off_file(path)
    return read_with_library(path)
