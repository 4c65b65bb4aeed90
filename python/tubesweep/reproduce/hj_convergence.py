"""Convergence of the general-Hamiltonian solvers (Sect. 5.1: Lax–Friedrichs; and the upwind solver) against exact solutions
(``tubesweep reproduce hj_convergence``; see ``docs/hamiltonians.md``):

* moving medium, solid-body rotation ω = 1 of the medium, F = 1, on the circle of radius 0.5
  (exact ``u = min(Rα/(F+ωR), R(2π−α)/(F−ωR))``) and on the sphere of radius 0.5 (exact by the
  rotating-frame construction, :func:`tubesweep.flows.rotation_travel_time_sphere`);
* constant Riemannian metric ``M = [[2, 0.6], [0.6, 0.5]]`` on the circle of radius 0.5 (exact by
  quadrature of ``∫ R dθ / sqrt(tᵀ M t)``).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from ..flows import rotation_travel_time_circle, rotation_travel_time_sphere, solid_body_rotation
from ..grid import Grid
from ..hamiltonians import Metric
from ..solve import solve
from ..surfaces.analytic import Circle, Sphere

R = 0.5
M2 = np.array([[2.0, 0.6], [0.6, 0.5]])


def _metric_circle_exact(p: np.ndarray) -> np.ndarray:
    a = np.mod(np.arctan2(p[:, 1], p[:, 0]) - np.pi, 2 * np.pi)
    th = np.linspace(0, 2 * np.pi, 200001)
    t = np.stack([-np.sin(th + np.pi), np.cos(th + np.pi)], axis=1)
    w = R / np.sqrt(np.einsum("ki,ij,kj->k", t, M2, t))
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(th))])
    fwd = np.interp(a, th, cum)
    return np.minimum(fwd, cum[-1] - fwd)


def _rows(name: str, cases, make, exact_fn, pts):
    exact = exact_fn(pts)
    rows = []
    for n in cases:
        sol = make(n)
        e = np.abs(sol(pts) - exact)
        rows.append(
            {
                "case": name,
                "N": n,
                "h": sol.grid.spacing,
                "max_err": float(np.nanmax(e)),
                "mean_err": float(np.nanmean(e)),
                "iterations": sol.stats.iterations,
                "seconds": round(sol.stats.seconds, 3),
            }
        )
    for a, b in zip(rows[:-1], rows[1:]):
        b["order_max"] = float(np.log(a["max_err"] / b["max_err"]) / np.log(a["h"] / b["h"]))
        b["order_mean"] = float(np.log(a["mean_err"] / b["mean_err"]) / np.log(a["h"] / b["h"]))
    return rows


def run(out_dir: Path, quick: bool) -> dict:
    out_dir = Path(out_dir)
    circ = Circle(R)
    pc = circ.sample(2000)
    n2 = (101, 201, 401) if quick else (101, 201, 401, 801)
    n3 = (29, 57) if quick else (29, 57, 113)
    g2 = lambda n: Grid(lower=(-1, -1), upper=(1, 1), shape=(n, n))  # noqa: E731
    g3 = lambda n: Grid(lower=(-0.7,) * 3, upper=(0.7,) * 3, shape=(n,) * 3)  # noqa: E731
    rng = np.random.default_rng(0)
    ps = rng.normal(size=(4000, 3))
    ps = R * ps / np.linalg.norm(ps, axis=1, keepdims=True)
    rows = []
    for scheme in ("lxf", "godunov"):
        label = "LxF" if scheme == "lxf" else "upwind"
        rows += _rows(
            f"moving medium, rotation, circle, {label}",
            n2,
            lambda n: solve(
                circ, g2(n), [(-R, 0)], speed=1.0, flow=solid_body_rotation(1.0), hamiltonian=scheme, order=1
            ),
            lambda p: rotation_travel_time_circle(p, R, np.pi, 1.0, 1.0),
            pc,
        )
        rows += _rows(
            f"metric M2, circle, {label}",
            n2,
            lambda n: solve(circ, g2(n), [(-R, 0)], hamiltonian=Metric(M2, scheme=scheme), order=1),
            _metric_circle_exact,
            pc,
        )
    sph = Sphere(R)
    for scheme in ("lxf", "godunov"):
        rows += _rows(
            f"moving medium, rotation, sphere, {'LxF' if scheme == 'lxf' else 'upwind'}",
            n3,
            lambda n: solve(
                sph, g3(n), [(-R, 0, 0)], speed=1.0, flow=solid_body_rotation(1.0), hamiltonian=scheme, order=1
            ),
            lambda p: rotation_travel_time_sphere(p, R, (-R, 0, 0), 1.0, 1.0),
            ps,
        )
    rows += _rows(
        "isotropic LxF (v = 0), sphere",
        n3,
        lambda n: solve(sph, g3(n), [(-R, 0, 0)], hamiltonian="lxf", order=1),
        lambda p: sph.geodesic_distance(p, (-R, 0, 0)),
        ps,
    )
    lines = [
        "| case | N | h | max error | order | mean error | order | iterations |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['case']} | {r['N']} | {r['h']:.4g} | {r['max_err']:.3e} | {r.get('order_max', float('nan')):.2f} | "
            f"{r['mean_err']:.3e} | {r.get('order_mean', float('nan')):.2f} | {r['iterations']} |"
        )
    table = "\n".join(lines)
    (out_dir / "hj_convergence.md").write_text(table + "\n")
    (out_dir / "hj_convergence.json").write_text(json.dumps(rows, indent=1))
    print(table)
    return {"rows": rows}


EXPERIMENTS = {"hj_convergence": run}
