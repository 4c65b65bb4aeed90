"""The ``tubesweep distances`` sub-command: the geodesic distance matrix between points on a
surface (:func:`tubesweep.distance_matrix`), locally on all cores or on a Dask cluster."""

from __future__ import annotations

import argparse
import sys
import time
import zipfile
from pathlib import Path
from typing import Any, Optional

import numpy as np

from ._cli_exit import exit_status
from ._paths import writable

EXAMPLES = """examples:
  tubesweep distances --surface sphere --n 101 --sample 200 --out D.npy
  tubesweep distances --mesh bunny --n 161 --points pts.npy --out D.npy
  tubesweep distances --mesh bunny --sample 1000 --out D.npy --scheduler tcp://10.0.0.5:8786
  tubesweep distances --phi phi.npy --lower -1 -1 -1 --upper 1 1 1 --points pts.npy --out D.npy
"""


def add_distances_parser(sub: Any) -> None:
    """Adds ``distances`` to the sub-commands ``sub`` of the ``tubesweep`` parser."""
    from .surfaces import REGISTRY

    p = sub.add_parser(
        "distances",
        help="geodesic distance matrix between points on a surface (all cores or a Dask cluster)",
        description="Geodesic distances between M points on a surface: one solve per point on a band built once, "
        "in parallel across the points (or on a Dask cluster with --scheduler). Writes the (M, M) matrix, "
        "symmetric with a zero diagonal (the average of the two one-way estimates), to --out, and the points to "
        "<out>_points.npy.",
        epilog=EXAMPLES,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--surface", choices=sorted(REGISTRY), help="a built-in surface")
    src.add_argument(
        "--mesh", type=Path, help="a triangle mesh (.obj .ply .stl .off .obj.gz), or bunny / spot for the bundled ones"
    )
    src.add_argument("--phi", type=Path, help="a .npy file with a level set function sampled on the grid")
    pts = p.add_mutually_exclusive_group(required=True)
    pts.add_argument(
        "--points",
        type=Path,
        help="the points (M, d) on the surface: a .npy file (numpy.save), or a text file (.txt .csv .xyz .dat: "
        "one point per line, coordinates separated by spaces or commas, '#' comments)",
    )
    pts.add_argument("--sample", type=int, metavar="K", help="K points by geodesic farthest-point sampling")
    p.add_argument("--out", type=Path, required=True, help="the .npy file the matrix is written to")
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="a Dask scheduler's address (e.g. tcp://10.0.0.5:8786): the solves run on its workers "
        "(pip install 'tubesweep[distributed]', or pip install '.[distributed]' in a checkout)",
    )
    p.add_argument(
        "--n",
        type=int,
        default=None,
        help="nodes per axis (--surface, default 101) or along the mesh's longest side (--mesh, default 200)",
    )
    p.add_argument(
        "--padding", type=float, default=None, help="--mesh: empty grid spacings around the mesh (default 8)"
    )
    p.add_argument("--normalize", action="store_true", help="--mesh: centre the mesh and scale its longest side to 1")
    p.add_argument("--lower", type=float, nargs="+", help="grid lower corner (--phi; optional for --surface)")
    p.add_argument("--upper", type=float, nargs="+", help="grid upper corner")
    p.add_argument("--inner", type=float, default=2.0, help="inner tube half-width in grid spacings (default 2)")
    p.add_argument("--outer", type=float, default=4.0, help="outer tube half-width in grid spacings (default 4)")
    p.add_argument("--threads", type=int, default=0, help="solves at once on this machine (default 0: all cores)")
    p.add_argument("--chunk-size", type=int, default=None, help="--scheduler: sources per Dask task")
    p.add_argument(
        "--tol",
        type=float,
        default=None,
        help="stop when no value changes by more than this in an iteration (default: 1e-10 of the travel time across the grid, at most 1e-10, "
        "at first order, about 5e-4 spacing² at second order)",
    )
    p.add_argument(
        "--order",
        choices=["1", "2", "auto"],
        default="auto",
        help="auto (default): second order where it applies, the paper's first-order scheme otherwise; 1 or 2",
    )
    p.add_argument("--quiet", action="store_true", help="no progress bar")


class _SourcesBar:
    """A progress bar over the sources: tqdm when installed, else a counter line (on a terminal)."""

    def __init__(self, description: str, quiet: bool):
        self.enabled = not quiet and sys.stderr.isatty()
        self._bar = None
        self._desc = description
        if self.enabled:
            try:
                from tqdm import tqdm

                self._bar = tqdm(desc=description, unit="source", file=sys.stderr, leave=False)
            except ImportError:
                self._bar = None

    def __call__(self, done: int, total: int) -> None:
        if not self.enabled:
            return
        if self._bar is not None:
            self._bar.total = total
            self._bar.n = done
            self._bar.refresh()
        else:
            print(f"\r{self._desc}: {done}/{total} sources", end="", file=sys.stderr, flush=True)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
        elif self.enabled:
            print(file=sys.stderr)


def _surface_and_grid(args: argparse.Namespace) -> Any:
    from .grid import Grid

    if args.mesh:
        from .surfaces.mesh import from_mesh

        if args.lower is not None or args.upper is not None:
            raise ValueError("--mesh picks its grid from --n and --padding; do not give --lower/--upper")
        from . import data

        surface = from_mesh(data.mesh_file(args.mesh), normalize=args.normalize)  # a file, or bunny / spot
        return surface, surface.grid(
            200 if args.n is None else args.n, padding=8.0 if args.padding is None else args.padding
        )
    if args.padding is not None or args.normalize:
        # (ignored before for a --surface or --phi, silently: a helper's review)
        raise ValueError(
            f"{'--padding' if args.padding is not None else '--normalize'} applies to --mesh only (a --surface or "
            "--phi grid is given by its box)"
        )
    if args.surface:
        from .surfaces import REGISTRY

        surface = REGISTRY[args.surface]()  # type: ignore[assignment]
        if (args.lower is None) != (args.upper is None):
            raise ValueError("give both --lower and --upper, or neither for the surface's own box")
        lower, upper = (args.lower, args.upper) if args.lower is not None else surface.default_box
        n = 101 if args.n is None else args.n
        return surface, Grid(lower, upper, (n,) * len(lower))
    from .surface import LevelSet

    if args.lower is None or args.upper is None:
        raise ValueError("--phi needs --lower and --upper (the grid's corners)")
    if args.n is not None:
        raise ValueError("--n applies to --surface and --mesh: the grid of --phi takes its shape from the array")
    try:
        phi = np.load(args.phi, allow_pickle=False)
    except (ValueError, EOFError, zipfile.BadZipFile):  # an empty file; a zip header without an archive
        raise ValueError(f"--phi {args.phi}: not a NumPy .npy file of numbers") from None
    if not isinstance(phi, np.ndarray):
        raise ValueError(f"--phi {args.phi}: give a .npy file (numpy.save), not an archive")
    return LevelSet(phi), Grid(args.lower, args.upper, phi.shape)


TEXT_SUFFIXES = (".txt", ".csv", ".xyz", ".dat")


def load_points(path: Path, ndim: int) -> np.ndarray:
    """The (M, ndim) points of ``--points``: a ``.npy`` file read by :func:`numpy.load`, a text file
    (one point per line, separated by spaces or commas) by :func:`numpy.loadtxt`."""
    suffix = path.suffix.lower()
    if suffix == ".npy":
        try:
            points = np.load(path, allow_pickle=False)
        except (ValueError, EOFError, zipfile.BadZipFile):
            raise ValueError(
                f"--points {path}: not a NumPy .npy file of numbers; save the points with numpy.save, or give a "
                f"text file ({' '.join(TEXT_SUFFIXES)}) with one point per line"
            ) from None
    elif suffix in TEXT_SUFFIXES:
        with open(path) as f:
            first = next((ln for ln in f if ln.strip() and not ln.lstrip().startswith("#")), "")
        try:
            points = np.loadtxt(path, delimiter="," if "," in first else None, ndmin=2, comments="#")
        except ValueError as e:
            raise ValueError(
                f"--points {path}: not a text file of numbers with {ndim} per line, separated by spaces or commas "
                f"(numpy.loadtxt: {e})"
            ) from None
    else:
        raise ValueError(
            f"--points {path}: give a .npy file (numpy.save) or a text file ({' '.join(TEXT_SUFFIXES)}) with one "
            f"point per line; '{path.suffix}' is neither"
        )
    points = np.asarray(points)
    if points.ndim != 2 or points.shape[1] != ndim or len(points) == 0:
        raise ValueError(
            f"--points {path}: needs M points of {ndim} coordinates (an (M, {ndim}) array); got shape {points.shape}"
        )
    if not np.issubdtype(points.dtype, np.number):
        raise ValueError(f"--points {path}: the points must be numbers; got {points.dtype}")
    return points.astype(float)


def _client(address: Optional[str]) -> Any:
    if address is None:
        return None
    try:
        from distributed import Client
    except ImportError:
        raise ImportError(
            "--scheduler needs Dask's distributed scheduler: pip install 'tubesweep[distributed]', "
            "or pip install '.[distributed]' in a checkout"
        ) from None
    return Client(address)


def cmd_distances(args: argparse.Namespace) -> int:
    """Runs ``tubesweep distances``; bad input raises ValueError/TypeError/OSError (exit status 2)."""
    from .distances import distance_matrix, farthest_point_sampling
    from .tube import Tube

    if args.out.suffix != ".npy":
        raise ValueError(f"--out {args.out}: the matrix is written as a .npy file; give a name ending in .npy")
    if args.out.parent and not args.out.parent.exists():
        raise ValueError(f"--out {args.out}: the folder {args.out.parent} does not exist")
    writable(args.out, "--out")
    if args.sample is not None and args.sample < 1:
        raise ValueError(f"--sample {args.sample}: give a positive number of points")
    if args.chunk_size is not None and args.scheduler is None:
        raise ValueError("--chunk-size is for --scheduler (the sources per Dask task)")
    order = args.order if args.order == "auto" else int(args.order)
    t0 = time.perf_counter()
    surface, grid = _surface_and_grid(args)
    client = _client(args.scheduler)  # connected first: a wrong address fails before any work
    tube = Tube(surface, grid, inner=args.inner, outer=args.outer)
    label = args.surface or (args.mesh or args.phi).name
    print(
        f"{label}: grid {grid.shape}, spacing {grid.spacing:.4g}; {tube.band_points:,} band nodes "
        f"({tube.setup_seconds:.2f} s)"
    )
    if args.points is not None:
        points = load_points(args.points, grid.ndim)
    else:
        bar = _SourcesBar("sampling", args.quiet)
        try:
            points, radii = farthest_point_sampling(
                tube, None, args.sample, tol=args.tol, threads=args.threads, progress=bar, order=order
            )
        finally:
            bar.close()
        apart = (
            " (inf: some points lie on parts of the surface no other point's front reaches)"
            if np.isinf(radii[-1])
            else ""
        )
        print(f"{len(points)} points by farthest-point sampling, last radius {radii[-1]:.4g}{apart}")
    bar = _SourcesBar("distances", args.quiet)
    t1 = time.perf_counter()
    try:
        matrix, info = distance_matrix(
            tube,
            None,
            points,
            client=client,
            tol=args.tol,
            threads=args.threads,
            chunk_size=args.chunk_size,
            progress=bar,
            info=True,
            order=order,
        )
    finally:
        bar.close()
        if client is not None:
            client.close()
    seconds = time.perf_counter() - t1
    np.save(args.out, matrix)
    points_file = args.out.with_name(args.out.stem + "_points.npy")
    np.save(points_file, info["points"])
    m = len(matrix)
    unreached = int(np.count_nonzero(np.isinf(matrix))) // 2
    apart = (
        f" ({unreached} of the {m * (m - 1) // 2} pairs lie on parts of the surface that do not join: inf in the matrix)"
        if unreached
        else ""
    )
    print(
        f"{m} x {m} distances in {seconds:.2f} s ({m / seconds:.1f} sources/s"
        f"{', on ' + args.scheduler if args.scheduler else ''}); largest {np.max(matrix[np.isfinite(matrix)]):.4g}{apart}; "
        f"asymmetry of the one-way estimates removed: {info['asymmetry']:.3g}, their largest diagonal "
        f"{info['diagonal']:.3g}; order {info['order']}"
        + (f" (second order does not apply: {info['order_fallback']})" if info["order_fallback"] else "")
    )
    print(f"wrote {args.out} and {points_file} ({time.perf_counter() - t0:.2f} s in all)")
    bad = info["unconverged"]
    return exit_status(bad == 0, f"{bad} of the {m} solves stopped at their iteration limit", "pass a larger --tol")
