"""Two sheets of a point cloud a few grid spacings apart: two concentric spheres sampled (radii 0.5
and 0.5 − gap, 40,000 samples on the outer one, as many per area on the inner one), the source on
the outer one, at N = 61 in [-1, 1]³ (h = 1/30). The band is cut across the narrow gaps that the
fits resolve (``PointCloudSurface.resolved_gap``: 5/3 of their radius, 5 spacings here;
``tubesweep._shortcuts``); before, the front crossed to the inner sphere and back, and the outer
sphere's distances came out short. Prints per gap, with the cut and without it (the class
attribute ``cuts_shortcuts`` switched off): the order run, the edges cut, the outer sphere's mean
and largest error against the great-circle distance and its share left unreached (inf), the
inner sphere's share reached (it has no source: inf is right), and whether the narrow-gap warning
came::

    .venv/bin/python benches/experiments/cloud_gaps.py            # about two minutes
    .venv/bin/python benches/experiments/cloud_gaps.py --gaps 3 7 --n 81
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

import tubesweep as ts
from tubesweep.surfaces.points import PointCloudSurface


def sphere_points(rng: np.random.Generator, n: int, r: float) -> np.ndarray:
    x = rng.normal(size=(n, 3))
    return r * x / np.linalg.norm(x, axis=1, keepdims=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--gaps", type=float, nargs="+", default=[2, 3, 4, 5, 6, 7, 8, 10], help="in grid spacings")
    ap.add_argument("--n", type=int, default=61)
    ap.add_argument("--samples", type=int, default=40000, help="on the outer sphere")
    args = ap.parse_args()
    h = 2.0 / (args.n - 1)
    grid = ts.Grid((-1.0,) * 3, (1.0,) * 3, (args.n,) * 3)
    source = np.array([0.0, 0.0, -0.5])
    print(f"N = {args.n}, h = {h:.4g}: gaps from 5 spacings are cut (5/3 of the fits' radius 3h)")
    print(
        "| gap (Δx) | cut | order | edges cut | outer mean / largest error | outer unreached | inner reached | warned |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for gap in args.gaps:
        rng = np.random.default_rng(1)
        outer = sphere_points(rng, args.samples, 0.5)
        inner = sphere_points(rng, int(args.samples * (1 - gap * h / 0.5) ** 2), 0.5 - gap * h)
        cloud = ts.surfaces.from_points(np.concatenate([outer, inner]))
        q_out, q_in = outer[:3000], inner[:3000]
        exact = 0.5 * np.arccos(np.clip(q_out @ source / 0.25, -1.0, 1.0))
        for cut in (True, False):
            PointCloudSurface.cuts_shortcuts = cut
            try:
                with warnings.catch_warnings(record=True) as caught:
                    warnings.simplefilter("always")
                    sol = ts.solve(cloud, grid, [source])
            finally:
                PointCloudSurface.cuts_shortcuts = True
            u = sol(q_out)
            fin = np.isfinite(u)
            err = np.abs(u[fin] - exact[fin])
            warned = any("faces itself" in str(w.message) for w in caught)
            print(
                f"| {gap:g} | {'yes' if cut else 'no'} | {sol.stats.order} | {sol.stats.cut_edges} | "
                f"{err.mean():.2e} / {err.max():.2e} | {np.mean(~fin):.1%} | {np.mean(np.isfinite(sol(q_in))):.1%} | "
                f"{'yes' if warned else 'no'} |"
            )


if __name__ == "__main__":
    main()
