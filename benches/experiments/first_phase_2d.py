"""2D ``order=2``: phase 1 on the first-order driver against the module's own factored sweeps
(``second_order._OWN_FIRST_PHASE``; docs/second-order.md, docs/development/history-notes.md).

Per case and N, both starts: iterations, local updates, whether the stagnation fallback fired,
wall time (one process, not interleaved: read the updates), and the largest difference between
the two solutions over the band in units of the stopping tolerance. Then the far max and mean
errors against the exact distances of ``tubesweep reproduce second-order``'s star and circle
(``reproduce.second_order.measure``) for both starts.

    .venv/bin/python benches/experiments/first_phase_2d.py [--sizes 201,801,1601]
"""

from __future__ import annotations

import argparse
import time
import warnings
from typing import Any, Callable, Sequence, Tuple

import numpy as np

import tubesweep as ts
from tubesweep import second_order as so
from tubesweep.reproduce.second_order import circle_case, measure, star_case


def grid(n: int) -> ts.Grid:
    return ts.Grid((-1.0, -1.0), (1.0, 1.0), (n, n))


def cases():
    yield "circle", lambda n: (ts.surfaces.Circle(0.5), [(0.5, 0.0)], {})
    yield "star", lambda n: (ts.surfaces.Star(), [(0.5, 0.0)], {})
    yield "ellipse", lambda n: (ts.surfaces.Ellipse(0.6, 0.35), [(0.6, 0.0)], {})
    three = [(0.5, 0.0), (-0.25, 0.4330127), (-0.25, -0.4330127)]
    yield "circle, 3 sources", lambda n: (ts.surfaces.Circle(0.5), three, {})
    yield (
        "circle, speed field",
        lambda n: (ts.surfaces.Circle(0.5), [(0.5, 0.0)], {"speed": lambda x: 1.0 + 0.5 * x[:, 1]}),
    )

    def mask(n):
        g = grid(n)
        X = np.stack(g.meshgrid(), -1)
        return ts.LevelSet.from_mask(np.linalg.norm(X - (0.05, 0.0), axis=-1) < 0.55, g, smooth=1.5), [(0.6, 0.0)], {}

    yield "smoothed mask", mask
    cp = ts.ClosestPoint(lambda x: 0.5 * x / np.linalg.norm(x, axis=1, keepdims=True))
    yield "circle, closest points", lambda n: (cp, [(0.5, 0.0)], {})


def print_errors(use: Callable[[Any], None], variants: Sequence[Tuple[Any, str]]) -> None:
    """The far max and mean errors against the exact distances of ``tubesweep reproduce
    second-order``'s star and circle, a column per variant (``use(value)`` switches to it)."""
    print("errors against the exact distances (far max, mean)")
    for name, make, ns in (
        ("star", star_case, (201, 401, 801, 1601)),
        ("circle", circle_case, (101, 201, 401, 801, 1601)),
    ):
        case = make()
        for n in ns:
            row = []
            for value, label in variants:
                use(value)
                r = measure(case, n, 2)
                row.append(f"{label} {r['far_max']:.3e} {r['mean']:.3e} ({r['iterations']} it)")
            print(f"{name:7s} N={n:5d}  " + " | ".join(row), flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="201,801,1601")
    sizes = [int(s) for s in ap.parse_args().sizes.split(",")]
    warnings.simplefilter("ignore")
    saved = dict(so._OWN_FIRST_PHASE)
    try:
        for name, make in cases():
            for n in sizes:
                surf, src, kw = make(n)
                out = {}
                for own in (True, False):
                    so._OWN_FIRST_PHASE[2] = own
                    t0 = time.perf_counter()
                    out[own] = (ts.solve(surf, grid(n), src, order=2, **kw), time.perf_counter() - t0)
                (a, ta), (b, tb) = out[True], out[False]
                both = np.isfinite(a.values) & np.isfinite(b.values)
                d = float(np.max(np.abs(a.values[both] - b.values[both])))
                print(
                    f"{name:22s} N={n:5d}  own: {a.stats.iterations:4d} it {a.stats.updates:10,d} upd "
                    f"fallback {a.stats.order2['fallback_iteration']} {ta:.2f} s | driver: {b.stats.iterations:4d} it "
                    f"{b.stats.updates:10,d} upd fallback {b.stats.order2['fallback_iteration']} {tb:.2f} s | "
                    f"updates {b.stats.updates / a.stats.updates:.2f} | max |own − driver| {d / a.stats.order2['tol']:.0f} tol",
                    flush=True,
                )

        def use(own: bool) -> None:
            so._OWN_FIRST_PHASE[2] = own

        print_errors(use, ((True, "own"), (False, "driver")))
    finally:
        so._OWN_FIRST_PHASE.update(saved)


if __name__ == "__main__":
    main()
