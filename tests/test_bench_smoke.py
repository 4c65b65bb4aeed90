"""A small, fast run of the benchmark harness (benches/run.py) on the smallest sizes, with
whichever peers are installed. Checks the output's structure and that tubesweep's errors
against the exact answers are finite and small; no timing assertions (the machine is shared)."""

from __future__ import annotations

import importlib.util
import json
import math
import os
import sys
from pathlib import Path

import numpy as np
import pytest

BENCHES = Path(__file__).resolve().parents[1] / "benches"
sys.path.insert(0, str(BENCHES))
sys.path.insert(0, str(BENCHES / "experiments"))  # the one-off studies it also runs

import run as bench  # noqa: E402
from problems import Spheroid, Torus, ellipse_closest  # noqa: E402

HAVE = {
    m: importlib.util.find_spec(m) is not None
    for m in ("skfmm", "potpourri3d", "pygeodesic", "geographiclib", "skimage")
}
PEER_MODULE = {"skfmm-tube": "skfmm", "heat": "potpourri3d", "mmp": "pygeodesic"}

# Max error bounds for tubesweep (Godunov) at these sizes: about twice what is measured.
GODUNOV_MAX = {("sphere", 21): 0.5, ("star", 101): 0.2, ("star", 201): 0.15, ("ellipsoid", 21): 0.5}


@pytest.fixture(scope="module")
def result(tmp_path_factory):
    cases = {"sphere": [21], "star": [101, 201]}  # two sizes: a curve to compare at equal error
    if HAVE["geographiclib"]:
        cases["ellipsoid"] = [21]
    out = tmp_path_factory.mktemp("bench")
    methods = [
        "tubesweep-godunov",
        "tubesweep-godunov-order2",
        "tubesweep-godunov-tolh",
        "tubesweep-godunov-1t",
        "skfmm-tube",
        "heat",
        "mmp",
    ]  # LxF: see tests/test_solve.py
    res = bench.run_bench("quick", cases=cases, repeats=1, methods=methods, out=out, verbose=False)
    res["out"] = out
    res["cases"] = cases
    return res


def _cases(result):
    """(problem, N, {method: record}) for every case of the run."""
    recs = result["records"]
    for prob, ns in result["cases"].items():
        for n in ns:
            yield prob, n, {r["method"]: r for r in recs if r["problem"] == prob and r["n"] == n}


def test_every_applicable_case_ran(result):
    for prob, n, got in _cases(result):
        assert got["tubesweep-godunov"]["status"] == "ok"
        assert got["tubesweep-godunov-tolh"]["status"] == "ok"
        assert "tubesweep-lxf" not in got
        for m, mod in PEER_MODULE.items():
            needs_mesh = m in ("heat", "mmp")
            if HAVE[mod] and not (needs_mesh and (prob == "star" or not HAVE["skimage"])):
                assert got[m]["status"] == "ok", got[m]
            else:
                assert m not in got


def test_table_structure(result):
    lines = result["table"].splitlines()
    header = [c.strip() for c in lines[0].strip("|").split("|")]
    assert header == [c[0] for c in bench.COLUMNS]
    assert all(line.startswith("|") and line.count("|") == len(header) + 1 for line in lines)
    assert len(lines) == 2 + len(result["records"])
    saved = json.loads((result["out"] / "results.json").read_text())
    assert len(saved["records"]) == len(result["records"])
    main_table = (result["out"] / "results.md").read_text().split("## At equal accuracy")[0]
    assert main_table.count("| tubesweep-godunov |") == sum(map(len, result["cases"].values()))


def test_time_at_error_interpolates_log_log_on_the_cheapest_bracketing_sizes():
    # (error, time) by grid size: error 1e-1 at 1 s, 1e-2 at 100 s, then a larger error again
    curve = [(1e-1, 1.0), (1e-2, 100.0), (5e-2, 400.0)]
    # halfway in log error between the first two points: halfway in log time, 10 s
    assert bench.time_at_error(curve, math.sqrt(1e-1 * 1e-2)) == pytest.approx(10.0)
    # 5e-2 is bracketed by the first pair and by the second: the first (cheaper) pair's time
    assert bench.time_at_error(curve, 5e-2) == pytest.approx(10 ** (2 * math.log10(2)))
    assert bench.time_at_error(curve, 1e-1) == pytest.approx(1.0)
    assert bench.time_at_error(curve, 1e-2) == pytest.approx(100.0)
    # outside the range: no extrapolation; one point: only its own error
    assert bench.time_at_error(curve, 2e-1) is None and bench.time_at_error(curve, 1e-3) is None
    assert bench.time_at_error([(1e-2, 3.0)], 1e-2) == 3.0 and bench.time_at_error([(1e-2, 3.0)], 2e-2) is None
    assert bench.time_at_error(curve, float("nan")) is None
    # an error equal to an end point's but for the last bits counts as that point's
    assert bench.time_at_error(curve, 1e-2 * (1 - 1e-12)) == pytest.approx(100.0)
    assert bench.time_at_error(curve, 1e-1 * (1 + 1e-12)) == pytest.approx(1.0)
    assert bench.time_at_error(curve, 1e-2 * (1 - 1e-6)) is None


def test_outside_the_curve_s_errors_the_time_is_bounded():
    curve = [(1e-1, 2.0), (1e-2, 100.0), (5e-2, 400.0)]
    # less accurate than every point: reached by the cheapest one at the latest
    assert bench.time_bound_at_error(curve, 0.5) == (">", 2.0)
    # more accurate than every point: needs more than the most accurate point's time
    assert bench.time_bound_at_error(curve, 1e-3) == ("<", 100.0)
    # inside the range, or no usable error: no bound
    assert bench.time_bound_at_error(curve, 3e-2) is None and bench.time_bound_at_error(curve, 1e-2) is None
    assert bench.time_bound_at_error(curve, float("inf")) is None and bench.time_bound_at_error([], 1.0) is None


def test_equal_error_rows_set_each_peer_case_beside_tubesweep_at_its_accuracy():
    def rec(method, n, max_err, mean_err, wall):
        return dict(status="ok", problem="p", method=method, n=n, max_err=max_err, mean_err=mean_err, wall_s=wall)

    records = [
        rec("tubesweep-godunov", 41, 1e-1, 1e-2, 1.0),
        rec("tubesweep-godunov", 81, 1e-2, 1e-3, 100.0),
        rec("skfmm-tube", 41, math.sqrt(1e-3), 1e-4, 30.0),
        rec("skfmm-tube", 81, 1e-2, 1e-2, 50.0),
        dict(status="timeout", problem="p", method="heat", n=41),
    ]
    rows = bench.equal_error(records)
    assert [(r["method"], r["n"]) for r in rows] == [("skfmm-tube", 41), ("skfmm-tube", 81)]
    a, b = rows
    assert a["ts_at_max_s"] == pytest.approx(10.0) and a["ratio_at_max"] == pytest.approx(3.0)
    # tubesweep's means do not reach 1e-4: it would need more than its finest size's 100 s
    assert a["ts_at_mean_s"] is None and a["ratio_at_mean"] is None and a["ratio_bound_at_mean"] == "<0.30"
    assert a["ratio_bound_at_max"] is None
    assert b["ratio_at_max"] == pytest.approx(0.5) and b["ratio_at_mean"] == pytest.approx(50.0)
    lines = bench.equal_error_table(rows).splitlines()
    assert len(lines) == 4 and lines[2].count("|") == len(bench.EQUAL_ERROR_COLUMNS) + 1
    assert "| 3.00 |" in lines[2] and "| — |" in lines[2] and lines[2].endswith("| <0.30 |")


def test_the_run_reports_the_peers_at_equal_accuracy(result):
    # the star ran at two sizes: every other method's star cases get a row
    rows = [r for r in result["equal_error"] if r["problem"] == "star"]
    others = [
        r
        for r in result["records"]
        if r["problem"] == "star" and r["status"] == "ok" and r["method"] != "tubesweep-godunov"
    ]
    assert sorted((r["method"], r["n"]) for r in rows) == sorted((r["method"], r["n"]) for r in others)
    for r in rows:
        if r["method"] == "tubesweep-godunov-1t":
            # the same errors as the all-core solve at each size: its own size's time
            same = [
                b
                for b in result["records"]
                if b["method"] == "tubesweep-godunov" and b["problem"] == "star" and b["n"] == r["n"]
            ]
            assert r["ts_at_max_s"] == pytest.approx(same[0]["wall_s"])
    saved = json.loads((result["out"] / "results.json").read_text())
    assert saved["equal_error"] == json.loads(json.dumps(result["equal_error"]))
    assert "## At equal accuracy" in (result["out"] / "results.md").read_text()


def test_tubesweep_errors_are_finite_and_small(result):
    for r in result["records"]:
        if not r["method"].startswith("tubesweep"):
            continue
        if r["method"] == "tubesweep-godunov-order2" and r["status"] != "ok":
            # order=2 refuses a grid that does not resolve the curvature (the spheroid at N = 21)
            assert "curvature" in r["note"], r
            continue
        assert r["n_nan"] == 0
        assert math.isfinite(r["max_err"]) and 0 <= r["mean_err"] <= r["max_err"]
        assert r["converged"] and r["updates"] > 0 and r["band_points"] > 0 and r["iterations"] >= 2
        if r["method"] == "tubesweep-godunov":
            assert r["max_err"] < GODUNOV_MAX[(r["problem"], r["n"])], r
            assert r["ratio"] == pytest.approx(1.0)
        assert r["delta_rss_mb"] >= 0 and r["peak_rss_mb"] > 0


def test_order2_is_more_accurate_and_the_time_to_accuracy_is_reported(result):
    for prob, n, got in _cases(result):
        two, one = got["tubesweep-godunov-order2"], got["tubesweep-godunov"]
        if two["status"] != "ok":
            continue
        assert two["mean_err"] < one["mean_err"] and two["far_max_err"] < one["far_max_err"], (prob, n)
    rows = {(r["problem"], r["method"]): r for r in result["time_to_accuracy"]}
    star = rows[("star", "tubesweep-godunov-order2")]
    # the star at N = 101 and 201: order=2 reaches a mean error of 1e-3 between them (a time) or
    # before (a bound), the first-order scheme only beyond (a lower bound)
    assert star["mean_err@0.001"] != "—" and not star["mean_err@0.001"].startswith(">"), star
    assert rows[("star", "tubesweep-godunov")]["mean_err@0.0002"].startswith(">")
    assert "## Time to accuracy" in (result["out"] / "results.md").read_text()
    assert result["time_to_accuracy_table"].count("\n") == len(result["time_to_accuracy"]) + 1


def test_a_tolerance_tied_to_the_grid_stops_earlier_at_the_same_accuracy(result):
    # tol = 1e-3·Δx: fewer or as many iterations and updates, and errors against the exact answer
    # that differ from the converged solve's by about tol (far below the scheme's O(Δx) error)
    for prob, n, got in _cases(result):
        full, loose = got["tubesweep-godunov"], got["tubesweep-godunov-tolh"]
        h = 2.0 / (n - 1)  # every benchmark grid spans [-1, 1]^d
        assert loose["iterations"] <= full["iterations"] and loose["updates"] <= full["updates"]
        assert abs(loose["max_err"] - full["max_err"]) <= 3e-3 * h, (prob, n, loose["max_err"], full["max_err"])


def test_one_thread_gives_the_same_answer_and_work_as_all_cores(result):
    # the solve's result does not depend on the thread count (bit-identical sweeps), so the
    # single-thread row differs from the default one only in its times
    for prob, n, got in _cases(result):
        one, every = got["tubesweep-godunov-1t"], got["tubesweep-godunov"]
        assert one["status"] == "ok"
        for key in ("max_err", "mean_err", "iterations", "updates", "band_points"):
            assert one[key] == every[key], (prob, n, key, one[key], every[key])


def test_peers_give_finite_errors(result):
    for r in result["records"]:
        if r["method"] in PEER_MODULE and r["status"] == "ok":
            assert math.isfinite(r["max_err"]) and r["max_err"] < 0.5, r
            assert r["ratio"] > 0


@pytest.mark.skipif(not HAVE["geographiclib"], reason="geographiclib not installed")
def test_geographiclib_matches_integrated_geodesics_on_the_spheroid():
    """The ellipsoid's exact reference: geographiclib's series at flattening 0.2 agree with a
    direct integration of the geodesic equations x'' = −(x'·H x' / |∇g|²) ∇g to < 1e-7."""
    from geographiclib.geodesic import Geodesic
    from scipy.integrate import solve_ivp

    s = Spheroid()
    a, c = s.a, s.c
    geod = Geodesic(a, 1 - c / a)
    hd = np.array([2 / a**2, 2 / a**2, 2 / c**2])

    def rhs(_, y):
        x, v = y[:3], y[3:]
        g = hd * x
        return np.concatenate([v, -(v @ (hd * v)) / (g @ g) * g])

    def on_surface(lat_deg, lon_deg):
        lat, lon = np.radians(lat_deg), np.radians(lon_deg)
        k = 1 / np.hypot(a * np.cos(lat), c * np.sin(lat))
        return np.array(
            [a * a * np.cos(lat) * k * np.cos(lon), a * a * np.cos(lat) * k * np.sin(lon), c * c * np.sin(lat) * k]
        )

    for lat0, az, dist in [(0.0, 30.0, 1.2), (20.0, 10.0, 2.0), (-40.0, 120.0, 1.0)]:
        lat = np.radians(lat0)
        azr = np.radians(az)
        v0 = np.sin(azr) * np.array([0, 1, 0]) + np.cos(azr) * np.array([-np.sin(lat), 0, np.cos(lat)])
        sol = solve_ivp(
            rhs, (0, dist), np.concatenate([on_surface(lat0, 0.0), v0]), rtol=1e-12, atol=1e-14, method="DOP853"
        )
        r = geod.Direct(lat0, 0.0, az, dist)
        assert np.linalg.norm(sol.y[:3, -1] - on_surface(r["lat2"], r["lon2"])) < 1e-7


def test_exact_distances_of_the_benchmark_surfaces():
    rng = np.random.default_rng(1)
    p = rng.uniform(-1, 1, (5000, 3))
    s = Spheroid()
    cp = s.closest(p)
    assert np.abs((cp[:, 0] ** 2 + cp[:, 1] ** 2) / s.a**2 + cp[:, 2] ** 2 / s.c**2 - 1).max() < 1e-12
    assert np.abs(np.abs(s.signed_distance(p)) - np.linalg.norm(p - cp, axis=1)).max() < 1e-12
    # the closest point is a local minimum: no better point among nearby surface points
    q = s.closest(cp + 1e-3 * rng.normal(size=cp.shape))
    assert np.all(np.linalg.norm(p - q, axis=1) >= np.abs(s.signed_distance(p)) - 1e-12)
    # ellipse: closed form on the axes
    x0, x1 = ellipse_closest(np.array([0.0, 2.0]), np.array([2.0, 0.0]), 0.5, 0.4)
    assert np.allclose(x0, [0.0, 0.5]) and np.allclose(x1, [0.4, 0.0])
    # torus: along the outer equator the distance is the arclength (R + r)|Δθ|
    t = Torus()
    th = np.array([0.3, -1.2])
    eq = np.stack([0.75 * np.cos(th), 0.75 * np.sin(th), 0 * th], 1)
    assert np.allclose(t.equator_distance(eq, (0.75, 0, 0)), 0.75 * np.abs(th))
    assert np.isnan(t.equator_distance(eq, (0.5, 0, 0.25))).all()


def test_microbench_interleaves_the_cases_and_reports_the_same_work_for_every_thread_count(monkeypatch):
    import microbench

    # the cases of a round run one after the other, round after round
    calls = []
    real = microbench.measure

    def spy(n, h, t, repeats, paper=False):
        calls.append(("paper" if paper else "default", t))
        return real(n, h, t, repeats, paper)

    monkeypatch.setattr(microbench, "measure", spy)
    rows = microbench.run(sizes=(31,), schemes=("godunov",), repeats=2, threads=(1, 2))
    one_round = [("paper", 1), ("paper", 2), ("default", 1), ("default", 2)]
    assert calls == one_round * 2
    assert [(r["sweeps"], r["threads"]) for r in rows] == one_round
    by = {(r["sweeps"], r["threads"]): r for r in rows}
    for sweeps in ("paper", "default"):
        # bit-identical sweeps for any thread count: the same iterations and local updates
        assert by[(sweeps, 1)]["updates"] == by[(sweeps, 2)]["updates"] > 0
        assert by[(sweeps, 1)]["iterations"] == by[(sweeps, 2)]["iterations"]
        r1, r2 = by[(sweeps, 1)], by[(sweeps, 2)]
        # the ratios are medians of per-round ratios of the warm solves' times
        assert r2["speedup"] > 0 and math.isfinite(r2["speedup"])
        for r in (r1, r2):
            assert r["sweep_s"] > 0
            assert r["per_core"] == pytest.approx(r["updates"] / r["sweep_s"] / r["threads"])
    # the default sweeps solve the same equations with fewer local updates
    assert by[("default", 1)]["updates"] < by[("paper", 1)]["updates"]
    assert by[("default", 2)]["vs_paper"] > 0
    # one core-to-core round trip per round, where threads can be pinned (a measured figure:
    # only its presence is checked)
    trips = rows[0]["core_round_trip_ns"]
    assert len(trips) == 2
    if sys.platform.startswith("linux") and len(os.sched_getaffinity(0)) >= 2:
        assert all(t is not None and math.isfinite(t) for t in trips)


def test_microbench_times_the_flag_free_kernel_with_the_same_work_on_every_thread_count():
    import microbench

    rows = microbench.run_kernel(sizes=(31,), repeats=2, threads=(1, 2))
    assert [(r["n"], r["threads"]) for r in rows] == [(31, 1), (31, 2)]
    r1, r2 = rows
    assert (r1["iterations"], r1["updates"], r1["band_points"]) == (r2["iterations"], r2["updates"], r2["band_points"])
    # every node but the fixed ones (and layer nodes without an upwind neighbour) in every one of
    # the 8 sweeps of every iteration (the example's plain sweeps keep the rim in every sweep)
    per_sweep, rest = divmod(r1["updates"], 8 * r1["iterations"])
    assert rest == 0 and 0.9 * r1["band_points"] < per_sweep < r1["band_points"]
    for r in rows:
        assert r["per_core"] == pytest.approx(r["updates"] / r["sweep_s"] / r["threads"])
        assert 0 <= r["prefetch_iterations"] <= r["iterations"]
    assert r2["speedup"] > 0 and math.isfinite(r2["speedup"])
    # the round trip between the first two CPUs before every round, where threads can be pinned
    # (Linux, two CPUs; a measured figure: only its presence is checked)
    trips = r1["core_round_trip_ns"]
    assert len(trips) == 2
    if sys.platform.startswith("linux") and len(os.sched_getaffinity(0)) >= 2:
        assert all(t is not None and math.isfinite(t) for t in trips)
    else:
        assert trips == [None, None]


def test_microbench_splits_the_speed_ups_of_rounds_at_two_core_to_core_latencies():
    import microbench

    assert microbench._latency_column([44.0, 50.0, 46.0]) == "44"
    assert microbench._latency_column([44.0, 370.0]) == "44–370"
    assert microbench._latency_column([44.0, None, 70.0]) == "44–70"
    assert microbench._latency_column([None, None]) == "n/a"
    # one latency (within the spread of 1.5): nothing to split
    assert microbench._split_speedups([44.0, 47.0, 45.0], [1.8, 1.7, 1.9]) is None
    assert microbench._split_speedups([None, None], [1.8, 1.7]) is None
    assert microbench._split_speedups([44.0, None], [1.8, 1.7]) is None
    # a zero (a broken measurement) is left out rather than dividing the rounds at 0
    assert microbench._split_speedups([0.0, 44.0, 45.0], [1.0, 1.8, 1.7]) is None
    # two: the medians of each side of the geometric midpoint (about 127 ns here); unmeasured
    # rounds are left out
    split = microbench._split_speedups([44.0, 370.0, 46.0, 360.0, 45.0, None], [1.80, 1.40, 1.82, 1.60, 1.78, 1.0])
    assert split == "speed-up 1.80 in 3 rounds at 44–46 ns, 1.50 in 2 rounds at 360–370 ns"
    # a spread between 1.5 and 2 shows as a range and splits too; one round prints one figure
    assert microbench._latency_column([40.0, 70.0]) == "40–70"
    assert microbench._split_speedups([40.0, 70.0, 41.0], [1.8, 1.6, 1.7]) == (
        "speed-up 1.75 in 2 rounds at 40–41 ns, 1.60 in 1 round at 70 ns"
    )


def test_front_window_surfaces_bench_runs_and_the_window_keeps_the_solutions(capsys):
    """benches/experiments/front_window_surfaces.py at a small size: every surface prints a row, the two
    solutions agree to far below the tolerance's scale, and the window is left at its default."""
    import front_window_surfaces

    default = sys.modules["tubesweep._first_order"].FRONT_WINDOW
    assert front_window_surfaces.main(["--n", "41", "--repeats", "1"]) == 0
    rows = [line for line in capsys.readouterr().out.splitlines()[2:] if line.strip()]
    assert [r.split()[0] for r in rows] == list(front_window_surfaces.NAMES)
    assert all(float(r.split()[-1]) < 1e-9 for r in rows)
    assert sys.modules["tubesweep._first_order"].FRONT_WINDOW == default


def test_oblique_planes_bench_axis_aligned_surfaces_settle_at_once_and_tilted_ones_do_not():
    """benches/experiments/oblique_planes.py at small sizes: along an axis the paper's sweeps converge in one
    iteration (and one to confirm it) at under 3.5 updates per node; a tilted line takes many;
    the coupled update brings the 45° line down to a few iterations but not the 16.7° one."""
    import oblique_planes

    flat2, tilted2, diagonal2 = (oblique_planes.measure(v, 101) for v in ((0.0, 1.0), (0.3, 1.0), (1.0, 1.0)))
    flat3 = oblique_planes.measure((0.0, 0.0, 1.0), 31)
    for flat in (flat2, flat3):
        assert flat["tilt"] == 0.0
        assert flat["paper_iterations"] == 2 and flat["paper_updates_per_node"] < 3.5
    assert tilted2["paper_iterations"] >= 10 and tilted2["default_iterations"] >= 8
    assert diagonal2["paper_iterations"] >= 10 and diagonal2["default_iterations"] <= 5
    assert tilted2["default_updates_per_node"] > 4 * flat2["default_updates_per_node"]


def test_dependency_cycles_bench_finds_the_pairs_the_coupled_update_removes(capsys):
    """benches/experiments/dependency_cycles.py: the gain around a hand-made 2-cycle and 4-cycle; on the
    tilted line, the paper's update leaves inner–layer pairs that read each other, and with the
    coupled update folded in no cycle is left."""
    import dependency_cycles as dc

    assert dc.cycles([{1: 0.5}, {0: 0.4}, {}]) == (1, 2, 2, pytest.approx(0.2))
    assert dc.cycles([{1: 0.5}, {2: 0.5}, {3: 0.5}, {0: 0.4}]) == (1, 4, 4, pytest.approx(0.05))
    assert dc.cycles([{1: 0.5}, {2: 0.5}, {}]) == (0, 0, 0, 0.0)
    assert dc.main(["--case", "line2", "--n", "101"]) == 0
    plain, coupled = (line.split() for line in capsys.readouterr().out.splitlines()[1:])
    assert plain[4] == "plain" and int(plain[5]) > 0 and int(plain[7]) == 2 and float(plain[8]) > 0.05
    assert coupled[4] == "coupled" and coupled[5:8] == ["0", "0", "0"]


def test_under_load_bench_times_every_mode_on_the_same_values():
    # benches/under_load.py's rounds at a tiny size: each mode timed in every round but the
    # discarded first, and the thread counts give the same values (its own assertion)
    import under_load

    times = under_load.rounds(21, 2, {"default": 0, "threads=1": 1})
    assert set(times) == {"default", "threads=1"}
    assert all(len(v) == 2 and all(t > 0 for t in v) for v in times.values())


def test_point_clouds_bench_quick(capsys):
    """benches/point_clouds.py --quick: the table's rows, tubesweep at order 2 on the closed clouds
    and within a few times its measured errors."""
    import point_clouds

    rows = point_clouds.main(["--quick"])["rows"]
    assert [r["cloud"] for r in rows] == ["sphere", "torus (outer equator)", "sphere, noise ±0.1Δx"]
    sphere, torus, noisy = (r["tubesweep"] for r in rows)
    assert sphere["order"] == 2 and sphere["mean"] < 2e-3
    assert noisy["order"] == 2 and noisy["mean"] < 3e-3
    assert torus["mean"] < 1e-2
    if HAVE["potpourri3d"]:
        assert all("heat" in r for r in rows)
    assert "| sphere | 3,000 | 31 |" in capsys.readouterr().out


def test_mask_creases_bench_says_more_than_the_fronts_gain_beyond_the_crease(capsys):
    """benches/experiments/mask_creases.py at a small size: two balls fused at 122° as a voxel mask,
    raw and smoothed over a voxel, with "auto" and order=1: every row has a crease warning whose
    figure covers the worst early arrival measured beyond the crease (tubesweep._coarse_creases)."""
    import mask_creases

    argv = ["--n", "41", "--angles", "122", "--kinds", "mask", "smooth1", "--orders", "auto", "1"]
    assert mask_creases.main(argv) == 0
    rows = [line.split() for line in capsys.readouterr().out.splitlines()[1:] if line.strip()]
    assert len(rows) == 4
    for row in rows:
        worst, said = float(row[5]), float(row[7])
        assert 4.0 < worst < said and len(row) == 8  # (no "**": the figure covers the worst)


def test_mask_creases_bench_says_concave_creases_at_90_degrees(capsys):
    """The same at 90°: the concave crease reads below the convex edges' turn and is said from the
    lower one (tubesweep._coarse_creases.TURN_CONCAVE); the figure covers the worst early arrival."""
    import mask_creases

    argv = ["--n", "41", "--angles", "90", "--kinds", "mask", "--orders", "auto", "1"]
    assert mask_creases.main(argv) == 0
    rows = [line.split() for line in capsys.readouterr().out.splitlines()[1:] if line.strip()]
    assert len(rows) == 2
    for row in rows:
        worst, said = float(row[5]), float(row[7])
        assert 2.5 < worst < said and len(row) == 8  # 2.93 < 4.66 ("auto"), 4.28 < 6.98 (order=1)


def test_limit_cycles_bench_s_cylinders_converge_without_the_fallback(capsys):
    """benches/experiments/limit_cycles.py --cylinder 61: the closed cylinder with its caps on grid
    planes cycled until its fallback to decreases only (33 iterations, the fallback at 31) before
    the BDF2 ramp closed at a kink through the node; now it and the cylinder moved off the planes
    converge at once."""
    import limit_cycles

    limit_cycles.cylinder(61, False)
    out = capsys.readouterr().out.splitlines()
    for line, change in ((out[0], out[1]), (out[2], out[3])):
        assert line.endswith("fallback at None") and change.split()[-1] == "None"
        assert int(line.split(": ")[1].split(" iterations")[0]) <= 18  # 14 and 17


def test_sharp_edges_redistance_bench_s_box_and_cylinder_come_within_their_cells(capsys):
    """benches/experiments/sharp_edges_redistance.py 41: a box's and a closed cylinder's exact
    distances, their faces and rims on nodes, re-distanced. Before the band took a node on the
    zero set by rounding (φ = +5.6e-17) as a crossing and started the nodes beside a rim from the
    zero set next to them, the box at N = 61 had 112 nodes 0.41Δx too far and the cylinder's
    nodes within 0.1Δx of its surface stood up to 0.51Δx (N = 41–51) and 0.98Δx (N = 101) off."""
    import sharp_edges_redistance

    box = sharp_edges_redistance.errors(sharp_edges_redistance.box, 41)
    cylinder = sharp_edges_redistance.errors(sharp_edges_redistance.cylinder, 41)
    assert (
        box["max"] < 0.01 and box["off"] == 0
    )  # 0.00 (0.32 at a node diagonal to a corner before its cells' corners on the zero set started it)
    assert cylinder["near_max"] < 0.3 and cylinder["max"] < 0.45  # 0.24 and 0.43 (the rims' cells)
    sharp_edges_redistance.main([41])
    assert len(capsys.readouterr().out.splitlines()) == 2


def test_mesh_check_passes_bench_finds_each_pass_equal_to_the_one_it_replaced(capsys):
    """benches/experiments/mesh_check_passes.py with one repeat: each of the four passes gives what
    the NumPy pass it replaced gives (the script asserts it) and prints its row."""
    import mesh_check_passes

    assert mesh_check_passes.main(["--repeats", "1"]) == 0
    rows = [line for line in capsys.readouterr().out.splitlines() if line.startswith("| ") and "×" in line]
    assert [r.split(" | ")[0][2:] for r in rows] == [
        "distinct edge keys", "distinct faces (rows)", "vertices at the same place (rows)", "connected parts"
    ]  # fmt: skip
