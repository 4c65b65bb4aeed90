"""A grid box that cuts the surface (docs/surfaces.md, "A grid box that cuts the surface"): what
``sol.stats.box_cut`` records for the torus of radii 0.6 and 0.25 in a box that ends at x = 0.3
(with the exact length of the two cut ovals), the circle of radius 0.6 cut the same way in 2D,
and the sphere of radius 0.97 in [-1, 1]³ at N = 61, whose tube only is cut::

    .venv/bin/python benches/experiments/box_cut.py
"""

from __future__ import annotations

import warnings

import numpy as np

import tubesweep as ts


def main() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        torus = ts.solve(
            ts.surfaces.Torus(0.6, 0.25), ts.Grid((-1, -1, -1), (0.3, 1, 1), (66, 101, 101)), [(-0.85, 0, 0)]
        )
        circle = ts.solve(ts.surfaces.Circle(0.6), ts.Grid((-1, -1), (0.3, 1), (66, 101)), [(-0.6, 0)])
        sphere = ts.solve(ts.surfaces.Sphere(0.97), ts.Grid((-1,) * 3, (1,) * 3, (61,) * 3), [(-0.97, 0, 0)], order=1)
    t = np.linspace(0, 2 * np.pi, 20001)
    rho = 0.6 + 0.25 * np.cos(t)
    oval = np.stack([np.sqrt(rho**2 - 0.09), 0.25 * np.sin(t)], axis=1)
    exact = 2 * float(np.sum(np.linalg.norm(np.diff(oval, axis=0), axis=1)))
    print(f"torus cut at x = 0.3: {torus.stats.box_cut} (the exact length of the cut: {exact:.4g})")
    print(f"circle cut at x = 0.3: {circle.stats.box_cut}")
    print(f"sphere R = 0.97, N = 61: {sphere.stats.box_cut}")


if __name__ == "__main__":
    main()
