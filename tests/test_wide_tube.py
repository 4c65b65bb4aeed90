"""An inner tube wider than the paper's at first order (``tubesweep._wide_tube``): the estimate in
``sol.stats.tube_shortcut`` against the measured errors, and its warning."""

import numpy as np
import pytest

import tubesweep as ts

G = ts.Grid((-1,) * 3, (1,) * 3, (61,) * 3)
SPHERE = ts.surfaces.Sphere(0.5)
SRC = (-0.5, 0.0, 0.0)
WARNING = "cuts through it on the inside of the bend"


def _sphere_points(count: int = 2000) -> np.ndarray:
    p = np.random.default_rng(0).normal(size=(count, 3))
    return 0.5 * p / np.linalg.norm(p, axis=1, keepdims=True)


def _largest_share(sol: ts.Solution) -> float:
    """The largest error at points of the sphere against the great-circle distances, as a share
    of the largest distance."""
    p = _sphere_points()
    exact = 0.5 * np.arccos(np.clip(2 * p @ np.array([-1.0, 0.0, 0.0]), -1, 1))
    return float(np.max(np.abs(sol(p) - exact)) / np.max(exact))


@pytest.mark.parametrize("inner", [4.0, 8.0])
def test_a_wide_inner_tube_at_first_order_is_estimated_and_warned(inner):
    with pytest.warns(RuntimeWarning, match=rf"inner={inner:g}: .*{WARNING}.* about \d+% short"):
        sol = ts.solve(SPHERE, G, [SRC], order=1, inner=inner, outer=inner + 2)
    measured = _largest_share(sol)
    # the sphere at N = 61: 16% (inner 4) and 37% (inner 8) short at worst, estimated 18% and 36%
    assert measured > 0.15
    assert 0.85 * measured < sol.stats.tube_shortcut < 1.25 * measured


def test_the_papers_tube_flat_surfaces_and_second_order_have_no_estimate():
    sol = ts.solve(SPHERE, G, [SRC], order=1)  # inner=2: the paper's tube, its own first-order error
    assert sol.stats.tube_shortcut is None and _largest_share(sol) < 0.07
    wide = ts.solve(SPHERE, G, [SRC], inner=8, outer=10)  # "auto": second order at any width
    assert wide.stats.order == 2 and wide.stats.tube_shortcut is None and _largest_share(wide) < 0.01
    plane = ts.surfaces.PlanePatch()
    flat = ts.solve(plane, G, [plane.default_source], order=1, inner=8, outer=10)  # no bend: nothing to cut
    assert flat.stats.tube_shortcut == 0.0
    x = np.random.default_rng(1).uniform(-0.6, 0.6, (500, 3))
    x[:, 2] = 0.0
    exact = np.linalg.norm(x - np.asarray(plane.default_source), axis=1)
    assert np.max(np.abs(flat(x) - exact)) < 3 * G.spacing


def test_a_tube_and_many_sources_give_the_same_estimate():
    with pytest.warns(RuntimeWarning, match=WARNING):
        one = ts.solve(SPHERE, G, [SRC], order=1, inner=4, outer=6)
    tube = ts.Tube(SPHERE, G, inner=4, outer=6)
    with pytest.warns(RuntimeWarning, match=WARNING):
        again = tube.solve([SRC], order=1)
    with pytest.warns(RuntimeWarning, match=WARNING):
        rows, stats = tube.solve_many([SRC, (0.5, 0.0, 0.0)], order=1, return_stats=True)
    assert again.stats.tube_shortcut == one.stats.tube_shortcut == stats["tube_shortcut"]
    assert np.array_equal(np.asarray(again.values), np.asarray(one.values))
