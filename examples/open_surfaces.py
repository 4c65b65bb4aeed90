"""Open and non-orientable surfaces: the upper hemisphere and the Möbius band.

Both are closest-point surfaces (paper Sect. 5.2): the tube closes around the rim, and the
extension direction ``(x − cp(x)) / |x − cp(x)|`` needs no orientation, so the Möbius band works
as it is. On the hemisphere the distance is exactly the great-circle distance.
"""

import argparse
from pathlib import Path

import numpy as np

import tubesweep as ts

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--n", type=int, default=81, help="grid nodes per axis (default: 81)")
parser.add_argument("--out", type=Path, default=Path("out/gallery"), help="folder for the picture")
args = parser.parse_args()
args.out.mkdir(parents=True, exist_ok=True)

grid = ts.Grid((-1, -1, -1), (1, 1, 1), (args.n,) * 3)

hemisphere = ts.surfaces.Hemisphere(0.5)
sol_h = ts.solve(hemisphere, grid, [hemisphere.default_source])
points = np.random.default_rng(0).normal(size=(2000, 3))  # random points on the sphere of radius 0.5
points[:, 2] = np.abs(points[:, 2])  # the upper half
points = 0.5 * points / np.linalg.norm(points, axis=1, keepdims=True)
error = np.abs(sol_h(points) - hemisphere.geodesic_distance(points, hemisphere.default_source))
print(f"hemisphere: {sol_h.stats.band_points:,} band nodes, max error {error.max() / grid.spacing:.2f} grid spacings")

mobius = ts.surfaces.MobiusBand()
sol_m = ts.solve(mobius, grid, [mobius.default_source])
print(f"Möbius band: {sol_m.stats.band_points:,} band nodes, largest distance {np.nanmax(sol_m.values):.3f}")

ts.plot(sol_h, views=((30, -60),), title="the upper hemisphere").savefig(
    args.out / "hemisphere.png", dpi=110, bbox_inches="tight"
)
print(f"wrote {args.out / 'hemisphere.png'}")
ts.plot(sol_m, views=((45, -60),), title="the Möbius band").savefig(
    args.out / "mobius.png", dpi=110, bbox_inches="tight"
)
print(f"wrote {args.out / 'mobius.png'}")
