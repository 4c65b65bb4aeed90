"""Reading a point cloud from a file (:func:`read_points`, re-exported by ``surfaces.points``):
text files of numbers, NumPy arrays and PLY files.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Optional, Union

import numpy as np

__all__ = ["read_points", "POINT_FILES"]

#: The file extensions :func:`read_points` reads.
POINT_FILES = (".xyz", ".txt", ".csv", ".pts", ".npy", ".ply")


def read_points(path: Union[str, Path]) -> np.ndarray:
    """The points of a ``.xyz`` / ``.txt`` / ``.csv`` / ``.pts`` (numbers, one point a line), ``.npy``
    or ``.ply`` file, as an ``(M, 3)`` (or ``(M, 2)``) float64 array.

    Text files are read with numpy: whitespace- or comma-separated columns, ``#`` comments and one
    header line allowed; the first three columns are the coordinates (two if there are only two).
    ``.ply`` needs plyfile, trimesh or meshio (the ``mesh`` extra).

    Parameters
    ----------
    path : str or pathlib.Path
        The file.

    Returns
    -------
    numpy.ndarray
        ``(M, 3)`` or ``(M, 2)`` float64.

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    ValueError
        If the file is not a point file (unknown extension, no numbers, the wrong number of columns).
    ImportError
        If a ``.ply`` file meets none of plyfile, trimesh, meshio.

    Examples
    --------
    >>> import numpy as np, tempfile, os
    >>> from tubesweep.surfaces.points import read_points
    >>> path = os.path.join(tempfile.mkdtemp(), "p.xyz")
    >>> np.savetxt(path, np.eye(3))
    >>> read_points(path).shape
    (3, 3)
    """
    path = Path(path)
    if path.is_dir():
        raise IsADirectoryError(f"point file {str(path)!r} is a directory")
    if not path.is_file():
        raise FileNotFoundError(f"point file {str(path)!r} does not exist")
    ext = path.suffix.lower()
    if ext not in POINT_FILES:
        raise ValueError(
            f"{path.name!r} is not a point file tubesweep reads: use one of {', '.join(POINT_FILES)} "
            "(a mesh file goes to from_mesh)"
        )
    if ext == ".npy":
        try:
            data = np.load(path, allow_pickle=False)
        except (ValueError, OSError) as e:
            raise ValueError(f"{path.name!r} is not a NumPy array file: {e}") from None
    elif ext == ".ply":
        data = _read_ply(path)
    else:
        data = _read_text(path, "," if ext == ".csv" else None)
    data = np.asarray(data)
    if data.dtype.kind not in "fiu" or data.ndim != 2 or data.shape[1] < 2:
        raise ValueError(
            f"{path.name!r} does not hold points: expected rows of 2 or 3 numbers, got an array of shape "
            f"{data.shape} and type {data.dtype}"
        )
    if data.shape[0] == 0:
        raise ValueError(f"{path.name!r} holds no points")
    if ext == ".npy" and data.shape[0] in (2, 3) and data.shape[1] > 3:
        raise ValueError(
            f"{path.name!r} holds an array of shape {data.shape}: {data.shape[0]} rows of {data.shape[1]} numbers, the "
            "points as columns; points are rows (one x, y, z a row): np.save(path, points.T)"
        )
    return np.ascontiguousarray(data[:, : min(3, data.shape[1])], dtype=float)


def _read_text(path: Path, delimiter: Optional[str]) -> np.ndarray:
    for skip in (0, 1):
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # numpy's "empty input file"
                data = np.loadtxt(path, delimiter=delimiter, skiprows=skip, ndmin=2, comments="#")
            return data
        except (ValueError, UnicodeDecodeError):
            continue
    raise ValueError(
        f"{path.name!r} is not a point file: its lines are not rows of numbers (x y z per line, "
        "whitespace- or comma-separated, one header line at most)"
    )


def _read_ply(path: Path) -> np.ndarray:
    try:
        from plyfile import PlyData

        try:
            v = PlyData.read(str(path))["vertex"]
        except Exception as e:  # plyfile raises its own errors for a broken file
            raise ValueError(f"{path.name!r} is not a readable PLY file: {e}") from None
        return np.c_[v["x"], v["y"], v["z"]]
    except ImportError:
        pass
    try:
        import trimesh

        try:
            loaded = trimesh.load(str(path), process=False)
        except Exception as e:  # trimesh raises many kinds for a broken file
            raise ValueError(f"{path.name!r} is not a readable PLY file: {e}") from None
        vertices = getattr(loaded, "vertices", None)
        if vertices is None:
            raise ValueError(f"{path.name!r} holds no vertices")
        return np.asarray(vertices, dtype=float)
    except ImportError:
        pass
    try:
        import meshio

        try:
            return np.asarray(meshio.read(str(path)).points, dtype=float)
        except Exception as e:  # meshio raises many kinds for a broken file
            raise ValueError(f"{path.name!r} is not a readable PLY file: {e}") from None
    except ImportError:
        raise ImportError(
            "reading .ply points needs plyfile, trimesh or meshio: pip install 'tubesweep[mesh]', "
            "or pip install '.[mesh]' in a checkout"
        ) from None
