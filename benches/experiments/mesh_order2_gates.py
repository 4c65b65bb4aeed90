"""Why ``order="auto"`` runs first order on Spot and the bunny at n = 200 (docs/point-clouds.md,
"Meshes"): the same solves with the mesh's gates lifted (``surfaces._mesh_smooth``: the coarse-mesh
and facing-gap tests), with the fitted map (the default's) and with the exact map everywhere,
beside the default's solve (the gates in place) and, with ``--finer``, the default on a finer grid.
Prints the order, the second-order sweeps' runaway iteration, the mean error against MMP relative
to the largest distance, and the time: the median of ``--repeats`` interleaved rounds, each timed
from the surface built from the mesh's arrays (the map's set-up and the solve), and its ratio to
the default's median. About two minutes per mesh on two cores (``--finer 400``: five more).

    .venv/bin/python benches/experiments/mesh_order2_gates.py --meshes spot,bunny --n 200
    .venv/bin/python benches/experiments/mesh_order2_gates.py --meshes spot --finer 400
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

import tubesweep as ts
from tubesweep.surfaces import _mesh_smooth


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--meshes", default="spot,bunny")
    ap.add_argument("--n", type=int, default=200)
    ap.add_argument("--finer", type=int, default=None, help="also the default (gates in place) on this grid")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    import pygeodesic.geodesic as geodesic

    gates = (_mesh_smooth.COARSE, _mesh_smooth.facing_pairs, _mesh_smooth.order2_obstacle)

    def lift(on: bool) -> None:
        if on:
            _mesh_smooth.COARSE = np.inf
            _mesh_smooth.facing_pairs = lambda *args, **kwargs: 0
            _mesh_smooth.order2_obstacle = lambda *args, **kwargs: None
        else:
            _mesh_smooth.COARSE, _mesh_smooth.facing_pairs, _mesh_smooth.order2_obstacle = gates

    def run(v: np.ndarray, f: np.ndarray, src: int, mode: str, n: int) -> tuple:
        """One solve: the mean error's values, the order, the runaway iteration and the time."""
        lift(mode not in ("default", "finer"))
        surf = ts.surfaces.from_mesh((v, f))
        grid = surf.grid(n)
        t = time.perf_counter()
        if mode in ("auto", "exact"):
            native = surf.smooth_map

            class Forced:
                def closest(self, x, h, max_distance=np.inf, _mode="auto"):  # type: ignore[no-untyped-def]
                    return native.closest(x, h, max_distance, mode)

            surf._h = grid.spacing
            surf._smooth_map = (_mesh_smooth.SAMPLE_SPACING * grid.spacing, Forced())
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the narrow gaps, as in benches/mesh_order2.py
            sol = ts.solve(surf, grid, [v[src]])
        seconds = time.perf_counter() - t
        lift(False)
        return sol.on_mesh(v), sol.stats.order, (sol.stats.order2 or {}).get("runaway_iteration"), seconds

    modes = [("default", args.n), ("auto", args.n), ("exact", args.n)]
    if args.finer:
        modes.append(("finer", args.finer))
    label = {
        "default": "default (gates in place)",
        "auto": "gates lifted, map=fitted",
        "exact": "gates lifted, map=exact",
    }
    for name in args.meshes.split(","):
        base = ts.surfaces.from_mesh(ts.data.path(name), smooth=False)
        used = np.unique(base.faces)
        remap = -np.ones(len(base.vertices), np.int64)
        remap[used] = np.arange(len(used))
        v, f = base.vertices[used], remap[base.faces]
        src = int(np.argmax(((v - v.mean(0)) ** 2).sum(1)))
        alg = geodesic.PyGeodesicAlgorithmExact(v, f.astype(np.int32))
        exact, _ = alg.geodesicDistances(np.array([src], np.int32), None)
        results: dict = {}
        times: dict = {m: [] for m, _ in modes}
        for _ in range(args.repeats):  # interleaved rounds
            for mode, n in modes:
                values, order, runaway, seconds = run(v, f, src, mode, n)
                results[mode] = (values, order, runaway)
                times[mode].append(seconds)
        base_time = float(np.median(times["default"]))
        for mode, n in modes:
            values, order, runaway = results[mode]
            err = np.abs(values - exact) / np.max(exact)
            median = float(np.median(times[mode]))
            print(
                f"{name} n={n} {label.get(mode, 'default (gates in place)')}: order {order}, runaway at {runaway}, "
                f"mean error {100 * err.mean():.3f} %, {median:.1f} s (median of {args.repeats}), "
                f"{median / base_time:.2f}x the default at n={args.n}"
            )


if __name__ == "__main__":
    main()
