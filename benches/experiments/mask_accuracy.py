"""What a voxel mask allows (docs/surfaces.md, "From a voxel mask / a segmentation"): the sphere
R = 0.5 in [−1, 1]³ as a mask (r < R at the nodes), raw and Gaussian-smoothed (σ in voxels), solved
by default (``ts.solve(ts.LevelSet.from_mask(mask, grid, smooth=σ), grid, source)``, source
(−0.5, 0, 0) on the sphere); the mean error of the travel times along the meridian through the
source against the exact sphere's (0.5 θ), in units of Δx, the order ``auto`` ran, and the radius
of the mask's surface (the median of |x| − d over the band).

    .venv/bin/python benches/experiments/mask_accuracy.py [N ...]
"""

from __future__ import annotations

import sys
import warnings

import numpy as np

import tubesweep as ts


def main(ns) -> None:
    th = np.linspace(0, np.pi, 201)
    pts = 0.5 * np.stack([-np.cos(th), np.zeros_like(th), np.sin(th)], 1)
    for n in ns:
        grid = ts.Grid((-1.0,) * 3, (1.0,) * 3, (n,) * 3)
        X, Y, Z = grid.meshgrid()
        mask = X**2 + Y**2 + Z**2 < 0.25
        for sigma in (0.0, 1.0, 1.5):
            ls = ts.LevelSet.from_mask(mask, grid, smooth=sigma)
            geom = ls.band(grid, 2 * grid.spacing)
            radius = float(np.median(np.linalg.norm(grid.node_points(geom.linear), axis=1) - geom.signed))
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                sol = ts.solve(ls, grid, [(-0.5, 0.0, 0.0)])
            err = float(np.mean(np.abs(sol(pts) - 0.5 * th)))
            print(
                f"N={n:4d} smooth={sigma:3.1f}: mean error on the meridian {err:.3e} = {err / grid.spacing:.2f} Δx "
                f"(order {sol.stats.order}); the surface's radius {radius:.4f} (0.5 − σ²κ/2 = "
                f"{0.5 - (sigma * grid.spacing) ** 2 * 2:.4f})",
                flush=True,
            )


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [61, 121])
