"""Warm re-solves on a moving surface (docs/moving-surfaces.md, issue 47): a sphere of radius 0.5
deforms into the ellipsoid (0.6, 0.5, 0.42) in ``--steps`` steps on an N³ grid over [−1, 1]³ (each
step moves the surface at most 0.3 Δx at N = 121), φ given as arrays of the exact signed distance,
the source at the north pole moving with it. Per step, interleaved in one process (A, B, A, B,
... ``--rounds`` times, medians):

* cold: ``ts.solve(phi_k, grid, [pole_k])``;
* warm: ``tube_k = tube_{k-1}.moved(phi_k)`` then ``tube_k.solve([pole_k], warm=previous)``
  (``moved`` counted in the warm time; the time of the solve alone is printed too);
* extrapolated: the same with ``warm=(older, previous)`` (the start 2·previous − older).

Prints per step the time ratios to cold, the updates of each, max |· − cold| over the band in
units of the solve's tolerance, and as a yardstick the same for a cold solve without its front
windows (another path to the same fixed point), then the medians and maxima over the steps.

    python benches/moving_surfaces.py            # N = 121, 20 steps, 3 rounds
    python benches/moving_surfaces.py --n 61 --steps 5 --rounds 1
    python benches/moving_surfaces.py --growth --n 121 --steps 20   # a growing sphere
    python benches/moving_surfaces.py --local --n 121 --rounds 3    # a bump on a part of the sphere

``--local``: the sphere's φ array and the same φ with a bump of compact support (radius 0.15,
pushed out by 0.3Δx) at the equator, at the antipode or next to the source (the north pole): the
two agree bit for bit away from the bump, and the warm sweeps start from the nodes whose update
changed (``sol.stats.order2["warm"]["changed"]``).
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

import tubesweep as ts
from tubesweep import second_order as _so


def axes(k: int, steps: int) -> np.ndarray:
    s = k / steps
    return 0.5 * np.array([1.0 + 0.2 * s, 1.0, 1.0 - 0.16 * s])


def phi_of(a: np.ndarray, points: np.ndarray, shape: tuple) -> np.ndarray:
    if np.allclose(a, a[0]):
        return (np.linalg.norm(points, axis=1) - a[0]).reshape(shape)
    return ts.surfaces.Ellipsoid(*a).signed_distance(points).reshape(shape)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=121)
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--growth", action="store_true", help="only the growing sphere (u(r·d)/r against r)")
    ap.add_argument("--local", action="store_true", help="only a bump on a part of the sphere")
    args = ap.parse_args()
    if args.growth:
        growth(args.n, args.steps)
        return
    if args.local:
        local(args.n, args.rounds)
        return
    n, steps = args.n, args.steps
    grid = ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3)
    pts = grid.node_points(np.arange(n**3))
    h = grid.spacing
    phis = [phi_of(axes(k, steps), pts, grid.shape) for k in range(steps + 1)]
    poles = [[(0.0, 0.0, float(axes(k, steps)[2]))] for k in range(steps + 1)]
    moves = [float(np.max(np.abs(phis[k] - phis[k - 1]))) / h for k in range(1, steps + 1)]
    print(f"N = {n}, h = {h:.4g}, {steps} steps, largest move per step {max(moves):.2f} Δx")
    tube = ts.Tube(phis[0], grid)
    older, prev = None, tube.solve(poles[0])
    rows = []
    for k in range(1, steps + 1):
        times: dict = {"cold": [], "warm": [], "warm2": [], "solve": []}
        for _ in range(args.rounds):
            t0 = time.perf_counter()
            new_tube = tube.moved(phis[k])
            t1 = time.perf_counter()
            warm = new_tube.solve(poles[k], warm=prev)
            t2 = time.perf_counter()
            cold = ts.solve(phis[k], grid, poles[k])
            t3 = time.perf_counter()
            new_tube2 = tube.moved(phis[k])
            warm2 = new_tube2.solve(poles[k], warm=prev if older is None else (older, prev))
            t4 = time.perf_counter()
            times["warm"].append(t2 - t0)
            times["solve"].append(t2 - t1)
            times["cold"].append(t3 - t2)
            times["warm2"].append(t4 - t3)
        # the yardstick: the cold solve without its front windows, another path to the same fixed point
        windows = _so.WINDOWS
        _so.WINDOWS = (0.0, 0.0)
        try:
            unwindowed = ts.solve(phis[k], grid, poles[k])
        finally:
            _so.WINDOWS = windows
        for s in (warm, warm2):
            assert s.stats.order == 2 and np.array_equal(s.linear, cold.linear)
            assert s.stats.order2["warm"]["restarted"] is None
        tol = cold.stats.order2["tol"]
        diff = [float(np.max(np.abs(s.values - cold.values))) / tol for s in (warm, warm2, unwindowed)]
        ratio = {key: statistics.median(a / c for a, c in zip(times[key], times["cold"])) for key in times}
        rows.append((ratio, diff))
        print(
            f"step {k:2d}: time/cold warm {ratio['warm']:.2f} (solve alone {ratio['solve']:.2f}), extrapolated "
            f"{ratio['warm2']:.2f}; updates {warm.stats.updates:,} / {warm2.stats.updates:,} / cold {cold.stats.updates:,}; "
            f"max|· − cold|/tol warm {diff[0]:.1f}, extrapolated {diff[1]:.1f}, cold without windows {diff[2]:.1f}"
        )
        tube, older, prev = new_tube2, prev, warm2
    for key, name in (("warm", "warm"), ("solve", "warm solve alone"), ("warm2", "extrapolated warm")):
        r = [x[0][key] for x in rows]
        print(f"{name}/cold time: median {statistics.median(r):.2f}, max {max(r):.2f}")
    for i, name in enumerate(("warm", "extrapolated warm", "cold without windows")):
        print(f"max|{name} − cold|: {max(x[1][i] for x in rows):.1f} tol")


def growth(n: int, steps: int) -> None:
    """A sphere grown from r = 0.5 by 0.4Δx per warm step: u(r·d)/r against the first step's and
    against the exact θ (the great-circle angle from the pole), at 400 random directions d with
    0.2 < θ < π − 0.3 (away from the source and the antipode)."""
    grid = ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3)
    h = grid.spacing
    rng = np.random.default_rng(3)
    d = rng.normal(size=(400, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    theta = np.arccos(np.clip(d[:, 2], -1, 1))
    keep = (theta > 0.2) & (theta < np.pi - 0.3)
    d, theta = d[keep], theta[keep]
    r = 0.5
    tube = ts.Tube(ts.surfaces.Sphere(r), grid)
    sol = tube.solve([(0.0, 0.0, r)])
    base = sol(r * d) / r
    worst_error, worst_scaling = float(np.max(np.abs(base - theta))), 0.0
    for _ in range(steps):
        r += 0.4 * h
        tube = tube.moved(ts.surfaces.Sphere(r))
        sol = tube.solve([(0.0, 0.0, r)], warm=sol)
        scaled = sol(r * d) / r
        worst_error = max(worst_error, float(np.max(np.abs(scaled - theta))))
        worst_scaling = max(worst_scaling, float(np.max(np.abs(scaled - base))))
    print(
        f"growth N = {n}, r 0.5 → {r:.4f} in {steps} warm steps: max |u(r·d)/r − u₀(r₀·d)/r₀| = {worst_scaling:.2e}; "
        f"max |u(r·d)/r − θ| = {worst_error:.2e}"
    )


def local(n: int, rounds: int) -> None:
    """A bump of 0.3Δx on a part of the sphere: warm (``moved`` and the solve) against cold,
    interleaved ``rounds`` times (medians), the updates, the nodes whose update changed and
    max |warm − cold| in tolerances."""
    grid = ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3)
    h = grid.spacing
    ax = np.linspace(-1, 1, n)
    x, y, z = np.meshgrid(ax, ax, ax, indexing="ij")
    phi = np.sqrt(x**2 + y**2 + z**2) - 0.5
    src = [(0.0, 0.0, 0.5)]
    tube = ts.Tube(phi, grid)
    sol = tube.solve(src)
    print(f"N = {n}: a bump of radius 0.15 pushed out by 0.3Δx, the source at the north pole")
    for centre, name in (((0.5, 0, 0), "equator"), ((0, 0, -0.5), "antipode"), ((0.3, 0, 0.4), "next to the source")):
        r2 = ((x - centre[0]) ** 2 + (y - centre[1]) ** 2 + (z - centre[2]) ** 2) / 0.15**2
        bumped = phi - 0.3 * h * np.where(r2 < 1, (1 - r2) ** 4, 0.0)
        times: dict = {"warm": [], "solve": [], "cold": []}
        for _ in range(rounds):
            t0 = time.perf_counter()
            moved = tube.moved(bumped)
            t1 = time.perf_counter()
            warm = moved.solve(src, warm=sol)
            t2 = time.perf_counter()
            cold = ts.solve(bumped, grid, src)
            t3 = time.perf_counter()
            times["warm"].append(t2 - t0)
            times["solve"].append(t2 - t1)
            times["cold"].append(t3 - t2)
        info = warm.stats.order2["warm"]
        assert info["restarted"] is None and np.array_equal(warm.linear, cold.linear)
        tol = cold.stats.order2["tol"]
        ratio = {k: statistics.median(a / c for a, c in zip(times[k], times["cold"])) for k in times}
        print(
            f"{name:>19}: time/cold warm {ratio['warm']:.2f} (solve alone {ratio['solve']:.2f}); changed "
            f"{info['changed']:,} of {warm.stats.band_points:,} nodes; updates {warm.stats.updates:,} / cold "
            f"{cold.stats.updates:,} ({warm.stats.updates / cold.stats.updates:.2f}); max|warm − cold|/tol "
            f"{float(np.max(np.abs(warm.values - cold.values))) / tol:.1f}"
        )


if __name__ == "__main__":
    main()
