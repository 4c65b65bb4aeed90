"""Medians of warm ``ts.solve`` calls on the benchmark sphere: wall time, set-up and sweeps.

Usage::

    .venv/bin/python benches/warm_solves.py [N] [REPEATS]      # default N = 201, 7 solves

It uses only ``ts.solve`` and ``sol.stats``, so it runs unchanged on older checkouts: to compare
two commits, build both (``make build`` in each checkout) and run it alternately in the two,
several rounds, which is how docs/benchmarks.md compares set-up times across commits. One
untimed solve first (the allocator's thresholds, the threads); OpenBLAS single-threaded as in
``make bench``.
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import tubesweep as ts  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from problems import sphere  # noqa: E402


def main() -> int:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 201
    repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 7
    p = sphere(n)
    ts.solve(p.surface, p.grid, sources=[p.source])
    wall, setup, sweeps = [], [], []
    for _ in range(repeats):
        t = time.perf_counter()
        sol = ts.solve(p.surface, p.grid, sources=[p.source])
        wall.append(time.perf_counter() - t)
        setup.append(sol.stats.setup_seconds)
        sweeps.append(sol.stats.seconds)
    ms = {k: round(1e3 * float(np.median(v)), 1) for k, v in (("wall_ms", wall), ("setup_ms", setup), ("sweeps_ms", sweeps))}
    print(json.dumps(dict(n=n, repeats=repeats, **ms)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
