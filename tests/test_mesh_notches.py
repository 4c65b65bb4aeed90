"""Notches of an open mesh's rim (surfaces/_mesh_notches.py): node pairs at a notch of a rim that
zigzags at the grid's scale are no gap between sheets, which sent the whole solve to first order."""

from __future__ import annotations

import numpy as np
import pytest

import tubesweep as ts
from tubesweep.surfaces import _mesh_notches

geodesic = pytest.importorskip("pygeodesic.geodesic")


def test_a_rim_that_zigzags_at_the_grid_s_scale_keeps_second_order(monkeypatch, experiment):
    v, f, source, rim = experiment("rim_notches").jagged_disc()
    exact, _ = geodesic.PyGeodesicAlgorithmExact(v, f).geodesicDistances(np.array([source]), None)
    grid = ts.Grid((-0.7,) * 3, (0.7,) * 3, (61,) * 3)
    sol = ts.solve(ts.surfaces.from_mesh((v, f)), grid, [v[source]])
    assert sol.stats.order == 2 and sol.stats.facing_pairs == 0
    err = np.abs(sol.on_mesh(v) - exact)
    assert err[~rim].mean() < 1e-3 and err[rim].mean() < 5e-3, (err[~rim].mean(), err[rim].mean())
    # without the notch test one pair at a notch was taken for a gap and the solve ran first order
    # (said in sol.stats.order_fallback), ten times further off
    monkeypatch.setattr(_mesh_notches, "NOTCH_REACH", 0.0)
    monkeypatch.setattr(_mesh_notches, "NOTCH_RATIO", 0.0)
    before = ts.solve(ts.surfaces.from_mesh((v, f)), grid, [v[source]])
    assert before.stats.order == 1 and before.stats.facing_pairs == 1
    assert "faces itself across gaps" in before.stats.order_fallback
    assert np.abs(before.on_mesh(v) - exact)[~rim].mean() > 5e-3


def test_pairs_are_notches_only_where_the_mesh_joins_their_closest_points_nearby():
    # a plate z = 0 with a slot 0.1 wide cut 0.6 deep into it from y = −0.5: nodes either side of
    # the slot are joined along the plate round the slot's end, about 0.9 long at y = −0.3 (a gap:
    # more than twice the 0.1 across) and 0.14 at y = 0.08 (next to the end: a notch)
    n = 41
    xs = np.linspace(-0.5, 0.5, n)
    x, y = np.meshgrid(xs, xs, indexing="ij")
    v = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    cx, cy = (x[:-1, :-1] + x[1:, 1:]) / 2, (y[:-1, :-1] + y[1:, 1:]) / 2
    i, j = np.nonzero(~((np.abs(cx) < 0.05) & (cy < 0.1)))
    a, b, c, d = i * n + j, (i + 1) * n + j, (i + 1) * n + j + 1, i * n + j + 1
    plate = ts.surfaces.from_mesh((v, np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])))
    grid = ts.Grid((-0.6, -0.6, -0.2), (0.6, 0.6, 0.2), (61, 61, 21))
    ends = np.array([[-0.04, -0.3, 0.0], [0.04, -0.3, 0.0], [-0.04, 0.08, 0.0], [0.04, 0.08, 0.0]])
    near = np.round((ends - np.asarray(grid.lower)) / grid.spacing).astype(np.int64)
    linear = np.ravel_multi_index(near.T, grid.shape)
    notch = _mesh_notches.pairs_at_notches(plate, grid, linear[[0, 2]], linear[[1, 3]])
    assert notch.tolist() == [False, True]
    # a closed mesh has none
    sphere = ts.surfaces.from_mesh(ts.surfaces.Sphere(0.5).triangulation())
    assert not _mesh_notches.pairs_at_notches(sphere, grid, linear[:1], linear[1:2]).any()
