"""Why a warm start cannot reach a fraction of a cold solve on a surface that moves everywhere
(issue 47, docs/development/performance-history.md, "Warm starts on a moving surface"): step k of
the sphere → ellipsoid sequence of ``benches/moving_surfaces.py`` solved cold and warm (from step
k − 1's solution, carried onto the moved tube), each iteration's updates per band node. One
iteration is 2^D sweeps, so an iteration that visits every node costs 2^D = 8 updates per node.

The cold solve's front window keeps its cost near two such iterations; a warm start that is off
by more than the tolerance at most nodes needs at least one iteration that changes them and one
that confirms them, so no such start comes near a third of a cold solve's sweeps.

    .venv/bin/python benches/experiments/warm_lower_bound.py [N] [step]   # 121 5
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import tubesweep as ts

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from moving_surfaces import axes, phi_of  # noqa: E402

STEPS = 20


def main(n: int, k: int) -> None:
    grid = ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3)
    pts = grid.node_points(np.arange(n**3))
    phis = [phi_of(axes(j, STEPS), pts, grid.shape) for j in (k - 1, k)]
    poles = [[(0.0, 0.0, float(axes(j, STEPS)[2]))] for j in (k - 1, k)]
    tube = ts.Tube(phis[0], grid)
    prev = tube.solve(poles[0])
    moved = tube.moved(phis[1])
    runs: dict = {"cold": [], "warm": []}
    cold = moved.solve(poles[1], progress=lambda it, change, updates: runs["cold"].append((change, updates)))
    warm = moved.solve(poles[1], warm=prev, progress=lambda it, change, updates: runs["warm"].append((change, updates)))
    nodes = cold.values.size
    tol = cold.stats.order2["tol"]
    print(f"N = {n}, step {k} of {STEPS}: {nodes:,} band nodes, tolerance {tol:.2e}")
    for name, sol in (("cold", cold), ("warm", warm)):
        per = [u / nodes for _, u in runs[name]]
        print(
            f"{name}: {len(per)} iterations, {sol.stats.updates / nodes:.1f} updates per node "
            f"({sol.stats.updates / nodes / 8:.2f} full iterations); per iteration " + " ".join(f"{p:.1f}" for p in per)
        )
    print(f"max |warm − cold| = {float(np.max(np.abs(warm.values - cold.values))) / tol:.1f} tolerances")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 121, int(sys.argv[2]) if len(sys.argv) > 2 else 5)
