"""tubesweep against its peers, side by side in one run (issue 7).

Usage (``make bench`` runs the default)::

    .venv/bin/python benches/run.py            # default sizes, ~10–15 min on 2 cores
    .venv/bin/python benches/run.py --quick    # smallest sizes, ~1 min
    .venv/bin/python benches/run.py --full     # every size up to N = 401 (much longer)
    .venv/bin/python benches/run.py --scale    # sphere N = 1001 and 2001, Godunov only
    .venv/bin/python benches/run.py --cases "sphere:41,81;star:201" --repeats 3

For every problem (sphere, oblate spheroid, six-fold star, torus, Stanford bunny), grid size N
and method (tubesweep Godunov / Lax–Friedrichs, scikit-fmm in a tube, heat method, MMP) it
reports the max and mean error against the exact answer at fixed points on the surface, the
median wall time of ``--repeats`` runs and its ratio to tubesweep (Godunov) on the same problem,
peak memory, band points, iterations, local updates and updates per second. It prints a table
and writes ``out/bench/results.{json,md}`` and the time-vs-error plot
``out/bench/time_vs_error.png``.

Each (problem, N, method) runs in its own child process so that its memory can be measured:
the child resets the kernel's peak-RSS counter (``/proc/self/clear_refs``) after the inputs are
prepared and reads ``VmHWM`` after the first run, so "ΔRSS" is the peak resident memory the
method itself added (Rust, C++ and NumPy allocations alike); "RSS" is the child's whole peak
(interpreter and libraries included). Where ``clear_refs`` is not writable, the child's
``ru_maxrss`` minus its resident size before the run is reported instead (an upper bound).
"""

from __future__ import annotations

import argparse
import gc
import json
import math
import os
import resource
import subprocess
import sys
import time
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Tuple

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

from time_vs_error import plot  # noqa: E402

OUT = REPO / "out" / "bench"

#: problem -> grid sizes, per preset
PRESETS: Dict[str, Dict[str, List[int]]] = {
    "quick": {"sphere": [41, 81], "ellipsoid": [41], "star": [201, 401], "torus": [41], "bunny": [101]},
    "default": {
        "sphere": [41, 81, 121, 201, 401],
        "ellipsoid": [41, 81, 121, 201],
        "star": [201, 401, 801, 1601],
        "torus": [41, 81, 161],
        "bunny": [101, 201],
    },
    "full": {
        "sphere": [41, 61, 81, 121, 161, 201, 281, 401],
        "ellipsoid": [41, 81, 121, 201, 401],
        "star": [101, 201, 401, 801, 1601],
        "torus": [41, 81, 161, 321],
        "bunny": [101, 201, 301],
    },
}
#: method -> largest N run in a preset (the slow ones); absent = no limit
CAPS: Dict[str, Dict[str, int]] = {
    "quick": {},
    "default": {
        "mmp": 201,
        "tubesweep-lxf": 201,
        "mmp@ellipsoid": 121,
        "tubesweep-godunov-order2": 201,
        "tubesweep-godunov-order2@star": 1601,
    },
    "full": {},
}
#: dimension of each problem (the mesh peers apply to surfaces in 3D only)
PROBLEM_DIMS = {"sphere": 3, "ellipsoid": 3, "star": 2, "torus": 3, "bunny": 3}
METHOD_ORDER = [
    "tubesweep-godunov",
    "tubesweep-godunov-order2",
    "tubesweep-godunov-tolh",
    "tubesweep-godunov-1t",
    "tubesweep-lxf",
    "skfmm-tube",
    "heat",
    "mmp",
]
SCALE_SIZES = [1001, 2001]
#: distance from the source and from the largest distance below which errors are not "far"
FAR = 0.1
#: the accuracies whose cost :func:`time_to_accuracy` reads off each method's sizes
TARGETS = (("mean_err", 1e-3), ("mean_err", 2e-4), ("far_max_err", 1e-2), ("far_max_err", 2e-3))


# --------------------------------------------------------------------------------------------
# memory probes (child side)
# --------------------------------------------------------------------------------------------
def _status_kb(field: str) -> Optional[int]:
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith(field + ":"):
                    return int(line.split()[1])
    except OSError:
        return None
    return None


def _reset_peak() -> bool:
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")
        return True
    except OSError:
        return False


def _peak_kb(reset_ok: bool) -> int:
    if reset_ok:
        v = _status_kb("VmHWM")
        if v is not None:
            return v
    return int(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)


# --------------------------------------------------------------------------------------------
# one case (child side)
# --------------------------------------------------------------------------------------------
def run_case(problem_name: str, n: int, method_name: str, repeats: int) -> Dict[str, Any]:
    import numpy as np
    from methods import METHODS
    from problems import PROBLEMS

    method = METHODS[method_name]
    rec: Dict[str, Any] = dict(problem=problem_name, n=n, method=method_name)
    problem = PROBLEMS[problem_name](n)
    ok, why = method.applies(problem)
    if not ok:
        rec.update(status="n/a", note=why)
        return rec
    prepared = method.prepare(problem)
    method.available()  # imports the peer's module here, outside the timed and measured region
    gc.collect()
    reset_ok = _reset_peak()
    rss0 = _status_kb("VmRSS") or 0
    outcome = method.run(prepared)
    peak = _peak_kb(reset_ok)
    walls = [outcome.stats["wall"]]
    sweeps = [outcome.stats.get("sweep_s", math.nan)]
    for _ in range(repeats - 1):
        o = method.run(prepared)
        walls.append(o.stats["wall"])
        sweeps.append(o.stats.get("sweep_s", math.nan))
    exact = np.asarray(outcome.exact, dtype=float)
    vals = np.asarray(outcome.values, dtype=float)
    sel = np.isfinite(exact)
    err = np.abs(vals[sel] - exact[sel])
    # "far": at least 0.1 from the source and from the farthest distances (the cut locus on the
    # sphere and the star; a rough stand-in for it on the other surfaces)
    ex = exact[sel]
    far = (ex >= FAR) & (ex <= np.max(ex) - FAR) if ex.size else ex.astype(bool)
    far_err = err[far]
    n_nan = int(np.count_nonzero(~np.isfinite(err)))
    st = dict(outcome.stats)
    st.pop("wall", None)
    rec.update(st)
    rec.update(
        status="ok",
        max_err=float(np.nanmax(err)) if err.size and n_nan < err.size else math.nan,
        mean_err=float(np.nanmean(err)) if err.size and n_nan < err.size else math.nan,
        far_max_err=float(np.nanmax(far_err)) if far_err.size and np.isfinite(far_err).any() else math.nan,
        n_eval=int(sel.sum()),
        n_nan=n_nan,
        wall_s=float(np.median(walls)),
        walls=[float(w) for w in walls],
        sweep_s=float(np.median(sweeps)) if "sweep_s" in st else math.nan,
        peak_rss_mb=peak / 1024.0,
        delta_rss_mb=max(0, peak - rss0) / 1024.0,
        rss_method="VmHWM after clear_refs" if reset_ok else "ru_maxrss (not reset)",
        notes=problem.notes,
    )
    # the time to the answer with the set-up the method needs (marching cubes for the mesh peers;
    # tubesweep's and scikit-fmm's band searches are in their wall time already)
    rec["total_s"] = rec["wall_s"] + float(st.get("mesh_s", 0.0))
    if "updates" in st and rec["sweep_s"] > 0:
        rec["updates_per_s"] = st["updates"] / rec["sweep_s"]
    return rec


def run_child(problem: str, n: int, method: str, repeats: int, timeout: float) -> Dict[str, Any]:
    cmd = [sys.executable, str(Path(__file__).resolve()), "--case", problem, str(n), method, str(repeats)]
    # OpenBLAS's worker threads spin for about 0.1 s of CPU after every threaded call (the exact
    # references' matrix products are one, just before the timed runs): on 2 cores that takes a
    # core from whatever runs next. None of the timed methods uses NumPy's BLAS, so the children
    # run it single-threaded, which spins nothing.
    env = dict(os.environ, OPENBLAS_NUM_THREADS=os.environ.get("OPENBLAS_NUM_THREADS", "1"))
    try:
        cp = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=str(REPO), env=env)
    except subprocess.TimeoutExpired:
        return dict(problem=problem, n=n, method=method, status="timeout", note=f"over {timeout:.0f} s")
    for line in reversed(cp.stdout.splitlines()):
        if line.startswith("RESULT "):
            return json.loads(line[7:])
    tail = (cp.stderr or cp.stdout).strip().splitlines()[-3:]
    return dict(problem=problem, n=n, method=method, status="error", note=" | ".join(tail))


# --------------------------------------------------------------------------------------------
# the run (parent side)
# --------------------------------------------------------------------------------------------
def plan(
    preset: str, cases: Optional[Dict[str, List[int]]] = None, methods: Optional[Sequence[str]] = None
) -> Tuple[List[Tuple[str, int, str]], List[str]]:
    """The (problem, N, method) cases to run and notes on what is skipped and why."""
    from methods import METHODS
    from problems import bunny_available

    sizes = cases if cases is not None else PRESETS[preset]
    caps = CAPS.get(preset, {})
    notes: List[str] = []
    todo: List[Tuple[str, int, str]] = []
    names = [m for m in METHOD_ORDER if methods is None or m in methods]
    avail = {}
    for m in names:
        ok, why = METHODS[m].available()
        avail[m] = ok
        if not ok:
            notes.append(f"skipped {why}")
    for prob, ns in sizes.items():
        if prob not in PROBLEM_DIMS:
            raise SystemExit(f"unknown problem {prob!r}; choose from {', '.join(PROBLEM_DIMS)}")
        if prob == "bunny":
            ok, why = bunny_available()
            if not ok:
                notes.append(f"skipped bunny: {why}")
                continue
        for n in ns:
            for m in names:
                if not avail[m] or PROBLEM_DIMS[prob] not in METHODS[m].dims:
                    continue
                if prob == "bunny" and m == "mmp":
                    continue  # MMP on the input mesh is the bunny's exact reference
                if prob == "bunny" and m == "tubesweep-godunov-order2":
                    continue  # order=2 refuses the bunny: a scanned mesh with gaps narrower than the tube
                cap = caps.get(f"{m}@{prob}", caps.get(m))
                if cap is not None and n > cap:
                    continue
                todo.append((prob, n, m))
    if "bunny" in sizes and "mmp" in names:
        notes.append("mmp is not listed on the bunny: MMP on the input mesh is the exact reference there")
    if "bunny" in sizes and "tubesweep-godunov-order2" in names:
        notes.append(
            "tubesweep-godunov-order2 is not run on the bunny: order=2 refuses it (a scanned mesh facing itself "
            "across gaps narrower than the tube; the default runs order=1, on the band cut there and above the "
            "mesh's concave edges)"
        )
    if any(PROBLEM_DIMS[p] == 2 for p in sizes):
        notes.append("heat and mmp need a triangle mesh of a surface: not run on the 2D star")
    for m, cap in caps.items():
        notes.append(f"{m} limited to N ≤ {cap} in this preset (use --full for all sizes)")
    return todo, notes


def add_ratios(records: List[Dict[str, Any]]) -> None:
    base = {
        (r["problem"], r["n"]): r["wall_s"]
        for r in records
        if r.get("status") == "ok" and r["method"] == "tubesweep-godunov"
    }
    for r in records:
        b = base.get((r["problem"], r["n"]))
        if r.get("status") == "ok" and b:
            r["ratio"] = r["wall_s"] / b


#: errors within this relative difference count as equal (a case's error that equals tubesweep's
#: finest or coarsest one in all printed digits is then read at that size, not left out)
SAME_ERROR = 1e-9


def _usable_points(curve: Sequence[Tuple[float, float]]) -> List[Tuple[float, float]]:
    """The (error, time) points of ``curve`` with both positive and finite, in order."""
    return [(e, t) for e, t in curve if e > 0 and t > 0 and math.isfinite(e) and math.isfinite(t)]


def time_at_error(curve: Sequence[Tuple[float, float]], err: float) -> Optional[float]:
    """The time at which a method reaches the error ``err``, read off its (error, time) points
    ordered by grid size: log–log linear interpolation on the first pair of consecutive points
    whose errors bracket ``err`` (so the cheapest grid that reaches it), errors within a relative
    :data:`SAME_ERROR` of each other counting as equal; a point whose error equals ``err`` gives
    its own time. ``None`` when no pair brackets it (no extrapolation: see
    :func:`time_bound_at_error`)."""
    pts = _usable_points(curve)
    if not (err > 0 and math.isfinite(err)):
        return None
    lo_tol, hi_tol = 1 - SAME_ERROR, 1 + SAME_ERROR
    for (e0, t0), (e1, t1) in zip(pts, pts[1:]):
        if min(e0, e1) * lo_tol <= err <= max(e0, e1) * hi_tol:
            if abs(e0 - e1) <= SAME_ERROR * max(e0, e1):
                return min(t0, t1)
            s = (math.log(err) - math.log(e0)) / (math.log(e1) - math.log(e0))
            s = min(1.0, max(0.0, s))
            return math.exp(math.log(t0) + s * (math.log(t1) - math.log(t0)))
    for e, t in pts:
        if abs(e - err) <= SAME_ERROR * e:
            return t
    return None


def time_bound_at_error(curve: Sequence[Tuple[float, float]], err: float) -> Optional[Tuple[str, float]]:
    """Where :func:`time_at_error` finds nothing because ``err`` lies outside the errors of
    ``curve``: ``(">", t)`` when every point is more accurate than ``err`` (the method would
    reach it in at most ``t``, its cheapest point's time, taking a coarser grid to cost less), or
    ``("<", t)`` when every point is less accurate (it would need a finer grid than its most
    accurate point, which took ``t``: more than ``t``). The signs are those of the resulting
    ratio of another time over it. ``None`` otherwise."""
    pts = _usable_points(curve)
    if not pts or not (err > 0 and math.isfinite(err)) or time_at_error(pts, err) is not None:
        return None
    if all(e < err for e, _ in pts):
        return (">", min(t for _, t in pts))
    if all(e > err for e, _ in pts):
        return ("<", min(pts)[1])
    return None


#: the method the peers are compared with at equal error
EQUAL_ERROR_BASE = "tubesweep-godunov"

EQUAL_ERROR_NOTE = (
    "At equal accuracy: each case's wall time over the time tubesweep-godunov needs for the same max "
    "(mean) error, read off its sizes in this run by log–log interpolation (> 1: tubesweep is faster "
    "at equal accuracy). Outside the errors of its sizes, a bound: '>r' where even its coarsest size "
    "is more accurate (r: over its cheapest time), '<r' where it would need a finer size than the run "
    "has (r: over its most accurate size's time)."
)


def equal_error(records: List[Dict[str, Any]]) -> List[Dict[str, Any]]:
    """Every other method's case set beside tubesweep (Godunov) at the same accuracy: for each
    (problem, method, N), the time tubesweep needs for that case's max error and for its mean
    error (:func:`time_at_error` along tubesweep's sizes of the problem), and the case's time
    over it (> 1: tubesweep is faster at equal accuracy). Where tubesweep's sizes in this run do
    not bracket the error, that time and ratio are ``None`` and ``ratio_bound_at_*`` holds the
    bound (``">1.23"`` or ``"<0.45"``, :func:`time_bound_at_error`) when there is one."""
    ok = [r for r in records if r.get("status") == "ok"]
    rows: List[Dict[str, Any]] = []
    for prob in dict.fromkeys(r["problem"] for r in ok):
        base = sorted((r for r in ok if r["problem"] == prob and r["method"] == EQUAL_ERROR_BASE), key=lambda r: r["n"])
        if len(base) < 2:
            continue
        for m in METHOD_ORDER:
            if m == EQUAL_ERROR_BASE:
                continue
            for r in sorted((r for r in ok if r["problem"] == prob and r["method"] == m), key=lambda r: r["n"]):
                row: Dict[str, Any] = dict(
                    problem=prob, method=m, n=r["n"], max_err=r["max_err"], mean_err=r["mean_err"], wall_s=r["wall_s"]
                )
                for kind in ("max", "mean"):
                    curve = [(b[f"{kind}_err"], b["wall_s"]) for b in base]
                    t = time_at_error(curve, r[f"{kind}_err"])
                    row[f"ts_at_{kind}_s"] = t
                    row[f"ratio_at_{kind}"] = None if t is None else r["wall_s"] / t
                    bound = time_bound_at_error(curve, r[f"{kind}_err"])
                    row[f"ratio_bound_at_{kind}"] = None if bound is None else f"{bound[0]}{r['wall_s'] / bound[1]:.2f}"
                rows.append(row)
    return rows


def time_to_accuracy(records: List[Dict[str, Any]]) -> List[Dict[str, Any]]:
    """For each problem and method, the time (set-up included: ``total_s``) it needs to reach
    each of :data:`TARGETS`, read off its own sizes in this run by :func:`time_at_error`, or a
    bound (``"<t"``: more accurate at its cheapest size, which took t; ``">t"``: not reached at
    its most accurate size, which took t)."""
    ok = [r for r in records if r.get("status") == "ok"]
    rows: List[Dict[str, Any]] = []
    for prob in dict.fromkeys(r["problem"] for r in ok):
        for m in METHOD_ORDER:
            recs = sorted((r for r in ok if r["problem"] == prob and r["method"] == m), key=lambda r: r["n"])
            if not recs:
                continue
            row: Dict[str, Any] = dict(problem=prob, method=m, sizes=",".join(str(r["n"]) for r in recs))
            for key, target in TARGETS:
                curve = [(r.get(key, math.nan), r["total_s"]) for r in recs]
                t = time_at_error(curve, target)
                if t is not None:
                    row[f"{key}@{target:g}"] = f"{t:.3g}"
                    continue
                bound = time_bound_at_error(curve, target)
                # time_bound_at_error's signs are those of a ratio over it: ">" = reached sooner
                row[f"{key}@{target:g}"] = (
                    "—" if bound is None else ("≤" if bound[0] == ">" else ">") + f"{bound[1]:.3g}"
                )
            rows.append(row)
    return rows


def time_to_accuracy_table(rows: List[Dict[str, Any]]) -> str:
    keys = [f"{k}@{t:g}" for k, t in TARGETS]
    heads = [("mean" if k == "mean_err" else "far max") + f" {t:g}" for k, t in TARGETS]
    out = [
        "| problem | method | sizes | " + " | ".join(f"s to {h}" for h in heads) + " |",
        "|---|---|---|" + "---:|" * len(keys),
    ]
    for r in rows:
        out.append(
            f"| {r['problem']} | {r['method']} | {r['sizes']} | " + " | ".join(r.get(k, "—") for k in keys) + " |"
        )
    return "\n".join(out)


TIME_TO_ACCURACY_NOTE = (
    "Time to accuracy: the seconds each method needs (its set-up included: marching cubes for the mesh "
    "peers) to reach a mean error and a far max error (points at least 0.1 from the source and from the "
    "largest distances), interpolated log–log between its sizes in this run; '≤t' where its cheapest "
    "size is already more accurate, '>t' where its most accurate size is not accurate enough."
)


EQUAL_ERROR_COLUMNS = [
    ("problem", "problem", "str"),
    ("method", "method", "str"),
    ("N", "n", "str"),
    ("max err", "max_err", "err"),
    ("wall ms", "wall_s", "ms"),
    ("ts ms at that max err", "ts_at_max_s", "ms"),
    ("× ts at equal max err", "ratio_at_max", "ratio"),
    ("mean err", "mean_err", "err"),
    ("ts ms at that mean err", "ts_at_mean_s", "ms"),
    ("× ts at equal mean err", "ratio_at_mean", "ratio"),
]


def equal_error_table(rows: List[Dict[str, Any]]) -> str:
    """A Markdown table of :func:`equal_error`'s rows (a ratio's bound where it has none)."""
    out = [
        "| " + " | ".join(c[0] for c in EQUAL_ERROR_COLUMNS) + " |",
        "|" + "|".join("---" if c[2] == "str" else "---:" for c in EQUAL_ERROR_COLUMNS) + "|",
    ]
    for r in rows:
        cells = []
        for _, key, kind in EQUAL_ERROR_COLUMNS:
            v = r.get(key)
            if v is None and key.startswith("ratio_at_") and r.get(key.replace("ratio_at_", "ratio_bound_at_")):
                cells.append(r[key.replace("ratio_at_", "ratio_bound_at_")])
            else:
                cells.append(_fmt(v, kind))
        out.append("| " + " | ".join(cells) + " |")
    return "\n".join(out)


def _fmt(v: Any, kind: str) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "—"
    if kind == "err":
        return f"{v:.2e}"
    if kind == "ms":
        return f"{1e3 * v:.1f}" if v < 10 else f"{v:.1f} s"
    if kind == "ratio":
        return f"{v:.2f}"
    if kind == "mb":
        return f"{v:.0f}" if v >= 10 else f"{v:.1f}"
    if kind == "int":
        return f"{int(v):,}"
    if kind == "rate":
        return f"{v / 1e6:.1f}"
    return str(v)


COLUMNS = [
    ("problem", "problem", "str"),
    ("N", "n", "str"),
    ("method", "method", "str"),
    ("max err", "max_err", "err"),
    ("far max", "far_max_err", "err"),
    ("mean err", "mean_err", "err"),
    ("wall ms", "wall_s", "ms"),
    ("× ts", "ratio", "ratio"),
    ("sweep ms", "sweep_s", "ms"),
    ("ΔRSS MB", "delta_rss_mb", "mb"),
    ("RSS MB", "peak_rss_mb", "mb"),
    ("band pts", "band_points", "int"),
    ("iters", "iterations", "int"),
    ("updates", "updates", "int"),
    ("Mupd/s", "updates_per_s", "rate"),
]


def table(records: List[Dict[str, Any]]) -> str:
    """A Markdown table of the records (one row per problem, N and method)."""
    head = "| " + " | ".join(c[0] for c in COLUMNS) + " |"
    sep = "|" + "|".join("---" if c[2] == "str" else "---:" for c in COLUMNS) + "|"
    rows = [head, sep]
    for r in records:
        if r.get("status") != "ok":
            # (a child's error note joins its last lines with " | ": not a column separator here)
            note = str(r.get("note", "")).replace("|", "¦")
            cells = [str(r["problem"]), str(r["n"]), str(r["method"]), f"{r.get('status')}: {note}"]
            cells += [""] * (len(COLUMNS) - len(cells))
        else:
            cells = [_fmt(r.get(key), kind) for _, key, kind in COLUMNS]
        rows.append("| " + " | ".join(cells) + " |")
    return "\n".join(rows)


def machine() -> str:
    import platform

    cpu = "?"
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    load = os.getloadavg() if hasattr(os, "getloadavg") else (math.nan,) * 3
    return (
        f"{platform.node()} · {cpu} · {os.cpu_count()} logical cores · Python {platform.python_version()} · "
        f"load average at start {load[0]:.1f}"
    )


def run_bench(
    preset: str = "default",
    cases: Optional[Dict[str, List[int]]] = None,
    repeats: int = 3,
    methods: Optional[Sequence[str]] = None,
    out: Path = OUT,
    timeout: float = 900.0,
    verbose: bool = True,
    make_plot: bool = True,
) -> Dict[str, Any]:
    """Runs the benchmark and writes ``results.json``, ``results.md`` and the plot to ``out``.
    Returns ``{"records", "notes", "table", "plot"}``."""
    todo, notes = plan(preset, cases, methods)
    t0 = time.perf_counter()
    header = machine()
    if verbose:
        print(f"tubesweep benchmark — preset {preset!r}, {len(todo)} cases, median of {repeats} runs each")
        print(header)
        for nt in notes:
            print("  note:", nt)
    records: List[Dict[str, Any]] = []
    for i, (prob, n, m) in enumerate(todo):
        t1 = time.perf_counter()
        rec = run_child(prob, n, m, repeats, timeout)
        records.append(rec)
        if verbose:
            if rec.get("status") == "ok":
                msg = f"max err {rec['max_err']:.2e}  wall {1e3 * rec['wall_s']:.1f} ms  ΔRSS {rec['delta_rss_mb']:.1f} MB"
            else:
                msg = f"{rec.get('status')}: {rec.get('note', '')}"
            print(f"[{i + 1}/{len(todo)}] {prob} N={n} {m}: {msg}  ({time.perf_counter() - t1:.1f} s)", flush=True)
    add_ratios(records)
    tab = table(records)
    at_equal_error = equal_error(records)
    eq_tab = equal_error_table(at_equal_error)
    to_accuracy = time_to_accuracy(records)
    acc_tab = time_to_accuracy_table(to_accuracy)
    elapsed = time.perf_counter() - t0
    out.mkdir(parents=True, exist_ok=True)
    png = plot(records, out / "time_vs_error.png", list(PRESETS["full"]), METHOD_ORDER) if make_plot else None
    case_notes = sorted({nt for r in records for nt in r.get("notes", [])})
    all_notes = notes + case_notes
    (out / "results.json").write_text(
        json.dumps(
            dict(
                machine=header,
                preset=preset,
                repeats=repeats,
                records=records,
                equal_error=at_equal_error,
                time_to_accuracy=to_accuracy,
                notes=all_notes,
                seconds=elapsed,
            ),
            indent=1,
            default=float,
        )
    )
    md = [
        f"# tubesweep benchmark ({preset})",
        "",
        header,
        "",
        tab,
        "",
        "## At equal accuracy",
        "",
        EQUAL_ERROR_NOTE,
        "",
        eq_tab,
        "",
        "## Time to accuracy",
        "",
        TIME_TO_ACCURACY_NOTE,
        "",
        acc_tab,
        "",
    ] + [f"- {nt}" for nt in all_notes]
    (out / "results.md").write_text("\n".join(md) + "\n")
    if verbose:
        print()
        print(tab)
        print()
        for nt in all_notes:
            print("note:", nt)
        print("× ts = median wall time / tubesweep-godunov's on the same problem and N (side by side in this run)")
        print()
        print(EQUAL_ERROR_NOTE)
        print(eq_tab)
        print()
        print(TIME_TO_ACCURACY_NOTE)
        print(acc_tab)
        print()
        print(f"wrote {out / 'results.md'}, {out / 'results.json'}" + (f", {png}" if png else ""))
        print(f"total {elapsed:.0f} s")
    return dict(
        records=records,
        notes=all_notes,
        table=tab,
        plot=png,
        equal_error=at_equal_error,
        equal_error_table=eq_tab,
        time_to_accuracy=to_accuracy,
        time_to_accuracy_table=acc_tab,
    )


# --------------------------------------------------------------------------------------------
# scale runs
# --------------------------------------------------------------------------------------------
def run_scale(
    sizes: Sequence[int] = SCALE_SIZES,
    out: Path = OUT,
    timeout: float = 3600.0,
    methods: Sequence[str] = ("tubesweep-godunov",),
) -> List[Dict[str, Any]]:
    """Sphere at large N with tubesweep (Godunov; ``methods`` may add ``tubesweep-godunov-tolh``),
    one run each in a child process: time, peak memory, band points and bytes per band point."""
    # (both methods allowed here are Godunov)
    print("scale runs: sphere r=0.5, source (-0.5,0,0), Godunov two-layer, one run per N (child process)")
    print(machine())
    recs = []
    for n, m in [(n, m) for n in sizes for m in methods]:
        t1 = time.perf_counter()
        r = run_child("sphere", n, m, 1, timeout)
        label = n if len(methods) == 1 else f"{n} {m}"
        if r.get("status") == "ok":
            r["bytes_per_band_point"] = r["delta_rss_mb"] * 1024 * 1024 / r["band_points"]
            r["band_bytes_per_point"] = r["band_bytes"] / r["band_points"]
            print(
                f"N={label}: wall {r['wall_s']:.2f} s (sweeps {r['sweep_s']:.2f} s, set-up {r['setup_s']:.2f} s), "
                f"{r['band_points']:,} band points, {r['iterations']} iterations, {r['updates']:,} updates "
                f"({r['updates_per_s'] / 1e6:.1f} M/s), peak ΔRSS {r['delta_rss_mb']:.0f} MB "
                f"= {r['bytes_per_band_point']:.0f} B/point (solver-held arrays {r['band_bytes_per_point']:.0f} B/point), "
                f"max err {r['max_err']:.2e}  ({time.perf_counter() - t1:.0f} s)",
                flush=True,
            )
        else:
            print(f"N={label}: {r.get('status')}: {r.get('note')}", flush=True)
        recs.append(r)
    out.mkdir(parents=True, exist_ok=True)
    (out / "scale.json").write_text(json.dumps(dict(machine=machine(), records=recs), indent=1, default=float))
    print(f"wrote {out / 'scale.json'}")
    return recs


def parse_cases(text: str) -> Dict[str, List[int]]:
    """``"sphere:41,81;star:201"`` -> ``{"sphere": [41, 81], "star": [201]}``."""
    out: Dict[str, List[int]] = {}
    for part in text.split(";"):
        part = part.strip()
        if not part:
            continue
        if ":" not in part:
            raise SystemExit(f"--cases: expected PROBLEM:N[,N...] separated by ';', got {part!r}")
        name, ns = part.split(":", 1)
        out[name.strip()] = [int(x) for x in ns.split(",") if x.strip()]
    return out


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter
    )
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--quick", action="store_true", help="smallest sizes only (~1 min)")
    g.add_argument("--full", action="store_true", help="every size, no caps on the slow peers (long)")
    g.add_argument("--scale", action="store_true", help=f"sphere at N = {SCALE_SIZES} with tubesweep only (minutes)")
    ap.add_argument("--cases", help="override sizes, e.g. 'sphere:41,81;star:201'")
    ap.add_argument("--methods", help=f"comma-separated subset of {','.join(METHOD_ORDER)}")
    ap.add_argument("--repeats", type=int, default=3, help="runs per case; the median is reported (default 3)")
    ap.add_argument("--out", type=Path, default=OUT, help="output folder (default out/bench)")
    ap.add_argument("--timeout", type=float, default=900.0, help="seconds per case before it is abandoned")
    ap.add_argument("--case", nargs=4, metavar=("PROBLEM", "N", "METHOD", "REPEATS"), help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    if a.case:
        rec = run_case(a.case[0], int(a.case[1]), a.case[2], int(a.case[3]))
        print("RESULT " + json.dumps(rec, default=float))
        return 0
    if a.repeats < 1:
        raise SystemExit("--repeats must be at least 1")
    if a.scale:
        sizes = parse_cases(a.cases).get("sphere", SCALE_SIZES) if a.cases else SCALE_SIZES
        methods = [m.strip() for m in a.methods.split(",")] if a.methods else ["tubesweep-godunov"]
        bad = [m for m in methods if m not in ("tubesweep-godunov", "tubesweep-godunov-tolh")]
        if bad:
            raise SystemExit(f"--scale runs tubesweep-godunov and tubesweep-godunov-tolh only, not {bad}")
        run_scale(sizes, a.out, timeout=max(a.timeout, 3600.0), methods=methods)
        return 0
    preset = "quick" if a.quick else "full" if a.full else "default"
    cases = parse_cases(a.cases) if a.cases else None
    methods = [m.strip() for m in a.methods.split(",")] if a.methods else None
    run_bench(preset, cases, a.repeats, methods, a.out, a.timeout)
    return 0


if __name__ == "__main__":
    sys.exit(main())
