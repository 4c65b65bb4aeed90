"""Parts of a surface that face each other across a gap narrower than the tubes: where the solve
warns (``_facing._warn_if_tubes_touch``, ``tubesweep_core::band::facing_sheets``) and what the answer is
there, against exact distances.

Usage::

    .venv/bin/python benches/experiments/facing_gaps.py            # about 8 s
    .venv/bin/python benches/experiments/facing_gaps.py --skip-meshes

Sections:

* ``plate``: a closed box 1 × 1 × t (a triangle mesh, 12 triangles) with t = 0.08, source at the
  centre of its top face; the travel time to the centre of the bottom face, exactly 1 + t (over an
  edge and back), at grids ``surface.grid(N)``. Where the two faces' tubes touch, the front
  crosses the plate. The same for t = 1 (the cube: convex edges only, no warning; its first-order
  error at the edges for comparison).
* ``library``: the facing pairs of every library surface on its default box at N = 41 and 81
  (121 and 241 for the curves): none but the double torus's body at N = 41, 4.8 spacings thick.
* ``spheres``: two spheres as ``min(d₁, d₂)``, 4.5–5.5 spacings apart in 8 random placements
  each: how often the front reaches the second sphere, and how often without a warning.
* ``meshes``: Spot (``ts.data.spot()``, source vertex 285) at grids 81 and 201, with the
  error at every vertex against exact polyhedral geodesics (pygeodesic, MMP; skipped without it),
  and the bunny's facing pairs at grids 101 and 201; then the geodesic paths from 300 random
  vertices that stop short (Spot at grid 81 with three sources, the bunny at 101 and 201) and how
  many of them end next to a pair across a narrow gap.
"""

from __future__ import annotations

import argparse
import os
import re
import warnings

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

import tubesweep as ts  # noqa: E402
from tubesweep import geodesic_paths  # noqa: E402


def box_mesh(t: float):
    """The closed box [−½, ½]² × [−t/2, t/2] as 8 vertices and 12 outward triangles."""
    v = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-t / 2, t / 2)])
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    f = np.array([tri for a, b, c, d in quads for tri in ((a, b, c), (a, c, d))])
    return v, f


def solve_quietly(surface, grid, sources):
    """The solution, whether it warned of a gap, and where the warning put the narrowest gap."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = ts.solve(surface, grid, sources, order=1)
    found = [str(w.message) for w in caught if "faces itself" in str(w.message)]
    near = None
    if found:
        near = np.array([float(x) for x in re.search(r"near \(([^)]*)\)", found[0]).group(1).split(",")])
    return sol, bool(found), near


def plate() -> None:
    print("plate: box 1 x 1 x t, source at the top face's centre, u at the bottom face's centre (exact 1 + t)")
    print(
        f"  {'t':>5} {'N':>4} {'h':>8} {'warned':>6} {'pairs':>6} {'gap':>8} {'advised h':>9} {'u':>8} {'error/h':>8}"
    )
    for t, sizes in ((0.08, (41, 81, 121, 161)), (1.0, (41, 81))):
        surface = ts.surfaces.from_mesh(box_mesh(t))
        for n in sizes:
            grid = surface.grid(n)
            h = grid.spacing
            sol, warned, _ = solve_quietly(surface, grid, np.array([[0.0, 0.0, t / 2]]))
            u = float(sol(np.array([[0.0, 0.0, -t / 2]]))[0])
            st = sol.stats
            advised = st.narrowest_gap / (2 * sol.inner + 2)
            print(
                f"  {t:5.2f} {n:4d} {h:8.4f} {str(warned):>6} {st.facing_pairs:6d} {st.narrowest_gap:8.4f} "
                f"{advised:9.4f} {u:8.4f} {(u - (1 + t)) / h:8.2f}"
            )


def library() -> None:
    print("library surfaces on their default boxes: facing pairs (narrowest gap)")
    for name, cls in ts.surfaces.REGISTRY.items():
        surface = cls()
        lower, upper = surface.default_box
        row = []
        for n in (121, 241) if len(lower) == 2 else (41, 81):
            grid = ts.Grid(lower, upper, (n,) * len(lower))
            start = np.array([[0.9, 0.1, 0.1][: len(lower)]])
            src = np.asarray(surface.project(start, grid)[1])
            sol, _, _ = solve_quietly(surface, grid, src)
            st = sol.stats
            row.append(f"N={n}: {st.facing_pairs}" + (f" ({st.narrowest_gap:.3g})" if st.facing_pairs else ""))
        print(f"  {name:13} " + ", ".join(row))


def spheres() -> None:
    """Two spheres of radius 0.45 as φ = min(d₁, d₂) (a callable), 4.5–5.5 spacings apart along
    random directions and offsets against the grid (seed 3), source on the first: how often the
    front reaches the second, which it never should, and how often that happens without a
    warning. The central differences straddle the ridge between them, so the directions there are
    not reliable; the kinks of φ find those places."""
    print("two spheres min(d1, d2) at N = 41, 8 placements per gap: second sphere reached / of them without a warning")
    rng = np.random.default_rng(3)
    grid = ts.Grid([-1.2] * 3, [1.2] * 3, (41,) * 3)
    h, r = grid.spacing, 0.45
    for gap in (4.5, 5.0, 5.5):
        reached = silent = 0
        for _ in range(8):
            axis = rng.normal(size=3)
            axis /= np.linalg.norm(axis)
            shift = rng.uniform(-0.5, 0.5, 3) * h
            c1, c2 = -(r + gap * h / 2) * axis + shift, (r + gap * h / 2) * axis + shift

            def phi(p, c1=c1, c2=c2):
                return np.minimum(np.linalg.norm(p - c1, axis=1) - r, np.linalg.norm(p - c2, axis=1) - r)

            sol, warned, _ = solve_quietly(ts.LevelSet(phi, lipschitz=1.0), grid, [c1 - r * axis])
            if np.isfinite(sol(np.array([c2 + r * axis]))[0]):
                reached += 1
                silent += int(not warned)
        print(f"  gap {gap} spacings: reached {reached}/8, without a warning {silent}")


def meshes() -> None:
    spot_file, bunny_file = ts.data.spot(), ts.data.bunny()
    if not spot_file.is_file():
        print(f"meshes: skipped ({spot_file} not found)")
        return
    try:
        import pygeodesic.geodesic as geodesic
    except ImportError:
        geodesic = None
    spot = ts.surfaces.from_mesh(spot_file)
    v = spot.vertices
    exact = None
    if geodesic is not None:
        exact, _ = geodesic.PyGeodesicAlgorithmExact(v, spot.faces).geodesicDistances(np.array([285]), None)
    print("Spot, source vertex 285: facing pairs, narrowest gap, error at the vertices / h (against MMP)")
    for n in (81, 201):
        grid = spot.grid(n)
        sol, warned, near = solve_quietly(spot, grid, v[[285]])
        st = sol.stats
        line = f"  N={n:3d} h={grid.spacing:.4f} warned={warned} pairs={st.facing_pairs} gap={st.narrowest_gap:.4f}"
        if exact is not None:
            err = (sol(v) - exact) / grid.spacing
            worst = int(np.argmin(err))
            line += f"  error/h: min {err[worst]:.2f}, median {np.median(err):.2f}, max {np.max(err):.2f}"
            if near is not None:
                line += f"; the worst vertex {np.linalg.norm(v[worst] - near):.3f} from the narrowest gap"
        print(line)
    if bunny_file.is_file():
        bunny = ts.surfaces.from_mesh(bunny_file)
        for n in (101, 201):
            sol, warned, _ = solve_quietly(bunny, bunny.grid(n), bunny.vertices[[0]])
            st = sol.stats
            print(f"  bunny N={n}: warned={warned} pairs={st.facing_pairs} gap={st.narrowest_gap:.5f}")
    print(
        "geodesic paths from 300 random vertices (seed 1) that stop short, and how many of them end within "
        f"{geodesic_paths.GAP_REACH:g} spacings (plus half the gap) of a pair across a narrow gap"
    )
    cases = [("spot", spot, 81, [285, 0, 1000])]
    if bunny_file.is_file():
        cases += [("bunny", bunny, 101, [0]), ("bunny", bunny, 201, [0])]
    for name, mesh, n, sources in cases:
        sol, _, _ = solve_quietly(mesh, mesh.grid(n), mesh.vertices[sources])
        starts = np.random.default_rng(1).choice(len(mesh.vertices), 300, replace=False)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            paths = sol.geodesic_paths(mesh.vertices[starts])
        ends = np.array([p[-1] for p in paths])
        src = mesh.vertices[sources]
        short = np.min(np.linalg.norm(ends[:, None, :] - src[None], axis=2), axis=1) > 1e-9
        at_gaps = geodesic_paths._near_narrow_gaps(sol, ends[short])
        print(f"  {name} N={n}, sources {sources}: {int(short.sum())} stop short, {at_gaps} of them at a narrow gap")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--skip-meshes", action="store_true")
    args = ap.parse_args()
    plate()
    library()
    spheres()
    if not args.skip_meshes:
        meshes()


if __name__ == "__main__":
    main()
