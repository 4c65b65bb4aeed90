"""2D ``order=2``: the second-order phase behind its front window (``second_order.WINDOWS[1]``, as
in 3D) against no window (docs/second-order.md, docs/development/history-notes.md).

Per case and N, both: iterations, local updates per band node, whether the stagnation fallback
fired or the sweeps ran away (then the result is first order), wall time (one process, not
interleaved: read the updates), and the largest difference between the two solutions over the
band in units of the stopping tolerance. Then the far max and mean errors against the exact
distances of ``tubesweep reproduce second-order``'s star and circle (``reproduce.second_order.measure``).

``--fast F,...``: the circle R = 0.5 whose speed rises smoothly to F times its value, 1 + (F − 1)(1 +
tanh(x/0.05))/2, from sources at four angles on the slow side, at ``--n`` (default 4001): the
window forced on (``WINDOW_2D_CONTRAST`` = ∞) against none, and which the default chose; errors
against travel times integrated along the circle. This is why the window is off where the
band's slowness varies more than ``WINDOW_2D_CONTRAST``.

    .venv/bin/python benches/experiments/window_2d.py [--sizes 201,801,1601] [--errors-only]
    .venv/bin/python benches/experiments/window_2d.py --fast 10,30 --n 4001
"""

from __future__ import annotations

import argparse
import time
import warnings
from typing import List

import numpy as np

import tubesweep as ts
from tubesweep import second_order as so

from first_phase_2d import cases, grid, print_errors  # the same seven 2D cases


def _set(window: bool) -> None:
    so.WINDOWS_2D = (0.0, so.WINDOWS[1] if window else 0.0)


def _fast(factors: List[float], n: int) -> None:
    r = 0.5
    th = np.linspace(0, 2 * np.pi, 3000, endpoint=False)
    pts = r * np.stack([np.cos(th), np.sin(th)], 1)
    saved = so.WINDOWS_2D, so.WINDOW_2D_CONTRAST
    for f in factors:

        def speed(x: np.ndarray, f: float = f) -> np.ndarray:
            return 1 + (f - 1) * 0.5 * (1 + np.tanh(x[:, 0] / 0.05))

        for th0 in np.linspace(np.pi / 2 + 0.2, 1.5 * np.pi - 0.2, 4):
            # the travel time along the circle both ways from the source, by the midpoint rule
            t = th0 + np.linspace(0, 2 * np.pi, 400_001)
            mid = 0.5 * (t[1:] + t[:-1])
            slow = 1 / speed(r * np.stack([np.cos(mid), np.sin(mid)], 1))
            along = np.concatenate([[0.0], np.cumsum(slow * np.diff(t) * r)])
            ccw = np.interp((th - th0) % (2 * np.pi), t - th0, along)
            exact = np.minimum(ccw, along[-1] - ccw)
            far = r * np.abs((th - th0 + np.pi) % (2 * np.pi) - np.pi) >= 0.1
            src = [(r * np.cos(th0), r * np.sin(th0))]
            cols, values = [], {}
            for label, windows, contrast in (("none", (0.0, 0.0), np.inf), ("window", saved[0], np.inf)):
                so.WINDOWS_2D, so.WINDOW_2D_CONTRAST = windows, contrast
                with warnings.catch_warnings(record=True) as w:
                    warnings.simplefilter("always")
                    t0 = time.perf_counter()
                    sol = ts.solve(ts.surfaces.Circle(r), grid(n), src, speed=speed, order=2)
                    sec = time.perf_counter() - t0
                values[label] = sol.values
                e = np.abs(sol(pts) - exact)[far]
                cols.append(
                    f"{label}: {sol.stats.iterations:5d} it {sol.stats.updates / len(sol.values):6.1f} upd/node "
                    f"fallback {sol.stats.order2['fallback_iteration']} {len(w)} warnings {sec:.2f} s "
                    f"max {e.max():.2e} mean {e.mean():.2e}"
                )
            so.WINDOWS_2D, so.WINDOW_2D_CONTRAST = saved
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                default = ts.solve(ts.surfaces.Circle(r), grid(n), src, speed=speed, order=2).values
            chose = [k for k, v in values.items() if np.array_equal(v, default)]
            print(
                f"fast {f:g}x N={n} source at {th0:.2f} rad  "
                + " | ".join(cols)
                + f" | the default: {chose[0] if chose else 'neither'}",
                flush=True,
            )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="201,801,1601")
    ap.add_argument("--errors-only", action="store_true")
    ap.add_argument("--fast", help="speed factors of the fast region (the circle only)")
    ap.add_argument("--n", type=int, default=4001)
    args = ap.parse_args()
    if args.fast:
        _fast([float(f) for f in args.fast.split(",")], args.n)
        return
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
