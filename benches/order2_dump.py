"""Writes the inputs of an ``order=2`` solve as the Python layer hands them to the core, for the
Rust example ``order2_phases`` (the cost of the set-up and of each phase, in ns per update).

Usage::

    .venv/bin/python benches/order2_dump.py sphere 201 /tmp/sphere201
    cargo run --release -p tubesweep-core --example order2_phases -- /tmp/sphere201 5 1

Files in the directory: ``linear`` (the band's C-order node indices, uint64), ``roles`` (uint8),
``phi`` (float64), ``dirs`` (float32, 3 per node) and ``params.txt`` (N, spacing, the grid's lower
corner; the source, its slowness, the constant slowness; the fixing radius, the outer width, the
two phases' tolerances and front windows, the ramp's length).
"""

from __future__ import annotations

import argparse
import os
from typing import Any

import numpy as np

import tubesweep as ts
import tubesweep.second_order as so

SURFACES = {
    "sphere": lambda: (ts.surfaces.Sphere(0.5), (-0.5, 0.0, 0.0)),
    "ellipsoid": lambda: (ts.surfaces.Ellipsoid(), None),
    "torus": lambda: (ts.surfaces.Torus(), None),
    "rounded-cube": lambda: (ts.surfaces.RoundedCube(), None),
}


def main(argv: Any = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("surface", choices=sorted(SURFACES))
    ap.add_argument("n", type=int)
    ap.add_argument("out")
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    surface, source = SURFACES[args.surface]()
    if source is None:
        source = tuple(float(c) for c in surface.default_source)
    native = so._native.second_order_solve
    on_tube = so.solve_on_tube

    def dump(band, roles, phi, directions, lower, h, feet, src_slowness, slowness, fix_radius, outer, *rest, **kw):
        tol_first, tol = rest[0], rest[1]
        if np.ndim(slowness) != 0 or len(feet) != 1 or kw.get("offsets") is not None:
            raise SystemExit("order2_dump writes one source, a constant speed and a level set only")
        np.asarray(roles, np.uint8).tofile(f"{args.out}/roles")
        np.asarray(phi, np.float64).tofile(f"{args.out}/phi")
        np.asarray(directions, np.float32).tofile(f"{args.out}/dirs")
        with open(f"{args.out}/params.txt", "w") as f:
            f.write(f"{args.n} {h!r} {' '.join(repr(float(c)) for c in lower)}\n")
            f.write(f"{' '.join(repr(float(c)) for c in feet[0])} {float(src_slowness[0])!r} {float(slowness)!r}\n")
            f.write(
                f"{fix_radius!r} {outer!r} {tol_first!r} {tol!r} {kw['window_first']!r} {kw['window_second']!r} "
                f"{kw['ramp_length']!r} {kw.get('extension_limit', float('inf'))!r}\n"
            )
        return native(
            band, roles, phi, directions, lower, h, feet, src_slowness, slowness, fix_radius, outer, *rest, **kw
        )

    def tube(t: Any, *a: Any, **k: Any) -> Any:
        np.asarray(t.linear, np.uint64).tofile(f"{args.out}/linear")
        return on_tube(t, *a, **k)

    so._native.second_order_solve, so.solve_on_tube = dump, tube
    try:
        grid = ts.Grid((-1.0,) * 3, (1.0,) * 3, (args.n,) * 3)
        sol = ts.solve(surface, grid, [source], order=2, threads=1)
    finally:
        so._native.second_order_solve, so.solve_on_tube = native, on_tube
    print(f"{args.out}: {sol.stats.band_points} band nodes, {sol.stats.iterations} iterations")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
