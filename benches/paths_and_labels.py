"""Geodesic paths and nearest-source labels, measured on the sphere against great circles.

For the sphere of radius 0.5 in [−1, 1]³ (N nodes per side) with one source at (−0.5, 0, 0),
40 random starts at least 0.3 from the antipode (the cut locus): the error of the paths'
lengths against the great-circle distance (and that of ``u`` at the starts), their largest distance from the great circle's
plane, and the time of tracing all 40 together. Then four sources: the share of band nodes
whose label differs from the nearest source along great circles, among the nodes more than two
grid spacings from a cell boundary and among the rest, and the time of the labels. Then paths from points on the boundaries of
two and of three of three sources' regions. Last, on
the Stanford bunny (``ts.data.bunny()``, grid ``surface.grid(n)``) from vertex 0 to 8 random
vertices: the paths' lengths and ``u`` against the exact polyhedral geodesic distances
(pygeodesic, MMP; skipped without it or the data), and the time of the labels at all its vertices
with two sources. These are the figures of
docs/paths-and-labels.md::

    .venv/bin/python benches/paths_and_labels.py            # N = 41, 81, 161, 321
    .venv/bin/python benches/paths_and_labels.py 41 81
    .venv/bin/python benches/paths_and_labels.py --order auto   # the sphere's tables at the default order

The sphere's tables are of the paper's first-order scheme (``order=1``) unless ``--order auto``
(the default of ``ts.solve``: second order on the sphere); the bunny's are of ``order=1`` (its
default there).
"""

from __future__ import annotations

import sys
import time

import numpy as np

import tubesweep as ts

R = 0.5


def starts(m: int, src: np.ndarray, seed: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < m:
        p = rng.normal(size=3)
        p *= R / np.linalg.norm(p)
        if R * np.arccos(np.clip(p @ src / R**2, -1, 1)) < np.pi * R - 0.3:
            out.append(p)
    return np.array(out)


def main(sizes: list, order: object = 1) -> int:
    src = np.array([-R, 0.0, 0.0])
    places = 2 if order == 1 else 3  # (second order's errors are hundredths of h)
    print(f"order={order!r}; paths: sphere r = 0.5, source (-0.5, 0, 0), 40 starts at least 0.3 from the antipode")
    print(
        "| N | h | length error max | max / h | u error at the starts, max / h | off the great circle: median | max "
        "| trace 40 paths |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for n in sizes:
        g = ts.Grid((-1, -1, -1), (1, 1, 1), (n, n, n))
        h = g.spacing
        sol = ts.solve(ts.surfaces.Sphere(R), g, [src], order=order)
        st = starts(40, src)
        t = time.perf_counter()
        paths = sol.geodesic_paths(st)
        took = time.perf_counter() - t
        err, off, uerr = [], [], []
        for s0, p in zip(st, paths):
            exact = R * np.arccos(np.clip(src @ s0 / R**2, -1, 1))
            err.append(abs(np.linalg.norm(np.diff(p, axis=0), axis=1).sum() - exact))
            uerr.append(abs(sol(s0[None])[0] - exact))
            nrm = np.cross(s0, src)
            off.append(np.max(np.abs(p @ (nrm / np.linalg.norm(nrm)))))
        print(
            f"| {n} | {h:.4g} | {max(err):.2e} | {max(err) / h:.{places}f} | {max(uerr) / h:.{places}f} | "
            f"{np.median(off):.2e} | "
            f"{max(off):.2e} | "
            f"{1e3 * took:.0f} ms |"
        )
    sources = np.array([[R, 0, 0], [-R, 0, 0], [0, 0, R], [0, -R * 0.6, -R * 0.8]])
    print()
    print("labels: the same sphere, four sources; label differs from the nearest source along great circles")
    print("| N | band nodes | > 2h from a cell boundary | within 2h | labels |")
    print("|---|---|---|---|---|")
    for n in sizes:
        g = ts.Grid((-1, -1, -1), (1, 1, 1), (n, n, n))
        sol = ts.solve(ts.surfaces.Sphere(R), g, sources, order=order)
        t = time.perf_counter()
        lab = sol.nearest_source()
        took = time.perf_counter() - t
        x = sol.points
        cp = R * x / np.linalg.norm(x, axis=1)[:, None]
        geo = R * np.arccos(np.clip(cp @ sources.T / R**2, -1, 1))
        srt = np.sort(geo, axis=1)
        away = srt[:, 1] - srt[:, 0] > 2 * g.spacing
        wrong = lab != np.argmin(geo, axis=1)
        print(
            f"| {n} | {len(lab):,} | {wrong[away].sum()} of {away.sum():,} | {wrong[~away].sum():,} of "
            f"{(~away).sum():,} ({100 * wrong[~away].mean():.0f}%) | {1e3 * took:.1f} ms |"
        )
    print()
    print("paths from where regions meet: sources (±0.5, 0, 0), (0, 0, 0.5); length error against π/4, in h")
    print("| N | from (0, -0.3, -0.4): two regions | from (0, 0.5, 0): three regions |")
    print("|---|---|---|")
    for n in sizes:
        g = ts.Grid((-1, -1, -1), (1, 1, 1), (n, n, n))
        sol = ts.solve(ts.surfaces.Sphere(R), g, sources[:3], order=order)
        two = np.array([0.0, -0.3, -0.4])
        lengths = [np.linalg.norm(np.diff(p, axis=0), axis=1).sum() for p in sol.geodesic_paths([two, (0.0, R, 0.0)])]
        e = [abs(v - np.pi / 4) / g.spacing for v in lengths]
        print(f"| {n} | {e[0]:.{places}f} | {e[1]:.{places}f} |")
    if order == 1:
        bunny_rows(sizes)
    return 0


def bunny_rows(sizes: list) -> None:
    mesh_file = ts.data.bunny()
    try:
        import pygeodesic.geodesic as geodesic
    except ImportError:
        print("\nbunny: skipped (pip install pygeodesic)")
        return
    if not mesh_file.exists():
        print(f"\nbunny: skipped ({mesh_file} not found)")
        return
    bunny = ts.surfaces.from_mesh(mesh_file)
    v = bunny.vertices
    targets = np.random.default_rng(0).choice(len(v), 8, replace=False)
    # one propagation from vertex 0 to all eight (one per target took 8 times as long)
    exact, _ = geodesic.PyGeodesicAlgorithmExact(v, bunny.faces).geodesicDistances(np.array([0]), targets)
    print()
    print("bunny: from vertex 0 to 8 random vertices, against exact polyhedral geodesics (MMP); errors in h")
    print("| N | h | path length error: mean | max | u error: mean | max |")
    print("|---|---|---|---|---|---|")
    for n in sizes:
        if n > 201:
            continue
        g = bunny.grid(n)
        sol = ts.solve(bunny, g, [v[0]], order=1)
        lengths = np.array([np.linalg.norm(np.diff(p, axis=0), axis=1).sum() for p in sol.geodesic_paths(v[targets])])
        u = sol.on_mesh(v[targets])
        el, eu = np.abs(lengths - exact) / g.spacing, np.abs(u - exact) / g.spacing
        print(f"| {n} | {g.spacing:.3g} | {el.mean():.2f} | {el.max():.2f} | {eu.mean():.2f} | {eu.max():.2f} |")
    nb = max((n for n in sizes if n <= 201), default=161)
    two = ts.solve(bunny, bunny.grid(nb), v[[0, 20000]], order=1)
    t = time.perf_counter()
    two.nearest_source()
    t1 = time.perf_counter()
    two.nearest_source(v)
    t2 = time.perf_counter()
    print(
        f"\nbunny, two sources, N = {nb}: labels of the {len(two.values):,} band nodes in {1e3 * (t1 - t):.0f} ms, "
        f"then at its {len(v):,} vertices in {1e3 * (t2 - t1):.0f} ms"
    )


if __name__ == "__main__":
    args = sys.argv[1:]
    chosen: object = 1
    if "--order" in args:
        i = args.index("--order")
        chosen = args[i + 1] if args[i + 1] == "auto" else int(args[i + 1])
        del args[i : i + 2]
    sys.exit(main([int(a) for a in args] or [41, 81, 161, 321], chosen))
