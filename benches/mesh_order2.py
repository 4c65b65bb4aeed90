"""Meshes at second order (docs/point-clouds.md, "Meshes"): tubesweep's default on a triangle mesh
(``from_mesh``'s smooth closest-point map, ``order="auto"``) side by side with the exact map at first
order (``smooth=False``), potpourri3d's heat method and exact polyhedral geodesics (MMP, pygeodesic),
error and time, in one run. Times are medians of interleaved repeats (A, B, C, D, A, B, ...), each
with its set-up (tubesweep: from_mesh + solve + on_mesh; heat: the solver's set-up + one solve; MMP:
the algorithm's set-up + one solve).

    .venv/bin/python benches/mesh_order2.py            # the tables of docs/point-clouds.md
    .venv/bin/python benches/mesh_order2.py --quick    # smaller grids and fewer repeats

Errors: the icosphere (trimesh's, subdivisions 5, radius 0.5: 10,242 vertices) and a spheroid mesh
(the same vertices with z scaled to 0.35) against the smooth surface's exact geodesics (great
circles; geographiclib), at the vertices; Spot and the bunny against MMP on the same mesh, relative
to the largest distance.
"""

from __future__ import annotations

import argparse
import json
import time
import warnings
from typing import Any, Callable, Dict, List, Optional

import numpy as np

import tubesweep as ts


def icosphere() -> tuple:
    import trimesh

    m = trimesh.creation.icosphere(subdivisions=5, radius=0.5)
    return np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)


def used_only(v: np.ndarray, f: np.ndarray) -> tuple:
    used = np.unique(f)
    remap = -np.ones(len(v), np.int64)
    remap[used] = np.arange(len(used))
    return v[used], remap[f]


def runners(v: np.ndarray, f: np.ndarray, src: int, grid: Any) -> Dict[str, Callable[[], np.ndarray]]:
    import potpourri3d as pp3d
    import pygeodesic.geodesic as geodesic

    def tubesweep(smooth: bool) -> Callable[[], np.ndarray]:
        def run() -> np.ndarray:
            surf = ts.surfaces.from_mesh((v, f), smooth=smooth)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # narrow gaps on Spot and the bunny, reported below
                sol = ts.solve(surf, grid, [v[src]])
            run.order = sol.stats.order  # type: ignore[attr-defined]
            run.why = sol.stats.order_fallback  # type: ignore[attr-defined]
            return sol.on_mesh(v)

        return run

    def heat() -> np.ndarray:
        return pp3d.MeshHeatMethodDistanceSolver(v, f).compute_distance(src)

    def mmp() -> np.ndarray:
        alg = geodesic.PyGeodesicAlgorithmExact(np.ascontiguousarray(v), np.ascontiguousarray(f, dtype=np.int32))
        d, _ = alg.geodesicDistances(np.array([src], dtype=np.int32), None)
        return np.asarray(d, float)

    return {
        "tubesweep default": tubesweep(True),
        "tubesweep smooth=False": tubesweep(False),
        "heat method": heat,
        "MMP": mmp,
    }


def compare(name: str, v: np.ndarray, f: np.ndarray, src: int, grid: Any, exact: Optional[np.ndarray], repeats: int):
    run = runners(v, f, src, grid)
    times: Dict[str, List[float]] = {k: [] for k in run}
    values: Dict[str, np.ndarray] = {}
    for _ in range(repeats):
        for k, fn in run.items():
            t = time.perf_counter()
            values[k] = fn()
            times[k].append(time.perf_counter() - t)
    relative = exact is None
    ref = values["MMP"] if relative else exact
    scale = float(np.max(ref)) if relative else 1.0
    rows = []
    for k in run:
        if relative and k == "MMP":
            continue
        err = np.abs(values[k] - ref) / scale
        row = {
            "mesh": name,
            "vertices": len(v),
            "N": int(max(grid.shape)),
            "method": k,
            "mean": float(np.mean(err)),
            "max": float(np.max(err)),
            "seconds": float(np.median(times[k])),
            "relative": relative,
        }
        if k.startswith("tubesweep"):
            row["order"] = run[k].order  # type: ignore[attr-defined]
            row["why first order"] = run[k].why  # type: ignore[attr-defined]
        rows.append(row)
    return rows


def great_circle(v: np.ndarray, src: int) -> np.ndarray:
    u = v / np.linalg.norm(v, axis=1, keepdims=True)
    return 0.5 * np.arccos(np.clip(u @ u[src], -1, 1))


def spheroid_exact(v: np.ndarray, src: int, a: float, c: float) -> np.ndarray:
    from geographiclib.geodesic import Geodesic

    geod = Geodesic(a, 1 - c / a)
    lat = np.degrees(np.arctan2((a / c) ** 2 * v[:, 2], np.hypot(v[:, 0], v[:, 1])))
    lon = np.degrees(np.arctan2(v[:, 1], v[:, 0]))
    return np.array([geod.Inverse(lat[src], lon[src], la, lo)["s12"] for la, lo in zip(lat, lon)])


def table(rows: List[Dict]) -> str:
    out = ["| mesh | N | method | mean error | max error | time | order |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        unit = " %" if r["relative"] else ""
        k = 100 if r["relative"] else 1
        fmt = (lambda x: f"{k * x:.3f}{unit}") if r["relative"] else (lambda x: f"{x:.2e}")
        out.append(
            f"| {r['mesh']} | {r['N'] if r['method'].startswith('tubesweep') else '—'} | {r['method']} | "
            f"{fmt(r['mean'])} | {fmt(r['max'])} | {r['seconds']:.2f} s | {r.get('order', '—')} |"
        )
    return "\n".join(out)


def main(argv: Optional[List[str]] = None) -> List[Dict]:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="N = 61 / n = 100 and one repeat")
    ap.add_argument("--json", help="also write the rows to this file")
    args = ap.parse_args(argv)
    repeats = 1 if args.quick else 3
    n_box, n_mesh = (61, 100) if args.quick else (101, 200)
    rows: List[Dict] = []
    v, f = icosphere()
    src = int(np.argmin(v[:, 0]))
    box = ts.Grid((-1,) * 3, (1,) * 3, (n_box,) * 3)
    rows += compare("icosphere (vs great circles)", v, f, src, box, great_circle(v, src), repeats)
    vs = v * np.array([1.0, 1.0, 0.7])
    top = int(np.argmax(vs[:, 2]))
    rows += compare(
        "spheroid 0.5/0.35 (vs geographiclib)", vs, f, top, box, spheroid_exact(vs, top, 0.5, 0.35), repeats
    )
    for name in ("spot", "bunny"):
        base = ts.surfaces.from_mesh(ts.data.path(name), smooth=False)
        vv, ff = used_only(base.vertices, base.faces)
        s = int(np.argmax(((vv - vv.mean(0)) ** 2).sum(1)))  # the default source: an ear tip
        rows += compare(f"{name} (vs MMP, relative)", vv, ff, s, base.grid(n_mesh), None, repeats)
    print(table(rows))
    for r in rows:
        if r.get("why first order"):
            print(f"{r['mesh']}, {r['method']}: first order because {r['why first order']}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(rows, fh, indent=1)
    return rows


if __name__ == "__main__":
    main()
