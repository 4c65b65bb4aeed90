"""What the input checks of docs/architecture.md ("Errors") guard against: each case run with its
check switched off (patched out in this process only), next to the answer it should give, and the
re-distancing retry timed on and off.

Usage::

    .venv/bin/python benches/experiments/input_checks.py            # every case, 4 alternating rounds of the retry
    .venv/bin/python benches/experiments/input_checks.py --rounds 2 --skip-spot

Sections:

* ``disc``: a disc smaller than a grid cell (``_prepare._check_surface_spans_two_cells`` off): the
  distance across the disc against the exact ``√2·r``;
* ``metric``: ``Metric(1e30·I)`` with the default ``tol`` (the Hamiltonian's tolerance check
  off): iterations, the share of the band left unreached, and whether it reported convergence;
* ``tiny-speed``: ``ts.travel_time`` at speed 1e-200 (the travel-time range check off): the
  corner's value × speed against the exact √2;
* ``box-side``: ``|x|² − 0.25`` re-distanced on [−0.55, 0.55]² at N = 15 against the exact circle's
  band (public API only, so it runs unchanged on older commits: on 989debf it shows the band
  nodes dropped before the fix);
* ``retry``: the torus quartic at N = 81 re-distanced with the retry of unsettled candidates off
  (``redistance._on_zero_set_within`` patched to find none) and on, alternating: band nodes and
  the band search's median time;
* ``sharp-box``: the box's ``|x|_∞ − 0.5`` re-distanced at N = 41 and 81, with the early stop of
  the extension layer's widening patched out and as it is, alternating: the medians of the time
  to the error and their ratio;
* ``spot``: the path from Spot's vertex 2000 (grid(81), three sources) with the progress threshold
  off (``geodesic_paths.PROGRESS_FRACTION = 0``) and on: its points and how many repeat the last.
"""

from __future__ import annotations

import argparse
import importlib
import os
import statistics
import time
import warnings

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import tubesweep as ts  # noqa: E402

# the modules themselves (``tubesweep.solve`` the attribute is the function; the tube's checks
# live in ``_prepare``)
euclidean, geodesic_paths, hamiltonian_solve, redistance, prepare = (
    importlib.import_module(f"tubesweep.{m}")
    for m in ("euclidean", "geodesic_paths", "_hamiltonian_solve", "redistance", "_prepare")
)

SPOT = ts.data.spot()


class patched:
    """Sets ``module.name = value`` for a ``with`` block."""

    def __init__(self, module, name, value):
        self.module, self.name, self.value = module, name, value

    def __enter__(self):
        self.old = getattr(self.module, self.name)
        setattr(self.module, self.name, self.value)

    def __exit__(self, *exc):
        setattr(self.module, self.name, self.old)


def disc() -> None:
    grid = ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3)
    h = grid.spacing
    print("disc (check off): r/h  u(0, r, 0)  exact √2·r  relative error")
    with patched(prepare, "_check_surface_spans_two_cells", lambda *a: None):
        for k in (0.02, 0.5, 1.0, 2.0):
            r = k * h
            u = ts.solve(ts.surfaces.Disc(radius=r), grid, [(r, 0, 0), (-r, 0, 0)], order=1)([(0, r, 0)])[0]
            print(f"  {k:5.2f}  {u:.5g}  {np.sqrt(2) * r:.5g}  {abs(u - np.sqrt(2) * r) / (np.sqrt(2) * r):.3f}")


def metric() -> None:
    grid = ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3)
    with patched(hamiltonian_solve, "check_tolerance_scale", lambda *a, **k: None):
        sol = ts.solve(
            ts.surfaces.Sphere(0.5), grid, [(-0.5, 0, 0)], hamiltonian=ts.hamiltonians.Metric(1e30 * np.eye(3))
        )
    print(
        f"metric 1e30·I (check off): {sol.stats.iterations} iterations, {np.isinf(sol.values).mean():.1%} of the band "
        f"unreached, converged={sol.stats.converged}"
    )


def tiny_speed() -> None:
    grid = ts.Grid((-1, -1), (1, 1), (41, 41))
    with patched(euclidean, "check_tolerance_scale", lambda *a, **k: None):
        u, st = ts.travel_time(grid, [(0, 0)], speed=1e-200, return_stats=True)
    print(
        f"travel_time at speed 1e-200 (check off): u(corner)·F = {u[0, 0] * 1e-200:.4g} against √2 = {np.sqrt(2):.4g}, "
        f"converged={st.converged}"
    )


def box_side() -> None:
    L, n = 0.55, 15
    grid = ts.Grid((-L, -L), (L, L), (n, n))
    X, Y = grid.meshgrid()
    exact = ts.solve(ts.surfaces.Circle(0.5), grid, [(-0.5, 0.0)], order=1)
    sol = ts.solve(ts.LevelSet(X**2 + Y**2 - 0.25, redistance=True), grid, [(-0.5, 0.0)], order=1)
    print(
        f"box side: re-distanced band {len(sol.linear)} nodes against the circle's {len(exact.linear)}, "
        f"{int(np.count_nonzero(~np.isfinite(sol.values)))} at inf, converged={sol.stats.converged}"
    )


def retry(rounds: int) -> None:
    grid = ts.Grid((-1,) * 3, (1,) * 3, (81,) * 3)
    X, Y, Z = grid.meshgrid()
    phi = (X**2 + Y**2 + Z**2 + 0.5**2 - 0.2**2) ** 2 - 4 * 0.5**2 * (X**2 + Y**2)
    none = lambda surface, grid, x, y, reach: np.zeros(len(x), bool)  # noqa: E731
    times: dict = {"off": [], "on": []}
    nodes: dict = {}
    for _ in range(rounds):
        for label in ("off", "on"):
            with patched(redistance, "_on_zero_set_within", none if label == "off" else redistance._on_zero_set_within):
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    t = time.perf_counter()
                    band = ts.LevelSet(phi, redistance=True).band(grid, 4 * grid.spacing)
                    times[label].append(time.perf_counter() - t)
            nodes[label] = len(band.linear)
    for label in ("off", "on"):
        ts_ = times[label]
        print(
            f"retry {label:3}: band {nodes[label]:,} nodes, band search median {statistics.median(ts_):.2f} s "
            f"(range {min(ts_):.2f}–{max(ts_):.2f}, {rounds} alternating rounds)"
        )
    print(f"  ratio of medians on/off: {statistics.median(times['on']) / statistics.median(times['off']):.2f}")


def sharp_box(sizes: tuple, rounds: int) -> None:
    """The box's |x|_∞ − 0.5 re-distanced, source at the top face's centre: the nodes next to its
    edges cannot be projected onto the zero level set, so the inner tube lacks neighbours. With
    the early stop patched out (``_prepare._lacking_neighbours`` made to report new nodes at every
    widening, as before the stop) the solve widens the layer four times before its error; now it
    stops at the first widening that brings none of them in. The two alternate, ``rounds`` times;
    the medians of the time to the error and their ratio are printed."""

    def box(n):
        grid = ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3)
        X, Y, Z = grid.meshgrid()
        return grid, ts.LevelSet(np.maximum(np.maximum(np.abs(X), np.abs(Y)), np.abs(Z)) - 0.5, redistance=True)

    counter = iter(range(1 << 30))
    fresh = lambda *args: np.array([next(counter)])  # noqa: E731
    for n in sizes:
        grid, surface = box(n)
        times: dict = {"widening to the end": [], "now": []}
        outcome: dict = {}
        for _ in range(rounds):
            for label, patch in (("widening to the end", fresh), ("now", prepare._lacking_neighbours)):
                with patched(prepare, "_lacking_neighbours", patch), warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    t = time.perf_counter()
                    try:
                        ts.solve(surface, grid, [(0.0, 0.0, 0.5)], order=1)
                        outcome[label] = "solved"
                    except ValueError as e:
                        outcome[label] = f"ValueError: {str(e)[:60]}..."
                    times[label].append(time.perf_counter() - t)
        for label, ts_ in times.items():
            print(
                f"sharp box N={n}, {label}: {outcome[label]} median {statistics.median(ts_):.1f} s "
                f"(range {min(ts_):.1f}–{max(ts_):.1f}, {rounds} alternating rounds)"
            )
        print(
            f"  ratio of medians now/before: {statistics.median(times['now']) / statistics.median(times['widening to the end']):.2f}"
        )


def spot() -> None:
    if not SPOT.is_file():
        print("spot: skipped (the bundled spot mesh is missing)")
        return
    mesh = ts.surfaces.from_mesh(SPOT)
    sol = ts.solve(mesh, mesh.grid(81), mesh.vertices[[285, 0, 1000]], order=1)
    for label, fraction in (("off", 0.0), ("on", geodesic_paths.PROGRESS_FRACTION)):
        with patched(geodesic_paths, "PROGRESS_FRACTION", fraction), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            path = sol.geodesic_path(mesh.vertices[2000])
        repeats = int(np.count_nonzero(np.linalg.norm(np.diff(path, axis=0), axis=1) < 1e-9))
        print(f"spot path, progress threshold {label:3}: {len(path)} points, {repeats} repeating the one before")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=4)
    ap.add_argument("--skip-spot", action="store_true")
    args = ap.parse_args()
    disc()
    metric()
    tiny_speed()
    box_side()
    retry(args.rounds)
    sharp_box((41, 81), args.rounds)
    if not args.skip_spot:
        spot()


if __name__ == "__main__":
    main()
