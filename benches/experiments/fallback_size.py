"""How large ``order="auto"``'s first-order fallback's errors are, against what its warning says
(``python/tubesweep/_fallback.py``, docs/second-order.md, "order='auto'").

On coarse grids where second order does not apply, per surface and N: the order that ran, the
largest error over points of the surface as a share of the largest distance, and the share the
warning states (— where it did not warn; + the edges' term when it adds one per edge crossed).
The sphere of radius 0.5 against the great circles from (−0.5, 0, 0), also with φ scaled by
0.5, as |x|² − 0.25 (not a distance: given as it is and re-distanced) and as 0.4·tanh(d/0.4) (smooth,
not quite a distance); the circle of radius
0.5 from (−0.5, 0); the hemisphere from its pole (an open surface: never warned about); the tori (0.6, 0.25) from (0.85, 0, 0) and (0.5, 0.2) from (0.7, 0, 0), the ellipsoid (0.8, 0.5, 0.3) from (0.8, 0, 0) and
``RoundedCube()`` from its bottom face's centre against second-order solves at N = 201 (a minute
or two each)::

    .venv/bin/python benches/experiments/fallback_size.py            # N = 12–41
    .venv/bin/python benches/experiments/fallback_size.py --quick    # the sphere only
"""

from __future__ import annotations

import argparse
import re
import warnings

import numpy as np

import tubesweep as ts

R = 0.5


def stated(caught) -> str:
    for w in caught:
        m = re.search(r"errors up to about (\d+)% of the distances", str(w.message))
        if m:
            edge = re.search(r"more \((\d+)% of the largest\) for each edge", str(w.message))
            return m.group(1) + "%" + (f" + {edge.group(1)}% per edge" if edge else "")
    return "—"


def surface_points(name: str, surface: object = None) -> np.ndarray:
    if name == "circle":
        t = np.linspace(0, 2 * np.pi, 240, endpoint=False)
        return R * np.c_[np.cos(t), np.sin(t)]
    if name == "torus":
        t = np.linspace(0, 2 * np.pi, 60, endpoint=False)
        a, b = np.meshgrid(t, t)
        big, small = (surface.R, surface.r) if isinstance(surface, ts.surfaces.Torus) else (0.6, 0.25)
        rho = big + small * np.cos(b)
        return np.c_[(rho * np.cos(a)).ravel(), (rho * np.sin(a)).ravel(), (small * np.sin(b)).ravel()]
    th, ph = np.meshgrid(np.linspace(0.05, np.pi - 0.05, 40), np.linspace(0, 2 * np.pi, 60, endpoint=False))
    if name == "rounded cube":
        p = np.random.default_rng(0).uniform(-1, 1, (3000, 3))
        return 0.5 * p / np.abs(p).max(axis=1, keepdims=True)  # on the cube; its rounding is within 0.03
    if name == "ellipsoid":
        return np.c_[
            (0.8 * np.sin(th) * np.cos(ph)).ravel(), (0.5 * np.sin(th) * np.sin(ph)).ravel(), (0.3 * np.cos(th)).ravel()
        ]
    on = R * np.c_[(np.sin(th) * np.cos(ph)).ravel(), (np.sin(th) * np.sin(ph)).ravel(), np.cos(th).ravel()]
    return on[on[:, 2] > 0.02] if name == "hemisphere" else on


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    square = lambda p: (p**2).sum(axis=1) - R**2  # noqa: E731  # |∇φ| = 2|x|: not a distance
    cases = [
        ("sphere", ts.surfaces.Sphere(R), (-R, 0.0, 0.0), (12, 16, 20, 25)),
        ("sphere, φ·0.5", lambda p: 0.5 * (np.linalg.norm(p, axis=1) - R), (-R, 0.0, 0.0), (31, 41)),
        ("sphere, |x|² − R²", square, (-R, 0.0, 0.0), (41, 61)),
        ("sphere, |x|² − R² re-distanced", ts.LevelSet(square, redistance=True), (-R, 0.0, 0.0), (61,)),
        # smooth but not quite a distance: |∇φ| falls from 1 to 0.94 across the inner tube
        (
            "sphere, 0.4·tanh(d/0.4)",
            lambda p: 0.4 * np.tanh((np.linalg.norm(p, axis=1) - R) / 0.4),
            (-R, 0.0, 0.0),
            (41,),
        ),
        ("circle", ts.surfaces.Circle(R), (-R, 0.0), (12, 16, 21, 31, 61)),
        ("hemisphere (open)", ts.surfaces.Hemisphere(R), (0.0, 0.0, R), (16, 21)),
    ]
    if not args.quick:
        cases += [
            ("rounded cube", ts.surfaces.RoundedCube(), (0.0, 0.0, -0.5), (41, 51, 61)),
            ("torus", ts.surfaces.Torus(0.6, 0.25), (0.85, 0.0, 0.0), (16, 21, 26, 31, 41)),
            ("torus (0.5, 0.2)", ts.surfaces.Torus(0.5, 0.2), (0.7, 0.0, 0.0), (41,)),
            ("ellipsoid", ts.surfaces.Ellipsoid(0.8, 0.5, 0.3), (0.8, 0.0, 0.0), (16, 21, 26, 31, 41)),
        ]
    print(
        "| surface | N | order | tube thinned (nodes) | largest error / largest distance | largest error / Δx "
        "| the warning says |"
    )
    print("|---|---|---|---|---|---|---|")
    for name, surface, src, ns in cases:
        d = len(src)
        key = next(
            k for k in ("rounded cube", "sphere", "circle", "hemisphere", "torus", "ellipsoid") if name.startswith(k)
        )
        pts = surface_points(key, surface)
        if key in ("sphere", "circle", "hemisphere"):
            exact = R * np.arccos(np.clip(pts @ np.asarray(src) / R**2, -1, 1))
        else:
            exact = ts.solve(surface, ts.Grid((-1,) * 3, (1,) * 3, (201,) * 3), [src], order=2)(pts)
            pts, exact = pts[np.isfinite(exact)], exact[np.isfinite(exact)]
        for n in ns:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                grid = ts.Grid((-1,) * d, (1,) * d, (n,) * d)
                sol = ts.solve(surface, grid, [src])
            error = np.max(np.abs(sol(pts) - exact))
            first = ""
            if sol.stats.order == 2:  # what the first-order scheme would have given there
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    one = ts.solve(surface, grid, [src], order=1)
                first = f" (order=1: {100 * np.max(np.abs(one(pts) - exact)) / np.max(exact):.1f}%)"
            print(
                f"| {name} | {n} | {sol.stats.order} | {sol.stats.crease_thinned} | {100 * error / np.max(exact):.1f}%{first} | "
                f"{error / grid.spacing:.1f} | {stated(caught)} |"
            )


if __name__ == "__main__":
    main()
