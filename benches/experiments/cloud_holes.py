"""Holes in a point cloud (python/tubesweep/surfaces/_cloud_holes.py): a sphere of radius 0.6
sampled 40,000 times with three holes of radius ``--radius`` cut at (0.6, 0, 0), (0, 0.6, 0) and
(0, 0, −0.6), the source at the north pole, in [-1, 1]³. Per N, with the hole test and without it
(``PointCloudSurface._pairs_over_holes`` switched off): the order run, the facing pairs left, the
edges cut, the holes reported (``sol.stats.bridged_holes``), whether the narrow-gap warning came,
and the errors of ``sol(samples)`` against the great-circle distance within 0.08 of a hole's rim
and elsewhere (the holes shorten no great circle from the pole by more than their detour).

Then the gaps that must stay gaps (each warned, none reported as a hole), at N = 61: a slit in
the sphere, a notch in a plate's outline, a cylinder slit along its length (a C), two parallel
plates 0.1 apart with aligned holes, two small patches side by side; and a plate with one small
hole (reported, not warned)::

    .venv/bin/python benches/experiments/cloud_holes.py               # about 20 s
    .venv/bin/python benches/experiments/cloud_holes.py --n 61 --radius 0.1
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

import tubesweep as ts
from tubesweep.surfaces.points import PointCloudSurface

CENTRES = np.array([(0.6, 0, 0), (0, 0.6, 0), (0, 0, -0.6)])


def holed_sphere(radius: float, samples: int = 40000, seed: int = 1) -> np.ndarray:
    x = np.random.default_rng(seed).normal(size=(samples, 3))
    x = 0.6 * x / np.linalg.norm(x, axis=1, keepdims=True)
    return x[np.min(np.linalg.norm(x[:, None] - CENTRES[None], axis=2), axis=1) > radius]


def solve(points: np.ndarray, n: int, source: np.ndarray, lo: float = -1.0, hi: float = 1.0):
    cloud = ts.surfaces.from_points(points)
    grid = ts.Grid((lo,) * 3, (hi,) * 3, (n,) * 3)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = ts.solve(cloud, grid, [source])
    gap_warned = any("faces itself across gaps" in str(w.message) for w in caught)
    hole_warned = any("hole(s) narrower than its band" in str(w.message) for w in caught)
    return sol, gap_warned, hole_warned


def holes_text(sol) -> str:
    b = sol.stats.bridged_holes
    return "—" if b is None else f"{b['count']} (widest {b['widest']:.3f}, detour {b['detour']:.3f})"


def sphere(ns: list, radius: float) -> None:
    pts = holed_sphere(radius)
    source = np.array([0.0, 0.0, 0.6])
    q = pts[:: max(len(pts) // 6000, 1)]
    exact = 0.6 * np.arccos(np.clip(q @ source / 0.36, -1.0, 1.0))
    near = np.min(np.linalg.norm(q[:, None] - CENTRES[None], axis=2), axis=1) < radius + 0.08
    print(f"sphere r = 0.6, {len(pts)} samples, three holes {2 * radius:.3g} wide")
    print("| N | hole test | order | facing pairs | edges cut | holes reported | gap warning | near a hole: mean / largest | elsewhere: mean / largest |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|")
    for n in ns:
        for on in (True, False):
            hook = PointCloudSurface._pairs_over_holes
            if not on:
                PointCloudSurface._pairs_over_holes = None  # type: ignore[assignment]
            try:
                sol, gap_warned, _ = solve(pts, n, source)
            finally:
                PointCloudSurface._pairs_over_holes = hook  # type: ignore[method-assign]
            err = np.abs(sol(q) - exact)
            print(f"| {n} | {'on' if on else 'off'} | {sol.stats.order} | {sol.stats.facing_pairs} | "
                  f"{sol.stats.cut_edges} | {holes_text(sol)} | {'yes' if gap_warned else 'no'} | "
                  f"{err[near].mean():.2e} / {err[near].max():.2e} | {err[~near].mean():.2e} / {err[~near].max():.2e} |")  # fmt: skip


def gaps() -> None:
    rng = np.random.default_rng(3)
    x = rng.normal(size=(60000, 3))
    x = 0.6 * x / np.linalg.norm(x, axis=1, keepdims=True)
    plate = rng.uniform(-0.6, 0.6, size=(40000, 3))
    plate[:, 2] = 0.0
    t, z = rng.uniform(0.15, 2 * np.pi - 0.15, 40000), rng.uniform(-0.6, 0.6, 40000)
    double = rng.uniform(-0.5, 0.5, size=(40000, 3))
    double[:20000, 2], double[20000:, 2] = 0.05, -0.05
    patch = rng.uniform(-0.1, 0.1, size=(4000, 3))
    patch[:, 2] = 0.0
    cases = [
        (
            "a slit 0.08 wide, 0.6 long, in the sphere",
            x[~((np.abs(x[:, 1]) < 0.04) & (x[:, 0] > 0) & (np.abs(x[:, 2]) < 0.3))],
            1.0,
        ),  # fmt: skip
        ("a notch 0.08 wide in a plate's outline", plate[~((np.abs(plate[:, 0]) < 0.04) & (plate[:, 1] > 0.3))], 1.0),
        ("a cylinder slit along its length (0.15 wide)", np.c_[0.5 * np.cos(t), 0.5 * np.sin(t), z], 1.0),
        ("two plates 0.1 apart, aligned holes 0.12 wide", double[np.hypot(double[:, 0], double[:, 1]) > 0.06], 1.0),
        ("two patches 0.08 apart", np.r_[patch, patch + [0.28, 0.0, 0.0]], 0.5),
        ("a plate with a hole 0.12 wide (a hole)", plate[np.hypot(plate[:, 0], plate[:, 1]) > 0.06], 1.0),
    ]
    print("\nat N = 61:")
    print("| cloud | facing pairs | holes reported | gap warning | hole warning |")
    print("|---|---|---|---|---|")
    for name, pts, half in cases:
        sol, gap_warned, hole_warned = solve(pts, 61, pts[0], -half, half)
        print(f"| {name} | {sol.stats.facing_pairs} | {holes_text(sol)} | {'yes' if gap_warned else 'no'} | "
              f"{'yes' if hole_warned else 'no'} |")  # fmt: skip


def curves() -> None:
    """A C-shaped curve (a circle of radius 0.5 less an arc, the source at one end): whether its
    ends are seen (rim samples), the far end's value against the way round, and the warnings."""
    print("\nC-shaped curves, the source at one end:")
    print("| samples | gap (sample spacings) | N | gap (grid spacings) | ends seen | far end / way round | warned |")
    print("|---|---|---|---|---|---|---|")
    for samples, gap, n in ((4000, 0.01, 121), (4000, 0.03, 121), (4000, 0.04, 121), (1000, 0.02, 121), (1000, 0.03, 81), (4000, 0.1, 161)):  # fmt: skip
        a = np.arcsin(gap)
        t = np.linspace(a, 2 * np.pi - a, samples)
        pts = 0.5 * np.c_[np.cos(t), np.sin(t)]
        cloud = ts.surfaces.from_points(pts)
        grid = ts.Grid((-1.0, -1.0), (1.0, 1.0), (n, n))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            sol = ts.solve(cloud, grid, [pts[0]])
        way_round = 0.5 * (2 * np.pi - 2 * a)
        spacing = 0.5 * (2 * np.pi - 2 * a) / (samples - 1)
        names = sorted({"ends" if "two ends" in str(w.message) else "gap" if "faces itself" in str(w.message) else "other" for w in caught})  # fmt: skip
        print(f"| {samples} | {gap / spacing:.0f} | {n} | {gap / grid.spacing:.1f} | {len(cloud.rim)} | "
              f"{float(sol(pts[-1:])[0]):.4f} / {way_round:.4f} | {', '.join(names) or 'no'} |")  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, nargs="+", default=[41, 61, 81, 101])
    ap.add_argument("--radius", type=float, default=0.05, help="the holes' radius")
    args = ap.parse_args()
    sphere(args.n, args.radius)
    gaps()
    curves()


if __name__ == "__main__":
    main()
