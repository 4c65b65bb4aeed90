"""What a voxel mask allows (docs/surfaces.md, "From a voxel mask / a segmentation"): the sphere
R = 0.5 in [−1, 1]³ as a mask (r < R at the nodes), raw and Gaussian-smoothed (σ in voxels), solved
by default (``ts.solve(ts.LevelSet.from_mask(mask, grid, smooth=σ), grid, source)``, source
(−0.5, 0, 0) on the sphere); the mean error of the travel times along the meridian through the
source against the exact sphere's (0.5 θ), in units of Δx, the order ``auto`` ran, and the radius
of the mask's surface (the median of |x| − d over the band). With ``--2d``, the circle R = 0.5 in
[−1, 1]² instead, source (0.5, 0), the mean error over the circle against its arclength, as a share
of the largest distance (π/2): a fixed σ in voxels leaves ripples of the voxels' size, and the
errors level off on fine grids.

    .venv/bin/python benches/experiments/mask_accuracy.py [N ...]
    .venv/bin/python benches/experiments/mask_accuracy.py --2d [N ...]
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


def main_2d(ns) -> None:
    th = np.linspace(0, 2 * np.pi, 2000, endpoint=False)
    pts = 0.5 * np.c_[np.cos(th), np.sin(th)]
    exact = 0.5 * np.minimum(th, 2 * np.pi - th)
    for n in ns:
        grid = ts.Grid((-1.0,) * 2, (1.0,) * 2, (n,) * 2)
        X, Y = grid.meshgrid()
        mask = X**2 + Y**2 < 0.25
        for sigma in (0.0, 1.0, 1.5):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                sol = ts.solve(ts.LevelSet.from_mask(mask, grid, smooth=sigma), grid, [(0.5, 0.0)])
            err = float(np.mean(np.abs(sol(pts) - exact)))
            print(
                f"N={n:4d} smooth={sigma:3.1f}: mean error on the circle {err:.3e} = {err / grid.spacing:.2f} Δx = "
                f"{100 * err / (0.5 * np.pi):.3f} % of π/2 (order {sol.stats.order})",
                flush=True,
            )


if __name__ == "__main__":
    args = sys.argv[1:]
    if args[:1] == ["--2d"]:
        main_2d([int(a) for a in args[1:]] or [101, 201, 401])
    else:
        main([int(a) for a in args] or [61, 121])
