"""How close can a warm start be? (issue 47, docs/moving-surfaces.md, "About the cold solve's time").

The sphere → ellipsoid sequence of ``benches/moving_surfaces.py`` (the same φ, poles and steps):
every step is solved cold, and each cold solution from step 3 on is predicted from the *cold*
solutions of the steps before — the best start a warm solve could have from previous steps:

* carried: the previous solution (what ``warm=previous`` starts from);
* linear: 2·u₋₁ − u₋₂ (what ``warm=(older, previous)`` starts from);
* quadratic: 3·u₋₁ − 3·u₋₂ + u₋₃.

Printed per step: the largest and the median |prediction − cold| over the nodes in all four bands,
in units of the solve's stopping tolerance (``sol.stats.order2["tol"]``), and the cold solve's
iterations and local updates per band node. The second-order sweeps contract a smooth error by
about 2.5 per iteration (``crates/tubesweep-core/src/second_order/warm.rs``), so a start whose
largest error is E tolerances needs about log(E)/log(2.5) iterations over the whole band before it
stops: printed as "iterations needed" for the best predictor.

    .venv/bin/python benches/experiments/warm_predictors.py [--n 121] [--steps 20]
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

import tubesweep as ts

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from moving_surfaces import axes, phi_of  # noqa: E402  (the same sequence as the warm-solve bench)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=121)
    ap.add_argument("--steps", type=int, default=20)
    args = ap.parse_args()
    n, steps = args.n, args.steps
    grid = ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3)
    pts = grid.node_points(np.arange(n**3))
    sols = []
    print(f"N = {n}, {steps} steps; |prediction − cold| / tol over the nodes of four consecutive bands")
    print("step  carried max/median  linear max/median  quadratic max/median  cold: iterations, updates per node")
    best = []
    for k in range(steps + 1):
        a = axes(k, steps)
        sol = ts.solve(phi_of(a, pts, grid.shape), grid, [(0.0, 0.0, float(a[2]))])
        sols.append(sol)
        if k < 3:
            continue
        last4 = sols[-4:]
        common = last4[0].linear
        for s in last4[1:]:
            common = np.intersect1d(common, s.linear, assume_unique=True)
        u = [s.values[np.searchsorted(s.linear, common)] for s in last4]  # u₋₃, u₋₂, u₋₁, u₀
        tol = sol.stats.order2["tol"]
        preds = {"carried": u[2], "linear": 2 * u[2] - u[1], "quadratic": 3 * u[2] - 3 * u[1] + u[0]}
        cells = []
        errs = {}
        for name, p in preds.items():
            e = np.abs(p - u[3]) / tol
            errs[name] = float(np.max(e))
            cells.append(f"{np.max(e):9.1f} / {np.median(e):7.2f}")
        best.append(min(errs.values()))
        per_node = sol.stats.updates / len(sol.linear)
        print(f"{k:4d}  " + "   ".join(cells) + f"   {sol.stats.iterations}, {per_node:.1f}")
    e = float(np.median(best))
    print(
        f"median over the steps of the best predictor's largest error: {e:.1f} tol, about "
        f"{math.log(max(e, 1.0)) / math.log(2.5):.1f} iterations over the whole band to contract it"
    )


if __name__ == "__main__":
    main()
