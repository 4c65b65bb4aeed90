"""Closest points on a triangle mesh: the queries a mesh surface's band costs, timed alone.

The band of a mesh surface (``MeshSurface.band``) is found coarse-to-fine with queries at block
centres (is any triangle within reach? ``MeshSurface.band_candidates``; on older checkouts the
closest triangle's distance), then every candidate node is queried once more for its closest point
(docs/meshes-and-output.md). This times both phases on the Stanford bunny's band (``make bench``'s
grid, ``surface.grid(n)``), medians of warm runs, with the thread count of ``RAYON_NUM_THREADS``
(all cores by default)::

    .venv/bin/python benches/experiments/closest_points.py                  # N = 201, 5 runs
    RAYON_NUM_THREADS=1 .venv/bin/python benches/experiments/closest_points.py --n 101
    .venv/bin/python benches/experiments/closest_points.py --split          # also by where the candidates lie

To compare two commits, build each in its own checkout (``make build``) and run the script in
both, alternately or at once on separate cores (``RAYON_NUM_THREADS=1 taskset -c 0 ...`` and
``-c 1``): this shared machine's speed drifts by 10–40% between runs.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from tubesweep.band import coarse_to_fine_candidates  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benches/: problems.py, methods.py
from problems import PROBLEMS  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=201, help="grid nodes along the bunny's longest side")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument(
        "--split",
        action="store_true",
        help="also time the queries of the candidates outside the band, of the band, and of its inner tube",
    )
    a = ap.parse_args()
    problem = PROBLEMS["bunny"](a.n)
    surface, grid = problem.surface, problem.grid
    half_width = 4 * grid.spacing  # the default outer tube
    tree = surface.tree

    def search() -> np.ndarray:
        if hasattr(surface, "band_candidates"):  # the band's own search (any triangle within reach)
            return surface.band_candidates(grid, half_width)
        # checkouts before it: the closest triangle's distance at every block centre
        return coarse_to_fine_candidates(grid, half_width, 1.0, lambda p, reach: surface.closest(p, reach)[0])

    candidates = search()
    points = np.ascontiguousarray(grid.points(grid.unravel(candidates)))
    reach = half_width * (1 + 1e-12)
    tree.closest(points, reach)  # warm
    coarse, final = [], []
    for _ in range(a.repeats):
        t = time.perf_counter()
        search()
        coarse.append(time.perf_counter() - t)
        t = time.perf_counter()
        d = tree.closest(points, reach)[0]
        final.append(time.perf_counter() - t)
    threads = os.environ.get("RAYON_NUM_THREADS", "all")
    final_s = statistics.median(final)
    print(
        f"bunny N={a.n}: {len(surface.faces)} triangles, {len(candidates):,} candidates, "
        f"{int((d <= half_width).sum()):,} band nodes; threads {threads}, medians of {a.repeats}"
    )
    print(
        f"  coarse-to-fine search {1e3 * statistics.median(coarse):.0f} ms, closest points of the candidates "
        f"{1e3 * final_s:.0f} ms ({1e9 * final_s / len(candidates):.0f} ns per query)"
    )
    if a.split:
        inner_width = 2 * grid.spacing  # the default inner tube

        def timed(selected: np.ndarray) -> float:
            pts = np.ascontiguousarray(points[selected])
            runs = []
            for _ in range(a.repeats):
                t = time.perf_counter()
                tree.closest(pts, reach)
                runs.append(time.perf_counter() - t)
            return statistics.median(runs)

        for label, selected in [
            ("outside the band", d > half_width),
            ("the band", d <= half_width),
            ("the inner tube", d <= inner_width),
        ]:
            s = timed(selected)
            k = int(selected.sum())
            print(f"  {label}: {k:,} queries, {1e3 * s:.0f} ms ({1e9 * s / max(k, 1):.0f} ns per query)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
