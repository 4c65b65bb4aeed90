"""Moving surfaces: what the caller is told (review of stop 68): evolve's φ checked as ts.Tube
checks it, tube.moved given a mesh's or a cloud's arrays, a warm start from a narrower band, and
the previous solve's tolerance a hair looser through the speed."""

from __future__ import annotations

import numpy as np
import pytest

import tubesweep as ts
from tubesweep.moving import WarmStartRefused

GRID = ts.Grid((-1, -1, -1), (1, 1, 1), (31, 31, 31))


def sphere_phi(r: float = 0.5) -> np.ndarray:
    return np.linalg.norm(np.stack(GRID.meshgrid(), -1), axis=-1) - r


def test_evolve_refuses_a_complex_phi_and_names_nan_as_its_own_requirement():
    law = lambda u: np.full_like(u, 0.1)  # noqa: E731
    # a complex φ was cast to real with only numpy's ComplexWarning (ts.Tube refuses it)
    with pytest.raises(TypeError, match="evolve: phi must hold real numbers"):
        ts.evolve(sphere_phi() + 1j, GRID, [(0, 0, 0.5)], law, dt=0.05, steps=1)
    # NaN far from the surface: the refusal blamed redistance=True, an option never passed
    phi = sphere_phi()
    phi = np.where(np.abs(phi) > 0.4, np.nan, phi)
    with pytest.raises(ValueError, match=r"evolve: phi is NaN or inf at \d+ of 29791 nodes .* re-distances φ at every"):
        ts.evolve(phi, GRID, [(0, 0, 0.5)], law, dt=0.05, steps=1)


def test_moved_given_a_mesh_s_or_a_cloud_s_arrays_names_the_surface_to_build():
    v, f = ts.surfaces.Sphere(0.5).triangulation(20)
    tube = ts.Tube(ts.surfaces.from_mesh((v, f)), GRID)
    with pytest.raises(TypeError, match=r"from_mesh\(\(vertices, triangles\)\)"):
        tube.moved((1.01 * v, f))
    with pytest.raises(TypeError, match=r"shape \(\d+, 3\), which looks like points.*from_points\(points\)"):
        tube.moved(1.01 * v)


def test_a_warm_start_from_a_band_narrower_than_the_new_inner_tube_says_so():
    phi = sphere_phi()
    prev = ts.Tube(phi, GRID).solve([(0, 0, 0.5)])
    # the same surface: the refusal blamed a move, by "outer − inner = -1 grid spacings"
    with pytest.raises(
        WarmStartRefused, match=r"inner tube \(inner = 5 grid spacings\) is as wide as .* \(outer = 4\)"
    ):
        ts.Tube(phi, GRID, inner=5, outer=8).solve([(0, 0, 0.5)], warm=prev)


def test_a_speed_changed_by_a_hair_keeps_the_local_start():
    # the default tolerance scales with the mean slowness: speed 1.000001 made the previous one
    # "looser" (printed as the same number) and every node started
    tube = ts.Tube(ts.surfaces.Sphere(0.5), GRID)
    prev = tube.solve([(0, 0, 0.5)])
    warm = tube.solve([(0, 0, 0.5)], speed=1.000001, warm=prev)
    assert warm.stats.order2["warm"]["all_started"] is None
    cold = tube.solve([(0, 0, 0.5)], speed=1.000001)
    assert np.max(np.abs(warm.values - cold.values)) < 10 * cold.stats.order2["tol"]
    slower = tube.solve([(0, 0, 0.5)], speed=1.5, warm=prev)
    assert "looser than this one's" in slower.stats.order2["warm"]["all_started"]
    assert "by more than 10%" in slower.stats.order2["warm"]["all_started"]


def test_evolve_takes_a_boolean_mask_and_a_level_set_of_an_array_and_says_what_to_pass_otherwise():
    # a review: ts.evolve(mask) told the user to pass ts.LevelSet.from_mask(mask, grid), which was
    # then refused with advice to call a signed_distance the LevelSet does not have
    law = lambda u: np.full_like(u, 0.1)  # noqa: E731
    mask = sphere_phi() < 0
    # (a mask of 7.5 voxels' radius: the paper's first-order scheme, warned)
    with pytest.warns(RuntimeWarning, match="ran the paper's first-order scheme"):
        by_mask = ts.evolve(mask, GRID, [(0, 0, 0.5)], law, dt=0.05, steps=1)
    with pytest.warns(RuntimeWarning, match="ran the paper's first-order scheme"):
        by_phi = ts.evolve(0.5 - mask.astype(float), GRID, [(0, 0, 0.5)], law, dt=0.05, steps=1)
    assert np.array_equal(by_mask.phis[-1], by_phi.phis[-1])
    assert np.array_equal(by_mask.solutions[-1].values, by_phi.solutions[-1].values)
    by_level_set = ts.evolve(ts.LevelSet(sphere_phi()), GRID, [(0, 0, 0.5)], law, dt=0.05, steps=1)
    by_array = ts.evolve(sphere_phi(), GRID, [(0, 0, 0.5)], law, dt=0.05, steps=1)
    assert np.array_equal(by_level_set.phis[-1], by_array.phis[-1])
    # the mask's surface lies half a spacing inside the sphere at most; after one step of 0.1·0.05
    # outwards the antipode's distance is about π·0.505
    u = by_mask.solutions[-1]([(0, 0, -0.5)])[0]
    assert abs(u - np.pi * 0.505) < 2 * GRID.spacing
    from_mask = ts.LevelSet.from_mask(mask, GRID, smooth=1)
    assert ts.evolve(from_mask, GRID, [(0, 0, 0.5)], law, dt=0.05, steps=1).times == [0.0, 0.05]
    with pytest.raises(ValueError, match=r"holds only the values 0 and 1, a mask.*mask > 0"):
        ts.evolve(mask.astype(float), GRID, [(0, 0, 0.5)], law, dt=0.05, steps=1)
    with pytest.raises(ValueError, match=r"evolve: phi holds only the values 0 and 255, a mask"):
        ts.evolve(mask.astype(np.uint8) * 255, GRID, [(0, 0, 0.5)], law, dt=0.05, steps=1)
    with pytest.raises(TypeError, match=r"got Sphere\. Pass its values: surface\.signed_distance\("):
        ts.evolve(ts.surfaces.Sphere(0.5), GRID, [(0, 0, 0.5)], law, dt=0.05, steps=1)
    with pytest.raises(TypeError, match=r"got function\. Pass its values: phi_function\("):
        ts.evolve(lambda p: np.linalg.norm(p, axis=1) - 0.5, GRID, [(0, 0, 0.5)], law, dt=0.05, steps=1)


def test_a_checkpoint_is_continued_only_on_its_own_grid_dt_and_every(tmp_path):
    # φ is an array of the grid's nodes: continued on [-1.1, 1.1]³ of the same shape, a review's
    # run put the surface at radius 0.573 instead of 0.51, without a word
    law = lambda u: np.full_like(u, 0.1)  # noqa: E731
    path = tmp_path / "run.npz"
    ts.evolve(sphere_phi(), GRID, [(0, 0, 0.5)], law, dt=0.05, steps=2, every=2, checkpoint=path)
    other = ts.Grid((-1.1, -1.1, -1.1), (1.1, 1.1, 1.1), (31, 31, 31))
    with pytest.raises(ValueError, match=r"written on the grid from \(-1.0, -1.0, -1.0\) to \(1.0, 1.0, 1.0\) with "):
        ts.read_checkpoint(path, other)
    with pytest.raises(ValueError, match=r"written with dt = 0.05, not dt = 0.1"):
        ts.read_checkpoint(path, GRID, dt=0.1)
    with pytest.raises(ValueError, match=r"written with every = 2, not every = 1"):
        ts.read_checkpoint(path, GRID, every=1)
    c = ts.read_checkpoint(path, GRID, dt=0.05, every=2)
    assert c.step == 2 and c.t == pytest.approx(0.1) and c.phi.shape == GRID.shape
    # a checkpoint of an earlier version (no grid): read, with a warning that it cannot be checked
    old = tmp_path / "old.npz"
    np.savez(old, phi=c.phi, t=c.t, step=c.step, sources=c.sources)
    with pytest.warns(RuntimeWarning, match="holds no grid, dt or every"):
        assert np.array_equal(ts.read_checkpoint(old, other).phi, c.phi)
    np.savez(tmp_path / "x.npz", a=1)
    with pytest.raises(ValueError, match="not a checkpoint of ts.evolve"):
        ts.read_checkpoint(tmp_path / "x.npz", GRID)


def test_a_source_carried_exactly_as_far_as_the_surface_may_move_is_taken():
    # a sphere off the nodes grown by exactly outer − inner = 2 spacings, its pole carried with it:
    # the pole's projection onto the discrete surface lay 0.004 spacings beyond the limit, and the
    # refusal said the source had left the surface's path
    h = GRID.spacing
    c = np.array([0.0123, 0.0271, -0.0089])
    r0 = np.linalg.norm(np.stack(GRID.meshgrid(), -1) - c, axis=-1)
    tube = ts.Tube(r0 - 0.5, GRID)
    sol = tube.solve([tuple(c + [0, 0, 0.5])])
    r = 0.5 + 2.0 * h
    warm = tube.moved(r0 - r).solve([tuple(c + [0, 0, r])], warm=sol)
    assert "refused" not in warm.stats.order2["warm"] and warm.stats.order == 2
    cold = ts.solve(r0 - r, GRID, [tuple(c + [0, 0, r])])
    assert np.max(np.abs(warm.values - cold.values)) <= 10 * cold.stats.order2["tol"]


def test_a_progress_that_cannot_take_step_steps_t_is_refused_before_the_first_solve():
    law = lambda u: np.full_like(u, 0.1)  # noqa: E731
    with pytest.raises(
        TypeError, match=r"progress is called as progress\(step, steps, t\), which its signature \(step\)"
    ):
        ts.evolve(sphere_phi(), GRID, [(0, 0, 0.5)], law, dt=0.05, steps=1, progress=lambda step: None)
    seen = []
    ts.evolve(sphere_phi(), GRID, [(0, 0, 0.5)], law, dt=0.05, steps=1, progress=lambda *a: seen.append(a))
    assert seen == [(1, 1, pytest.approx(0.05))]
