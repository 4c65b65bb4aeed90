"""Geodesic paths traced back from the solution (Solution.geodesic_path(s), tubesweep.geodesic_paths)."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import tubesweep as ts
from tubesweep.flows import solid_body_rotation

R = 0.5


def _sphere(n, sources):
    return ts.solve(ts.surfaces.Sphere(R), ts.Grid((-1, -1, -1), (1, 1, 1), (n, n, n)), sources)


def _length(path):
    return float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())


def _random_sphere_points(m, seed, away_from=None, margin=0.3):
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < m:
        p = rng.normal(size=3)
        p *= R / np.linalg.norm(p)
        if away_from is None or R * np.arccos(np.clip(p @ away_from / R**2, -1, 1)) < np.pi * R - margin:
            out.append(p)
    return np.array(out)


@pytest.mark.parametrize("n", [41, 81])
def test_paths_on_a_sphere_follow_great_circles_to_the_source(n):
    src = np.array([-R, 0.0, 0.0])
    sol = _sphere(n, [src])
    h = sol.grid.spacing
    starts = _random_sphere_points(12, 3, away_from=src)
    paths = sol.geodesic_paths(starts)
    off_plane = []
    for s0, path in zip(starts, paths):
        assert np.allclose(path[0], s0, atol=1e-12)
        assert np.array_equal(path[-1], src)  # the path ends on the source itself
        # every point on the sphere, to the accuracy of the level set's projection (two Newton steps)
        assert np.max(np.abs(np.linalg.norm(path, axis=1) - R)) < 1e-6
        exact = R * np.arccos(np.clip(src @ s0 / R**2, -1, 1))
        # the length is first-order accurate (benches/paths_and_labels.py, other starts: 0.16 h, 0.15 h)
        assert abs(_length(path) - exact) < 0.5 * h
        normal = np.cross(s0, src)
        off_plane.append(np.max(np.abs(path @ (normal / np.linalg.norm(normal)))))
    # the distance from the great circle converges more slowly than the length (medians measured:
    # 0.020 at N = 41, 0.017 at N = 81, 0.012 at N = 161, 0.0077 at N = 321)
    assert np.median(off_plane) < 0.03 and max(off_plane) < 0.1


def test_a_path_on_a_circle_runs_along_the_arc():
    g = ts.Grid((-1, -1), (1, 1), (201, 201))
    sol = ts.solve(ts.surfaces.Circle(0.6), g, [(0.6, 0.0)])
    path = sol.geodesic_path((0.0, 0.6), step=0.25)
    assert np.array_equal(path[-1], [0.6, 0.0])
    assert np.max(np.abs(np.linalg.norm(path, axis=1) - 0.6)) < 1e-6
    assert np.all(path[:, 0] >= -1e-12) and np.all(path[:, 1] >= -1e-12)  # the short way round
    assert abs(_length(path) - 0.6 * np.pi / 2) < 1e-3


def test_paths_end_at_the_source_that_reaches_the_start_first():
    sources = np.array([[R, 0, 0], [-R, 0, 0], [0, 0, R]])
    sol = _sphere(61, sources)
    starts = _random_sphere_points(20, 5)
    labels = sol.nearest_source(starts)
    for s0, path, k in zip(starts, sol.geodesic_paths(starts), labels):
        end = int(np.argmin(np.linalg.norm(sources - path[-1], axis=1)))
        assert np.array_equal(path[-1], sources[end])
        geo = R * np.arccos(np.clip(sources @ s0 / R**2, -1, 1))
        if np.sort(geo)[1] - geo.min() > 4 * sol.grid.spacing:
            assert end == np.argmin(geo) == k


@pytest.mark.parametrize("n", [61, 121])
def test_paths_from_where_regions_meet_leave_the_boundary(n):
    sources = np.array([[R, 0, 0], [-R, 0, 0], [0, 0, R]])
    sol = _sphere(n, sources)
    h = sol.grid.spacing
    two = np.array([0.0, -0.3, -0.4])  # as far from sources 0 and 1, on the boundary of their regions
    three = np.array([0.0, R, 0.0])  # as far from all three
    p2, p3 = sol.geodesic_paths([two, three])
    # measured: 0.03 h and 0.72 h at N = 61, 0.04 h and 0.30 h at N = 121 (benches/paths_and_labels.py
    # prints other N); with central differences alone the first ran along the boundary, 1.8 h too long
    assert abs(_length(p2) - np.pi / 4 * 2 * R) < 0.2 * h
    assert abs(_length(p3) - np.pi / 4 * 2 * R) < 1.0 * h
    for p in (p2, p3):
        assert any(np.array_equal(p[-1], s) for s in sources)


def test_paths_on_a_mesh_and_an_open_surface_reach_the_source():
    g = ts.Grid((-1, -1, -1), (1, 1, 1), (61, 61, 61))
    hemi = ts.solve(ts.surfaces.Hemisphere(), g, [(0.0, 0.0, 0.5)])
    starts = np.array([[0.5, 0.0, 0.0], [0.0, -0.3, 0.4], [-0.3, 0.0, 0.4]])
    for s0, path in zip(starts, hemi.geodesic_paths(starts)):
        assert np.array_equal(path[-1], [0.0, 0.0, 0.5])
        assert np.all(path[:, 2] >= -1e-9)  # stays on the hemisphere
        assert abs(_length(path) - 0.5 * np.arccos(s0[2] / 0.5)) < g.spacing
    v, f = ts.triangulate(ts.solve(ts.surfaces.Sphere(R), g, [(R, 0, 0)]))
    mesh = ts.surfaces.from_mesh((v, f))
    sol = ts.solve(mesh, g, [v[0]])
    path = sol.geodesic_path(v[len(v) // 2])
    assert np.array_equal(path[-1], v[0])
    d, _ = mesh.project(path, g)
    assert np.max(d) < 1e-9  # projected onto the triangles


def test_bad_requests_are_refused_with_the_argument_named():
    g = ts.Grid((-1, -1), (1, 1), (101, 101))
    sol = ts.solve(ts.surfaces.Circle(0.6), g, [(0.6, 0.0)])
    with pytest.raises(ValueError, match="step"):
        sol.geodesic_path((0.0, 0.6), step=0.0)
    with pytest.raises(ValueError, match="step"):
        sol.geodesic_path((0.0, 0.6), step=True)
    with pytest.raises(ValueError, match="step"):
        sol.geodesic_path((0.0, 0.6), step=1e-6)
    with pytest.raises(ValueError, match="max_steps"):
        sol.geodesic_path((0.0, 0.6), max_steps=True)
    with pytest.raises(ValueError, match="start must be one point"):
        sol.geodesic_path([(0.0, 0.6), (0.0, -0.6)])
    with pytest.raises(ValueError, match="step"):
        sol.geodesic_path((0.0, 0.6), step=1.5)
    with pytest.raises(ValueError, match="max_steps"):
        sol.geodesic_path((0.0, 0.6), max_steps=0)
    with pytest.raises(ValueError, match=r"starts\[1\].*farther than the inner tube"):
        sol.geodesic_paths([(0.0, 0.6), (0.0, 0.0)])
    with pytest.raises(ValueError, match="starts must have shape"):
        sol.geodesic_paths([(0.0, 0.6, 0.0)])
    moving = ts.solve(ts.surfaces.Circle(0.6), g, [(-0.6, 0.0)], flow=solid_body_rotation(0.5))
    with pytest.raises(ValueError, match="isotropic"):
        moving.geodesic_path((0.0, 0.6))
    # a component no source reaches: two circles, the source on one
    two = ts.LevelSet(
        lambda p: np.minimum(np.linalg.norm(p - (0.4, 0), axis=1), np.linalg.norm(p + (0.4, 0), axis=1)) - 0.3
    )
    sol2 = ts.solve(two, g, [(0.7, 0.0)])
    with pytest.raises(ValueError, match="not reached by any source"):
        sol2.geodesic_path((-0.7, 0.0))


def test_a_path_cut_short_warns_and_returns_what_it_traced():
    g = ts.Grid((-1, -1), (1, 1), (101, 101))
    sol = ts.solve(ts.surfaces.Circle(0.6), g, [(0.6, 0.0)])
    with pytest.warns(RuntimeWarning, match="max_steps = 3"):
        path = sol.geodesic_path((0.0, 0.6), max_steps=3)
    assert path.shape == (4, 2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        full = sol.geodesic_path((0.0, 0.6))
        # the start, one point per step, the source: exactly enough steps still arrive
        steps = len(full) - 2
        assert np.array_equal(sol.geodesic_path((0.0, 0.6), max_steps=steps), full)
    assert np.allclose(full[:4], path)
    with pytest.warns(RuntimeWarning, match="did not reach"):
        short = sol.geodesic_path((0.0, 0.6), max_steps=steps - 1)
    assert np.array_equal(short, full[:-2])


def test_paths_to_many_sources_off_the_nodes_end_at_a_source():
    """Fifty random sources on the sphere (none on a grid node, about 10 h apart), and two 4 h
    apart: every path ends on a source without a warning, at most about a grid spacing longer
    than the great circle to it, at the nearest source or one within a grid spacing as near."""
    rng = np.random.default_rng(0)

    def on_sphere(m):
        p = rng.normal(size=(m, 3))
        return R * p / np.linalg.norm(p, axis=1)[:, None]

    two = np.array([[R * np.cos(0.05), R * np.sin(0.05), 0.0], [R * np.cos(0.05), -R * np.sin(0.05), 0.0]])
    for sources in (on_sphere(50), two):
        sol = _sphere(81, sources)
        h = sol.grid.spacing
        starts = on_sphere(300)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            paths = sol.geodesic_paths(starts)
        geo = R * np.arccos(np.clip(starts @ sources.T / R**2, -1, 1))
        end = np.array([np.argmin(np.linalg.norm(sources - p[-1], axis=1)) for p in paths])
        # (the sources projected onto the sphere: the same to rounding)
        assert all(np.allclose(p[-1], sources[k], atol=1e-12) for p, k in zip(paths, end))
        to_end = geo[np.arange(len(starts)), end]
        err = np.array([_length(p) for p in paths]) - to_end
        # a scratch run with 1000 starts: max 1.13 h, mean 0.02 h (fifty sources); max 0.44 h, mean 0.11 h (two)
        assert np.max(np.abs(err)) < 1.5 * h and abs(np.mean(err)) < 0.15 * h
        assert np.max(to_end - geo.min(axis=1)) < h


def test_a_path_starting_at_the_edge_of_the_grid_uses_one_sided_differences():
    g = ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41))
    for sources in ([(0.0, 0.0, 0.0)], [(0.0, 0.0, 0.0), (-0.8, 0.8, 0.0)]):
        with pytest.warns(RuntimeWarning, match="the grid box cuts the surface"):  # the patch is wider than the box
            sol = ts.solve(ts.surfaces.PlanePatch(1.5), g, sources)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            path = sol.geodesic_path((0.98, 0.98, 0.0))
        assert np.array_equal(path[-1], [0.0, 0.0, 0.0])
        assert abs(_length(path) - 0.98 * np.sqrt(2)) < 0.5 * g.spacing
    # a sphere cut by the grid, two sources: a start next to the cut, whose stencil leaves the
    # grid, takes steps (it stopped where it started: found in review). Its geodesic dips below
    # the cut, so the path ends at the grid's edge, with a warning.
    cut = ts.Grid((-1, -1, -0.2), (1, 1, 1), (41, 41, 25))
    sources = np.array([[0.3, 0, 0.4], [-0.4743, 0, -0.1581]])
    with pytest.warns(RuntimeWarning, match="the grid box cuts the surface"):
        sol = ts.solve(ts.surfaces.Sphere(R), cut, sources)
    with pytest.warns(RuntimeWarning, match="stopped before reaching a source"):
        path = sol.geodesic_path((0.0934, 0.4672, -0.1516))
    u = sol(path)
    assert len(path) >= 5 and np.all(np.diff(u) < 0)


def test_plot_draws_paths(tmp_path):
    pytest.importorskip("matplotlib")
    g = ts.Grid((-1, -1), (1, 1), (81, 81))
    sol = ts.solve(ts.surfaces.Circle(0.6), g, [(0.6, 0.0)])
    path = sol.geodesic_path((0.0, -0.6))
    fig = ts.plot(sol, paths=[path])
    drawn = [ln for ln in fig.axes[0].lines if np.array_equal(ln.get_xydata(), path)]
    assert len(drawn) == 1
    with pytest.raises(ValueError, match=r"paths\[0\]"):
        ts.plot(sol, paths=[np.zeros((3, 3))])
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    sol3 = _sphere(41, [(R, 0, 0)])
    paths3 = sol3.geodesic_paths([(0, 0, R), (-R, 0, 0.01)])
    fig3 = ts.plot(sol3, paths=paths3)
    fig3.savefig(tmp_path / "paths.png")
    for ax in fig3.axes[:2]:  # both views: every segment drawn, in red, those behind the sphere faint
        red = [
            c
            for c in ax.collections
            if isinstance(c, Line3DCollection) and np.allclose(c.get_color()[0][:3], (1, 0, 0))
        ]
        assert sum(len(c.get_segments()) for c in red) == sum(len(p) - 1 for p in paths3)
        assert sorted(c.get_alpha() for c in red) == [0.3, 1.0]


BUNNY = ts.data.bunny()


def test_path_lengths_on_the_bunny_match_exact_polyhedral_geodesics():
    geodesic = pytest.importorskip("pygeodesic.geodesic")
    bunny = ts.surfaces.from_mesh(BUNNY)
    v = bunny.vertices
    targets = np.random.default_rng(0).choice(len(v), 8, replace=False)
    # one propagation from vertex 0 to all eight (one per target took 8 times as long)
    exact, _ = geodesic.PyGeodesicAlgorithmExact(v, bunny.faces).geodesicDistances(np.array([0]), targets)
    g = bunny.grid(81)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the ears' narrow gaps at this grid are cut, not warned about
        sol = ts.solve(bunny, g, [v[0]])
        paths = sol.geodesic_paths(v[targets])
    lengths = np.array([_length(p) for p in paths])
    # measured: mean 0.10 h, max 0.25 h; u itself is off by up to 1.4 h (before the band was cut
    # across the gaps and above the concave edges: 0.11 h, 0.31 h and 2.7 h)
    assert np.max(np.abs(lengths - exact)) < 0.6 * g.spacing
    assert np.mean(np.abs(lengths - exact)) < 0.25 * g.spacing
    for p in paths:
        assert np.array_equal(p[-1], v[0])


def test_the_source_finder_agrees_with_brute_force():
    from tubesweep.geodesic_paths import _SourceFinder

    g = ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41))
    rng = np.random.default_rng(0)
    src = rng.uniform(-0.9, 0.9, size=(5000, 3))
    src[100:200] = src[100]  # a hundred sources at one point: the lowest index wins
    pts = rng.uniform(-0.9, 0.9, size=(3000, 3))
    pts[:50] = src[100] + 0.001
    d = np.linalg.norm(pts[:, None] - src[None], axis=2)
    for radius in (0.05, 0.1, 0.013):  # one, two grid spacings and less
        got = _SourceFinder(g, src, radius).within(pts)
        want = np.where(d.min(1) <= radius, d.argmin(1), -1)
        assert np.array_equal(got, want) and np.count_nonzero(got >= 0) > 50


def test_a_path_from_where_u_barely_decreased_reaches_its_source_without_repeating_points():
    # on Spot at grid(81) with three sources the path from vertex 2000 reached a point where u
    # fell only at the rounding level: rounding-level decreases reset the stall count, and it ran
    # on in place, 136 of its 299 points repeating the last one. Then it stopped next to a narrow
    # gap, where the front had crossed; with the band cut there (``_shortcuts``) it runs through
    sources = [285, 0, 1000]
    spot = ts.surfaces.from_mesh(ts.data.spot())
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sol = ts.solve(spot, spot.grid(81), spot.vertices[sources])
        path = sol.geodesic_path(spot.vertices[2000])
    steps = np.linalg.norm(np.diff(path, axis=0), axis=1)
    assert np.count_nonzero(steps < 1e-9) == 0 and len(path) < 150
    assert min(np.linalg.norm(path[-1] - spot.vertices[s]) for s in sources) == 0.0


def test_a_stall_away_from_any_narrow_gap_does_not_mention_one():
    # a sphere cut by the grid (as above): the path leaves the grid, with no narrow gap anywhere
    cut = ts.Grid((-1, -1, -0.2), (1, 1, 1), (41, 41, 25))
    sources = np.array([[0.3, 0, 0.4], [-0.4743, 0, -0.1581]])
    with pytest.warns(RuntimeWarning, match="the grid box cuts the surface"):
        sol = ts.solve(ts.surfaces.Sphere(0.5), cut, sources)
    assert sol.narrow_gaps()[0].shape == (0, 3)
    with pytest.warns(RuntimeWarning, match="stopped before reaching a source") as caught:
        sol.geodesic_path((0.0934, 0.4672, -0.1516))
    assert not any("gap narrower" in str(w.message) for w in caught)


def test_the_paths_and_labels_bench_runs_at_both_orders_at_a_small_size(capsys):
    # benches/paths_and_labels.py, the figures of docs/paths-and-labels.md, at N = 31
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benches"))
    import paths_and_labels

    assert paths_and_labels.main([31], "auto") == 0
    out = capsys.readouterr().out
    row = next(line for line in out.splitlines() if line.startswith("| 31 | 0.06667 |"))
    # second order: the longest path within a hundredth of a spacing of the great circle's length
    assert float(row.split("|")[4]) < 0.01
    labels = next(line for line in out.splitlines() if line.startswith("| 31 |") and " of " in line)
    assert labels.split("|")[3].strip().startswith("0 of ")  # none wrong away from a boundary
