"""A mesh with noise in its vertices against the same mesh smoothed (docs/point-clouds.md, "Meshes"):
an icosphere of 20,480 triangles (radius 0.5, trimesh) with Gaussian vertex noise of 0.4-1% of its
radius, solved from (-0.5, 0, 0) on the N = 61 grid over [-1, 1]^3, as it is and after
``trimesh.smoothing.filter_taubin`` (10 iterations). Prints the order that ran, the largest error
against the sphere's great circles on the equator's half from 0.2 rad off the source to 0.05 rad
before its antipode (relative to the largest distance there), the largest and the mean error over
4,000 random points of the sphere 0.2 rad or more from the source and its antipode (relative to
πR), and the start of the fallback reason.

    python benches/experiments/rough_meshes.py
"""

from __future__ import annotations

import numpy as np
import trimesh

import tubesweep as ts


def main() -> None:
    grid = ts.Grid((-1,) * 3, (1,) * 3, (61,) * 3)
    th = np.linspace(0.2, np.pi - 0.05, 20)
    pts = np.c_[0.5 * np.cos(th), 0.5 * np.sin(th), 0 * th]
    exact = 0.5 * (np.pi - th)
    sphere = trimesh.creation.icosphere(subdivisions=5, radius=0.5)
    rng = np.random.default_rng(1)
    p = rng.standard_normal((20000, 3))
    p = 0.5 * p / np.linalg.norm(p, axis=1, keepdims=True)
    angle = np.arccos(np.clip(-p[:, 0] / 0.5, -1, 1))  # from the source (-0.5, 0, 0)
    p = p[(angle > 0.2) & (angle < np.pi - 0.2)][:4000]
    p_exact = 0.5 * np.arccos(np.clip(-p[:, 0] / 0.5, -1, 1))
    print("| vertex noise | mesh | order | largest error (equator) | largest / mean (4,000 points) | fallback reason |")
    print("|---|---|---|---|---|---|")
    for amp in (0.002, 0.003, 0.005):
        v = sphere.vertices + amp * np.random.default_rng(0).standard_normal(sphere.vertices.shape)
        smoothed = trimesh.Trimesh(v, sphere.faces, process=False)
        trimesh.smoothing.filter_taubin(smoothed, iterations=10)
        for name, vertices in (("as it is", v), ("Taubin-smoothed", np.asarray(smoothed.vertices))):
            sol = ts.solve(ts.surfaces.from_mesh((vertices, sphere.faces)), grid, [(-0.5, 0, 0)])
            err = np.max(np.abs(sol(pts) - exact)) / exact.max()
            e = np.abs(sol(p) - p_exact) / (0.5 * np.pi)
            reason = (sol.stats.order_fallback or "")[:40]
            print(
                f"| {amp / 0.5:.1%} of R | {name} | {sol.stats.order} | {err:.2%} | {e.max():.2%} / {e.mean():.3%} "
                f"| {reason} |"
            )


if __name__ == "__main__":
    main()
