"""A flat disc whose rim zigzags at the grid's scale (python/tubesweep/surfaces/_mesh_notches.py):
a jittered lattice of spacing 0.02 on [−0.55, 0.55]², Delaunay-triangulated (scipy), the triangles
whose three vertices lie within 0.5 of the centre kept, tilted by 0.3 rad about x in the box
[−0.7, 0.7]³; the source at the rim vertex nearest (−0.5, 0). Per N: the order run, the facing
pairs left, and the errors of ``sol.on_mesh`` against exact polyhedral geodesics (pygeodesic) at
the rim's vertices and the others, with the notch test (``after``) and without it
(``before``: ``NOTCH_REACH`` and ``NOTCH_RATIO`` set to 0)::

    .venv/bin/python benches/experiments/rim_notches.py
    .venv/bin/python benches/experiments/rim_notches.py --n 61 91 121
    .venv/bin/python benches/experiments/rim_notches.py --rolled     # the test's cost, a few seconds

``--rolled``: what the notch test costs where many facing pairs lie next to a rim: a sheet
rolled 1.6 turns (an Archimedean spiral from radius 0.08, 0.08 between turns, 0.5 wide, meshed at
0.006: about 20,000 vertices) at N = 61, the time of ``ts.solve`` with the test and without it,
alternated over five rounds (medians, and their ratio).
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np


def jagged_disc(spacing: float = 0.02, seed: int = 1):
    """Vertices, faces, the source vertex and the rim's vertices of the tilted jagged disc."""
    from scipy.spatial import Delaunay

    rng = np.random.default_rng(seed)
    g = np.arange(-0.55, 0.55 + 1e-9, spacing)
    x, y = np.meshgrid(g, g)
    p = np.c_[x.ravel(), y.ravel()] + rng.uniform(-0.3 * spacing, 0.3 * spacing, (x.size, 2))
    t = Delaunay(p).simplices
    f = t[(np.linalg.norm(p[t], axis=2) <= 0.5).all(axis=1)]
    used = np.unique(f)
    renumber = np.full(len(p), -1)
    renumber[used] = np.arange(len(used))
    flat, f = p[used], renumber[f]
    turn = 0.3
    rotation = np.array([[1, 0, 0], [0, np.cos(turn), -np.sin(turn)], [0, np.sin(turn), np.cos(turn)]])
    v = np.c_[flat, np.full(len(flat), 0.0113)] @ rotation.T
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [0, 2]]]), axis=1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    rim = np.zeros(len(v), bool)
    rim[unique[counts == 1].ravel()] = True
    source = int(np.argmin(np.linalg.norm(flat - (-0.5, 0.0), axis=1)))
    return v, f, source, rim


def rolled_sheet(start: float = 0.08, pitch: float = 0.08, turns: float = 1.6, step: float = 0.006):
    """Vertices, faces and a source vertex (on the outer rim) of a sheet rolled along an Archimedean
    spiral r = start + pitch·θ/2π, 0.5 wide along y, meshed at about ``step``."""
    angles = [0.0]
    while angles[-1] < 2 * np.pi * turns:
        angles.append(angles[-1] + step / (start + pitch * angles[-1] / (2 * np.pi)))
    theta = np.array(angles)
    r = start + pitch * theta / (2 * np.pi)
    y = np.linspace(-0.25, 0.25, int(0.5 / step) + 1)
    ring, across = len(theta), len(y)
    v = np.column_stack([np.repeat(r * np.cos(theta), across), np.tile(y, ring), np.repeat(r * np.sin(theta), across)])
    i = np.arange(ring * across).reshape(ring, across)
    a, b, c, d = i[:-1, :-1].ravel(), i[1:, :-1].ravel(), i[1:, 1:].ravel(), i[:-1, 1:].ravel()
    return v, np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])]), int(i[-1, across // 2])


def rolled(rounds: int = 5) -> None:
    """The ``--rolled`` timing (see the module)."""
    import time

    import tubesweep as ts
    from tubesweep.surfaces import _mesh_notches

    v, f, source = rolled_sheet()
    grid = ts.Grid((-0.7,) * 3, (0.7,) * 3, (61,) * 3)
    reach, ratio = _mesh_notches.NOTCH_REACH, _mesh_notches.NOTCH_RATIO
    times: dict = {"without": [], "with": []}
    for _ in range(rounds):
        for label, settings in (("without", (0.0, 0.0)), ("with", (reach, ratio))):
            _mesh_notches.NOTCH_REACH, _mesh_notches.NOTCH_RATIO = settings
            mesh = ts.surfaces.from_mesh((v, f))
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                start = time.perf_counter()
                sol = ts.solve(mesh, grid, [v[source]])
                times[label].append(time.perf_counter() - start)
    _mesh_notches.NOTCH_REACH, _mesh_notches.NOTCH_RATIO = reach, ratio
    without, with_test = np.median(times["without"]), np.median(times["with"])
    print(f"rolled sheet, {len(v)} vertices, N = 61: order {sol.stats.order}, {sol.stats.facing_pairs} facing pairs; "
          f"ts.solve median {without:.3f} s without the notch test, {with_test:.3f} s with it ({with_test / without:.2f}x)")  # fmt: skip


def main() -> None:
    import pygeodesic.geodesic as geodesic

    import tubesweep as ts
    from tubesweep.surfaces import _mesh_notches

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, nargs="+", default=[41, 61, 71, 81, 91, 111, 121])
    ap.add_argument("--rolled", action="store_true", help="the notch test's cost on a rolled sheet instead")
    args = ap.parse_args()
    if args.rolled:
        rolled()
        return
    v, f, source, rim = jagged_disc()
    exact, _ = geodesic.PyGeodesicAlgorithmExact(v, f).geodesicDistances(np.array([source]), None)
    reach, ratio = _mesh_notches.NOTCH_REACH, _mesh_notches.NOTCH_RATIO
    print("| N | notch test | order | facing pairs | rim: mean, min | others: mean, min |")
    print("|---|---|---|---|---|---|")
    for n in args.n:
        grid = ts.Grid((-0.7,) * 3, (0.7,) * 3, (n,) * 3)
        for label, settings in (("before", (0.0, 0.0)), ("after", (reach, ratio))):
            _mesh_notches.NOTCH_REACH, _mesh_notches.NOTCH_RATIO = settings
            mesh = ts.surfaces.from_mesh((v, f))
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                sol = ts.solve(mesh, grid, [v[source]])
            e = sol.on_mesh(v) - exact
            print(
                f"| {n} | {label} | {sol.stats.order} | {sol.stats.facing_pairs} | {e[rim].mean():+.4f}, "
                f"{e[rim].min():+.4f} | {e[~rim].mean():+.5f}, {e[~rim].min():+.4f} |"
            )
    _mesh_notches.NOTCH_REACH, _mesh_notches.NOTCH_RATIO = reach, ratio


if __name__ == "__main__":
    main()
