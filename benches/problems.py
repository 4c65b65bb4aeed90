"""Benchmark problems with exact answers: the surfaces, sources, evaluation points and exact
distances that every method (tubesweep and the peers) is measured against.

Every problem is built for one grid size ``n`` (nodes per axis of the box ``[-1, 1]^d``, or of
the mesh's box for the bunny) and provides

* ``surface`` (a :class:`tubesweep.Surface`), ``grid`` and ``source`` (a point on the surface);
* ``eval_points`` — points on the exact surface where errors are measured, and ``exact`` — the
  exact geodesic distance from ``source`` there;
* ``dense_phi(grid)`` — φ on the whole box, used only to extract the marching-cubes mesh the
  mesh-based peers run on (exact within a few Δx of the surface; its zero set is what matters);
* ``exact_from(source, points)`` — the exact distance from another source point on the surface
  (the mesh peers start from a mesh vertex, which need not coincide with ``source``).

Exact answers:

* sphere (radius 0.5): great-circle distance;
* ellipsoid: the oblate spheroid x²/a² + y²/a² + z²/c² = 1 with a = 0.5, c = 0.4 (flattening
  f = 0.2), an ellipsoid of revolution, so the exact geodesic distance is geographiclib's
  ``Geodesic(a, f).Inverse`` between geodetic coordinates (checked against a direct numerical
  integration of the geodesic equations in ``tests/test_bench_smoke.py``);
* six-fold star (2D, paper Sect. 6.1): arclength, ``tubesweep.surfaces.Star.geodesic_distance``;
* torus (R = 0.5, r = 0.25): on the outer equator the exact distance from a source on it is the
  equator arclength (R + r)|Δθ| as long as |Δθ| is below the first conjugate point
  π·sqrt(r / (R + r)) ≈ 1.81 rad (the equator is a geodesic of positive curvature
  K = 1 / (r (R + r)); geodesics leaving it at an angle return to it no earlier than the
  conjugate point). We measure on |Δθ| ≤ 1.5 rad;
* Stanford bunny: exact polyhedral geodesic distance (MMP, pygeodesic) on the input mesh, at its
  vertices.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np

import tubesweep as ts
import tubesweep.surfaces  # noqa: F401  (ts.surfaces)

REPO = Path(__file__).resolve().parents[1]
BUNNY = ts.data.bunny()

#: Points on the surface where errors are measured (fixed, the same for every method and N).
N_EVAL = 2000


@dataclass
class Problem:
    """One benchmark problem at one grid size."""

    name: str
    n: int
    ndim: int
    surface: ts.Surface
    grid: ts.Grid
    source: np.ndarray
    eval_points: np.ndarray
    exact: np.ndarray
    exact_from: Callable[[np.ndarray, np.ndarray], np.ndarray]
    dense_phi: Optional[Callable[[ts.Grid], np.ndarray]] = None
    #: (V, F) of a given input mesh (bunny): the mesh peers run on it instead of marching cubes
    input_mesh: Optional[Tuple[np.ndarray, np.ndarray]] = None
    notes: List[str] = field(default_factory=list)


def fibonacci_sphere(m: int) -> np.ndarray:
    """m nearly uniform unit vectors (Fibonacci lattice)."""
    i = np.arange(m) + 0.5
    z = 1 - 2 * i / m
    t = math.pi * (1 + 5**0.5) * i
    s = np.sqrt(1 - z * z)
    return np.stack([s * np.cos(t), s * np.sin(t), z], axis=1)


def box_grid(n: int, ndim: int) -> ts.Grid:
    return ts.Grid(lower=(-1.0,) * ndim, upper=(1.0,) * ndim, shape=(n,) * ndim)


def dense_points(grid: ts.Grid) -> np.ndarray:
    axes = [grid.lower[k] + grid.spacing * np.arange(grid.shape[k]) for k in range(grid.ndim)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, grid.ndim)


# --------------------------------------------------------------------------------------------
# sphere
# --------------------------------------------------------------------------------------------
def sphere(n: int) -> Problem:
    surf = ts.surfaces.Sphere(radius=0.5)
    src = np.array([-0.5, 0.0, 0.0])
    pts = 0.5 * fibonacci_sphere(N_EVAL)

    def exact_from(s: np.ndarray, p: np.ndarray) -> np.ndarray:
        return surf.geodesic_distance(p, s)

    def dense(grid: ts.Grid) -> np.ndarray:
        return (np.linalg.norm(dense_points(grid), axis=1) - 0.5).reshape(grid.shape)

    return Problem("sphere", n, 3, surf, box_grid(n, 3), src, pts, exact_from(src, pts), exact_from, dense)


# --------------------------------------------------------------------------------------------
# oblate spheroid
# --------------------------------------------------------------------------------------------
SPHEROID_A, SPHEROID_C = 0.5, 0.4


def ellipse_closest(y0: np.ndarray, y1: np.ndarray, a: float, c: float) -> Tuple[np.ndarray, np.ndarray]:
    """Closest point (x0, x1) on the ellipse (x0/a)² + (x1/c)² = 1 (a ≥ c) to points (y0, y1) in
    the first quadrant (y0, y1 ≥ 0).

    The closest point is x_i = e_i² y_i / (t + e_i²) with t the root of
    F(t) = Σ (e_i y_i / (t + e_i²))² − 1 on t > −c², a convex decreasing function; Newton's
    method from t0 = max_i(e_i y_i − e_i²) (where F ≥ 0) converges monotonically. Points on the
    major axis (y1 = 0) are solved in closed form.
    """
    y0 = np.asarray(y0, dtype=float)
    y1 = np.asarray(y1, dtype=float)
    x0 = np.empty_like(y0)
    x1 = np.empty_like(y1)
    axis = y1 <= 1e-12 * c
    # on the major axis: inside the evolute's cusp the closest point leaves the axis
    ya = y0[axis]
    inner = ya < (a * a - c * c) / a
    xa = np.where(inner, a * a * ya / (a * a - c * c), a)
    x0[axis] = xa
    x1[axis] = np.where(inner, c * np.sqrt(np.maximum(0.0, 1 - (xa / a) ** 2)), 0.0)
    g = ~axis
    q0, q1 = y0[g], y1[g]
    t = np.maximum(a * q0 - a * a, c * q1 - c * c)
    active = np.ones(t.shape, bool)
    for _ in range(300):
        if not active.any():
            break
        ta, p0, p1 = t[active], q0[active], q1[active]
        r0 = a * p0 / (ta + a * a)
        r1 = c * p1 / (ta + c * c)
        f = r0 * r0 + r1 * r1 - 1.0
        df = -2.0 * (r0 * r0 / (ta + a * a) + r1 * r1 / (ta + c * c))
        step = -f / df
        t[active] = ta + step
        done = np.abs(step) <= 1e-15 * np.maximum(1.0, np.abs(ta))
        idx = np.flatnonzero(active)
        active[idx[done]] = False
    x0[g] = a * a * q0 / (t + a * a)
    x1[g] = c * c * q1 / (t + c * c)
    return x0, x1


class Spheroid(ts.surfaces.Ellipsoid):
    """The oblate spheroid x²/a² + y²/a² + z²/c² = 1 (a ≥ c): the library's ``Ellipsoid(a, a, c)``,
    whose exact signed distance the core evaluates in Rust (what a user would solve on), with the
    benchmark's own closest point (Newton on the meridian ellipse) and geographiclib's geodesics
    for the exact answers."""

    def __init__(self, a: float = SPHEROID_A, c: float = SPHEROID_C):
        if not a >= c > 0:
            raise ValueError(f"need a >= c > 0 for an oblate spheroid; got a={a}, c={c}")
        super().__init__(a, a, c)
        self.a, self.c = float(a), float(c)

    def closest(self, p: np.ndarray) -> np.ndarray:
        p = np.asarray(p, dtype=float)
        rho = np.hypot(p[:, 0], p[:, 1])
        x0, x1 = ellipse_closest(rho, np.abs(p[:, 2]), self.a, self.c)
        safe = np.where(rho > 0, rho, 1.0)
        cx = np.where(rho > 0, p[:, 0] / safe, 1.0)
        cy = np.where(rho > 0, p[:, 1] / safe, 0.0)
        return np.stack([x0 * cx, x0 * cy, np.where(p[:, 2] >= 0, x1, -x1)], axis=1)

    def approx_phi(self, p: np.ndarray) -> np.ndarray:
        """g / |∇g| with g = ρ²/a² + z²/c² − 1: the same zero set, distance-like near it."""
        g = (p[:, 0] ** 2 + p[:, 1] ** 2) / self.a**2 + p[:, 2] ** 2 / self.c**2 - 1.0
        grad = 2 * np.sqrt((p[:, 0] ** 2 + p[:, 1] ** 2) / self.a**4 + p[:, 2] ** 2 / self.c**4)
        return g / np.maximum(grad, 1e-12)

    def geodetic(self, p: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
        """Geodetic latitude and longitude (degrees) of surface points (normal direction)."""
        p = np.asarray(p, dtype=float)
        rho = np.hypot(p[:, 0], p[:, 1])
        lat = np.degrees(np.arctan2(p[:, 2] / self.c**2, rho / self.a**2))
        lon = np.degrees(np.arctan2(p[:, 1], p[:, 0]))
        return lat, lon

    def geodesic_distance(self, points: np.ndarray, source: Sequence[float]) -> np.ndarray:
        """Exact geodesic distance (geographiclib) between the closest points of ``points`` and
        ``source`` on the spheroid."""
        try:
            from geographiclib.geodesic import Geodesic
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("the ellipsoid benchmark needs geographiclib: pip install geographiclib") from e
        geod = Geodesic(self.a, 1.0 - self.c / self.a)
        q = self.closest(np.asarray(points, dtype=float))
        s = self.closest(np.asarray(source, dtype=float).reshape(1, 3))
        lat, lon = self.geodetic(q)
        slat, slon = self.geodetic(s)
        out = np.empty(len(q))
        for i in range(len(q)):
            out[i] = geod.Inverse(float(slat[0]), float(slon[0]), float(lat[i]), float(lon[i]), Geodesic.DISTANCE)[
                "s12"
            ]
        return out


def ellipsoid(n: int) -> Problem:
    surf = Spheroid()
    src = np.array([-SPHEROID_A, 0.0, 0.0])
    u = fibonacci_sphere(N_EVAL)
    pts = np.stack([SPHEROID_A * u[:, 0], SPHEROID_A * u[:, 1], SPHEROID_C * u[:, 2]], axis=1)
    pts = surf.closest(pts)  # exactly on the surface (up to rounding)

    def dense(grid: ts.Grid) -> np.ndarray:
        x = dense_points(grid)
        phi = surf.approx_phi(x)
        near = np.abs(phi) < 3 * grid.spacing
        phi[near] = surf.signed_distance(x[near])
        return phi.reshape(grid.shape)

    p = Problem(
        "ellipsoid",
        n,
        3,
        surf,
        box_grid(n, 3),
        src,
        pts,
        surf.geodesic_distance(pts, src),
        surf.geodesic_distance,
        dense,
    )
    p.notes.append(
        f"oblate spheroid a={SPHEROID_A}, c={SPHEROID_C} (f={1 - SPHEROID_C / SPHEROID_A:.2f}); exact: geographiclib"
    )
    return p


# --------------------------------------------------------------------------------------------
# six-fold star (2D)
# --------------------------------------------------------------------------------------------
_STAR: Dict[str, object] = {}


def star(n: int) -> Problem:
    if "surf" not in _STAR:
        surf = ts.surfaces.Star(exact=True)
        src = np.asarray(surf.default_source, dtype=float)
        pts = surf.sample(N_EVAL)
        _STAR.update(surf=surf, src=src, pts=pts, exact=surf.geodesic_distance(pts, src))
    surf = _STAR["surf"]  # type: ignore[assignment]

    def exact_from(s: np.ndarray, p: np.ndarray) -> np.ndarray:
        return surf.geodesic_distance(p, s)  # type: ignore[attr-defined]

    return Problem("star", n, 2, surf, box_grid(n, 2), _STAR["src"], _STAR["pts"], _STAR["exact"], exact_from)  # type: ignore[arg-type]


# --------------------------------------------------------------------------------------------
# torus
# --------------------------------------------------------------------------------------------
TORUS_R, TORUS_r = 0.5, 0.25
TORUS_MAX_ANGLE = 1.5  # rad, below the conjugate point π·sqrt(r/(R+r)) ≈ 1.814


class Torus(ts.surfaces.Torus):
    """The torus (sqrt(x² + y²) − R)² + z² = r²: the library's ``Torus(R, r)``, whose exact signed
    distance the core evaluates in Rust (what a user would solve on), with the benchmark's own
    closest point and reference along the outer equator."""

    def __init__(self, R: float = TORUS_R, r: float = TORUS_r):
        if not R > r > 0:
            raise ValueError(f"need R > r > 0; got R={R}, r={r}")
        super().__init__(R, r)
        self.R, self.r = float(R), float(r)

    def closest(self, p: np.ndarray) -> np.ndarray:
        p = np.asarray(p, dtype=float)
        rho = np.hypot(p[:, 0], p[:, 1])
        safe = np.where(rho > 0, rho, 1.0)
        ring = np.stack([self.R * p[:, 0] / safe, self.R * p[:, 1] / safe, np.zeros(len(p))], axis=1)
        d = p - ring
        nd = np.linalg.norm(d, axis=1, keepdims=True)
        return ring + self.r * d / np.where(nd > 0, nd, 1.0)

    def equator_distance(self, points: np.ndarray, source: Sequence[float]) -> np.ndarray:
        """(R + r)|Δθ| between points and a source on the outer equator (exact there for
        |Δθ| below the conjugate point; NaN elsewhere)."""
        p = np.asarray(points, dtype=float)
        s = np.asarray(source, dtype=float).reshape(3)
        a = np.arctan2(p[:, 1], p[:, 0]) - math.atan2(s[1], s[0])
        a = np.abs(np.angle(np.exp(1j * a)))
        ok = (np.abs(p[:, 2]) < 1e-9) & (np.abs(np.hypot(p[:, 0], p[:, 1]) - (self.R + self.r)) < 1e-9)
        ok &= abs(s[2]) < 1e-9 and abs(math.hypot(s[0], s[1]) - (self.R + self.r)) < 1e-9
        return np.where(ok & (a <= math.pi * math.sqrt(self.r / (self.R + self.r))), (self.R + self.r) * a, np.nan)


def torus(n: int) -> Problem:
    surf = Torus()
    src = np.array([TORUS_R + TORUS_r, 0.0, 0.0])
    th = np.linspace(-TORUS_MAX_ANGLE, TORUS_MAX_ANGLE, 401)
    pts = np.stack([(TORUS_R + TORUS_r) * np.cos(th), (TORUS_R + TORUS_r) * np.sin(th), np.zeros_like(th)], axis=1)

    def dense(grid: ts.Grid) -> np.ndarray:
        return surf.signed_distance(dense_points(grid)).reshape(grid.shape)

    p = Problem(
        "torus", n, 3, surf, box_grid(n, 3), src, pts, surf.equator_distance(pts, src), surf.equator_distance, dense
    )
    p.notes.append(f"torus R={TORUS_R}, r={TORUS_r}; errors on the outer equator, |Δθ| ≤ {TORUS_MAX_ANGLE} rad")
    return p


# --------------------------------------------------------------------------------------------
# Stanford bunny
# --------------------------------------------------------------------------------------------
read_obj = ts.data.read_obj  # plain or gzip-compressed OBJ, file order kept


def compact_mesh(v: np.ndarray, f: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """Drops unreferenced vertices and degenerate faces (MMP needs a clean mesh)."""
    f = f[(f[:, 0] != f[:, 1]) & (f[:, 1] != f[:, 2]) & (f[:, 0] != f[:, 2])]
    used = np.unique(f)
    remap = -np.ones(len(v), dtype=np.int64)
    remap[used] = np.arange(len(used))
    return v[used], remap[f]


BUNNY_EVAL_SEED = 7
_BUNNY: Dict[str, object] = {}


def bunny_available() -> Tuple[bool, str]:
    if not BUNNY.exists():
        return False, f"{BUNNY} not found"
    if not hasattr(ts, "surfaces") or not hasattr(ts.surfaces, "from_mesh"):
        return False, "tubesweep.surfaces.from_mesh is not available in this build (mesh surfaces not merged yet)"
    return True, ""


def bunny_reference(cache_dir: Optional[Path] = None) -> Dict[str, np.ndarray]:
    """Input mesh, source vertex, evaluation vertices and their exact polyhedral geodesic
    distances (pygeodesic MMP on the input mesh), cached on disk."""
    if _BUNNY:
        return _BUNNY  # type: ignore[return-value]
    v, f = compact_mesh(*read_obj(BUNNY))
    # source: the vertex nearest the top of the bunny's back (a fixed, reproducible choice)
    centre = 0.5 * (v.min(0) + v.max(0))
    target = centre + np.array([0.0, 0.5, 0.0]) * (v.max(0) - v.min(0))
    src = int(np.argmin(np.linalg.norm(v - target, axis=1)))
    rng = np.random.default_rng(BUNNY_EVAL_SEED)
    ev = np.sort(rng.choice(len(v), size=min(N_EVAL, len(v)), replace=False))
    cache = (cache_dir or REPO / "out" / "bench" / "cache") / f"bunny_exact_{len(v)}_{src}_{BUNNY_EVAL_SEED}.npy"
    if cache.exists():
        dist = np.load(cache)
    else:
        import pygeodesic.geodesic as geodesic

        algo = geodesic.PyGeodesicAlgorithmExact(v, f.astype(np.int32))
        dist, _ = algo.geodesicDistances(np.array([src], dtype=np.int32), None)
        cache.parent.mkdir(parents=True, exist_ok=True)
        np.save(cache, dist)
    _BUNNY.update(v=v, f=f, src=np.array(src), eval_idx=ev, dist=np.asarray(dist, dtype=float))
    return _BUNNY  # type: ignore[return-value]


def bunny(n: int) -> Problem:
    ok, why = bunny_available()
    if not ok:
        raise RuntimeError(why)
    ref = bunny_reference()
    v, f, src, ev, dist = ref["v"], ref["f"], int(ref["src"]), ref["eval_idx"], ref["dist"]
    surf = ts.surfaces.from_mesh(str(BUNNY))
    grid = surf.grid(n=n)

    def exact_from(s: np.ndarray, p: np.ndarray) -> np.ndarray:
        raise NotImplementedError("the bunny's exact distances are known from the source vertex only")

    p = Problem("bunny", n, 3, surf, grid, v[src].copy(), v[ev], dist[ev], exact_from, None, input_mesh=(v, f))
    p.notes.append("bunny: exact = MMP (pygeodesic) on the input mesh; mesh peers run on the input mesh")
    return p


PROBLEMS: Dict[str, Callable[[int], Problem]] = {
    "sphere": sphere,
    "ellipsoid": ellipsoid,
    "star": star,
    "torus": torus,
    "bunny": bunny,
}
