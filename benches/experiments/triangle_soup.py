"""A triangle soup refused: an icosphere of radius 0.5 (trimesh) whose triangles were each shrunk
by 20% about their centroids, so that every triangle is a separate piece, and the source's piece is
smaller than the grid resolves (``tests/test_mesh_parts.py``). Times ``ts.solve`` until its
``ValueError`` and the parts of the mesh checks that take longest (``cProfile``)::

    .venv/bin/python benches/experiments/triangle_soup.py            # 20,480 triangles, N = 61
    .venv/bin/python benches/experiments/triangle_soup.py --subdivisions 4 --n 41
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import time

import numpy as np


def main() -> None:
    import trimesh

    import tubesweep as ts

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--subdivisions", type=int, default=5)
    ap.add_argument("--n", type=int, default=61)
    ap.add_argument("--top", type=int, default=12, help="profile rows to print (0: none)")
    args = ap.parse_args()
    m = trimesh.creation.icosphere(args.subdivisions, 0.5)
    tri = np.asarray(m.vertices)[np.asarray(m.faces)]
    centre = tri.mean(1, keepdims=True)
    v = (centre + 0.8 * (tri - centre)).reshape(-1, 3)
    soup = ts.surfaces.from_mesh((v, np.arange(len(v)).reshape(-1, 3)))
    profile = cProfile.Profile()
    start = time.perf_counter()
    profile.enable()
    try:
        ts.solve(soup, soup.grid(args.n), [v[:3].mean(0)])
        said = "solved (not refused)"
    except ValueError as e:
        said = f"refused: {str(e)[:120]}..."
    profile.disable()
    print(f"{len(tri)} separate triangles, N = {args.n}: {time.perf_counter() - start:.1f} s to the answer; {said}")
    if args.top:
        pstats.Stats(profile).sort_stats("cumulative").print_stats(args.top)


if __name__ == "__main__":
    main()
