"""What the re-distancing's settling tolerance changes in the solve (docs/development/history-notes.md,
"settling at 1e-10, 1e-9 or 1e-8"): ``redistance.REFINE_SETTLED`` set to 1e-12 (the default), 1e-10,
1e-9 and 1e-8 for ``|x|² − 0.25`` and the ellipsoid quadric (``redistance=True``) and the sphere's
mask smoothed with σ = 1.5 voxels, solved by default from a pole; printed per tolerance: the mean
error on a meridian against the sphere's 0.5·θ (the ellipsoid: the mean of ``u`` there, its change
the only figure) and the order that ran.

    .venv/bin/python benches/experiments/redistance_settling.py [N ...]   # 61 121
"""

from __future__ import annotations

import sys
import warnings

import numpy as np

import tubesweep as ts
import tubesweep.redistance as rd

TOLERANCES = (1e-12, 1e-10, 1e-9, 1e-8)


def main(ns) -> None:
    th = np.linspace(0.05, np.pi - 0.05, 200)
    meridian = np.c_[0.5 * np.sin(th), 0 * th, 0.5 * np.cos(th)]
    default = rd.REFINE_SETTLED
    for n in ns:
        grid = ts.Grid((-1.0,) * 3, (1.0,) * 3, (n,) * 3)
        X, Y, Z = grid.meshgrid()
        cases = {
            "|x|²−R²": (ts.LevelSet(X**2 + Y**2 + Z**2 - 0.25, redistance=True), (0.0, 0.0, 0.5)),
            "ellipsoid": (
                ts.LevelSet((X / 0.6) ** 2 + (Y / 0.5) ** 2 + (Z / 0.4) ** 2 - 1, redistance=True),
                (0.0, 0.0, 0.4),
            ),
            "mask σ=1.5": (ts.LevelSet.from_mask(X**2 + Y**2 + Z**2 < 0.25, grid, smooth=1.5), (0.0, 0.0, 0.5)),
        }
        for name, (ls, source) in cases.items():
            row = []
            try:
                for tol in TOLERANCES:
                    rd.REFINE_SETTLED = tol
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        sol = ts.solve(ls, grid, [source])
                    u = sol(meridian)
                    figure = float(np.nanmean(u)) if name == "ellipsoid" else float(np.mean(np.abs(u - 0.5 * th)))
                    row.append(f"{tol:g}: {figure:.6e} (order {sol.stats.order})")
            finally:
                rd.REFINE_SETTLED = default
            print(f"N={n} {name:11s} " + "  ".join(row))


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [61, 121])
