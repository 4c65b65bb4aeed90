"""Nearest-source labels (Solution.nearest_source; tubesweep_core::solution::nearest_source)."""

from __future__ import annotations

import numpy as np
import pytest

import tubesweep as ts
from tubesweep.output import read_vtp

R = 0.5


def _exact_sphere_labels(points, sources):
    """The nearest source along great circles, and the margin to the second nearest."""
    cp = R * points / np.linalg.norm(points, axis=1)[:, None]
    geo = R * np.arccos(np.clip(cp @ sources.T / R**2, -1, 1))
    order = np.sort(geo, axis=1)
    return np.argmin(geo, axis=1), order[:, 1] - order[:, 0]


@pytest.mark.parametrize("hamiltonian", ["godunov", "lxf"])
def test_labels_on_a_sphere_are_the_geodesic_voronoi_cells(hamiltonian):
    g = ts.Grid((-1, -1, -1), (1, 1, 1), (61, 61, 61))
    sources = np.array([[R, 0, 0], [-R, 0, 0], [0, 0, R], [0, -R * 0.6, -R * 0.8]])
    sol = ts.solve(ts.surfaces.Sphere(R), g, sources, hamiltonian=hamiltonian)
    labels = sol.nearest_source()
    assert labels.shape == sol.values.shape and labels.dtype == np.int64
    assert np.all(labels >= 0)  # one component, every node reached
    exact, margin = _exact_sphere_labels(sol.points, sources)
    away = margin > 2 * g.spacing
    assert away.mean() > 0.8
    assert np.array_equal(labels[away], exact[away])
    # near the cells' boundaries, about one spacing either side, either label
    assert np.mean(labels[~away] == exact[~away]) > 0.7
    # every source's own nodes carry its label
    for k, s in enumerate(sources):
        near = np.linalg.norm(sol.points - s, axis=1) < 1.5 * g.spacing
        assert np.all(labels[near] == k)
    # the labels are computed once and handed out as copies
    labels[:] = -5
    assert np.all(sol.nearest_source() >= 0)


def test_labels_at_points_and_on_a_component_no_source_reaches():
    g = ts.Grid((-1, -1), (1, 1), (161, 161))
    two = ts.LevelSet(
        lambda p: np.minimum(np.linalg.norm(p - (0.45, 0), axis=1), np.linalg.norm(p + (0.45, 0), axis=1)) - 0.3
    )
    sol = ts.solve(two, g, [(0.75, 0.0), (0.15, 0.0)])
    t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    right = np.column_stack([0.45 + 0.3 * np.cos(t), 0.3 * np.sin(t)])
    left = right - (0.9, 0.0)
    lab = sol.nearest_source(right)
    # the cells meet where the angle from the centre is ±π/2
    clear = np.abs(np.abs(np.cos(t))) > 0.1
    assert np.array_equal(lab[clear], np.where(np.cos(t[clear]) > 0, 0, 1))
    assert np.all(sol.nearest_source(left) == -1)
    band = sol.nearest_source()
    assert np.all(band[~np.isfinite(sol.values)] == -1) and np.all(band[np.isfinite(sol.values)] >= 0)
    # far from the band: no label
    assert sol.nearest_source([(0.0, 0.95)])[0] == -1
    with pytest.raises(ValueError, match="points must have shape"):
        sol.nearest_source([(0.0, 0.0, 0.0)])


def test_labels_follow_the_sources_order_on_a_tube_and_reach_the_export(tmp_path):
    g = ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41))
    tube = ts.Tube(ts.surfaces.Sphere(R), g)
    a = tube.solve([(R, 0, 0), (-R, 0, 0)])
    b = tube.solve([(-R, 0, 0), (R, 0, 0)])
    la, lb = a.nearest_source(), b.nearest_source()
    x = a.points[:, 0]
    clear = np.abs(x) > 2 * g.spacing
    assert np.array_equal(la[clear], np.where(x[clear] > 0, 0, 1))
    assert np.array_equal(lb[clear], 1 - la[clear])
    path = ts.export(a, tmp_path / "two.vtp")
    pts, _, data = read_vtp(path)
    labels = data["nearest_source"]
    assert set(np.unique(labels)) == {0.0, 1.0}
    clear = np.abs(pts[:, 0]) > 2 * g.spacing
    assert np.array_equal(labels[clear], np.where(pts[clear, 0] > 0, 0.0, 1.0))
    one = ts.export(tube.solve([(R, 0, 0)]), tmp_path / "one.vtp")
    assert "nearest_source" not in read_vtp(one)[2]


def test_labels_with_node_sources_duplicates_and_anisotropic_hamiltonians(tmp_path):
    from tubesweep.flows import solid_body_rotation

    g = ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41))
    sources = np.array([[R, 0, 0], [-R, 0, 0], [R, 0, 0]])  # the third repeats the first
    for init in ("exact", "node"):
        sol = ts.solve(ts.surfaces.Sphere(R), g, sources, source_init=init)
        labels = sol.nearest_source()
        x = sol.points[:, 0]
        clear = np.abs(x) > 2 * g.spacing
        # a node as near to two sources takes the first of them
        assert np.array_equal(labels[clear], np.where(x[clear] > 0, 0, 1)), init
    c = ts.surfaces.Circle(0.6)
    g2 = ts.Grid((-1, -1), (1, 1), (81, 81))
    moving = ts.solve(c, g2, [(0.6, 0.0), (-0.6, 0.0)], flow=solid_body_rotation(0.5))
    with pytest.raises(ValueError, match="isotropic"):
        moving.nearest_source()
    # one source: its label wherever a front arrives, for any Hamiltonian
    single = ts.solve(c, g2, [(0.6, 0.0)], flow=solid_body_rotation(0.5))
    assert np.array_equal(single.nearest_source(), np.where(np.isfinite(single.values), 0, -1))
    # the export leaves the labels out rather than failing
    _, _, data = read_vtp(ts.export(moving, tmp_path / "moving.vtp"))
    assert "nearest_source" not in data and "u" in data


def test_a_point_on_a_component_no_source_reaches_gets_no_value_and_no_label():
    # two spheres 8 spacings apart, sources on one: the nearest *reached* node of a point on the
    # other lay on the first's band, and the point read u = 0.0 and label 0
    g = ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41))

    def phi(p):
        return np.minimum(np.linalg.norm(p - [0.5, 0, 0], axis=1) - 0.3, np.linalg.norm(p + [0.5, 0, 0], axis=1) - 0.3)

    sol = ts.solve(phi, g, [(0.2, 0, 0), (0.8, 0, 0)])
    far = [(-0.2, 0, 0)]
    assert np.isinf(sol(far)[0]) and np.isposinf(sol.on_mesh(far)[0]) and sol.nearest_source(far)[0] == -1
    near = [(0.5, 0.3, 0)]
    assert abs(sol.on_mesh(near)[0] - 0.3 * np.pi / 2) < 0.1 * 0.3 * np.pi / 2 and sol.nearest_source(near)[0] in (0, 1)
