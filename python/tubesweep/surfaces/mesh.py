"""Triangle meshes as implicit surfaces, in the closest-point representation (paper Sect. 5.2).

:func:`from_mesh` reads an OBJ / PLY / STL / OFF file (with trimesh, or meshio as a fallback) or
takes a ``(V, F)`` pair and returns a :class:`MeshSurface`. The solver then sees the mesh Σ only
through the closest-point function ``cp(x) = argmin_{z ∈ Σ} |x − z|`` evaluated at the band nodes:

* the tube is ``{x : |x − cp(x)| ≤ h}``, inner (Γ^in) and extension layer (Γ^out) as in Sect. 5.2;
* the extension direction of Eq. (8) is ``(x − cp(x)) / |x − cp(x)|`` — it needs no inside and no
  outside, so scanned meshes with holes (the Stanford bunny) and open or non-orientable meshes
  work as they are;
* where the mesh is closed and consistently oriented a signed distance is also available
  (sign from the angle-weighted pseudo-normal of the closest feature, Bærentzen & Aanæs 2005).

Closest points are computed exactly and only at the nodes of the band, which is found
coarse-to-fine like :func:`tubesweep.band.discover_band`. The spatial index is an AABB tree in
the Rust core (``tubesweep_core::surface::mesh``, exposed as ``tubesweep._native.TriangleTree``): a binary
tree of boxes over the triangles, searched nearer-child-first and pruned by box distance, with a
search radius so that far-away points cost almost nothing; queries run in parallel.

Reading files needs trimesh or meshio, the optional ``mesh`` extra: ``pip install
'tubesweep[mesh]'``, or ``pip install '.[mesh]'`` in a checkout. ``(V, F)`` arrays need nothing
beyond numpy.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any, Dict, Optional, Sequence, Tuple, Union

import numpy as np

from ..grid import Grid
from ..band import BandGeometry, coarse_to_fine_candidates
from ..surface import Surface
from ..closest_point import ClosestPoint
from .._validate import check_flag, real_array, real_scalar, whole_indices
from ..grid import MAX_COORDINATE
from .. import _distinct
from .._distinct import distinct, distinct_rows
from .._warn import user_stacklevel
from ._mesh_files import MESH_EXTRA, read_mesh
from ._triangle_projection import EDGE_AB, EDGE_AC, EDGE_BC, FACE, VERT_A, VERT_B, VERT_C, closest_points_on_triangles
from .analytic import finite_center, size_parameter
from . import _mesh_smooth as smooth_mesh
from ._mesh_checks import thin_parts, unique_edges, warn_repeated_vertices, warn_thin_parts
from ._mesh_parts import node_parts, part_cut_pairs
from ._mesh_holes import bridged_holes, pairs_over_holes
from ._mesh_pinches import pinch_cut_pairs
from ._mesh_slits import slits
from ._mesh_notches import pairs_at_notches

__all__ = [
    "from_mesh",
    "MeshSurface",
    "SmoothMeshSurface",
    "read_mesh",
    "closest_points_on_triangles",
    "FACE",
    "VERT_A",
    "VERT_B",
    "VERT_C",
    "EDGE_AB",
    "EDGE_AC",
    "EDGE_BC",
]

_MESH_EXTRA = MESH_EXTRA


# ---------------------------------------------------------------------------------------------
# the surface
# ---------------------------------------------------------------------------------------------


class MeshSurface(Surface):
    """A triangle mesh in the closest-point representation (paper Sect. 5.2).

    Build it with :func:`from_mesh`. Closest points are exact and come from an AABB tree in the
    Rust core, computed only at the band's nodes.

    Parameters
    ----------
    vertices : numpy.ndarray
        ``(n, 3)`` vertex coordinates.
    faces : numpy.ndarray
        ``(m, 3)`` vertex indices of the triangles.
    signed : bool, optional
        Report a signed φ (needs a closed, consistently oriented mesh); default: when closed.
    name : str
        A name for printing.
    scale, offset
        The normalisation applied by :func:`from_mesh` (``x_normalised = (x_file − offset) · scale``).

    Attributes
    ----------
    vertices, faces : numpy.ndarray
        The mesh.
    closed : bool
        Every edge shared by exactly two faces, consistently oriented.
    signed : bool
        Whether :meth:`band` reports a signed φ.

    Raises
    ------
    ValueError
        If faces index missing vertices, vertices are not finite, or ``signed=True`` is asked of an
        open mesh.

    Examples
    --------
    >>> import tubesweep as ts
    >>> spot = ts.surfaces.from_mesh(ts.data.spot())
    >>> spot.closed, len(spot.vertices)
    (True, 2930)
    """

    ndim = 3
    #: False: exact closest points (see :class:`SmoothMeshSurface`)
    smooth = False
    #: the band is cut across narrow gaps and above concave edges (``tubesweep._shortcuts``)
    cuts_shortcuts = True
    _part_cut_pairs = part_cut_pairs  # the band's edges between separate parts (cut: _shortcuts)
    _node_parts = node_parts  # each node's part, for a band left uncut (_parts)
    _bridged_holes = bridged_holes  # its holes the band spans, warned (stats.bridged_holes)
    _pairs_over_holes = pairs_over_holes  # facing pairs over a hole: no gap (_prepare)
    _pairs_at_notches = pairs_at_notches  # facing pairs at a notch of the rim: no gap (_facing)
    _slits = slits  # its slits (stats.slits), warned where the band joins their sides
    _pinch_cut_pairs = pinch_cut_pairs  # the band's edges between sheets meeting at a point (cut)

    def __init__(
        self,
        vertices: np.ndarray,
        faces: np.ndarray,
        *,
        signed: Optional[bool] = None,
        name: str = "mesh",
        scale: float = 1.0,
        offset: Optional[np.ndarray] = None,
    ):
        v = real_array(vertices, "vertices")
        f = whole_indices(faces, "faces")
        # the shapes before ascontiguousarray, which makes a 0-d array 1-d
        if v.ndim != 2 or v.shape[1] != 3:
            raise ValueError(f"vertices must have shape (n, 3); got {v.shape} ({v.ndim} dimensions)")
        if f.ndim != 2 or f.shape[1] != 3:
            raise ValueError(
                f"faces must be triangles, shape (m, 3); got {f.shape} "
                + (
                    "(the triangles as columns: pass faces.T)"
                    if f.ndim == 2 and f.shape[0] == 3 and f.shape[1] != 3
                    else "(triangulate polygons first)"
                )
            )
        v, f = np.ascontiguousarray(v), np.ascontiguousarray(f)
        if f.size == 0:
            raise ValueError("the mesh has no faces")
        if f.min() < 0 or f.max() >= len(v):
            raise ValueError(
                f"faces index vertices 0..{len(v) - 1} but contain {int(f.min())}..{int(f.max())}"
                + (
                    " (numbered from 1, as OBJ files write them? pass faces - 1)"
                    if f.min() == 1 and f.max() == len(v)
                    else ""
                )
            )
        finite = np.all(np.isfinite(v), axis=1)
        if not np.all(finite):
            bad = np.flatnonzero(~finite)
            used = int(np.count_nonzero(np.isin(f, bad).any(axis=1)))
            raise ValueError(
                f"vertices contain NaN or inf: {bad.size} vertices (the first, index {int(bad[0])}: "
                f"{tuple(float(x) for x in v[bad[0]])}), used by {used} faces. Every vertex must be finite "
                "(drop the unused ones, or repair the file)"
            )
        big = float(np.max(np.abs(v))) if v.size else 0.0
        if big > MAX_COORDINATE:
            raise ValueError(
                f"vertices have coordinates up to {big:.3g}; they must lie within ±{MAX_COORDINATE:g} "
                "(the solver keeps distances in single precision). Rescale the mesh, e.g. "
                "from_mesh(..., normalize=True)"
            )
        # a triangle listed twice (the same three vertices) adds nothing to the surface, but would
        # count its edges twice and make a closed mesh look open: kept once, with a warning
        first, _ = distinct_rows(np.sort(f, axis=1))
        #: the number of repeated triangles dropped from ``faces``
        self.duplicate_faces = int(len(f) - len(first))
        if self.duplicate_faces:
            warnings.warn(
                f"the mesh lists {self.duplicate_faces} triangles more than once (the same three vertices); "
                "each is kept once (surface.faces holds the rest, in the file's order)",
                RuntimeWarning,
                stacklevel=user_stacklevel(),
            )
            f = np.ascontiguousarray(f[np.sort(first)])
        self.vertices = v
        self.faces = f
        self.name = name
        self.scale = float(scale)
        self.offset = np.zeros(3) if offset is None else np.asarray(offset, dtype=float)

        a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
        cross = np.cross(b - a, c - a)
        area2 = np.linalg.norm(cross, axis=1)
        extent = float(np.ptp(v[_distinct.used_vertices(f, len(v))], axis=0).max())
        good = area2 > 1e-12 * max(extent, 1e-300) ** 2
        if not np.any(good):
            # (a mesh at 1e-200 was refused with no hint of its scale: a helper's review)
            tiny = (
                f": the mesh spans only {extent:.3g}, where the squares of its edges underflow; rescale it, e.g. "
                "from_mesh(..., normalize=True) or vertices * a factor"
                if 0 < extent < 1e-100
                else ""
            )
            raise ValueError("every triangle of the mesh is degenerate (zero area)" + tiny)
        self._good = np.flatnonzero(good)  # tree triangles → mesh faces
        self._tree: Any = None
        self._band_normals: Optional[Tuple[np.ndarray, Optional[np.ndarray]]] = None
        self.face_normals = np.zeros_like(cross)
        self.face_normals[good] = cross[good] / area2[good, None]

        edge_ids, counts = unique_edges(f)
        # a triangle naming a vertex twice has no edges of its own: not counted ([0, 0, 1] made a
        # closed sphere mesh open, unsigned)
        proper = (f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])

        def edges_of(use: np.ndarray) -> Tuple[np.ndarray, int]:
            # the faces' edge counts, and the edges two faces run the same way (faces flipped
            # against their neighbours)
            fp = f[use]
            e_dir = np.concatenate([fp[:, [0, 1]], fp[:, [1, 2]], fp[:, [2, 0]]])
            flips = len(e_dir) - len(distinct(e_dir[:, 0] * len(v) + e_dir[:, 1]))
            return np.bincount(edge_ids[use].ravel(), minlength=len(counts)), flips

        counts, flipped = edges_of(proper)
        if not (np.all(counts[counts > 0] == 2) and flipped == 0) and not np.all(good[proper]):
            # a zero-area "needle" (a vertex on the middle of an edge: [a, b, mid(a, b)]) laid on a
            # closed mesh made it open and unsigned, blamed on flipped faces; without the
            # zero-area triangles it is closed (where they fill a T-junction, it is closed with them)
            counts_good, flipped_good = edges_of(proper & good)
            if np.all(counts_good[counts_good > 0] == 2) and flipped_good == 0:
                counts, flipped = counts_good, flipped_good
        directed_unique = flipped == 0
        self._flipped_edges = int(flipped)  # (thin_parts orients the normals where this is not 0)
        self.closed = bool(np.all(counts[counts > 0] == 2) and directed_unique)
        self.boundary_edges = int(np.count_nonzero(counts == 1))
        if self.boundary_edges:
            warn_repeated_vertices(v, f, self.boundary_edges)
        if signed is None:
            signed = self.closed
        if signed and not self.closed:
            what = [f"{self.boundary_edges} boundary edges"] if self.boundary_edges else []
            what += [f"{flipped} edges that two faces run the same way (faces flipped)"] if flipped else []
            raise ValueError(
                f"signed=True needs a closed, consistently oriented mesh; this one has {' and '.join(what)}. Use "
                "signed=False (the closest-point representation needs no inside/outside)"
                + (", or orient the faces consistently (trimesh: mesh.fix_normals())" if flipped else "")
            )
        self.signed = bool(signed)
        if self.signed:
            self._setup_pseudonormals(a, b, c, cross, good, edge_ids, len(counts))

    # ------------------------------------------------------------------ geometry helpers
    def _setup_pseudonormals(self, a, b, c, cross, good, edge_ids, n_edges) -> None:
        """Angle-weighted vertex normals and edge normals for the sign of a closed mesh."""
        f = self.faces
        n = self.face_normals
        # orientation: a positive enclosed volume means outward normals
        vol = float(np.einsum("ij,ij->i", a, cross).sum()) / 6.0
        self._flip = -1.0 if vol < 0 else 1.0

        def angle(p, q, r):
            u, w = q - p, r - p
            return np.arctan2(np.linalg.norm(np.cross(u, w), axis=1), np.einsum("ij,ij->i", u, w))

        vn = np.zeros_like(self.vertices)
        for k, (p, q, r) in enumerate(((a, b, c), (b, c, a), (c, a, b))):
            np.add.at(vn, f[:, k], angle(p, q, r)[:, None] * n)
        en = np.zeros((n_edges, 3))
        for k in range(3):
            np.add.at(en, edge_ids[:, k], n)
        self._vertex_normals = vn
        self._edge_normals = en
        self._edge_ids = edge_ids

    def _pseudonormal(self, face: np.ndarray, code: np.ndarray) -> np.ndarray:
        out = self.face_normals[face].copy()
        for k, vert in ((VERT_A, 0), (VERT_B, 1), (VERT_C, 2)):
            m = code == k
            out[m] = self._vertex_normals[self.faces[face[m], vert]]
        for k, e in ((EDGE_AB, 0), (EDGE_AC, 1), (EDGE_BC, 2)):
            m = code == k
            out[m] = self._edge_normals[self._edge_ids[face[m], e]]
        return out * self._flip

    def _tree_normals(self) -> Tuple[np.ndarray, Optional[np.ndarray]]:
        """Per triangle of the tree: its unit normal (T, 3) and, on a closed mesh, the outward
        pseudo-normals of its seven features (T, 7, 3) in the order of the feature codes, which
        the core's band reads (``tubesweep_core::band::mesh_band``). Built on first use and kept with
        the surface: 24 bytes per triangle, 192 on a closed mesh (the bunny, open, 69,451
        triangles: 1.7 MB)."""
        if self._band_normals is None:
            g = self._good
            face = np.ascontiguousarray(self.face_normals[g])
            pseudo = None
            if self.signed:
                # feature code k of every tree triangle, k = FACE … EDGE_BC
                pseudo = np.ascontiguousarray(
                    np.stack([self._pseudonormal(g, np.full(len(g), k)) for k in range(EDGE_BC + 1)], axis=1)
                )
            self._band_normals = (face, pseudo)
        return self._band_normals

    def __getstate__(self) -> dict:
        # the native AABB tree does not pickle: a copy builds it again on first use
        state = self.__dict__.copy()
        state["_tree"] = None
        return state

    @property
    def tree(self) -> Any:
        """The AABB tree over the non-degenerate triangles (built on first use)."""
        if self._tree is None:
            from .. import _native

            self._tree = _native.TriangleTree(self.vertices, np.ascontiguousarray(self.faces[self._good]))
        return self._tree

    def closest(
        self, points: Any, max_distance: float = np.inf
    ) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Exact closest points on the mesh.

        Parameters
        ----------
        points : array_like
            ``(M, 3)`` points.
        max_distance : float
            Search no farther: points farther away get distance ``inf``, closest point NaN, face -1.

        Returns
        -------
        distance : numpy.ndarray
            ``(M,)`` unsigned distances.
        closest : numpy.ndarray
            ``(M, 3)`` closest points.
        face : numpy.ndarray
            ``(M,)`` the face each closest point lies on.
        feature : numpy.ndarray
            ``(M,)`` which feature of that face (see :func:`closest_points_on_triangles`).

        Examples
        --------
        >>> import tubesweep as ts
        >>> spot = ts.surfaces.from_mesh(ts.data.spot())
        >>> d, cp, face, feature = spot.closest([[0.0, 0.0, 0.0]])
        """
        x = np.ascontiguousarray(np.asarray(points, dtype=float).reshape(-1, 3))
        d, cp, t, code = self.tree.closest(x, float(max_distance))
        face = np.where(t >= 0, self._good[np.maximum(t, 0)], -1)
        return d, cp, face, code

    def _warn_thin_parts(self, h: float, inner: float) -> None:
        """The warning of parts of the mesh closer to each other than a grid spacing ``h``
        (``_mesh_checks.thin_parts``, kept per spacing), for the tube of a solve."""
        cache: Dict[float, Tuple[float, Optional[np.ndarray]]] = self.__dict__.setdefault("_thin_cache", {})
        if h not in cache:
            cache[h] = thin_parts(self, h)
        share, where = cache[h]
        warn_thin_parts(share, where, h, inner)

    def signed_distance(self, points: Any) -> np.ndarray:
        """Signed distance to a closed mesh (negative inside), from the angle-weighted pseudo-normal of
        the closest feature (Bærentzen & Aanæs 2005).

        Parameters
        ----------
        points : array_like
            ``(M, 3)`` points.

        Returns
        -------
        numpy.ndarray
            ``(M,)`` signed distances.

        Raises
        ------
        ValueError
            For an open mesh (no inside), or one built with ``signed=False``.

        Examples
        --------
        >>> import tubesweep as ts
        >>> spot = ts.surfaces.from_mesh(ts.data.spot())
        >>> float(spot.signed_distance([spot.vertices.mean(axis=0)])[0]) < 0
        True
        """
        if not self.signed:
            raise ValueError("signed_distance needs a closed mesh built with signed=True (or left to auto-detect)")
        x = np.ascontiguousarray(points, dtype=float).reshape(-1, 3)
        d, cp, t, code = self.closest(x)
        s = np.einsum("ij,ij->i", x - cp, self._pseudonormal(t, code))
        return np.where(s < 0, -d, d)

    # ------------------------------------------------------------------ Surface interface
    def band(self, grid: Grid, half_width: float) -> BandGeometry:
        """The band nodes within ``half_width`` of the mesh, found coarse-to-fine, with their extension
        directions ``(x − cp(x)) / |x − cp(x)|`` (Sect. 5.2; the face normal at nodes on the mesh).

        Parameters
        ----------
        grid : Grid
            The grid.
        half_width : float
            The band's half-width (a distance).

        Returns
        -------
        BandGeometry
            The band's nodes, φ (signed for a closed mesh) and directions.

        Raises
        ------
        ValueError
            If the grid is not 3D.

        Examples
        --------
        >>> import tubesweep as ts
        >>> spot = ts.surfaces.from_mesh(ts.data.spot())
        >>> grid = spot.grid(40)
        >>> geometry = spot.band(grid, 4 * grid.spacing)
        """
        self.check_grid(grid)
        h = grid.spacing
        lin = self.band_candidates(grid, half_width)
        if lin.size == 0:
            return BandGeometry(np.zeros(0, np.int64), np.zeros(0), np.zeros(0), np.zeros((0, 3), np.float32))
        x = grid.node_points(lin)
        # the closest points, the distances, signs and directions of the candidates within the
        # half-width, in Rust on all threads (tubesweep_core::band::mesh_band)
        face, pseudo = self._tree_normals()
        kept, dist, signed, direction = self.tree.band(x, float(half_width), 1e-12 * h, face, pseudo)
        return BandGeometry(lin[kept].astype(np.int64), dist, signed, direction, consumable=True)

    def band_candidates(self, grid: Grid, half_width: float) -> np.ndarray:
        """The candidate nodes of the band: the nodes of the blocks that may hold band nodes, found
        coarse-to-fine with the AABB tree.

        Parameters
        ----------
        grid : Grid
            The grid.
        half_width : float
            The band's half-width (a distance).

        Returns
        -------
        numpy.ndarray
            C-order linear indices of the candidates, sorted.

        Examples
        --------
        >>> import tubesweep as ts
        >>> spot = ts.surfaces.from_mesh(ts.data.spot())
        >>> grid = spot.grid(40)
        >>> candidates = spot.band_candidates(grid, 4 * grid.spacing)
        """
        tree = self.tree
        return coarse_to_fine_candidates(
            grid,
            half_width,
            1.0,
            lambda p, reach: self.closest(p, reach)[0],
            within=lambda p, limits: tree.any_within(
                np.ascontiguousarray(p, dtype=float), np.ascontiguousarray(limits, dtype=float)
            ),
        )

    def project(self, points: np.ndarray, grid: Grid) -> Tuple[np.ndarray, np.ndarray]:
        """Closest points on the mesh and the distances to them.

        Parameters
        ----------
        points : numpy.ndarray
            ``(M, 3)`` points.
        grid : Grid
            Unused (the mesh needs no grid); for the :class:`~tubesweep.Surface` interface.

        Returns
        -------
        distance : numpy.ndarray
            ``(M,)`` unsigned distances.
        closest : numpy.ndarray
            ``(M, 3)`` closest points.

        Examples
        --------
        >>> import tubesweep as ts
        >>> spot = ts.surfaces.from_mesh(ts.data.spot())
        >>> d, cp = spot.project(spot.vertices[:2] + 0.01, spot.grid(40))
        """
        d, cp, _, _ = self.closest(points)
        return d, cp

    # ------------------------------------------------------------------ conveniences
    @property
    def used_vertices(self) -> np.ndarray:
        return _distinct.used_vertices(self.faces, len(self.vertices))

    @property
    def default_source_vertex(self) -> int:
        """The (used) vertex farthest from the mean of the used vertices — e.g. an ear tip of the bunny."""
        u = self.used_vertices
        p = self.vertices[u]
        return int(u[np.argmax(((p - p.mean(0)) ** 2).sum(1))])

    @property
    def default_source(self) -> np.ndarray:
        return self.vertices[self.default_source_vertex].copy()

    @property
    def bounds(self) -> Tuple[np.ndarray, np.ndarray]:
        p = self.vertices[self.used_vertices]
        return p.min(0), p.max(0)

    @property
    def default_box(self) -> Tuple[Tuple[float, ...], Tuple[float, ...]]:
        g = self.grid(101)
        return tuple(float(x) for x in g.lower), tuple(float(x) for x in g.upper)

    def grid(self, n: int = 200, padding: float = 8.0) -> Grid:
        """A grid around the mesh, with the same spacing in every axis.

        Parameters
        ----------
        n : int
            Nodes along the longest side of the mesh's bounding box, padding included (at least
            ``2·padding + 3``).
        padding : float
            Empty grid spacings between the bounding box and the grid's faces on every side; it must hold
            the outer tube (``outer`` = 4 by default) plus one node.

        Returns
        -------
        Grid
            ``n`` nodes along the longest axis, fewer along the others.

        Raises
        ------
        ValueError
            If ``n`` cannot hold the padding or the padding is negative or not finite.
        TypeError
            If ``n`` is not a whole number.

        Examples
        --------
        >>> import tubesweep as ts
        >>> spot = ts.surfaces.from_mesh(ts.data.spot())
        >>> spot.grid(100).shape[2]
        100
        """
        if (
            isinstance(n, (bool, np.bool_))
            or not isinstance(n, (int, float, np.integer, np.floating))
            or not float(n).is_integer()
        ):
            raise TypeError(f"n must be a whole number of nodes along the longest axis; got {n!r}")
        n = int(n)
        try:
            pad = real_scalar(padding, "padding")
        except TypeError:
            pad = float("nan")  # refused below, as a ValueError like a negative padding
        if not (np.isfinite(pad) and pad >= 0):
            raise ValueError(f"padding must be a finite number >= 0 of grid spacings; got {padding!r}")
        if n < 2 * padding + 3:
            raise ValueError(
                f"n = {n} nodes cannot hold {padding} spacings of padding on both sides; use n >= {int(2 * padding + 3)}"
            )
        lo, hi = self.bounds
        ext = hi - lo
        h = float(ext.max()) / (n - 1 - 2 * padding)
        counts = np.maximum(3, np.ceil(ext / h - 1e-9).astype(int) + 1 + int(np.ceil(2 * padding)))
        counts[int(np.argmax(ext))] = n
        centre = 0.5 * (lo + hi)
        lower = centre - 0.5 * h * (counts - 1)
        return Grid(lower, lower + h * (counts - 1), counts)

    def triangulation(self) -> Tuple[np.ndarray, np.ndarray]:
        """The input mesh, for pictures and export.

        Returns
        -------
        vertices : numpy.ndarray
            ``(n, 3)``.
        faces : numpy.ndarray
            ``(m, 3)``.

        Examples
        --------
        >>> import tubesweep as ts
        >>> spot = ts.surfaces.from_mesh(ts.data.spot())
        >>> v, f = spot.triangulation()
        """
        return self.vertices, self.faces

    def sample(self, n: int = 1000, seed: int = 0) -> np.ndarray:
        """Random points spread over the mesh, area-weighted.

        Parameters
        ----------
        n : int
            How many points.
        seed : int
            Seed of the random generator.

        Returns
        -------
        numpy.ndarray
            ``(n, 3)`` points on the mesh.

        Examples
        --------
        >>> import tubesweep as ts
        >>> spot = ts.surfaces.from_mesh(ts.data.spot())
        >>> spot.sample(5).shape
        (5, 3)
        """
        rng = np.random.default_rng(seed)
        f = self.faces[self._good]
        a, b, c = (self.vertices[f[:, k]] for k in range(3))
        area = np.linalg.norm(np.cross(b - a, c - a), axis=1)
        t = rng.choice(len(f), size=n, p=area / area.sum())
        r1, r2 = rng.random(n), rng.random(n)
        s = np.sqrt(r1)
        return (1 - s)[:, None] * a[t] + (s * (1 - r2))[:, None] * b[t] + (s * r2)[:, None] * c[t]

    def __repr__(self) -> str:
        return (
            f"MeshSurface({self.name!r}, {len(self.vertices)} vertices, {len(self.faces)} faces, "
            f"closed={self.closed}, signed={self.signed})"
        )


class SmoothMeshSurface(smooth_mesh.SmoothMap, MeshSurface, ClosestPoint):
    """A triangle mesh through a smooth closest-point map, for second order (the default of
    :func:`from_mesh`).

    The map (``tubesweep_core::surface::mesh_smooth``, docs/point-clouds.md) is the exact closest
    point where the triangles are small against the grid spacing Δx, and elsewhere the
    moving-least-squares projection onto a local quadric fitted to the mesh's vertices and face
    centroids whose normals agree with the exact foot's triangle (so the two sheets of a thin part
    never mix), with the exact closest point as fall-back where the fit disagrees with the mesh.
    On an open mesh it is the exact map within a few Δx of the boundary, where the second-order
    geometry runs first order. Everything else is :class:`MeshSurface`'s: ``closest`` and
    ``signed_distance`` stay exact.

    Attributes
    ----------
    report : dict
        After a band: how many band nodes got each map (``fitted``, ``fine``, ``rim``,
        ``fallback``), and ``h`` the grid spacing it was built for; ``sol.stats.order2["mesh_map"]``
        holds a copy.

    Examples
    --------
    >>> import tubesweep as ts
    >>> spot = ts.surfaces.from_mesh(ts.data.spot())
    >>> type(spot).__name__, spot.smooth
    ('SmoothMeshSurface', True)
    """

    smooth = True
    open_surface = False  # order=2 runs; the geometry turns it off near the boundary

    def __init__(self, vertices: np.ndarray, faces: np.ndarray, **kwargs: Any):
        MeshSurface.__init__(self, vertices, faces, **kwargs)
        self._noise = 0.0
        self.lipschitz = 1.0
        self._smooth_map: Any = None
        self._h: Optional[float] = None
        self._band_cache: Optional[Tuple[np.ndarray, np.ndarray]] = None
        self.report: dict = {}

    def __repr__(self) -> str:
        return MeshSurface.__repr__(self)[:-1] + ", smooth=True)"


def from_mesh(
    mesh: Union[str, Path, Tuple[Any, Any]],
    *,
    normalize: bool = False,
    size: float = 1.0,
    center: Sequence[float] = (0.0, 0.0, 0.0),
    signed: Optional[bool] = None,
    smooth: bool = True,
    cut_shortcuts: bool = True,
) -> MeshSurface:
    """A triangle mesh as a surface for :func:`tubesweep.solve` (closest-point representation).

    Parameters
    ----------
    mesh : str, pathlib.Path, (vertices, faces) or a mesh object
        An OBJ / PLY / STL / OFF file (or ``.obj.gz``, e.g. :func:`tubesweep.data.bunny`), a
        pair of arrays ``(vertices (n, 3), faces (m, 3))``, or an object with ``.vertices`` and
        ``.faces`` (a ``trimesh.Trimesh``).
    normalize : bool
        Move the centre of the bounding box to ``center`` and scale the longest side to ``size``.
        The applied map is kept as ``surface.offset`` / ``surface.scale``.
    size : float
        With ``normalize``: the length of the longest side (default 1).
    center : sequence of float
        With ``normalize``: where the centre of the bounding box goes (default the origin).
    signed : bool, optional
        Report a signed distance as φ (needs a closed, consistently oriented mesh). Default: signed
        exactly when the mesh is closed. The solver itself only needs the unsigned distance and the
        extension direction ``(x − cp(x)) / |x − cp(x)|`` (Sect. 5.2), so open meshes with holes work.
    smooth : bool
        True (the default): a :class:`SmoothMeshSurface`, whose closest points follow the smooth
        surface behind the mesh where the triangles are large against the grid spacing, so that
        ``order="auto"`` runs second order on it (docs/point-clouds.md). False: the exact closest
        points of the polyhedron and the first-order scheme.
    cut_shortcuts : bool
        True (the default): the band is cut where a step of one grid spacing in the tube would
        stand for a much longer way along the surface, above the mesh's concave edges and across
        gaps narrower than the tubes, so that the front does not cut across them
        (docs/surfaces.md, "Parts of the surface that face each other"; about three times smaller
        first-order errors on scanned meshes). False: the paper's two-layer method on the whole
        band, which warns about narrow gaps instead (with ``smooth=False``, the values of earlier
        versions bit for bit).

    Returns
    -------
    MeshSurface
        The mesh as a closest-point surface for :func:`tubesweep.solve` (a
        :class:`SmoothMeshSurface` with ``smooth=True``).

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    ValueError
        If the file holds no triangles, faces index missing vertices, vertices are not finite,
        ``signed=True`` is asked of an open mesh, or ``normalize`` meets a mesh of no extent.
    ImportError
        If reading the file needs trimesh or meshio and neither is installed
        (``pip install 'tubesweep[mesh]'``, or ``pip install '.[mesh]'`` in a checkout).

    Examples
    --------
    >>> import tubesweep as ts
    >>> bunny = ts.surfaces.from_mesh(ts.data.bunny())
    >>> grid = bunny.grid(n=100)
    >>> sol = ts.solve(bunny, grid, sources=[bunny.default_source])  # doctest: +SKIP
    >>> u = sol.on_mesh(bunny.vertices)  # doctest: +SKIP
    """
    if isinstance(mesh, (str, Path)):
        v, f = read_mesh(mesh)
        name = Path(str(mesh)[:-3] if str(mesh).lower().endswith(".gz") else mesh).stem
    else:
        if isinstance(mesh, dict):  # (unpacked, its two keys were taken for the arrays: "got str")
            raise TypeError(
                f"mesh must be a file path or a pair (vertices, faces); got a dict with keys {sorted(map(str, mesh))}: "
                "pass (mesh['vertices'], mesh['faces'])"
            )
        if hasattr(mesh, "vertices") and hasattr(mesh, "faces"):  # a trimesh.Trimesh (or alike)
            mesh = (np.asarray(getattr(mesh, "vertices")), np.asarray(getattr(mesh, "faces")))
        try:
            v, f = mesh
        except (TypeError, ValueError):
            raise TypeError(
                "mesh must be a file path, a pair (vertices, faces) or a mesh object with .vertices and .faces "
                f"(trimesh); got {type(mesh).__name__}"
            ) from None
        v = real_array(v, "vertices")
        f = whole_indices(f, "faces")
        name = "mesh"
    for flag, value in (("smooth", smooth), ("cut_shortcuts", cut_shortcuts), ("normalize", normalize)):
        check_flag(value, flag)
    check_flag(signed, "signed", none=True)
    kind = SmoothMeshSurface if smooth else MeshSurface
    offset = np.zeros(3)
    scale = 1.0
    if normalize:
        size = size_parameter("size", size)
        target = finite_center(center, 3)
        if f.size == 0 or f.min() < 0 or f.max() >= len(v) or v.ndim != 2 or v.shape[1] != 3:
            return kind(v, f, signed=signed, name=name)  # raises with the mesh's own message
        used = v[_distinct.used_vertices(f, len(v))]
        lo, hi = used.min(0), used.max(0)
        if not float((hi - lo).max()) > 0:
            raise ValueError(
                "the mesh's vertices all coincide: it has no extent to normalize (every triangle is degenerate)"
            )
        scale = float(size) / float((hi - lo).max())
        offset = 0.5 * (lo + hi) - target / scale
        v = (v - offset) * scale
    surface = kind(v, f, signed=signed, name=name, scale=scale, offset=offset)
    surface.cuts_shortcuts = bool(cut_shortcuts)
    return surface
