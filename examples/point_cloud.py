"""Geodesic distance on a point cloud: 20,000 random samples of a torus, with no triangles.

The samples become a surface through moving-least-squares closest points
(``ts.surfaces.from_points``), solved to second order, read back at the samples and drawn as
the cloud coloured by distance. Prints the error along the outer equator, where the exact
distance is the arclength.
"""

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import tubesweep as ts  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__)
parser.add_argument("--n", type=int, default=81, help="grid nodes per axis on [-1, 1]^3")
parser.add_argument("--out", type=Path, default=Path("out/gallery"), help="folder for the picture")
args = parser.parse_args()

# area-uniform random samples of the torus R = 0.5, r = 0.2
rng = np.random.default_rng(0)
theta, phi = rng.uniform(0, 2 * np.pi, (2, 40_000))
keep = 0.7 * rng.uniform(size=40_000) < 0.5 + 0.2 * np.cos(phi)
theta, phi = theta[keep][:20_000], phi[keep][:20_000]
rho = 0.5 + 0.2 * np.cos(phi)
samples = np.c_[rho * np.cos(theta), rho * np.sin(theta), 0.2 * np.sin(phi)]

cloud = ts.surfaces.from_points(samples)
print(cloud)
grid = ts.Grid((-1, -1, -1), (1, 1, 1), (args.n,) * 3)
source = (0.7, 0.0, 0.0)  # on the outer equator
sol = ts.solve(cloud, grid, sources=[source])
print(f"order {sol.stats.order}")

t = np.linspace(-1.0, 1.0, 101)  # the outer equator, within its conjugate point (|θ| ≤ 1.02)
equator = np.c_[0.7 * np.cos(t), 0.7 * np.sin(t), 0 * t]
error = np.abs(sol(equator) - 0.7 * np.abs(t))
print(f"error along the outer equator: mean {error.mean():.2e}, max {error.max():.2e}")

u = sol(samples)
normal = np.c_[np.cos(phi) * np.cos(theta), np.cos(phi) * np.sin(theta), np.sin(phi)]  # for the picture only
fig = plt.figure(figsize=(11, 4.6))
for k, azim in enumerate((-25, 155)):  # the source's side, then the far side of the ring
    ax = fig.add_subplot(1, 2, k + 1, projection="3d", computed_zorder=False)  # the star drawn over the samples
    e, a = np.radians(35), np.radians(azim)
    front = normal @ (np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)) > 0  # (matplotlib draws no depth)
    art = ax.scatter(*samples[front].T, c=u[front], s=16, cmap="viridis", vmin=0, vmax=np.nanmax(u), depthshade=False)
    if k == 0:
        ax.scatter(*source, color="red", marker="*", s=250, depthshade=False, zorder=3)
    ax.view_init(elev=35, azim=azim)
    ax.set_box_aspect((1.4, 1.4, 0.4), zoom=1.35)
    ax.set_axis_off()
    ax.set_title(f"seen from azimuth {azim}°, elevation 35°", fontsize=10)
fig.colorbar(art, ax=fig.axes, shrink=0.6, label="geodesic distance")
fig.suptitle("20,000 samples of a torus (no triangles), coloured by the distance from the red star")
args.out.mkdir(parents=True, exist_ok=True)
fig.savefig(args.out / "point_cloud.png", dpi=110, bbox_inches="tight")
print(f"wrote {args.out / 'point_cloud.png'}")
