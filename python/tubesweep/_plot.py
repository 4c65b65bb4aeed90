"""Pictures of solutions and travel-time fields (:func:`tubesweep.plot`), with matplotlib.

What a picture for a paper needs: a shaded surface coloured by the distance, iso-distance lines
with their values, the sources (red stars) and the starts of geodesic paths marked, labelled
views and a labelled colour bar; for travel times in the box, contours with their values. It uses
no pyplot state, so it displays inline in notebooks and never changes the backend.
"""

from __future__ import annotations

from typing import Any, List, Optional, Sequence, Tuple, Union

import numpy as np

from ._plot_style import (
    _LABEL_BOX,
    _SOURCE_STYLE,
    _START_STYLE,
    DISTANCE_LABEL,
    FIELD_LABEL_CLEARANCE,
    LABEL_CLEARANCE,
    TIME_LABEL,
    _check_paths,
    _colorbar,
    _label_colors,
    _label_text,
    _levels,
    _need_matplotlib,
    _source_legend,
)
from ._plot_surface import _plot_surface
from .box_solution import BoxSolution

__all__ = ["plot"]


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
    with labelled contours (in 3D the slice z through the first of ``sources``, the middle one
    without them).

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
        If matplotlib is not installed (``pip install 'tubesweep[plot]'``, or ``pip install '.[plot]'`` in a checkout).
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
    src3 = (
        np.atleast_2d(np.asarray(sources, dtype=float))
        if sources is not None and not isinstance(sources, bool)
        else np.zeros((0, grid.ndim))
    )
    if grid.ndim == 3:
        # the slice through the first source (the middle one without): a source drawn on the
        # middle slice looked like u = 0 where u was not (a review)
        k = grid.shape[2] // 2
        if len(src3) and src3.shape[1] == 3:
            k = int(np.clip(np.rint(grid.continuous_index(src3[:1])[0, 2]), 0, grid.shape[2] - 1))
            src3 = src3[np.abs(src3[:, 2] - grid.axis(2)[k]) <= 0.5 * grid.spacing]  # the sources in it
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
    if len(src3):
        ax.scatter(src3[:, 0], src3[:, 1], s=180, zorder=5, **_SOURCE_STYLE)
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
