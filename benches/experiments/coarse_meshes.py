"""Meshes coarse against the grid (docs/point-clouds.md, "Meshes"): triangles larger than 3 Δx.
A triangulation of a smooth surface (an icosphere, edges turning by 12–23°) now gets the smooth
map built for the spacing that resolves its triangles, and second order; a polyhedron (a cube
split into triangles, 90° edges) keeps the exact map and first order. Prints, per mesh and grid,
the triangles' size in grid spacings, the order ``order="auto"`` ran, and the largest and mean
error at the vertices against the exact polyhedral geodesics (pygeodesic's MMP) relative to the
largest distance, with the exact map at first order beside it (what ``order="auto"`` ran on every
coarse mesh before). About half a minute.

    .venv/bin/python benches/experiments/coarse_meshes.py
    .venv/bin/python benches/experiments/coarse_meshes.py --sizes 31,41,61,81,121
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

import tubesweep as ts
from tubesweep.surfaces import _mesh_smooth


def icosphere(levels: int, r: float = 0.5):
    """The icosahedron subdivided ``levels`` times, projected onto the sphere of radius ``r``."""
    t = (1 + 5**0.5) / 2
    v = [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t]]
    v += [[t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]
    f = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2]]
    f += [[10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11]]
    f += [[6, 2, 10], [8, 6, 7], [9, 8, 1]]
    pts = [np.array(p, float) / np.linalg.norm(p) for p in v]
    for _ in range(levels):
        mid: dict = {}

        def middle(a: int, b: int) -> int:
            key = (min(a, b), max(a, b))
            if key not in mid:
                m = pts[a] + pts[b]
                pts.append(m / np.linalg.norm(m))
                mid[key] = len(pts) - 1
            return mid[key]

        new = []
        for a, b, c in f:
            ab, bc, ca = middle(a, b), middle(b, c), middle(c, a)
            new += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
        f = new
    return r * np.array(pts), np.array(f)


def cube(k: int):
    """The cube [-0.4, 0.4]³, each face a k × k grid of squares cut in two (shared vertices)."""
    s = np.linspace(-0.4, 0.4, k + 1)
    pts = np.array([[x, y, z] for x in s for y in s for z in s])
    pts = pts[np.max(np.abs(pts), axis=1) > 0.4 - 1e-12]
    index = {tuple(np.round(p, 9)): i for i, p in enumerate(pts)}
    faces = []
    for axis in range(3):
        for side in (-0.4, 0.4):
            for i in range(k):
                for j in range(k):
                    quad = []
                    for a, b in ((i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)):
                        p = [0.0, 0.0, 0.0]
                        p[axis], p[(axis + 1) % 3], p[(axis + 2) % 3] = side, s[a], s[b]
                        quad.append(index[tuple(np.round(p, 9))])
                    faces += [[quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]]
    return pts, np.array(faces)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="31,41,61,81")
    args = ap.parse_args()
    import pygeodesic.geodesic as geodesic

    meshes = {
        "icosphere, 80 triangles": icosphere(1),
        "icosphere, 320 triangles": icosphere(2),
        "cube, 96 triangles": cube(2),
    }
    print("| mesh | N | triangle / Δx | order | largest error | mean error | exact map, order 1: largest | mean |")
    print("|---|---|---|---|---|---|---|---|")
    for name, (v, f) in meshes.items():
        exact, _ = geodesic.PyGeodesicAlgorithmExact(v, f).geodesicDistances(np.array([0]), None)
        top = float(exact.max())
        for n in (int(s) for s in args.sizes.split(",")):
            grid = ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3)
            surf = ts.surfaces.from_mesh((v, f))
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                sol = ts.solve(surf, grid, [v[0]])
                first = ts.solve(ts.surfaces.from_mesh((v, f), smooth=False), grid, [v[0]], order=1)
            e = np.abs(sol.on_mesh(v) - exact) / top
            e1 = np.abs(first.on_mesh(v) - exact) / top
            size = _mesh_smooth.median_size(surf) / grid.spacing
            print(
                f"| {name} | {n} | {size:.1f} | {sol.stats.order} | {e.max():.2%} | {e.mean():.3%} "
                f"| {e1.max():.2%} | {e1.mean():.3%} |"
            )


if __name__ == "__main__":
    main()
