"""The front window on the library's surfaces: the default sweeps with and without it, side by side.

For each surface of ``tubesweep.surfaces`` that has a default box and source, solves at N nodes per
axis with ``FRONT_WINDOW`` (``tubesweep/_validate.py``, read by ``ts.solve``) at 0 (off) and at its
default, the better of ``--repeats`` runs each, and prints iterations, local updates, sweep time
and the largest difference between the two solutions (the window changes the order of the
updates, not the fixed point). Curves (2D) are included: the window is off there, so both columns
agree.

    .venv/bin/python benches/experiments/front_window_surfaces.py [--n 121] [--repeats 2] [--windows 1,1.5,3]

``--windows`` compares other values of the constant with the window off (one line each).
"""

from __future__ import annotations

import argparse
import sys
import warnings
from typing import Optional, Sequence

import numpy as np

import tubesweep as ts
import tubesweep.surfaces as tss

NAMES = (
    "Sphere",
    "Ellipsoid",
    "Torus",
    "DoubleTorus",
    "RoundedCube",
    "Hemisphere",
    "MobiusBand",
    "PlanePatch",
    "Disc",
    "Circle",
    "Star",
)


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=121)
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--windows", help="comma-separated values of FRONT_WINDOW to compare (default: its default)")
    a = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    solve_module = sys.modules["tubesweep._first_order"]
    default = solve_module.FRONT_WINDOW
    windows = [float(w) for w in a.windows.split(",")] if a.windows else [default]
    print(
        f"N={a.n}, Godunov two-layer, default sweeps; window off → on (FRONT_WINDOW = "
        f"{', '.join(f'{w:g}' for w in windows)}; default {default:g}), best of {a.repeats}"
    )
    print(
        f"{'surface':12s} {'window':>6s} {'iters':>9s} {'updates':>21s} {'ratio':>6s} {'sweep ms':>13s} {'max |Δu|':>9s}"
    )
    try:
        for name in NAMES:
            surf = getattr(tss, name)()
            lo, hi = surf.default_box
            grid = ts.Grid(lo, hi, (a.n,) * len(lo))
            runs = []
            for w in [0.0] + windows:
                solve_module.FRONT_WINDOW = w
                best, sol = np.inf, None
                for _ in range(a.repeats):
                    sol = ts.solve(surf, grid, [surf.default_source], order=1)
                    best = min(best, sol.stats.seconds)
                assert sol is not None
                runs.append((sol, best))
            s0, t0 = runs[0]
            fin = np.isfinite(s0.values)
            for w, (s1, t1) in zip(windows, runs[1:]):
                diff = float(np.max(np.abs(s0.values[fin] - s1.values[fin]))) if fin.any() else 0.0
                print(
                    f"{name:12s} {w:6g} {s0.stats.iterations:4d}→{s1.stats.iterations:<4d} "
                    f"{s0.stats.updates:10,d}→{s1.stats.updates:<10,d} "
                    f"{s1.stats.updates / max(s0.stats.updates, 1):6.2f} {t0 * 1e3:6.0f}→{t1 * 1e3:<6.0f} {diff:9.1e}",
                    flush=True,
                )
    finally:
        solve_module.FRONT_WINDOW = default
    return 0


if __name__ == "__main__":
    sys.exit(main())
