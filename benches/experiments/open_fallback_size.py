"""How large ``order="auto"``'s first-order fallback's errors are on open surfaces, against what
its warning says (``python/tubesweep/_fallback.py``, ``OPEN_BEND``; ``_curvature.concave_curvature``).

Per case: the order that ran, the largest error over points of the surface as a share of the
largest distance (too short and too long), and the share the warning states (— where it did not
warn). The hemisphere of radius 0.5 (analytic and as a cloud) from its pole, a sphere cloud with a
stray flat patch far off (the patch's rim makes the cloud open), a sphere cloud with a hole, a
cloud of the cow Spot (40,000 samples of ``ts.data.spot()``) with its top tenth cut off, against
its own second-order solve at N = 161 (half a minute; with trimesh), and flat plane patches and
discs from their centres (their first-order errors are a few per cent and no bend is stated)::

    .venv/bin/python benches/experiments/open_fallback_size.py
"""

from __future__ import annotations

import re
import warnings

import numpy as np

import tubesweep as ts

R = 0.5
POLE = np.array([0.0, 0.0, R])


def fibonacci(n: int) -> np.ndarray:
    i = np.arange(n) + 0.5
    polar, turn = np.arccos(1 - 2 * i / n), np.pi * (1 + 5**0.5) * i
    return R * np.c_[np.cos(turn) * np.sin(polar), np.sin(turn) * np.sin(polar), np.cos(polar)]


def box(a: float, b: float, h: float) -> ts.Grid:
    n = int(round((b - a) / h)) + 1
    return ts.Grid([a] * 3, [a + (n - 1) * h] * 3, [n] * 3)


def row(name: str, surface, grid: ts.Grid, points: np.ndarray, exact: np.ndarray, source) -> None:
    exact = np.asarray(exact, dtype=float)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            sol = ts.solve(surface, grid, [source])
        except ValueError as e:
            print(f"{name:24s} Δx = {grid.spacing:.3f}  refused: {str(e)[:70]}")
            return
    u = sol(points)
    ok = np.isfinite(u)
    ok &= np.isfinite(exact)
    off = (exact[ok] - u[ok]) / exact[ok].max()
    said = "—"
    for w in caught:
        m = re.search(r"errors of roughly (\d+)% of the distances", str(w.message))
        said = m.group(1) + "%" if m else said
    print(
        f"{name:24s} Δx = {grid.spacing:.3f}  order {sol.stats.order}  short {100 * off.max():5.1f}%  "
        f"long {100 * -off.min():5.1f}%  said {said}"
    )


def main() -> None:
    on_sphere = fibonacci(500)
    great_circle = R * np.arccos(np.clip(on_sphere @ POLE / R**2, -1, 1))
    upper = on_sphere[:, 2] > 0.05
    cap = fibonacci(4000)
    cap = ts.surfaces.from_points(cap[cap[:, 2] > 0])
    for h in (0.2, 0.15, 0.12):
        for name, surface in (("hemisphere", ts.surfaces.Hemisphere()), ("hemisphere cloud", cap)):
            row(name, surface, box(-0.5 - 4 * h, 0.5 + 4 * h, h), on_sphere[upper], great_circle[upper], POLE)
    patch = np.c_[np.random.default_rng(0).uniform(-0.1, 0.1, (60, 2)), np.zeros(60)] + [2.0, 0, 0]
    stray = ts.surfaces.from_points(np.r_[fibonacci(2000), patch])
    for n in (25, 31, 41):
        row("sphere + stray patch", stray, stray.grid(n), on_sphere, great_circle, POLE)
    holed = fibonacci(3000)
    holed = ts.surfaces.from_points(holed[holed[:, 0] < 0.4])
    kept = on_sphere[:, 0] < 0.35
    for n in (15, 19, 23):
        row("sphere with a hole", holed, holed.grid(n, padding=4), on_sphere[kept], great_circle[kept], POLE)
    spot_with_a_hole()
    for surface, size in (
        (ts.surfaces.PlanePatch(half_size=0.25), 0.25),
        (ts.surfaces.PlanePatch(half_size=0.4), 0.4),
        (ts.surfaces.Disc(radius=0.3), 0.3 / np.sqrt(2)),
    ):
        t = np.linspace(-size, size, 21)
        x, y = np.meshgrid(t, t)
        points = np.c_[x.ravel(), y.ravel(), 0 * x.ravel()]
        points = points[np.linalg.norm(points, axis=1) > 1e-9]
        row(type(surface).__name__, surface, box(-0.6, 0.6, 0.1), points, np.linalg.norm(points, axis=1), (0, 0, 0))


def spot_with_a_hole() -> None:
    try:
        import trimesh
    except ImportError:
        print("Spot: needs trimesh")
        return
    mesh = ts.surfaces.from_mesh(ts.data.spot())
    samples = trimesh.sample.sample_surface_even(
        trimesh.Trimesh(mesh.vertices, mesh.faces, process=False), 40000, seed=0
    )[0]
    samples = samples[samples[:, 1] < np.quantile(samples[:, 1], 0.9)]
    cloud = ts.surfaces.from_points(samples)
    points, source = samples[::50], samples[0]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (the fine solve's narrow gaps at the cow's legs)
        reference = ts.solve(cloud, cloud.grid(161), [source])(points)
    for n in (31, 41, 61):
        row("Spot cloud with a hole", cloud, cloud.grid(n), points, reference, source)


if __name__ == "__main__":
    main()
