"""Open and non-orientable surfaces: the upper hemisphere and the Möbius band.

Both are closest-point surfaces (paper Sect. 5.2): the tube closes around the rim, and the
extension direction ``(x − cp(x)) / |x − cp(x)|`` needs no orientation, so the Möbius band works
as it is. On the hemisphere the distance is exactly the great-circle distance.
"""

import numpy as np

import tubesweep as ts
from _common import options, save, sphere_points

args = options(__doc__, n=81)
grid = ts.Grid((-1, -1, -1), (1, 1, 1), (args.n,) * 3)

hemisphere = ts.surfaces.Hemisphere(0.5)
sol_h = ts.solve(hemisphere, grid, [hemisphere.default_source])
points = sphere_points(2000, upper=True)
error = np.abs(sol_h(points) - hemisphere.geodesic_distance(points, hemisphere.default_source))
print(f"hemisphere: {sol_h.stats.band_points:,} band nodes, max error {error.max() / grid.spacing:.2f} grid spacings")

mobius = ts.surfaces.MobiusBand()
sol_m = ts.solve(mobius, grid, [mobius.default_source])
print(f"Möbius band: {sol_m.stats.band_points:,} band nodes, largest distance {np.nanmax(sol_m.values):.3f}")

save(ts.plot(sol_h, views=((30, -60),), title="the upper hemisphere"), args.out, "hemisphere.png")
save(ts.plot(sol_m, views=((45, -60),), title="the Möbius band"), args.out, "mobius.png")
