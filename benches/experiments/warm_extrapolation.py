"""How close a start extrapolated in time gets to a moving surface's next solution (issue 47,
docs/development/performance-history.md, "Warm starts on a moving surface"): the sphere of
``benches/moving_surfaces.py`` deforming into its ellipsoid in 20 steps on an N³ grid, each step
solved cold; at the nodes common to four consecutive steps' bands, the error of three starts for
step k against its cold solution, in units of the solve's tolerance: the previous step's values,
the linear extrapolation 2·u_{k−1} − u_{k−2} and the quadratic 3·u_{k−1} − 3·u_{k−2} + u_{k−3}.

    .venv/bin/python benches/experiments/warm_extrapolation.py [N] [last step]   # 61 7
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import tubesweep as ts

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from moving_surfaces import axes, phi_of  # noqa: E402

STEPS = 20


def main(n: int, last: int) -> None:
    grid = ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3)
    pts = grid.node_points(np.arange(n**3))
    sols = [
        ts.solve(phi_of(axes(k, STEPS), pts, grid.shape), grid, [(0.0, 0.0, float(axes(k, STEPS)[2]))])
        for k in range(last + 1)
    ]
    tol = sols[-1].stats.order2["tol"]

    def at(sol, linear):
        return sol.values[np.searchsorted(sol.linear, linear)]

    for k in range(3, last + 1):
        common = sols[k].linear
        for j in (k - 1, k - 2, k - 3):
            common = np.intersect1d(common, sols[j].linear)
        u = np.array([at(sols[j], common) for j in (k, k - 1, k - 2, k - 3)])
        u = u[:, np.all(np.isfinite(u), axis=0)]
        starts = {
            "previous": u[1],
            "linear": 2 * u[1] - u[2],
            "quadratic": 3 * u[1] - 3 * u[2] + u[3],
        }
        for name, start in starts.items():
            e = np.abs(start - u[0]) / tol
            print(
                f"step {k} {name:9s} median {np.median(e):8.2f} p99 {np.percentile(e, 99):9.1f} "
                f"largest {e.max():9.1f} above 10 tol {np.mean(e > 10):.2f}"
            )


if __name__ == "__main__":
    args = [int(a) for a in sys.argv[1:]]
    main(args[0] if args else 61, args[1] if len(args) > 1 else 7)
