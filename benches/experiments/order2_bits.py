"""Hashes of the values of nine default solves, to show that a change of the core keeps the bits
(docs/development/performance-history.md, "The second-order update's instructions"): surfaces
with only resolved nodes and with first-order nodes (a crease, a rim, unresolved tips), a
smoothed mask, a speed field, ``solve_many`` and a 2D curve, the 3D ones on the default threads
and on one. Run it on two builds and compare the outputs (``diff``)::

    .venv/bin/python benches/experiments/order2_bits.py > before.txt   # on the first build
    .venv/bin/python benches/experiments/order2_bits.py > after.txt    # on the second
    diff before.txt after.txt && echo "the same bits"
"""

from __future__ import annotations

import hashlib
import warnings

import numpy as np

import tubesweep as ts


def digest(a: np.ndarray) -> str:
    return hashlib.sha1(np.ascontiguousarray(a).tobytes()).hexdigest()[:16]


def grid(d: int, n: int) -> ts.Grid:
    return ts.Grid((-1.0,) * d, (1.0,) * d, (n,) * d)


def main() -> None:
    warnings.simplefilter("ignore")  # the double torus's crease warning: its values are the point
    S = ts.surfaces
    for name, surf, n in (
        ("sphere", S.Sphere(0.5), 61),
        ("rounded cube", S.RoundedCube(), 81),
        ("double torus (crease)", S.DoubleTorus(), 101),
        ("hemisphere (rim)", S.Hemisphere(0.5), 61),
        ("ellipsoid (tips)", S.Ellipsoid(0.6, 0.45, 0.3), 51),
    ):
        src = [tuple(float(c) for c in surf.default_source)]
        sol = ts.solve(surf, grid(3, n), src)
        one = ts.solve(surf, grid(3, n), src, threads=1)
        print(f"{name} N = {n}: order {sol.stats.order}, {digest(sol.values)}, one thread {digest(one.values)}")
    g = grid(3, 61)
    X, Y, Z = g.meshgrid()
    mask = ts.LevelSet.from_mask(X**2 + Y**2 + Z**2 < 0.25, g, smooth=1.5)
    print(f"smoothed mask N = 61: {digest(ts.solve(mask, g, [(-0.5, 0.0, 0.0)]).values)}")
    field = ts.solve(S.Sphere(0.5), g, [(-0.5, 0.0, 0.0)], speed=lambda p: 1 + 0.3 * p[:, 0])
    print(f"sphere, speed 1 + 0.3x, N = 61: {digest(field.values)}")
    many = ts.Tube(S.Sphere(0.5), g).solve_many([(0.5, 0, 0), (0, 0.5, 0), (0, 0, -0.5)])
    print(f"solve_many, three sources, N = 61: {digest(many)}")
    star = S.Star()
    print(f"star (2D) N = 201: {digest(ts.solve(star, grid(2, 201), [star.default_source]).values)}")


if __name__ == "__main__":
    main()
