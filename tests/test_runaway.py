"""A region far faster than the sources: the factored update ``u = u₀ + w`` of ``order=2`` is not
causal there, its sweeps run away (travel times falling without bound), and so does their
first-order factored restart. The solve detects the creep within tens of iterations
(``second_order/phase.rs``, ``CREEP_TOLERANCES``; before, 10,000 iterations, 1–5 minutes, and a
band of zeros reported as ``order=2``) and returns the paper's first-order scheme, with a warning
(``order="auto"``), or refuses (``order=2``)."""

from __future__ import annotations

import numpy as np
import pytest

import tubesweep as ts
from tubesweep.second_order import Order2RanAway


def fast_half(d: int, n: int, contrast: float):
    """The circle or sphere of radius 0.5, the speed ``contrast`` on x > 0 and 1 elsewhere."""
    g = ts.Grid((-1.0,) * d, (1.0,) * d, (n,) * d)
    X = g.meshgrid()
    r = np.sqrt(sum(x**2 for x in X))
    speed = np.ones(g.shape)
    speed[X[0] > 0] = contrast
    return ts.LevelSet(r - 0.5), g, speed


@pytest.mark.parametrize(
    ("d", "n", "contrast", "shown", "bound"), [(2, 201, 1000.0, r"1e\+03", 0.02), (3, 41, 100.0, "100", 0.12)]
)
def test_a_fast_region_falls_back_to_the_papers_scheme_with_a_warning(d, n, contrast, shown, bound):
    surf, g, speed = fast_half(d, n, contrast)
    src = [(-0.5,) + (0.0,) * (d - 1)]
    with pytest.warns(
        RuntimeWarning,
        match=rf"ran away .* restart did too: .*much higher than at the sources \(here up to {shown} times\)",
    ):
        sol = ts.solve(surf, g, src, speed=speed)
    ref = ts.solve(surf, g, src, speed=speed, order=1)
    assert sol.stats.order == 1 and sol.stats.converged and "ran away" in sol.stats.order_fallback
    np.testing.assert_array_equal(sol.values, ref.values)
    # the antipode: a quarter circle at speed 1 and one at `contrast`, to order 1's error at this N
    # (0.13 on the sphere at N = 41 at a constant speed), not the zeros of a runaway
    far = np.array([(0.5,) + (0.0,) * (d - 1)])
    assert abs(float(sol(far)[0]) - 0.25 * np.pi * (1 + 1 / contrast)) < bound
    with pytest.raises(Order2RanAway, match=r"order=1, the paper's scheme"):
        ts.solve(surf, g, src, speed=speed, order=2)


def test_a_tube_does_not_keep_a_runaway_as_its_refusal():
    surf, g, speed = fast_half(2, 201, 1000.0)
    tube = ts.Tube(surf, g)
    src = [(-0.5, 0.0)]
    with pytest.warns(RuntimeWarning, match="ran away"):
        assert tube.solve(src, speed=speed).stats.order == 1
    # the same band at a constant speed: second order
    assert tube.solve(src).stats.order == 2
    with pytest.warns(RuntimeWarning, match=r"ran away .*\(2 of 2 solves, sources \[0, 1\]\)"):
        values, st = tube.solve_many([(-0.5, 0.0), (0.0, -0.5)], speed=speed, return_stats=True)
    assert st["order"] == 1 and "ran away" in st["order_fallback"]
    assert tube.solve_many([(-0.5, 0.0)], return_stats=True)[1]["order"] == 2


def test_a_moderate_contrast_stays_second_order():
    # 3–50 times faster: the factored sweeps converge (the creep test does not fire)
    surf, g, speed = fast_half(2, 201, 10.0)
    sol = ts.solve(surf, g, [(-0.5, 0.0)], speed=speed)
    o = sol.stats.order2
    assert sol.stats.order == 2 and sol.stats.converged and o["runaway_iteration"] is None
    # a jump in the speed: the error is larger than on a smooth speed, and far below order 1's (0.01)
    assert abs(float(sol([(0.5, 0.0)])[0]) - 0.25 * np.pi * 1.1) < 5e-3
