"""Pictures of solutions and travel-time fields (:func:`tubesweep.plot`), with matplotlib.

What a picture for a paper needs: a shaded surface coloured by the distance, iso-distance lines
with their values, the sources (red stars) and the starts of geodesic paths marked, labelled
views and a labelled colour bar; for travel times in the box, contours with their values. It uses
no pyplot state, so it displays inline in notebooks and never changes the backend.
"""

from __future__ import annotations

from typing import Any, List, Optional, Sequence, Tuple, Union

import numpy as np

from ._validate import real_array
from .box_solution import BoxSolution
from .surface import LevelSet

__all__ = ["plot"]

#: The colour bar's label by what is shown.
DISTANCE_LABEL = "geodesic distance"
TIME_LABEL = "travel time"

_SOURCE_STYLE = dict(c="r", marker="*", edgecolors="k", linewidths=0.6, gid="sources")
_START_STYLE = dict(marker="o", facecolors="w", edgecolors="r", linewidths=1.4, gid="path starts")
#: Iso-line labels keep this share of the surface's size away from the sources' stars.
LABEL_CLEARANCE = 0.15
#: Contour labels of a travel-time field keep this share of the box's size away from the stars.
FIELD_LABEL_CLEARANCE = 0.08
_LABEL_BOX = dict(boxstyle="round,pad=0.12", fc="w", ec="none", alpha=0.75)


def _need_matplotlib() -> Any:
    try:
        import matplotlib
    except ImportError:
        raise ImportError("plotting needs the optional package 'matplotlib': pip install 'tubesweep[plot]'") from None
    return matplotlib


def _levels(levels: Any, umax: float) -> np.ndarray:
    """The iso-values: ``levels`` values, or that many round values in (0, umax)."""
    from matplotlib.ticker import MaxNLocator

    if np.ndim(levels) == 0:
        if isinstance(levels, np.ndarray):
            levels = levels.item()
        if (
            isinstance(levels, (bool, np.bool_))
            or not isinstance(levels, (int, float, np.integer, np.floating))
            or not (float(levels).is_integer() and 0 <= levels <= 1000)
        ):
            raise ValueError(
                f"levels must be a number of iso-lines (an integer from 0 to 1000) or a sequence of their "
                f"values; got {levels!r}"
            )
        lv = MaxNLocator(int(levels) + 1).tick_values(0.0, umax) if levels > 0 else np.zeros(0)
    else:
        lv = real_array(levels, "levels").reshape(-1)
        if not np.all(np.isfinite(lv)):
            raise ValueError(f"levels must be finite values of the solution; got {levels!r}")
    return lv[(lv > 0) & (lv < umax)]  # type: ignore[index, operator, return-value]


def _label_text(value: float) -> str:
    return f"{value:.3g}"


def _colorbar(fig: Any, mappable: Any, axes: Any, label: str, lv: np.ndarray) -> Any:
    cb = fig.colorbar(mappable, ax=axes, shrink=0.75, label=label)
    for c in lv:  # the iso-values drawn on the bar, so each line's value can be read off
        cb.ax.axhline(c, color="k", lw=0.7)
    return cb


def _check_paths(paths: Optional[Sequence[Any]], ndim: int) -> List[np.ndarray]:
    lines = [real_array(q, f"paths[{i}]") for i, q in enumerate(paths or [])]
    for i, q in enumerate(lines):
        if q.ndim != 2 or q.shape[1] != ndim or len(q) < 1:
            raise ValueError(f"paths[{i}] must be an array of shape (P, {ndim}); got shape {q.shape}")
    return lines


def plot(
    sol: Any,
    *,
    grid: Any = None,
    ax: Any = None,
    mesh: Optional[Tuple[Any, Any]] = None,
    levels: Union[int, Sequence[float]] = 12,
    cmap: str = "viridis",
    views: Optional[Sequence[Tuple[float, float]]] = None,
    title: Optional[str] = None,
    sources: Any = True,
    colorbar: bool = True,
    up: str = "z",
    paths: Optional[Sequence[Any]] = None,
    color: str = "distance",
    label: Optional[str] = None,
    speed: Any = None,
) -> Any:
    """A picture of a solution, or of a travel-time field: a matplotlib Figure.

    Surfaces (3D): the surface shaded and coloured by the distance, iso-distance lines labelled
    with their values, the sources as red stars, one labelled panel per view. Curves (2D): the
    curve coloured by the distance, with ticks and values where it crosses each iso-value. Travel
    times in the box (an array from :func:`tubesweep.travel_time` with its ``grid``): the field
    with labelled contours (the middle slice in 3D).

    Parameters
    ----------
    sol : Solution, BoxSolution or numpy.ndarray
        A :func:`tubesweep.solve` result, a :func:`tubesweep.travel_time` result with
        ``return_solution=True`` (its grid and sources come with it), or a travel-time array
        (then ``grid`` is needed).
    grid : Grid, optional
        The grid of a travel-time array.
    ax : matplotlib Axes, optional
        Draw into this axes (a 3D axes for surfaces: only the first view is drawn). Default: a
        new figure.
    mesh : (vertices, faces), optional
        The surface mesh to draw (3D); default: :func:`tubesweep.triangulate`'s. A surface with no
        mesh (a bare :class:`~tubesweep.ClosestPoint`) is drawn as the cloud of its closest points.
    levels : int or sequence of float
        How many iso-lines (round values are chosen), or their values.
    cmap : str
        A matplotlib colour map for the distance.
    views : sequence of (elevation, azimuth), optional
        One 3D panel per view, in degrees. Default: two panels from opposite sides, 20° above
        the horizon, the first at the (first) source's azimuth, the second at the far side; for a
        source near the top or bottom, from 45° above and below (the far pole in the second); a
        surface elongated across the view seen from the side. Each panel frames the whole
        surface with equal scales on the three axes.
    title : str, optional
        The figure's title.
    sources : bool or array
        Mark the sources (a solution's own; for a travel-time array, pass their coordinates).
    colorbar : bool
        Draw a colour bar (labelled ``label``, with the iso-values on it).
    up : {"x", "y", "z"}
        The axis drawn vertically in 3D (most mesh files, the bunny and Spot among them, use "y").
    paths : sequence of (P, d) arrays, optional
        Polylines drawn in red, e.g. :meth:`Solution.geodesic_paths`; each start is marked with a
        circle, and in 3D a segment on the far side of an oriented surface is drawn faint.
    color : {"distance", "nearest_source"}
        Colour by the distance, or by which source reaches each place first (the geodesic Voronoi
        cells of :meth:`Solution.nearest_source`; iso-distance lines are drawn over them).
    label : str, optional
        The colour bar's label; default "geodesic distance" (surfaces) or "travel time" (fields).
    speed : array, optional
        For a travel-time field: the speed on the grid, drawn as the background (the contours of
        the travel time over it).

    Returns
    -------
    matplotlib.figure.Figure
        Save it with ``fig.savefig("u.png")``; it displays inline in notebooks.

    Raises
    ------
    ImportError
        If matplotlib is not installed (``pip install 'tubesweep[plot]'``).
    ValueError
        For a bad ``levels``, ``up``, ``color`` or ``paths``, or a travel-time array without
        a matching ``grid``.

    Examples
    --------
    >>> import tubesweep as ts
    >>> s = ts.surfaces.Sphere(0.5)
    >>> sol = ts.solve(s, ts.Grid((-1, -1, -1), (1, 1, 1), (61, 61, 61)), [s.default_source])
    >>> fig = ts.plot(sol, title="geodesic distance on a sphere")
    >>> fig.savefig("sphere.png")  # doctest: +SKIP
    """
    _need_matplotlib()
    if color not in ("distance", "nearest_source"):
        raise ValueError(f"color must be 'distance' or 'nearest_source'; got {color!r}")
    if isinstance(sol, BoxSolution):  # travel_time(..., return_solution=True): its field, grid and sources
        if grid is not None and grid != sol.grid:
            raise ValueError("a travel-time solution carries its own grid; leave out grid= (or pass sol.values)")
        grid = sol.grid
        sources = sol.sources if sources is True else (None if sources is False else sources)
        sol = sol.values
    if isinstance(sol, np.ndarray) or (grid is not None and not hasattr(sol, "surface")):
        return _plot_field(
            np.asarray(sol, dtype=float),
            grid,
            ax=ax,
            levels=levels,
            cmap=cmap,
            title=title,
            sources=sources,
            colorbar=colorbar,
            label=label or TIME_LABEL,
            speed=speed,
            paths=paths,
        )
    grid = sol.grid
    lines = _check_paths(paths, grid.ndim)
    finite = sol.values[np.isfinite(sol.values)]
    umax = float(finite.max()) if finite.size else 1.0
    lv = _levels(levels, umax)
    if grid.ndim == 2:
        return _plot_curve(
            sol,
            lv,
            umax,
            ax=ax,
            cmap=cmap,
            title=title,
            sources=bool(sources),
            colorbar=colorbar,
            label=label or DISTANCE_LABEL,
            lines=lines,
            color=color,
        )
    if up not in ("x", "y", "z"):
        raise ValueError(f"up must be 'x', 'y' or 'z'; got {up!r}")
    return _plot_surface(
        sol,
        lv,
        umax,
        ax=ax,
        mesh=mesh,
        cmap=cmap,
        views=views,
        title=title,
        sources=bool(sources),
        colorbar=colorbar,
        up=up,
        lines=lines,
        color=color,
        label=label or DISTANCE_LABEL,
    )


# ---------------------------------------------------------------------------------------------
# the whole box
# ---------------------------------------------------------------------------------------------
def _plot_field(
    u: np.ndarray,
    grid: Any,
    *,
    ax: Any,
    levels: Any,
    cmap: str,
    title: Optional[str],
    sources: Any,
    colorbar: bool,
    label: str,
    speed: Any,
    paths: Any,
) -> Any:
    from matplotlib.figure import Figure

    if grid is None or not hasattr(grid, "shape"):
        raise ValueError("plotting a travel-time array needs its grid: ts.plot(u, grid=grid)")
    if tuple(u.shape) != tuple(grid.shape):
        raise ValueError(f"the travel-time array has shape {u.shape} but the grid {tuple(grid.shape)}")
    back = None if speed is None else np.asarray(speed, dtype=float)
    if back is not None and back.shape != u.shape:
        raise ValueError(f"speed must be an array of the grid's shape {tuple(grid.shape)}; got {back.shape}")
    where = ""
    if grid.ndim == 3:
        k = grid.shape[2] // 2
        u = u[:, :, k]
        back = None if back is None else back[:, :, k]
        where = f" (slice z = {grid.axis(2)[k]:.3g})"
    x, y = grid.axis(0), grid.axis(1)
    finite = u[np.isfinite(u)]
    umax = float(finite.max()) if finite.size else 1.0
    lv = _levels(levels, umax)
    if ax is None:
        fig = Figure(figsize=(6.2, 5.4))
        ax = fig.add_subplot(1, 1, 1)
    fig = ax.figure
    if back is None:
        m = ax.pcolormesh(x, y, u.T, shading="auto", cmap=cmap)
        line_color = "k"
    else:
        m = ax.pcolormesh(x, y, back.T, shading="auto", cmap="cividis")
        line_color = "w"
    if lv.size:
        from matplotlib import patheffects

        cs = ax.contour(x, y, u.T, levels=lv, colors=line_color, linewidths=0.8)
        if back is not None:  # white lines outlined, readable on light and dark layers alike
            cs.set_path_effects([patheffects.withStroke(linewidth=1.8, foreground="k")])
        src = (
            np.atleast_2d(np.asarray(sources, dtype=float))[:, :2]
            if sources is not None and not isinstance(sources, bool)
            else np.zeros((0, 2))
        )
        at = _field_label_places(cs, src, float(max(x[-1] - x[0], y[-1] - y[0])))
        for t in ax.clabel(cs, fmt=_label_text, fontsize=7, inline=True, colors="k", manual=at):
            t.set_bbox(_LABEL_BOX)
    for q in _check_paths(paths, 2):
        ax.plot(q[:, 0], q[:, 1], "r-", lw=1.5)
        ax.scatter(q[:1, 0], q[:1, 1], s=30, zorder=4, **_START_STYLE)
    if sources is not None and not isinstance(sources, bool):
        src = np.atleast_2d(np.asarray(sources, dtype=float))
        ax.scatter(src[:, 0], src[:, 1], s=180, zorder=5, **_SOURCE_STYLE)
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    if colorbar:
        cb = fig.colorbar(m, ax=ax, shrink=0.85, label="speed F" if back is not None else label)
        if back is None:
            for c in lv:
                cb.ax.axhline(c, color="k", lw=0.7)
    ax.set_title((title or "") + where if (title or where) else "")
    return fig


def _field_label_places(cs: Any, sources: np.ndarray, size: float) -> List[Tuple[float, float]]:
    """One place per contour line for its label: the middle of its longest piece among the points
    ``FIELD_LABEL_CLEARANCE · size`` or more from every source (a line closer than that all round,
    such as a small circle about a source, goes unlabelled: its label would cover the star)."""
    places = []
    for level_segs in cs.allsegs:
        best: Optional[np.ndarray] = None
        for seg in level_segs:
            seg = np.asarray(seg, dtype=float).reshape(-1, 2)
            if len(sources):
                far = np.min(np.linalg.norm(seg[:, None, :] - sources[None, :, :], axis=2), axis=1)
                seg = seg[far >= FIELD_LABEL_CLEARANCE * size]
            if len(seg) and (best is None or len(seg) > len(best)):
                best = seg
        if best is not None:
            p = best[len(best) // 2]
            places.append((float(p[0]), float(p[1])))
    return places


# ---------------------------------------------------------------------------------------------
# curves
# ---------------------------------------------------------------------------------------------
def _label_colors(labels: np.ndarray) -> np.ndarray:
    """One qualitative colour per source (tab10, repeating), grey where no front arrives."""
    import matplotlib

    tab = matplotlib.colormaps["tab10"]
    rgba = np.array([tab(int(k) % 10) for k in np.maximum(labels, 0)], dtype=float).reshape(-1, 4)
    rgba[labels < 0] = (0.7, 0.7, 0.7, 1.0)
    return rgba


def _source_legend(fig: Any, axes: Any, n: int) -> None:
    from matplotlib.patches import Patch

    handles = [Patch(color=_label_colors(np.array([k]))[0], label=f"nearest to source {k}") for k in range(n)]
    fig.legend(handles=handles, loc="lower center", ncol=min(n, 4), fontsize=8, frameon=False)


def _plot_curve(
    sol: Any,
    lv: np.ndarray,
    umax: float,
    *,
    ax: Any,
    cmap: str,
    title: Optional[str],
    sources: bool,
    colorbar: bool,
    label: str,
    lines: List[np.ndarray],
    color: str,
) -> Any:
    import matplotlib
    from matplotlib import colors as mcolors
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure

    from ._triangulate import triangulate

    grid = sol.grid
    cmap_obj = matplotlib.colormaps[cmap] if isinstance(cmap, str) else cmap
    norm = mcolors.Normalize(0.0, umax)
    if ax is None:
        fig = Figure(figsize=(6.2, 5.4))
        ax = fig.add_subplot(1, 1, 1)
    fig = ax.figure
    # the band, faint, for where the solution lives; the curve itself carries the colours
    dense = sol.to_dense()
    dense = np.where(np.isfinite(dense), dense, np.nan)
    X, Y = grid.meshgrid()
    ax.pcolormesh(X, Y, dense, shading="auto", cmap=cmap_obj, norm=norm, alpha=0.35)
    try:
        v, seg = triangulate(sol)
    except (ValueError, ImportError):
        v, seg = None, None
    if v is not None and len(seg):  # type: ignore[arg-type]
        u = sol.on_mesh(v)
        ends = v[seg]
        useg = np.nanmean(u[seg], axis=1)
        if color == "nearest_source" and len(sol.sources) > 1:
            lab = sol.nearest_source(ends.mean(axis=1))
            cols = _label_colors(lab)
        else:
            cols = cmap_obj(norm(np.nan_to_num(useg, nan=umax)))
        ax.add_collection(LineCollection(ends, colors=cols, linewidths=4.0, capstyle="round", zorder=2))  # type: ignore[arg-type]
        _curve_ticks(ax, v, seg, u, lv, sol.sources if sources else np.zeros((0, 2)))  # type: ignore[arg-type]
    elif lv.size:
        ax.contour(X, Y, dense, levels=lv, colors="k", linewidths=0.5)
    for q in lines:
        ax.plot(q[:, 0], q[:, 1], "r-", lw=1.5, zorder=3)
        ax.scatter(q[:1, 0], q[:1, 1], s=30, zorder=4, **_START_STYLE)
    if sources:
        ax.scatter(sol.sources[:, 0], sol.sources[:, 1], s=200, zorder=5, **_SOURCE_STYLE)
    ax.set_aspect("equal")
    p = sol.points
    lo, hi = p.min(0), p.max(0)
    pad = 0.08 * float((hi - lo).max())
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    if color == "nearest_source" and len(sol.sources) > 1:
        _source_legend(fig, ax, len(sol.sources))
    elif colorbar:
        from matplotlib import cm

        sm = cm.ScalarMappable(norm=norm, cmap=cmap_obj)  # the curve's colours, not the faint band's
        sm.set_array([])
        _colorbar(fig, sm, ax, label, lv)
    if title:
        ax.set_title(title)
    return fig


def _curve_ticks(ax: Any, v: np.ndarray, seg: np.ndarray, u: np.ndarray, lv: np.ndarray, avoid: np.ndarray) -> None:
    """A short black tick across the curve where it crosses each iso-value, and the value beside
    every other one (so that the labels do not crowd), away from the sources' stars (``avoid``)."""
    if not lv.size:
        return
    a, b = u[seg[:, 0]], u[seg[:, 1]]
    centre = v.mean(axis=0)
    size = float(np.ptp(v, axis=0).max())
    placed: List[np.ndarray] = []
    for i, c in enumerate(lv):
        cross = np.isfinite(a) & np.isfinite(b) & ((a - c) * (b - c) < 0)
        for k in np.flatnonzero(cross):
            t = (c - a[k]) / (b[k] - a[k])
            p = v[seg[k, 0]] + t * (v[seg[k, 1]] - v[seg[k, 0]])
            d = v[seg[k, 1]] - v[seg[k, 0]]
            n = np.array([-d[1], d[0]]) / max(np.hypot(*d), 1e-300)
            if np.dot(n, p - centre) < 0:  # the outward side, for the label
                n = -n
            tick = 0.025 * size
            ax.plot(
                [p[0] - tick * n[0], p[0] + tick * n[0]],
                [p[1] - tick * n[1], p[1] + tick * n[1]],
                "k-",
                lw=1.0,
                zorder=3,
            )
            q = p + 0.07 * size * n
            clear = not np.any(np.linalg.norm(avoid - q, axis=1) < LABEL_CLEARANCE * size)
            if i % 2 == 0 and clear and all(np.linalg.norm(p - q) > 0.15 * size for q in placed):
                ax.text(q[0], q[1], _label_text(c), fontsize=7, ha="center", va="center", zorder=4, bbox=_LABEL_BOX)
                placed.append(p)


# ---------------------------------------------------------------------------------------------
# surfaces
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
    else:
        _draw_mesh(
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
    if title:
        fig.suptitle(title)
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
) -> None:
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
