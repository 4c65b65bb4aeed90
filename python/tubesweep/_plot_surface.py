"""Shaded surfaces for :func:`tubesweep.plot`: a mesh of the solution's zero level set (or the
user's mesh, or a point cloud) coloured by the distance, its iso-distance lines with their values,
and the default views that show where the values change."""

from __future__ import annotations

from typing import Any, List, Optional, Sequence, Tuple

import numpy as np

from ._plot_style import (
    _LABEL_BOX,
    _SOURCE_STYLE,
    _START_STYLE,
    LABEL_CLEARANCE,
    _colorbar,
    _label_colors,
    _label_text,
    _source_legend,
)
from .surface import LevelSet


def _iso_segments(v: np.ndarray, f: np.ndarray, u: np.ndarray, level: float) -> Tuple[np.ndarray, np.ndarray]:
    """Marching triangles: segments (s, 2, 3) of the piecewise-linear level line u = level and the
    faces (s,) they cross."""
    uf = u[f] - level
    pts = []
    for i, j in ((0, 1), (1, 2), (2, 0)):
        a, b = uf[:, i], uf[:, j]
        cross = (a * b < 0) & np.isfinite(a) & np.isfinite(b)
        with np.errstate(invalid="ignore"):  # (inf − inf where a part is unreached: not crossed)
            t = np.where(cross, a / np.where(cross, a - b, 1.0), np.nan)
        p = v[f[:, i]] + t[:, None] * (v[f[:, j]] - v[f[:, i]])
        pts.append(np.where(cross[:, None], p, np.nan))
    pts = np.stack(pts, axis=1)  # type: ignore[assignment]  # (m, 3 edges, 3)
    have = np.isfinite(pts[:, :, 0])  # type: ignore[call-overload]
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


def _view_title(elev: float, azim: float) -> str:
    return f"seen from azimuth {azim:.0f}°, elevation {elev:.0f}°"


#: The default views look from this many degrees above the horizon.
VIEW_TILT = 20.0
#: A surface whose longest side is this many times its second longest is seen from the side.
ELONGATED = 1.5


def _checked_views(views: Any) -> Tuple[Tuple[float, float], ...]:
    """``views`` as (elevation, azimuth) pairs of finite degrees, or a ValueError naming it
    ("not enough values to unpack" before: a helper's review)."""
    try:
        pairs = np.asarray(views, dtype=float)
    except (TypeError, ValueError):
        pairs = np.empty((0, 0))
    if pairs.ndim != 2 or pairs.shape[1] != 2 or len(pairs) == 0 or not np.all(np.isfinite(pairs)):
        raise ValueError(
            f"views must be a sequence of (elevation, azimuth) pairs in degrees, e.g. [(20, -60), (20, 120)]; got {views!r}"
        )
    return tuple((float(e), float(a)) for e, a in pairs)


#: A surface whose bounding box is thinner than this share of its largest side along one axis is
#: flat: seen from its face (:func:`_default_views`).
FLAT = 0.1
#: The elevation of both views of a flat surface lying in the horizontal plane.
FLAT_ELEVATION = 65.0


def _default_views(sol: Any, v: Optional[np.ndarray], perm: List[int]) -> Tuple[Tuple[float, float], ...]:
    """Two views (elevation, azimuth) from opposite sides: the first at the azimuth of the first
    source seen from the centre of the surface's bounding box, the second at the opposite azimuth,
    both ``VIEW_TILT`` degrees above the horizon; for a source near the top or the bottom (more
    than 45° up or down) from 45° above and 45° below instead, so that the far pole is seen."""
    pts = v if v is not None else sol.points
    pts = np.asarray(pts, dtype=float)[:, perm]
    centre = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
    ext = np.ptp(pts, axis=0)
    d = np.asarray(sol.sources, dtype=float)[:1, perm].reshape(-1)
    d = d - centre if d.size == 3 else np.zeros(3)
    longest = np.argsort(ext)[::-1]
    thin = int(longest[2])
    if ext[thin] < FLAT * float(ext.max()):
        # a flat surface (a disc, a plate, one triangle) seen from its face, not edge-on (a review:
        # a triangle drawn as a line, a disc's labels stacked on a thin ellipse)
        if thin == 2:
            off = float(np.hypot(d[0], d[1])) > 0.05 * float(ext.max() or 1.0)
            azim = float(np.degrees(np.arctan2(d[1], d[0]))) if off else -60.0
            return ((FLAT_ELEVATION, azim), (FLAT_ELEVATION, azim + 180.0 if azim <= 0 else azim - 180.0))
        face = 0.0 if thin == 0 else 90.0
        return ((VIEW_TILT, face), (VIEW_TILT, face - 180.0))
    k = int(longest[0])
    if k != 2 and ext[k] > ELONGATED * ext[longest[1]]:
        # a surface elongated across the view is seen from the side, turned at most 30° towards the
        # source's end: looking along its length would hide most of it
        other = 1 - k
        d[k] = np.clip(d[k], -np.tan(np.radians(30.0)) * abs(d[other]), np.tan(np.radians(30.0)) * abs(d[other]))
        if abs(d[other]) <= 0.05 * float(ext.max()):
            d[other] = -1.0 if k == 0 else 1.0  # the source at an end: from the front
            d[k] = np.sign(d[k]) * np.tan(np.radians(30.0))
    horizontal = float(np.hypot(d[0], d[1]))
    azim = float(np.degrees(np.arctan2(d[1], d[0]))) if horizontal > 0.05 * float(ext.max() or 1.0) else -60.0
    far = azim + 180.0 if azim <= 0 else azim - 180.0
    elev = float(np.degrees(np.arctan2(d[2], horizontal)))
    if abs(elev) > 45.0 and np.linalg.norm(d) > 0.05 * float(ext.max() or 1.0):
        up = 45.0 if elev > 0 else -45.0
        return ((up, azim), (-up, far))
    return ((VIEW_TILT, azim), (VIEW_TILT, far))


def _plot_surface(
    sol: Any,
    lv: np.ndarray,
    umax: float,
    *,
    ax: Any,
    mesh: Any,
    cmap: str,
    views: Optional[Sequence[Tuple[float, float]]],
    title: Optional[str],
    sources: bool,
    colorbar: bool,
    up: str,
    lines: List[np.ndarray],
    color: str,
    label: str,
) -> Any:
    import matplotlib
    from matplotlib import cm, colors as mcolors
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    from ._triangulate import triangulate

    cmap_obj = matplotlib.colormaps[cmap] if isinstance(cmap, str) else cmap
    norm = mcolors.Normalize(0.0, umax)
    perm = {"x": [1, 2, 0], "y": [2, 0, 1], "z": [0, 1, 2]}[up]  # a cyclic permutation puts `up` last
    try:
        v, f = triangulate(sol, mesh=mesh)
    except ValueError:
        if mesh is not None or isinstance(sol.surface, LevelSet):
            raise
        v, f = None, None  # a bare closest-point surface: drawn as its points
    if views is None:
        views = _default_views(sol, v, perm)
    else:
        views = _checked_views(views)
    if ax is not None:
        axes = [ax]
        fig = ax.figure
        views = views[:1]
    else:
        fig = Figure(figsize=(5.2 * len(views) + 1.2, 5.2))
        axes = [
            fig.add_subplot(1, len(views), i + 1, projection="3d", computed_zorder=False) for i in range(len(views))
        ]
    by_label = color == "nearest_source" and len(sol.sources) > 1
    src = sol.sources[:, perm]
    if v is None:
        _draw_point_cloud(sol, axes, views, perm, cmap_obj, norm, by_label, sources, src, lines)
        grey = bool(np.any(np.isinf(sol.values)))
    else:
        grey = _draw_mesh(
            sol,
            v,
            f,  # type: ignore[arg-type]
            axes,
            views,
            perm,
            cmap_obj,
            norm,
            lv,
            by_label,
            sources,
            src,
            lines,
            Poly3DCollection,
            Line3DCollection,
        )
    if by_label:
        _source_legend(fig, axes, len(sol.sources))
    elif colorbar:
        sm = cm.ScalarMappable(norm=norm, cmap=cmap_obj)
        sm.set_array([])
        _colorbar(fig, sm, axes, label, lv)
    # parts of the surface no source reaches are drawn grey: said once, under the title
    said = [t for t in (title, "(grey: not reached, u = inf)" if grey else "") if t]
    if said:
        fig.suptitle("\n".join(said))
    return fig


def _draw_mesh(
    sol: Any,
    v: np.ndarray,
    f: np.ndarray,
    axes: List[Any],
    views: Sequence[Tuple[float, float]],
    perm: List[int],
    cmap_obj: Any,
    norm: Any,
    lv: np.ndarray,
    by_label: bool,
    sources: bool,
    src: np.ndarray,
    lines: List[np.ndarray],
    Poly3DCollection: Any,
    Line3DCollection: Any,
) -> bool:
    """Draws the mesh in each of ``axes``; whether a face was drawn grey (no corner reached)."""
    if f.shape[1] == 4:  # quads as two triangles each: the shading and the iso-lines walk triangles
        f = np.vstack([f[:, [0, 1, 2]], f[:, [0, 2, 3]]])
    u = sol.on_mesh(v)
    v = v[:, perm]
    tri = v[f]
    finite = np.isfinite(u[f])
    # the mean of the reached corners (NaN for a face none of whose corners was reached)
    uface = np.where(finite, u[f], 0.0).sum(axis=1) / np.where(finite.any(axis=1), finite.sum(axis=1), np.nan)
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    centroids = tri.mean(1)
    if by_label:
        base = _label_colors(sol.nearest_source(centroids[:, np.argsort(perm)]))
    else:
        base = cmap_obj(norm(np.nan_to_num(uface, nan=float(norm.vmax))))
        base[~np.isfinite(uface)] = (0.7, 0.7, 0.7, 1.0)
    iso = [_iso_segments(v, f, u, c) for c in lv]
    orient = _orientation(f, v)
    segs = [np.stack([q[:-1], q[1:]], axis=1)[:, :, perm] for q in lines if len(q) >= 2]
    seg = np.concatenate(segs) if segs else np.zeros((0, 2, 3))
    seg_near = _nearest_face(seg.mean(1), centroids)
    src_near = _nearest_face(src, centroids)
    starts = np.array([q[0][perm] for q in lines]).reshape(-1, 3)
    start_near = _nearest_face(starts, centroids)
    ext = np.ptp(v, axis=0)
    size = float(ext.max())
    for a, (elev, azim) in zip(axes, views):
        e, z = np.radians(elev), np.radians(azim)
        eye = np.array([np.cos(e) * np.cos(z), np.cos(e) * np.sin(z), np.sin(e)])
        light = eye + np.array([0.3, 0.3, 0.6])
        light /= np.linalg.norm(light)
        shade = 0.45 + 0.55 * np.abs(n @ light)
        fc = base.copy()
        fc[:, :3] *= shade[:, None]
        a.add_collection3d(Poly3DCollection(tri, facecolors=fc, edgecolors=fc, linewidths=0.2, zorder=1))

        def facing(faces: np.ndarray, strict: bool = False) -> np.ndarray:
            if orient == 0:
                return np.ones(len(faces), bool)
            d = (n[faces] @ eye) * orient
            return d > 0 if strict else d >= 0

        # iso-lines over the surface (on an oriented mesh only those on faces that face the eye),
        # each labelled with its value where it faces the eye most
        placed: List[np.ndarray] = []
        for k, (s_all, s_face) in enumerate(iso):
            seen = facing(s_face, strict=True)
            if not np.any(seen):
                continue
            a.add_collection3d(Line3DCollection(s_all[seen], colors="k", linewidths=0.6, zorder=2))
            if k % 2 == 0:
                mids = s_all[seen].mean(axis=1)
                score = (n[s_face[seen]] @ eye) * (orient if orient != 0 else 1.0)
                for j in np.argsort(-score)[:50]:
                    # apart from the other labels, and not under a source's star
                    if all(np.linalg.norm(mids[j] - q) > 0.12 * size for q in placed) and not (
                        sources and np.any(np.linalg.norm(src - mids[j], axis=1) < LABEL_CLEARANCE * size)
                    ):
                        a.text(
                            *mids[j],
                            _label_text(lv[k]),
                            fontsize=7,
                            ha="center",
                            va="center",
                            zorder=4,
                            bbox=_LABEL_BOX,
                        )
                        placed.append(mids[j])
                        break
        if len(seg):
            front = facing(seg_near)
            for sel, alpha in ((front, 1.0), (~front, 0.3)):
                if np.any(sel):
                    a.add_collection3d(Line3DCollection(seg[sel], colors="r", linewidths=1.6, alpha=alpha, zorder=3))
        # the starts of the paths, faint on the far side like the paths themselves; the sources
        # only where the eye sees them (on the far side a star would seem to lie on the near side)
        front = facing(start_near)
        for sel, alpha in ((front, 1.0), (~front, 0.35)):
            if np.any(sel):
                a.scatter(*starts[sel].T, s=40, depthshade=False, zorder=4, alpha=alpha, **_START_STYLE)
        front = facing(src_near)
        if sources and np.any(front):
            a.scatter(*src[front].T, s=220, depthshade=False, zorder=5, **_SOURCE_STYLE)
        _frame(a, v, ext, elev, azim)
    return bool(np.any(~finite.any(axis=1)))


def _draw_point_cloud(
    sol: Any,
    axes: List[Any],
    views: Sequence[Tuple[float, float]],
    perm: List[int],
    cmap_obj: Any,
    norm: Any,
    by_label: bool,
    sources: bool,
    src: np.ndarray,
    lines: List[np.ndarray],
) -> None:
    """A surface with no mesh: the closest points of the band nodes nearest to it, coloured."""
    h = sol.grid.spacing
    near = np.abs(sol.phi) <= 0.75 * h
    nodes = sol.points[near]
    _, cp = sol.surface.project(nodes, sol.grid)
    cp = np.asarray(cp, dtype=float)
    u = sol.values[near]
    ok = np.isfinite(u)
    cp, u = cp[ok], u[ok]
    colors = _label_colors(sol.nearest_source(cp)) if by_label else cmap_obj(norm(u))
    p = cp[:, perm]
    ext = np.ptp(p, axis=0)
    for a, (elev, azim) in zip(axes, views):
        a.scatter(*p.T, c=colors, s=5, depthshade=True, zorder=1)
        for q in lines:
            qq = q[:, perm]
            a.plot(*qq.T, "r-", lw=1.6, zorder=3)
            a.scatter(*qq[:1].T, s=40, depthshade=False, zorder=4, **_START_STYLE)
        if sources:
            a.scatter(*src.T, s=220, depthshade=False, zorder=5, **_SOURCE_STYLE)
        _frame(a, p, ext, elev, azim)


#: The share of the projected bounding box (which mplot3d fits into the panel) that the surface spans.
FILL = 0.95


def _frame(a: Any, v: np.ndarray, ext: np.ndarray, elev: float, azim: float) -> None:
    """The whole surface in the panel: the axes' limits its bounding box, equal scales on the three
    axes, and the zoom chosen so that the projected surface spans ``FILL`` of the projected box."""
    from mpl_toolkits.mplot3d import proj3d

    lo, hi = v.min(0), v.max(0)
    flat = hi - lo <= 1e-9 * max(float((hi - lo).max()), 1e-300)  # a flat surface's own plane: a hair of depth
    lo, hi = (
        np.where(flat, lo - 1e-6 * max(float((hi - lo).max()), 1e-300), lo),
        np.where(flat, hi + 1e-6 * max(float((hi - lo).max()), 1e-300), hi),
    )
    a.set_xlim(lo[0], hi[0])
    a.set_ylim(lo[1], hi[1])
    a.set_zlim(lo[2], hi[2])
    aspect = tuple(np.maximum(ext, 1e-9 * ext.max()))
    a.view_init(elev, azim)
    a.set_axis_off()
    a.set_title(_view_title(elev, azim), fontsize=9)
    a.set_box_aspect(aspect, zoom=1.0)
    # at zoom 1 the projected bounding box fits the panel; the zoom scales the projection about the
    # box's centre: scale until the projected surface (not its box's corners) spans FILL of it
    corners = np.array(np.meshgrid(*zip(lo, hi), indexing="ij")).reshape(3, -1)
    sample = v[:: max(1, len(v) // 20000)].T
    M = a.get_proj()
    bx, by, _ = proj3d.proj_transform(*corners, M)
    x, y, _ = proj3d.proj_transform(*sample, M)
    cx, cy = 0.5 * (bx.min() + bx.max()), 0.5 * (by.min() + by.max())
    reach = max(
        float(np.max(np.abs(x - cx))) / max(0.5 * float(np.ptp(bx)), 1e-300),
        float(np.max(np.abs(y - cy))) / max(0.5 * float(np.ptp(by)), 1e-300),
    )
    a.set_box_aspect(aspect, zoom=FILL / max(reach, 1e-3))
