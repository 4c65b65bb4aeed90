"""``make demo`` / ``tubesweep demo``: geodesic distance on a sphere and a six-fold star with both
Hamiltonians, geodesic paths to the nearest of three sources on the sphere, a layered-medium travel
time in the box, a table and pictures."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np


def run_demo(out: Path, quick: bool = False) -> int:
    from ._plot import plot
    from .euclidean import travel_time
    from .grid import Grid
    from .solve import solve
    from .surfaces import Sphere, Star

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []

    sphere = Sphere(0.5)
    n3 = 61 if quick else 121
    grid3 = Grid((-1, -1, -1), (1, 1, 1), (n3,) * 3)
    th = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    ring = np.stack([np.zeros_like(th), 0.5 * np.cos(th), 0.5 * np.sin(th)], axis=1)
    for ham in ("godunov", "lxf"):
        t0 = time.perf_counter()
        sol = solve(sphere, grid3, [sphere.default_source], hamiltonian=ham)
        wall = time.perf_counter() - t0
        err = np.nanmax(np.abs(sol(ring) - np.pi / 4))
        rows.append(("sphere r=0.5", ham, n3, err, sol.stats, wall))
        if ham == "godunov":
            # the default views: the first faces the source, the second its antipode
            fig = plot(
                sol,
                title=f"geodesic distance on a sphere of radius 0.5 from the red star (grid {n3}³)",
            )
            fig.savefig(out / "sphere.png", dpi=110, bbox_inches="tight")

    # three sources: each start's path runs to the source that reaches it first
    # (on the side the first view faces)
    sources = np.array([[0.6, -0.7, 0.3], [-0.5, -0.8, -0.2], [0.1, -0.3, 0.95]])
    sources = 0.5 * sources / np.linalg.norm(sources, axis=1)[:, None]
    sol = solve(sphere, grid3, sources)
    starts = np.array([[0.0, -1.0, 0.0], [0.5, -0.6, -0.6], [-0.7, -0.6, 0.4], [0.9, -0.3, 0.6], [-0.2, -0.5, -0.8]])
    starts = 0.5 * starts / np.linalg.norm(starts, axis=1)[:, None]
    paths = sol.geodesic_paths(starts)
    lengths = np.array([np.linalg.norm(np.diff(p, axis=0), axis=1).sum() for p in paths])
    exact = 0.5 * np.arccos(np.clip(starts @ sources.T / 0.25, -1, 1)).min(axis=1)
    path_err, u_err = np.max(np.abs(lengths - exact)), np.max(np.abs(sol(starts) - exact))
    fig = plot(
        sol, paths=paths, title=f"shortest paths (from the white circles) to the nearest of three sources, grid {n3}³"
    )
    fig.savefig(out / "sphere_paths.png", dpi=100, bbox_inches="tight")

    star = Star()
    n2 = 201 if quick else 801
    grid2 = Grid((-1, -1), (1, 1), (n2, n2))
    pts = star.sample(2000)
    exact = star.geodesic_distance(pts, star.default_source)  # type: ignore[arg-type]
    for ham in ("godunov", "lxf"):
        t0 = time.perf_counter()
        sol = solve(star, grid2, [star.default_source], hamiltonian=ham)
        wall = time.perf_counter() - t0
        err = np.nanmax(np.abs(sol(pts) - exact))
        rows.append(("six-fold star", ham, n2, err, sol.stats, wall))
        if ham == "godunov":
            fig = plot(sol, title=f"arclength on the six-fold star from the red star (grid {n2}²)")
            fig.savefig(out / "star.png", dpi=110, bbox_inches="tight")

    # a layered medium in the box: speed from 1 below y = 0 to 2 above, a tanh ramp
    gridb = Grid((-1, -1), (1, 1), (301, 301))
    speed = lambda p: 1.5 + 0.5 * np.tanh(8 * p[:, 1])  # noqa: E731
    u, st = travel_time(gridb, [(0.0, -0.6)], speed=speed, return_stats=True)
    X, Y = gridb.meshgrid()
    fig = plot(
        u,
        grid=gridb,
        sources=[(0.0, -0.6)],
        speed=1.5 + 0.5 * np.tanh(8 * Y),
        title="travel time from the red star, speed 1.5 + 0.5 tanh(8y)",
    )
    fig.savefig(out / "layered.png", dpi=110, bbox_inches="tight")

    print(
        f"{'problem':<16} {'H':<8} {'order':>5} {'N':>5} {'max error':>10} {'iters':>6} {'band pts':>9} {'sweeps s':>9} {'wall s':>8}"
    )
    for name, ham, n, err, s, wall in rows:
        print(
            f"{name:<16} {ham:<8} {s.order:>5} {n:>5} {err:>10.2e} {s.iterations:>6} {s.band_points:>9} {s.seconds:>9.3f} {wall:>8.3f}"
        )
    print(
        f"geodesic paths on the sphere (5 starts, 3 sources, N={n3}): length error max {path_err:.2e} "
        f"(u at the starts: {u_err:.2e})"
    )
    print(f"layered medium (box 301^2, Godunov): {st.iterations} iterations, sweeps {st.seconds:.3f} s")
    print(f"pictures: {out / 'sphere.png'}, {out / 'sphere_paths.png'}, {out / 'star.png'}, {out / 'layered.png'}")
    return 0
