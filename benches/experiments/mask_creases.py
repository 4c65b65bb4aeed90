"""Creases of voxel masks and noisy φ (``tubesweep._coarse_creases``): how early a front arrives
beyond the crease, against what the crease warning says. docs/second-order.md, "Creases".

Two balls of radius 0.5 on [−1, 1]³ joined by ``min``, their faces meeting at 90°–140°, given as a
voxel mask (raw, ``smooth=1`` or ``smooth=1.5``), as their distance with noise of 0.3Δx
re-distanced, or as their distance re-distanced; the source at the far pole of the first ball, the
points along the second's meridian up to 0.1 before the crease. For each: the worst and the mean
early arrival in grid spacings, and the largest figure a crease warning gave (none: no crease
warning; ``**``: the worst beyond what was said)::

    .venv/bin/python benches/experiments/mask_creases.py                   # N = 41, 61; about 2 minutes
    .venv/bin/python benches/experiments/mask_creases.py --n 41 --kinds mask --orders auto
"""

from __future__ import annotations

import argparse
from typing import List, Optional
import re
import warnings

import numpy as np

import tubesweep as ts

_SAID = re.compile(r"early by (?:up to about )?([0-9.e+-]+)")


def _surface(kind: str, d: np.ndarray, grid: ts.Grid) -> ts.Surface:
    if kind == "mask":
        return ts.LevelSet.from_mask(d < 0, grid)
    if kind.startswith("smooth"):
        return ts.LevelSet.from_mask(d < 0, grid, smooth=float(kind[len("smooth") :]))
    if kind == "noisy":
        noise = 0.3 * grid.spacing * np.random.default_rng(0).normal(size=d.shape)
        return ts.LevelSet(d + noise, redistance=True)
    return ts.LevelSet(d, redistance=True)


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--n", type=int, nargs="+", default=[41, 61])
    parser.add_argument("--angles", type=float, nargs="+", default=[90, 106, 122, 140])
    parser.add_argument("--kinds", nargs="+", default=["mask", "smooth1", "smooth1.5", "noisy", "exact"])
    parser.add_argument("--orders", nargs="+", default=["auto", "1"])
    args = parser.parse_args(argv)
    r = 0.5
    print("N  angle kind       order ran  worst  mean   said")
    for n in args.n:
        grid = ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3)
        x = np.stack(grid.meshgrid(), axis=-1)
        for angle in args.angles:
            c = r * np.sin(np.radians(angle / 2))
            d = np.minimum(np.linalg.norm(x + [c, 0, 0], axis=-1), np.linalg.norm(x - [c, 0, 0], axis=-1)) - r
            crease = np.arccos(-c / r)
            beta = np.linspace(0.05, crease - 0.1, 40)
            points = np.c_[c + r * np.cos(beta), r * np.sin(beta), 0 * beta]
            exact = r * (2 * crease - beta)
            for kind in args.kinds:
                surface = _surface(kind, d, grid)
                for order in args.orders:
                    with warnings.catch_warnings(record=True) as caught:
                        warnings.simplefilter("always")
                        sol = ts.solve(surface, grid, [(-c - r, 0, 0)], order="auto" if order == "auto" else int(order))
                    said = [
                        float(m.group(1)) / grid.spacing
                        for w in caught
                        if "crease" in str(w.message) and (m := _SAID.search(str(w.message)))
                    ]
                    early = (exact - sol(points)) / grid.spacing
                    figure = f"{max(said):6.2f}" if said else "  none"
                    flag = " **" if said and max(said) < early.max() else ""
                    print(
                        f"{n:<3}{angle:5.0f}  {kind:10s} {order:5s} {sol.stats.order:<3} {early.max():6.2f} "
                        f"{early.mean():6.2f} {figure}{flag}",
                        flush=True,
                    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
