"""Hostile inputs, group 9: public API areas the other groups barely touch — many sources
(``Tube.solve_many``, ``ts.distance_matrix``, ``ts.farthest_point_sampling``), what a ``Solution``
offers beyond its values (point evaluation, pickling, geodesic paths, labels; ``BoxSolution``) and
files out (``ts.export``, ``Evolution.export``, ``evolve``'s checkpoints); ``api_reach_more`` has
the anisotropic Hamiltonians, the command line and awkward meshes and clouds.

The checks are exact values (great circles, the uniform flow's circle front, the box's exact
distance at second order), reference solves (the single solve a batch row must equal bit for bit,
docs/many-sources.md; ``Metric(4·I)`` against the isotropic solve at speed 2, docs/hamiltonians.md;
the clean mesh against the same mesh with awkward records) or invariants (a symmetric matrix with
a zero diagonal, ``inf`` between parts no path joins, non-increasing sampling radii, a file read
back). ``expect="error"`` marks what the docs or docstrings promise to refuse. The names all start
with ``reach-`` (``hostile_inputs.py --only reach-``).
"""

import textwrap

from hostile.framework import case


def snippet(*parts: str) -> str:
    """A case's code: a shared set-up and the case's own lines, each dedented on its own."""
    return "".join(textwrap.dedent(part).strip("\n") + "\n" for part in parts)


# ------------------------------------------------------------------------------------------------
# 9a. many sources: Tube.solve_many (docs/many-sources.md: row k equals tube.solve(sources[k]) bit
# for bit, at both orders, with or without at=)
# ------------------------------------------------------------------------------------------------
MANY = """
tube = ts.Tube(SPHERE, G3)
S = 0.5 * np.eye(3)  # three point sources on the sphere of radius 0.5
AT = 0.5 * np.array([[-1.0, 0, 0], [0, -1.0, 0], [0.6, 0.8, 0]])
def rows_equal(U, groups, at=None, **kw):  # each row the single solve of its source, bit for bit
    ref = [tube.solve(g, **kw) for g in groups]
    ref = [s.values if at is None else s(at) for s in ref]
    return all(np.array_equal(u, r, equal_nan=True) for u, r in zip(U, ref)) and len(U) == len(groups)
"""
for label, code, check in [
    (
        "order=2 rows equal the single solves",
        "U, st = tube.solve_many(S, order=2, return_stats=True)",
        "st['order'] == 2 and U.shape == (3, tube.band_points) and rows_equal(U, [[s] for s in S], order=2)",
    ),
    (
        "order=1 at= equals sol(at)",
        "U = tube.solve_many(S, at=AT, order=1)",
        "U.shape == (3, 3) and rows_equal(U, [[s] for s in S], AT, order=1)",
    ),
    # the sphere's centre (no closest point), a corner far from the band, a point on the sphere: NaN
    # off the band as sol(points) gives it (its docstring), at both orders
    (
        "at= off the band reads NaN as sol(at)",
        "P = np.array([[0.0, 0, 0], [0.95, 0.95, 0.95], [-0.5, 0, 0]])\n"
        "U1, U2 = tube.solve_many(S[:2], at=P, order=1), tube.solve_many(S[:2], at=P, order=2)",
        "rows_equal(U1, [[s] for s in S[:2]], P, order=1) and rows_equal(U2, [[s] for s in S[:2]], P, order=2)"
        " and np.isnan(U2[:, :2]).all() and np.isfinite(U2[:, 2]).all()",
    ),
    (
        "duplicate sources give identical rows",
        "U = tube.solve_many([S[0], S[1], S[0]])",
        "np.array_equal(U[0], U[2]) and rows_equal(U, [[S[0]], [S[1]], [S[0]]])",
    ),
    # a group is one multi-source solve; a point repeated in it is still the same nearest point
    (
        "a group with a repeated point equals the multi-source solve",
        "G = [np.array([S[0], S[0], S[1]]), S[2]]\nU = tube.solve_many(G, at=AT)",
        "rows_equal(U, [G[0], [S[2]]], AT)",
    ),
    (
        "a callable speed at order 2",
        "sp = lambda x: 1.0 + 0.5 * x[:, 2]\nU = tube.solve_many(S, at=AT, speed=sp)",
        "rows_equal(U, [[s] for s in S], AT, speed=sp)",
    ),
]:
    case(f"reach-many/{label}", snippet(MANY, code, f"ok = {check}"), expect="correct")
case(
    "reach-many/at= empty (0, 3)",
    snippet(MANY, "U = tube.solve_many(S, at=np.empty((0, 3)))", "ok = U.shape == (3, 0)"),
)
for label, call, message in [
    ("at= with NaN", "tube.solve_many(S, at=[[0.5, 0, 0], [np.nan, 0, 0]])", "NaN"),
    ("no sources (an empty list)", "tube.solve_many([])", "empty"),
    # renamed() names a bad source by its place among the K (many_order2.py)
    ("a group of no points is named", "tube.solve_many([S[0], np.empty((0, 3))])", "sources[1]"),
    ("a source off the surface is named", "tube.solve_many([S[0], (0.2, 0.0, 0.0)])", "sources[1]"),
    ("a Hamiltonian object", "tube.solve_many(S, hamiltonian=ts.hamiltonians.Isotropic())", "solve_many takes"),
]:
    case(f"reach-many/{label}", snippet(MANY, f"U = {call}", "ok = False"), expect="error", message=message)
case(
    "reach-many/progress raises: the exception, no partial result",
    snippet(
        MANY,
        """
        def progress(done, total):
            raise UserError(f"stop at {done} of {total}")
        rng = np.random.default_rng(0)
        x = rng.normal(size=(24, 3))
        U = tube.solve_many(0.5 * x / np.linalg.norm(x, axis=1, keepdims=True), progress=progress, threads=1)
        ok = False  # returned although progress raised (or was never called in about 2 s of solves)
        """,
    ),
    expect="error",
    message="stop at",
)
TWO_PARTS = """
g = ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3)
X = np.stack(g.meshgrid(), axis=-1)
# a sphere of radius 0.35 about (-0.45, 0, 0) and one of radius 0.2 about (0.55, 0, 0), 9 spacings apart
phi = np.minimum(np.linalg.norm(X - (-0.45, 0, 0), axis=-1) - 0.35, np.linalg.norm(X - (0.55, 0, 0), axis=-1) - 0.2)
tube2 = ts.Tube(phi, g)
A, B = np.array([-0.1, 0, 0]), np.array([0.35, 0, 0])  # on the big one, on the small one
FAR_A, FAR_B = np.array([-0.8, 0, 0]), np.array([0.75, 0, 0])  # their antipodes
def between(u, exact):  # a first- or second-order value of the half great circle
    return 0.8 * exact < u < exact + 2 * g.spacing
"""
case(
    "reach-many/sources on two parts: inf across",
    snippet(
        TWO_PARTS,
        """
        U = tube2.solve_many([A, B], at=[FAR_A, FAR_B])
        ok = U[0, 1] == np.inf and U[1, 0] == np.inf and between(U[0, 0], np.pi * 0.35) and between(U[1, 1], np.pi * 0.2)
        """,
    ),
    expect="correct",
)
ICO = """
def icosphere(levels):  # an octahedron refined onto the sphere of radius 0.5 (docs/point-clouds.md)
    v = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
    f = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    for _ in range(levels):
        a, b, c = f.T
        edges = np.sort(np.r_[np.c_[a, b], np.c_[b, c], np.c_[c, a]], axis=1)
        pairs, index = np.unique(edges, axis=0, return_inverse=True)
        middle = v[pairs].sum(axis=1)
        v = np.r_[v, middle / np.linalg.norm(middle, axis=1, keepdims=True)]
        ab, bc, ca = len(v) - len(pairs) + index.reshape(3, -1)
        f = np.r_[np.c_[a, ab, ca], np.c_[ab, b, bc], np.c_[ca, bc, c], np.c_[ab, bc, ca]]
    return 0.5 * v, f
V, F = icosphere(3)  # 258 vertices, edges of 2.1 to 3.2 spacings of GM: the smooth map is a fit everywhere
GM = ts.Grid((-0.7,) * 3, (0.7,) * 3, (31,) * 3)
EXACT = 0.5 * np.arccos(np.clip(V @ V[4] / 0.25, -1, 1))  # great circles from V[4] = (0, 0, 0.5)
def mesh_solve(v, f, grid=GM, **kw):  # the solve from V[4] and its mean error at the sphere's vertices
    sol = ts.solve(ts.surfaces.from_mesh((v, f), **kw), grid, [V[4]])
    return sol, float(np.mean(np.abs(sol.on_mesh(V) - EXACT)))
"""
case(
    "reach-many/return_stats on an exact-map mesh: order 1 and why",
    snippet(
        ICO,
        """
        tube = ts.Tube(ts.surfaces.from_mesh((V, F), smooth=False), GM)
        U, st = tube.solve_many([V[4], V[0]], return_stats=True)
        ok = st["order"] == 1 and bool(st["order_fallback"]) and len(st["iterations"]) == 2
        ok = ok and all(np.array_equal(U[k], tube.solve([p]).values) for k, p in enumerate([V[4], V[0]]))
        """,
    ),
    expect="correct",
)

# ------------------------------------------------------------------------------------------------
# 9b. ts.distance_matrix and ts.farthest_point_sampling (docs/many-sources.md)
# ------------------------------------------------------------------------------------------------
case(
    "reach-dmatrix/the default order against great circles",
    """
    rng = np.random.default_rng(3)
    x = rng.normal(size=(6, 3))
    P = 0.5 * x / np.linalg.norm(x, axis=1, keepdims=True)
    D, info = ts.distance_matrix(SPHERE, ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3), P, info=True)
    E = 0.5 * np.arccos(np.clip(P @ P.T / 0.25, -1, 1))
    # symmetric bit for bit, a zero diagonal, exactly 0 one-way at second order (the docs); the
    # second-order error at N = 41 is some 1e-2 at most (3.2e-3 at N = 101), order 1's 0.16
    ok = info["order"] == 2 and info["diagonal"] == 0 and np.array_equal(D, D.T) and np.all(np.diag(D) == 0)
    ok = ok and float(np.max(np.abs(D - E))) < 0.05
    """,
    expect="correct",
)
case(
    "reach-dmatrix/identical points are exactly 0 apart",
    snippet(
        MANY,
        """
        D = ts.distance_matrix(tube, None, [S[0], S[1], S[0]])
        ok = D[0, 2] == 0 and np.array_equal(D[0], D[2]) and np.array_equal(D, D.T) and abs(D[0, 1] - np.pi / 4) < 0.05
        """,
    ),
    expect="correct",
)
for label, call, message in [
    ("a point off the surface is named", "ts.distance_matrix(tube, None, [S[0], (0.0, 0.0, 0.0)])", "points[1]"),
]:
    case(
        f"reach-dmatrix/{label}",
        snippet(MANY, f"D = {call}", "ok = False"),
        expect="error",
        message=message,
    )
case(
    "reach-dmatrix/two parts: inf between them",
    snippet(
        TWO_PARTS,
        """
        D = ts.distance_matrix(tube2, None, [A, FAR_A, B])
        ok = D[0, 2] == np.inf and D[1, 2] == np.inf and between(D[0, 1], np.pi * 0.35) and np.array_equal(D, D.T)
        """,
    ),
    expect="correct",
)
case(
    "reach-fps/the sphere: the antipode, then a quarter circle",
    snippet(
        MANY,
        """
        pts, radii = ts.farthest_point_sampling(tube, None, 4, start=S[0])
        h = G3.spacing
        ok = np.allclose(pts[0], S[0]) and np.linalg.norm(pts[1] + S[0]) < 2 * h and radii[0] == np.inf
        ok = ok and abs(radii[1] - np.pi / 2) < 0.05 and abs(radii[2] - np.pi / 4) < 0.05
        # (the points are the closest points of inner-tube nodes, one Newton step each: 7e-5 off here)
        ok = ok and bool(np.all(np.diff(radii[1:]) <= 0)) and np.allclose(np.linalg.norm(pts, axis=1), 0.5, atol=0.01 * h)
        """,
    ),
    expect="correct",
)
for label, call, message in [
    ("k beyond the distinct surface points", "ts.farthest_point_sampling(tube, None, 10**6)", "exceeds"),
]:
    case(f"reach-fps/{label}", snippet(MANY, f"r = {call}", "ok = False"), expect="error", message=message)
case(
    "reach-fps/two parts: the second point on the other part, radius inf",
    snippet(
        TWO_PARTS,
        """
        pts, radii = ts.farthest_point_sampling(tube2, None, 3, start=A)
        # docstring: a point on a part the others do not reach has radius inf
        ok = radii[0] == np.inf and radii[1] == np.inf and pts[1][0] > 0.2 and np.isfinite(radii[2]) and pts[2][0] < 0
        """,
    ),
    expect="correct",
)

# ------------------------------------------------------------------------------------------------
# 9c. what a Solution offers (solution.py docstrings, docs/paths-and-labels.md) and BoxSolution
# ------------------------------------------------------------------------------------------------
case(
    "reach-solution/pickled at order 2: the same values read at points",
    """
    import pickle
    sol = ts.solve(SPHERE, G3, [(0.5, 0, 0)])
    s2 = pickle.loads(pickle.dumps(sol))
    P = np.array([[0.5, 0, 0], [0.45, 0.2, 0.1], [-0.5, 0, 0], [0.0, 0.0, 0.0]])
    ok = sol.order == 2 and s2.order == 2 and np.array_equal(s2(P), sol(P), equal_nan=True) and s2(P)[0] == 0
    ok = ok and np.array_equal(s2.nearest_source(), sol.nearest_source())
    """,
    expect="correct",
)
case(
    "reach-solution/read at no points (0, 3)",
    """
    a, b = ts.solve(SPHERE, G3, [(0.5, 0, 0)]), ts.solve(SPHERE, G3, [(0.5, 0, 0)], order=1)
    ok = a(np.empty((0, 3))).shape == (0,) and b(np.empty((0, 3)), interpolation="cubic").shape == (0,)
    """,
    expect="correct",
)
case(
    "reach-solution/exactly 0 at the source at order 2, linear and cubic",
    """
    sol = ts.solve(SPHERE, G3, [(0.5, 0, 0)])
    # docs/many-sources.md: the factored form near the source is read, "exactly 0 at the source"
    ok = sol.order == 2 and sol([(0.5, 0, 0)])[0] == 0 and sol([(0.5, 0, 0)], interpolation="cubic")[0] == 0
    """,
    expect="correct",
)
case(
    "reach-solution/geodesic path: a quarter great circle",
    """
    sol = ts.solve(SPHERE, G3, [(-0.5, 0, 0)])
    path = sol.geodesic_path((0, 0.5, 0))
    length = float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())
    # first-order lengths: 0.16 spacings off at N = 41 (docs/paths-and-labels.md); half a spacing allowed
    ok = abs(length - np.pi / 4) < 0.5 * G3.spacing and np.allclose(path[-1], (-0.5, 0, 0), atol=1e-9)
    ok = ok and np.allclose(np.linalg.norm(path, axis=1), 0.5, atol=1e-6)
    """,
    expect="correct",
)
case(
    "reach-solution/geodesic path from the source itself",
    """
    sol = ts.solve(SPHERE, G3, [(-0.5, 0, 0)])
    path = sol.geodesic_path((-0.5, 0, 0))
    ok = len(path) <= 2 and float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum()) < 1e-9
    """,
    expect="correct",
)
case(
    "reach-solution/geodesic paths from no starts",
    """
    paths = ts.solve(SPHERE, G3, [(-0.5, 0, 0)]).geodesic_paths(np.empty((0, 3)))
    ok = list(paths) == []
    """,
)
case(
    "reach-solution/nearest_source on two parts: -1 where unreached",
    snippet(
        TWO_PARTS,
        """
        sol = tube2.solve([A])
        lab = sol.nearest_source()
        ok = bool(np.all(lab[np.isinf(sol.values)] == -1)) and bool(np.all(lab[np.isfinite(sol.values)] == 0))
        ok = ok and sol.nearest_source([FAR_A, FAR_B]).tolist() == [0, -1]
        """,
    ),
    expect="correct",
)
case(
    "reach-solution/nearest_source of a metric solve with two sources",
    """
    sol = ts.solve(SPHERE, G3, [(0.5, 0, 0), (-0.5, 0, 0)], hamiltonian=ts.hamiltonians.Metric(np.diag([2.0, 1, 1])))
    lab = sol.nearest_source()
    ok = False
    """,
    expect="error",
    message="isotropic",
)
case(
    "reach-box/BoxSolution: NaN outside the box, 0 at the source, exact inside",
    """
    b = ts.travel_time(G2, [(0.1, 0.2)], order=2, return_solution=True)
    v = b([(5.0, 5.0), (0.1, 0.2), (0.4, 0.6)])
    e = b(np.empty((0, 2)))
    ok = np.isnan(v[0]) and v[1] == 0 and abs(v[2] - 0.5) < 1e-9 and e.shape == (0,)
    """,
    expect="correct",
)

# ------------------------------------------------------------------------------------------------
# 9d. files out: ts.export (output.py docstring, docs/meshes-and-output.md), Evolution.export and
# evolve's checkpoints (docs/moving-surfaces.md)
# ------------------------------------------------------------------------------------------------
EXPORT = """
from tubesweep.output import read_vtp
SOL = ts.solve(SPHERE, G3, [(0.5, 0, 0)])
def at(*parts):
    return os.path.join(TMP, *parts)
def read_ok(p, sol):  # the file read back: u at the vertices is sol.on_mesh there
    v, c, d = read_vtp(p)
    return close(d["u"], sol.on_mesh(v), 1e-12) and len(c) > 0
"""
case(
    "reach-export/.VTP in folders that do not exist yet",
    snippet(EXPORT, "p = ts.export(SOL, at('e1', 'a', 'b', 'S.VTP'))", "ok = os.path.isfile(p) and read_ok(p, SOL)"),
    expect="correct",
)
case(
    "reach-export/overwrites an existing file",
    snippet(
        EXPORT,
        """
        other = ts.solve(SPHERE, G3, [(-0.5, 0, 0), (0, 0, 0.5)])
        p = ts.export(SOL, at('e2.vtp'))
        p = ts.export(other, at('e2.vtp'))
        v, c, d = read_vtp(p)
        ok = read_ok(p, other) and close(d["nearest_source"], other.nearest_source(v), 0)
        """,
    ),
    expect="correct",
)
case(
    "reach-export/.vtu through meshio, u and nearest_source",
    snippet(
        EXPORT,
        """
        import meshio
        sol = ts.solve(SPHERE, G3, [(-0.5, 0, 0), (0, 0, 0.5)])
        m = meshio.read(ts.export(sol, at("e3.vtu")))
        ok = close(m.point_data["u"], sol.on_mesh(m.points), 1e-9)
        ok = ok and close(m.point_data["nearest_source"], sol.nearest_source(m.points), 0)
        """,
    ),
    expect="correct",
)
for label, call, message in [
    ("an unknown suffix .stl", "ts.export(SOL, at('e4.stl'))", "unknown format"),
]:
    case(f"reach-export/{label}", snippet(EXPORT, f"p = {call}", "ok = False"), expect="error", message=message)
case(
    "reach-export/onto a directory",
    snippet(EXPORT, "os.makedirs(at('e9.vtp'))", "p = ts.export(SOL, at('e9.vtp'))", "ok = False"),
    expect="error",
)
case(
    "reach-export/under a path that is a file",
    snippet(
        EXPORT,
        """
        write("e10", "a file, not a folder")
        try:
            p = ts.export(SOL, at("e10", "x.vtp"))
        except OSError as e:  # documented: "OSError If the file cannot be written"
            raise ValueError(f"{type(e).__name__}: {e}") from None
        ok = False
        """,
    ),
    expect="error",
)
CLOUD = """
from tubesweep.output import read_vtp
rng = np.random.default_rng(0)
x = rng.normal(size=(3000, 3))
P = 0.5 * x / np.linalg.norm(x, axis=1, keepdims=True)  # 3000 samples of the sphere of radius 0.5
EXACT = 0.5 * np.arccos(np.clip(P @ P[0] / 0.25, -1, 1))
"""
case(
    "reach-export/a point cloud's .vtp read back by read_vtp",
    snippet(
        CLOUD,
        """
        cloud = ts.surfaces.from_points(P)
        sol = ts.solve(cloud, G3, [P[0]])
        # docs/meshes-and-output.md: ".vtp (VTK XML PolyData, ASCII) written by tubesweep and read back
        # by ts.output.read_vtp"
        v, c, d = read_vtp(ts.export(sol, os.path.join(TMP, "e12.vtp")))
        ok = len(v) == len(cloud.points) and close(d["u"], sol(cloud.points), 1e-12)
        """,
    ),
    expect="correct",
)
case(
    "reach-export/a point cloud's normals are written",
    snippet(
        CLOUD,
        """
        # from_points: "normals ... kept for tubesweep.export"
        cloud = ts.surfaces.from_points(P, normals=2 * P)
        sol = ts.solve(cloud, G3, [P[0]])
        text = open(ts.export(sol, os.path.join(TMP, "e13.vtp"))).read()
        ok = "normal" in text.lower()
        """,
    ),
    expect="correct",
)
EVOLVE = """
X, Y, Z = G3.meshgrid()
PHI = np.sqrt(X**2 + Y**2 + Z**2) - 0.5
SPEED = lambda u: 0.2 + 0 * u
def run(phi=None, sources=((0, 0, 0.5),), **kw):
    kw.setdefault("dt", 0.05)
    kw.setdefault("steps", 2)
    return ts.evolve(PHI if phi is None else phi, G3, sources, kw.pop("speed", SPEED), **kw)
"""
case(
    "reach-evolve/.pvd into a new folder, frames read back",
    snippet(
        EVOLVE,
        """
        import xml.etree.ElementTree as ET
        from tubesweep.output import read_vtp
        ev = run()
        p = ev.export(os.path.join(TMP, "v1", "new", "run.pvd"))
        sets = ET.parse(p).getroot().findall("Collection/DataSet")
        files = [os.path.join(os.path.dirname(p), s.get("file")) for s in sets]
        ok = [float(s.get("timestep")) for s in sets] == ev.times and len(files) == 3
        for f, sol in zip(files, ev.solutions):
            v, c, d = read_vtp(f)
            ok = ok and close(d["u"], sol.on_mesh(v), 1e-12)
        """,
    ),
    expect="correct",
)
case(
    "reach-evolve/a checkpoint resumed equals the longer run",
    snippet(
        EVOLVE,
        """
        ck = os.path.join(TMP, "v3.npz")
        run(checkpoint=ck)
        d = np.load(ck)
        more = run(phi=d["phi"], sources=d["sources"])
        full = run(steps=4)
        # a constant speed moves φ the same whatever u: the resumed φ is the 4-step φ
        ok = int(d["step"]) == 2 and abs(float(d["t"]) - 0.1) < 1e-12 and close(more.phis[-1], full.phis[-1], 1e-12)
        a = 0.52 * np.array([[0, 0.6, 0.8], [0.6, 0, -0.8], [0, 0, -1.0]])
        ok = ok and close(more.solutions[-1](a), full.solutions[-1](a), 1e-3)
        """,
    ),
    expect="correct",
)
case(
    "reach-evolve/every beyond steps keeps the first and last",
    snippet(EVOLVE, "ev = run(steps=3, every=10)", "ok = np.allclose(ev.times, [0.0, 0.15]) and len(ev.phis) == 2"),
    expect="correct",
)
case(
    "reach-evolve/cfl=1.5",
    snippet(EVOLVE, "ev = run(cfl=1.5)", "ok = False"),
    expect="error",
    message="cfl",
)
