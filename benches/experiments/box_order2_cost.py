"""The box's ``order=2`` travel times, timed alone: a 3D box with one point source, at constant
speed and on a smooth speed field, one thread, the fastest of ``--rounds`` rounds of each (CPU
time). Used to check that a change to the factored box solver (e.g. its runaway guard,
docs/box-second-order.md) costs nothing::

    .venv/bin/python benches/experiments/box_order2_cost.py              # N = 121, 3 rounds
    .venv/bin/python benches/experiments/box_order2_cost.py --n 81 --rounds 5

To compare two commits, build each in its own checkout (``make build``) and run the script in
both, alternately: this shared machine's speed drifts by 10–40% between runs.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import tubesweep as ts


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=121)
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    n = args.n
    grid = ts.Grid((-1, -1, -1), (1, 1, 1), (n, n, n))
    x = np.stack(np.meshgrid(*[np.linspace(-1, 1, n)] * 3, indexing="ij"), -1)
    speeds = {"constant": 1.0, "smooth field": 1.0 + 0.5 * np.sin(2 * x[..., 0]) * np.cos(3 * x[..., 1])}
    best = dict.fromkeys(speeds, np.inf)
    for _ in range(args.rounds):
        for name, speed in speeds.items():
            t0 = time.process_time()
            ts.travel_time(grid, [(0.1, -0.2, 0.05)], speed=speed, order=2, threads=1)
            best[name] = min(best[name], time.process_time() - t0)
    print(f"N = {n}, order=2, one thread, fastest of {args.rounds} rounds (CPU s):")
    for name, t in best.items():
        print(f"  {name:13} {t:.3f}")


if __name__ == "__main__":
    main()
