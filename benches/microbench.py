"""Kernel throughput through the public API: local updates per second (per core) from
``sol.stats`` (issue 7 target: ≥ 100 M updates/s per core in the 3D Godunov tube kernel,
parallel speed-up ≥ 1.7× on 2 cores).

For each scheme and grid size it solves the sphere (radius 0.5, source (−0.5, 0, 0)) with
``ts.solve`` in child processes with ``RAYON_NUM_THREADS`` = 1 and = the number of cores, and
reports ``stats.updates / stats.seconds`` (the native solve: its preparation and the sweeps; band
construction excluded), that rate
divided by the thread count, and the speed-up of the sweeps. Every case runs once per round (the
second of two solves in a fresh process), ``--repeats`` rounds; times are medians over the rounds
and the ratios medians of the per-round ratios, so that this shared machine's drift, which moves
single timings by 20–40%, cancels out of them. With a single-threaded kernel the
two thread counts give the same time (speed-up ≈ 1).

Each case runs twice: with the paper's plain sweeps (``paper_sweeps=True``) and with the default
sweeps (the coupled Godunov update, the outer rim swept last), which solve the same equations with
fewer local updates; "× paper" is the paper sweeps' time over the default's at the same thread
count (> 1: the default is faster). The default's updates are fewer and dearer (the cheap ones are
the ones it skips), so its updates per second are lower while its time is shorter: compare times.

Then a second table times the kernel alone: the Rust ``sphere`` example (built here with cargo)
with ``PLAIN=1``, the paper's sweeps to the letter without the active flags (every node but the
fixed ones updated in every sweep), Godunov, at ``--kernel-sizes`` on 1 thread and on all cores,
interleaved the same way. Its rate counts no skipped node, so it is the kernel's rate per update;
the "prefetched" column says in how many iterations the sweeps fetched the rows ahead
(``SolveOptions::row_prefetch_above``: when the visited rows' data exceed a share of the
last-level cache). With more than one thread count it also measures, before every round, the
round trip of a cache line between the first two CPUs (the Rust ``core_to_core`` example) and
prints the rounds' range: the parallel sweeps pass values and flags between the cores at every
tile, so the speed-up falls as that latency grows, and on a virtual machine the latency is the
host's placement of the virtual CPUs, which can change within minutes (this machine has shown
about 42 ns and 360–440 ns). When a size's rounds ran at both, it also prints the median
speed-up of each group.

    .venv/bin/python benches/microbench.py [--sizes 101,201] [--repeats 3] [--kernel-sizes 101,201,401]
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence

REPO = Path(__file__).resolve().parents[1]


def _child(n: int, hamiltonian: str, repeats: int, paper: bool) -> Dict[str, Any]:
    import tubesweep as ts
    import tubesweep.surfaces as tss

    grid = ts.Grid(lower=(-1, -1, -1), upper=(1, 1, 1), shape=(n, n, n))
    sphere = tss.Sphere(radius=0.5)
    secs: List[float] = []
    st = None
    for _ in range(repeats):
        sol = ts.solve(sphere, grid, sources=[(-0.5, 0.0, 0.0)], hamiltonian=hamiltonian, paper_sweeps=paper, order=1)
        st = sol.stats
        secs.append(st.seconds)
    assert st is not None
    med = statistics.median(secs)
    return dict(
        n=n,
        hamiltonian=hamiltonian,
        band_points=st.band_points,
        iterations=st.iterations,
        updates=st.updates,
        sweep_s=med,
        updates_per_s=st.updates / med if med > 0 else float("nan"),
        converged=bool(st.converged),
        seconds=[float(s) for s in secs],
    )


def measure(n: int, hamiltonian: str, threads: int, repeats: int, paper: bool = False) -> Dict[str, Any]:
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    cmd = [sys.executable, str(Path(__file__).resolve()), "--child", str(n), hamiltonian, str(repeats), str(int(paper))]
    cp = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=str(REPO))
    for line in reversed(cp.stdout.splitlines()):
        if line.startswith("RESULT "):
            rec = json.loads(line[7:])
            rec["threads"] = threads
            rec["sweeps"] = "paper" if paper else "default"
            return rec
    raise RuntimeError(f"child failed: {cp.stderr.strip()[-500:]}")


def run(
    sizes: Sequence[int] = (101, 201),
    schemes: Sequence[str] = ("godunov", "lxf"),
    repeats: int = 3,
    threads: Optional[Sequence[int]] = None,
) -> List[Dict[str, Any]]:
    """Runs every (sweeps, threads) case of a scheme and size once per round, ``repeats`` rounds,
    so that the machine's drift affects all cases alike; the speed-up and "× paper" are medians
    of the per-round ratios (the two times of a ratio come from the same round)."""
    cores = os.cpu_count() or 1
    tlist = sorted(set(threads or (1, cores)))
    rows = []
    print(
        f"sphere r=0.5, two-layer, sol.stats (native solve: preparation and sweeps), {repeats} interleaved rounds (medians); {cores} cores"
    )
    print(
        f"{'scheme':8} {'N':>5} {'sweeps':>7} {'threads':>7} {'band pts':>10} {'iters':>5} {'updates':>13} "
        f"{'sweep ms':>9} {'Mupd/s':>8} {'Mupd/s/core':>11} {'speed-up':>8} {'× paper':>8} {'core-to-core ns':>15}"
    )
    multi = len(tlist) > 1
    notes = []
    for h in schemes:
        for n in sizes:
            cases = [(paper, t) for paper in (True, False) for t in tlist]
            runs: Dict[Any, List[Dict[str, Any]]] = {c: [] for c in cases}
            trips: List[Optional[float]] = []
            for _ in range(repeats):
                # the latency between the two cores right before the round's runs
                trips.append(core_round_trip_ns() if multi else None)
                for paper, t in cases:
                    runs[(paper, t)].append(measure(n, h, t, 2, paper))
            secs = {c: [r["seconds"][-1] for r in runs[c]] for c in cases}  # the warm (second) solve
            for paper, t in cases:
                r = dict(runs[(paper, t)][0])
                ratios = _fill_rates(r, secs[(paper, t)], secs[(paper, tlist[0])], t, trips)
                r["vs_paper"] = statistics.median(a / b for a, b in zip(secs[(True, t)], secs[(paper, t)]))
                rows.append(r)
                print(
                    f"{h:8} {n:5d} {r['sweeps']:>7} {t:7d} {r['band_points']:10,d} {r['iterations']:5d} "
                    f"{r['updates']:13,d} {1e3 * r['sweep_s']:9.1f} {r['updates_per_s'] / 1e6:8.1f} "
                    f"{r['per_core'] / 1e6:11.1f} {r['speedup']:8.2f} {r['vs_paper']:8.2f} "
                    f"{_latency_column(trips) if multi else '':>15}",
                    flush=True,
                )
                split = _split_speedups(trips, ratios) if t != tlist[0] else None
                if split:
                    notes.append(f"  {h}, N = {n}, {r['sweeps']} sweeps, {t} threads: {split}")
    _print_split_notes(notes)
    return rows


SPHERE_EXAMPLE = REPO / "target" / "release" / "examples" / "sphere"
CORE_TO_CORE_EXAMPLE = REPO / "target" / "release" / "examples" / "core_to_core"
_EXAMPLE_LINE = re.compile(r"band=(\d+) .*iterations=(\d+) updates=(\d+) sweeps=([0-9.]+)s .*prefetched=(\d+)")


def build_sphere_example() -> Path:
    """Builds the Rust ``sphere`` example (cargo's incremental build: seconds when up to date)."""
    subprocess.run(
        ["cargo", "build", "--release", "-q", "-p", "tubesweep-core", "--example", "sphere"], cwd=str(REPO), check=True
    )
    return SPHERE_EXAMPLE


_CORE_TO_CORE_BUILT = False


def core_round_trip_ns(trips: int = 50_000) -> Optional[float]:
    """The Rust ``core_to_core`` example's median round trip of a cache line between the first two
    CPUs (ns), or None where it cannot be measured (no Rust toolchain, not Linux, fewer than two
    CPUs, pinning refused, or no answer within a minute). The parallel sweeps hand values and flags
    from core to core at every tile, so their speed-up falls as this grows; on a virtual machine it
    is the host's placement of the virtual CPUs, and it can change between runs, even within one.
    The example is built at the first call."""
    global _CORE_TO_CORE_BUILT
    try:
        if not _CORE_TO_CORE_BUILT:
            subprocess.run(
                ["cargo", "build", "--release", "-q", "-p", "tubesweep-core", "--example", "core_to_core"],
                cwd=str(REPO),
                check=True,
            )
            _CORE_TO_CORE_BUILT = True
        cp = subprocess.run(
            [str(CORE_TO_CORE_EXAMPLE), str(trips)], capture_output=True, text=True, check=True, timeout=60
        )
    except (OSError, subprocess.SubprocessError):
        return None
    m = re.search(r"round_trip_ns=([0-9.]+)", cp.stdout)
    return float(m.group(1)) if m else None


# rounds whose core-to-core round trips differ by more than this factor are shown as a range and
# their speed-ups split into the nearer and the farther rounds
_LATENCY_SPREAD = 1.5


def _latency_column(trips: List[Optional[float]]) -> str:
    """The rounds' core-to-core round trips (ns): the smallest when they agree to within
    ``_LATENCY_SPREAD``, else ``min–max``; ``n/a`` when none was measured."""
    got = [t for t in trips if t is not None]
    if not got:
        return "n/a"
    lo, hi = min(got), max(got)
    return f"{lo:.0f}" if hi < _LATENCY_SPREAD * lo else f"{lo:.0f}–{hi:.0f}"


def _ns_range(values: List[float]) -> str:
    lo, hi = min(values), max(values)
    return f"{lo:.0f} ns" if round(lo) == round(hi) else f"{lo:.0f}–{hi:.0f} ns"


def _split_speedups(trips: List[Optional[float]], speedups: List[float]) -> Optional[str]:
    """When the rounds ran at two latencies (the host moved the virtual CPUs: the largest round
    trip at least ``_LATENCY_SPREAD`` times the smallest), the median speed-up of the rounds on
    either side of the geometric midpoint; None otherwise, or without two measured rounds."""
    pairs = [(t, s) for t, s in zip(trips, speedups) if t is not None and t > 0]
    if len(pairs) < 2:
        return None
    lo, hi = min(t for t, _ in pairs), max(t for t, _ in pairs)
    if hi < _LATENCY_SPREAD * lo:
        return None
    mid = (lo * hi) ** 0.5
    near = [(t, s) for t, s in pairs if t < mid]
    far = [(t, s) for t, s in pairs if t >= mid]

    def group(g: List[Any]) -> str:
        n = len(g)
        return (
            f"{statistics.median(s for _, s in g):.2f} in {n} round{'s' if n > 1 else ''} at "
            f"{_ns_range([t for t, _ in g])}"
        )

    return f"speed-up {group(near)}, {group(far)}"


def _fill_rates(
    r: Dict[str, Any], secs: List[float], base_secs: List[float], threads: int, trips: List[Optional[float]]
) -> List[float]:
    """Sets a case's median sweep time, its updates per second (in all and per core), its
    speed-up over the first thread count (the median of the per-round ratios) and the rounds'
    core-to-core round trips; returns the per-round speed-ups."""
    r["sweep_s"] = statistics.median(secs)
    r["updates_per_s"] = r["updates"] / r["sweep_s"] if r["sweep_s"] > 0 else float("nan")
    r["per_core"] = r["updates_per_s"] / threads
    ratios = [a / b for a, b in zip(base_secs, secs)]
    r["speedup"] = statistics.median(ratios)
    r["core_round_trip_ns"] = trips
    return ratios


def _print_split_notes(notes: List[str]) -> None:
    if notes:
        print("rounds at two core-to-core latencies (examples/core_to_core.rs, measured before each round):")
        print("\n".join(notes))


def kernel_once(example: Path, n: int, threads: int) -> Dict[str, Any]:
    """One run of the example's flag-free sweeps (``PLAIN=1``: every node but the fixed ones
    updated in every sweep, pointwise, the rim in every sweep): the kernel's own rate."""
    env = dict(os.environ, PLAIN="1")
    cp = subprocess.run(
        [str(example), str(n), "godunov", str(threads)], capture_output=True, text=True, env=env, check=True
    )
    m = _EXAMPLE_LINE.search(cp.stdout)
    if m is None:
        raise RuntimeError(f"unexpected output of {example}: {cp.stdout[-500:]}")
    band, iters, updates, secs, prefetched = m.groups()
    return dict(
        n=n,
        threads=threads,
        band_points=int(band),
        iterations=int(iters),
        updates=int(updates),
        seconds=float(secs),
        prefetch_iterations=int(prefetched),
    )


def run_kernel(
    sizes: Sequence[int] = (101, 201, 401),
    repeats: int = 3,
    threads: Optional[Sequence[int]] = None,
    example: Optional[Path] = None,
) -> List[Dict[str, Any]]:
    """The 3D Godunov kernel alone: the Rust ``sphere`` example's flag-free sweeps, one run of
    every (size, thread count) per round, ``repeats`` rounds; time = the native solve (no Python,
    no band construction), the speed-up a median of per-round ratios."""
    cores = os.cpu_count() or 1
    tlist = sorted(set(threads or (1, cores)))
    example = example or build_sphere_example()
    print(
        f"the kernel alone: Rust sphere example, PLAIN=1 (every node in every sweep), Godunov, "
        f"{repeats} interleaved rounds (medians); {cores} cores"
    )
    multi = len(tlist) > 1
    print(
        f"{'N':>5} {'threads':>7} {'band pts':>10} {'iters':>5} {'updates':>13} {'sweep ms':>9} {'Mupd/s':>8} "
        f"{'Mupd/s/core':>11} {'speed-up':>8} {'prefetched':>10} {'core-to-core ns':>15}"
    )
    rows = []
    notes = []
    for n in sizes:
        runs: Dict[int, List[Dict[str, Any]]] = {t: [] for t in tlist}
        trips: List[Optional[float]] = []
        for _ in range(repeats):
            # the latency between the two cores right before the round's runs
            trips.append(core_round_trip_ns() if multi else None)
            for t in tlist:
                runs[t].append(kernel_once(example, n, t))
        secs = {t: [r["seconds"] for r in runs[t]] for t in tlist}
        for t in tlist:
            r = dict(runs[t][0])
            ratios = _fill_rates(r, secs[t], secs[tlist[0]], t, trips)
            rows.append(r)
            print(
                f"{n:5d} {t:7d} {r['band_points']:10,d} {r['iterations']:5d} {r['updates']:13,d} "
                f"{1e3 * r['sweep_s']:9.1f} {r['updates_per_s'] / 1e6:8.1f} {r['per_core'] / 1e6:11.1f} "
                f"{r['speedup']:8.2f} {r['prefetch_iterations']:>4d} of {r['iterations']:<3d} "
                f"{_latency_column(trips) if multi else '':>15}",
                flush=True,
            )
            split = _split_speedups(trips, ratios) if t != tlist[0] else None
            if split:
                notes.append(f"  N = {n}, {t} threads: {split}")
    _print_split_notes(notes)
    return rows


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(description="updates per second per core of the sweep kernel, via ts.solve")
    ap.add_argument("--sizes", default="101,201", help="grid sizes N, comma-separated (default 101,201)")
    ap.add_argument("--schemes", default="godunov,lxf")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--threads", help="thread counts to compare (default: 1 and all cores)")
    ap.add_argument(
        "--kernel-sizes",
        default="101,201,401",
        help="grid sizes of the kernel-alone table (the Rust example's flag-free sweeps); '' skips it",
    )
    ap.add_argument("--child", nargs=4, help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.child:
        print("RESULT " + json.dumps(_child(int(a.child[0]), a.child[1], int(a.child[2]), a.child[3] == "1")))
        return 0
    th = [int(x) for x in a.threads.split(",")] if a.threads else None
    run([int(x) for x in a.sizes.split(",")], a.schemes.split(","), a.repeats, th)
    if a.kernel_sizes.strip():
        print()
        run_kernel([int(x) for x in a.kernel_sizes.split(",")], a.repeats, th)
    return 0


if __name__ == "__main__":
    sys.exit(main())
