"""order="auto"'s first-order fallback on a grid that does not resolve the surface: a warning that
says how large its errors are (python/tubesweep/_fallback.py)."""

import re
import warnings

import numpy as np
import pytest

import tubesweep as ts
from conftest import FIRST_ORDER_SIZE
from tubesweep._fallback import FIRST_ORDER_SPACINGS, SIZE_WARNING, first_order_share

R = 0.5
SIZE = r"errors up to about (\d+)% of the distances"


def _stated_share(record) -> float:
    (w,) = [w for w in record if str(w.message).startswith(FIRST_ORDER_SIZE)]
    return int(re.search(SIZE, str(w.message)).group(1)) / 100


@pytest.mark.parametrize("n", [12, 16, 20])
def test_a_sphere_the_grid_does_not_resolve_warns_how_large_the_errors_are(n):
    g = ts.Grid((-1, -1, -1), (1, 1, 1), (n, n, n))
    with pytest.warns(RuntimeWarning, match=SIZE) as record:
        sol = ts.solve(ts.surfaces.Sphere(R), g, sources=[(-R, 0, 0)])
    assert sol.stats.order == 1 and "does not resolve" in sol.stats.order_fallback
    # the antipode is short by about FIRST_ORDER_SPACINGS spacings, 22-37% of π/2; the warning
    # says 19-22% (the smaller of 3Δx against the largest distance solved and Δx·κ, κ = 2)
    short = (np.pi * R - sol([(R, 0, 0)])[0]) / g.spacing
    assert 2.5 < short < 3.5
    stated = _stated_share(record)
    assert 0.18 < stated < short * g.spacing / (np.pi * R)
    assert stated == pytest.approx(min(FIRST_ORDER_SPACINGS * g.spacing / np.max(sol.values), 2 * g.spacing), rel=0.2)


def test_the_same_sphere_a_little_finer_runs_second_order_without_a_word():
    g = ts.Grid((-1, -1, -1), (1, 1, 1), (25, 25, 25))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sol = ts.solve(ts.surfaces.Sphere(R), g, sources=[(-R, 0, 0)])
    assert sol.stats.order == 2
    assert abs(sol([(R, 0, 0)])[0] - np.pi * R) < 0.025  # 1.3%, against 18% at first order


def test_a_circle_on_a_coarse_grid_warns_too_and_the_tube_and_many_sources_alike():
    g = ts.Grid((-1, -1), (1, 1), (16, 16))
    circle = lambda p: np.linalg.norm(p, axis=1) - R  # noqa: E731
    with pytest.warns(RuntimeWarning, match=SIZE) as record:
        sol = ts.solve(circle, g, sources=[(-R, 0)])
    assert sol.stats.order == 1 and 2.0 < (np.pi * R - sol([(R, 0)])[0]) / g.spacing < 3.5
    assert _stated_share(record) > 0.15
    tube = ts.Tube(circle, g)
    with pytest.warns(RuntimeWarning, match=SIZE):
        again = tube.solve([(-R, 0)])
    assert np.array_equal(again.values, sol.values)
    with pytest.warns(RuntimeWarning, match=SIZE):
        many = tube.solve_many([(-R, 0), (R, 0)])
    assert np.array_equal(many[0], sol.values)


def test_an_option_of_the_first_order_scheme_is_the_caller_s_choice_and_not_warned_about():
    # the same coarse sphere with the naive tube: the caller chose the paper's baseline
    g = ts.Grid((-1, -1, -1), (1, 1, 1), (16, 16, 16))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sol = ts.solve(ts.surfaces.Sphere(R), g, sources=[(-R, 0, 0)], method="naive")
        assert sol.stats.order == 1
        ts.solve(ts.surfaces.Sphere(R), g, sources=[(-R, 0, 0)], hamiltonian="lxf")


def test_a_fine_enough_first_order_fallback_stays_in_the_stats():
    # a mesh given as it is (the exact map: first order) at N = 61: 3Δx is 6% of the distances,
    # below the warning's share, and its errors are smaller still
    trimesh = pytest.importorskip("trimesh")
    ico = trimesh.creation.icosphere(subdivisions=3, radius=R)
    v, f = np.asarray(ico.vertices), np.asarray(ico.faces)
    g = ts.Grid((-1, -1, -1), (1, 1, 1), (61, 61, 61))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sol = ts.solve(ts.surfaces.from_mesh((v, f), smooth=False), g, sources=[v[0]])
    assert sol.stats.order == 1
    # the farthest vertex, against the sphere's arc: within the share the warning would name
    far = int(np.argmin(v @ v[0]))
    assert abs(sol.on_mesh(v[[far]])[0] - np.pi * R) < SIZE_WARNING * np.pi * R


def test_the_share_is_the_smaller_estimate_over_the_finite_values():
    assert first_order_share(np.array([0.0, 1.0, np.inf, np.nan]), 0.1, 2.0) == (pytest.approx(0.2), 1.0)
    assert first_order_share(np.array([0.0, 1.0]), 0.1, 5.0) == (pytest.approx(0.3), 1.0)
    assert first_order_share(np.array([np.inf, 0.0]), 0.1, 2.0) == (0.0, 0.0)
    assert SIZE_WARNING == 0.1


def test_the_tube_sees_the_sphere_s_curvature_and_a_flat_plane_s():
    from tubesweep._fallback import mean_curvature
    from tubesweep._prepare import _prepare_tube
    from tubesweep.surface import as_surface

    g = ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41))
    sphere = _prepare_tube(as_surface(ts.surfaces.Sphere(R)), g, 2.0, 4.0, "two-layer", False)
    assert mean_curvature(sphere) == pytest.approx(2.0, abs=0.05)  # 1/R, the parallel surfaces' mean
    plane = _prepare_tube(as_surface(lambda p: p[:, 2] - 0.013), g, 2.0, 4.0, "two-layer", False)
    assert mean_curvature(plane) < 1e-5
