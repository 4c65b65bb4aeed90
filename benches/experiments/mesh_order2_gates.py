"""Why ``order="auto"`` runs first order on Spot and the bunny at n = 200 (docs/point-clouds.md,
"Meshes"): the same solves with the mesh's gates lifted (``surfaces._mesh_smooth``: the coarse-mesh
and facing-gap tests), with the fitted map (the default's) and with the exact map everywhere.
Prints, beside the default's solve (the gates in place), the order, the second-order sweeps'
runaway iteration, the mean error against MMP relative to the largest distance, and the time (each
solve once, timed from the surface built from the mesh's arrays: the map's set-up and the solve). About half a minute per mesh on two
cores.

    .venv/bin/python benches/experiments/mesh_order2_gates.py --meshes spot,bunny --n 200
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

    for name in args.meshes.split(","):
        base = ts.surfaces.from_mesh(ts.data.path(name), smooth=False)
        used = np.unique(base.faces)
        remap = -np.ones(len(base.vertices), np.int64)
        remap[used] = np.arange(len(used))
        v, f = base.vertices[used], remap[base.faces]
        src = int(np.argmax(((v - v.mean(0)) ** 2).sum(1)))
        alg = geodesic.PyGeodesicAlgorithmExact(v, f.astype(np.int32))
        exact, _ = alg.geodesicDistances(np.array([src], np.int32), None)
        for mode in ("default", "auto", "exact"):
            lift(mode != "default")
            surf = ts.surfaces.from_mesh((v, f))
            grid = surf.grid(args.n)
            if mode == "default":
                t = time.perf_counter()
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")  # the narrow gaps, as in benches/mesh_order2.py
                    sol = ts.solve(surf, grid, [v[src]])
                seconds = time.perf_counter() - t
                err = np.abs(sol.on_mesh(v) - exact) / np.max(exact)
                print(
                    f"{name} n={args.n} default (gates in place): order {sol.stats.order}, mean error "
                    f"{100 * err.mean():.3f} %, {seconds:.1f} s"
                )
                continue
            t = time.perf_counter()
            native = surf.smooth_map

            class Forced:
                def closest(self, x, h, max_distance=np.inf, _mode="auto"):  # type: ignore[no-untyped-def]
                    return native.closest(x, h, max_distance, mode)

            surf._h = grid.spacing
            surf._smooth_map = (_mesh_smooth.SAMPLE_SPACING * grid.spacing, Forced())
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                sol = ts.solve(surf, grid, [v[src]])
            seconds = time.perf_counter() - t
            err = np.abs(sol.on_mesh(v) - exact) / np.max(exact)
            o2 = sol.stats.order2 or {}
            print(
                f"{name} n={args.n} gates lifted, map={'fitted' if mode == 'auto' else 'exact'}: order {sol.stats.order}, runaway at "
                f"{o2.get('runaway_iteration')}, mean error {100 * err.mean():.3f} %, {seconds:.1f} s"
            )


if __name__ == "__main__":
    main()
