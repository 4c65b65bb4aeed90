"""Would re-using the moved band's per-node parts pay? (issue 47, docs/development/performance-history.md,
"Warm starts on a moving surface"). On the sphere at N = 121 with a bump of 0.3Δx at the
antipode (the ``--local`` case of ``benches/moving_surfaces.py``): the time to gather the new φ at
each band node and its six axis neighbours (what a check that a node's direction is unchanged must
read) against the time to compute the directions outright, and the band search and band
structure for scale (best of 30 calls each); then where the time of ``tube.moved`` and of the warm
solve goes (cProfile, 20 calls each, the calls above 0.5 ms per call).

    .venv/bin/python benches/experiments/moved_reuse_check.py [--n 121]
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import time

import numpy as np

import tubesweep as ts
from tubesweep import _native


def best(f, k: int = 30) -> float:
    times = []
    for _ in range(k):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return 1e3 * min(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=121)
    n = ap.parse_args().n
    grid = ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3)
    h = grid.spacing
    x, y, z = grid.meshgrid()
    phi = np.sqrt(x**2 + y**2 + z**2) - 0.5
    r2 = (x**2 + y**2 + (z + 0.5) ** 2) / 0.15**2
    bumped = phi - 0.3 * h * np.where(r2 < 1, (1 - r2) ** 4, 0.0)
    tube = ts.Tube(phi, grid)
    lin = np.ascontiguousarray(tube._tube.linear, dtype=np.int64)
    flat = bumped.reshape(-1)
    offsets = (0, 1, -1, n, -n, n * n, -n * n)
    directions = np.empty((len(lin), 3), np.float32)
    print(f"N = {n}, {len(lin):,} band nodes; best of 30, ms")
    print(f"gather φ at the node and its six neighbours: {best(lambda: [flat[lin + s] for s in offsets]):.2f}")
    print(
        "directions computed: "
        f"{best(lambda: _native.outward_directions_of_samples(bumped, h, lin.view(np.uint64), directions)):.2f}"
    )
    print(f"band search: {best(lambda: _native.band_of_samples(bumped, 4 * h)):.2f}")
    print(f"band structure: {best(lambda: _native.Band.from_linear([n] * 3, lin.view(np.uint64))):.2f}")
    src = [(0.0, 0.0, 0.5)]
    sol = tube.solve(src)
    moved = tube.moved(bumped)
    for what, call in (("tube.moved", lambda: tube.moved(bumped)), ("warm solve", lambda: moved.solve(src, warm=sol))):
        profile = cProfile.Profile()
        profile.enable()
        for _ in range(20):
            call()
        profile.disable()
        stats = pstats.Stats(profile).stats  # type: ignore[attr-defined]
        rows = sorted(((tt / 20 * 1e3, f[2]) for f, (_, _, tt, _, _) in stats.items()), reverse=True)
        print(f"{what}: " + ", ".join(f"{name} {ms:.1f}" for ms, name in rows if ms > 0.5) + " (ms per call)")


if __name__ == "__main__":
    main()
