"""The dependency graph of a converged solve: which nodes each local update reads, and whether
those reads form cycles before and after the coupled Godunov update.

Usage::

    .venv/bin/python benches/experiments/dependency_cycles.py                       # the 2D and 3D cases below
    .venv/bin/python benches/experiments/dependency_cycles.py --case plane3 --n 61

At the converged values every node's update is a function of a few neighbours: an inner node's
Godunov update (Eq. (3)) of its upwind neighbours along each axis, weighted by the derivative
(ū − a_k) / Σ_j (ū − a_j); an extension-layer node's update (5) of its upwind neighbours toward the
surface, with the weights of Eq. (5). Gauss–Seidel sweeps converge in finitely many sweeps on
the nodes that lie on no cycle of this graph, and only geometrically on its strongly connected
components. The coupled update (docs/architecture.md, "Invariants") solves an
inner node together with each layer neighbour that reads it; the script folds those pairs in
(the inner node then reads the layer node's other neighbours) and counts the cycles again. The
last column is the largest gain around a cycle of two to four nodes: the product of its weights,
by which an error is damped each time it goes round. Nodes on no cycle still need one more sweep
for every change of orientation along the paths they read through. Deterministic, no timing;
the directions come from the library's own band (``Surface.band``).
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from pathlib import Path
from typing import Dict, List, Optional, Sequence, Tuple

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from scipy.sparse import csr_matrix  # noqa: E402
from scipy.sparse.csgraph import connected_components  # noqa: E402

import tubesweep as ts  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benches/: problems.py, methods.py
from problems import sphere  # noqa: E402

OFFSET = 0.0131  # the planes and lines pass this far from the origin, off the grid's nodes


def case(name: str, n: int) -> Tuple[ts.Surface, ts.Grid, np.ndarray]:
    if name == "sphere":
        p = sphere(n)
        return p.surface, p.grid, np.asarray(p.source, dtype=float)
    normal = {"line2": (0.3, 1.0), "plane3": (0.3, 0.4, 1.0)}[name]
    unit = np.asarray(normal) / np.linalg.norm(normal)
    d = len(unit)
    return ts.LevelSet(lambda q: q @ unit - OFFSET), ts.Grid([-1.0] * d, [1.0] * d, [n] * d), OFFSET * unit


def reads(sol: ts.Solution, direction: np.ndarray) -> List[Dict[int, float]]:
    """Per node, the nodes its converged update reads and their weights."""
    shape, u, roles = sol.grid.shape, sol.values, sol.roles
    d = len(shape)
    position = {int(l): i for i, l in enumerate(sol.linear)}
    index = np.array(np.unravel_index(sol.linear, shape)).T

    def neighbour(i: int, k: int, step: int) -> int:
        j = index[i].copy()
        j[k] += step
        if not 0 <= j[k] < shape[k]:
            return -1
        return position.get(int(np.ravel_multi_index(j, shape)), -1)

    out: List[Dict[int, float]] = []
    for i in range(len(u)):
        w: Dict[int, float] = {}
        if roles[i] == 2:  # extension layer: Eq. (5), the upwind neighbours toward the surface
            for k in range(d):
                v = float(direction[i, k])
                j = neighbour(i, k, -1 if v > 0 else 1) if v != 0 else -1
                if j >= 0:
                    w[j] = abs(v)
            total = sum(w.values())
            w = {j: x / total for j, x in w.items()} if total > 0 else {}
        elif roles[i] == 1:  # inner tube: the derivatives of the Godunov root (3)
            picks = []
            for k in range(d):
                m, p = neighbour(i, k, -1), neighbour(i, k, 1)
                um = u[m] if m >= 0 else np.inf
                up = u[p] if p >= 0 else np.inf
                picks.append((um, m) if um <= up else (up, p))
            gaps = {j: u[i] - a for a, j in picks if a < u[i]}
            total = sum(gaps.values())
            w = {j: g / total for j, g in gaps.items()} if total > 0 else {}
        out.append(w)
    return out


def couple(graph: List[Dict[int, float]], roles: np.ndarray) -> List[Dict[int, float]]:
    """The coupled update folded in: an inner node reading a layer node that reads it back reads
    that node's other neighbours instead, with the weights of the pair solved together."""
    out = []
    for i, w in enumerate(graph):
        if roles[i] != 1:
            out.append(w)
            continue
        folded: Dict[int, float] = {}
        for j, g in w.items():
            back = graph[j].get(i, 0.0) if roles[j] == 2 else 0.0
            if back == 0.0:
                folded[j] = folded.get(j, 0.0) + g
                continue
            for q, wq in graph[j].items():
                if q != i:
                    folded[q] = folded.get(q, 0.0) + g * wq / (1.0 - g * back)
        out.append(folded)
    return out


def cycles(graph: List[Dict[int, float]]) -> Tuple[int, int, int, float]:
    """(strongly connected components of more than one node, their nodes, the largest, the
    largest gain around a cycle of two to four nodes: the product of its weights, by which an
    error is damped each time it goes round)."""
    m = len(graph)
    rows = [i for i, w in enumerate(graph) for _ in w]
    cols = [j for w in graph for j in w]
    data = [x for w in graph for x in w.values()]
    a = csr_matrix((data, (rows, cols)), shape=(m, m))
    _, label = connected_components(a, directed=True, connection="strong")
    sizes = np.bincount(label)
    gain = 0.0
    for i in np.nonzero(sizes[label] > 1)[0]:
        inside = {j: w for j, w in graph[i].items() if label[j] == label[i]}
        for j, w1 in inside.items():
            for k, w2 in graph[j].items():
                if label[k] != label[i]:
                    continue
                if k == i:
                    gain = max(gain, w1 * w2)
                    continue
                gain = max(gain, w1 * w2 * graph[k].get(i, 0.0))
                for l, w3 in graph[k].items():
                    if l != j and label[l] == label[i]:
                        gain = max(gain, w1 * w2 * w3 * graph[l].get(i, 0.0))
    big = sizes[sizes > 1]
    return len(big), int(big.sum()), int(big.max()) if len(big) else 0, gain


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--case", choices=["line2", "plane3", "sphere"], help="one case (default: all three)")
    ap.add_argument("--n", type=int, help="grid size (default: 201 for the line, 41 in 3D)")
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    print(
        f"{'case':>7s} {'N':>4s} {'band':>7s} {'iters':>5s} {'update':>8s} {'cycles':>6s} {'nodes':>6s} {'largest':>7s} {'gain':>8s}"
    )
    for name in [args.case] if args.case else ["line2", "plane3", "sphere"]:
        n = args.n or (201 if name == "line2" else 41)
        surface, grid, source = case(name, n)
        tube = ts.Tube(surface, grid)
        sol = tube.solve([source], order=1)
        geometry = surface.band(grid, tube.outer * grid.spacing)
        assert np.array_equal(geometry.linear, sol.linear), "the band the solve ran on"
        graph = reads(sol, geometry.direction)
        for label, g in (("plain", graph), ("coupled", couple(graph, sol.roles))):
            k, nodes, largest, gain = cycles(g)
            print(
                f"{name:>7s} {n:>4d} {len(sol.values):>7,d} {sol.stats.iterations:>5d} {label:>8s} {k:>6d} {nodes:>6d} "
                f"{largest:>7d} {gain:>8.1e}"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
