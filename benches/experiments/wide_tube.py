"""An inner tube wider than the paper's at first order (``order=1`` with ``inner`` above 2): how
much shorter the distances come out, against what ``sol.stats.tube_shortcut`` (and its warning,
``tubesweep._wide_tube``) estimates. The largest error relative to the largest distance, at 2,000
points on the surface, against the second-order solve on the same grid (``order=2``, the default
tube; its own errors are about 1e-4 of the distances here)::

    .venv/bin/python benches/experiments/wide_tube.py            # N = 61 (2D 201); about a minute
    .venv/bin/python benches/experiments/wide_tube.py --n 81
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

import tubesweep as ts


def surface_points(surface: ts.Surface, grid: ts.Grid, count: int, seed: int = 0) -> np.ndarray:
    """``count`` points on the surface: random points of the box projected onto it, kept where
    they lay within a few spacings of it."""
    rng = np.random.default_rng(seed)
    lo, hi = np.asarray(grid.lower, float), np.asarray(grid.upper, float)
    found: list = []
    while sum(len(f) for f in found) < count:
        x = lo + (hi - lo) * rng.random((20 * count, grid.ndim))
        phi = np.abs(surface.phi(x, grid)) if hasattr(surface, "phi") else None
        if phi is not None:
            x = x[phi < 3 * grid.spacing]
        if len(x) == 0:
            continue
        distance, closest = surface.project(x, grid)
        found.append(closest[distance < 3 * grid.spacing])
    return np.concatenate(found)[:count]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=61, help="nodes per axis in 3D (2D: 201 and above: 3.3 N)")
    ap.add_argument("--inner", default="2,3,4,8")
    args = ap.parse_args()
    n2 = max(201, int(3.3 * args.n))
    cases = [
        ("sphere r = 0.5", ts.surfaces.Sphere(0.5), 3),
        ("sphere r = 0.3", ts.surfaces.Sphere(0.3), 3),
        ("ellipsoid", ts.surfaces.Ellipsoid(), 3),
        ("torus", ts.surfaces.Torus(), 3),
        ("hemisphere (open)", ts.surfaces.Hemisphere(), 3),
        ("plane patch (flat)", ts.surfaces.PlanePatch(), 3),
        ("circle", ts.surfaces.Circle(), 2),
        ("star", ts.surfaces.Star(), 2),
    ]
    print("| surface | N | inner | measured | sol.stats.tube_shortcut | warned |")
    print("|---|---|---|---|---|---|")
    for name, surface, d in cases:
        n = args.n if d == 3 else n2
        grid = ts.Grid((-1.0,) * d, (1.0,) * d, (n,) * d)
        source = surface.default_source
        points = surface_points(surface, grid, 2000)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            reference = ts.solve(surface, grid, [source], order=2)(points)
        scale = float(np.max(reference[np.isfinite(reference)]))
        for inner in (float(v) for v in args.inner.split(",")):
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                sol = ts.solve(surface, grid, [source], order=1, inner=inner, outer=inner + 2)
            err = np.abs(sol(points) - reference)
            warned = any("cuts through it on the inside of the bend" in str(w.message) for w in caught)
            est = sol.stats.tube_shortcut
            print(
                f"| {name} | {n} | {inner:g} | {np.max(err[np.isfinite(err)]) / scale:.3f} | "
                f"{'—' if est is None else f'{est:.3f}'} | {'yes' if warned else 'no'} |"
            )


if __name__ == "__main__":
    main()
