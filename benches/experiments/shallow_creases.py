"""Creases whose faces meet at a shallow angle, in a φ given as it is (docs/second-order.md,
"Shallow creases"): two spheres of radius 0.5 cut by ``max`` (a lens) whose normals turn
by 40° or 60° at the rim, off the grid's symmetry by a small shift, the source at one cap's apex;
the error beyond the crease against the exact distance along the meridian, R·(2β − ψ), in grid
spacings, with what the solve reports (crease nodes, warnings). And regular polygons in 2D
(exact signed distances), whose corners turn by 360°/n::

    .venv/bin/python benches/experiments/shallow_creases.py            # about a minute
    .venv/bin/python benches/experiments/shallow_creases.py --n 61 81
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

import tubesweep as ts

R = 0.5
SHIFT = np.array((0.011, -0.007, 0.003))


def lens(turn: float, n: int, order: object) -> str:
    a = R * np.sin(np.radians(turn / 2))
    left, right = np.array([-a, 0, 0]) + SHIFT, np.array([a, 0, 0]) + SHIFT

    def phi(p: np.ndarray) -> np.ndarray:
        return np.maximum(np.linalg.norm(p - left, axis=1) - R, np.linalg.norm(p - right, axis=1) - R)

    beta = np.arccos(a / R)
    source = right - [R, 0, 0]  # the apex of the left cap (the right sphere's far point)
    rng = np.random.default_rng(0)
    psi = rng.uniform(0.15, beta - 0.08, 400)  # from the far cap's apex, away from it and the rim
    az = rng.uniform(0, 2 * np.pi, 400)
    points = left + R * np.c_[np.cos(psi), np.sin(psi) * np.cos(az), np.sin(psi) * np.sin(az)]
    exact = R * (2 * beta - psi)
    grid = ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = ts.solve(phi, grid, [source], order=order)
    err = (sol(points) - exact) / grid.spacing
    found = (sol.stats.order2 or {}).get("creases", {}).get("nodes") if sol.stats.order2 else None
    if found is None and sol.stats.creases:
        found = sol.stats.creases.get("nodes")
    warned = any("crease" in str(w.message) for w in caught)
    return (
        f"| lens, {turn:g}° | {n} | {order} | {sol.stats.order} | {np.mean(err):.2f} | {np.min(err):.2f} | "
        f"{found} | {'yes' if warned else 'no'} |"
    )


def polygon(sides: int, n: int) -> str:
    t = 0.1 + 2 * np.pi * np.arange(sides) / sides
    corners = np.c_[0.013 + 0.6 * np.cos(t), -0.007 + 0.6 * np.sin(t)]

    def phi(p: np.ndarray) -> np.ndarray:
        d = np.full(len(p), np.inf)
        inside = np.ones(len(p), bool)
        for i in range(sides):
            a, b = corners[i], corners[(i + 1) % sides]
            ab = b - a
            s = np.clip(((p - a) @ ab) / (ab @ ab), 0, 1)
            d = np.minimum(d, np.linalg.norm(p - (a + s[:, None] * ab), axis=1))
            inside &= ab[0] * (p[:, 1] - a[1]) - ab[1] * (p[:, 0] - a[0]) > 0
        return np.where(inside, -d, d)

    side = np.linalg.norm(corners[1] - corners[0])
    perimeter = sides * side

    def at(s: np.ndarray) -> np.ndarray:
        s = np.mod(s, perimeter)
        k = (s // side).astype(int) % sides
        u = (s - k * side) / side
        return corners[k] + u[:, None] * (corners[(k + 1) % sides] - corners[k])

    s0 = 0.37 * side
    s = np.random.default_rng(0).uniform(0, perimeter, 1000)
    exact = np.minimum(np.abs(s - s0), perimeter - np.abs(s - s0))
    keep = np.abs(exact - perimeter / 2) > 0.05  # away from the cut locus
    grid = ts.Grid((-1, -1), (1, 1), (n, n))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = ts.solve(phi, grid, [at(np.array([s0]))[0]])
    err = (sol(at(s[keep])) - exact[keep]) / grid.spacing
    found = (sol.stats.order2 or {}).get("creases", {}).get("nodes") if sol.stats.order2 else None
    warned = any("crease" in str(w.message) for w in caught)
    return (
        f"| {sides}-gon, {360 / sides:.0f}° | {n} | auto | {sol.stats.order} | {np.mean(err):.2f} | "
        f"{np.min(err):.2f} | {found} | {'yes' if warned else 'no'} |"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, nargs="+", default=[61, 81, 121], help="3D sizes (2D: 201 and 401)")
    args = ap.parse_args()
    print(
        "| surface, turn at the crease | N | order asked | ran | mean error (Δx) | worst (Δx) | crease nodes | warned |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for turn in (60.0, 40.0):
        for order in ("auto", 1):
            for n in args.n:
                print(lens(turn, n, order))
    for sides in (6, 8, 12):
        for n in (201, 401):
            print(polygon(sides, n))


if __name__ == "__main__":
    main()
