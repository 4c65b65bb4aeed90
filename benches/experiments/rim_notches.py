"""A flat disc whose rim zigzags at the grid's scale (python/tubesweep/surfaces/_mesh_notches.py):
a jittered lattice of spacing 0.02 on [−0.55, 0.55]², Delaunay-triangulated (scipy), the triangles
whose three vertices lie within 0.5 of the centre kept, tilted by 0.3 rad about x in the box
[−0.7, 0.7]³; the source at the rim vertex nearest (−0.5, 0). Per N: the order run, the facing
pairs left, and the errors of ``sol.on_mesh`` against exact polyhedral geodesics (pygeodesic) at
the rim's vertices and the others, with the notch test (``after``) and without it
(``before``: ``NOTCH_REACH`` and ``NOTCH_RATIO`` set to 0)::

    .venv/bin/python benches/experiments/rim_notches.py
    .venv/bin/python benches/experiments/rim_notches.py --n 61 91 121
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


def main() -> None:
    import pygeodesic.geodesic as geodesic

    import tubesweep as ts
    from tubesweep.surfaces import _mesh_notches

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, nargs="+", default=[41, 61, 71, 81, 91, 111, 121])
    args = ap.parse_args()
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
