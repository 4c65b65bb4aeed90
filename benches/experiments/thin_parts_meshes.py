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
"""

from __future__ import annotations

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


if __name__ == "__main__":
    main()
