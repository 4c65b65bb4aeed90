"""``order=2`` on every closed surface of the library: does it apply, does it converge without
warnings, is it more accurate than ``order=1``? The evidence behind ``order="auto"`` and the
choice of the default (docs/second-order.md, "The default").

For each closed library surface (the 2D curves and the 3D surfaces, the sphere and the spheroid
also as closest-point maps, the bunny mesh) and a few N over [−1, 1]^d, both orders are solved from
the surface's default source; the errors of ``sol(points)`` at points of the surface are taken
against the exact geodesic distance where the library has it (circle, ellipse, star, sphere;
the torus's outer equator) and otherwise against a fine ``order=2`` solution (N_ref below), whose
own error is far below the coarse grids' (the sphere's at N = 321: mean 1e-5). "far max" leaves
out the points within 0.1 of the source. Also printed: what ``order="auto"`` chose and why.

    .venv/bin/python benches/experiments/order2_surfaces.py [--quick] [--out out/order2_surfaces.md]
"""

from __future__ import annotations

import argparse
import time
import warnings
from pathlib import Path
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

import tubesweep as ts
from tubesweep import surfaces as S


def _grid(d: int, n: int) -> ts.Grid:
    return ts.Grid((-1.0,) * d, (1.0,) * d, (n,) * d)


def _points_3d(surf: Any, n: int, seed: int = 0) -> np.ndarray:
    """Points of a 3D surface: random directions from the origin, projected onto the surface."""
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(n, 3))
    v *= 0.5 / np.linalg.norm(v, axis=1, keepdims=True)
    _, p = surf.project(v, _grid(3, 201))
    # a second projection brings the points onto the surface to rounding
    _, p = surf.project(p, _grid(3, 201))
    return p


# name: (surface, sizes, quick sizes, exact distance or None, reference N for a fine order=2 solution)
CASES: Dict[str, Tuple[Any, Tuple[int, ...], Tuple[int, ...], bool, Optional[int]]] = {
    "circle (2D)": (S.Circle(0.5), (51, 101, 201), (51, 101), True, None),
    "ellipse (2D)": (S.Ellipse(), (51, 101, 201), (51, 101), True, None),
    "six-fold star (2D)": (S.Star(), (101, 201, 401), (201, 401), True, None),
    "sphere": (S.Sphere(0.5), (51, 101, 201), (51, 101), True, None),
    "sphere (closest-point map)": (
        ts.ClosestPoint(lambda x: 0.5 * x / np.linalg.norm(x, axis=1, keepdims=True)),
        (51, 101),
        (51,),
        True,
        None,
    ),
    "ellipsoid 0.6/0.45/0.3": (S.Ellipsoid(), (51, 101, 201), (51, 101), False, 321),
    "spheroid 0.6/0.6/0.4 (closest-point map)": (
        ts.ClosestPoint(S.Ellipsoid(0.6, 0.6, 0.4).closest_point),
        (51, 101),
        (51,),
        False,
        321,
    ),
    "torus 0.5/0.2": (S.Torus(), (51, 101, 201), (51, 101), False, 321),
    "rounded cube 0.5/0.1": (S.RoundedCube(), (51, 101, 201), (101,), False, 321),
    "double torus": (S.DoubleTorus(), (51, 101), (51,), False, None),
}


def _case_points(name: str, surf: Any) -> Tuple[np.ndarray, Any]:
    """Points on the surface and the source."""
    if "closest-point" in name:
        base = S.Sphere(0.5) if name.startswith("sphere") else S.Ellipsoid(0.6, 0.6, 0.4)
        return _points_3d(base, 2000), np.array([-0.5, 0, 0]) if name.startswith("sphere") else np.array([-0.6, 0, 0])
    if hasattr(surf, "sample") and surf.ndim == 2:
        return surf.sample(2000), np.asarray(surf.default_source, float)
    return _points_3d(surf, 2000), np.asarray(surf.default_source, float)


def _exact(name: str, surf: Any, pts: np.ndarray, src: np.ndarray) -> np.ndarray:
    if "closest-point" in name:
        return S.Sphere(0.5).geodesic_distance(pts, src)
    return surf.geodesic_distance(pts, src)


def _solve(surf: Any, n: int, d: int, src: np.ndarray, order: Any) -> Tuple[Any, List[str], float, Optional[str]]:
    """The solution (None when refused), the warnings, the seconds, the refusal's text."""
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        t0 = time.perf_counter()
        try:
            sol = ts.solve(surf, _grid(d, n), [src], order=order)
        except ValueError as e:
            return None, [str(x.message) for x in w], time.perf_counter() - t0, str(e)
        return sol, [str(x.message) for x in w], time.perf_counter() - t0, None


def run(quick: bool) -> List[Dict[str, Any]]:
    rows: List[Dict[str, Any]] = []
    for name, (surf, sizes, quick_sizes, exact, n_ref) in CASES.items():
        d = 2 if "(2D)" in name else 3
        pts, src = _case_points(name, surf)
        ref = _exact(name, surf, pts, src) if exact else None
        ref_note = "exact"
        if ref is None and n_ref is not None:
            sol_ref, _, _, why = _solve(surf, n_ref, d, src, 2)
            ref = None if sol_ref is None else sol_ref(pts)
            ref_note = f"order=2 at N={n_ref}"
        for n in quick_sizes if quick else sizes:
            row: Dict[str, Any] = {"surface": name, "N": n, "reference": ref_note if ref is not None else "none"}
            for order in (1, 2):
                sol, warns, sec, why = _solve(surf, n, d, src, order)
                key = f"o{order}"
                row[f"{key}_seconds"] = sec
                row[f"{key}_warnings"] = len(warns)
                if sol is None:
                    row[f"{key}_refused"] = why
                    continue
                row[f"{key}_converged"] = bool(sol.stats.converged)
                if order == 2:
                    o2 = sol.stats.order2 or {}
                    row["safeguard"] = o2.get("fallback_iteration")
                    row["runaway"] = o2.get("runaway_iteration")
                if ref is not None:
                    e = np.abs(sol(pts) - ref)
                    far = ref >= 0.1
                    row[f"{key}_far_max"] = float(np.nanmax(e[far]))
                    row[f"{key}_mean"] = float(np.nanmean(e))
            auto = _solve(surf, n, d, src, "auto")[0]
            if auto is not None:
                row["auto"] = auto.stats.order
            rows.append(row)
            print(_line(row), flush=True)
    return rows


def _fmt(v: Any) -> str:
    return "–" if v is None else f"{v:.2g}"


HEADER = (
    "| surface | N | reference | order=2 applies | converged, warnings (order=1 / order=2) | far max order=1 → order=2 "
    "| mean order=1 → order=2 | gain (mean) | time ratio | auto |\n|---|---|---|---|---|---|---|---|---|---|"
)


def _line(r: Dict[str, Any]) -> str:
    applies = "no: " + r["o2_refused"].split(". ")[0][:90] if "o2_refused" in r else "yes"
    conv = (
        f"{r.get('o1_converged', '–')}, {r['o1_warnings']} / {r.get('o2_converged', '–')}, {r['o2_warnings']}"
        + (f" (safeguard at {r['safeguard']})" if r.get("safeguard") is not None else "")
        + (" (RUNAWAY)" if r.get("runaway") is not None else "")
    )
    gain = r["o1_mean"] / r["o2_mean"] if "o2_mean" in r and "o1_mean" in r and r["o2_mean"] > 0 else None
    return (
        f"| {r['surface']} | {r['N']} | {r['reference']} | {applies} | {conv} | "
        f"{_fmt(r.get('o1_far_max'))} → {_fmt(r.get('o2_far_max'))} | {_fmt(r.get('o1_mean'))} → "
        f"{_fmt(r.get('o2_mean'))} | {'–' if gain is None else f'{gain:.0f}×'} | "
        f"{r['o2_seconds'] / r['o1_seconds']:.1f} | {r.get('auto', '–')} |"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", type=Path, default=Path("out/order2_surfaces.md"))
    args = ap.parse_args()
    print(HEADER)
    rows = run(args.quick)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(HEADER + "\n" + "\n".join(_line(r) for r in rows) + "\n")
    # the bunny: a closed mesh, refused by order=2 (its closest points are piecewise flat)
    bunny = S.from_mesh(ts.data.bunny())
    lo, hi = (np.asarray(b, float) for b in bunny.default_box)
    side = float(np.max(hi - lo))
    g = ts.Grid(tuple((lo + hi - side) / 2), tuple((lo + hi + side) / 2), (61,) * 3)
    try:
        ts.solve(bunny, g, [bunny.default_source], order=2)
        print("bunny mesh: order=2 applied")
    except ValueError as e:
        print("bunny mesh: order=2 refused:", str(e)[:160])


if __name__ == "__main__":
    main()
