"""Noisy point clouds (scans): samples of a sphere of radius 0.6 (or its upper half, an open scan)
with Gaussian noise of a given share of the grid spacing, in [-1, 1]³, the source at the north
pole. Prints per case what ``from_points`` found (outliers, rim samples, the noise it measured
against the noise added), the fits' smoothing radius ρ the solve used
(``PointCloudSurface.smoothing_radius``), the order run, the time of ``from_points`` and of the
solve, the largest and median error against the great-circle distance (in grid spacings) at
3000 points of the exact sphere, and the warnings (their first words)::

    .venv/bin/python benches/experiments/noisy_clouds.py                 # about five minutes
    .venv/bin/python benches/experiments/noisy_clouds.py --n 61 --samples 20000 --noise 0.5 1
    .venv/bin/python benches/experiments/noisy_clouds.py --span 3 --n 61 --samples 20000 --noise 0.5

``--span S`` overrides the fits' reach in noises (``points.NOISE_SPAN``) to see what a narrower
or wider fit does.
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

import tubesweep as ts
from tubesweep.surfaces import points as cloud_module


def samples(rng: np.random.Generator, m: int, sigma: float, open_scan: bool) -> np.ndarray:
    p = rng.normal(size=(m, 3))
    if open_scan:
        p[:, 2] = np.abs(p[:, 2])
    p = 0.6 * p / np.linalg.norm(p, axis=1, keepdims=True)
    return p + sigma * rng.normal(size=p.shape)


def case(n: int, noise: float, m: int, open_scan: bool, seed: int) -> str:
    rng = np.random.default_rng(seed)
    h = 2.0 / (n - 1)
    grid = ts.Grid((-1.0,) * 3, (1.0,) * 3, (n,) * 3)
    p = samples(rng, m, noise * h, open_scan)
    label = f"{'half sphere' if open_scan else 'sphere'} N={n} noise={noise:g}h samples={m}"
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        t0 = time.perf_counter()
        try:
            cloud = ts.surfaces.from_points(p)
            t1 = time.perf_counter()
            sol = ts.solve(cloud, grid, [[0.0, 0.0, 0.6]])
        except ValueError as e:
            return f"{label}: refused: {str(e)[:160]}"
        t2 = time.perf_counter()
    q = rng.normal(size=(3000, 3))
    if open_scan:
        q[:, 2] = np.abs(q[:, 2])
    q = 0.6 * q / np.linalg.norm(q, axis=1, keepdims=True)
    e = np.abs(sol(q) - 0.6 * np.arccos(np.clip(q[:, 2] / 0.6, -1, 1))) / h
    r = cloud.report
    return (
        f"{label}: outliers {r['outliers']}, rim {r['rim_samples']}, noise measured "
        f"{cloud.noise / (noise * h) if noise else 0:.2f} of the added, rho {cloud.smoothing / h:.1f}h, "
        f"order {sol.stats.order}, from_points {t1 - t0:.1f} s, solve {t2 - t1:.1f} s, error max "
        f"{np.nanmax(e):.3f}h median {np.nanmedian(e):.3f}h; warnings: "
        + ("; ".join(str(w.message)[:48] for w in said) or "none")
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, nargs="+", default=[41, 81])
    ap.add_argument("--samples", type=int, nargs="+", default=[5000, 50000])
    ap.add_argument("--noise", type=float, nargs="+", default=[0, 0.1, 0.25, 0.5, 1.0], help="in grid spacings")
    ap.add_argument("--open", action="store_true", help="the upper half of the sphere (a scan with a rim)")
    ap.add_argument("--span", type=float, default=None, help="override points.NOISE_SPAN")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    if args.span is not None:
        cloud_module.NOISE_SPAN = args.span
    for n in args.n:
        for m in args.samples:
            for noise in args.noise:
                print(case(n, noise, m, args.open, args.seed), flush=True)


if __name__ == "__main__":
    main()
