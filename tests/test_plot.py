"""ts.plot: what a published picture needs is there (labelled colour bar and views, iso-values
written on the lines, sources and path starts marked), for surfaces, curves, travel-time fields,
surfaces without a mesh and nearest-source cells."""

import numpy as np
import pytest

import tubesweep as ts

pytest.importorskip("matplotlib")


def _texts(fig):
    return [t.get_text() for ax in fig.axes for t in ax.texts]


@pytest.fixture(scope="module")
def sphere_sol():
    s = ts.surfaces.Sphere(0.5)
    return ts.solve(s, ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3), [s.default_source])


def test_a_surface_has_labelled_views_colour_bar_and_iso_values(sphere_sol):
    fig = ts.plot(sphere_sol, levels=[0.3, 0.6, 0.9, 1.2], views=((20, -150), (20, 30)))
    views, bar = fig.axes[:2], fig.axes[2]
    assert [a.get_title() for a in views] == [
        "seen from azimuth -150°, elevation 20°",
        "seen from azimuth 30°, elevation 20°",
    ]
    assert bar.get_ylabel() == "geodesic distance"
    assert len(bar.lines) == 4  # the iso-values on the bar
    # every other level is written on its line, in each view where it is seen
    labels = set(_texts(fig))
    assert labels <= {"0.3", "0.9"} and labels
    # the source faces the first view, not the second (it is not drawn through the sphere)
    stars = [[len(c.get_offsets()) for c in a.collections if c.get_gid() == "sources"] for a in views]
    assert stars == [[1], []]


def test_the_start_of_each_path_is_marked(sphere_sol):
    starts = np.array([[0.0, -0.5, 0.0], [0.0, 0.0, -0.5]])
    paths = sphere_sol.geodesic_paths(starts)
    fig = ts.plot(sphere_sol, paths=paths, views=((0, -90), (0, 90)))
    # the view from -y sees the first start; the second, on -z, is seen edge-on from both
    # (a start on the far side is drawn faint, like its path)
    seen = [
        sum(len(c.get_offsets()) for c in a.collections if c.get_gid() == "path starts" and c.get_alpha() == 1.0)
        for a in fig.axes[:2]
    ]
    marked = [sum(len(c.get_offsets()) for c in a.collections if c.get_gid() == "path starts") for a in fig.axes[:2]]
    assert marked == [2, 2] and seen[0] >= 1 and seen[0] > seen[1]
    with pytest.raises(ValueError, match=r"paths\[0\] must be an array of shape"):
        ts.plot(sphere_sol, paths=[np.zeros((3, 2))])


def test_a_curve_has_ticks_and_values_where_it_crosses_each_level():
    star = ts.surfaces.Star()
    sol = ts.solve(star, ts.Grid((-1, -1), (1, 1), (201, 201)), [star.default_source])
    fig = ts.plot(sol, levels=[0.5, 1.0, 1.5, 2.0])
    assert len(fig.axes) == 2 and fig.axes[1].get_ylabel() == "geodesic distance"
    # each level crosses the closed curve twice (once either way from the source): a tick each
    ticks = [ln for ln in fig.axes[0].lines if len(ln.get_xdata()) == 2]
    assert len(ticks) == 8
    assert set(_texts(fig)) == {"0.5", "1.5"}


def test_a_travel_time_field_with_its_grid_gets_labelled_contours():
    grid = ts.Grid((-1, -1), (1, 1), (101, 101))
    u = ts.travel_time(grid, [(0.0, 0.0)])
    fig = ts.plot(u, grid=grid, sources=[(0.0, 0.0)], levels=[0.25, 0.5, 0.75])
    assert fig.axes[1].get_ylabel() == "travel time"
    assert {"0.25", "0.5", "0.75"} <= set(_texts(fig))
    with pytest.raises(ValueError, match="needs its grid"):
        ts.plot(u)  # an array without its grid
    with pytest.raises(ValueError, match="shape"):
        ts.plot(u[:50], grid=grid)
    g3 = ts.Grid((-1,) * 3, (1,) * 3, (21,) * 3)
    fig3 = ts.plot(ts.travel_time(g3, [(0.0, 0.0, 0.0)]), grid=g3)
    assert "slice z = 0" in fig3.axes[0].get_title()
    # a source off the middle slice: the slice through it (the star was drawn on z = 0, where u
    # was 0.3 at the star: a review)
    fig3 = ts.plot(ts.travel_time(g3, [(0.2, 0.1, -0.3)]), grid=g3, sources=[(0.2, 0.1, -0.3)])
    assert "slice z = -0.3" in fig3.axes[0].get_title()


def test_a_closest_point_surface_without_a_mesh_is_drawn_as_its_points():
    def cp(x):  # the sphere of radius 0.5, as a bare closest-point function
        r = np.linalg.norm(x, axis=1, keepdims=True)
        return 0.5 * x / np.where(r > 0, r, 1.0)

    grid = ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3)
    sol = ts.solve(ts.ClosestPoint(cp), grid, [(-0.5, 0.0, 0.0)])
    with pytest.raises(ValueError, match="mesh="):
        ts.triangulate(sol)
    fig = ts.plot(sol, views=((20, -60),))
    cloud = max((c for c in fig.axes[0].collections), key=lambda c: len(c.get_offsets()))
    near = np.count_nonzero(np.abs(sol.phi) <= 0.75 * grid.spacing)
    assert len(cloud.get_offsets()) == near > 1000


def test_nearest_source_cells_are_coloured_per_source_with_a_legend():
    torus = ts.surfaces.Torus(0.5, 0.2)
    sources = np.array([[0.7, 0.0, 0.0], [-0.7, 0.0, 0.0], [0.0, 0.7, 0.0]])
    sol = ts.solve(torus, ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3), sources)  # r = 4 spacings, order 2
    fig = ts.plot(sol, color="nearest_source", views=((30, -60),))
    assert [t.get_text() for t in fig.legends[0].get_texts()] == [f"nearest to source {k}" for k in range(3)]
    faces = fig.axes[0].collections[0].get_facecolors()
    # three cells, three hues (shading changes brightness, not the hue's ratio of channels)
    hues = {tuple(np.round(c[:3] / max(c[:3].max(), 1e-9), 1)) for c in faces}
    assert len(hues) >= 3
    with pytest.raises(ValueError, match="color must be"):
        ts.plot(sol, color="labels")


def _eye(elev, azim):
    e, a = np.radians(elev), np.radians(azim)
    return np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])


def test_the_default_views_look_at_the_source_and_at_the_far_side(sphere_sol):
    fig = ts.plot(sphere_sol)
    views = fig.axes[:2]
    # the first view faces the source, the second the far side, both from 20° above
    eyes = [_eye(a.elev, a.azim) for a in views]
    src = sphere_sol.sources[0] / np.linalg.norm(sphere_sol.sources[0])
    assert eyes[0] @ src == pytest.approx(np.cos(np.radians(20.0)))
    assert eyes[1] @ -src == pytest.approx(np.cos(np.radians(20.0)))
    stars = [[len(c.get_offsets()) for c in a.collections if c.get_gid() == "sources"] for a in views]
    assert stars == [[1], []]
    # iso-line labels stay clear of the source's star: the line 0.05 around it goes unlabelled
    fig = ts.plot(sphere_sol, levels=[0.05, 0.3, 0.6])
    labels = [(t.get_text(), np.array(t.get_position_3d())) for a in fig.axes[:2] for t in a.texts]
    assert {text for text, _ in labels} == {"0.6"}
    size = 1.0  # the sphere's diameter
    assert all(np.linalg.norm(p - sphere_sol.sources[0]) > 0.15 * size for _, p in labels)


def test_a_spheroid_with_the_source_at_the_pole_is_seen_whole():
    # both former fixed views looked at it from 20° above the equator: the far half never shown
    from tubesweep._plot_surface import _default_views
    from tubesweep._triangulate import triangulate

    s = ts.surfaces.Ellipsoid(0.25, 0.25, 0.5)
    with pytest.warns(
        RuntimeWarning, match="whose errors are a few grid spacings"
    ):  # first order at its tips' curvature
        sol = ts.solve(s, ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3), [(0, 0, 0.5)])
    v, f = triangulate(sol)
    views = _default_views(sol, v, [0, 1, 2])
    eyes = [_eye(*view) for view in views]
    tri = v[f]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n *= np.sign(np.einsum("ij,ij->i", n, tri.mean(1)))[:, None]  # outward
    seen = [(n @ e) > 0 for e in eyes]
    assert np.mean(seen[0] | seen[1]) > 0.99  # every face but the silhouette's
    far = sol.on_mesh(tri.mean(1)) > 0.9 * np.nanmax(sol.values)  # around the far pole
    assert np.all(seen[1][far]) and not np.any(seen[0][far])
    assert seen[0][np.argmax(tri.mean(1)[:, 2])]  # the source's pole in the first view


def test_an_elongated_surface_is_framed_whole():
    # two spheres side by side (φ = the smaller of their distances), a source at the right end: the
    # former fixed zoom cut off the right sphere and the source
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from mpl_toolkits.mplot3d import proj3d

    c1, c2, r = np.array([-0.45, 0, 0]), np.array([0.45, 0, 0]), 0.35
    phi = lambda p: np.minimum(np.linalg.norm(p - c1, axis=1) - r, np.linalg.norm(p - c2, axis=1) - r)  # noqa: E731
    grid = ts.Grid((-1, -0.5, -0.5), (1, 0.5, 0.5), (81, 41, 41))
    sol = ts.solve(phi, grid, [(0.8, 0, 0), (-0.45, 0, 0.35)], order=1)
    fig = ts.plot(sol)
    FigureCanvasAgg(fig).draw()
    ends = np.array([[-0.8, 0, 0], [0.8, 0, 0], [-0.45, 0, 0.35], [0.45, 0, -0.35]])  # the extremes
    for a in fig.axes[:2]:
        x, y, _ = proj3d.proj_transform(*ends.T, a.get_proj())
        px = a.transData.transform(np.c_[x, y])
        box = a.get_window_extent()
        assert np.all((px[:, 0] > box.x0) & (px[:, 0] < box.x1) & (px[:, 1] > box.y0) & (px[:, 1] < box.y1))
        assert np.ptp(px[:, 0]) > 0.6 * box.width  # and not drawn small
    stars = [sum(len(c.get_offsets()) for c in a.collections if c.get_gid() == "sources") for a in fig.axes[:2]]
    assert stars[0] == 2  # the first view sees both sources


def test_a_box_solution_is_drawn_as_its_field():
    grid = ts.Grid((-1, -1), (1, 1), (61, 61))
    sol = ts.travel_time(grid, [(0.2, -0.1)], order=2, return_solution=True)
    fig = ts.plot(sol, levels=[0.25, 0.5])
    assert fig.axes[1].get_ylabel() == "travel time" and {"0.25", "0.5"} <= set(_texts(fig))
    stars = [c for c in fig.axes[0].collections if c.get_gid() == "sources"]
    assert len(stars) == 1 and np.allclose(stars[0].get_offsets(), [[0.2, -0.1]])
    g3 = ts.Grid((-1,) * 3, (1,) * 3, (21,) * 3)
    fig3 = ts.plot(ts.travel_time(g3, [(0.0, 0.0, 0.0)], order=2, return_solution=True))
    assert "slice z = 0" in fig3.axes[0].get_title()
    with pytest.raises(ValueError, match="carries its own grid"):
        ts.plot(sol, grid=ts.Grid((-1, -1), (1, 1), (31, 31)))


def test_views_that_are_not_pairs_are_named():
    # "not enough values to unpack" (a helper's review)
    s = ts.surfaces.Sphere(0.5)
    sol = ts.solve(s, ts.Grid((-1,) * 3, (1,) * 3, (21,) * 3), [s.default_source])
    with pytest.raises(ValueError, match=r"views must be a sequence of \(elevation, azimuth\) pairs"):
        ts.plot(sol, views=[(1,)])


def test_a_flat_surface_is_seen_from_its_face():
    # a disc was drawn from 20° above, a thin ellipse with its labels stacked; one triangle edge-on
    g = ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3)
    sol = ts.solve(ts.surfaces.Disc(0.6), g, [(0.3, 0.0, 0.0)])
    fig = ts.plot(sol)
    assert [round(a.elev) for a in fig.axes[:2]] == [65, 65]


def test_parts_no_source_reaches_are_said_grey_under_the_title():
    g = ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3)

    def two(p):
        return np.minimum(np.linalg.norm(p - [0.5, 0, 0], axis=1), np.linalg.norm(p + [0.5, 0, 0], axis=1)) - 0.3

    fig = ts.plot(ts.solve(two, g, [(-0.8, 0.0, 0.0)]))
    assert fig._suptitle.get_text() == "(grey: not reached, u = inf)"
    fig = ts.plot(ts.solve(ts.surfaces.Sphere(0.5), g, [(0.5, 0.0, 0.0)]))
    assert fig._suptitle is None or "grey" not in fig._suptitle.get_text()
