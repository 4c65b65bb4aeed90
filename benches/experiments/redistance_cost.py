"""The cost of re-distancing a sampled φ against the solve that follows it (issue 43: at most half),
for the mask of the sphere R = 0.5 (raw and smoothed σ = 1.5 voxels) and the gyroid-like
φ = sin4x·cos4y + sin4y·cos4z + sin4z·cos4x in [−1, 1]³: the re-distanced band alone
(``LevelSet.band``), then the whole ``ts.solve`` (which re-distances again), default options; CPU
times of the process, all threads.

    .venv/bin/python benches/experiments/redistance_cost.py [N]
"""

from __future__ import annotations

import sys
import time
import warnings

import numpy as np

import tubesweep as ts


def main(n: int) -> None:
    grid = ts.Grid((-1.0,) * 3, (1.0,) * 3, (n,) * 3)
    X, Y, Z = grid.meshgrid()
    mask = X**2 + Y**2 + Z**2 < 0.25
    gyroid = np.sin(4 * X) * np.cos(4 * Y) + np.sin(4 * Y) * np.cos(4 * Z) + np.sin(4 * Z) * np.cos(4 * X)
    cases = [
        ("sphere mask", lambda: ts.LevelSet.from_mask(mask, grid), (-0.5, 0.0, 0.0)),
        ("sphere mask σ=1.5", lambda: ts.LevelSet.from_mask(mask, grid, smooth=1.5), (-0.5, 0.0, 0.0)),
        ("gyroid-like", lambda: ts.LevelSet(gyroid, redistance=True), None),
    ]
    for name, make, src in cases:
        ls = make()
        # CPU time of the process (all threads): a busy machine changes it far less than the wall
        # clock; the band twice, the faster kept
        t_band = float("inf")
        for _ in range(2):
            c0 = time.process_time()
            geom = ls.band(grid, 4 * grid.spacing)
            t_band = min(t_band, time.process_time() - c0)
        if src is None:  # a band node next to the zero set, nearest the centre
            x = grid.node_points(geom.linear)
            src = tuple(x[np.argmin(np.abs(geom.signed) + 1e-3 * np.linalg.norm(x, axis=1))])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            c0 = time.process_time()
            sol = ts.solve(ls, grid, [src])
            t_solve = time.process_time() - c0
        rest = t_solve - t_band
        print(
            f"N={n} {name:18s} band nodes {len(geom.linear)}: re-distancing {t_band:.2f} s CPU, the whole solve "
            f"{t_solve:.2f} s CPU (order {sol.stats.order}; sweeps {sol.stats.seconds:.2f} s wall): re-distancing / "
            f"the rest of the solve = {t_band / rest:.2f}",
            flush=True,
        )


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 201)
