"""Where the two-layer sweeps still spend their iterations, over the whole band (docs/development/
performance-history.md, "What still makes iterations grow with N"): the front window (which exploits
what this shows) is switched off here.

1. The residual after k iterations by angle from the source on the sphere: the difference from
   the converged solution (tol 1e-12) after 3, 5 and 7 iterations, largest per 20° band.
2. Iterations against N on a tilted plane (no curvature) for the two-layer tube, the naive tube
   (no extension layer) and the paper's plain sweeps.

    .venv/bin/python benches/experiments/convergence_front.py [--n 201]
"""

from __future__ import annotations

import argparse
import sys
import warnings
from typing import Optional, Sequence

import numpy as np

import tubesweep as ts


def whole_band_sweeps() -> None:
    """Switches the front window off (``FRONT_WINDOW`` of ``tubesweep/_validate.py``, read by
    ``ts.solve``) for the rest of this process."""
    sys.modules["tubesweep._first_order"].FRONT_WINDOW = 0.0  # type: ignore[attr-defined]


def residual_by_angle(n: int) -> None:
    warnings.simplefilter("ignore")
    g = ts.Grid((-1, -1, -1), (1, 1, 1), (n, n, n))
    sphere = ts.surfaces.Sphere(0.5)
    final = ts.solve(sphere, g, [(-0.5, 0, 0)], tol=1e-12, order=1)
    x = final.points
    ang = np.degrees(np.arccos(np.clip(-x[:, 0] / np.linalg.norm(x, axis=1), -1, 1)))
    print(f"sphere N={n}: largest |u_k − u| after k iterations, per angle from the source")
    print("   k " + " ".join(f"{a:>3d}–{a + 20:<3d}" for a in range(0, 180, 20)))
    for k in (3, 5, 7):
        s = ts.solve(sphere, g, [(-0.5, 0, 0)], max_iterations=k, tol=1e-12, order=1)
        d = s.values - final.values
        print(f"  {k:2d} " + " ".join(f"{d[(ang >= a) & (ang < a + 20)].max():7.0e}" for a in range(0, 180, 20)))


def tilted_plane(sizes: Sequence[int]) -> None:
    warnings.simplefilter("ignore")
    normal = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
    print("tilted plane φ = x·(1,2,3)/√14: iterations")
    print(f"{'N':>5} {'two-layer':>10} {'naive':>6} {'paper sweeps':>13}")
    for n in sizes:
        g = ts.Grid((-1, -1, -1), (1, 1, 1), (n, n, n))
        its = [
            ts.solve(lambda p: p @ normal, g, [(0, 0, 0)], **kw, order=1).stats.iterations
            for kw in ({}, {"method": "naive"}, {"paper_sweeps": True})
        ]
        print(f"{n:5d} {its[0]:10d} {its[1]:6d} {its[2]:13d}")


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(description="where the sweeps spend their iterations")
    ap.add_argument("--n", type=int, default=201, help="sphere grid size for the residual table")
    a = ap.parse_args(argv)
    whole_band_sweeps()
    residual_by_angle(a.n)
    tilted_plane((101, 201))
    return 0


if __name__ == "__main__":
    sys.exit(main())
