"""Holes in a mesh (python/tubesweep/surfaces/_mesh_holes.py): an icosphere of radius 0.6
(trimesh, 5 subdivisions, 10,242 vertices) with three holes of radius ``--radius`` punched at
(0.6, 0, 0), (0, 0.6, 0) and (0, 0, −0.6), the source at the north pole. Errors of ``sol(vertices)``
against exact polyhedral geodesics (pygeodesic), at vertices within 0.08 of a hole's centre and
at those over 0.3 away, for ``order="auto"`` and ``order=1``; and whether the band bridges the
holes (``sol.stats.bridged_holes``)::

    .venv/bin/python benches/experiments/mesh_holes.py                 # N = 41 ... 161, a minute
    .venv/bin/python benches/experiments/mesh_holes.py --n 61 --radius 0.05
    .venv/bin/python benches/experiments/mesh_holes.py --bunny        # the bundled bunny's base holes

``--bunny``: the bundled bunny's holes (their widths and detours against its size) and the errors
of ``sol.on_mesh`` at its vertices within 0.02 of a hole's centre and elsewhere, in grid
spacings, the source at its default vertex (an ear tip), at n = 60, 100, 150, 200.
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np


def holed_sphere(radius: float, subdivisions: int = 5):
    import trimesh

    m = trimesh.creation.icosphere(subdivisions=subdivisions, radius=0.6)
    v, f = np.asarray(m.vertices), np.asarray(m.faces)
    centres = np.array([(0.6, 0, 0), (0, 0.6, 0), (0, 0, -0.6)])
    mid = v[f].mean(axis=1)
    drop = np.min(np.linalg.norm(mid[:, None] - centres[None], axis=2), axis=1) < radius
    kept = trimesh.Trimesh(v, f[~drop], process=False)
    kept.remove_unreferenced_vertices()
    return np.asarray(kept.vertices), np.asarray(kept.faces), centres


def bunny() -> None:
    import pygeodesic.geodesic as geodesic

    import tubesweep as ts
    from tubesweep.surfaces import _mesh_holes

    surface = ts.surfaces.from_mesh(ts.data.bunny())
    found = _mesh_holes.holes(surface)
    v = surface.vertices[surface.used_vertices]
    size = float(np.linalg.norm(v.max(axis=0) - v.min(axis=0)))
    print(f"bunny: size {size:.4f}; holes: widths {np.round(found.width, 4).tolist()}, detours "
          f"{np.round(found.detour, 4).tolist()} ({np.round(100 * found.detour / size, 1).tolist()} % of its size)")  # fmt: skip
    src = surface.default_source_vertex
    exact, _ = geodesic.PyGeodesicAlgorithmExact(surface.vertices, surface.faces.astype(np.int32)).geodesicDistances(
        np.array([src], dtype=np.int32), None
    )
    ok = np.zeros(len(surface.vertices), bool)
    ok[surface.used_vertices] = True
    ok &= exact < 1e30
    near = np.min(np.linalg.norm(surface.vertices[:, None] - found.centre[None], axis=2), axis=1) < 0.02
    print("| n | order | holes bridged | near a hole: largest error / h | elsewhere: largest error / h |")
    print("|---|---|---|---|---|")
    for n in (60, 100, 150, 200):
        grid = surface.grid(n)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            sol = ts.solve(surface, grid, [surface.vertices[src]])
        err = np.abs(sol.on_mesh(surface.vertices) - exact) / grid.spacing
        b = sol.stats.bridged_holes
        print(f"| {n} | {sol.stats.order} | {0 if b is None else b['count']} | {err[ok & near].max():.2f} | "
              f"{err[ok & ~near].max():.2f} |")  # fmt: skip


def main() -> None:
    import pygeodesic.geodesic as geodesic

    import tubesweep as ts

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, nargs="+", default=[41, 61, 81, 101, 121, 161])
    ap.add_argument("--radius", type=float, default=0.05, help="the holes' radius")
    ap.add_argument("--bunny", action="store_true", help="the bundled bunny's holes instead")
    args = ap.parse_args()
    if args.bunny:
        bunny()
        return
    v, f, centres = holed_sphere(args.radius)
    source = int(np.argmax(v[:, 2]))
    exact, _ = geodesic.PyGeodesicAlgorithmExact(v, f).geodesicDistances(np.array([source]), None)
    near_hole = np.min(np.linalg.norm(v[:, None] - centres[None], axis=2), axis=1)
    surface = ts.surfaces.from_mesh((v, f))
    print(
        f"holes of radius {args.radius}; errors against exact polyhedral geodesics (largest distance {exact.max():.3f})"
    )
    print(
        "| N | h | order asked | order run | bridged (widest / band span) | near a hole: max, mean | elsewhere: max, mean |"
    )
    print("|---|---|---|---|---|---|---|")
    for n in args.n:
        grid = ts.Grid((-0.8,) * 3, (0.8,) * 3, (n,) * 3)
        for order in ("auto", 1):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                sol = ts.solve(surface, grid, [tuple(v[source])], order=order)
            err = np.abs(sol(v) - exact)
            near, far = near_hole < 0.08, near_hole > 0.3
            b = sol.stats.bridged_holes
            bridged = "no" if b is None else f"{b['count']} ({b['widest']:.3f} / {b['reach']:.3f})"
            print(
                f"| {n} | {grid.spacing:.4f} | {order} | {sol.stats.order} | {bridged} | "
                f"{err[near].max():.2e}, {err[near].mean():.2e} | {err[far].max():.2e}, {err[far].mean():.2e} |"
            )


if __name__ == "__main__":
    main()
