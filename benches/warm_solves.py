"""Medians of warm ``ts.solve`` calls on the benchmark sphere: wall time, set-up and sweeps.

Usage::

    .venv/bin/python benches/warm_solves.py [N] [REPEATS]      # default N = 201, 7 solves
    .venv/bin/python benches/warm_solves.py 201 7 --dense      # φ handed in as an array
    .venv/bin/python benches/warm_solves.py 101 3 --redistance # φ = |x|² − r² as an array
    .venv/bin/python benches/warm_solves.py 101 1 --redistance --callable  # … as a callable
    .venv/bin/python benches/warm_solves.py 201 7 --tube       # ts.Tube built once, then tube.solve
    .venv/bin/python benches/warm_solves.py 201 5 --bunny      # the bunny (surface.grid(n=N))
    .venv/bin/python benches/warm_solves.py 201 7 --ellipsoid  # the bench's spheroid
    .venv/bin/python benches/warm_solves.py 161 3 --library mobius  # a library surface

It uses only ``ts.solve`` and ``sol.stats``, so it runs unchanged on older checkouts: to compare
two commits, build both (``make build`` in each checkout) and run it alternately in the two,
several rounds, which is how docs/benchmarks.md compares set-up times across commits. One
untimed solve first (the allocator's thresholds, the threads), whose peak resident memory above
the process's before it is printed as ``first_solve_delta_rss_mb`` (the ΔRSS of
``benches/run.py``); OpenBLAS single-threaded as in
``make bench``. With ``--dense`` the surface is ``ts.LevelSet`` of φ sampled on the whole grid
(the sphere's exact signed distance, an array of the grid's shape, as a user with a level set
array hands it in) instead of the library's ``Sphere``, whose φ is found coarse-to-fine. With
``--redistance`` the array is ``|x|² − r²`` (the same sphere, not a distance function) and the
surface ``ts.LevelSet(array, redistance=True)``; it also prints the band's candidates by a bound on
|∇φ| over the whole box and, on checkouts that have it, by the bound near each node (for a
callable, by the gradient at the candidates); with ``--redistance --callable`` the same φ is a
callable instead of an array. With
``--tube`` the solves are ``tube.solve`` on one ``ts.Tube`` built before them (its build time is
printed as ``tube_build_ms``); with ``--bunny`` the problem is the bench's bunny instead of the
sphere, with ``--ellipsoid`` the bench's oblate spheroid (the library's ``Ellipsoid(0.5, 0.5, 0.4)``;
it needs geographiclib for the exact answers, as ``make bench`` installs), and with ``--library
NAME`` the library surface ``ts.surfaces.REGISTRY[NAME]()`` on its default box with N nodes per
axis, from its default source.
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path
from types import SimpleNamespace

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import tubesweep as ts  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from problems import bunny, ellipsoid, sphere  # noqa: E402
from run import _peak_kb, _reset_peak, _status_kb  # noqa: E402


def redistance_candidates(surface: ts.LevelSet, grid: ts.Grid) -> dict:
    """The candidates of the re-distanced band (outer = 4Δx) by a bound on |∇φ| over the whole
    box and, where this checkout has it, by the bound near each node that it uses."""
    from tubesweep import _native
    from tubesweep import redistance as rd

    w = 4 * grid.spacing
    L = rd.estimate_lipschitz(surface, grid)
    if not surface.is_dense:  # a callable: found coarse-to-fine, then narrowed where that exists
        from tubesweep.band import discover_band

        cand, values = discover_band(surface._fn, grid, L * w, L)
        out = {"whole_box_candidates": len(cand)}
        if hasattr(rd, "_narrowed_by_candidate_gradients"):
            out["local_bound_candidates"] = len(rd._narrowed_by_candidate_gradients(surface, grid, w, L, cand, values))
        return out
    out = {"whole_box_candidates": len(_native.band_of_samples(surface._array, L * w)[0])}
    if hasattr(_native, "redistance_candidates_of_samples"):
        out["local_bound_candidates"] = len(
            _native.redistance_candidates_of_samples(surface._array, grid.spacing, w)[0]
        )
    return out


def main() -> int:
    flags = {"--dense", "--redistance", "--callable", "--tube", "--bunny", "--ellipsoid"}
    redistance = "--redistance" in sys.argv
    dense = ("--dense" in sys.argv or redistance) and "--callable" not in sys.argv
    use_tube = "--tube" in sys.argv
    argv = sys.argv[1:]
    library = None
    if "--library" in argv:
        i = argv.index("--library")
        if i + 1 >= len(argv) or argv[i + 1] not in ts.surfaces.REGISTRY:
            raise SystemExit(f"--library takes a surface name: one of {', '.join(ts.surfaces.REGISTRY)}")
        if dense or "--callable" in argv:
            raise SystemExit(
                "--library solves on the library surface itself: not with --dense, --redistance or --callable"
            )
        library = argv[i + 1]
        argv = argv[:i] + argv[i + 2 :]
    args = [a for a in argv if a not in flags]
    n = int(args[0]) if len(args) > 0 else 201
    repeats = int(args[1]) if len(args) > 1 else 7
    extra = {}
    if library is not None:
        surf = ts.surfaces.REGISTRY[library]()
        lower, upper = surf.default_box
        p = SimpleNamespace(
            surface=surf, grid=ts.Grid(lower=lower, upper=upper, shape=(n,) * len(lower)), source=surf.default_source
        )
        extra["library"] = library
    else:
        p = bunny(n) if "--bunny" in sys.argv else ellipsoid(n) if "--ellipsoid" in sys.argv else sphere(n)
    if redistance and "--callable" in sys.argv:
        centre = np.asarray(p.surface.center, dtype=float)
        surface = ts.LevelSet(lambda x: np.sum((x - centre) ** 2, axis=1) - 0.25, redistance=True)  # r = 0.5
    elif redistance:
        d = p.dense_phi(p.grid)  # |x − c| − r
        surface = ts.LevelSet(d * (d + 2 * 0.5), redistance=True)  # |x − c|² − r², r = 0.5
    elif dense:
        surface = ts.LevelSet(p.dense_phi(p.grid))
    else:
        surface = p.surface
    if use_tube:
        t = time.perf_counter()
        tube = ts.Tube(surface, p.grid)
        extra["tube_build_ms"] = round(1e3 * (time.perf_counter() - t), 1)

        def run() -> ts.Solution:
            return tube.solve([p.source], order=1)
    else:

        def run() -> ts.Solution:
            return ts.solve(surface, p.grid, sources=[p.source], order=1)

    # the peak resident memory the first solve adds, as benches/run.py measures it ("ΔRSS")
    reset_ok = _reset_peak()
    before = _status_kb("VmRSS") or 0
    run()
    delta_rss_mb = round((_peak_kb(reset_ok) - before) / 1024, 1)
    wall, setup, sweeps = [], [], []
    for _ in range(repeats):
        t = time.perf_counter()
        sol = run()
        wall.append(time.perf_counter() - t)
        setup.append(sol.stats.setup_seconds)
        sweeps.append(sol.stats.seconds)
    if redistance:  # after the timed solves, whose memory it would otherwise change
        extra.update(redistance_candidates(surface, p.grid))
    ms = {
        k: round(1e3 * float(np.median(v)), 1)
        for k, v in (("wall_ms", wall), ("setup_ms", setup), ("sweeps_ms", sweeps))
    }
    print(
        json.dumps(
            dict(
                n=n,
                repeats=repeats,
                dense=dense,
                redistance=redistance,
                tube=use_tube,
                **ms,
                first_solve_delta_rss_mb=delta_rss_mb,
                **extra,
            )
        )
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
