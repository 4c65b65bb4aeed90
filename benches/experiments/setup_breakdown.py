"""Where the set-up of ``ts.solve`` goes: its pieces timed one by one on a library surface.

Usage::

    .venv/bin/python benches/experiments/setup_breakdown.py                 # sphere, N = 201
    .venv/bin/python benches/experiments/setup_breakdown.py --surface star --n 801 --repeats 15

Each piece runs ``--repeats`` times in a warm process (after one untimed run) and the median is
printed, with the whole solve's ``sol.stats.setup_seconds`` and ``sol.stats.seconds`` for scale.
The pieces are those of ``LevelSet.band`` for a callable φ (docs/architecture.md): the
coarse-to-fine band search (candidates, then φ at them and the filter), the band structure,
the rim places, φ there, the outward directions and the check for gaps narrower than the tubes
(the kinks of φ, then ``_facing._warn_if_tubes_touch``); then the whole of it for the surface's φ
as a plain callable, and for the library surface itself, whose band is found in Rust in one
call (``_native.analytic_level_set_band``, the same nodes and bits). Set ``OPENBLAS_NUM_THREADS=1`` as
``make bench`` does (see README).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path
from typing import Callable, Dict, List

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import tubesweep as ts  # noqa: E402
from tubesweep import _native  # noqa: E402
from tubesweep.band import _kinks, coarse_to_fine_candidates, discover_band  # noqa: E402

from tubesweep._facing import _warn_if_tubes_touch  # noqa: E402
from tubesweep._roles import ROLE_INNER, ROLE_OUTER  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benches/: problems.py, methods.py
from problems import PROBLEMS  # noqa: E402


def median_ms(f: Callable[[], object], repeats: int) -> float:
    f()  # warm: the allocator's thresholds, the threads
    times: List[float] = []
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return 1e3 * float(np.median(times))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--surface", default="sphere", choices=["sphere", "torus", "star"])
    ap.add_argument("--n", type=int, default=201)
    ap.add_argument("--repeats", type=int, default=9)
    a = ap.parse_args()
    problem = PROBLEMS[a.surface](a.n)
    surf, grid = problem.surface, problem.grid
    h, shape = grid.spacing, list(grid.shape)
    width = 4 * h  # the default outer tube
    fn = surf._fn
    linear, values = discover_band(fn, grid, width, surf.lipschitz)
    ul = linear.view(np.uint64)
    band = _native.Band.from_linear(shape, ul)
    pos, counts = band.rim_nodes(0, len(linear))
    rim_phi = surf._phi_at_rim_places(grid, linear, pos, counts)
    direction = np.empty((len(linear), grid.ndim), np.float32)
    norm = band.outward_directions(h, values, 0, len(linear), rim_phi, direction)
    phi32 = values.astype(np.float32)
    roles = np.where(np.abs(values) <= 2 * h, ROLE_INNER, ROLE_OUTER).astype(np.uint8)
    kink = _kinks(norm, grid, linear, band)
    r = a.repeats
    rows: Dict[str, float] = {
        "band search: candidates (coarse-to-fine levels, last split)": median_ms(
            lambda: coarse_to_fine_candidates(grid, width, surf.lipschitz, lambda p, reach: np.abs(fn(p))), r
        ),
        "band search: whole (candidates, their coordinates, φ, the filter)": median_ms(
            lambda: discover_band(fn, grid, width, surf.lipschitz), r
        ),
        "band structure (Band.from_linear)": median_ms(lambda: _native.Band.from_linear(shape, ul), r),
        "rim places (Band.rim_nodes)": median_ms(lambda: band.rim_nodes(0, len(linear)), r),
        "rim coordinates and φ there": median_ms(lambda: surf._phi_at_rim_places(grid, linear, pos, counts), r),
        "outward directions (Band.outward_directions)": median_ms(
            lambda: band.outward_directions(h, values, 0, len(linear), rim_phi, direction), r
        ),
        "gaps narrower than the tubes: the kinks of φ (surface._kinks)": median_ms(
            lambda: _kinks(norm, grid, linear, band), r
        ),
        "gaps narrower than the tubes: the pairs (_facing._warn_if_tubes_touch)": median_ms(
            lambda: _warn_if_tubes_touch(grid, band, linear, roles, phi32, direction, 2.0, kink), r
        ),
        "LevelSet.band of the same φ as a callable, all of the above": median_ms(
            lambda: ts.LevelSet(fn, lipschitz=surf.lipschitz).band(grid, width), r
        ),
        "LevelSet.band of the library surface (the same band found in Rust)": median_ms(
            lambda: surf.band(grid, width), r
        ),
    }
    stats = []
    for _ in range(r + 1):
        sol = ts.solve(surf, grid, sources=[problem.source], order=1)
        stats.append((sol.stats.setup_seconds, sol.stats.seconds))
    setup, sweeps = (1e3 * float(np.median([s[k] for s in stats[1:]])) for k in (0, 1))
    print(f"{a.surface} N={a.n}: {len(linear):,} band nodes, medians of {r} warm runs [ms]")
    for name, ms in rows.items():
        print(f"  {ms:8.2f}  {name}")
    print(f"  {setup:8.2f}  ts.solve set-up (sol.stats.setup_seconds: the above, roles, sources)")
    print(f"  {sweeps:8.2f}  ts.solve native solve: preparation and sweeps (sol.stats.seconds)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
