"""Creases: how early a front arrives after crossing one, with the inner tube thinned at creases
(``order="auto"`` and 2: ``tubesweep_core::band::crease_ridges``) and without it (``order=1``, the
paper's scheme). docs/second-order.md, "What order=2 needs".

The cube max|x| − 0.5 on [−1, 1]³, source at the bottom centre: the top centre (exact 2.0, two
edges crossed) and the centre of a side face (exact 1.0, one edge), the shortcut per edge in grid
spacings; N odd puts nodes on the faces, N even a quarter spacing off them. The cube of
half-width 0.45 turned at random, the same path, against ``order=1``. Two spheres of radius
0.5 joined by ``min`` (centres 0 and 0.6: a concave crease circle, its normals 74° apart), source
(−0.5, 0, 0): the mean error on the far sphere's meridian up to 0.1 before the crease, against
the great-circle distance through the crease circle::

    .venv/bin/python benches/experiments/creases.py            # N = 40–121; under a minute
    .venv/bin/python benches/experiments/creases.py --quick    # N = 41
"""

from __future__ import annotations

import argparse
import math
import warnings

import numpy as np

import tubesweep as ts


def _solve(surface: ts.Surface, grid: ts.Grid, source: tuple, order: object) -> ts.Solution:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return ts.solve(surface, grid, [source], order=order)


def cube(sizes: list) -> None:
    print("the cube max|x| − 0.5, source at the bottom centre: shortcut per edge crossed")
    for n in sizes:
        g = ts.Grid((-1.0,) * 3, (1.0,) * 3, (n,) * 3)
        x, y, z = g.meshgrid()
        phi = np.maximum(np.maximum(np.abs(x), np.abs(y)), np.abs(z)) - 0.5
        row = []
        for order in ("auto", 1):
            sol = _solve(ts.LevelSet(phi), g, (0.0, 0.0, -0.5), order)
            top, side = sol([(0.0, 0.0, 0.5), (0.5, 0.0, 0.0)])
            row.append(
                f"{order!s:>4} (ran {sol.stats.order}): top {top:.4f}, {(2 - top) / 2 / g.spacing:5.2f}Δx per edge; "
                f"side {side:.4f}, {(1 - side) / g.spacing:5.2f}Δx"
            )
        print(f"  N = {n:3d}  " + "  |  ".join(row))


def rotated(sizes: list, turns: int) -> None:
    print("the cube max|q| − 0.45 turned at random (q = R x): shortcut per edge, bottom centre to top centre")
    rng = np.random.default_rng(1)
    for n in sizes:
        g = ts.Grid((-1.0,) * 3, (1.0,) * 3, (n,) * 3)
        x, y, z = g.meshgrid()
        for _ in range(turns):
            a, b = rng.uniform(0, 1.5), rng.uniform(0, 1.0)
            rz = np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])
            rx = np.array([[1, 0, 0], [0, math.cos(b), -math.sin(b)], [0, math.sin(b), math.cos(b)]])
            r = rx @ rz
            phi = np.max(np.abs(np.einsum("ij,j...->i...", r, np.stack([x, y, z]))), axis=0) - 0.45
            src, dst = r.T @ np.array([0, 0, -0.45]), r.T @ np.array([0, 0, 0.45])
            row = []
            for order in ("auto", 1):
                sol = _solve(ts.LevelSet(phi), g, tuple(src), order)
                row.append(f"{order!s:>4} (ran {sol.stats.order}): {(1.8 - sol([dst])[0]) / 2 / g.spacing:5.2f}Δx")
            print(f"  N = {n:3d}  turned by {a:.2f}, {b:.2f} rad:  " + "  |  ".join(row))


def _box(n: int, upper: tuple) -> ts.Grid:
    h = 2.0 / (n - 1)
    shape = tuple(int(round((u + 1.0) / h)) + 1 for u in upper)
    return ts.Grid((-1.0,) * 3, tuple(-1.0 + h * (s - 1) for s in shape), shape)


def two_spheres(sizes: list) -> None:
    print("two spheres joined by min: mean error (signed mean in Δx) on the far sphere")
    a = np.linspace(0.0, math.acos(0.6) - 0.1, 50)
    pts = np.c_[0.6 + 0.5 * np.cos(a), 0.5 * np.sin(a), 0 * a]
    ph = np.linspace(0.0, 2 * math.pi, 4001)
    crease = np.c_[0.3 + 0 * ph, 0.4 * np.cos(ph), 0.4 * np.sin(ph)]
    to_crease = 0.5 * np.arccos(np.clip(-crease[:, 0] / 0.5, -1, 1))
    exact = np.array(
        [
            np.min(to_crease + 0.5 * np.arccos(np.clip((crease - [0.6, 0, 0]) @ (p - [0.6, 0, 0]) / 0.25, -1, 1)))
            for p in pts
        ]
    )
    for n in sizes:
        g = _box(n, (1.6, 1.0, 1.0))
        x, y, z = g.meshgrid()
        phi = np.minimum(np.sqrt(x * x + y * y + z * z), np.sqrt((x - 0.6) ** 2 + y * y + z * z)) - 0.5
        row = []
        for order in ("auto", 1):
            e = _solve(ts.LevelSet(phi), g, (-0.5, 0.0, 0.0), order)(pts) - exact
            row.append(f"{order!s:>4}: {np.mean(np.abs(e)):.2e} ({np.mean(e) / g.spacing:+.2f}Δx)")
        print(f"  N = {n:3d}  " + "  |  ".join(row))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args()
    cube([41] if a.quick else [40, 41, 80, 81, 121])
    rotated([41] if a.quick else [41, 61, 81], 2 if a.quick else 4)
    two_spheres([61] if a.quick else [61, 81, 121])


if __name__ == "__main__":
    main()
