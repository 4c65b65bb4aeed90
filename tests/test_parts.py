"""Parts of the surface that no path joins (tubesweep._parts): a part without a source stays
unreached even where the front crosses a gap narrower than the tubes to it."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import tubesweep as ts
from tubesweep._parts import NO_PART, part_labels

GRID = ts.Grid((-1.2, -1, -1), (1.2, 1, 1), (49, 41, 41))  # h = 0.05
R, C = 0.3, 0.45  # two spheres 0.3 = 6 spacings apart


def two_spheres() -> np.ndarray:
    x = np.stack(GRID.meshgrid(), -1)
    return np.minimum(np.linalg.norm(x - [-C, 0, 0], axis=-1), np.linalg.norm(x - [C, 0, 0], axis=-1)) - R


def quiet(f, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the narrow gap between the spheres, said elsewhere
        return f(*args, **kwargs)


@pytest.mark.parametrize("order", [1, 2])
def test_a_sphere_without_a_source_six_spacings_away_stays_unreached(order):
    # re-distanced (as every step of ts.evolve is), the front crossed the gap: the far sphere read
    # 1.27 at its far pole with converged=True, shorter than any path across the gap (≥ 1.40)
    surface = ts.LevelSet(two_spheres(), redistance=True)
    with pytest.warns(RuntimeWarning, match="faces itself across gaps"):
        with pytest.warns(RuntimeWarning, match="equidistant from two parts"):
            sol = ts.solve(surface, GRID, [(-C, 0, R)], order=order)
    assert sol.stats.order == order and sol.stats.converged and sol.stats.facing_pairs > 0
    far = np.array([(C, 0, R), (C + R, 0, 0), (C, 0, -R)])
    assert np.all(np.isinf(sol(far)))
    # the source's sphere is solved as alone: the great-circle distances, to the scheme's accuracy
    near = np.array([(-C, 0, -R), (-C - R, 0, 0), (-C, R, 0)])
    exact = R * np.array([np.pi, np.pi / 2, np.pi / 2])
    assert np.max(np.abs(sol(near) - exact)) < (0.2 if order == 1 else 0.02)
    # the parts: one per sphere's inner tube (the extension layer belongs to none)
    labels = part_labels(sol_tube(surface))
    assert labels is not None and len(np.unique(labels[labels != NO_PART])) == 2


def sol_tube(surface):
    return quiet(ts.Tube, surface, GRID)._tube


@pytest.mark.parametrize("order", [1, 2])
def test_a_batch_drops_the_other_parts_as_the_single_solves_do(order):
    tube = quiet(ts.Tube, ts.LevelSet(two_spheres(), redistance=True), GRID)
    sources = [(-C, 0, R), (C, 0, -R)]
    # on both spheres, and across the gap between them (cells with corners on both parts)
    gap = np.stack([np.arange(-0.15, 0.151, 0.025), 0 * np.arange(13), 0 * np.arange(13)], 1)
    at = np.concatenate([[(C, 0, R), (C + R, 0, 0), (-C, 0, -R), (-C - R, 0, 0)], gap])
    rows = quiet(tube.solve_many, sources, at=at, order=order)
    full = quiet(tube.solve_many, sources, order=order)
    for k, source in enumerate(sources):
        single = quiet(tube.solve, [source], order=order)
        assert np.array_equal(rows[k], single(at)) and np.array_equal(full[k], single.values)
    assert np.all(np.isinf(rows[0, :2])) and np.all(np.isfinite(rows[0, 2:4]))
    assert np.all(np.isinf(rows[1, 2:4])) and np.all(np.isfinite(rows[1, :2]))
    assert np.isfinite(rows[0, 4]) and np.isinf(rows[0, -1])  # the gap's ends, on each side
    at = at[:4]
    d = quiet(ts.distance_matrix, tube, None, at, order=order)
    assert np.all(np.isinf(d[:2, 2:])) and np.all(np.isfinite(d[:2, :2])) and np.all(np.isfinite(d[2:, 2:]))


def test_an_evolving_droplet_does_not_reach_the_sphere_beneath_it():
    # a droplet carrying the source 6 spacings above a larger sphere: every frame of ts.evolve
    # gave the sphere finite distances, and its speed law V = g(u) moved it by them
    grid = ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41))
    x = np.stack(grid.meshgrid(), -1)
    top, bottom = np.array([0.0, 0.0, 0.75]), np.array([0.0, 0.0, -0.25])
    phi = np.minimum(np.linalg.norm(x - top, axis=-1) - 0.2, np.linalg.norm(x - bottom, axis=-1) - 0.5)
    ev = quiet(ts.evolve, phi, grid, [top + [0, 0.2, 0]], lambda u: 0.1 / (1 + u), dt=0.01, steps=1)
    sphere = np.array([bottom + [0, 0, -0.5], bottom + [0.5, 0, 0]])
    for sol in ev.solutions:
        assert np.all(np.isinf(sol(sphere)))


def test_the_faces_of_a_cube_next_to_a_sphere_stay_one_part():
    # second order moves the nodes at a cube's creases to the extension layer; its faces stay one
    # part (the paper's inner tube is labelled) and all six are reached, the sphere is not
    grid = ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41))  # h = 0.05
    x = np.stack(grid.meshgrid(), -1)
    q = np.abs(x - [-0.4, 0, 0]) - 0.3
    cube = np.linalg.norm(np.maximum(q, 0), axis=-1) + np.minimum(q.max(axis=-1), 0)
    sphere = np.linalg.norm(x - [0.45, 0, 0], axis=-1) - 0.3  # 0.25 = 5 spacings from the cube
    sol = quiet(ts.solve, np.minimum(cube, sphere), grid, [(-0.4, 0, 0.3)])
    assert sol.stats.facing_pairs > 0 and sol.stats.crease_thinned > 0
    faces = np.array([(-0.4, 0, -0.3), (-0.7, 0, 0), (-0.1, 0, 0), (-0.4, 0.3, 0), (-0.4, -0.3, 0)])
    assert np.all(np.isfinite(sol(faces)))
    assert np.all(np.isinf(sol(np.array([(0.75, 0, 0), (0.45, 0, 0.3)]))))


def test_a_thin_inner_tube_or_a_corner_across_a_narrow_gap_drops_nothing_reachable():
    # (a review) φ = 2·distance with inner=1: an inner tube half a spacing thick broke the source's
    # sphere into nine parts, eight set to inf; now a tube that thin is not labelled
    g = ts.Grid((-1,) * 3, (1,) * 3, (60,) * 3)
    h, r = g.spacing, 0.45
    top = np.array([0, 0, r + 3 * h + 0.2])

    def phi(x):
        return 2.0 * np.minimum(np.linalg.norm(x, axis=-1) - r, np.linalg.norm(x - top, axis=-1) - 0.2)

    sol = quiet(ts.solve, phi, g, [(r, 0, 0)], inner=1, outer=3)
    assert sol.stats.facing_pairs > 0
    d = np.random.default_rng(0).normal(size=(2000, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    assert np.all(np.isfinite(sol(r * d)))
    # two concentric spheres 3.2 spacings apart, inner=1: a point on the source's sphere had a
    # corner of weight 6e-6 in the other sphere's extension layer, set to inf; only inner-tube
    # nodes are dropped now, and the other sphere still reads inf
    g = ts.Grid((-1,) * 3, (1,) * 3, (61,) * 3)
    outer_r = 0.8
    inner_r = outer_r - 3.2 * g.spacing
    shell = ts.LevelSet(
        lambda x: np.maximum(inner_r - np.linalg.norm(x, axis=-1), np.linalg.norm(x, axis=-1) - outer_r),
        redistance=True,
    )
    point = np.array([-0.26594992, 0.49978387, -0.56523156])
    point *= outer_r / np.linalg.norm(point)
    sol = quiet(ts.solve, shell, g, [(outer_r, 0, 0)], inner=1, outer=3, order=1)
    assert sol.stats.facing_pairs > 0
    assert np.isfinite(sol([point])[0]) and np.isinf(sol([inner_r * point / outer_r])[0])


def test_points_on_the_reached_part_read_its_values_beside_an_unreached_one():
    # a shell three spacings thick, re-distanced, the source on its outer sphere: its inner sphere
    # is a part no source reaches, and 36 of 20,000 points on the outer sphere read +inf through a
    # corner of the inner sphere's tube weighing 0.001 (a helper's review)
    grid = ts.Grid((-1,) * 3, (1,) * 3, (61,) * 3)
    h = grid.spacing
    r = np.linalg.norm(np.stack(grid.meshgrid(), -1), axis=-1)
    shell = np.abs(r - (0.5 - 1.5 * h)) - 1.5 * h
    with pytest.warns(RuntimeWarning, match="faces itself across gaps"):
        sol = ts.solve(ts.LevelSet(shell, redistance=True), grid, [(-0.5, 0, 0)])
    x = np.random.default_rng(0).normal(size=(20000, 3))
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    exact = 0.5 * np.arccos(np.clip(-x[:, 0], -1, 1))
    for interpolation in ("linear", "cubic"):
        u = sol(0.5 * x, interpolation=interpolation)
        assert np.all(np.isfinite(u)) and np.max(np.abs(u - exact)) < 0.01 * np.pi * 0.5
    # the inner sphere's points still read +inf, and the band's nodes there are unreached
    assert np.all(np.isinf(sol((0.5 - 3 * h) * x[:500])))
    assert np.count_nonzero(np.isinf(sol.values)) > 1000
