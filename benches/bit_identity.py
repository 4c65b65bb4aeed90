"""Bit-identity check for refactors: one SHA-256 over the values of a fixed set of solves.

Usage::

    .venv/bin/python benches/bit_identity.py            # prints one line per case and the total hash
    .venv/bin/python benches/bit_identity.py --expect HASH   # exit status 1 if the hash differs

Run it before and after a change that must not alter results (formatting, moving files, splitting
modules): the two totals must be equal. The cases cover the features end to end — a sphere and a
torus given by φ, a 2D star curve, the hemisphere (closest points, open), a mesh surface built in
code, ``travel_time`` in the box (Godunov and Lax–Friedrichs, one and two threads), the moving
medium and a metric (general Hamiltonians), several sources with nearest-source labels, geodesic
paths, interpolation, ``Tube`` re-solves, φ re-distancing, Algorithm 2 and the paper's plain
sweeps — each hashed as raw float64/int64 bytes, together with the iteration counts. Small
grids, about half a minute in all.
"""

from __future__ import annotations

import argparse
import hashlib
import sys
import warnings

import numpy as np

import tubesweep as ts
from tubesweep.flows import point_vortices, solid_body_rotation
from tubesweep.surfaces import Hemisphere, Sphere, Star, Torus


def _bytes(x) -> bytes:
    a = np.ascontiguousarray(np.asarray(x))
    if a.dtype.kind == "f":
        a = a.astype("<f8")
    elif a.dtype.kind in "iub":
        a = a.astype("<i8")
    return str(a.shape).encode() + a.tobytes()


def _solution(sol) -> list:
    return [sol.linear, sol.values, sol.roles, np.array([sol.stats.iterations])]


def _cube(n: int, d: int = 3) -> ts.Grid:
    return ts.Grid([-1.0] * d, [1.0] * d, [n] * d)


def _octahedron_mesh():
    """A subdivided, inflated octahedron: a closed triangle mesh made in code."""
    v = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
    f = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    for _ in range(2):
        verts = list(map(tuple, v))
        index = {p: i for i, p in enumerate(verts)}
        faces = []

        def mid(a, b):
            p = tuple((np.asarray(verts[a]) + np.asarray(verts[b])) / 2)
            if p not in index:
                index[p] = len(verts)
                verts.append(p)
            return index[p]

        for a, b, c in f:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            faces += [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
        v, f = np.array(verts), np.array(faces)
    v = 0.5 * v / np.linalg.norm(v, axis=1, keepdims=True)
    return v, f


def cases():
    sphere = Sphere(0.5)
    g = _cube(41)
    s = ts.solve(sphere, g, [(-0.5, 0, 0)], order=1)
    yield "sphere godunov", _solution(s) + [s([(0.5, 0, 0), (0, 0.5, 0), (0.3, 0.3, 0.1)])]
    yield "sphere lxf", _solution(ts.solve(sphere, g, [(-0.5, 0, 0)], hamiltonian="lxf", order=1))
    yield (
        "sphere callable phi",
        _solution(ts.solve(lambda p: np.linalg.norm(p, axis=1) - 0.5, g, [(-0.5, 0, 0)], order=1)),
    )
    yield "sphere naive", _solution(ts.solve(sphere, g, [(-0.5, 0, 0)], method="naive", max_iterations=30, order=1))
    yield "sphere paper sweeps", _solution(ts.solve(sphere, g, [(-0.5, 0, 0)], paper_sweeps=True, order=1))
    yield "sphere one thread", _solution(ts.solve(sphere, g, [(-0.5, 0, 0)], threads=1, order=1))
    g101 = _cube(101)
    for threads in (1, 2):  # big enough for the parallel strips, the front window and the row prefetch
        yield f"sphere N=101 {threads}t", _solution(ts.solve(sphere, g101, [(-0.5, 0, 0)], threads=threads, order=1))
        yield (
            f"sphere N=101 lxf {threads}t",
            _solution(ts.solve(sphere, g101, [(-0.5, 0, 0)], hamiltonian="lxf", threads=threads, order=1)),
        )
    yield "sphere speed", _solution(ts.solve(sphere, g, [(-0.5, 0, 0)], speed=lambda p: 1.0 + 0.5 * p[:, 2], order=1))

    srcs = [(-0.5, 0, 0), (0, 0.5, 0), (0, 0, -0.5)]
    m = ts.solve(sphere, g, srcs, order=1)
    yield "sphere three sources + labels", _solution(m) + [m.nearest_source(), m.nearest_source([(0.5, 0, 0)])]
    yield "geodesic paths", [m.geodesic_path((0.5, 0.0, 0.0))] + m.geodesic_paths([(0.1, -0.48, 0.1), (0.3, 0.3, 0.3)])

    tube = ts.Tube(sphere, g)
    yield (
        "tube re-solve",
        _solution(tube.solve([(0, 0, 0.5)], order=1))
        + _solution(tube.solve([(0, 0, 0.5)], hamiltonian="lxf", order=1)),
    )

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rd = ts.solve(ts.LevelSet(lambda p: np.sum(p * p, axis=1) - 0.25, redistance=True), g, [(-0.5, 0, 0)], order=1)
    yield "redistanced phi", _solution(rd)

    torus = Torus()
    yield "torus", _solution(ts.solve(torus, _cube(41), [torus.default_source], order=1))

    star = Star()
    g2 = _cube(161, 2)
    st = ts.solve(star, g2, [star.default_source], order=1)
    yield "star curve", _solution(st) + [st.geodesic_path(-np.asarray(star.default_source))]
    yield (
        "circle moving medium",
        _solution(ts.solve(ts.surfaces.Circle(0.5), g2, [(-0.5, 0)], flow=solid_body_rotation(0.5), order=1)),
    )
    yield (
        "circle metric",
        _solution(
            ts.solve(
                ts.surfaces.Circle(0.5),
                g2,
                [(-0.5, 0)],
                hamiltonian=ts.hamiltonians.Metric(np.array([[2.0, 0.3], [0.3, 1.0]])),
            )
        ),
    )
    vort = point_vortices([(0.3, 0.2, 0.0), (-0.2, -0.3, 0.0)], [0.1, -0.1], core=0.05)
    yield "sphere vortices", _solution(ts.solve(sphere, g, [(-0.5, 0, 0)], flow=vort, order=1))

    hemi = Hemisphere()
    h = ts.solve(hemi, _cube(41), [hemi.default_source], order=1)
    yield "hemisphere cp", _solution(h) + [h([(0.0, 0.0, 0.5)])]

    v, f = _octahedron_mesh()
    mesh = ts.surfaces.from_mesh((v, f))
    ms = ts.solve(mesh, _cube(41), [tuple(v[0])], order=1)
    yield "mesh surface", _solution(ms) + [ms.on_mesh(v)]

    gb = _cube(81, 2)
    for ham in ("godunov", "lxf"):
        for threads in (1, 2):
            u, st_ = ts.travel_time(
                gb,
                [(0.1, 0.2), (-0.5, -0.5)],
                speed=lambda p: 1.0 + 0.3 * p[:, 0],
                hamiltonian=ham,
                threads=threads,
                return_stats=True,
            )
            yield f"travel_time 2D {ham} {threads}t", [u, np.array([st_.iterations])]
    yield "travel_time 3D", [ts.travel_time(_cube(31), [(0.1, 0.2, -0.3)], speed=2.0)]

    # the paper's configuration (Sect. 6.1): the unit-radius sphere, two-layer tube, Godunov, plain sweeps
    pg = ts.Grid((-2, -2, -2), (2, 2, 2), (41, 41, 41))
    yield "paper sphere", _solution(ts.solve(Sphere(1.0), pg, [(-1.0, 0, 0)], paper_sweeps=True, order=1))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--expect", help="the hash the run must reproduce")
    args = ap.parse_args()
    total = hashlib.sha256()
    for name, arrays in cases():
        h = hashlib.sha256()
        for a in arrays:
            h.update(_bytes(a))
        total.update(name.encode() + h.digest())
        print(f"{h.hexdigest()[:16]}  {name}", flush=True)
    digest = total.hexdigest()
    print(f"total {digest}")
    if args.expect and args.expect != digest:
        print(f"MISMATCH: expected {args.expect}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
