"""Warm starts with several sources (docs/moving-surfaces.md, "The cold solve's values"): the
sphere of radius 0.5 grown by 0.3 grid spacings, K random sources moved with it (seed 1), solved
warm from the previous step and cold, and cold at a hundredth of the tolerance (the fixed point
the stopping rule approximates). Prints, in stopping tolerances over the inner tube, how far the
warm solve is from the cold one and each from the tight one::

    .venv/bin/python benches/experiments/warm_many_sources.py            # N = 41 and 61, a minute
    .venv/bin/python benches/experiments/warm_many_sources.py --n 41
"""

from __future__ import annotations

import argparse

import numpy as np

import tubesweep as ts


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, nargs="+", default=[41, 61], help="nodes per axis")
    ap.add_argument("--sources", type=int, nargs="+", default=[1, 2, 5, 10, 20, 200])
    args = ap.parse_args()
    print("| N | sources | warm − cold | cold − tight | warm − tight |")
    print("|---|---|---|---|---|")
    for n in args.n:
        grid = ts.Grid((-1, -1, -1), (1, 1, 1), (n, n, n))
        h = grid.spacing
        r = np.linalg.norm(np.stack(grid.meshgrid(), -1), axis=-1)
        tube = ts.Tube(r - 0.5, grid)
        r1 = 0.5 + 0.3 * h
        moved = tube.moved(r - r1)
        for k in args.sources:
            d = np.random.default_rng(1).normal(size=(k, 3))
            d /= np.linalg.norm(d, axis=1, keepdims=True)
            previous = tube.solve(0.5 * d)
            warm = moved.solve(r1 * d, warm=previous)
            cold = moved.solve(r1 * d)
            tol = cold.stats.order2["tol"]
            tight = moved.solve(r1 * d, tol=tol / 100)
            inner = cold.roles != 2

            def gap(a: ts.Solution, b: ts.Solution) -> float:
                return float(np.max(np.abs(a.values - b.values)[inner]) / tol)

            print(f"| {n} | {k} | {gap(warm, cold):.1f} | {gap(cold, tight):.1f} | {gap(warm, tight):.1f} |")


if __name__ == "__main__":
    main()
