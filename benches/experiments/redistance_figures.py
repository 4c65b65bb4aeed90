"""Order-2 figures of re-distanced smooth level sets (not distances), the command behind issue 43's
"nothing regresses on smooth inputs": a sphere |x|² − R², an ellipsoid quadric and a torus quartic,
sampled on the grid, ``LevelSet(phi, redistance=True)``, ``order=2``; errors against the library
surfaces' exact geodesic distances (the ellipsoid against the library ellipsoid's own order-2
solution at the same N, which has no closed form), and the time of the re-distanced band alone.

First, per N, the band of the sphere's |x|² − R² itself: the largest and the mean error of its
signed distances against |x| − R, in Δx, and the same for the projection from each node
(``tubesweep.redistance._project``: Newton steps and orthogonality iterations with the central
differences' normal), and how far apart the two are; and the CPU time of the band against that
of the projection of the band's nodes alone (the path arrays took before the sub-cell
re-distancing, which projected a few more candidates besides), interleaved, medians of 3.

    .venv/bin/python benches/experiments/redistance_figures.py [N ...]
"""

from __future__ import annotations

import sys
import time
import warnings

import numpy as np

import tubesweep as ts


def cases(grid):
    X, Y, Z = grid.meshgrid()
    yield "sphere |x|²−R²", X**2 + Y**2 + Z**2 - 0.25, ts.surfaces.Sphere(0.5), (-0.5, 0.0, 0.0)
    ell = ts.surfaces.Ellipsoid()
    a, b, c = ell.axes
    yield "ellipsoid quadric", (X / a) ** 2 + (Y / b) ** 2 + (Z / c) ** 2 - 1, ell, (a, 0.0, 0.0)
    tor = ts.surfaces.Torus()
    q = (np.hypot(X, Y) - tor.R) ** 2 + Z**2 - tor.r**2
    yield "torus quartic", q, tor, (tor.R + tor.r, 0.0, 0.0)


def band_figures(grid):
    from tubesweep.redistance import _project

    X, Y, Z = grid.meshgrid()
    ls = ts.LevelSet(X**2 + Y**2 + Z**2 - 0.25, redistance=True)
    geom = ls.band(grid, 4 * grid.spacing)
    x = grid.node_points(geom.linear)
    exact = np.linalg.norm(x, axis=1) - 0.5
    _, projected, ok = _project(ls, grid, x, 300)
    t_band, t_proj = [], []
    for _ in range(3):
        c = time.process_time()
        ls.band(grid, 4 * grid.spacing)
        t_band.append(time.process_time() - c)
        c = time.process_time()
        _project(ls, grid, x)
        t_proj.append(time.process_time() - c)
    err = np.abs(geom.signed - exact) / grid.spacing
    ref = np.abs(projected - exact)[ok] / grid.spacing
    apart = np.abs(geom.signed - projected)[ok] / grid.spacing
    print(
        f"N={grid.shape[0]:4d} band of |x|²−R²: error max {err.max():.4f} mean {err.mean():.4f} Δx; the projection from "
        f"the node: max {ref.max():.4f} mean {ref.mean():.4f} Δx; apart max {apart.max():.4f} mean {apart.mean():.5f} Δx; "
        f"CPU: band {np.median(t_band):.3f} s, projection of its nodes {np.median(t_proj):.3f} s",
        flush=True,
    )


def main(ns):
    for n in ns:
        grid = ts.Grid((-1.0,) * 3, (1.0,) * 3, (n,) * 3)
        band_figures(grid)
        for name, phi, exact, src in cases(grid):
            V, _ = exact.triangulation(40)
            ls = ts.LevelSet(phi, redistance=True)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                t0 = time.perf_counter()
                ls.band(grid, 4 * grid.spacing)
                t_band = time.perf_counter() - t0
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                t0 = time.perf_counter()
                try:
                    sol = ts.solve(ls, grid, [src], order=2)
                except ValueError as e:
                    print(f"N={n:4d} {name:18s} order=2 refused: {str(e)[:100]}")
                    sol = ts.solve(ls, grid, [src])
                t_solve = time.perf_counter() - t0
            if hasattr(exact, "geodesic_distance"):
                ref = exact.geodesic_distance(V, src)
            else:
                ref = ts.solve(exact, grid, [src], order=2)(V)
            err = np.abs(sol(V) - ref)
            err = err[np.isfinite(err)]
            print(
                f"N={n:4d} {name:18s} order={sol.stats.order} mean={np.mean(err):.4e} max={np.max(err):.4e} "
                f"band {t_band:.2f} s, solve {t_solve:.2f} s",
                flush=True,
            )


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [61, 81, 121])
