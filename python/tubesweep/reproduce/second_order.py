"""Beyond the paper: ``order=2`` (docs/second-order.md). ``tubesweep reproduce second-order``
measures the second-order scheme next to the paper's first-order one on the sphere (great-circle
distances), an oblate spheroid (geodesics from geographiclib, when installed), the circle and the
six-fold star, and the sphere and circle given as closest-point maps, with the fitted orders and
the issue's targets (met or not), and writes ``second_order.csv`` / ``second_order.md``.

"far" errors leave out the points within 0.1 of the source and of the cut locus (the antipode,
or the arc of the equator about it on the spheroid), where no grid method converges at its order
in the max norm (docs/second-order.md, "Accuracy")."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any, Callable, Dict, List, Tuple

import numpy as np

from ._report import fit_order, local_orders, write_csv, write_markdown

SPHEROID = (0.6, 0.4)


def fibonacci_sphere(n: int, radius: float = 0.5) -> np.ndarray:
    """n nearly uniform points on the sphere of ``radius`` about the origin."""
    i = np.arange(n) + 0.5
    z = 1 - 2 * i / n
    r = np.sqrt(1 - z * z)
    t = np.pi * (1 + 5**0.5) * i
    return radius * np.stack([r * np.cos(t), r * np.sin(t), z], axis=1)


Case = Tuple[Any, np.ndarray, np.ndarray, np.ndarray, np.ndarray, Dict[str, np.ndarray]]


def sphere_case() -> Case:
    """The sphere R = 0.5, source (−0.5, 0, 0): 4000 points, their exact distances, the far mask
    and the circle x = 0 (exact π/4)."""
    from ..surfaces import Sphere

    surf = Sphere(0.5)
    src = np.array([-0.5, 0.0, 0.0])
    pts = fibonacci_sphere(4000)
    exact = surf.geodesic_distance(pts, src.tolist())
    far = (exact >= 0.1) & (exact <= 0.5 * np.pi - 0.1)
    th = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    ring = np.stack([np.zeros_like(th), 0.5 * np.cos(th), 0.5 * np.sin(th)], 1)
    return surf, src, pts, exact, far, {"circle x=0": ring}


def spheroid_case() -> Case:
    """The oblate spheroid a = 0.6, c = 0.4 (the library's Ellipsoid(0.6, 0.6, 0.4)), source on
    the equator: 4000 points placed by geodetic latitude and longitude, exact distances from
    geographiclib (Karney's geodesics, independent of this code)."""
    from geographiclib.geodesic import Geodesic

    from ..surfaces import Ellipsoid

    a, c = SPHEROID
    surf = Ellipsoid(a, a, c)
    geod = Geodesic(a, 1.0 - c / a)
    rng = np.random.default_rng(3)
    lat = np.degrees(np.arcsin(rng.uniform(-1, 1, 4000)))
    lon = rng.uniform(-180, 180, 4000)
    phi, lam = np.radians(lat), np.radians(lon)
    nu = a * a / np.sqrt(a * a * np.cos(phi) ** 2 + c * c * np.sin(phi) ** 2)
    pts = np.stack(
        [nu * np.cos(phi) * np.cos(lam), nu * np.cos(phi) * np.sin(lam), (c * c / (a * a)) * nu * np.sin(phi)], 1
    )
    src = np.array([-a, 0.0, 0.0])
    exact = np.array([geod.Inverse(0.0, 180.0, float(p), float(q), Geodesic.DISTANCE)["s12"] for p, q in zip(lat, lon)])
    far = (exact >= 0.1) & ~((np.abs(pts[:, 2]) < 0.1) & (np.abs(lon) < 80))
    return surf, src, pts, exact, far, {}


def circle_case() -> Case:
    from ..surfaces import Circle

    surf = Circle(0.5)
    src = np.array([-0.5, 0.0])
    pts = surf.sample(2000)
    exact = surf.geodesic_distance(pts, src.tolist())
    return surf, src, pts, exact, (exact >= 0.1) & (exact <= 0.5 * np.pi - 0.1), {}


def sphere_cp_case() -> Case:
    """The sphere of :func:`sphere_case` given as a closest-point map (``ts.ClosestPoint``)."""
    from ..closest_point import ClosestPoint

    _, src, pts, exact, far, extra = sphere_case()
    return ClosestPoint(lambda x: 0.5 * x / np.linalg.norm(x, axis=1, keepdims=True)), src, pts, exact, far, extra


def circle_cp_case() -> Case:
    """The circle of :func:`circle_case` given as a closest-point map."""
    from ..closest_point import ClosestPoint

    _, src, pts, exact, far, extra = circle_case()
    return ClosestPoint(lambda x: 0.5 * x / np.linalg.norm(x, axis=1, keepdims=True)), src, pts, exact, far, extra


def star_case() -> Case:
    from ..surfaces import Star

    surf = Star()
    src = np.array([0.5, 0.0])
    pts = surf.sample(2000)
    exact = surf.geodesic_distance(pts, src.tolist())
    return surf, src, pts, exact, (exact >= 0.1) & (exact <= exact.max() - 0.1), {}


def measure(case: Case, n: int, order: int) -> Dict[str, Any]:
    """One solve at N nodes per axis over [−1, 1]^d: far max, mean and the extra sets' max
    errors, the iterations and the time (band set-up included)."""
    from .. import Grid, solve

    surf, src, pts, exact, far, extra = case
    d = pts.shape[1]
    g = Grid((-1.0,) * d, (1.0,) * d, (n,) * d)
    t0 = time.perf_counter()
    sol = solve(surf, g, [src], order=order)
    seconds = time.perf_counter() - t0
    e = np.abs(sol(pts) - exact)
    row = {
        "N": n,
        "order": order,
        "far_max": float(e[far].max()),
        "mean": float(np.nanmean(e)),
        "iterations": sol.stats.iterations,
        "seconds": seconds,
        "fallback": (sol.stats.order2 or {}).get("fallback_iteration"),
        # how well the tube resolves the tightest curvature (order=2 needs < 1)
        "outer_kappa": sol.outer * g.spacing * sol.stats.order2["max_curvature"] if sol.stats.order2 else None,
    }
    for name, ring in extra.items():
        row[name] = float(np.max(np.abs(sol(ring) - np.pi / 4)))
    return row


CASES: Dict[str, Tuple[Callable[[], Case], Tuple[int, ...], Tuple[int, ...]]] = {
    # name: (case, sizes, quick sizes)
    "sphere": (sphere_case, (51, 101, 151, 201), (31, 51)),
    "spheroid 0.6/0.6/0.4": (spheroid_case, (51, 101, 151, 201, 251, 301), (41, 61)),
    "circle": (circle_case, (51, 101, 201, 401), (101, 201)),
    # from N = 201, where the tube resolves the tips' curvature with margin (outer·Δx·κ = 0.49 there)
    "six-fold star": (star_case, (201, 401, 801, 1601), (201, 401)),
    "sphere (closest-point map)": (sphere_cp_case, (51, 101, 151, 201), (31, 51)),
    "circle (closest-point map)": (circle_cp_case, (51, 101, 201, 401), (101, 201)),
}

#: The orders are fitted from this N on (full runs): where the tube resolves the surface's tightest
#: curvature as well as the sphere's range does at its coarsest grid (outer·Δx·κ ≤ 0.32 there).
#: The spheroid's κ = a/c² = 3.75 at the equator gives 0.60 at N = 51 (the sphere: 0.32) and 0.30
#: at N = 101; its pairwise orders, printed with the fits, rise from 51 to 101 and settle from 101
#: on (docs/second-order.md, "Accuracy"). The star's sizes start at its own such N.
FIT_FROM = {"spheroid 0.6/0.6/0.4": 101}

#: The accuracy targets set for order=2 on surfaces: (surface, what, bound, "max" or "min").
TARGETS = [
    ("sphere", "far max at N = 201", 4e-4, "max"),
    ("sphere", "mean at N = 201", 4e-5, "max"),
    ("sphere", "circle x=0 max at N = 201", 3e-5, "max"),
    ("sphere", "far max order", 1.7, "min"),
    ("sphere", "mean order", 1.85, "min"),
    ("spheroid 0.6/0.6/0.4", "far max order", 1.8, "min"),
    ("spheroid 0.6/0.6/0.4", "mean order", 1.85, "min"),
    ("circle", "far max order", 1.9, "min"),
    ("circle", "mean order", 1.9, "min"),
    ("six-fold star", "far max order", 1.9, "min"),
    ("six-fold star", "mean order", 1.9, "min"),
    ("sphere (closest-point map)", "far max order", 1.7, "min"),
    ("sphere (closest-point map)", "mean order", 1.85, "min"),
    ("circle (closest-point map)", "far max order", 1.9, "min"),
    ("circle (closest-point map)", "mean order", 1.9, "min"),
]


def target_lines(rows: List[Dict[str, Any]], orders: List[Dict[str, Any]]) -> List[str]:
    """The targets' table: each target, the figure measured for order=2 and whether it is met."""
    lines = ["| surface | target | measured (order=2) | met |", "|---|---|---|---|"]
    for surface, what, bound, kind in TARGETS:
        value = None
        if "N = 201" in what:
            key = {"far max": "far_max", "mean": "mean", "circle x=0 max": "circle x=0"}[what.split(" at")[0]]
            value = next(
                (r.get(key) for r in rows if r["surface"] == surface and r["order"] == 2 and r["N"] == 201), None
            )
        else:
            key = "far_max_order" if what.startswith("far") else "mean_order"
            value = next((o[key] for o in orders if o["surface"] == surface and o["order"] == 2), None)
        if value is None:
            continue
        met = value <= bound if kind == "max" else value >= bound
        fitted_n = next((o["N"] for o in orders if o["surface"] == surface and o["order"] == 2), "")
        shown = f"{value:.3g}" if "N = 201" in what else f"{value:.2f} (N = {fitted_n})"
        lines.append(
            f"| {surface} | {what} {'≤' if kind == 'max' else '≥'} {bound:g} | {shown} | {'yes' if met else 'no'} |"
        )
    return lines


#: Geodesic distances from the source at which :func:`nodal_profile` reports the nodal error
#: (π/4 is the circle x = 0, the antipode is at π/2).
PROFILE_DISTANCES = (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, np.pi / 4, 0.9, 1.0, 1.2, 1.4)


def nodal_profile(n: int) -> Dict[str, Any]:
    """Where the sphere's error comes from: the signed error of the order=2 *nodal* values against
    the exact solution in the tube (the great-circle distance of the node's closest point, constant
    along the normals), divided by Δx², averaged over the inner-tube nodes within 3Δx of the source,
    from 3Δx to 10Δx, and within Δx/2 of each of :data:`PROFILE_DISTANCES`. A source treatment
    error would show as a step within the first spacings that every N carries on; a truncation
    error of the scheme shows as a profile e(r)/Δx² that is the same at every N."""
    from .. import Grid, solve
    from ..surfaces import Sphere

    radius, src = 0.5, np.array([-0.5, 0.0, 0.0])
    g = Grid((-1.0,) * 3, (1.0,) * 3, (n,) * 3)
    h = g.spacing
    sol = solve(Sphere(radius), g, [src], order=2)
    p = sol.points
    foot = radius * p / np.linalg.norm(p, axis=1, keepdims=True)
    exact = radius * np.arccos(np.clip(foot @ src / radius**2, -1.0, 1.0))
    err = (sol.values - exact) / h**2
    inner = sol.inner_mask
    row: Dict[str, Any] = {
        "N": n,
        "near": float(err[inner & (exact < 3 * h)].mean()),
        "mid": float(err[inner & (exact >= 3 * h) & (exact < 10 * h)].mean()),
    }
    for r in PROFILE_DISTANCES:
        row[f"{r:.3g}"] = float(err[inner & (np.abs(exact - r) < 0.5 * h)].mean())
    return row


def profile_lines(rows: List[Dict[str, Any]]) -> List[str]:
    """The table of :func:`nodal_profile` rows."""
    keys = [f"{r:.3g}" for r in PROFILE_DISTANCES]
    lines = [
        "Sphere, order=2: signed error of the nodal values against the exact solution in the tube, ÷ Δx², "
        "by geodesic distance r from the source (inner-tube nodes; π/4 = 0.785 is the circle x = 0):",
        "",
        "| N | r < 3Δx | 3Δx ≤ r < 10Δx | " + " | ".join(f"r = {k}" for k in keys) + " |",
        "|---" * (3 + len(keys)) + "|",
    ]
    for row in rows:
        lines.append(
            f"| {row['N']} | {row['near']:+.3f} | {row['mid']:+.3f} | "
            + " | ".join(f"{row[k]:+.3f}" for k in keys)
            + " |"
        )
    return lines


def run(out_dir: Path, quick: bool) -> dict:
    rows: List[Dict[str, Any]] = []
    orders: List[Dict[str, Any]] = []
    for name, (make, sizes, quick_sizes) in CASES.items():
        try:
            case = make()
        except ImportError as e:  # geographiclib is optional
            print(f"{name}: skipped ({e})")
            continue
        ns = quick_sizes if quick else sizes
        for order in (1, 2):
            measured = [measure(case, n, order) for n in ns]
            for m in measured:
                rows.append({"surface": name, **m})
            hs = [2.0 / (m["N"] - 1) for m in measured]
            first = FIT_FROM.get(name, 0) if not quick else 0
            fit = [m for m in measured if m["N"] >= first]
            hf = [2.0 / (m["N"] - 1) for m in fit]
            fitted = {
                "surface": name,
                "order": order,
                "N": f"{fit[0]['N']}–{fit[-1]['N']}",
                "far_max_order": fit_order(hf, [m["far_max"] for m in fit]),
                "mean_order": fit_order(hf, [m["mean"] for m in fit]),
                # between consecutive sizes, all of them (also those before the fitted range)
                "pairwise": (
                    local_orders(hs, [m["far_max"] for m in measured]),
                    local_orders(hs, [m["mean"] for m in measured]),
                ),
            }
            if case[5]:
                fitted["circle_order"] = fit_order(hf, [m["circle x=0"] for m in fit])
            orders.append(fitted)
    columns = [
        "surface",
        "N",
        "order",
        "far_max",
        "mean",
        "circle x=0",
        "outer_kappa",
        "iterations",
        "seconds",
        "fallback",
    ]
    write_csv(out_dir / "second_order.csv", [{c: r.get(c, "") for c in columns} for r in rows])
    lines = [
        "Errors of `sol(points)` against exact geodesic distances; far: at least 0.1 from the source and "
        "the cut locus. Seconds: `ts.solve` including the band's set-up, on this machine.",
        "",
        "| surface | N | order | far max | mean | circle x=0 max | outer·Δx·κ | iterations | seconds |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        ring = f"{r['circle x=0']:.3e}" if "circle x=0" in r else ""
        resolved = f"{r['outer_kappa']:.2f}" if r.get("outer_kappa") is not None else ""
        lines.append(
            f"| {r['surface']} | {r['N']} | {r['order']} | {r['far_max']:.3e} | {r['mean']:.3e} | {ring} | "
            f"{resolved} | {r['iterations']} | {r['seconds']:.3f} |"
        )
    lines += [
        "",
        "| surface | N (fitted) | order | far max order | mean order | circle x=0 order | pairwise far max | "
        "pairwise mean |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for o in orders:
        ring = f"{o['circle_order']:.2f}" if "circle_order" in o else ""
        far_pw, mean_pw = (", ".join(f"{v:.2f}" for v in pw) for pw in o["pairwise"])
        lines.append(
            f"| {o['surface']} | {o['N']} | {o['order']} | {o['far_max_order']:.2f} | {o['mean_order']:.2f} | {ring} | "
            f"{far_pw} | {mean_pw} |"
        )
    profile = [nodal_profile(n) for n in ((51,) if quick else (101, 201, 401))]
    lines += [""] + profile_lines(profile)
    if not quick:
        lines += ["", "Targets for order=2 on surfaces (met or not):", ""] + target_lines(rows, orders)
    write_markdown(
        out_dir / "second_order.md", "order=2: errors and fitted orders (beyond the paper)", [("", "\n".join(lines))]
    )
    print("\n".join(lines))
    return {"rows": rows, "orders": orders, "profile": profile}


EXPERIMENTS = {"second-order": run}
