"""2D ``order=2``: the second-order phase behind its front window (``second_order.WINDOWS[1]``, as
in 3D) against no window (docs/second-order.md, docs/development/history-notes.md).

Per case and N, both: iterations, local updates per band node, whether the stagnation fallback
fired or the sweeps ran away (then the result is first order), wall time (one process, not
interleaved: read the updates), and the largest difference between the two solutions over the
band in units of the stopping tolerance. Then the far max and mean errors against the exact
distances of ``tubesweep reproduce second-order``'s star and circle (``reproduce.second_order.measure``).

    .venv/bin/python benches/experiments/window_2d.py [--sizes 201,801,1601] [--errors-only]
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

import tubesweep as ts
from tubesweep import second_order as so

from first_phase_2d import cases, grid, print_errors  # the same seven 2D cases


def _set(window: bool) -> None:
    so.WINDOWS_2D = (0.0, so.WINDOWS[1] if window else 0.0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="201,801,1601")
    ap.add_argument("--errors-only", action="store_true")
    args = ap.parse_args()
    sizes = [int(s) for s in args.sizes.split(",")]
    warnings.simplefilter("ignore")
    saved = so.WINDOWS_2D
    try:
        for name, make in () if args.errors_only else cases():
            for n in sizes:
                surf, src, kw = make(n)
                out = {}
                for window in (False, True):
                    _set(window)
                    t0 = time.perf_counter()
                    out[window] = (ts.solve(surf, grid(n), src, order=2, **kw), time.perf_counter() - t0)
                (a, ta), (b, tb) = out[False], out[True]
                both = np.isfinite(a.values) & np.isfinite(b.values)
                d = float(np.max(np.abs(a.values[both] - b.values[both])))

                def cols(s, t):
                    o = s.stats.order2
                    return (
                        f"{s.stats.iterations:5d} it {s.stats.updates / len(s.values):6.1f} upd/node "
                        f"order {s.stats.order} fallback {o['fallback_iteration']} {t:.2f} s"
                    )

                print(
                    f"{name:22s} N={n:5d}  none: {cols(a, ta)} | window: {cols(b, tb)} | updates "
                    f"{b.stats.updates / a.stats.updates:.2f} | max |none − window| {d / b.stats.order2['tol']:.0f} tol",
                    flush=True,
                )
        print_errors(_set, ((False, "none"), (True, "window")))
    finally:
        so.WINDOWS_2D = saved


if __name__ == "__main__":
    main()
