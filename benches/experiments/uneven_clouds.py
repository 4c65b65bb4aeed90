"""Point clouds whose sampling is uneven or noisy (docs/point-clouds.md, "What is checked"): a
sphere of radius 0.5 sampled evenly, 30 times more densely above its equator than below, and with
Gaussian noise of 2 % of its radius, at N = 61 on [-1, 1]³, the source at the north pole. Prints,
per cloud, the rim samples found, the order run, and the largest and mean error at 3000 points of
the sphere against great circles, relative to the largest distance. About half a minute.

    .venv/bin/python benches/experiments/uneven_clouds.py
"""

from __future__ import annotations

import warnings

import numpy as np

import tubesweep as ts

R = 0.5


def sphere(rng: np.random.Generator, m: int) -> np.ndarray:
    x = rng.normal(size=(m, 3))
    return R * x / np.linalg.norm(x, axis=1, keepdims=True)


def main() -> None:
    rng = np.random.default_rng(1)
    dense, sparse = sphere(rng, 8000), sphere(rng, 300)
    noisy = sphere(rng, 40000)
    clouds = {
        "even, 8000 samples": sphere(rng, 8000),
        "30x denser above the equator": np.vstack([dense[dense[:, 2] > 0], sparse[sparse[:, 2] <= 0]]),
        "40,000 samples, noise 2% of the radius": noisy + 0.01 * rng.normal(size=noisy.shape),
    }
    grid = ts.Grid((-1,) * 3, (1,) * 3, (61,) * 3)
    probe = sphere(rng, 3000)
    exact = R * np.arccos(np.clip(probe[:, 2] / R, -1, 1))
    print("| cloud | rim samples | order | largest error | mean error |")
    print("|---|---|---|---|---|")
    for name, points in clouds.items():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the noisy cloud's outliers
            cloud = ts.surfaces.from_points(points)
            sol = ts.solve(cloud, grid, [(0.0, 0.0, R)])
        e = np.abs(sol(probe) - exact) / (np.pi * R)
        print(f"| {name} | {cloud.report['rim_samples']} | {sol.stats.order} | {e.max():.2%} | {e.mean():.3%} |")


if __name__ == "__main__":
    main()
