"""Many sources on one surface (issue 33): the figures ``make bench`` prints for them.

Usage::

    .venv/bin/python benches/many_sources.py                # every part
    .venv/bin/python benches/many_sources.py --quick        # small sizes (a smoke run)
    .venv/bin/python benches/many_sources.py --parts sphere,dask,peers,bunny,matrix

Parts (all side by side in one run: read the ratios, the machine is shared):

* ``sphere``: the sphere (radius 0.5) at N = 101, K = 50 sources: a loop of
  ``tube.solve(threads=1)`` against ``tube.solve_many(threads=1)`` and ``threads=2``, in
  alternating rounds; sources/s and the speed-up of ``solve_many`` on 2 threads over the loop
  (target ≥ 1.8×, ≥ 60 sources/s).
* ``bunny``: the same on the Stanford bunny at N = 161 (K = 20).
* ``dask``: a Dask LocalCluster of 2 single-threaded worker processes against ``solve_many``
  (2 threads) on the same 200 sources with ``at=`` 200 points (target: within 1.3×); the
  cluster's start, the first call (the workers build the tube) and warm calls.
* ``peers``: per source, on the marching-cubes mesh of the same grid (sphere, N = 101):
  potpourri3d's heat method with its factorisation reused, exact MMP (pygeodesic), and
  ``solve_many``: sources/s and the error against the great-circle distance at the mesh's vertices.
* ``matrix``: the 1000 × 1000 distance matrix between bunny vertices at N = 161 with
  ``ts.distance_matrix`` (2 threads), its time and peak memory against the band's size.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import tubesweep as ts  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from problems import BUNNY, bunny_available, fibonacci_sphere  # noqa: E402
from run import _peak_kb, _reset_peak, _status_kb  # noqa: E402

R = 0.5


def sphere_tube(n: int) -> ts.Tube:
    return ts.Tube(ts.surfaces.Sphere(R), ts.Grid((-1, -1, -1), (1, 1, 1), (n, n, n)))


def rates(tube: ts.Tube, sources: np.ndarray, at: np.ndarray, rounds: int) -> dict:
    """Sources per second of: the loop of tube.solve(threads=1), solve_many on 1 and on 2 threads,
    in alternating rounds, the best round of each (the machine is shared); and the cores the
    process obtained in that round (its CPU time over the wall time: 2 for two busy threads on
    an otherwise idle machine, less when other jobs hold the cores)."""
    k = len(sources)
    best = {"loop": (np.inf, 0.0), "many1": (np.inf, 0.0), "many2": (np.inf, 0.0)}

    def keep(name: str, wall: float, cpu: float) -> None:
        if wall < best[name][0]:
            best[name] = (wall, cpu / wall)

    for _ in range(rounds):
        t, c = time.perf_counter(), time.process_time()
        for s in sources:
            tube.solve([s], threads=1, order=1)(at)
        keep("loop", time.perf_counter() - t, time.process_time() - c)
        for name, threads in (("many1", 1), ("many2", 2)):
            t, c = time.perf_counter(), time.process_time()
            tube.solve_many(sources, at=at, threads=threads)
            keep(name, time.perf_counter() - t, time.process_time() - c)
    out = {name: k / wall for name, (wall, _) in best.items()}
    out.update({name + "_cores": cores for name, (_, cores) in best.items()})
    return out


def print_rates(label: str, band: int, k: int, r: dict) -> None:
    print(
        f"{label}: {band:,} band nodes, {k} sources (cores: the CPU time the process got per wall second; "
        "CPU ms/source: the work per source, which stays put when the threads do not slow each other)"
    )
    rows = (
        ("loop of tube.solve(threads=1)", "loop", ""),
        ("solve_many(threads=1)", "many1", ""),
        ("solve_many(threads=2)", "many2", "; target >= 1.8x"),
    )
    for text, key, target in rows:
        cpu_ms = 1000.0 * r[key + "_cores"] / r[key]
        ratio = f"  ({r[key] / r['loop']:.2f}x the loop{target})" if key != "loop" else ""
        print(
            f"  {text:30s} {r[key]:7.1f} sources/s  cores {r[key + '_cores']:.2f}  CPU {cpu_ms:6.1f} ms/source{ratio}"
        )


def part_sphere(quick: bool) -> None:
    n, k = (41, 8) if quick else (101, 50)
    tube = sphere_tube(n)
    src = R * fibonacci_sphere(k)
    r = rates(tube, src, src, 1 if quick else 3)
    print_rates(f"sphere N = {n}", tube.band_points, k, r)
    print(f"  target >= 60 sources/s on 2 cores: {'met' if r['many2'] >= 60 else 'NOT met'} ({r['many2']:.1f})")


def bunny_tube(n: int) -> "tuple[ts.Tube, np.ndarray]":
    surf = ts.surfaces.from_mesh(str(BUNNY))
    return ts.Tube(surf, surf.grid(n=n), outer=5.0), surf.vertices


def part_bunny(quick: bool) -> None:
    ok, why = bunny_available()
    if not ok:
        print(f"bunny: skipped ({why})")
        return
    n, k = (81, 6) if quick else (161, 20)
    tube, vertices = bunny_tube(n)
    pick = np.random.default_rng(1).choice(len(vertices), size=k, replace=False)
    r = rates(tube, vertices[pick], vertices[pick], 1 if quick else 2)
    print_rates(f"bunny N = {n}", tube.band_points, k, r)


def part_dask(quick: bool) -> None:
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        print("dask: skipped (pip install tubesweep[distributed])")
        return
    n, k = (61, 40) if quick else (101, 200)
    tube = sphere_tube(n)
    src = R * fibonacci_sphere(k)
    t = time.perf_counter()
    with (
        LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None, silence_logs=40
        ) as cluster,
        Client(cluster) as client,
    ):
        start = time.perf_counter() - t
        t = time.perf_counter()
        first = tube.solve_many(src, at=src, client=client)
        first_s = time.perf_counter() - t
        local_s, dask_s = np.inf, np.inf
        for _ in range(1 if quick else 3):
            t = time.perf_counter()
            local = tube.solve_many(src, at=src, threads=2)
            local_s = min(local_s, time.perf_counter() - t)
            t = time.perf_counter()
            remote = tube.solve_many(src, at=src, client=client)
            dask_s = min(dask_s, time.perf_counter() - t)
    same = np.array_equal(local.view(np.uint64), remote.view(np.uint64)) and np.array_equal(
        first.view(np.uint64), local.view(np.uint64)
    )
    print(f"dask LocalCluster (2 worker processes x 1 thread), sphere N = {n}, {k} sources, at = {k} points")
    print(f"  cluster start {start:.2f} s; first call (workers build the tube) {first_s:.2f} s")
    print(
        f"  solve_many(threads=2) {local_s:.2f} s ({k / local_s:.1f} sources/s); dask {dask_s:.2f} s "
        f"({k / dask_s:.1f} sources/s): {dask_s / local_s:.2f}x (target <= 1.3x), overhead {dask_s - local_s:+.2f} s; "
        f"equal bit for bit: {same}"
    )


def marching_cubes_sphere(n: int) -> "tuple[np.ndarray, np.ndarray]":
    """The marching-cubes mesh of the sphere on the grid of N nodes per axis, cleaned, as the
    mesh peers of ``benches/run.py`` get it (``methods.marching_cubes_mesh``)."""
    from methods import marching_cubes_mesh
    from problems import sphere

    v, f = marching_cubes_mesh(sphere(n))
    return np.ascontiguousarray(v, dtype=float), np.ascontiguousarray(f, dtype=np.int32)


def great_circle(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    pu = p / np.linalg.norm(p, axis=1)[:, None]
    qu = q / np.linalg.norm(q, axis=1)[:, None]
    return R * np.arccos(np.clip(pu @ qu.T, -1.0, 1.0))


def part_peers(quick: bool) -> None:
    n, k = (41, 2) if quick else (101, 10)
    v, f = marching_cubes_sphere(n)
    idx = np.random.default_rng(2).choice(len(v), size=k, replace=False)
    exact = great_circle(v[idx], v)  # (k, V)
    rows = []
    tube = sphere_tube(n)
    t = time.perf_counter()
    ours = tube.solve_many(v[idx], at=v, threads=2)
    rows.append(("tubesweep solve_many (2 threads)", k / (time.perf_counter() - t), ours, tube.setup_seconds))
    t = time.perf_counter()
    ours1 = tube.solve_many(v[idx], at=v, threads=1)
    rows.append(("tubesweep solve_many (1 thread)", k / (time.perf_counter() - t), ours1, tube.setup_seconds))
    try:
        import potpourri3d as pp3d

        t = time.perf_counter()
        solver = pp3d.MeshHeatMethodDistanceSolver(v, f)
        setup = time.perf_counter() - t
        t = time.perf_counter()
        heat = np.array([solver.compute_distance(int(i)) for i in idx])
        rows.append(("potpourri3d heat method (factorisation reused)", k / (time.perf_counter() - t), heat, setup))
    except ImportError:
        print("  potpourri3d: skipped (pip install potpourri3d)")
    try:
        import pygeodesic.geodesic as geodesic

        t = time.perf_counter()
        algo = geodesic.PyGeodesicAlgorithmExact(v, f)
        setup = time.perf_counter() - t
        kk = min(k, 2 if quick else 4)
        t = time.perf_counter()
        mmp = np.array([algo.geodesicDistances(np.array([i], dtype=np.int32), None)[0] for i in idx[:kk]])
        rows.append((f"pygeodesic exact MMP ({kk} sources)", kk / (time.perf_counter() - t), mmp, setup))
    except ImportError:
        print("  pygeodesic: skipped (pip install pygeodesic)")
    print(
        f"peers per source on the marching-cubes mesh of the sphere at N = {n} ({len(v):,} vertices, {k} sources); "
        "error against the great-circle distance at every vertex"
    )
    print(f"  {'method':50s} {'sources/s':>10s} {'set-up s':>9s} {'max err':>9s} {'mean err':>9s}")
    for name, rate, values, setup in rows:
        e = np.abs(values - exact[: len(values)])
        print(f"  {name:50s} {rate:10.2f} {setup:9.2f} {np.nanmax(e):9.2e} {np.nanmean(e):9.2e}")


def part_matrix(quick: bool) -> None:
    ok, why = bunny_available()
    if not ok:
        print(f"matrix: skipped ({why})")
        return
    n, m = (81, 60) if quick else (161, 1000)
    reset = _reset_peak()
    before = _status_kb("VmRSS") or 0
    tube, vertices = bunny_tube(n)
    pick = np.sort(np.random.default_rng(3).choice(len(vertices), size=m, replace=False))
    after_tube = _peak_kb(reset)
    t = time.perf_counter()
    d, info = ts.distance_matrix(tube, None, vertices[pick], threads=2, info=True)
    seconds = time.perf_counter() - t
    peak = _peak_kb(reset)
    band_mb = tube.band_points * 8 / 2**20
    print(
        f"{m} x {m} matrix on the bunny at N = {n} ({tube.band_points:,} band nodes), 2 threads: {seconds:.1f} s "
        f"({m / seconds:.1f} sources/s)"
    )
    print(
        f"  peak RSS {peak / 1024:.0f} MB (process before the tube {before / 1024:.0f} MB, after it "
        f"{after_tube / 1024:.0f} MB); the matrix {d.nbytes / 2**20:.1f} MB; {m} band arrays would be "
        f"{m * band_mb:.0f} MB"
    )
    print(
        f"  asymmetry of the one-way estimates removed {info['asymmetry']:.3g} "
        f"(mean {info['asymmetry_mean']:.3g}; largest distance "
        f"{np.max(d[np.isfinite(d)]):.3g}), their largest diagonal {info['diagonal']:.3g}"
    )


PARTS = {"sphere": part_sphere, "bunny": part_bunny, "dask": part_dask, "peers": part_peers, "matrix": part_matrix}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--parts", default=",".join(PARTS))
    args = ap.parse_args()
    print(f"== many sources (issue 33){' --quick' if args.quick else ''}: {os.cpu_count()} CPUs ==")
    for name in args.parts.split(","):
        t = time.perf_counter()
        PARTS[name](args.quick)
        print(f"  ({name}: {time.perf_counter() - t:.1f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
