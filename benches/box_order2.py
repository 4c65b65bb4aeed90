"""Box travel times, order=1 against order=2 (issue 31, items 4 and 6), and cubic evaluation.

1. A point source in a linear-speed medium in [-1, 1]^3, slowness 1/(2 + (0.5, -0.4, 0.3)·x),
   source off the nodes at (0.013, -0.071, 0.05); the exact travel time is
   arccosh(1 + |g|^2 |x - xs|^2 / (2 v(x) v(xs))) / |g|. Errors at every node and at 4000 random
   points (multilinear and cubic evaluation of BoxSolution), time of each solve (one run,
   side by side), fitted orders over the sizes.
2. The same with a constant speed and with two sources (constant speed: order=2 is exact up to
   the stopping test with one source; with two, the nodes next to where the fronts meet keep an
   O(Δx) error).
3. Cubic against multilinear evaluation of ts.solve's surface solution on the sphere (R = 0.5,
   source (-0.5, 0, 0), 4000 points of the exact sphere; far: geodesic distance ≥ 0.1 from the
   source and the antipode), with the default solve and, where ts.solve accepts it, order=2.

    python benches/box_order2.py [--sizes 21,41,81,121] [--sphere 101,201]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import tubesweep as ts

A, G = 2.0, np.array([0.5, -0.4, 0.3])
XS = np.array([0.013, -0.071, 0.05])


def speed(p):
    return A + p @ G


def exact(p):
    gn = np.linalg.norm(G)
    r2 = np.sum((p - XS) ** 2, axis=1)
    return np.arccosh(1 + gn**2 * r2 / (2 * speed(p) * speed(XS[None])[0])) / gn


def fitted_order(ns, errs):
    h = 2.0 / (np.asarray(ns, float) - 1)
    return float(np.polyfit(np.log(h), np.log(errs), 1)[0])


def linear_speed_table(sizes):
    print("## Point source in a linear-speed medium, 3D (exact: arccosh)\n")
    print(
        "| N | order | nodes max | nodes mean | points max (linear) | points mean (linear) | points max (cubic) | "
        "points mean (cubic) | iterations | solve s | order-2 / order-1 time |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    rng = np.random.default_rng(0)
    pts = rng.uniform(-0.95, 0.95, (4000, 3))
    ex_pts = exact(pts)
    rows = {1: [], 2: []}
    for n in sizes:
        grid = ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3)
        nodes = np.stack([c.reshape(-1) for c in grid.meshgrid()], axis=1)
        ex = exact(nodes)
        times = {}
        for order in (1, 2):
            t0 = time.perf_counter()
            sol, st = ts.travel_time(grid, [XS], speed=speed, order=order, return_solution=True, return_stats=True)
            times[order] = time.perf_counter() - t0
            e = np.abs(sol.values.reshape(-1) - ex)
            el = np.abs(sol(pts) - ex_pts)
            ec = np.abs(sol(pts, interpolation="cubic") - ex_pts)
            rows[order].append((e.max(), e.mean(), el.max(), el.mean(), ec.max(), ec.mean()))
            its = (
                f"{st.iterations}"
                if order == 1
                else f"{st.order2['first_order_iterations']} + {st.order2['second_order_iterations']}"
            )
            ratio = f"{times[2] / times[1]:.1f}" if order == 2 else ""
            print(
                f"| {n} | {order} | {e.max():.2e} | {e.mean():.2e} | {el.max():.2e} | {el.mean():.2e} | "
                f"{ec.max():.2e} | {ec.mean():.2e} | {its} | {times[order]:.2f} | {ratio} |",
                flush=True,
            )
    if len(sizes) > 1:
        print()
        names = [
            "nodes max",
            "nodes mean",
            "points max (linear)",
            "points mean (linear)",
            "points max (cubic)",
            "points mean (cubic)",
        ]
        for order in (1, 2):
            e = np.array(rows[order])
            fits = ", ".join(f"{names[i]} {fitted_order(sizes, e[:, i]):.2f}" for i in range(6))
            print(f"fitted order, order={order} (N = {sizes[0]}…{sizes[-1]}): {fits}")
    print()


def constant_speed_table(n):
    print(f"## Constant speed 2, N = {n} (3D)\n")
    print("| sources | order | nodes max | nodes mean | nodes ≥ 3Δx from where fronts meet, max | solve s |")
    print("|---|---|---|---|---|---|")
    grid = ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3)
    nodes = np.stack([c.reshape(-1) for c in grid.meshgrid()], axis=1)
    for src in ([XS], [XS, np.array([0.5, 0.43, -0.37])]):
        s = np.array(src)
        d = np.sort(np.linalg.norm(nodes[:, None] - s[None], axis=2), axis=1)
        ex = d[:, 0] / 2.0
        away = (d[:, 1] - d[:, 0] > 3 * grid.spacing) if len(s) > 1 else np.ones(len(d), bool)
        for order in (1, 2):
            t0 = time.perf_counter()
            u = ts.travel_time(grid, s, speed=2.0, order=order)
            dt = time.perf_counter() - t0
            e = np.abs(u.reshape(-1) - ex)
            print(
                f"| {len(s)} | {order} | {e.max():.2e} | {e.mean():.2e} | {e[away].max():.2e} | {dt:.2f} |", flush=True
            )
    print()


def sphere_table(sizes):
    print("## Cubic against multilinear evaluation on the sphere (ts.solve)\n")
    print("| N | solve | evaluation | far max | mean | max on the circle x = 0 |")
    print("|---|---|---|---|---|---|")
    R, src = 0.5, np.array([-0.5, 0.0, 0.0])
    v = np.random.default_rng(1).normal(size=(4000, 3))
    p = R * v / np.linalg.norm(v, axis=1)[:, None]
    ex = R * np.arccos(np.clip(p @ src / R**2, -1, 1))
    far = (ex >= 0.1) & (ex <= np.pi * R - 0.1)
    a = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    circle = np.stack([np.zeros_like(a), R * np.cos(a), R * np.sin(a)], axis=1)
    for n in sizes:
        grid = ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3)
        solves = [("order=1", {"order": 1})]
        try:
            ts.solve(
                lambda q: np.linalg.norm(q, axis=1) - R, ts.Grid((-1,) * 3, (1,) * 3, (21,) * 3), sources=[src], order=2
            )
            solves.append(("order=2", {"order": 2}))
        except (TypeError, ValueError):  # ts.solve has no order=2 (yet), or not for this surface
            pass
        for name, kw in solves:
            sol = ts.solve(lambda q: np.linalg.norm(q, axis=1) - R, grid, sources=[src], **kw)
            for kind in ("linear", "cubic"):
                e = np.abs(sol(p, interpolation=kind) - ex)
                ec = np.abs(sol(circle, interpolation=kind) - np.pi * R / 2)
                print(
                    f"| {n} | {name} | {kind} | {np.nanmax(e[far]):.2e} | {np.nanmean(e):.2e} | {np.nanmax(ec):.2e} |",
                    flush=True,
                )
    print()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="21,41,81,121", help="N of the 3D linear-speed runs")
    ap.add_argument("--constant", type=int, default=61, help="N of the constant-speed runs")
    ap.add_argument("--sphere", default="101,201", help="N of the sphere runs (empty: skip)")
    args = ap.parse_args()
    sizes = [int(x) for x in args.sizes.split(",") if x]
    print("# Box travel times: order=1 against order=2, and cubic evaluation (benches/box_order2.py)\n")
    linear_speed_table(sizes)
    constant_speed_table(args.constant)
    if args.sphere:
        sphere_table([int(x) for x in args.sphere.split(",") if x])


if __name__ == "__main__":
    main()
