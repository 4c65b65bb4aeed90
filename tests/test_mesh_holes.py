"""Holes of an open mesh (surfaces/_mesh_holes.py): found with their widths, not taken for gaps
between sheets (which sent the solve to first order), and reported where the band spans them."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import tubesweep as ts
from tubesweep.surfaces import _mesh_holes

trimesh = pytest.importorskip("trimesh")

CENTRES = np.array([(0.6, 0.0, 0.0), (0.0, 0.6, 0.0), (0.0, 0.0, -0.6)])


def holed_sphere(radius: float, centres: np.ndarray = CENTRES, subdivisions: int = 4):
    """An icosphere of radius 0.6 with holes of ``radius`` at ``centres`` (faces removed)."""
    m = trimesh.creation.icosphere(subdivisions=subdivisions, radius=0.6)
    v, f = np.asarray(m.vertices), np.asarray(m.faces)
    mid = v[f].mean(axis=1)
    drop = np.min(np.linalg.norm(mid[:, None] - centres[None], axis=2), axis=1) < radius
    kept = trimesh.Trimesh(v, f[~drop], process=False)
    kept.remove_unreferenced_vertices()
    return np.asarray(kept.vertices), np.asarray(kept.faces)


def test_holes_are_found_with_their_widths_and_centres():
    v, f = holed_sphere(0.05)
    found = _mesh_holes.holes(ts.surfaces.from_mesh((v, f)))
    assert found.width.size == 3
    # the faces whose centres lie within 0.05 of a hole's centre: hexagons 0.077 across their flats
    assert np.allclose(found.width, 0.0766, atol=2e-3), found.width
    # the detour round a hole against its width: 0.57 for a circle, 0.78 for these hexagons
    assert np.allclose(found.detour / found.width, 0.78, atol=0.03), found.detour / found.width
    gap = np.min(np.linalg.norm(found.centre[:, None] - CENTRES[None], axis=2), axis=1)
    assert np.all(gap < 0.01), found.centre
    # a closed mesh has none; a strip's outline is no hole (its centre lies on the strip)
    m = trimesh.creation.icosphere(subdivisions=3, radius=0.6)
    assert _mesh_holes.holes(ts.surfaces.from_mesh((m.vertices, m.faces))).width.size == 0
    x, y = np.meshgrid(np.linspace(0, 1, 21), np.linspace(0, 0.05, 3))
    strip_v = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    quads = [(j * 21 + i, j * 21 + i + 1, (j + 1) * 21 + i) for j in range(2) for i in range(20)]
    quads += [(j * 21 + i + 1, (j + 1) * 21 + i + 1, (j + 1) * 21 + i) for j in range(2) for i in range(20)]
    strip = ts.surfaces.from_mesh((strip_v, np.array(quads)))
    assert _mesh_holes.holes(strip).width.size == 0


def test_node_pairs_over_a_hole_are_not_a_gap_between_sheets():
    surf = ts.surfaces.from_mesh(holed_sphere(0.05))
    # two nodes over the hole at (0, 0.6, 0), either side of the sphere: both read the rim
    first = np.array([[0.0, 0.587, 0.0], [0.0, 0.0, 0.3]])
    second = np.array([[0.0, 0.613, 0.0], [0.0, 0.0, 0.33]])
    # the second pair lies inside the sphere below its north pole: not over a hole
    assert _mesh_holes.across_holes(surf, first, second).tolist() == [True, False]
    closed = trimesh.creation.icosphere(subdivisions=3, radius=0.6)
    assert not _mesh_holes.across_holes(ts.surfaces.from_mesh((closed.vertices, closed.faces)), first, second).any()


def test_a_sphere_with_small_holes_runs_second_order_against_exact_geodesics():
    geodesic = pytest.importorskip("pygeodesic.geodesic")
    v, f = holed_sphere(0.05)
    surf = ts.surfaces.from_mesh((v, f))
    grid = ts.Grid((-0.8,) * 3, (0.8,) * 3, (61,) * 3)
    source = int(np.argmax(v[:, 2]))
    sol = ts.solve(surf, grid, [tuple(v[source])])
    # a node pair over a hole sent this solve to first order ("faces itself across gaps"): mean
    # error 1.5e-2 away from the holes
    assert sol.stats.order == 2 and sol.stats.facing_pairs == 0, (sol.stats.order_fallback, sol.stats.facing_pairs)
    exact, _ = geodesic.PyGeodesicAlgorithmExact(v, f).geodesicDistances(np.array([source]), None)
    err = np.abs(sol(v) - exact)
    far = np.min(np.linalg.norm(v[:, None] - CENTRES[None], axis=2), axis=1) > 0.3
    assert err[far].mean() < 1e-3 and err[far].max() < 2e-2, (err[far].mean(), err[far].max())
    # the band (8 spacings, 0.213) spans the holes (0.077 wide): reported, not warned (the detour
    # round one, 0.060, is 2.9% of the mesh's size)
    holes = sol.stats.bridged_holes
    assert holes is not None and holes["count"] == 3, holes
    assert holes["reach"] == pytest.approx(8 * grid.spacing)
    assert holes["widest"] == pytest.approx(0.0766, abs=2e-3), holes
    assert holes["detour"] == pytest.approx(0.0597, abs=2e-3) and holes["detour"] < 0.1 * holes["size"], holes
    # the batch of several sources reports them as well
    _, batch = ts.Tube(surf, grid).solve_many(
        [tuple(v[source]), tuple(v[np.argmin(v[:, 0])])], at=v[:10], return_stats=True
    )
    assert batch["bridged_holes"] == holes
    _, info = ts.distance_matrix(surf, grid, v[[source, 0, 100]], info=True)
    assert info["bridged_holes"] == holes
    # a band narrower than the holes (2·outer·h below 0.0766) leaves them open
    assert _mesh_holes.bridged(surf, 0.0097, 4.0) is not None
    assert _mesh_holes.bridged(surf, 0.0095, 4.0) is None


def test_a_wide_hole_the_band_spans_is_warned_with_its_detour():
    v, f = holed_sphere(0.25, CENTRES[:1], subdivisions=3)
    surf = ts.surfaces.from_mesh((v, f))
    grid = ts.Grid((-0.8,) * 3, (0.8,) * 3, (21,) * 3)  # h = 0.08: the band spans 0.64
    with pytest.warns(RuntimeWarning, match=r"1 hole\(s\) narrower than its band") as record:
        sol = ts.solve(surf, grid, [(0.0, 0.0, 0.6)], order=1)
    message = str(next(w.message for w in record if "hole" in str(w.message)))
    holes = sol.stats.bridged_holes
    assert holes is not None and holes["count"] == 1 and holes["detour"] > 0.1 * holes["size"], holes
    assert f"up to about {holes['detour']:.3g}" in message and "fill_holes" in message
    # a grid whose band does not span it: nothing reported, nothing warned
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        fine = ts.solve(surf, ts.Grid((-0.8,) * 3, (0.8,) * 3, (41,) * 3), [(0.0, 0.0, 0.6)], order=1)
    assert fine.stats.bridged_holes is None


def test_a_notch_in_a_plates_outline_is_still_a_gap():
    # a plate with a notch 0.1 wide cut in from its edge: the pairs across the notch read the
    # plate's outline (not a hole: its centre lies on the plate) and stay facing pairs
    n = 81
    xs = np.linspace(-0.5, 0.5, n)
    x, y = np.meshgrid(xs, xs, indexing="ij")
    v = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    cx, cy = (x[:-1, :-1] + x[1:, 1:]) / 2, (y[:-1, :-1] + y[1:, 1:]) / 2
    i, j = np.nonzero(~((np.abs(cx) < 0.05) & (cy < 0.2)))
    a, b, c, d = i * n + j, (i + 1) * n + j, (i + 1) * n + j + 1, i * n + j + 1
    f = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    plate = ts.surfaces.from_mesh((v, f))
    assert _mesh_holes.holes(plate).width.size == 0
    grid = ts.Grid((-0.6, -0.6, -0.3), (0.6, 0.6, 0.3), (61, 61, 31))
    sol = ts.solve(plate, grid, [(-0.2, -0.3, 0.0)])
    assert sol.stats.order == 1 and sol.stats.facing_pairs > 50, (sol.stats.order, sol.stats.facing_pairs)
    assert "faces itself across gaps" in sol.stats.order_fallback


def test_a_split_seam_is_no_hole():
    # a UV sphere whose vertices are doubled along an arc of a meridian (a texture seam): open,
    # its seam a loop of zero width, which is no hole (the hull of a curved arc has a width)
    r, rows, cols = 0.6, 29, 60
    th, ph = np.meshgrid(
        np.linspace(0, np.pi, rows + 2)[1:-1], np.linspace(0, 2 * np.pi, cols, endpoint=False), indexing="ij"
    )
    v = np.column_stack(
        [
            r * np.sin(th.ravel()) * np.cos(ph.ravel()),
            r * np.sin(th.ravel()) * np.sin(ph.ravel()),
            r * np.cos(th.ravel()),
        ]
    )
    seam = np.arange(10, 20)  # rows whose longitude-0 vertex is doubled
    double = np.arange(rows) * cols
    double[seam] = len(v) + np.arange(seam.size)
    v = np.vstack([v, v[seam * cols], [(0, 0, r), (0, 0, -r)]])
    north, south = len(v) - 2, len(v) - 1

    def at(i, j):
        return double[i] if j == cols else i * cols + j

    f = [(at(i, j), at(i + 1, j), at(i, j + 1)) for i in range(rows - 1) for j in range(cols)]
    f += [(at(i, j + 1), at(i + 1, j), at(i + 1, j + 1)) for i in range(rows - 1) for j in range(cols)]
    f += [(north, at(0, j), at(0, j + 1)) for j in range(cols)] + [
        (south, at(rows - 1, j + 1), at(rows - 1, j)) for j in range(cols)
    ]
    sphere = ts.surfaces.from_mesh((v, np.array(f)))
    assert not sphere.closed and sphere.boundary_edges == 2 * (seam.size + 1)
    assert _mesh_holes.holes(sphere).width.size == 0
    assert _mesh_holes.bridged(sphere, 0.05, 4.0) is None
