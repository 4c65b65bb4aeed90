"""Geodesic distance on a sphere, against the exact great-circle distance.

The sphere of radius 0.5 as the level set of its signed distance, one source, the two-layer tube
method with the Godunov Hamiltonian. Prints the largest and the mean error on the surface in
grid spacings.
"""

import numpy as np

import tubesweep as ts
from _common import options, save, sphere_points

args = options(__doc__, n=101)
sphere = ts.surfaces.Sphere(0.5)
grid = ts.Grid((-1, -1, -1), (1, 1, 1), (args.n,) * 3)
sol = ts.solve(sphere, grid, sources=[sphere.default_source])
print(sol)

points = sphere_points(2000)  # random points on the surface
error = np.abs(sol(points) - sphere.geodesic_distance(points, sphere.default_source)) / grid.spacing
print(f"error in grid spacings: max {error.max():.2f}, mean {error.mean():.2f}")

fig = ts.plot(sol, views=((20, -150), (20, 30)), title="geodesic distance on a sphere from the red star")
save(fig, args.out, "sphere.png")
