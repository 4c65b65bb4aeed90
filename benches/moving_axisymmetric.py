"""The coupled evolution checked against a reference that needs no tubesweep (docs/moving-surfaces.md,
issue 47): a sphere of radius 0.5 moved by ``ts.evolve`` with the normal speed V = g(u), u the
geodesic distance from its north pole, stays a surface of revolution, and on a surface of revolution
the distance from the pole is the arclength along the meridian. So its meridian moves as a plane
curve with normal speed g(arclength from the pole): the reference tracks that curve with marker
particles (Heun's method, the markers redistributed uniformly in arclength after every step, a
fine step), in numpy.

Compared at the final time, at every grid size:

* shape: the Hausdorff distance between the zero level set and the reference surface (the largest
  distance of the level set's points to the reference meridian, and of the reference's points to
  the level set, |φ| interpolated there);
* distances: |u − s| at the level set's points (s the reference's arclength at the nearest point
  of its meridian), max and mean, away from the south pole (the cut point).

    python benches/moving_axisymmetric.py                  # N = 41, 61, 81
    python benches/moving_axisymmetric.py --sizes 41,61,81,121
"""

from __future__ import annotations

import argparse
import math
import time
from typing import Callable, Dict

import numpy as np
from scipy.ndimage import map_coordinates
from scipy.spatial import cKDTree

import tubesweep as ts

R0 = 0.5
T = 0.25


def g(s: np.ndarray) -> np.ndarray:
    """The speed law: faster away from the pole (the sphere becomes a pear)."""
    return 0.2 + 0.3 * np.minimum(s, 2.0)


def _resample(p: np.ndarray, m: int) -> np.ndarray:
    """``m`` + 1 points uniformly in arclength along the polyline ``p`` (its ends kept)."""
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    t = np.linspace(0.0, s[-1], m + 1)
    return np.stack([np.interp(t, s, p[:, 0]), np.interp(t, s, p[:, 1])], axis=1)


def _velocity(p: np.ndarray, law: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """The normal velocity g(s)·n of each marker of the meridian ``p`` ((ρ, z), from the north pole
    to the south pole through ρ > 0): n = (t_z, −t_ρ)... rotated so that it points outward."""
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    tan = np.gradient(p, s, axis=0, edge_order=2)
    tan /= np.linalg.norm(tan, axis=1)[:, None]
    n = np.stack([-tan[:, 1], tan[:, 0]], axis=1)
    n[0], n[-1] = (0.0, 1.0), (0.0, -1.0)  # the poles move along the axis
    return law(s)[:, None] * n


def reference(t_end: float, m: int = 2000) -> np.ndarray:
    """The meridian at ``t_end``, ``m`` + 1 markers, by front tracking."""
    a = np.linspace(0.0, math.pi, m + 1)
    p = np.stack([R0 * np.sin(a), R0 * np.cos(a)], axis=1)
    ds = R0 * math.pi / m
    steps = int(math.ceil(t_end / (0.25 * ds / float(g(np.array([10.0]))[0]))))
    dt = t_end / steps
    for _ in range(steps):
        k1 = _velocity(p, g)
        q = p + dt * k1
        q[:, 0] = np.maximum(q[:, 0], 0.0)
        p = p + 0.5 * dt * (k1 + _velocity(q, g))
        p[0, 0] = p[-1, 0] = 0.0
        p = _resample(p, m)
    return p


def compare(n: int, meridian: np.ndarray) -> Dict[str, float]:
    grid = ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3)
    h = grid.spacing
    x = np.stack(grid.meshgrid(), -1)
    phi = np.linalg.norm(x, axis=-1) - R0
    vmax = float(g(np.array([10.0]))[0])
    steps = int(math.ceil(T / (0.5 * h / vmax)))
    t0 = time.perf_counter()
    ev = ts.evolve(phi, grid, [(0.0, 0.0, R0)], g, dt=T / steps, steps=steps, every=steps)
    seconds = time.perf_counter() - t0
    sol = ev.solutions[-1]
    # the zero level set's points: the inner nodes' projections
    inner = sol.linear[np.abs(sol.phi) <= 1.0 * h]
    _, feet = sol.surface.project(grid.node_points(inner), grid)
    rz = np.stack([np.hypot(feet[:, 0], feet[:, 1]), feet[:, 2]], axis=1)
    dense = _resample(meridian, 20000)
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(dense, axis=0), axis=1))])
    tree = cKDTree(dense)
    gap, nearest = tree.query(rz)
    # the reference's points, rotated to 16 azimuths, against |φ| of the final array
    az = np.linspace(0, 2 * math.pi, 16, endpoint=False)
    ref3 = np.concatenate(
        [np.stack([meridian[:, 0] * math.cos(b), meridian[:, 0] * math.sin(b), meridian[:, 1]], 1) for b in az]
    )
    coords = ((ref3 - np.asarray(grid.lower)) / h).T
    phi_ref = map_coordinates(ev.phis[-1], coords, order=1)
    hausdorff = max(float(np.max(gap)), float(np.max(np.abs(phi_ref))))
    u = sol(feet)
    s_ref = arc[nearest]
    far = (s_ref > 0.1) & (s_ref < arc[-1] - 0.3)
    err = np.abs(u - s_ref)[far]
    return {
        "n": n,
        "h": h,
        "steps": steps,
        "hausdorff": hausdorff,
        "max": float(np.max(err)),
        "mean": float(np.mean(err)),
        "seconds": seconds,
        "warm": ev.warm_starts,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="41,61,81")
    args = ap.parse_args()
    meridian = reference(T)
    print(f"reference: meridian at t = {T}, pole at z = {meridian[0, 1]:.5f} (exact {R0 + 0.2 * T:.5f})")
    rows = [compare(int(n), meridian) for n in args.sizes.split(",")]
    for i, r in enumerate(rows):
        line = (
            f"N = {r['n']:4d} ({r['steps']} steps, {r['warm']} warm, {r['seconds']:.1f} s): Hausdorff {r['hausdorff']:.3e}, "
            f"distance max {r['max']:.3e}, mean {r['mean']:.3e}"
        )
        if i:
            q = rows[i - 1]
            fit = lambda k: math.log(q[k] / r[k]) / math.log(q["h"] / r["h"])  # noqa: E731
            line += f"; orders {fit('hausdorff'):.2f} / {fit('max'):.2f} / {fit('mean'):.2f}"
        print(line)


if __name__ == "__main__":
    main()
