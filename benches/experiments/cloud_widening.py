"""A point cloud whose band is widened (``surfaces/_cloud_widening.py``): a sphere of radius 0.5
sampled with 4000 points on its northern half and 50 on its southern, refused at N = 61 after four
widenings. Times ``ts.solve`` to its ValueError with the narrower bands' closest points kept and,
alternated with it, with every widening computing every node again (``known_feet`` switched
off); medians of the rounds::

    .venv/bin/python benches/experiments/cloud_widening.py --rounds 3
"""

from __future__ import annotations

import argparse
import statistics
import time
import warnings

import numpy as np


def main() -> None:
    import tubesweep as ts
    from tubesweep.surfaces import _cloud_widening, points

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    rng = np.random.default_rng(1)
    a, b = (0.5 * x / np.linalg.norm(x, axis=1, keepdims=True) for x in (rng.normal(size=(m, 3)) for m in (8000, 100)))
    grid = ts.Grid((-1,) * 3, (1,) * 3, (61,) * 3)
    kept = points.known_feet
    times: dict = {"kept": [], "computed again": []}
    for _ in range(args.rounds):
        for name in times:
            points.known_feet = kept if name == "kept" else (lambda cloud, grid: None)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                cloud = ts.surfaces.from_points(np.vstack([a[a[:, 2] > 0], b[b[:, 2] <= 0]]))
                start = time.perf_counter()
                try:
                    ts.solve(cloud, grid, sources=[(0.0, 0.0, 0.5)])
                except ValueError:
                    pass
                times[name].append(time.perf_counter() - start)
    points.known_feet = _cloud_widening.known_feet
    for name, t in times.items():
        print(f"{name}: median {statistics.median(t):.2f} s ({', '.join(f'{x:.2f}' for x in t)})")
    print(
        f"ratio kept / computed again: {statistics.median(times['kept']) / statistics.median(times['computed again']):.2f}"
    )


if __name__ == "__main__":
    main()
