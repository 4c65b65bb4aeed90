"""How near the re-distanced band comes to the exact distance of shapes with sharp edges whose
faces and rims lie on grid nodes (docs/surfaces.md, "How good it is"): a box (half-sides 0.5, 0.4,
0.3) and a closed cylinder (radius 0.5, caps at z = ±0.4) in [−1, 1]³, given by their exact signed
distances and re-distanced (``ts.LevelSet(d, redistance=True).band(grid, 4Δx)``). Printed per
shape and N: the largest error of the band against the exact distance and the number of nodes off
by more than 0.1Δx, in all and at the nodes within 0.1Δx of the surface (those beside a rim, which
the edges of their cells cross only at nodes where φ vanishes). The interpolant's zero set cuts a
curved rim off within its cells, so errors of about 0.3–0.4Δx remain next to the cylinder's rims;
the box's straight edges, along grid lines, it keeps.

    .venv/bin/python benches/experiments/sharp_edges_redistance.py [N ...]   # default 61 101
"""

from __future__ import annotations

import sys
import warnings

import numpy as np

import tubesweep as ts


def box(x, y, z):
    q = [np.abs(x) - 0.5, np.abs(y) - 0.4, np.abs(z) - 0.3]
    outside = np.sqrt(sum(np.maximum(c, 0) ** 2 for c in q))
    return outside + np.minimum(np.maximum(np.maximum(q[0], q[1]), q[2]), 0)


def cylinder(x, y, z):
    dr, dz = np.hypot(x, y) - 0.5, np.abs(z) - 0.4
    return np.minimum(np.maximum(dr, dz), 0) + np.hypot(np.maximum(dr, 0), np.maximum(dz, 0))


def errors(shape, n: int) -> dict:
    """The band's errors (in Δx) against the exact distance of ``shape`` at N = ``n``."""
    grid = ts.Grid((-1.0,) * 3, (1.0,) * 3, (n,) * 3)
    d = shape(*grid.meshgrid())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        band = ts.LevelSet(d, redistance=True).band(grid, 4 * grid.spacing)
    exact = d.ravel()[band.linear]
    err = np.abs(band.signed - exact) / grid.spacing
    near = np.abs(exact) < 0.1 * grid.spacing
    return {
        "max": float(err.max()),
        "off": int((err > 0.1).sum()),
        "near_max": float(err[near].max()),
        "near_off": int((err[near] > 0.1).sum()),
        "nodes": len(err),
    }


def main(ns) -> None:
    for n in ns:
        for name, shape in (("box", box), ("cylinder", cylinder)):
            e = errors(shape, n)
            print(
                f"N={n:4d} {name:9s} band nodes {e['nodes']:7d}  largest error {e['max']:.2f}Δx, "
                f"{e['off']} nodes above 0.1Δx; within 0.1Δx of the surface {e['near_max']:.2f}Δx, "
                f"{e['near_off']} above 0.1Δx",
                flush=True,
            )


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [61, 101])
