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
    sol = ts.solve(torus, ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3), sources)
    fig = ts.plot(sol, color="nearest_source", views=((30, -60),))
    assert [t.get_text() for t in fig.legends[0].get_texts()] == [f"nearest to source {k}" for k in range(3)]
    faces = fig.axes[0].collections[0].get_facecolors()
    # three cells, three hues (shading changes brightness, not the hue's ratio of channels)
    hues = {tuple(np.round(c[:3] / max(c[:3].max(), 1e-9), 1)) for c in faces}
    assert len(hues) >= 3
    with pytest.raises(ValueError, match="color must be"):
        ts.plot(sol, color="labels")
