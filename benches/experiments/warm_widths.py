"""A warm start from a solve with other tube widths (docs/moving-surfaces.md, "The cold solve's
values"): the sphere of radius 0.5 at N = 41, the source at its north pole, solved with the
default widths (inner 2, outer 4); then warm solves with ``outer`` = 5, 6, 7 from it, on the same
sphere and on one grown by half a spacing, against cold solves with those widths. Prints the
largest gap in stopping tolerances over the band, where it lies (its distance from the surface in
spacings), and on the surface (at the band nodes' projections onto the sphere)::

    .venv/bin/python benches/experiments/warm_widths.py      # a few seconds
"""

from __future__ import annotations

import numpy as np

import tubesweep as ts


def main() -> None:
    grid = ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41))
    h = grid.spacing
    previous = ts.Tube(ts.surfaces.Sphere(0.5), grid).solve([(0, 0, 0.5)])
    print("| outer | surface | largest gap (tol) | at |x| − r | on the surface (tol) |")
    print("|---|---|---|---|---|")
    for outer in (5, 6, 7):
        for r in (0.5, 0.5 + 0.5 * h):
            tube = ts.Tube(ts.surfaces.Sphere(r), grid, inner=2, outer=outer)
            cold = tube.solve([(0, 0, r)])
            warm = tube.solve([(0, 0, r)], warm=previous)
            tol = cold.stats.order2["tol"]
            gap = np.abs(warm.values - cold.values)
            x = grid.node_points(warm.linear)
            at = float(np.linalg.norm(x[int(np.argmax(gap))]) - r) / h
            on = r * x / np.linalg.norm(x, axis=1, keepdims=True)
            surface = float(np.max(np.abs(warm(on) - cold(on))))
            name = "same" if r == 0.5 else "grown by 0.5Δx"
            print(f"| {outer} | {name} | {gap.max() / tol:.1f} | {at:.1f} Δx | {surface / tol:.1f} |")


if __name__ == "__main__":
    main()
