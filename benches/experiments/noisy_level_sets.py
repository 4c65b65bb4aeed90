"""The sphere's φ with Gaussian noise, and the cube's creases: what ``order="auto"`` runs and how
accurate it is (issue 43: noise and creases; docs/second-order.md, "What order=2 needs").

Noise: φ = |x| − 0.5 + noise·N(0, 1) on [−1, 1]³, source (−0.5, 0, 0), mean and max errors on the
meridian z = 0, y > 0 against the great-circle distance, at order 2 (the default) and 1, with
``order2["geometry_fitted"]`` (the fits over three grid steps at every node) and the first-order
nodes. Creases: the cube max|x| − 0.5 from the bottom centre to the top centre (exact 2.0), the
shortcut per edge measured against the one the warning says (up to 1.5Δx with the inner tube thinned at creases;
benches/experiments/creases.py has the figures)::

    .venv/bin/python benches/experiments/noisy_level_sets.py            # N = 61 and 121, about a minute
    .venv/bin/python benches/experiments/noisy_level_sets.py --quick    # N = 61
"""

from __future__ import annotations

import argparse
import math
import re
import warnings

import numpy as np

import tubesweep as ts


def _grid(n: int) -> ts.Grid:
    return ts.Grid((-1.0,) * 3, (1.0,) * 3, (n,) * 3)


def noise(sizes: list) -> None:
    th = np.linspace(0.05, math.pi - 0.05, 300)
    meridian = np.c_[-0.5 * np.cos(th), 0.5 * np.sin(th), 0 * th]
    print("noise in φ: mean / max error on a meridian")
    for n in sizes:
        g = _grid(n)
        x, y, z = g.meshgrid()
        for level in (0.0, 1e-4, 3e-4, 1e-3, 3e-3):
            phi = np.sqrt(x * x + y * y + z * z) - 0.5 + level * np.random.default_rng(0).standard_normal(g.shape)
            row = []
            for order in ("auto", 1):
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    sol = ts.solve(ts.LevelSet(phi), g, [(-0.5, 0.0, 0.0)], order=order)
                e = np.abs(sol(meridian) - 0.5 * th)
                row.append(f"{e.mean():.2e} / {e.max():.2e}")
                if order == "auto":
                    o2 = sol.stats.order2 or {}
                    info = (
                        f"order {sol.stats.order}, fitted {o2.get('geometry_fitted')}, "
                        f"first-order nodes {o2.get('first_order_nodes')}"
                    )
            print(
                f"  N = {n:3d}  noise {level:.0e} ({level / g.spacing:.3f}Δx): default {row[0]} ({info}); order=1 {row[1]}"
            )


def creases(sizes: list) -> None:
    print("the cube max|x| − 0.5, bottom centre to top centre (exact 2.0)")
    for n in sizes:
        g = _grid(n)
        x, y, z = g.meshgrid()
        phi = np.maximum(np.maximum(np.abs(x), np.abs(y)), np.abs(z)) - 0.5
        for inner in (2.0, 1.0):
            with warnings.catch_warnings(record=True) as rec:
                warnings.simplefilter("always")
                sol = ts.solve(ts.LevelSet(phi), g, [(0.0, 0.0, -0.5)], inner=inner)
            said = next((re.search(r"about ([0-9.]+) per crease", str(w.message)) for w in rec), None)
            top = float(sol([(0.0, 0.0, 0.5)])[0])
            per_edge = (2.0 - top) / 2
            told = f"{float(said.group(1)) / g.spacing:.2f}Δx" if said else "(no warning)"
            print(
                f"  N = {n:3d}  inner = {inner:g}: order {sol.stats.order}, {top:.4f}; per edge "
                f"{per_edge / g.spacing:.2f}Δx, the warning says {told}"
            )


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args()
    sizes = [61] if a.quick else [61, 121]
    noise(sizes)
    creases([41] if a.quick else [41, 81])


if __name__ == "__main__":
    main()
