"""The private native module rejects malformed calls with exceptions: no panic crosses into
Python."""

import numpy as np
import pytest

from tubesweep import _native


def test_band_construction_errors():
    with pytest.raises(ValueError, match="sorted"):
        _native.Band.from_linear([5, 5], np.array([3, 2], dtype=np.uint64))
    with pytest.raises(ValueError, match="outside"):
        _native.Band.from_linear([5, 5], np.array([30], dtype=np.uint64))
    with pytest.raises(ValueError, match="2D and 3D"):
        _native.Band.from_linear([5, 5, 5, 5], np.array([0], dtype=np.uint64))
    with pytest.raises(ValueError, match="at least 3"):
        _native.Band.full_box([2, 9])


def test_solve_argument_errors():
    band = _native.Band.full_box([5, 5])
    roles = np.ones(25, np.uint8)
    fixed = (np.zeros(0, np.int64), np.zeros(0))
    ok = dict(
        spacing=0.25,
        slowness=1.0,
        directions=None,
        scheme="godunov",
        missing="infinity",
        tol=1e-9,
        max_iterations=10,
        infinity=None,
    )
    with pytest.raises(ValueError, match="one entry per band node"):
        band.solve(roles[:-1], *fixed, **ok)
    with pytest.raises(ValueError, match="role"):
        band.solve(np.full(25, 7, np.uint8), *fixed, **ok)
    with pytest.raises(ValueError, match="scheme"):
        band.solve(roles, *fixed, **{**ok, "scheme": "weno"})
    with pytest.raises(ValueError, match="infinity"):
        band.solve(roles, *fixed, **{**ok, "infinity": -1.0})
    with pytest.raises(ValueError, match="speed"):
        band.solve(roles, *fixed, **{**ok, "slowness": np.ones(3)})
    r2 = roles.copy()
    r2[3] = 2
    with pytest.raises(ValueError, match="directions"):
        band.solve(r2, *fixed, **ok)
    with pytest.raises(ValueError, match="points"):
        band.interpolate(np.zeros(25), [0.0, 0.0], 0.25, np.zeros((3, 3)))
    with pytest.raises(ValueError, match="values"):
        band.interpolate(np.zeros(24), [0.0, 0.0], 0.25, np.zeros((3, 2)))


def test_unreached_nodes_report_the_infinity_used():
    band = _native.Band.from_linear([5, 5], np.array([0, 1, 20, 21], dtype=np.uint64))  # two pieces
    roles = np.array([0, 1, 1, 1], np.uint8)
    vals, st = band.solve(roles, np.array([0]), np.zeros(1), 1.0, 1.0, None, "godunov", "infinity", 1e-12, 10, None)
    assert vals[1] == 1.0
    assert vals[2] == st["infinity"] and vals[3] == st["infinity"]


def test_a_failing_solve_leaves_the_directions_as_they_were_and_fortran_order_is_refused():
    band = _native.Band.full_box([5, 5])
    roles = np.ones(25, np.uint8)
    roles[3] = 2  # one extension-layer node
    fixed = (np.zeros(0, np.int64), np.zeros(0))
    ok = dict(
        spacing=0.25, slowness=1.0, scheme="godunov", missing="infinity", tol=1e-9, max_iterations=10, infinity=None
    )
    directions = np.tile(np.float32([0.6, 0.8]), (25, 1))
    before = directions.copy()
    for bad in ({"spacing": -1.0}, {"infinity": -1.0}, {"tol": -1.0}, {"slowness": np.ones(3)}):
        with pytest.raises(ValueError):
            band.solve(roles, *fixed, directions=directions, **{**ok, **bad})
        np.testing.assert_array_equal(directions, before)
    with pytest.raises(ValueError, match="fixed_positions"):
        band.solve(roles, np.array([99], np.int64), np.zeros(1), directions=directions, **ok)
    np.testing.assert_array_equal(directions, before)
    # a Fortran-ordered (K, d) array would be read with its axes swapped: refused, by name
    with pytest.raises(ValueError, match="directions must be a C-ordered"):
        band.solve(roles, *fixed, directions=np.asfortranarray(directions), **ok)
    with pytest.raises(ValueError, match="points must be a C-ordered"):
        band.interpolate(np.zeros(25), [0.0, 0.0], 0.25, np.asfortranarray(np.zeros((4, 2))))


def test_the_analytic_band_s_gradient_norms_are_single_precision_and_bound_like_the_whole_band():
    """|∇φ| comes back in float32 (4 bytes per node at the set-up's peak, not 8), and
    ``surface._norm_bounds``, which works chunk by chunk, gives the range of the whole band: over
    the nodes within half the band of the surface when there are any, over all of them when not."""
    from tubesweep.band import EVAL_CHUNK
    from tubesweep.surface import _norm_bounds

    n = 61
    h = 2.0 / (n - 1)
    linear, values, band, direction, norm = _native.analytic_level_set_band(
        "sphere", [0.0, 0.0, 0.0, 0.5], [n, n, n], [-1.0, -1.0, -1.0], h, 4 * h, 1.0
    )
    assert norm.dtype == np.float32 and direction.dtype == np.float32
    assert len(norm) == len(linear) == len(values) == len(band) > 0
    assert np.all(np.abs(norm - 1.0) < 0.05)
    rng = np.random.default_rng(3)
    k = 2 * EVAL_CHUNK + 123  # three chunks, the last one short
    values = rng.uniform(-1.0, 1.0, k)
    norm = rng.uniform(0.5, 1.5, k).astype(np.float32)
    near = np.abs(values) <= 0.25
    assert _norm_bounds(values, norm, 0.5) == (float(norm[near].min()), float(norm[near].max()), True)
    far = np.where(np.abs(values) < 0.3, 0.3, values)  # no node within 0.25
    assert _norm_bounds(far, norm, 0.5) == (float(norm.min()), float(norm.max()), False)
    # a NaN is passed on, as the whole band's minimum would, and does not hide the near nodes
    norm[k // 2] = np.nan
    lo, hi, found = _norm_bounds(np.zeros(k), norm, 0.5)
    assert np.isnan(lo) and np.isnan(hi) and found
