"""The ``tubesweep`` command line.

Sub-commands: ``solve`` (a curve or surface), ``travel-time`` (the whole box), ``distances`` (a
geodesic distance matrix, cli_distances.py), ``demo``, ``reproduce`` (the paper's experiments) and ``info``. Run ``tubesweep COMMAND --help``.
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path
from typing import Any, List, Optional, Sequence

import numpy as np

from . import __version__
from ._progress import make_progress
from .cli_distances import add_distances_parser, cmd_distances
from ._cli_exit import exit_status, flag_named
from ._paths import writable

EPILOG = """examples:
  tubesweep solve --surface sphere --n 101 --png
  tubesweep solve --mesh bunny --export out/bunny.vtu --png
  tubesweep solve --mesh my-part.obj --source-vertex 0 --export out/part.ply
  tubesweep solve --surface star --n 401 --hamiltonian lxf --source 0.5 0 --out out/star
  tubesweep solve --phi phi.npy --lower -1 -1 -1 --upper 1 1 1 --source 0.5 0 0 --redistance
  tubesweep solve --mask mask.npy --lower -1 -1 -1 --upper 1 1 1 --source 0.5 0 0 --smooth 1.5
  tubesweep travel-time --n 201 --dim 2 --source 0 0 --png
  tubesweep reproduce all --quick
"""


def _surface_names() -> List[str]:
    from .surfaces import REGISTRY

    return sorted(REGISTRY)


def _add_solver_options(p: argparse.ArgumentParser, box: bool = False) -> None:
    """The options every solving command takes; ``box``: the whole box's first-order sweeps
    (``travel-time``, which has no --order: its help spoke of second order and --order auto)."""
    p.add_argument(
        "--hamiltonian",
        choices=["godunov", "lxf"],
        default="godunov",
        help="numerical Hamiltonian: Godunov (Eq. 3) or Lax-Friedrichs (Eq. 4) (default: godunov)",
    )
    p.add_argument(
        "--tol",
        type=float,
        default=None,
        help="stop when no value changes by more than this in an iteration (default: 1e-10 of the travel time across the grid, at most 1e-10"
        + (
            "; about 1e-3 × the grid spacing is as accurate and faster)"
            if box
            else ", at first order, about 5e-4 spacing² at second order; at first order about 1e-3 × the grid spacing is "
            "as accurate and faster)"
        ),
    )
    p.add_argument(
        "--max-iterations",
        type=int,
        default=10000,
        help="stop after this many iterations (2^d sweeps each) even if not converged; the files are then "
        "written with the last iterate and the command exits with status 3 (default: 10000)",
    )
    p.add_argument("--out", type=Path, default=Path("out"), help="output folder (default: ./out)")
    p.add_argument("--png", action="store_true", help="write a picture into --out (needs matplotlib)")
    p.add_argument(
        "--quiet",
        action="store_true",
        help=(
            "no progress bar; the summary line, warnings and errors are still printed"
            if box
            else "no progress bar and no notes (such as why order 1 ran where order 2 was asked for or chosen "
            "by --order auto); the summary line, warnings and errors are still printed"
        ),
    )


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="tubesweep",
        description="Distances and first-arrival times on implicit curves and surfaces by the fast sweeping "
        "method of Wong & Leung (2016): the eikonal equation in a thin tube around the surface, an "
        "extension equation in an outer layer, only O(N^(d-1)) grid nodes.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"tubesweep {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    p = sub.add_parser(
        "solve",
        help="first-arrival time on a curve/surface (two-layer tube, Algorithm 3)",
        description="Solve |grad_S u| = 1/F on an implicit curve or surface and write what is asked for into "
        "--out: a picture (--png), a mesh for ParaView (--export), the dense array (--dense), geodesic paths "
        "(--path-from), the band values (--npz: solution.npz). With none of these, solution.npz is written.",
    )
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--surface", choices=_surface_names(), help="a built-in curve or surface")
    src.add_argument(
        "--phi",
        type=Path,
        help="a .npy (or one-array .npz) file with a level set function φ sampled on "
        "the grid given by --lower/--upper; add --redistance if φ is not a signed distance",
    )
    src.add_argument(
        "--mask",
        type=Path,
        help="a .npy (or one-array .npz) file with a voxel mask (boolean, or 0 and 1; 1 inside) on the grid given "
        "by --lower/--upper: the surface between inside and outside voxels (ts.LevelSet.from_mask); see --smooth",
    )
    src.add_argument(
        "--mesh",
        type=Path,
        help="a triangle mesh file (.obj .ply .stl .off .obj.gz), or 'bunny' / 'spot' "
        "for the bundled example meshes; used in the closest-point representation (Sect. 5.2): open and "
        "scanned meshes with holes are fine",
    )
    src.add_argument(
        "--points",
        type=Path,
        help="a point cloud file (.xyz .txt .csv .pts .npy .ply): closest points by moving least squares; "
        "writes u at the samples to points.npz",
    )
    p.add_argument(
        "--n",
        type=int,
        default=None,
        help="nodes per axis for --surface (default: 101); for --mesh and --points, nodes along the longest side "
        "of the bounding box, padding included (default: 200 and 101); not for --phi or --mask (their arrays' shape)",
    )
    p.add_argument(
        "--padding", type=float, default=None, help="--mesh: empty grid spacings around the mesh (default 8)"
    )
    p.add_argument(
        "--normalize",
        action="store_true",
        help="--mesh: centre the mesh at the origin and scale its longest side to 1 (sources are then in "
        "the new coordinates)",
    )
    p.add_argument(
        "--source-vertex",
        type=int,
        action="append",
        help="--mesh: a source at this vertex (0-based; repeat for several; default: the vertex farthest "
        "from the centroid)",
    )
    p.add_argument(
        "--lower",
        type=float,
        nargs="+",
        help="grid lower corner (with --phi; default for --surface: the surface's box)",
    )
    p.add_argument("--upper", type=float, nargs="+", help="grid upper corner (with --lower)")
    p.add_argument(
        "--source",
        type=float,
        nargs="+",
        action="append",
        help="a source point on the surface (repeat for several; default: the surface's own)",
    )
    p.add_argument("--speed", type=float, default=1.0, help="constant speed F (default 1)")
    p.add_argument(
        "--method",
        choices=["two-layer", "naive"],
        default="two-layer",
        help="two-layer = Algorithm 3 (default); naive = Algorithm 2, the baseline that does not converge",
    )
    p.add_argument(
        "--order",
        choices=["1", "2", "auto"],
        default="auto",
        help="1 = the paper's first-order scheme; 2 = second order, decided node by node (first order at rims, "
        "creases and unresolved curvature; refuses a grid that does not resolve most of the tube, a cube's edges, "
        "coarse or self-facing meshes, Lax-Friedrichs); auto = 2 where it applies, 1 otherwise, with the reason "
        "printed (default: auto)",
    )
    p.add_argument("--inner", type=float, default=2.0, help="inner tube half-width in grid spacings (default 2)")
    p.add_argument(
        "--outer",
        type=float,
        default=4.0,
        help="outer tube half-width in grid spacings (default 4; the paper's Fig. 8 uses 5 for the bunny, "
        "which changes no value on the surface)",
    )
    p.add_argument(
        "--source-init",
        choices=["exact", "node"],
        default="exact",
        help="how point sources start: exact = the exact distance at the nodes within 2 grid spacings "
        "(default), node = u = 0 at the nearest node only, as in the paper",
    )
    p.add_argument(
        "--redistance",
        action="store_true",
        help="--phi: re-distance φ in the band (for a level set function that is not a signed distance, "
        "e.g. x² + y² + z² − r²)",
    )
    p.add_argument("--dense", action="store_true", help="write the dense array solution_dense.npy (NaN off the band)")
    p.add_argument(
        "--npz",
        action="store_true",
        help="write the band values to solution.npz (indices, values, roles, phi, the grid, the sources and, with "
        "several sources, nearest_source); the default when no other output (--png, --export, --dense, "
        "--path-from) is asked for",
    )
    p.add_argument(
        "--smooth",
        type=float,
        default=0.0,
        help="--mask: smooth the mask with a Gaussian of this width in voxels first (default 0: none)",
    )
    p.add_argument(
        "--up",
        choices=["x", "y", "z"],
        help="the vertical axis of 3D pictures (default: y for --mesh, as in most mesh files, z otherwise)",
    )
    p.add_argument(
        "--export",
        type=Path,
        action="append",
        metavar="FILE",
        help="write the surface mesh with u as point data for ParaView to FILE (relative to the current "
        "directory, like --out): .vtu .vtp .vtk .ply .obj (repeatable)",
    )
    p.add_argument(
        "--path-from",
        type=float,
        nargs="+",
        action="append",
        metavar="X",
        help="trace the geodesic path from this point of the surface to its nearest source (repeatable); "
        "writes paths.npz, prints each length and draws the paths in --png",
    )
    p.add_argument(
        "--path-from-vertex",
        type=int,
        action="append",
        metavar="I",
        help="--mesh: trace the geodesic path from vertex I (repeatable)",
    )
    _add_solver_options(p)

    t = sub.add_parser(
        "travel-time",
        help="first-arrival time in the whole box (Algorithm 1)",
        description="Travel times from point sources in [-1,1]^d with constant speed; writes travel_time.npy "
        "(and travel_time.png with --png) into --out.",
    )
    t.add_argument("--n", type=int, default=201, help="nodes per axis (default: 201)")
    t.add_argument("--dim", type=int, choices=[2, 3], default=2, help="2 (a square) or 3 (a cube) (default: 2)")
    t.add_argument(
        "--source",
        type=float,
        nargs="+",
        action="append",
        help="a source point, --dim coordinates (repeatable; default: the origin)",
    )
    t.add_argument("--speed", type=float, default=1.0, help="constant speed F > 0 (default: 1)")
    _add_solver_options(t, box=True)

    d = sub.add_parser("demo", help="run the built-in examples, print a table and write pictures")
    d.add_argument("--out", type=Path, default=Path("out/demo"), help="output folder (default: out/demo)")
    d.add_argument("--quick", action="store_true", help="smaller grids")

    r = sub.add_parser(
        "reproduce",
        help="reproduce the paper's tables and figures",
        description="Reproduce the numerical experiments of Wong & Leung (2016). Writes CSV, Markdown "
        "and PNG files per experiment.",
    )
    r.add_argument("names", nargs="+", help="experiment names or 'all' (see 'tubesweep reproduce list')")
    r.add_argument("--quick", action="store_true", help="small grids only (under two minutes in all)")
    r.add_argument("--out", type=Path, default=Path("out/reproduce"), help="output folder (default: out/reproduce)")

    sub.add_parser("info", help="version and build information")
    add_distances_parser(sub)  # `tubesweep distances`, in cli_distances.py
    return parser


class UsageError(ValueError):
    """A command line that cannot run (an argument missing, out of range or contradicting another):
    printed as an ``error:`` line, exit status 2, like every other refused input."""


def _grid_for(surface, n: int, lower: Optional[Sequence[float]], upper: Optional[Sequence[float]]):
    from .grid import Grid

    if lower is None or upper is None:
        box = getattr(surface, "default_box", None)
        if box is None:
            raise UsageError("give --lower and --upper for this surface")
        lower, upper = box
    return Grid(lower, upper, (n,) * len(lower))


def _load_phi(path: Path, flag: str = "--phi") -> np.ndarray:
    """φ (or a mask, ``flag``) sampled on the grid from a ``.npy`` file, or from a ``.npz`` holding one
    array (or one named ``phi``)."""
    import zipfile

    try:
        data = np.load(path, allow_pickle=False)
    except (ValueError, EOFError, zipfile.BadZipFile):
        raise UsageError(
            f"{flag} {path}: not a NumPy .npy or .npz file of numbers (NumPy cannot read it as one); save "
            f"it with numpy.save or numpy.savez"
        ) from None
    if isinstance(data, np.lib.npyio.NpzFile):
        with data:
            names = list(data.files)
            if "phi" in names:
                return np.asarray(data["phi"])
            if len(names) == 1:
                return np.asarray(data[names[0]])
        raise UsageError(f"{flag} {path}: an .npz file must hold one array or one named 'phi'; it holds {names}")
    return np.asarray(data)


def _fmt_point(p: Sequence[float]) -> str:
    return " ".join(f"{float(v):g}" for v in p)


def _check_phi_box(phi: np.ndarray, grid: Any, sources: np.ndarray, args: argparse.Namespace) -> None:
    """A source off φ's zero level set, with --phi, is most often a box (--lower/--upper) that is
    not the one φ was sampled on: says so, with what points to it (sources outside the box, the
    zero level set cut by the box's faces, |∇φ| ≠ 1 for a φ that should be a distance)."""
    box = f"--lower {_fmt_point(grid.lower)} --upper {_fmt_point(grid.upper)}"
    outside = np.flatnonzero(~grid.contains(sources))
    if outside.size:
        raise UsageError(
            f"--source {_fmt_point(sources[outside[0]])}: outside the grid box {box}; the box must be the one "
            f"φ ({args.phi}) was sampled on, and the sources on its zero level set inside it"
        )
    from ._interpolation import interpolate_dense

    h = grid.spacing
    at_sources = interpolate_dense(np.asarray(phi, dtype=float), grid, np.asarray(sources, dtype=float), "linear")
    off = np.flatnonzero(~(np.abs(at_sources) <= args.inner * h))
    if not off.size:
        return
    i = int(off[0])
    if not np.isfinite(at_sources[i]):
        bad = int(np.count_nonzero(~np.isfinite(phi)))
        raise UsageError(
            f"--phi {args.phi}: φ is NaN or inf at {bad} of its {phi.size} nodes, among them those around --source "
            f"{_fmt_point(sources[i])}; φ must be finite near the surface (NaN far from it, outside the band, is allowed)"
        )
    hints = []
    faces = [np.take(phi, [0, -1], axis=k) for k in range(phi.ndim)]
    if any(np.any(np.abs(f) <= h) or (np.nanmin(f) < 0 < np.nanmax(f)) for f in faces):
        hints.append("φ's zero level set reaches the box's faces (the box cuts the surface)")
    if not args.redistance:
        near = np.abs(phi) <= 2 * h
        if np.count_nonzero(near) >= 4:
            g = np.gradient(phi.astype(float), h)
            slope = float(np.median(np.sqrt(sum(gk[near] ** 2 for gk in g))))
            if abs(slope - 1.0) > 0.1:
                hints.append(
                    f"φ changes by {slope:.3g} per unit length near its zero level set, where a signed distance "
                    f"changes by 1: if φ is a distance, it was sampled on a box {slope:.3g} times this one's size"
                )
    raise UsageError(
        f"--source {_fmt_point(sources[i])}: φ is {float(at_sources[i]):.4g} there on the grid {box}, so the source "
        f"is {abs(float(at_sources[i])) / h:.3g} grid spacings off the surface"
        + (" and " if hints else "")
        + "; ".join(hints)
        + ". Check that --lower/--upper are the corners of the grid φ was sampled on (φ has shape "
        f"{'×'.join(map(str, phi.shape))}), then that the source lies on the surface"
    )


def _grid_of(surface: Any, n: int, padding: Optional[float]) -> Any:
    """A mesh's or a cloud's ``grid(n, padding)``, its refusal led by the flags that set it."""
    pad = 8.0 if padding is None else padding
    try:
        return surface.grid(n, padding=pad)
    except ValueError as e:
        raise UsageError(f"--n {n} --padding {pad:g}: {e}") from None


def cmd_solve(args: argparse.Namespace) -> int:
    from .grid import Grid
    from .solve import solve
    from .surface import LevelSet

    if args.source_vertex and not args.mesh:
        raise UsageError("--source-vertex needs --mesh")
    if args.path_from_vertex and not args.mesh:
        raise UsageError("--path-from-vertex needs --mesh")
    # what can be checked before the solve is checked before it
    from .geodesic_paths import starts_beyond_inner_tube
    from .output import export_format

    if args.out.exists() and not args.out.is_dir():
        raise UsageError(f"--out {args.out}: exists and is not a directory")
    if args.mesh:
        from .surfaces.mesh import from_mesh

        from . import data

        surface = from_mesh(data.mesh_file(args.mesh), normalize=args.normalize)  # a file, or bunny / spot
        n = 200 if args.n is None else args.n
        if args.lower is not None or args.upper is not None:
            raise UsageError("--mesh picks its grid from --n and --padding; do not give --lower/--upper")
        grid = _grid_of(surface, n, args.padding)
        name = surface.name
        print(f"{surface}; grid {grid.shape}, spacing {grid.spacing:.4g}")
    elif args.points:
        from .surfaces.points import from_points

        surface = from_points(args.points)  # type: ignore[assignment]
        if args.lower is not None or args.upper is not None:
            raise UsageError("--points picks its grid from --n and --padding; do not give --lower/--upper")
        grid = _grid_of(surface, 101 if args.n is None else args.n, args.padding)
        name = surface.name
        print(f"{surface}; grid {grid.shape}, spacing {grid.spacing:.4g}")
    elif args.surface:
        from .surfaces import REGISTRY

        if (args.lower is None) != (args.upper is None):
            raise UsageError("give both --lower and --upper (the grid's corners), or neither for the surface's own box")

        surface = REGISTRY[args.surface]()  # type: ignore[assignment]
        grid = _grid_for(surface, 101 if args.n is None else args.n, args.lower, args.upper)
        name = args.surface
    elif args.mask:
        mask = _load_phi(args.mask, "--mask")
        if args.lower is None or args.upper is None:
            raise UsageError("--mask needs --lower and --upper (the grid's corners)")
        grid = Grid(args.lower, args.upper, mask.shape)
        surface = LevelSet.from_mask(mask, grid, smooth=args.smooth)  # type: ignore[assignment]
        name = args.mask.stem
    else:
        phi = _load_phi(args.phi)
        if args.lower is None or args.upper is None:
            raise UsageError("--phi needs --lower and --upper (the grid's corners)")
        grid = Grid(args.lower, args.upper, phi.shape)
        surface = LevelSet(phi, redistance=args.redistance)  # type: ignore[assignment]
        name = args.phi.stem
    if args.smooth and not args.mask:
        raise UsageError("--smooth applies to --mask only")
    if args.redistance and not args.phi:
        raise UsageError("--redistance applies to --phi only (library surfaces and meshes are distances already)")
    if args.padding is not None and not (args.mesh or args.points):
        raise UsageError("--padding applies to --mesh only (a --surface or --phi grid is given by its box)")
    if args.normalize and not args.mesh:
        raise UsageError("--normalize applies to --mesh only (it was ignored for a --surface, --phi or --points)")
    if args.n is not None and (args.phi or args.mask):
        raise UsageError(
            f"--n applies to --surface, --mesh and --points: the grid of {'--phi' if args.phi else '--mask'} takes its "
            "shape from the array (it was ignored)"
        )
    if args.up is not None and (not args.png or grid.ndim != 3):
        raise UsageError(
            "--up sets the vertical axis of --png's 3D picture"
            + ("; a 2D curve's picture has none" if grid.ndim != 3 else ": add --png (it was ignored)")
        )
    bad_arity = [len(p) for p in args.path_from or [] if len(p) != grid.ndim]
    if bad_arity:
        raise UsageError(f"--path-from needs {grid.ndim} coordinates on a {grid.ndim}D grid; got {bad_arity[0]}")
    bad_arity = [len(p) for p in args.source or [] if len(p) != grid.ndim]
    if bad_arity:
        raise UsageError(f"--source needs {grid.ndim} coordinates on a {grid.ndim}D grid; got {bad_arity[0]}")
    for i in args.path_from_vertex or []:
        if not 0 <= i < len(surface.vertices):
            raise UsageError(f"--path-from-vertex {i}: the mesh has vertices 0..{len(surface.vertices) - 1}")
    if args.path_from:
        # a start off the surface is refused by the paths; refused here before the solve instead
        starts = np.array(args.path_from, dtype=float)
        outside = np.flatnonzero(~grid.contains(starts))
        if outside.size:
            raise UsageError(f"--path-from {' '.join(map(str, args.path_from[outside[0]]))}: outside the grid")
        far, dist = starts_beyond_inner_tube(surface, grid, starts, args.inner)
        if far.size:
            raise UsageError(
                f"--path-from {' '.join(map(str, args.path_from[far[0]]))}: {float(dist[far[0]]):.4g} from "
                f"the surface, farther than the inner tube ({args.inner:g} grid spacings); start on the surface"
            )
    for path in args.export or []:
        try:
            export_format(path, curve=grid.ndim == 2)
            writable(Path(path), "--export")
        except ValueError as e:
            raise UsageError(f"--export {path}: {e}" if not str(e).startswith("--export") else str(e)) from None
    try:
        writable(args.out, "--out", folder=True)
    except ValueError as e:
        raise UsageError(str(e)) from None
    if args.source_vertex:
        nv = len(surface.vertices)
        bad = [i for i in args.source_vertex if not 0 <= i < nv]
        if bad:
            raise UsageError(f"--source-vertex {bad[0]}: the mesh has vertices 0..{nv - 1}")
        sources = surface.vertices[np.array(args.source_vertex)]
        if args.source:
            sources = np.vstack([sources, np.array(args.source, dtype=float)])
    elif args.source:
        sources = np.array(args.source, dtype=float)
    elif hasattr(surface, "default_source"):
        sources = np.atleast_2d(surface.default_source)
    else:
        raise UsageError("give --source")
    if args.phi:
        _check_phi_box(phi, grid, sources, args)
    progress = make_progress(f"solve {name}", args.quiet)
    t0 = time.perf_counter()
    try:
        sol = solve(
            surface,
            grid,
            sources,
            hamiltonian=args.hamiltonian,
            speed=args.speed,
            inner=args.inner,
            outer=args.outer,
            method=args.method,
            source_init=args.source_init,
            tol=args.tol,
            max_iterations=args.max_iterations,
            progress=progress,
            order="auto" if args.order == "auto" else int(args.order),
        )
    finally:
        if progress is not None:
            progress.close()  # type: ignore[attr-defined]
    wall = time.perf_counter() - t0
    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    s = sol.stats
    # the names of docs/benchmarks.md: wall = the whole solve, sweeps = sol.stats.seconds, set-up = the rest
    print(
        f"{name}: grid {grid.shape}, band {s.band_points} nodes ({s.inner_points} inner, {s.outer_points} outer), "
        f"{s.iterations} iterations, {s.updates} updates, converged={s.converged}; wall {wall:.3f} s "
        f"(sweeps {s.seconds:.3f} s, set-up {max(wall - s.seconds, 0.0):.3f} s), order {s.order}"
    )
    if s.order_fallback is not None and not args.quiet:
        print(f"order=2 does not apply, so order 1 ran: {s.order_fallback}")
    unreached = int(np.count_nonzero(np.isinf(sol.values)))
    if unreached and not args.quiet:
        print(
            f"{unreached} of the {s.band_points} band nodes are not reached (u = inf, grey in pictures): they lie on parts "
            "of the surface that no source's part joins; a source on each part reaches it"
        )
    asked = args.png or args.dense or args.export or args.path_from or args.path_from_vertex
    if args.npz or not asked:
        _write_npz(out / "solution.npz", sol)
        print(f"wrote {out / 'solution.npz'}")
    if args.points:
        samples = surface.points  # type: ignore[attr-defined]
        np.savez_compressed(out / "points.npz", points=samples, u=sol(samples))
        print(f"wrote {out / 'points.npz'} (u at the {len(samples)} samples)")
    if args.dense:
        np.save(out / "solution_dense.npy", sol.to_dense())
        print(f"wrote {out / 'solution_dense.npy'}")
    for path in args.export or []:
        from .output import export

        t1 = time.perf_counter()
        print(f"wrote {export(sol, path)} ({time.perf_counter() - t1:.2f} s)")
    paths = _trace_paths(args, surface, sol, out)
    if args.png:
        from .output import plot

        up = args.up or ("y" if args.mesh else "z")
        fig = plot(
            sol,
            up=up,
            title=f"{name}: geodesic distance from the red star ({_scheme_words(s.order, args.hamiltonian)}, "
            f"grid {'×'.join(map(str, grid.shape))})",
            paths=paths,
        )
        fig.savefig(out / "solution.png", dpi=110, bbox_inches="tight")
        print(f"wrote {out / 'solution.png'}")
    return exit_status(s.converged, *_unconverged(s.iterations, args.max_iterations))


def _scheme_words(order: int, hamiltonian: str) -> str:
    """The scheme that ran, for a picture's title: "second order", "first order", or the first
    order with its local solver when that is not the default Godunov update ("first order, lxf")."""
    words = "second order" if order == 2 else "first order"
    return words if hamiltonian == "godunov" else f"{words}, {hamiltonian}"


def _unconverged(iterations: int, max_iterations: int) -> tuple:
    """What stopped a solve reported not converged, and its cure, for :func:`exit_status`: the
    iteration limit, or values the solve could not settle (the warning above says which)."""
    if iterations >= max_iterations:
        return f"the solve stopped at --max-iterations {max_iterations}", "pass a larger --max-iterations or --tol"
    return "the solve ended", "see the warning above for why"


def _write_npz(path: Path, sol: Any) -> None:
    """The band values with what is needed to place them on the grid (``--npz``)."""
    grid = sol.grid
    labels = {"nearest_source": sol.nearest_source()} if len(sol.sources) > 1 and sol._isotropic else {}
    np.savez_compressed(
        path,
        indices=sol.indices,
        values=sol.values,
        roles=sol.roles,
        phi=sol.phi,
        lower=grid.lower,
        upper=grid.upper,
        shape=np.array(grid.shape),
        sources=sol.sources,
        **labels,
    )


def _trace_paths(args: argparse.Namespace, surface: Any, sol: Any, out: Path) -> list:
    """The geodesic paths of --path-from / --path-from-vertex: printed, written to paths.npz."""
    starts = [np.array(p, dtype=float) for p in args.path_from or []]
    for i in args.path_from_vertex or []:
        nv = len(surface.vertices)
        if not 0 <= i < nv:
            raise UsageError(f"--path-from-vertex {i}: the mesh has vertices 0..{nv - 1}")
        starts.append(surface.vertices[i])
    if not starts:
        return []
    d = sol.grid.ndim
    bad = [len(p) for p in starts if len(p) != d]
    if bad:
        raise UsageError(f"--path-from needs {d} coordinates on a {d}D grid; got {bad[0]}")
    from .geodesic_paths import _onto_surface

    paths = sol.geodesic_paths(np.array(starts))
    ends = _onto_surface(sol, np.asarray(sol.sources, dtype=float))  # where a finished path ends
    for k, (p0, path) in enumerate(zip(starts, paths)):
        length = float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())
        hit = np.flatnonzero(np.all(ends == path[-1], axis=1))
        where = f"to source {int(hit[0])}" if hit.size else "stopped short of the sources (see the warning)"
        print(f"path {k} from {tuple(round(float(v), 6) for v in p0)}: length {length:.6g} {where}, {len(path)} points")
    np.savez_compressed(out / "paths.npz", **{f"path_{k}": p for k, p in enumerate(paths)})
    print(f"wrote {out / 'paths.npz'}")
    return paths


def cmd_travel_time(args: argparse.Namespace) -> int:
    from .euclidean import travel_time
    from .grid import Grid

    grid = Grid((-1.0,) * args.dim, (1.0,) * args.dim, (args.n,) * args.dim)
    sources = np.array(args.source, dtype=float) if args.source else np.zeros((1, args.dim))
    progress = make_progress("travel-time", args.quiet)
    try:
        u, s = travel_time(
            grid,
            sources,
            speed=args.speed,
            hamiltonian=args.hamiltonian,
            tol=args.tol,
            max_iterations=args.max_iterations,
            return_stats=True,
            progress=progress,
        )
    finally:
        if progress is not None:
            progress.close()  # type: ignore[attr-defined]
    args.out.mkdir(parents=True, exist_ok=True)
    np.save(args.out / "travel_time.npy", u)
    print(
        f"grid {grid.shape}: {s.iterations} iterations, {s.updates} updates, converged={s.converged}; sweeps "
        f"{s.seconds:.3f} s; wrote {args.out / 'travel_time.npy'}"
    )
    if args.png:
        from ._plot import plot

        plot(u, grid=grid, sources=sources, title="travel time").savefig(
            args.out / "travel_time.png", dpi=110, bbox_inches="tight"
        )
        print(f"wrote {args.out / 'travel_time.png'}")
    return exit_status(s.converged, *_unconverged(s.iterations, args.max_iterations))


def cmd_reproduce(args: argparse.Namespace) -> int:
    from . import reproduce

    if args.names == ["list"]:
        for n in reproduce.experiments():
            print(n)
        return 0
    reproduce.run(args.names, args.out, quick=args.quick)
    return 0


def cmd_info(_: argparse.Namespace) -> int:
    from . import _native

    print(
        f"tubesweep {__version__} (core {_native.__version__}), numpy {np.__version__}, python {sys.version.split()[0]}"
    )
    return 0


def _warning_line(
    message: Any, category: Any, filename: str, lineno: int, file: Any = None, line: Optional[str] = None
) -> None:
    """Shows a warning as one ``warning: …`` line on stderr, without the library's source line
    (what the command-line user can act on is the message)."""
    print(f"warning: {message}", file=sys.stderr if file is None else file)


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        return 0
    with warnings.catch_warnings():
        warnings.showwarning = _warning_line
        return _run(parser, args, list(sys.argv[1:] if argv is None else argv))


def _long_options(parser: argparse.ArgumentParser, command: Optional[str]) -> List[str]:
    """The long options of ``command``'s parser (for the abbreviations argparse accepts)."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction) and command in action.choices:
            return [o for o in action.choices[command]._option_string_actions if o.startswith("--")]
    return []


def _run(parser: argparse.ArgumentParser, args: argparse.Namespace, argv: Sequence[str]) -> int:
    try:
        if args.command == "solve":
            return cmd_solve(args)
        if args.command == "travel-time":
            return cmd_travel_time(args)
        if args.command == "demo":
            from .demo import run_demo

            return run_demo(args.out, quick=args.quick)
        if args.command == "reproduce":
            return cmd_reproduce(args)
        if args.command == "info":
            return cmd_info(args)
        if args.command == "distances":
            return cmd_distances(args)
    except KeyboardInterrupt:
        print("\ninterrupted", file=sys.stderr)
        return 130
    except (ValueError, TypeError, MemoryError, ImportError, OSError, NotImplementedError, Warning, EOFError) as e:
        # OSError: files (missing, a directory, no permission); NotImplementedError: a mesh format
        # that trimesh/meshio cannot read; Warning: a warning turned into an error (-W error);
        # EOFError: a file that ends early (numpy.load of an empty file; zipfile.BadZipFile is an
        # Exception, caught where files are read)
        print(f"error: {flag_named(str(e), argv, _long_options(parser, args.command))}", file=sys.stderr)
        return 2
    parser.print_help()
    return 1


if __name__ == "__main__":
    raise SystemExit(main())
