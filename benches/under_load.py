"""The default thread count on a busy machine (issue 35, item 6): the sphere at N = 201 solved with
the default threads, with ``threads=1`` and with every core explicitly (the fixed parallel
pipeline, the default before the adaptive choice), on a quiet machine and with other processes
keeping cores busy (one busy-looping process per core but one).

Usage::

    .venv/bin/python benches/under_load.py               # 7 alternating rounds each
    .venv/bin/python benches/under_load.py --rounds 11 --n 201

The modes alternate within each round, and the medians and their ratios are printed: on a shared
machine (other jobs compiling) absolute times drift, ratios measured side by side much less.
Targets: loaded, default / threads=1 <= 1.15; quiet, default no slower than all cores explicitly.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import tubesweep as ts  # noqa: E402

BUSY = "while True: pass"


def timed(solve) -> float:
    t = time.perf_counter()
    solve()
    return time.perf_counter() - t


def rounds(n: int, k: int, modes: dict) -> dict:
    grid = ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3)
    surface = ts.surfaces.Sphere(0.5)
    ref = None
    times: dict = {m: [] for m in modes}
    for r in range(k + 1):
        for m, threads in modes.items():
            sol = None

            def solve():
                nonlocal sol
                sol = ts.solve(surface, grid, [(0.5, 0, 0)], threads=threads, order=1)

            t = timed(solve)
            if ref is None:
                ref = sol.values
            assert np.array_equal(sol.values, ref), "the thread count changed the values"
            if r > 0:  # round 0 warms the caches
                times[m].append(t)
    return times


def report(label: str, times: dict) -> None:
    med = {m: statistics.median(v) for m, v in times.items()}
    print(f"{label}:")
    for m, v in times.items():
        print(f"  {m:14} median {1e3 * med[m]:7.1f} ms  (range {1e3 * min(v):.1f}-{1e3 * max(v):.1f}, {len(v)} rounds)")
    print(f"  default / threads=1: {med['default'] / med['threads=1']:.2f}")
    if "all cores" in med:
        print(f"  default / all cores: {med['default'] / med['all cores']:.2f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=201)
    ap.add_argument("--rounds", type=int, default=7)
    args = ap.parse_args()
    cores = os.cpu_count() or 1
    modes = {"default": 0, "threads=1": 1, "all cores": cores}
    print(f"sphere N = {args.n}, {cores} cores, {args.rounds} alternating rounds (round 0 discarded)")
    report("quiet", rounds(args.n, args.rounds, modes))
    busy = [subprocess.Popen([sys.executable, "-c", BUSY]) for _ in range(max(1, cores - 1))]
    try:
        time.sleep(0.5)
        report(f"{len(busy)} of {cores} cores kept busy by busy-looping processes", rounds(args.n, args.rounds, modes))
    finally:
        for p in busy:
            p.kill()
            p.wait()


if __name__ == "__main__":
    main()
