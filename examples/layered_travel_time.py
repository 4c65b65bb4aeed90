"""Travel time in a layered medium, in the whole box (the paper's Algorithm 1).

Speed 1 below y = 0 and 2 above, with a smooth transition: the fronts speed up as they cross into
the fast layer, and waves that run along it overtake the direct ones (head waves).
"""

import argparse
from pathlib import Path

import numpy as np

import tubesweep as ts

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--n", type=int, default=301, help="grid nodes per axis (default: 301)")
parser.add_argument("--out", type=Path, default=Path("out/gallery"), help="folder for the picture")
args = parser.parse_args()
args.out.mkdir(parents=True, exist_ok=True)

grid = ts.Grid((-1, -1), (1, 1), (args.n, args.n))
source = (0.0, -0.6)


def speed(p):
    return 1.5 + 0.5 * np.tanh(8 * p[:, 1])


u, stats = ts.travel_time(grid, [source], speed=speed, return_stats=True)
print(
    f"grid {grid.shape}: {stats.iterations} iterations; time to (0, -1): {u[args.n // 2, 0]:.3f} "
    f"(straight down at speed ≈ 1: 0.4)"
)

X, Y = grid.meshgrid()
fig = ts.plot(
    u,
    grid=grid,
    sources=[source],
    speed=speed(np.c_[X.ravel(), Y.ravel()]).reshape(X.shape),
    title="travel time from the red star, speed 1.5 + 0.5 tanh(8y)",
)
fig.savefig(args.out / "layered_travel_time.png", dpi=110, bbox_inches="tight")
print(f"wrote {args.out / 'layered_travel_time.png'}")
