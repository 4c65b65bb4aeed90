"""Many sources at second order: each row is its source's ``tube.solve`` also where that solve
falls back or is degraded (widths that leave second order no room, a source whose sweeps run
away, nodes next to a source, many first-order nodes), and a batch too large for memory is a
MemoryError (review of stop 68)."""

import warnings

import numpy as np
import pytest

import tubesweep as ts
from tubesweep.second_order import NarrowExtension, Order2RanAway


def bits(a):
    return np.ascontiguousarray(a, dtype=float).view(np.uint64)


def single(tube, source, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return tube.solve([source], **kw)


def test_widths_that_leave_second_order_no_room_decide_the_batch_as_tube_solve():
    # outer = 3 is widened to 4 while the band is built; tube.solve keeps to the widths given
    # (first order under "auto", refused under order=2); the batch ran second order
    g = ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3)
    with pytest.warns(RuntimeWarning, match="Widening the extension layer to outer = 4"):
        tube = ts.Tube(ts.surfaces.Sphere(0.5), g, inner=2, outer=3)
    src = (0.5, 0.0, 0.0)
    with pytest.warns(RuntimeWarning, match="the widths given decide"):
        U, st = tube.solve_many([src], return_stats=True)
    assert st["order"] == 1 and "outer ≥ inner + 2" in st["order_fallback"]
    assert np.array_equal(bits(U[0]), bits(single(tube, src).values))
    with pytest.raises(NarrowExtension, match="outer ≥ inner \\+ 2"):
        tube.solve_many([src], order=2)
    with pytest.raises(NarrowExtension):
        ts.distance_matrix(tube, None, [src, (-0.5, 0, 0)], order=2)


@pytest.fixture(scope="module")
def obstacle():
    # a source inside a ball of speed 0.01: its second-order sweeps run away (the factored update
    # is not causal where the speed is 100 times the source's), the other source's do not
    g = ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3)
    x = np.stack(np.meshgrid(*[np.linspace(-1, 1, 41)] * 3, indexing="ij"), -1)
    speed = np.where(np.linalg.norm(x - [0.5, 0, 0], axis=-1) < 0.15, 1e-2, 1.0)
    return ts.Tube(ts.surfaces.Sphere(0.5), g), speed


def test_a_source_whose_sweeps_run_away_falls_back_alone(obstacle):
    tube, speed = obstacle
    sources = [(0.5, 0, 0), (-0.5, 0, 0), (0, 0, 0.5)]
    at = [(0, 0, 0.5), (0, 0.5, 0), (-0.5, 0, 0)]
    with pytest.warns(
        RuntimeWarning, match=r"ran away .* \(1 of 3 solves, sources \[0\]\); their rows are the first-order solution"
    ):
        U, st = tube.solve_many(sources, at=at, speed=speed, return_stats=True)
    # the lowest order of any row, and each row's; the two others kept second order (the whole
    # batch ran first order, 0.031 off at a quarter turn where second order is 1e-4 off)
    assert st["order"] == 1 and st["orders"].tolist() == [1, 2, 2]
    assert "ran away" in st["order_fallback"]
    for k, s in enumerate(sources):
        sol = single(tube, s, speed=speed)
        assert sol.stats.order == st["orders"][k]
        assert np.array_equal(bits(U[k]), bits(sol(at))), k
        # the row's stats are its solve's (the first-order one's for the source that ran away)
        assert st["converged"][k] and st["iterations"][k] == sol.stats.iterations, k
    assert abs(U[1, 1] - np.pi / 4) < 5e-4  # (−0.5, 0, 0) to (0, 0.5, 0): a quarter turn, speed 1
    # the whole band too, and order=2 refuses as tube.solve does
    with pytest.warns(RuntimeWarning, match="ran away"):
        V = tube.solve_many(sources[:2], speed=speed)
    assert np.array_equal(bits(V[1]), bits(single(tube, sources[1], speed=speed).values))
    with pytest.raises(Order2RanAway, match=r"1 of 2 solves, sources \[0\]"):
        tube.solve_many(sources[:2], speed=speed, order=2)


def test_rows_are_never_negative_and_equal_single_solves_next_to_their_sources():
    # farthest point sampling returns closest points of band nodes: u = u0 + w rounds below 0
    # there (down to -1.3e-5 on this torus), which tube.solve clamps at 0
    s = ts.surfaces.Torus(0.6, 0.25)
    tube = ts.Tube(s, ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3))
    points, _ = ts.farthest_point_sampling(tube, None, 10)
    U = tube.solve_many(points)
    assert U.min() == 0.0
    at = points + 0.3 * tube.grid.spacing * np.array([0.0, 0.0, 1.0])
    A = tube.solve_many(points, at=at)
    for k in range(10):
        sol = single(tube, points[k])
        assert np.array_equal(bits(U[k]), bits(sol.values)), k
        assert np.array_equal(bits(A[k]), bits(sol(at))), k


def test_many_first_order_nodes_are_warned_and_counted_as_for_a_single_solve():
    s = ts.surfaces.MobiusBand()
    tube = ts.Tube(s, ts.Grid(*s.default_box, (21,) * 3))
    with pytest.warns(RuntimeWarning, match=r"order=2: \d+ of the \d+ inner-tube nodes \(\d+%\) ran the first-order"):
        sol = tube.solve([s.default_source])
    with pytest.warns(RuntimeWarning, match=r"ran the first-order update") as caught:
        U, st = tube.solve_many([s.default_source], return_stats=True)
    assert len([w for w in caught if "first-order update" in str(w.message)]) == 1
    assert st["first_order_nodes"] == sol.stats.order2["first_order_nodes"] > 0.4 * st["inner_nodes"]
    assert st["inner_nodes"] == sol.stats.order2["inner_nodes"]
    assert np.array_equal(bits(U[0]), bits(sol.values))


def test_empty_points_and_a_bad_progress_are_refused_before_any_solve():
    tube = ts.Tube(ts.surfaces.Sphere(0.5), ts.Grid((-1,) * 3, (1,) * 3, (21,) * 3))
    with pytest.raises(ValueError, match=r"points is empty: give at least one point"):
        ts.distance_matrix(tube, None, [])
    with pytest.raises(TypeError, match="progress must be a callable"):
        ts.farthest_point_sampling(tube, None, 3, progress=3)


def test_values_at_points_near_a_source_on_a_phi_array_are_sol_at():
    # within three spacings of a source the batch read the chord from the point itself, not from
    # its closest point as sol(points) does: a point 0.005 off the sphere above its source read
    # 0.005 (sol: 0), points on it up to 7.7e-5 off sol's, on a φ array (analytic surfaces matched)
    g = ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3)
    phi = np.linalg.norm(np.stack(g.meshgrid(), -1), axis=-1) - 0.5
    tube = ts.Tube(ts.LevelSet(phi), g)
    src = np.array([[0.0, 0.0, 0.5]])
    t = np.linspace(0.01, 0.4, 40)
    on = 0.5 * np.c_[np.sin(t), 0 * t, np.cos(t)]
    at = np.concatenate([on, on * (1 + np.linspace(-0.02, 0.02, 40))[:, None]])
    sol = single(tube, src[0])
    assert np.array_equal(bits(tube.solve_many(src, at=at)[0]), bits(sol(at)))
    assert sol(src * 1.01)[0] < 1e-12


def test_a_tube_split_at_creases_falls_back_in_the_batch_as_in_a_single_solve():
    # two balls joined by a neck 1.9 spacings thick: thinned at its creases the inner tube splits,
    # which tube.solve finds from its band values and solves at first order; solve_many, whose
    # rows at `at` cannot show it, read inf on the far ball, converged, unwarned, until a
    # tube.solve had refused the tube; ts.distance_matrix too (a review)
    g = ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3)
    x = np.stack(g.meshgrid(), -1)
    balls = np.minimum(np.linalg.norm(x - (-0.45, 0, 0), axis=-1), np.linalg.norm(x - (0.45, 0, 0), axis=-1)) - 0.35
    neck = np.maximum(np.hypot(x[..., 1], x[..., 2]) - 0.095, np.abs(x[..., 0]) - 0.45)
    phi = ts.LevelSet(np.minimum(balls, neck), redistance=True)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rows, st = ts.Tube(phi, g).solve_many([(-0.8, 0, 0)], at=[(0.8, 0, 0)], return_stats=True)
        single = ts.Tube(phi, g).solve([(-0.8, 0, 0)])
        matrix = ts.distance_matrix(phi, g, [(-0.8, 0, 0), (0.8, 0, 0)])
    assert any("crease" in str(w.message) for w in caught)  # (its creases are said, and the first order)
    assert single.stats.order == 1 and "splits" in single.stats.order_fallback
    assert st["order"] == 1 and "splits" in st["order_fallback"]
    assert rows[0, 0] == single([(0.8, 0, 0)])[0] and 1.8 < rows[0, 0] < 1.9
    assert np.all(np.isfinite(matrix)) and abs(matrix[0, 1] - rows[0, 0]) < 1e-6


def test_an_infinity_below_the_travel_times_is_refused_by_the_batch_as_by_a_single_solve():
    # solve_many(order=1, infinity=1.0) on the sphere: the far pole read inf, converged, unwarned
    tube = ts.Tube(ts.surfaces.Sphere(0.5), ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3))
    for at in ([(0.5, 0, 0), (0, 0, -0.5)], None):
        with pytest.raises(ValueError, match=r"infinity=1 is not above the travel times: the front stopped"):
            tube.solve_many([(0, 0, 0.5)], at=at, order=1, infinity=1.0)
    # above them it stands, equal to the single solve
    rows = tube.solve_many([(0, 0, 0.5)], at=[(0, 0, -0.5)], order=1, infinity=10.0)
    assert rows[0, 0] == tube.solve([(0, 0, 0.5)], order=1, infinity=10.0)([(0, 0, -0.5)])[0]


def test_a_batch_too_large_for_memory_is_refused_before_any_source_is_set_up(monkeypatch):
    # at order=1 the allocation refused it, after minutes of per-source set-up (120,000 sources:
    # 172 s; a review); now the K rows are checked first
    import tubesweep._validate as validate

    tube = ts.Tube(ts.surfaces.Sphere(0.5), ts.Grid((-1,) * 3, (1,) * 3, (21,) * 3))
    monkeypatch.setattr(validate, "available_memory_bytes", lambda: 10_000_000)
    sources = 0.5 * np.eye(3)[np.arange(600) % 3]
    for order in (1, "auto"):
        with pytest.raises(MemoryError, match=rf"solve_many's 600 rows of {tube.band_points} values needs about"):
            tube.solve_many(sources, order=order)
    assert tube.solve_many(sources, at=[(0.5, 0, 0)], order=1).shape == (600, 1)  # K × M fits
