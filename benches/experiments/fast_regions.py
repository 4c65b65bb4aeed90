"""``order=2`` where the speed is far higher than at the source, without a runaway: the largest
and mean error of the circle of radius 0.5 against its exact travel times, at N = 101–801, for
``order=2`` and ``order=1``, with the fitted order of each refinement.

Cases (the speed is constant along the circle's normals, so the exact travel time is the
integral of the slowness along the arc from the source at (−0.5, 0)): the right half ``c`` times
faster (c = 3, 30, 100: a jump), and a speed rising smoothly along the circle as
``c^((x + 0.5))`` (c = 30, x the foot point's abscissa). From a contrast of about 30 the errors
converge at first order (still 2–40 times below ``order=1``'s): where u is nearly flat, w = u − u₀
carries u₀'s curvature at the source's slowness, which the BDF2 ramp's kink test
(``second_order/local.rs``, ``KINK2``, scaled by the node's slowness) takes for a kink, so the fast
region runs BDF2's first-order fallback. Attempts to scale that test otherwise, and why none was
kept: docs/development/history-notes.md::

    .venv/bin/python benches/experiments/fast_regions.py

With ``--sphere``: the sphere of radius 0.5 with its half x > 0 3 or 30 times faster, the source
at (−0.5, 0, 0), N = 41–81, the errors along the great circle z = 0 through the source.
"""

from __future__ import annotations

import math
import sys
import warnings

import numpy as np

import tubesweep as ts

R = 0.5
SIZES = (101, 201, 401, 801)


def jump(c: float):
    # (the nodes on x = 0 slow: their foot points' abscissa rounds to ±6e-17)
    return lambda x: np.where(x > 1e-12, c, 1.0)


def smooth(c: float):
    return lambda x: np.exp(math.log(c) * (x + R))


def errors(n: int, speed_of_x, order: int):
    g = ts.Grid((-1.0, -1.0), (1.0, 1.0), (n, n))
    x, y = g.meshgrid()
    foot_x = R * np.cos(np.arctan2(y, x))  # constant along the normals
    surf = ts.LevelSet(np.hypot(x, y) - R)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sol = ts.solve(surf, g, [(-R, 0.0)], speed=speed_of_x(foot_x), order=order)
    # the exact travel time from the source (angle π) to the angle θ ∈ [0, π] (by symmetry)
    theta = np.linspace(np.pi, 0.0, 400001)
    slowness = 1.0 / speed_of_x(R * np.cos(theta))
    exact = np.concatenate([[0.0], np.cumsum(0.5 * (slowness[1:] + slowness[:-1]) * R * np.diff(-theta))])
    at = np.arange(0, theta.size, 1000)
    points = R * np.c_[np.cos(theta[at]), np.sin(theta[at])]
    e = np.abs(sol(points) - exact[at])
    return sol.stats.order, float(e.max()), float(e.mean())


def sphere() -> None:
    print("| case | N | order=2 max | mean | iterations |")
    print("|---|---|---|---|---|")
    for c in (3.0, 30.0):
        for n in (41, 61, 81):
            g = ts.Grid((-1.0,) * 3, (1.0,) * 3, (n,) * 3)
            speed = np.where(g.meshgrid()[0] > 1e-12, c, 1.0)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                sol = ts.solve(ts.surfaces.Sphere(R), g, [(-R, 0.0, 0.0)], speed=speed)
            theta = np.linspace(np.pi, 0.0, 181)
            a = np.pi - theta
            exact = R * np.where(a <= np.pi / 2, a, np.pi / 2 + (a - np.pi / 2) / c)
            e = np.abs(sol(R * np.c_[np.cos(theta), np.sin(theta), 0 * theta]) - exact)
            assert sol.stats.order == 2
            print(f"| half {c:g}× faster | {n} | {e.max():.2e} | {e.mean():.2e} | {sol.stats.iterations} |")


def main() -> None:
    if "--sphere" in sys.argv[1:]:
        sphere()
        return
    cases = [("right half 3× faster", jump(3.0)), ("right half 30× faster", jump(30.0))]
    cases += [("right half 100× faster", jump(100.0)), ("speed 30^(x+0.5)", smooth(30.0))]
    print("| case | N | order=2 max | mean | order | order=1 max | mean |")
    print("|---|---|---|---|---|---|---|")
    for name, speed in cases:
        before = None
        for n in SIZES:
            ran, mx, mean = errors(n, speed, 2)
            _, mx1, mean1 = errors(n, speed, 1)
            rate = "" if before is None else f"{math.log2(before / mx):.2f}"
            print(f"| {name} | {n} | {mx:.2e} | {mean:.2e} | {rate} | {mx1:.2e} | {mean1:.2e} |")
            assert ran == 2
            before = mx


if __name__ == "__main__":
    main()
