"""Example meshes shipped with tubesweep: the Stanford bunny and Keenan Crane's Spot.

Both are stored gzip-compressed inside the package (``tubesweep/data/*.obj.gz``), so they are
there in a source checkout and in an installed wheel alike. Their credits and terms are in
``tubesweep/data/README.md`` (and :data:`CREDITS`).

* :func:`bunny` — the Stanford bunny (Turk & Levoy 1994): 35,947 vertices, 69,451 triangles. A
  *scanned* mesh, not watertight (holes at the base), in the file's own units (about 0.15 wide).
* :func:`spot` — "Spot" the cow (Keenan Crane): 2,930 vertices, 5,856 triangles, closed, genus 0,
  about 1.4 long.

Each returns the :class:`~pathlib.Path` of the compressed file, which :func:`tubesweep.surfaces.from_mesh`
reads directly (numpy only, no mesh library needed); :func:`load` returns the ``(vertices, faces)``
arrays. On the command line, ``tubesweep solve --mesh bunny`` and ``--mesh spot`` name them.
"""

from __future__ import annotations

from pathlib import Path
from typing import Dict, Tuple, Union

import numpy as np

__all__ = ["bunny", "spot", "path", "load", "read_obj", "mesh_file", "NAMES", "CREDITS"]

_HERE = Path(__file__).resolve().parent

#: Bundled meshes: short name → file name inside the package.
NAMES: Dict[str, str] = {"bunny": "stanford-bunny.obj.gz", "spot": "spot.obj.gz"}

#: One line of credit per bundled mesh (full terms in ``tubesweep/data/README.md``).
CREDITS: Dict[str, str] = {
    "bunny": "Stanford Bunny: Greg Turk and Marc Levoy (1994), Stanford 3D Scanning Repository, "
    "Stanford Computer Graphics Laboratory",
    "spot": "Spot: Keenan Crane, Keenan's 3D Model Repository (released into the public domain, CC0)",
}


def path(name: str) -> Path:
    """The file of a bundled mesh.

    Parameters
    ----------
    name : str
        ``"bunny"`` or ``"spot"`` (see :data:`NAMES`).

    Returns
    -------
    pathlib.Path
        The gzip-compressed OBJ file inside the installed package.

    Raises
    ------
    ValueError
        If ``name`` is not one of the bundled meshes.
    FileNotFoundError
        If the package was installed without its data files.

    Examples
    --------
    >>> import tubesweep as ts
    >>> ts.data.path("spot").name
    'spot.obj.gz'
    """
    key = str(name).lower()
    if key not in NAMES:
        raise ValueError(f"no bundled mesh named {name!r}; the bundled meshes are {sorted(NAMES)}")
    p = _HERE / NAMES[key]
    if not p.is_file():
        raise FileNotFoundError(
            f"the bundled mesh {p} is missing: reinstall tubesweep (its wheel ships tubesweep/data/*.obj.gz)"
        )
    return p


def mesh_file(name_or_path: Union[str, Path]) -> Path:
    """A mesh file named on the command line: the file itself, or a bundled mesh by its name.

    Parameters
    ----------
    name_or_path : str or pathlib.Path
        A path, or ``"bunny"`` / ``"spot"`` (used only when no file of that name exists).

    Returns
    -------
    pathlib.Path
        The file to read.

    Raises
    ------
    FileNotFoundError
        If a bundled mesh is missing from the installation.

    Examples
    --------
    >>> import tubesweep as ts
    >>> ts.data.mesh_file("spot").name
    'spot.obj.gz'
    """
    p = Path(name_or_path)
    if not p.exists() and str(name_or_path).lower() in NAMES:
        return path(str(name_or_path))
    return p


def bunny() -> Path:
    """The Stanford bunny's file (a scanned mesh with holes at its base).

    Returns
    -------
    pathlib.Path
        ``stanford-bunny.obj.gz`` inside the package; pass it to :func:`tubesweep.surfaces.from_mesh`.

    Raises
    ------
    FileNotFoundError
        If the package was installed without its data files.

    Examples
    --------
    >>> import tubesweep as ts
    >>> surface = ts.surfaces.from_mesh(ts.data.bunny())
    >>> surface.vertices.shape, surface.faces.shape
    ((35947, 3), (69451, 3))
    """
    return path("bunny")


def spot() -> Path:
    """Spot the cow's file (a closed, genus-0 mesh).

    Returns
    -------
    pathlib.Path
        ``spot.obj.gz`` inside the package; pass it to :func:`tubesweep.surfaces.from_mesh`.

    Raises
    ------
    FileNotFoundError
        If the package was installed without its data files.

    Examples
    --------
    >>> import tubesweep as ts
    >>> surface = ts.surfaces.from_mesh(ts.data.spot())
    >>> surface.closed
    True
    """
    return path("spot")


def load(name: str) -> Tuple[np.ndarray, np.ndarray]:
    """The vertices and triangles of a bundled mesh.

    Parameters
    ----------
    name : str
        ``"bunny"`` or ``"spot"``.

    Returns
    -------
    vertices : numpy.ndarray
        ``(n, 3)`` float64, in the file's order and units.
    faces : numpy.ndarray
        ``(m, 3)`` int64, zero-based vertex indices.

    Raises
    ------
    ValueError
        If ``name`` is not one of the bundled meshes.

    Examples
    --------
    >>> import tubesweep as ts
    >>> v, f = ts.data.load("spot")
    >>> v.shape, f.shape
    ((2930, 3), (5856, 3))
    """
    return read_obj(path(name))


def read_obj(file: Union[str, Path]) -> Tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles of a Wavefront OBJ file, plain or gzip-compressed (``.obj.gz``).

    Reads ``v`` and ``f`` records only (texture and normal indices after ``/`` are ignored), keeps
    the file's vertex order, and fan-triangulates polygons. Needs nothing beyond numpy.

    Parameters
    ----------
    file : str or pathlib.Path
        An ``.obj`` or ``.obj.gz`` file.

    Returns
    -------
    vertices : numpy.ndarray
        ``(n, 3)`` float64.
    faces : numpy.ndarray
        ``(m, 3)`` int64, zero-based.

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    ValueError
        If it holds no vertices or no faces, or a face refers to a vertex that does not exist.

    Examples
    --------
    >>> import tubesweep as ts
    >>> v, f = ts.data.read_obj(ts.data.spot())
    >>> int(f.max()) < len(v)
    True
    """
    from ..surfaces._mesh_files import read_obj_file

    file = Path(file)
    if not file.is_file():
        raise FileNotFoundError(f"mesh file {str(file)!r} does not exist")
    # the robust reader (indentation, tabs, comments; dropped records reported)
    return read_obj_file(file)
