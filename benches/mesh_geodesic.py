"""Accuracy and timing of tubesweep on a triangle mesh against exact polyhedral geodesics.

Solves the surface eikonal equation (two-layer tube, Algorithm 3, closest-point representation of
Sect. 5.2) on a mesh from one source vertex, interpolates the solution onto every vertex
(``Solution.on_mesh``) and compares with the exact polyhedral geodesic distance of the same mesh
(MMP algorithm, pygeodesic — a benchmark-only dependency: ``pip install pygeodesic``).
Errors are reported in units of the grid spacing Δx.

    .venv/bin/python benches/mesh_geodesic.py --mesh bunny --n 200 --outer 5
    .venv/bin/python benches/mesh_geodesic.py --mesh bunny --n 200 --outer 5 --no-cut   # the uncut band

Besides the errors' size: the share of vertices below the exact distance, the mean signed error,
and the mean error near the source (within a fifth of the largest distance) and far from it.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

import tubesweep as ts


def exact_geodesics(v: np.ndarray, f: np.ndarray, source: int) -> np.ndarray:
    import pygeodesic.geodesic as geodesic

    alg = geodesic.PyGeodesicAlgorithmExact(np.ascontiguousarray(v), np.ascontiguousarray(f, dtype=np.int32))
    d, _ = alg.geodesicDistances(np.array([source], dtype=np.int32), None)
    d = np.asarray(d, dtype=float)
    d[d > 1e30] = np.inf  # unreachable (other components, unused vertices)
    return d


def compare(
    mesh: str, n: int, outer: float, source: int | None = None, hamiltonian: str = "godunov", cut: bool = True
) -> dict:
    t0 = time.perf_counter()
    surf = ts.surfaces.from_mesh(ts.data.path(mesh) if mesh in ts.data.NAMES else mesh, cut_shortcuts=cut)
    t_load = time.perf_counter() - t0
    grid = surf.grid(n)
    src = surf.default_source_vertex if source is None else int(source)
    t1 = time.perf_counter()
    sol = ts.solve(surf, grid, [surf.vertices[src]], outer=outer, hamiltonian=hamiltonian)
    u = sol.on_mesh(surf.vertices)
    t_solve = time.perf_counter() - t1
    t2 = time.perf_counter()
    exact = exact_geodesics(surf.vertices, surf.faces, src)
    t_exact = time.perf_counter() - t2
    used = np.zeros(len(surf.vertices), bool)
    used[surf.used_vertices] = True
    ok = used & np.isfinite(exact)
    signed = (u[ok] - exact[ok]) / grid.spacing
    err = np.abs(signed)
    rel = np.abs(u[ok] - exact[ok]) / np.max(exact[ok])
    far = exact[ok] / np.max(exact[ok])
    return {
        "mesh": Path(mesh).name,
        "n": n,
        "grid": list(grid.shape),
        "dx": grid.spacing,
        "outer": outer,
        "hamiltonian": hamiltonian,
        "cut_shortcuts": cut,
        "cut_edges": sol.stats.cut_edges,
        "source_vertex": src,
        "vertices_compared": int(ok.sum()),
        "nan_vertices": int(np.count_nonzero(~np.isfinite(u[ok]))),
        "band_points": sol.stats.band_points,
        "iterations": sol.stats.iterations,
        "seconds_load": round(t_load, 2),
        "seconds_setup": round(sol.stats.setup_seconds, 2),
        "seconds_sweeps": round(sol.stats.seconds, 2),
        "seconds_solve_total": round(t_solve, 2),
        "seconds_exact_geodesic": round(t_exact, 2),
        "max_geodesic": float(np.max(exact[ok])),
        "err_dx_max": float(np.nanmax(err)),
        "err_dx_mean": float(np.nanmean(err)),
        "err_dx_median": float(np.nanmedian(err)),
        "err_dx_p95": float(np.nanpercentile(err, 95)),
        "err_dx_p99": float(np.nanpercentile(err, 99)),
        "err_rel_max": float(np.nanmax(rel)),
        "err_rel_mean": float(np.nanmean(rel)),
        # the sign: the share of vertices below the exact distance, the mean signed error, and the
        # mean error within the nearest fifth of the largest distance and beyond four fifths
        "below_share": float(np.mean(signed < 0)),
        "err_dx_signed_mean": float(np.nanmean(signed)),
        "err_dx_mean_near": float(np.nanmean(err[far < 0.2])),
        "err_dx_mean_far": float(np.nanmean(err[far > 0.8])),
    }


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument(
        "--mesh", default="bunny", help="a mesh file, or bunny / spot for the bundled meshes (default: bunny)"
    )
    p.add_argument("--n", type=int, nargs="+", default=[200])
    p.add_argument("--outer", type=float, default=5.0)
    p.add_argument("--source-vertex", type=int)
    p.add_argument("--hamiltonian", default="godunov")
    p.add_argument("--no-cut", action="store_true", help="from_mesh(cut_shortcuts=False): the uncut band")
    p.add_argument("--json", type=Path, help="append the results to this JSON-lines file")
    a = p.parse_args()
    for n in a.n:
        r = compare(a.mesh, n, a.outer, a.source_vertex, a.hamiltonian, not a.no_cut)
        print(json.dumps(r), flush=True)
        if a.json:
            a.json.parent.mkdir(parents=True, exist_ok=True)
            with open(a.json, "a") as fh:
                fh.write(json.dumps(r) + "\n")


if __name__ == "__main__":
    main()
