"""The Stanford bunny: distance from the tip of an ear, and the shortest path from the farthest point.

A scanned mesh with holes, read as a closest-point surface (nothing about inside or outside is
needed). The geodesic path runs from its start (white circle) against the gradient of the
distance to the source (red star).
"""

import argparse
from pathlib import Path

import numpy as np

import tubesweep as ts

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--n", type=int, default=120, help="grid nodes per axis (default: 120)")
parser.add_argument("--out", type=Path, default=Path("out/gallery"), help="folder for the picture")
args = parser.parse_args()
args.out.mkdir(parents=True, exist_ok=True)

bunny = ts.surfaces.from_mesh(ts.data.bunny())
grid = bunny.grid(args.n)
source = bunny.default_source  # the vertex farthest from the centroid: the tip of an ear
sol = ts.solve(bunny, grid, sources=[source])
print(sol)

u = sol.on_mesh(bunny.vertices)
far = bunny.vertices[np.nanargmax(u)]  # the vertex farthest from the source
path = sol.geodesic_path(far)
length = float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())
print(
    f"path from the farthest vertex: {len(path)} points, length {length:.4f}; the distance there: {sol([far])[0]:.4f}"
)

fig = ts.plot(
    sol, up="y", paths=[path], title="the Stanford bunny: distance from the red star, the path from the farthest point"
)
fig.savefig(args.out / "bunny_path.png", dpi=110, bbox_inches="tight")
print(f"wrote {args.out / 'bunny_path.png'}")
