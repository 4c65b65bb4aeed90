"""The mesh checks' array passes, timed alone (docs/development/history-notes.md, "Meshes"): NumPy's
``np.unique`` of a mesh's edge keys against a sort (``tubesweep._distinct``), its ``axis=0`` form
against a ``lexsort`` of the columns, and a mesh's connected parts by the NumPy label propagation
they replaced against the union–find in Rust (``surfaces._mesh_parts.vertex_parts``), on the
bundled bunny's faces. Medians of ``--repeats`` runs; each pair's results are checked equal::

    .venv/bin/python benches/experiments/mesh_check_passes.py
    .venv/bin/python benches/experiments/mesh_check_passes.py --repeats 11

NumPy 2.3 and later find ``np.unique``'s values of a 1-D array by hashing, which on 10⁵–10⁶ large
integers costs many times a sort; earlier NumPy sorted, and the two columns come out close.
"""

from __future__ import annotations

import argparse
import statistics
import time
from typing import Any, Callable, List, Optional

import numpy as np

import tubesweep as ts
from tubesweep._distinct import distinct, distinct_rows
from tubesweep.surfaces._mesh_parts import vertex_parts


def label_propagation(n_vertices: int, faces: np.ndarray) -> np.ndarray:
    """The NumPy version ``vertex_parts`` had: label propagation with pointer jumping."""
    f = np.asarray(faces, dtype=np.int64)
    a = np.concatenate([f[:, 0], f[:, 1], f[:, 2]])
    b = np.concatenate([f[:, 1], f[:, 2], f[:, 0]])
    label = np.arange(n_vertices, dtype=np.int64)
    while True:
        low = np.minimum(label[a], label[b])
        new = label.copy()
        for ends in (a, b, label[a], label[b]):
            np.minimum.at(new, ends, low)
        while True:
            jumped = new[new]
            if np.array_equal(jumped, new):
                break
            new = jumped
        if np.array_equal(new, label):
            return label
        label = new


def timed(fn: Callable[[], Any], repeats: int) -> tuple:
    out, times = None, []
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return out, 1e3 * statistics.median(times)


def main(argv: Optional[List[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args(argv)
    mesh = ts.surfaces.from_mesh(ts.data.path("bunny"), smooth=False)
    v, f = mesh.vertices, mesh.faces
    e = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    keys = e[:, 0] * len(v) + e[:, 1]
    sorted_faces = np.sort(f, axis=1)
    print(f"numpy {np.__version__}; the bunny: {len(v):,} vertices, {len(f):,} faces, {len(keys):,} edge keys")
    rows = [
        ("distinct edge keys", lambda: np.unique(keys), lambda: distinct(keys), np.array_equal),
        (
            "distinct faces (rows)",
            lambda: np.unique(sorted_faces, axis=0, return_index=True)[1],
            lambda: distinct_rows(sorted_faces)[0],
            np.array_equal,
        ),
        (
            "vertices at the same place (rows)",
            lambda: np.unique(v, axis=0, return_inverse=True)[1].ravel(),
            lambda: distinct_rows(v)[1],
            np.array_equal,
        ),
        (
            "connected parts",
            lambda: label_propagation(len(v), f),
            lambda: vertex_parts(len(v), f),
            np.array_equal,
        ),
    ]
    print("| pass | before (ms) | now (ms) | ratio |\n|---|---|---|---|")
    for name, before, now, same in rows:
        a, ta = timed(before, args.repeats)
        b, tb = timed(now, args.repeats)
        assert same(a, b), name
        print(f"| {name} | {ta:.1f} | {tb:.1f} | {ta / tb:.0f}× |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
