"""A closed mesh thinner than its tubes: a flat ellipsoid (semi-axes 0.5, 0.5, c) from the centre of
its top face, against exact polyhedral geodesics (pygeodesic, MMP) on the same mesh
(``docs/surfaces.md``, "Parts of the surface that face each other"). Its two faces lie within each
other's tubes over much of the surface: the band is cut between them (``sol.stats.cut_edges``), but
the two sides lie within a grid spacing of each other near the rim, where no tube keeps them apart
and the front crosses between them. Prints per thickness and grid the share of the inner tube in
facing pairs, the share of the mesh's area within a spacing of a part facing it (the warning's
trigger, ``surfaces._mesh_checks.THIN_SHARE``), the shortfall at the bottom face's centre in grid
spacings, and the largest and mean error over the vertices relative to the largest distance::

    .venv/bin/python benches/experiments/thin_parts_meshes.py      # about a minute

``--plates`` instead measures where the front starts to cross (``_mesh_checks.THIN_REACH`` and
``GAP_REACH``): a box plate 1 × 1 × t from its top centre to its bottom centre (exact 1 + t) and a
slot w wide and 0.3 deep in a block 0.4 high, from the top left of the slot to its top right
(exact 1.1 + w), against t and w in grid spacings, the mesh aligned with the grid's nodes or
shifted by 0.3 spacings; it prints the error in spacings and whether the thin-part warning
came (about two minutes)::

    .venv/bin/python benches/experiments/thin_parts_meshes.py --plates
"""

from __future__ import annotations

import sys
import warnings

import numpy as np
import trimesh

import tubesweep as ts
from tubesweep.surfaces._mesh_checks import thin_parts


def main() -> None:
    import pygeodesic.geodesic as geodesic

    warnings.simplefilter("ignore")  # the warning under study
    sphere = trimesh.creation.icosphere(5, radius=1.0)
    print("| c | N | facing share | thin share | bottom centre short (Δx) | largest / mean error |")
    print("|---|---|---|---|---|---|")
    for c in (0.025, 0.05, 0.1):
        v = sphere.vertices * [0.5, 0.5, c]
        top, bottom = int(np.argmax(v[:, 2])), int(np.argmin(v[:, 2]))
        exact, _ = geodesic.PyGeodesicAlgorithmExact(v, sphere.faces).geodesicDistances(np.array([top]), None)
        mesh = ts.surfaces.from_mesh((v, sphere.faces))
        for n in (41, 61, 81):
            grid = ts.Grid((-0.6,) * 3, (0.6,) * 3, (n,) * 3)
            sol = ts.solve(mesh, grid, [v[top]])
            u = sol.on_mesh(v)
            e = np.abs(u - exact) / exact.max()
            short = (exact[bottom] - u[bottom]) / grid.spacing
            share = sol.stats.facing_pairs / max(sol.stats.inner_points, 1)
            thin, _ = thin_parts(mesh, grid.spacing)
            print(f"| {c} | {n} | {share:.1%} | {thin:.1%} | {short:.1f} | {e.max():.1%} / {e.mean():.2%} |")


def cells_surface(edges: list, filled: np.ndarray) -> trimesh.Trimesh:
    """The closed surface of a union of the cells of a rectilinear grid (``edges``: each axis's
    cell boundaries; ``filled[i, j, k]``: cell filled), its triangles facing out."""
    pad = np.pad(filled.astype(bool), 1)
    quads = []
    for axis in range(3):
        turn = pad.astype(int) - np.roll(pad, -1, axis=axis).astype(int)  # +1: filled, next one empty
        for cell in zip(*np.nonzero(turn)):
            a, b = (axis + 1) % 3, (axis + 2) % 3
            at = [0, 0, 0]
            at[axis] = cell[axis]  # the face between padded cells c and c + 1: edge c - 1 + 1
            corners = []
            for da, db in ((0, 0), (1, 0), (1, 1), (0, 1)):
                at[a], at[b] = cell[a] - 1 + da, cell[b] - 1 + db
                corners.append([edges[0][at[0]], edges[1][at[1]], edges[2][at[2]]])
            quads.append(corners if turn[cell] > 0 else corners[::-1])
    q = np.array(quads, float)
    triangles = np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]])
    mesh = trimesh.Trimesh(triangles.reshape(-1, 3), np.arange(3 * len(triangles)).reshape(-1, 3))
    mesh.merge_vertices()
    return mesh


def plates() -> None:
    """Where a plate and a slot start to be crossed (module notes)."""
    print("| mesh | N | shift (Δx) | width (Δx) | error (Δx) | warned |")
    print("|---|---|---|---|---|---|")
    for kind, widths in (("plate", (0.98, 1.0, 1.02, 1.05, 1.1)), ("slot", (1.2, 1.35, 1.5, 1.6, 1.75))):
        for n in (41, 61, 101):
            h = 1.4 / (n - 1)
            grid = ts.Grid((-0.2,) * 3, (1.2,) * 3, (n,) * 3)
            for shift in (0.0, 0.3):
                for width in widths:
                    w = width * h
                    if kind == "plate":
                        mesh = cells_surface([[0, 1], [0, 1], [0, w]], np.ones((1, 1, 1), bool))
                        source, probe, exact = (0.5, 0.5, w), (0.5, 0.5, 0.0), 1.0 + w
                    else:
                        filled = np.ones((3, 1, 2), bool)
                        filled[1, 0, 1] = False
                        mesh = cells_surface([[0, 0.45, 0.45 + w, 0.9 + w], [0, 0.4], [0, 0.1, 0.4]], filled)
                        source, probe, exact = (0.2, 0.2, 0.4), (0.7 + w, 0.2, 0.4), 1.1 + w
                    surface = ts.surfaces.from_mesh((mesh.vertices + shift * h, mesh.faces))
                    with warnings.catch_warnings(record=True) as caught:
                        warnings.simplefilter("always")
                        sol = ts.solve(surface, grid, [np.add(source, shift * h)])
                    u = sol.on_mesh(np.array([np.add(probe, shift * h)]))[0]
                    warned = any("of another part of it that faces it" in str(c.message) for c in caught)
                    print(f"| {kind} | {n} | {shift} | {width} | {(u - exact) / h:+.1f} | {warned} |")


if __name__ == "__main__":
    plates() if "--plates" in sys.argv[1:] else main()
