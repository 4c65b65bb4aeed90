"""Many sources on one surface (issue 33): the figures ``make bench`` prints for them.

Usage::

    .venv/bin/python benches/many_sources.py                # every part
    .venv/bin/python benches/many_sources.py --quick        # small sizes (a smoke run)
    .venv/bin/python benches/many_sources.py --parts sphere,orders,memory,dask,peers,bunny,matrix

Parts (all side by side in one run: read the ratios, the machine is shared):

* ``sphere``: the sphere (radius 0.5) at N = 101, K = 50 sources: a loop of
  ``tube.solve(threads=1)`` against ``tube.solve_many(threads=1)`` and ``threads=2``, in
  alternating rounds; sources/s and the speed-up of ``solve_many`` on 2 threads over the loop
  (target ≥ 1.8×, ≥ 60 sources/s).
* ``orders`` (issue 46): the sphere at N = 101 with 40 random surface points at the default order
  (second order there) and at ``order=1``, in 7 interleaved rounds (medians of per-round ratios,
  and the load average before and after): the loop of ``tube.solve(threads=1)`` against
  ``solve_many`` on 1 thread and on all cores (rows equal bit for bit; target ≥ 1.6× on 2 cores),
  the CPU per source of the default against ``order=1`` (target ≤ 2.5×), ``distance_matrix``'s
  mean error against the great-circle distance (target ≤ 2e-4), its symmetry and zero diagonal.
* ``memory`` (issue 46): peak RSS (each run in its own process, its ``VmHWM``) of
  ``ts.solve`` with 10,000 sources and of a 10,000-source ``solve_many`` at N = 41, the default
  order against ``order=1`` (target ≤ 3×).
* ``bunny``: the same on the Stanford bunny at N = 161 (K = 20).
* ``dask``: a Dask LocalCluster of 2 single-threaded worker processes against ``solve_many``
  (2 threads) on the same 200 sources with ``at=`` 200 points (target: within 1.3×); the
  cluster's start, the first call (the workers build the tube) and warm calls.
* ``peers``: per source, on the marching-cubes mesh of the same grid (sphere, N = 101):
  potpourri3d's heat method with its factorisation reused, exact MMP (pygeodesic), and
  ``solve_many``: sources/s and the error against the great-circle distance at the mesh's vertices.
* ``matrix``: the 1000 × 1000 distance matrix between bunny vertices at N = 161 with
  ``ts.distance_matrix`` (2 threads), its time and peak memory against the band's size; after
  other parts it runs in a process of its own (the memory they held would be counted, and the
  allocator's free memory re-used).
"""

from __future__ import annotations

import argparse
import os
import subprocess
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


def rates(tube: ts.Tube, sources: np.ndarray, at: np.ndarray, rounds: int, order: "int | str" = 1) -> dict:
    """Sources per second of: the loop of tube.solve(threads=1), solve_many on 1 and on 2 threads,
    in alternating rounds, the best round of each (the machine is shared); and the cores the
    process obtained in that round (its CPU time over the wall time: 2 for two busy threads on
    an otherwise idle machine, less when other jobs hold the cores). ``same``: the rows of
    solve_many equal the loop's bit for bit."""
    k = len(sources)
    best = {"loop": (np.inf, 0.0), "many1": (np.inf, 0.0), "many2": (np.inf, 0.0)}

    def keep(name: str, wall: float, cpu: float) -> None:
        if wall < best[name][0]:
            best[name] = (wall, cpu / wall)

    same = True
    for _ in range(rounds):
        t, c = time.perf_counter(), time.process_time()
        loop = np.array([tube.solve([s], threads=1, order=order)(at) for s in sources])
        keep("loop", time.perf_counter() - t, time.process_time() - c)
        for name, threads in (("many1", 1), ("many2", 2)):
            t, c = time.perf_counter(), time.process_time()
            many = tube.solve_many(sources, at=at, threads=threads, order=order)
            keep(name, time.perf_counter() - t, time.process_time() - c)
            same = same and np.array_equal(many.view(np.uint64), loop.view(np.uint64))
    out: dict = {name: k / wall for name, (wall, _) in best.items()}
    out["same"] = same
    out.update({name + "_cores": cores for name, (_, cores) in best.items()})
    return out


def print_rates(label: str, band: int, k: int, r: dict, target: str = "; target >= 1.8x") -> None:
    print(
        f"{label}: {band:,} band nodes, {k} sources (cores: the CPU time the process got per wall second; "
        "CPU ms/source: the work per source, which stays put when the threads do not slow each other)"
    )
    rows = (
        ("loop of tube.solve(threads=1)", "loop", ""),
        ("solve_many(threads=1)", "many1", ""),
        ("solve_many(threads=2)", "many2", target),
    )
    for text, key, target in rows:
        cpu_ms = 1000.0 * r[key + "_cores"] / r[key]
        ratio = f"  ({r[key] / r['loop']:.2f}x the loop{target})" if key != "loop" else ""
        print(
            f"  {text:30s} {r[key]:7.1f} sources/s  cores {r[key + '_cores']:.2f}  CPU {cpu_ms:6.1f} ms/source{ratio}"
        )
    print(f"  rows of solve_many equal to the loop's bit for bit: {r['same']}")


def part_sphere(quick: bool) -> None:
    n, k = (41, 8) if quick else (101, 50)
    tube = sphere_tube(n)
    src = R * fibonacci_sphere(k)
    r = rates(tube, src, src, 1 if quick else 3)
    print_rates(f"sphere N = {n}", tube.band_points, k, r)
    print(f"  target >= 60 sources/s on 2 cores: {'met' if r['many2'] >= 60 else 'NOT met'} ({r['many2']:.1f})")


def random_sphere_points(m: int, seed: int) -> np.ndarray:
    v = np.random.default_rng(seed).normal(size=(m, 3))
    return R * v / np.linalg.norm(v, axis=1)[:, None]


def interleaved(tube: ts.Tube, pts: np.ndarray, rounds: int) -> dict:
    """Issue 46's cost and speed-up protocol: in every round, one after the other, at ``order=1``
    and at the default order, the loop of ``tube.solve(threads=1)`` and ``solve_many`` on 1 thread
    and on the default thread count (``threads=0``: all cores), each read at ``pts``. Per run the
    wall time and the process's CPU time per source; per round the ratios (the default order's
    CPU per source over order=1's, solve_many's speed over the loop's), so that a change of load
    between rounds cancels out of each ratio; the medians over the rounds. ``same``: the rows of
    solve_many equal the loop's bit for bit in every run. ``stats``: per order, from the first
    round's solve_many(threads=1), the mean updates and iterations per source and the share of its
    wall time spent in the sweeps (the solves' own timings)."""
    k = len(pts)
    runs = [("loop", 1), ("many1", 1), ("many0", 0)]
    out: dict = {o: {name: {"wall": [], "cpu": []} for name, _ in runs} for o in (1, "auto")}
    same = True
    out["stats"] = {}
    for rnd in range(rounds):
        for order in (1, "auto"):
            loop = None
            for name, threads in runs:
                t, c = time.perf_counter(), time.process_time()
                if name == "loop":
                    loop = np.array([tube.solve([p], threads=1, order=order)(pts) for p in pts])
                    values = loop
                elif rnd == 0 and name == "many1":
                    values, st = tube.solve_many(pts, at=pts, threads=threads, order=order, return_stats=True)
                    wall = time.perf_counter() - t
                    out["stats"][order] = (
                        np.mean(st["updates"]),
                        np.mean(st["iterations"]),
                        np.sum(st["seconds"]) / wall,
                    )
                else:
                    values = tube.solve_many(pts, at=pts, threads=threads, order=order)
                if name != "loop":
                    same = same and np.array_equal(values.view(np.uint64), loop.view(np.uint64))
                out[order][name]["wall"].append((time.perf_counter() - t) / k)
                out[order][name]["cpu"].append((time.process_time() - c) / k)
    out["same"] = same
    return out


def part_orders(quick: bool) -> None:
    """Issue 46's targets on the sphere at N = 101 with 40 random surface points: the default
    order (second order here) against order=1, the loop of tube.solve(threads=1) against
    solve_many (interleaved rounds, medians: :func:`interleaved`), and distance_matrix's error
    against the great-circle distance."""
    n, k = (41, 8) if quick else (101, 40)
    rounds = 2 if quick else 7
    tube = sphere_tube(n)
    pts = random_sphere_points(k, seed=46)
    load = os.getloadavg()
    r = interleaved(tube, pts, rounds)
    load_after = os.getloadavg()
    med = np.median
    print(
        f"sphere N = {n} ({tube.band_points:,} band nodes), {k} random surface points, each solve read at them; "
        f"{rounds} interleaved rounds, medians; load average (1 min) {load[0]:.1f} before, {load_after[0]:.1f} after, "
        f"{os.cpu_count()} CPUs"
    )
    for order in (1, "auto"):
        loop = np.array(r[order]["loop"]["wall"])
        for name, text in (
            ("loop", "loop of tube.solve(threads=1)"),
            ("many1", "solve_many(threads=1)"),
            ("many0", "solve_many() (all cores)"),
        ):
            wall, cpu = np.array(r[order][name]["wall"]), np.array(r[order][name]["cpu"])
            speed = f"  {med(loop / wall):.2f}x the loop" if name != "loop" else ""
            target = "  (target >= 1.6x)" if (order, name) == ("auto", "many0") else ""
            print(
                f"  order={order!r:6s} {text:32s} {1 / med(wall):6.1f} sources/s  CPU {1000 * med(cpu):6.1f} ms/source  "
                f"cores {med(cpu / wall):.2f}{speed}{target}"
            )
    for name, text in (("many1", "1 thread"), ("many0", "all cores")):
        a, b = np.array(r["auto"][name]["cpu"]), np.array(r[1][name]["cpu"])
        print(
            f"  solve_many ({text}): CPU per source at the default order / order=1: {med(a / b):.2f}x, per round "
            f"{np.round(a / b, 2).tolist()} (target <= 2.5x)"
        )
    for order in (1, "auto"):
        updates, iterations, share = r["stats"][order]
        print(
            f"  solve_many(threads=1, order={order!r}), per source: {updates / 1e6:.2f} million updates in "
            f"{iterations:.1f} iterations; {100 * share:.0f}% of the wall time in the sweeps"
        )
    a, b = np.array(r["auto"]["many1"]["cpu"]), np.array(r[1]["many1"]["cpu"])
    per_update = med(a / b) / (r["stats"]["auto"][0] / r["stats"][1][0])
    print(f"  CPU per update at the default order / order=1 (solve_many, 1 thread): {per_update:.2f}x")
    print(f"  rows of solve_many equal to the loop's bit for bit at both orders: {r['same']}")
    exact = great_circle(pts, pts)
    for order in (1, "auto"):
        t = time.perf_counter()
        d, info = ts.distance_matrix(tube, None, pts, threads=2, info=True, order=order)
        sec = time.perf_counter() - t
        e = np.abs(d - exact)[~np.eye(k, dtype=bool)]
        print(
            f"  distance_matrix order={order!r} (ran order {info['order']}): mean error {e.mean():.2e} "
            f"(target <= 2e-4 at the default), max {e.max():.2e}; symmetric {np.array_equal(d, d.T)}, zero diagonal "
            f"{bool(np.all(np.diag(d) == 0))}; asymmetry removed {info['asymmetry']:.2e}, largest one-way diagonal "
            f"{info['diagonal']:.2e}; {k / sec:.1f} sources/s"
        )
        if order == "auto":
            default = d
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        print("  dask: skipped (pip install tubesweep[distributed])")
        return
    with (
        LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None, silence_logs=40
        ) as cluster,
        Client(cluster) as client,
    ):
        remote = ts.distance_matrix(tube, None, pts, client=client)
    print(
        f"  distance_matrix on a Dask LocalCluster (2 processes) equal to the local one bit for bit: {np.array_equal(remote, default)}"
    )


# A child's peak resident memory: its own VmHWM (Linux; run.py's reader, imported first in every
# child, the baseline's too). ``ru_maxrss`` is not it: Linux carries the parent's high-water mark
# at the fork over to the child (a child of a large process reads at least the parent's size), so
# after the other parts it read the bench process's size
# (tests/test_many_sources.py::test_the_bench_memory_of_a_child_is_its_own_not_its_parents).
_PEAK_OF_THIS_PROCESS = f"""
import resource, sys
sys.path.insert(0, {str(Path(__file__).resolve().parent)!r})
from run import _status_kb
def peak_kb():
    return _status_kb("VmHWM") or resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
"""

_MEMORY_CHILD = (
    _PEAK_OF_THIS_PROCESS
    + r"""
import sys
import numpy as np
import tubesweep as ts
what, order, n, k = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
order = order if order == "auto" else int(order)
v = np.random.default_rng(0).normal(size=(k, 3))
src = 0.5 * v / np.linalg.norm(v, axis=1)[:, None]
grid = ts.Grid((-1, -1, -1), (1, 1, 1), (n, n, n))
at = src[:100]
if what == "solve":
    sol = ts.solve(ts.surfaces.Sphere(0.5), grid, src, order=order)
    u = sol(at)
    ran = sol.stats.order
else:
    tube = ts.Tube(ts.surfaces.Sphere(0.5), grid)
    u, st = tube.solve_many(src, at=at, threads=2, order=order, return_stats=True)
    ran = st["order"]
print(peak_kb(), ran)
"""
)


def part_memory(quick: bool) -> None:
    """Peak resident memory (VmHWM, each run in its own process) of ts.solve with
    10,000 sources and of a 10,000-source solve_many (at 100 points) on the sphere at N = 41, at
    the default order against order=1."""
    n, k = (41, 1000) if quick else (41, 10000)
    base = int(
        subprocess.run(
            [
                sys.executable,
                "-c",
                _PEAK_OF_THIS_PROCESS + "import tubesweep\nprint(peak_kb())",
            ],
            capture_output=True,
            text=True,
            check=True,
        ).stdout
    )
    print(
        f"peak RSS, sphere N = {n}, {k} sources (each run in its own process; importing tubesweep alone: {base / 1024:.0f} MB)"
    )
    for what, label in (
        ("solve", f"ts.solve with {k} sources, read at 100 points"),
        ("many", f"solve_many of {k} sources at 100 points (2 threads)"),
    ):
        peak = {}
        for order in ("1", "auto"):
            t = time.perf_counter()
            out = subprocess.run(
                [sys.executable, "-c", _MEMORY_CHILD, what, order, str(n), str(k)],
                capture_output=True,
                text=True,
                check=True,
            ).stdout.split()
            peak[order] = int(out[0])
            print(
                f"  {label}, order={order} (ran {out[1]}): {peak[order] / 1024:.0f} MB ({time.perf_counter() - t:.1f} s)"
            )
        print(f"  ratio default / order=1: {peak['auto'] / peak['1']:.2f} (target <= 3)")


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
    for order in (1, 2):
        for threads in (2, 1):
            t = time.perf_counter()
            ours = tube.solve_many(v[idx], at=v, threads=threads, order=order)
            rate = k / (time.perf_counter() - t)
            rows.append(
                (
                    f"tubesweep solve_many order={order} ({threads} thread{'s' if threads > 1 else ''})",
                    rate,
                    ours,
                    tube.setup_seconds,
                )
            )
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


PARTS = {
    "sphere": part_sphere,
    "orders": part_orders,
    "memory": part_memory,
    "bunny": part_bunny,
    "dask": part_dask,
    "peers": part_peers,
    "matrix": part_matrix,
}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--parts", default=",".join(PARTS))
    args = ap.parse_args()
    print(f"== many sources (issues 33, 46){' --quick' if args.quick else ''}: {os.cpu_count()} CPUs ==")
    names = args.parts.split(",")
    for i, name in enumerate(names):
        t = time.perf_counter()
        if name == "matrix" and i > 0:
            argv = [sys.executable, __file__, "--parts", "matrix"] + (["--quick"] if args.quick else [])
            out = subprocess.run(argv, capture_output=True, text=True, check=True).stdout
            print("\n".join(out.splitlines()[1:-1]))  # without its heading and its own timing line
        else:
            PARTS[name](args.quick)
        print(f"  ({name}: {time.perf_counter() - t:.1f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
