"""Meshes coarse against the grid (docs/point-clouds.md, "Meshes"): triangles larger than 3 Δx.
A triangulation of a smooth surface (an icosphere, edges turning by 12–23°) now gets the smooth
map built for the spacing that resolves its triangles, and second order; a polyhedron (a cube
split into triangles, 90° edges) keeps the exact map and first order. Prints, per mesh and grid,
the triangles' size in grid spacings, the order ``order="auto"`` ran, and the largest and mean
error at the vertices against the exact polyhedral geodesics (pygeodesic's MMP) relative to the
largest distance (trimesh's meshes, the source at vertex 0), with the exact map at first order beside it (what ``order="auto"`` ran on every
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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="31,41,61,81")
    args = ap.parse_args()
    import pygeodesic.geodesic as geodesic
    import trimesh

    shapes = {
        "icosphere, 80 triangles": trimesh.creation.icosphere(1, 0.5),
        "icosphere, 320 triangles": trimesh.creation.icosphere(2, 0.5),
        "cube, 192 triangles": trimesh.creation.box((0.8, 0.8, 0.8)).subdivide().subdivide(),
    }
    meshes = {name: (np.asarray(m.vertices, float), np.asarray(m.faces)) for name, m in shapes.items()}
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
