"""What a one-off ``ts.solve`` spends outside its sweeps: the Python-side steps by their own time.

Usage::

    .venv/bin/python benches/experiments/solve_overhead.py                       # sphere N = 121, order=1
    .venv/bin/python benches/experiments/solve_overhead.py --surface torus --n 81 --order auto

Times ``--repeats`` solves in a warm process (medians: the whole call, the sweeps'
``sol.stats.seconds``), then profiles one more with ``cProfile`` and prints the functions of the
package and of the native module that took the most time themselves (``tottime``), with their
share of the sweeps' time. A check that costs a sizeable share of the sweeps shows at the top
(the thin-slab test of level sets, ``_thin_level_set.thin_share``, took 1.5 times the sweeps of
the sphere at N = 121 before it looked up each node's neighbours once).
"""

from __future__ import annotations

import argparse
import cProfile
import os
import pstats
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import tubesweep as ts  # noqa: E402

SURFACES = {
    "sphere": lambda: ts.surfaces.Sphere(0.5),
    "torus": lambda: ts.surfaces.Torus(0.5, 0.2),
    "ellipsoid": lambda: ts.surfaces.Ellipsoid(0.5, 0.5, 0.4),
}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--surface", default="sphere", choices=sorted(SURFACES))
    ap.add_argument("--n", type=int, default=121)
    ap.add_argument("--order", default="1", choices=["1", "2", "auto"])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--top", type=int, default=10)
    a = ap.parse_args()
    order = a.order if a.order == "auto" else int(a.order)
    surface = SURFACES[a.surface]()
    grid = ts.Grid((-1,) * 3, (1,) * 3, (a.n,) * 3)
    source = [surface.default_source]

    def run() -> ts.Solution:
        return ts.solve(surface, grid, source, order=order)

    run()
    walls, sweeps = [], []
    for _ in range(a.repeats):
        t = time.perf_counter()
        sol = run()
        walls.append(time.perf_counter() - t)
        sweeps.append(sol.stats.seconds)
    wall, sweep = 1e3 * float(np.median(walls)), 1e3 * float(np.median(sweeps))
    print(f"{a.surface} N = {a.n}, order={a.order}: {sol.stats.band_points:,} band nodes, ran order {sol.stats.order}")
    print(
        f"  whole call {wall:.1f} ms, sweeps {sweep:.1f} ms, the rest {wall - sweep:.1f} ms ({(wall - sweep) / sweep:.2f}x the sweeps)"
    )
    prof = cProfile.Profile()
    prof.enable()
    run()
    prof.disable()
    stats = pstats.Stats(prof).stats  # type: ignore[attr-defined]
    rows = []
    for (path, line, name), (_, _, tottime, cumtime, _) in stats.items():
        if "tubesweep" in path or path == "~":
            where = name if path == "~" else f"{os.path.basename(path)}:{line} {name}"
            rows.append((tottime, cumtime, where))
    rows.sort(reverse=True)
    print(f"  one profiled call, the {a.top} steps that took the most time themselves (ms, share of the sweeps):")
    for tottime, cumtime, where in rows[: a.top]:
        print(f"    {1e3 * tottime:8.1f}  {tottime * 1e3 / sweep:5.2f}x   {where}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
