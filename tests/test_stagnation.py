"""The stagnation safeguard of the second-order sweeps as the user hears of it
(``tubesweep._stagnation``): the phase-2 iteration at which the sweeps fell back to accepting
decreases only, how far from settled the values were then, and a warning when that is large."""

import warnings

import numpy as np
import pytest

import tubesweep as ts
from tubesweep._stagnation import FALLBACK_WARNING, fallback_message

SOURCE = (0.5, 0.0, 0.0)


def sphere_solve(tol=None):
    grid = ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3)
    kw = {} if tol is None else {"tol": tol}
    return ts.solve(ts.surfaces.Sphere(0.5), grid, [SOURCE], **kw)


def test_a_converging_solve_reports_no_fallback():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sol = sphere_solve()
    o = sol.stats.order2
    assert sol.stats.order == 2 and o["fallback_iteration"] is None and o["fallback_change"] is None


def test_a_stall_at_the_round_off_is_recorded_and_small_ones_stay_quiet():
    # tol = 1e-15 against travel times up to 1.56: the changes stop falling at about 2e-14, 22
    # tolerances: the stats record it, no warning (below FALLBACK_WARNING tolerances)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sol = sphere_solve(1e-15)
    o = sol.stats.order2
    assert sol.stats.converged and o["fallback_iteration"] is not None
    assert 1e-15 < o["fallback_change"] < FALLBACK_WARNING * 1e-15
    # the values are those of the default tolerance's solve to its tolerance
    ref = sphere_solve()
    assert np.max(np.abs(sol.values - ref.values)) < 20 * ref.stats.order2["tol"]


def test_a_tol_below_the_round_off_warns_that_it_cannot_be_met():
    with pytest.warns(RuntimeWarning, match=r"round-off of travel times up to 1\.5.*tol=1e-16 is below what float64"):
        sol = sphere_solve(1e-16)
    o = sol.stats.order2
    assert sol.stats.converged and o["fallback_iteration"] is not None
    assert 1e-15 < o["fallback_change"] < 1e-13


def test_a_large_fallback_says_how_large():
    text = fallback_message(12, 3e-5, 1e-7, np.array([1.5]))
    assert "iteration 12" in text and "3e-05, 300 times tol=1e-07" in text and "off the second-order" in text
    assert fallback_message(12, 0.9 * FALLBACK_WARNING * 1e-7, 1e-7, np.array([1.5])) is None
    assert fallback_message(None, None, 1e-7, np.array([1.5])) is None
    # the same change against travel times of 1e9 is their round-off
    assert "round-off" in fallback_message(12, 3e-5, 1e-7, np.array([1e9, np.inf]))


def test_many_sources_report_their_fallbacks_per_source():
    tube = ts.Tube(ts.surfaces.Sphere(0.5), ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3))
    sources = [SOURCE, (0.0, 0.5, 0.0)]
    _, st = tube.solve_many(sources, order=2, return_stats=True)
    assert np.all(st["fallback_iteration"] == -1) and np.all(np.isnan(st["fallback_change"]))
    with pytest.warns(RuntimeWarning, match=r"2 of 2 solves \(sources \[0, 1\]\) fell back.*round-off"):
        _, st = tube.solve_many(sources, order=2, tol=1e-17, return_stats=True)
    assert np.all(st["fallback_iteration"] > 0) and np.all(
        (st["fallback_change"] > 1e-15) & (st["fallback_change"] < 1e-13)
    )


def test_the_box_reports_the_same_entries():
    grid = ts.Grid((-1, -1), (1, 1), (101, 101))
    _, st = ts.travel_time(grid, [(0.1, 0.2)], order=2, return_stats=True)
    assert st.order2["fallback_iteration"] is None and st.order2["fallback_change"] is None


def test_a_tol_far_below_the_default_is_named_in_the_advice():
    # the six-fold star at N = 801 with 1e-5 of the default tol: the changes stop falling at about
    # 6e-12 (200 tolerances), above the round-off test; the advice is about tol, not the grid
    grid = ts.Grid((-1.0, -1.0), (1.0, 1.0), (801, 801))
    star = ts.surfaces.Star()
    default = ts.solve(star, grid, [(0.5, 0.0)])
    tol = 1e-5 * default.stats.order2["tol"]
    with pytest.warns(RuntimeWarning, match=r"tol=3\.125e-14 is 100000 times below the default \(3\.13e-09\)") as rec:
        sol = ts.solve(star, grid, [(0.5, 0.0)], tol=tol)
    assert "finer grid" not in str(rec[0].message)
    o = sol.stats.order2
    assert sol.stats.converged and o["fallback_iteration"] is not None and o["fallback_change"] > FALLBACK_WARNING * tol
    # the values are the default solve's to within the default's creep at this N (docs/development)
    assert np.max(np.abs(sol.values - default.values)) < 100 * default.stats.order2["tol"]
    # at the default the same stall is below it: no fallback
    assert default.stats.order2["fallback_iteration"] is None


def test_the_advice_names_the_grid_at_the_default_tol():
    text = fallback_message(12, 3e-5, 1e-7, np.array([1.5]), default_tol=1e-7)
    assert "finer grid" in text and "below the default" not in text
    text = fallback_message(12, 3e-5, 1e-9, np.array([1.5]), default_tol=1e-7)
    assert "tol=1e-09 is 100 times below the default (1e-07)" in text and "a tol of 3e-05 or more" in text
