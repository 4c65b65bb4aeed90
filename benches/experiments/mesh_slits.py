"""Slits and pinches in meshes (python/tubesweep/surfaces/_mesh_slits.py, _mesh_pinches.py;
docs/meshes-and-output.md).

Two cases with exact answers, at several grid sizes and slit widths (in grid spacings):

* a cylinder of radius 0.3 and height 1 slit along its length, the source on the slit's edge:
  on the far side, from a spacing past its edge half-way round, the distance is the way round
  (the largest error there, in grid spacings, and the smallest ratio to the exact);
* a square sheet [−½, ½]² with a slit from its edge to y = 0.1, the source and three points on
  the two sides: the distance is the straight lines round the slit's end (the largest error in
  grid spacings);

the bundled bunny's slit report (slits are found and reported, and warned about where the band
joins their sides: the distances across those stay short); and two icospheres touching at a shared vertex (a pinch,
python/tubesweep/surfaces/_mesh_pinches.py), the source at the far pole of one, against exact
polyhedral geodesics through the pinch (pygeodesic), with the pinch's cut and without it. Prints the
narrowest slit found (``sol.stats.slits``), the order run and the warnings. About half a minute.

    python benches/experiments/mesh_slits.py
"""

from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import numpy as np

import tubesweep as ts

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests"))
from test_mesh_pinches import touching_spheres  # noqa: E402
from test_mesh_slits import R, slit_cylinder, slit_sheet  # noqa: E402


def _warned(caught) -> str:
    return "yes" if any("a slit" in m for m in caught) else "no"


def solve(surf, grid, source):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = ts.solve(surf, grid, [source])
    return sol, [str(w.message)[:120] for w in caught]


def cylinder() -> None:
    print("slit cylinder (r = 0.3), source on the slit's edge; far side from a spacing past its edge")
    print(
        "| N | turned | slit (spacings) | largest error (spacings) | smallest u / exact | far edge's vertices, most short | order | slit warned |"
    )
    print("|---|---|---|---|---|---|---|---|")
    cases = [(n, 0, s) for n in (41, 81) for s in (0.6, 1.0, 1.8, 3.0)] + [(81, 45, s) for s in (1.8, 2.3, 3.0)]
    for n, turn, spacings in cases:
        h = slit_cylinder(0.01).grid(n).spacing
        surf = slit_cylinder(spacings * h)
        c, s = np.cos(np.radians(turn)), np.sin(np.radians(turn))
        rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        surf = ts.surfaces.from_mesh((surf.vertices @ rotation.T, surf.faces))  # the slit turned about the axis
        grid = surf.grid(n)
        a = spacings * h / (2 * R)
        sol, caught = solve(surf, grid, rotation @ (R * np.cos(a), R * np.sin(a), 0.0))
        th = -a - np.linspace(grid.spacing / R, np.pi, 60)
        exact = R * (2 * np.pi + th - a)
        u = sol(np.c_[R * np.cos(th), R * np.sin(th), np.zeros_like(th)] @ rotation.T)
        # the far edge's own vertices (read by on_mesh, as ts.export does): the way round, unrolled
        unturned = surf.vertices @ rotation
        edge = np.abs(np.arctan2(unturned[:, 1], unturned[:, 0]) + a) < 1e-6
        edge_err = (
            sol.on_mesh(surf.vertices[edge]) - np.hypot(R * (2 * np.pi - 2 * a), unturned[edge, 2])
        ) / grid.spacing
        print(
            f"| {n} | {turn}° | {spacings:g} | {np.max(np.abs(u - exact)) / grid.spacing:.2f} | {np.min(u / exact):.3f} | "
            f"{max(0.0, -float(np.min(edge_err))):.2f} | {sol.stats.order} | {_warned(caught)} |"
        )


def sheet() -> None:
    print("\nsquare sheet with a slit to y = 0.1; source (−0.15, −0.3); points x = 0.15, y = −0.3, −0.1, 0.05")
    print("| N | slit (spacings) | largest error (spacings) | order | facing pairs | slit warned |")
    print("|---|---|---|---|---|---|")
    for n in (41, 81, 121):
        for k in (1, 3):
            surf, half, end = slit_sheet(k)
            grid = surf.grid(n)
            source = np.array([-0.15, -0.3, 0.0])
            points = np.array([[0.15, y, 0.0] for y in (-0.3, -0.1, 0.05)])
            sol, caught = solve(surf, grid, source)
            a, b = np.array([-half, end, 0.0]), np.array([half, end, 0.0])
            exact = np.linalg.norm(source - a) + 2 * half + np.linalg.norm(points - b, axis=1)
            err = np.max(np.abs(sol(points) - exact)) / grid.spacing
            print(
                f"| {n} | {2 * half / grid.spacing:.2f} | {err:.2f} | {sol.stats.order} | {sol.stats.facing_pairs} | "
                f"{_warned(caught)} |"
            )


def bunny() -> None:
    print("\nthe bundled bunny: sol.stats.slits")
    surf = ts.surfaces.from_mesh(ts.data.bunny())
    for n in (60, 100, 200):
        sol, caught = solve(surf, surf.grid(n), surf.default_source)
        s = sol.stats.slits
        share = f"{s['detour'] / s['size']:.1%}" if s else "-"
        print(
            f"n = {n}: {s and {k: s[k] for k in ('count', 'gap', 'detour')}} (detour {share} of its size), warnings {len(caught)}"
        )


def pinch() -> None:
    from tubesweep.surfaces.mesh import MeshSurface

    print("\ntwo icospheres (642 vertices each) touching at a shared vertex; errors in grid spacings")
    print("| N | pinch cut | far sphere, mean | far sphere, largest short | near sphere, mean | order |")
    print("|---|---|---|---|---|---|")
    vertices, faces, low, exact = touching_spheres()
    cut = MeshSurface._pinch_cut_pairs
    for n in (61, 101, 141):
        for on in (True, False):
            MeshSurface._pinch_cut_pairs = cut if on else None
            surf = ts.surfaces.from_mesh((vertices, faces))
            grid = surf.grid(n)
            sol, _ = solve(surf, grid, vertices[low])
            err = (sol.on_mesh(vertices) - exact) / grid.spacing
            far, near = vertices[:, 2] > 0.1, vertices[:, 2] < -0.1
            print(
                f"| {n} | {'yes' if on else 'no'} | {err[far].mean():.2f} | {-err[far].min():.2f} | "
                f"{err[near].mean():.2f} | {sol.stats.order} |"
            )
    MeshSurface._pinch_cut_pairs = cut


if __name__ == "__main__":
    t0 = time.perf_counter()
    cylinder()
    sheet()
    bunny()
    pinch()
    print(f"\n{time.perf_counter() - t0:.0f} s")
