"""2D ``order=2`` on fine curves: the stopping tolerance against the distance to the fixed point
(``second_order.FINE_CURVE_SPACINGS``, docs/second-order.md). Phase 2's changes fall ever more
slowly as the grid is refined, so a stop at a change of ``tol`` leaves the values about
``tol·ℓ/Δx`` from the fixed point: with a tolerance of ``1e-3·Δx²/ℓ`` that gap is first order in
Δx and outgrows the scheme's O(Δx²) error.

Per case and N: far max and mean errors against the exact distances of ``tubesweep reproduce
second-order``'s circle and six-fold star, the iterations, and the largest difference from a
reference solve at 1/100 of the Δx² tolerance (the fixed point to within its own gap), for three
tolerances: the Δx² rule alone, the default (that rule times ``min(1, 200·Δx/ℓ)``), and the
reference.

    .venv/bin/python benches/experiments/fine_curve_tolerance.py [--sizes 401,801,1601,3201]
"""

from __future__ import annotations

import argparse

import numpy as np

import tubesweep as ts
from tubesweep.reproduce.second_order import circle_case, star_case
from tubesweep.second_order import TOL_FACTOR


def main(sizes: list) -> None:
    for name, make in (("circle", circle_case), ("star", star_case)):
        surf, src, pts, exact, far, _ = make()
        for n in sizes:
            grid = ts.Grid((-1.0, -1.0), (1.0, 1.0), (n, n))
            dx2 = TOL_FACTOR[2] * grid.spacing**2  # ℓ = 1 and the slowness 1 on these grids
            runs = {"Δx² rule": dx2, "default": None, "reference": dx2 / 100}
            sols = {k: ts.solve(surf, grid, [src], **({} if t is None else {"tol": t})) for k, t in runs.items()}
            ref = sols["reference"].values
            for k, sol in sols.items():
                e = np.abs(sol(pts) - exact)
                tol = sol.stats.order2["tol"]
                gap = float(np.max(np.abs(sol.values - ref)))
                print(
                    f"{name:6s} N = {n:5d} {k:10s} tol {tol:.3g}: far max {e[far].max():.3g}, mean {np.nanmean(e):.3g}, "
                    f"{sol.stats.iterations} iterations, max |· − reference| {gap:.2g}"
                )


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="401,801,1601,3201")
    a = ap.parse_args()
    main([int(s) for s in a.sizes.split(",")])
