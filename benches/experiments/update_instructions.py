"""Instructions per second-order update, to compare two builds without timing noise
(docs/development/performance-history.md, "The second-order update's instructions"): ``K``
one-thread ``order=2`` solves of the rounded cube (or the sphere) on an N³ grid, run under
valgrind; the difference between K = 3 and K = 1 over two is one solve's instructions, and the
row walk's share (``RowWalk::walk_v3``, the sweeps with the update inlined) over the printed
updates is the update's instructions::

    for k in 1 3; do RAYON_NUM_THREADS=1 valgrind --tool=cachegrind --cache-sim=no \\
        --cachegrind-out-file=cg.$k .venv/bin/python benches/experiments/update_instructions.py $k 81 cube; done
    cg_annotate cg.3 | grep walk_v3; cg_annotate cg.1 | grep walk_v3

    .venv/bin/python benches/experiments/update_instructions.py K [N] [cube|sphere]   # 81 cube
"""

from __future__ import annotations

import sys

import tubesweep as ts


def main(k: int, n: int, which: str) -> None:
    grid = ts.Grid((-1.0,) * 3, (1.0,) * 3, (n,) * 3)
    if which == "sphere":
        surf, src = ts.surfaces.Sphere(0.5), (-0.5, 0.0, 0.0)
    else:
        surf = ts.surfaces.RoundedCube()
        src = tuple(float(c) for c in surf.default_source)
    for _ in range(k):
        sol = ts.solve(surf, grid, [src], order=2, threads=1)
    print(f"{which} N = {n}: {sol.stats.updates:,} updates, {sol.stats.iterations} iterations per solve")


if __name__ == "__main__":
    main(
        int(sys.argv[1]),
        int(sys.argv[2]) if len(sys.argv) > 2 else 81,
        sys.argv[3] if len(sys.argv) > 3 else "cube",
    )
