"""Warm re-solves on a moving surface (tubesweep.moving, docs/moving-surfaces.md): the warm start
reaches the cold solve's values, refuses what it cannot carry with the cause named, and a sphere
that grows keeps its distances proportional to its radius."""

from __future__ import annotations

import numpy as np
import pytest

import tubesweep as ts
from tubesweep.moving import WarmStartRefused

N = 41
GRID = ts.Grid((-1, -1, -1), (1, 1, 1), (N, N, N))
H = GRID.spacing


def pole(r: float) -> list:
    return [(0.0, 0.0, r)]


@pytest.fixture(scope="module")
def first():
    tube = ts.Tube(ts.surfaces.Sphere(0.5), GRID)
    return tube, tube.solve(pole(0.5))


def test_a_warm_solve_on_a_grown_sphere_equals_the_cold_solve(first):
    tube, sol = first
    r = 0.5 + 0.4 * H
    moved = tube.moved(ts.surfaces.Sphere(r))
    warm = moved.solve(pole(r), warm=sol)
    cold = ts.solve(ts.surfaces.Sphere(r), GRID, pole(r))
    assert warm.stats.order == 2 and np.array_equal(warm.linear, cold.linear)
    info = warm.stats.order2["warm"]
    assert info["restarted"] is None and info["carried"] > 0.8 * warm.stats.band_points
    tol = cold.stats.order2["tol"]
    assert np.max(np.abs(warm.values - cold.values)) <= 10 * tol
    # ts.solve(..., warm=) runs the same solve as the tube's, bit for bit
    again = ts.solve(ts.surfaces.Sphere(r), GRID, pole(r), warm=sol)
    assert np.array_equal(again.values, warm.values)


def test_a_start_extrapolated_from_two_steps_reaches_the_cold_values(first):
    tube, s0 = first
    r1, r2 = 0.5 + 0.4 * H, 0.5 + 0.8 * H
    t1 = tube.moved(ts.surfaces.Sphere(r1))
    s1 = t1.solve(pole(r1), warm=s0)
    s2 = t1.moved(ts.surfaces.Sphere(r2)).solve(pole(r2), warm=(s0, s1))
    cold = ts.solve(ts.surfaces.Sphere(r2), GRID, pole(r2))
    assert s2.stats.order2["warm"]["extrapolated"] > 0.8 * s2.stats.band_points
    assert np.max(np.abs(s2.values - cold.values)) <= 10 * cold.stats.order2["tol"]


def test_distances_on_a_growing_sphere_scale_with_its_radius(first):
    # warm steps of 0.4Δx from r = 0.5 to 0.5 + 2Δx: u(r·d)/r is the same function of the
    # direction d at every radius, to the solver's accuracy (its error against rθ)
    tube, sol = first
    rng = np.random.default_rng(3)
    d = rng.normal(size=(200, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    theta = np.arccos(np.clip(d[:, 2], -1, 1))
    d, theta = d[(theta > 0.2) & (theta < np.pi - 0.3)], theta[(theta > 0.2) & (theta < np.pi - 0.3)]
    base = sol(0.5 * d) / 0.5
    worst_error = np.max(np.abs(base - theta))
    worst_scaling = 0.0
    r = 0.5
    for _ in range(5):
        r += 0.4 * H
        tube = tube.moved(ts.surfaces.Sphere(r))
        sol = tube.solve(pole(r), warm=sol)
        assert sol.stats.order2["warm"]["restarted"] is None
        scaled = sol(r * d) / r
        worst_error = max(worst_error, np.max(np.abs(scaled - theta)))
        worst_scaling = max(worst_scaling, np.max(np.abs(scaled - base)))
    # measured at N = 41: 5.3e-3 against θ, 2.4e-3 between the radii
    assert worst_error < 1e-2
    assert worst_scaling <= worst_error


def test_refusals_name_the_cause(first):
    tube, sol = first
    r = 0.5 + 0.4 * H
    moved = tube.moved(ts.surfaces.Sphere(r))
    other = ts.Grid((-1, -1, -1), (1, 1, 1), (43, 43, 43))
    with pytest.raises(WarmStartRefused, match="another grid"):
        ts.solve(ts.surfaces.Sphere(r), other, pole(r), warm=sol)
    with pytest.raises(WarmStartRefused, match="solved at first order"):
        moved.solve(pole(r), warm=tube.solve(pole(0.5), order=1))
    with pytest.raises(WarmStartRefused, match="order=1 was asked for"):
        moved.solve(pole(r), warm=sol, order=1)
    with pytest.raises(WarmStartRefused, match="source 0 moved"):
        moved.solve([(r, 0.0, 0.0)], warm=sol)
    with pytest.raises(WarmStartRefused, match="1 source"):
        moved.solve([(0.0, 0.0, r), (r, 0.0, 0.0)], warm=sol)
    far = 0.5 + 3.0 * H  # farther than outer − inner = 2 spacings
    with pytest.raises(WarmStartRefused, match="moved farther than outer − inner = 2 grid spacings"):
        tube.moved(ts.surfaces.Sphere(far)).solve(pole(far), warm=sol)
    with pytest.raises(TypeError, match="warm must be the Solution"):
        moved.solve(pole(r), warm=sol.values)
    with pytest.raises(ValueError, match="warm_refused must be"):
        moved.solve(pole(r), warm=sol, warm_refused="ignore")
    with pytest.raises(ValueError, match="the φ array has shape"):
        ts.Tube(np.linalg.norm(GRID.meshgrid(), axis=0) - 0.5, GRID).moved(np.zeros((5, 5, 5)))


def test_a_refused_warm_start_solves_cold_when_asked(first):
    tube, sol = first
    far = 0.5 + 3.0 * H
    s = tube.moved(ts.surfaces.Sphere(far)).solve(pole(far), warm=sol, warm_refused="cold")
    cold = ts.solve(ts.surfaces.Sphere(far), GRID, pole(far))
    assert np.array_equal(s.values, cold.values)
    assert "moved farther" in s.stats.order2["warm"]["refused"]
