"""How the surface's tilt against the grid sets the sweeps' work: straight lines (2D) and planes
(3D) at several tilts, each solved with the paper's sweeps and with the default ones.

Usage::

    .venv/bin/python benches/experiments/oblique_planes.py [--n2 201] [--n3 101]

A line or plane through the box with a source on it has an exact solution that is linear along
the surface, so the only thing that changes between the rows is the angle between the surface
and the grid's axes. For each it prints the iterations and the local updates per band node
(``sol.stats``; deterministic, no timing). With the surface along an axis the extension layer
copies values straight across the tube and every node settles in one or two iterations; tilted,
the layer's upwind neighbours (toward the surface) and the inner tube's (toward the source) lie
on different sides, and the values settle over several iterations. The numbers are quoted in
docs/development/performance-history.md ("What still makes iterations grow with N").
"""

from __future__ import annotations

import argparse
import os
import warnings
from typing import Dict, Optional, Sequence

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import tubesweep as ts  # noqa: E402

# normals of the lines (2D) and planes (3D); the first of each lies along the grid's axes
NORMALS_2D = [(0.0, 1.0), (0.3, 1.0), (1.0, 1.0)]
NORMALS_3D = [(0.0, 0.0, 1.0), (0.3, 0.0, 1.0), (0.3, 0.4, 1.0), (1.0, 1.0, 1.0)]
# the surface passes this far from the origin, off the grid's nodes
OFFSET = 0.0131


def measure(normal: Sequence[float], n: int) -> Dict[str, float]:
    """The line or plane with this normal on an N-node grid: its band points, the tilt (degrees
    between the normal and its nearest axis), and per sweep kind ("paper", "default") the
    iterations and the local updates per band node."""
    d = len(normal)
    grid = ts.Grid([-1.0] * d, [1.0] * d, [n] * d)
    unit = np.asarray(normal, dtype=float) / np.linalg.norm(normal)
    surface = ts.LevelSet(lambda p: p @ unit - OFFSET)
    out: Dict[str, float] = {"tilt": float(np.degrees(np.arccos(np.max(np.abs(unit)))))}
    for kind, paper in (("paper", True), ("default", False)):
        st = ts.solve(surface, grid, sources=[OFFSET * unit], paper_sweeps=paper, order=1).stats
        out["band_points"] = st.band_points
        out[f"{kind}_iterations"] = st.iterations
        out[f"{kind}_updates_per_node"] = st.updates / st.band_points
    return out


def row(normal: Sequence[float], n: int) -> str:
    m = measure(normal, n)
    cells = " ".join(
        f"{int(m[f'{k}_iterations']):>6d} {m[f'{k}_updates_per_node']:>9.2f}" for k in ("paper", "default")
    )
    return f"{len(normal)}D {n:>5d} {str(tuple(normal)):>16s} {m['tilt']:>6.1f} {int(m['band_points']):>9,d} {cells}"


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n2", type=int, default=201, help="grid size of the 2D lines (default 201)")
    ap.add_argument("--n3", type=int, default=101, help="grid size of the 3D planes (default 101)")
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")  # the planes' φ is exact; nothing to warn about
    print("straight lines and planes with a source on them, two-layer Godunov, inner 2, outer 4")
    print(f"{'':2s} {'':>5s} {'':>16s} {'':>6s} {'':>9s} {'paper sweeps':>16s} {'default sweeps':>16s}")
    print(
        f"{'':2s} {'N':>5s} {'normal':>16s} {'tilt°':>6s} {'band pts':>9s} "
        + " ".join([f"{'iters':>6s} {'upd/node':>9s}"] * 2)
    )
    for normal in NORMALS_2D:
        print(row(normal, args.n2))
    for normal in NORMALS_3D:
        print(row(normal, args.n3))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
