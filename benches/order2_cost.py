"""The cost of ``order=2`` against ``order=1`` (issue 31's cost targets): time and memory per band
node of ``ts.solve`` on the same surface, grid and source, measured side by side.

Usage::

    .venv/bin/python benches/order2_cost.py                    # sphere N = 201, 7 rounds
    .venv/bin/python benches/order2_cost.py --rounds 5 --n 201 --surfaces sphere,ellipsoid,torus

Each round runs order=1 and order=2 one after the other (alternating which goes first), with the
default thread count and with ``threads=1``; the medians and the ratios order=2 / order=1 are
printed, with the machine's load average (a shared machine's absolute times drift; ratios measured
side by side much less). Memory: ``sol.stats.band_bytes / sol.stats.band_points``, everything each
solve holds per band node (band structure, values, roles, flags, per-node geometry).
Targets: time ratio <= 2.5, memory ratio <= 1.5.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import tubesweep as ts  # noqa: E402

#: The closed level-set surfaces of the library, each with a source on it. The sphere is the
#: issue's configuration (R = 0.5 in [-1, 1]^3, source (-0.5, 0, 0)).
SURFACES = {
    "sphere": lambda: (ts.surfaces.Sphere(0.5), (-0.5, 0.0, 0.0)),
    "ellipsoid": lambda: (ts.surfaces.Ellipsoid(), None),
    "torus": lambda: (ts.surfaces.Torus(), None),
    "double-torus": lambda: (ts.surfaces.DoubleTorus(), None),
    "rounded-cube": lambda: (ts.surfaces.RoundedCube(), None),
}


def measure(surface, grid, source, rounds: int, threads: int) -> dict:
    times: dict = {1: [], 2: []}
    per_node = {}
    for r in range(rounds):
        for order in (1, 2) if r % 2 == 0 else (2, 1):
            t = time.perf_counter()
            sol = ts.solve(surface, grid, [source], order=order, threads=threads)
            times[order].append(time.perf_counter() - t)
            per_node[order] = sol.stats.band_bytes / sol.stats.band_points
            if order == 2 and not sol.stats.converged:
                raise SystemExit("order=2 did not converge")
    return {"t1": statistics.median(times[1]), "t2": statistics.median(times[2]), "b1": per_node[1], "b2": per_node[2]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=201)
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--surfaces", default="sphere")
    args = ap.parse_args(argv)
    grid = ts.Grid((-1.0,) * 3, (1.0,) * 3, (args.n,) * 3)
    print(f"order=2 against order=1, ts.solve at N = {args.n}, {args.rounds} alternating rounds, medians")
    print(f"load average before: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    print("| surface | threads | order=1 s | order=2 s | time ratio | order=1 B/node | order=2 B/node | memory ratio |")
    print("|---|---|---|---|---|---|---|---|")
    worst = [0.0, 0.0]
    for name in args.surfaces.split(","):
        surface, source = SURFACES[name]()
        if source is None:
            source = tuple(float(c) for c in surface.default_source)
        ts.solve(surface, grid, [source], order=2)  # warm-up (band caches, imports)
        for threads in (0, 1):
            m = measure(surface, grid, source, args.rounds, threads)
            ratio, mem = m["t2"] / m["t1"], m["b2"] / m["b1"]
            worst = [max(worst[0], ratio), max(worst[1], mem)]
            label = "default" if threads == 0 else str(threads)
            print(
                f"| {name} | {label} | {m['t1']:.3f} | {m['t2']:.3f} | {ratio:.2f} | {m['b1']:.1f} | {m['b2']:.1f} | "
                f"{mem:.2f} |"
            )
            sys.stdout.flush()
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    print(f"worst time ratio {worst[0]:.2f} (target <= 2.5), worst memory ratio {worst[1]:.2f} (target <= 1.5)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
