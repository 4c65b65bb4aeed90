"""Issue 32's figures: the upwind local solver for the moving medium and Riemannian metrics against
the Lax–Friedrichs update of Sect. 5.1 and the isotropic Godunov solver, side by side in one run.

    .venv/bin/python benches/upwind.py [--quick] [--out out/bench]

* rotating medium on the sphere (R = 0.5, F = 1, ω = 1, source (−0.5, 0, 0); exact solution by
  root finding, ts.flows.rotation_travel_time_sphere): max / mean errors, fitted order over
  N = 61…141, iterations and updates beside LxF's, and the cost per node update (one thread, sweep
  seconds / updates) against the isotropic Godunov solver on the same band: its default sweeps,
  its plain sweeps, and Eq. (3) in the upwind solver's own sweeps (like for like; the kernel-level
  comparison is `cargo run --release -p tubesweep-core --example upwind_sweep`);
* a constant metric on the tilted plane x + 2y + 2z = 0 (with the default source ball and with a
  fixed ball of radius 0.1, ``source_radius``) and on the circle of radius 0.5 against the isotropic
  Godunov solver on the same grids;
* the box (ts.travel_time) with a uniform flow and a constant metric.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

import tubesweep as ts
from tubesweep.flows import rotation_travel_time_sphere, solid_body_rotation
from tubesweep.surfaces.analytic import Circle, Sphere

R = 0.5


def _order(hs, errs):
    return float(np.polyfit(np.log(hs), np.log(errs), 1)[0]) if len(errs) > 1 else float("nan")


def _per_update(sol):
    return 1e9 * sol.stats.seconds / max(sol.stats.updates, 1)


def sphere(ns):
    s = Sphere(R)
    p = np.random.default_rng(0).normal(size=(4000, 3))
    p = R * p / np.linalg.norm(p, axis=1, keepdims=True)
    exact = rotation_travel_time_sphere(p, R, (-R, 0, 0), 1.0, 1.0)
    geo = s.geodesic_distance(p, (-R, 0, 0))
    rows = []
    for n in ns:
        g = ts.Grid(lower=(-0.7,) * 3, upper=(0.7,) * 3, shape=(n,) * 3)
        row = {"N": n, "h": g.spacing}
        for name, kw, ex in (
            ("upwind", dict(flow=solid_body_rotation(1.0)), exact),
            ("lxf", dict(flow=solid_body_rotation(1.0), hamiltonian="lxf"), exact),
            ("isotropic godunov (v = 0)", dict(), geo),
            ("isotropic godunov, plain sweeps", dict(paper_sweeps=True), geo),
            # Eq. (3) through the same interface and sweeps as the upwind solver (active flags, the rim
            # last, no coupled update, no front window): the like-for-like cost per update
            ("isotropic godunov, same sweeps", dict(hamiltonian=ts.hamiltonians.Isotropic(scheme="godunov")), geo),
            ("upwind, v = 0", dict(flow=lambda q: np.zeros_like(q)), geo),
        ):
            sol = ts.solve(s, g, [(-R, 0, 0)], threads=1, **kw, order=1)
            e = np.abs(sol(p) - ex)
            row[name] = {
                "max": float(np.nanmax(e)),
                "mean": float(np.nanmean(e)),
                "iterations": sol.stats.iterations,
                "updates": sol.stats.updates,
                "sweep_s": sol.stats.seconds,
                "ns_per_update": _per_update(sol),
            }
        rows.append(row)
        print(
            f"sphere N={n}: upwind max {row['upwind']['max']:.3e} mean {row['upwind']['mean']:.3e} "
            f"({row['upwind']['iterations']} it) | LxF max {row['lxf']['max']:.3e} mean {row['lxf']['mean']:.3e} "
            f"({row['lxf']['iterations']} it) | isotropic Godunov max {row['isotropic godunov (v = 0)']['max']:.3e} | "
            f"ns/update upwind {row['upwind']['ns_per_update']:.0f}, isotropic {row['isotropic godunov (v = 0)']['ns_per_update']:.0f}"
            f" (plain {row['isotropic godunov, plain sweeps']['ns_per_update']:.0f}, same sweeps "
            f"{row['isotropic godunov, same sweeps']['ns_per_update']:.0f}), LxF {row['lxf']['ns_per_update']:.0f}",
            flush=True,
        )
    return rows


def plane(ns):
    """The constant metric on the tilted plane x + 2y + 2z = 0 in [-0.6, 0.6]^3, sampled within 0.35 of the
    source, with the default source ball (2 grid spacings) and with a fixed ball of radius 0.1
    (``source_radius``), which removes the point source's O(h log 1/h) pollution."""
    nrm = np.array([1.0, 2.0, 2.0]) / 3.0
    pl = ts.LevelSet(lambda q: q @ nrm, lipschitz=1.0)
    M = np.array([[2.0, 0.5, 0.2], [0.5, 1.0, 0.3], [0.2, 0.3, 0.6]])
    P = np.eye(3) - np.outer(nrm, nrm)
    A = np.linalg.pinv(P @ M @ P)
    q = np.random.default_rng(1).uniform(-0.35, 0.35, size=(2000, 3))
    q -= (q @ nrm)[:, None] * nrm
    exact = np.sqrt(np.einsum("ki,ij,kj->k", q, A, q))
    dist = np.linalg.norm(q, axis=1)
    rows = []
    for n in ns:
        g = ts.Grid(lower=(-0.6,) * 3, upper=(0.6,) * 3, shape=(n,) * 3)
        r = {"N": n, "h": g.spacing}
        for ball, rad in (("", None), (", fixed ball 0.1", 0.1)):
            up = ts.solve(pl, g, [(0, 0, 0)], hamiltonian=ts.hamiltonians.Metric(M), source_radius=rad, order=1)
            lxf = ts.solve(
                pl, g, [(0, 0, 0)], hamiltonian=ts.hamiltonians.Metric(M, scheme="lxf"), source_radius=rad, order=1
            )
            iso = ts.solve(pl, g, [(0, 0, 0)], source_radius=rad, order=1)
            for k, sol, ex in (("upwind", up, exact), ("lxf", lxf, exact), ("isotropic godunov", iso, dist)):
                e = np.abs(sol(q) - ex)
                r[k + ball] = {
                    "max": float(np.nanmax(e)),
                    "mean": float(np.nanmean(e)),
                    "iterations": sol.stats.iterations,
                }
            print(
                f"tilted plane N={n}{ball}: upwind max {r['upwind' + ball]['max']:.3e} mean "
                f"{r['upwind' + ball]['mean']:.3e} | isotropic max {r['isotropic godunov' + ball]['max']:.3e} mean "
                f"{r['isotropic godunov' + ball]['mean']:.3e} | LxF max {r['lxf' + ball]['max']:.3e}",
                flush=True,
            )
        rows.append(r)
    return rows


def circle(ns):
    c = Circle(R)
    M = np.array([[2.0, 0.6], [0.6, 0.5]])
    pts = c.sample(2000)
    a = np.mod(np.arctan2(pts[:, 1], pts[:, 0]) - np.pi, 2 * np.pi)
    th = np.linspace(0, 2 * np.pi, 200001)
    t = np.stack([-np.sin(th + np.pi), np.cos(th + np.pi)], axis=1)
    w = R / np.sqrt(np.einsum("ki,ij,kj->k", t, M, t))
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(th))])
    fwd = np.interp(a, th, cum)
    exact = np.minimum(fwd, cum[-1] - fwd)
    arc = R * np.minimum(a, 2 * np.pi - a)
    rows = []
    for n in ns:
        g = ts.Grid((-1, -1), (1, 1), (n, n))
        up = ts.solve(c, g, [(-R, 0)], hamiltonian=ts.hamiltonians.Metric(M), order=1)
        iso = ts.solve(c, g, [(-R, 0)], order=1)
        r = {"N": n, "h": g.spacing}
        for k, sol, ex in (("upwind", up, exact), ("isotropic godunov", iso, arc)):
            e = np.abs(sol(pts) - ex)
            r[k] = {"max": float(np.nanmax(e)), "mean": float(np.nanmean(e)), "iterations": sol.stats.iterations}
        rows.append(r)
        print(
            f"metric circle N={n}: upwind max {r['upwind']['max']:.3e} | isotropic max {r['isotropic godunov']['max']:.3e}",
            flush=True,
        )
    return rows


def box(ns):
    src = np.array([0.013, -0.1])
    v = np.array([0.3, -0.2])
    M = np.array([[2.0, 0.6], [0.6, 0.5]])
    rows = []
    for n in ns:
        g = ts.Grid((-1, -1), (1, 1), (n, n))
        x = np.stack([c.reshape(-1) for c in g.meshgrid()], axis=1) - src
        a, dv = 1 - v @ v, x @ v
        ex_flow = (-dv + np.sqrt(dv**2 + a * np.sum(x * x, axis=1))) / a
        ex_met = np.sqrt(np.einsum("ki,ij,kj->k", x, np.linalg.inv(M), x))
        r = {"N": n}
        for k, kw, ex in (
            ("flow upwind", dict(flow=v), ex_flow),
            ("flow lxf", dict(flow=v, hamiltonian="lxf"), ex_flow),
            ("metric upwind", dict(hamiltonian=ts.hamiltonians.Metric(M)), ex_met),
            ("isotropic godunov", dict(), np.linalg.norm(x, axis=1)),
        ):
            u, st = ts.travel_time(g, [src], return_stats=True, **kw)
            r[k] = {"max": float(np.max(np.abs(u.ravel() - ex))), "iterations": st.iterations, "seconds": st.seconds}
        rows.append(r)
        print(
            "box N=%d: " % n + " | ".join(f"{k} {r[k]['max']:.3e} ({r[k]['iterations']} it)" for k in r if k != "N"),
            flush=True,
        )
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default="out/bench")
    args = ap.parse_args()
    t0 = time.perf_counter()
    ns = (61, 81, 101) if args.quick else (61, 81, 101, 121, 141)
    out = {"sphere": sphere(ns)}
    hs = [r["h"] for r in out["sphere"]]
    for k in ("upwind", "lxf", "isotropic godunov (v = 0)"):
        out[f"sphere fitted order of the max error, {k}"] = _order(hs, [r[k]["max"] for r in out["sphere"]])
    last = out["sphere"][-1]
    out["cost per update upwind / isotropic Godunov (same band, one thread)"] = [
        r["upwind"]["ns_per_update"] / r["isotropic godunov (v = 0)"]["ns_per_update"] for r in out["sphere"]
    ]
    out["cost per update upwind / Eq. (3) in the same sweeps (like for like)"] = [
        r["upwind"]["ns_per_update"] / r["isotropic godunov, same sweeps"]["ns_per_update"] for r in out["sphere"]
    ]
    out["cost per update upwind / isotropic Godunov with plain sweeps"] = [
        r["upwind"]["ns_per_update"] / r["isotropic godunov, plain sweeps"]["ns_per_update"] for r in out["sphere"]
    ]
    out["plane"] = plane((25, 49) if args.quick else (25, 49, 97, 193))
    for ball in ("", ", fixed ball 0.1"):
        rows = out["plane"][1:] if len(out["plane"]) > 2 else out["plane"]  # N >= 49 (all with --quick)
        out[f"plane{ball} fitted orders (max, N >= 49; all with --quick): upwind, isotropic"] = [
            _order([r["h"] for r in rows], [r[k + ball]["max"] for r in rows]) for k in ("upwind", "isotropic godunov")
        ]
        out[f"plane{ball} max error upwind / isotropic"] = [
            r["upwind" + ball]["max"] / r["isotropic godunov" + ball]["max"] for r in out["plane"]
        ]
    out["circle"] = circle((101, 201) if args.quick else (101, 201, 401, 801))
    out["circle max error upwind / isotropic"] = [
        r["upwind"]["max"] / r["isotropic godunov"]["max"] for r in out["circle"]
    ]
    out["circle fitted orders (max): upwind, isotropic"] = [
        _order([r["h"] for r in out["circle"]], [r[k]["max"] for r in out["circle"]])
        for k in ("upwind", "isotropic godunov")
    ]
    out["box"] = box((101, 201) if args.quick else (101, 201, 401))
    out["seconds"] = round(time.perf_counter() - t0, 1)
    print(
        f"\nsphere N={last['N']}: upwind max error {last['upwind']['max']:.3e} (target ≤ 3e-2), LxF {last['lxf']['max']:.3e}"
    )
    for k, v in out.items():
        if not isinstance(v, list) or (v and not isinstance(v[0], dict)):
            print(f"{k}: {np.round(v, 3).tolist() if isinstance(v, list) else round(v, 3)}")
    path = Path(args.out)
    path.mkdir(parents=True, exist_ok=True)
    (path / "upwind.json").write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
