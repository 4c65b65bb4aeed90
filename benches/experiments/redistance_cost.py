"""The cost of re-distancing a sampled φ against the solve that follows it (issue 43: at most half),
for the mask of the sphere R = 0.5 (raw and smoothed σ = 1.5 voxels), the sphere's ``|x|² − R²`` and
the gyroid-like φ = sin4x·cos4y + sin4y·cos4z + sin4z·cos4x in [−1, 1]³, ``redistance=True``.

Per case, interleaved in one process (band, solve, band, solve, …; medians): the re-distanced band
alone (``LevelSet.band`` with the default outer width, 4Δx), then the whole ``ts.solve`` with
default options (which re-distances again); "the rest" is the solve less the band. Printed: the
wall-clock medians and their ratio, and the same for the CPU time of the process (all threads),
which a busy machine changes less.

    .venv/bin/python benches/experiments/redistance_cost.py [N ...] [--repeats R]   # default 101 201, R = 5
"""

from __future__ import annotations

import sys
import time
import warnings

import numpy as np

import tubesweep as ts


def _cases(grid):
    X, Y, Z = grid.meshgrid()
    mask = X**2 + Y**2 + Z**2 < 0.25
    yield "sphere mask", ts.LevelSet.from_mask(mask, grid)
    yield "sphere mask σ=1.5", ts.LevelSet.from_mask(mask, grid, smooth=1.5)
    yield "|x|²−R²", ts.LevelSet(X**2 + Y**2 + Z**2 - 0.25, redistance=True)
    gyroid = np.sin(4 * X) * np.cos(4 * Y) + np.sin(4 * Y) * np.cos(4 * Z) + np.sin(4 * Z) * np.cos(4 * X)
    yield "gyroid-like", ts.LevelSet(gyroid, redistance=True)


def _timed(f):
    w, c = time.perf_counter(), time.process_time()
    out = f()
    return out, time.perf_counter() - w, time.process_time() - c


def main(ns, repeats: int) -> None:
    for n in ns:
        grid = ts.Grid((-1.0,) * 3, (1.0,) * 3, (n,) * 3)
        for name, ls in _cases(grid):
            geom = ls.band(grid, 4 * grid.spacing)
            # the source: a band node next to the zero set, nearest (−0.5, 0, 0)
            x = grid.node_points(geom.linear)
            src = tuple(x[np.argmin(np.abs(geom.signed) + 1e-3 * np.linalg.norm(x - [-0.5, 0.0, 0.0], axis=1))])
            band_w, band_c, solve_w, solve_c = [], [], [], []
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                ts.solve(ls, grid, [src])  # untimed: the allocator, the threads
                for _ in range(repeats):
                    _, w, c = _timed(lambda: ls.band(grid, 4 * grid.spacing))
                    band_w.append(w)
                    band_c.append(c)
                    sol, w, c = _timed(lambda: ts.solve(ls, grid, [src]))
                    solve_w.append(w)
                    solve_c.append(c)
            bw, bc = float(np.median(band_w)), float(np.median(band_c))
            rw, rc = float(np.median(solve_w)) - bw, float(np.median(solve_c)) - bc
            print(
                f"N={n} {name:18s} band nodes {len(geom.linear):8d} (order {sol.stats.order}): re-distancing "
                f"{bw:.3f} s, the rest of the solve {rw:.3f} s: ratio {bw / rw:.2f} (CPU: {bc:.3f} s / {rc:.3f} s = "
                f"{bc / rc:.2f})",
                flush=True,
            )


if __name__ == "__main__":
    args = sys.argv[1:]
    repeats = 5
    if "--repeats" in args:
        i = args.index("--repeats")
        repeats = int(args[i + 1])
        args = args[:i] + args[i + 2 :]
    main([int(a) for a in args] or [101, 201], repeats)
