"""Hostile inputs, group 8: surfaces from any φ and surfaces that move — voxel masks
(``ts.LevelSet.from_mask``), re-distanced φ (``LevelSet(phi, redistance=True)``), point clouds
(``ts.surfaces.from_points``), warm starts (``tube.moved``, ``warm=``, ``warm_refused=``) and
``ts.evolve``.

The checks are exact values or invariants: the sphere of radius 0.5's great-circle distance
``0.5·arccos(p·q / 0.25)``, a plane's Euclidean distance, the chord as a lower bound of a geodesic
distance, equal values for the same input in another layout or dtype, a warm solve within ten
stopping tolerances of the cold one (docs/moving-surfaces.md). ``expect="error"`` marks what
docs/surfaces.md, docs/point-clouds.md, docs/moving-surfaces.md or the docstrings promise to refuse.
"""

import textwrap

from hostile.framework import case


def snippet(*parts: str) -> str:
    """A case's code: a shared set-up and the case's own lines, each dedented on its own."""
    return "".join(textwrap.dedent(part).strip("\n") + "\n" for part in parts)


# ------------------------------------------------------------------------------------------------
# 8a. voxel masks: ts.LevelSet.from_mask (docs/surfaces.md, "From a voxel mask")
# ------------------------------------------------------------------------------------------------
BALL = """
X, Y, Z = G3.meshgrid()
R = np.sqrt(X**2 + Y**2 + Z**2)
ball = R < 0.5  # the ball of radius 0.5 on G3 (31 nodes, h = 1/15)
def mask_solve(m, **kw):
    return ts.solve(ts.LevelSet.from_mask(m, G3, **kw), G3, [(-0.5, 0, 0)])
"""
for label, mask, message in [
    ("all True", "np.ones(G3.shape, bool)", "all True"),
    ("all False", "np.zeros(G3.shape, bool)", "all False"),
    ("wrong shape", "ball[:-1]", "shape"),
    ("float with 0.5", "np.where(ball, 0.5, 0.0)", "0 and 1"),
    ("float with NaN", "np.where(ball, np.nan, 0.0)", "0 and 1"),
    ("complex", "ball + 0j", "dtype"),
    ("object array of bools", "ball.astype(object)", "dtype"),
    ("touching the box", "R < 1.2", "touches the grid's boundary"),
    ("smooth negative", "ball, smooth=-1.0", "smooth"),
    ("smooth NaN", "ball, smooth=float('nan')", "smooth"),
    # σ = 1e6 voxels erases any object (an error says so, docs/surfaces.md)
    ("smooth 1e6 voxels", "ball, smooth=1e6", "erases the object"),
]:
    case(f"mask/{label}", snippet(BALL, f"sol = mask_solve({mask}); ok = sane(sol)"), expect="error", message=message)
for label, mask in [
    ("Fortran order", "np.asfortranarray(ball)"),
    ("a strided view", "np.kron(ball, np.ones((2, 2, 2), bool))[::2, ::2, ::2]"),
    ("float32 of 0 and 1", "ball.astype(np.float32)"),
    ("int8 of 0 and 1", "ball.astype(np.int8)"),
]:
    case(
        f"mask/{label}",
        snippet(
            BALL,
            f"""
            sol, ref = mask_solve({mask}), mask_solve(ball)
            ok = close(sol.values, ref.values, 0) and sane(sol)  # the same mask: the same values, bit for bit
            """,
        ),
        expect="correct",
    )
case(
    "mask/2-D disc",
    """
    X, Y = G2.meshgrid()
    sol = ts.solve(ts.LevelSet.from_mask(X**2 + Y**2 < 0.25, G2), G2, [(-0.5, 0)])
    # half the circle of radius 0.5: pi/2; a raw mask is first order (measured 1.454 at N = 41)
    ok = sane(sol) and abs(sol([(0.5, 0)])[0] - np.pi / 2) < 0.15 * np.pi / 2
    """,
    expect="correct",
)
case(
    "mask/two separate blobs",
    """
    X, Y, Z = G3.meshgrid()
    two = (np.sqrt((X - 0.55)**2 + Y**2 + Z**2) < 0.25) | (np.sqrt((X + 0.55)**2 + Y**2 + Z**2) < 0.25)
    sol = ts.solve(ts.LevelSet.from_mask(two, G3), G3, [(0.8, 0, 0)])
    x = G3.node_points(sol.linear)[:, 0]
    u = sol([(0.3, 0, 0)])[0]  # the antipode on the source's blob: pi * 0.25 = 0.785 (first order: 0.60)
    # the blob without a source unreached (+inf), the other one finite and bounded
    ok = bool(np.all(np.isfinite(sol.values[x > 0])) and np.all(np.isinf(sol.values[x < 0])))
    ok = ok and 0.5 * np.pi * 0.25 < u < np.pi * 0.25 + G3.spacing
    """,
    expect="correct",
)
case(
    "mask/a single voxel",
    """
    X, Y, Z = G3.meshgrid()
    h = G3.spacing
    sol = ts.solve(ts.LevelSet.from_mask(X**2 + Y**2 + Z**2 < 0.01, G3), G3, [(h / 2, 0, 0)])
    # the surface is a blob of radius h/3 to h/2 about the origin: from (h/2, 0, 0) to the far side
    # (-h/2, 0, 0) the geodesic distance is at least the chord h (or a clean refusal: too small)
    ok = sane(sol) and sol([(-h / 2, 0, 0)])[0] >= 0.99 * h
    """,
)

# ------------------------------------------------------------------------------------------------
# 8b. re-distanced φ arrays and callables: LevelSet(phi, redistance=True) (docs/surfaces.md: "any φ
# whose zero level set crosses the grid", far from a distance, with plateaus, float32 noise)
# ------------------------------------------------------------------------------------------------
QUADRIC = """
X, Y, Z = G3.meshgrid()
R = np.sqrt(X**2 + Y**2 + Z**2)
def redist(phi, grid=G3):
    return ts.solve(ts.LevelSet(phi, redistance=True), grid, [(0.5, 0, 0)])
def band_error(sol):  # the re-distanced band against the exact signed distance |x| - 0.5
    return float(np.max(np.abs(sol.phi - (np.linalg.norm(sol.grid.node_points(sol.linear), axis=1) - 0.5))))
"""
for label, phi, message in [
    ("no sign change", "R + 1.0", "no sign change"),
    ("a constant zero", "np.zeros(G3.shape)", "no sign change"),
    ("NaN on the surface", "np.where(np.abs(R - 0.5) < 0.03, np.nan, R**2 - 0.25)", "NaN or inf"),
    ("inf far from the surface", "np.where(R > 0.9, np.inf, R**2 - 0.25)", "NaN or inf"),
]:
    case(
        f"redistance/{label}",
        snippet(QUADRIC, f"sol = redist({phi}); ok = sphere_ok(sol)"),
        expect="error",
        message=message,
    )
SAME_AS_QUADRIC = "close(sol.values, redist(R**2 - 0.25).values, {})"
# the same zero level set scaled: the same re-distanced band (3.3e-3 from |x| - 0.5 at N = 31 for
# scales 1 to 1e152), the same values
SCALED = "band_error(sol) < 0.01 and " + SAME_AS_QUADRIC.format("1e-3")
for label, phi, check in [
    ("plateau clip 0.1", "np.clip(R - 0.5, -0.1, 0.1)", "sphere_ok(sol)"),
    # a plateau a sixth of a spacing wide: the surface is known cell by cell (first order)
    (
        "plateau clip 0.01",
        "np.clip(R - 0.5, -0.01, 0.01)",
        "sane(sol) and abs(sol([(-0.5, 0, 0)])[0] - np.pi / 2) < 0.2",
    ),
    ("positive inside", "0.25 - R**2", SAME_AS_QUADRIC.format("1e-9")),
    ("float32", "(R**2 - 0.25).astype(np.float32)", SAME_AS_QUADRIC.format("1e-5")),
    ("scaled by 1e-200", "1e-200 * (R**2 - 0.25)", SCALED),
    ("scaled by 1e200", "1e200 * (R**2 - 0.25)", SCALED),
]:
    case(f"redistance/{label}", snippet(QUADRIC, f"sol = redist({phi})", f"ok = {check}"), expect="returns")
case(
    "redistance/zero exactly on grid nodes",
    """
    g = ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3)  # h = 0.05: (±0.5, 0, 0) and more nodes lie on the sphere
    X, Y, Z = g.meshgrid()
    phi = X**2 + Y**2 + Z**2 - 0.25
    assert np.count_nonzero(phi == 0) >= 6
    sol = ts.solve(ts.LevelSet(phi, redistance=True), g, [(0.5, 0, 0)])
    ok = sane(sol) and abs(sol([(-0.5, 0, 0)])[0] - np.pi / 2) < 0.03  # second order: 1.556
    """,
    expect="correct",
)
case(
    "redistance/plane zero on a layer of nodes",
    """
    X, Y, Z = G3.meshgrid()  # phi = x: zero on the nodes of the plane x = 0, which the box cuts
    sol = ts.solve(ts.LevelSet(X.copy(), redistance=True), G3, [(0, 0, 0)])
    ok = sane(sol) and abs(sol([(0, 0.5, 0.3)])[0] - np.sqrt(0.34)) < 0.01  # Euclidean in the plane
    """,
    expect="correct",
)
case(
    "redistance/one negative node",
    """
    phi = np.ones(G3.shape); phi[15, 15, 15] = -1e-3  # a surface far smaller than a grid cell
    sol = ts.solve(ts.LevelSet(phi, redistance=True), G3, [(0, 0, 0)])
    ok = sane(sol) and float(np.max(sol.values[sol.roles != 2])) < G3.spacing
    """,
)
case(
    "redistance/callable 2-D quadric",
    """
    sol = ts.solve(ts.LevelSet(lambda x: 4 * (np.sum(x**2, axis=1) - 0.25), redistance=True), G2, [(0.5, 0)])
    ok = sane(sol) and abs(sol([(-0.5, 0)])[0] - np.pi / 2) < 0.01
    """,
    expect="correct",
)

# ------------------------------------------------------------------------------------------------
# 8c. point clouds: ts.surfaces.from_points (docs/point-clouds.md, "What is checked")
# ------------------------------------------------------------------------------------------------
CLOUD = """
rng = np.random.default_rng(0)
x = rng.normal(size=(3000, 3))
P = 0.5 * x / np.linalg.norm(x, axis=1, keepdims=True)  # 3000 samples of the sphere of radius 0.5
EXACT = 0.5 * np.arccos(np.clip(P @ P[0] / 0.25, -1, 1))  # great circles from P[0]
def cloud_error(points, grid=G3, **kw):  # the largest error at the samples (0.022 for P at N = 31)
    cloud = ts.surfaces.from_points(points, **kw)
    sol = ts.solve(cloud, grid, [P[0]])
    return float(np.max(np.abs(sol(P) - EXACT))), cloud
"""
for label, points, message in [
    ("10 points", "P[:10]", "distinct points"),
    ("a NaN sample", "np.r_[P, [[np.nan, 0, 0]]]", "NaN or inf"),
    ("all on a line", "np.outer(np.linspace(-0.5, 0.5, 200), [1.0, 0.3, -1.0])", "one line"),
    ("coordinates 1e31", "P * 1e31", "rescale"),
    ("normals of shape (M, 2)", "P, normals=P[:, :2]", "normals must have the points' shape"),
    ("much sparser than the grid", "P[:100], grid=ts.Grid((-1,) * 3, (1,) * 3, (101,) * 3)", "spacing"),
    # the docstring: "TypeError If points is not numbers"
    ("strings of digits", "P.astype(str)", "numbers"),
]:
    case(
        f"cloud/{label}",
        snippet(CLOUD, f"err, cloud = cloud_error({points}); ok = err < 0.05"),
        expect="error",
        message=message,
    )
for label, points, check, expect, message in [
    # repeated samples are kept once (cloud.report["repeated"]): the same surface, the same values
    (
        "every sample twice",
        "np.r_[P, P]",
        "cloud.report['repeated'] == 3000 and err == cloud_error(P)[0]",
        "correct",
        None,
    ),
    # the samples again, 1e-9 apart (two scans merged, a float32 round trip): the same surface
    ("every sample twice 1e-9 apart", "np.r_[P, P + 1e-9]", "err < 0.05", "correct", None),
    (
        "one far outlier",
        "np.r_[P, [[0.0, 0.0, 0.7]]]",
        "err < 0.05 and len(cloud.outliers) == 1",
        "warning",
        "off the surface",
    ),
    ("complex with an imaginary part", "P + 0.1j", "err < 0.05", None, None),
]:
    case(
        f"cloud/{label}",
        snippet(CLOUD, f"err, cloud = cloud_error({points})", f"ok = {check}"),
        expect=expect,
        message=message,
    )
case(
    "cloud/a flat disc",
    """
    rng = np.random.default_rng(1)
    r, a = np.sqrt(rng.uniform(0, 0.36, 3000)), rng.uniform(0, 2 * np.pi, 3000)
    disc = np.c_[r * np.cos(a), r * np.sin(a), 0 * r]  # all samples on the plane z = 0
    cloud = ts.surfaces.from_points(disc)
    sol = ts.solve(cloud, G3, [cloud.points[0]])
    exact = np.linalg.norm(cloud.points - cloud.points[0], axis=1)  # a convex disc: Euclidean
    ok = cloud.open_surface and float(np.max(np.abs(sol(cloud.points) - exact))) < 0.05
    """,
    expect="correct",
)
case(
    "cloud/coordinates scaled by 1e10",
    snippet(
        CLOUD,
        """
        L = 1e10
        cloud = ts.surfaces.from_points(P * L)
        sol = ts.solve(cloud, ts.Grid((-L,) * 3, (L,) * 3, (31,) * 3), [cloud.points[0]])
        ok = float(np.max(np.abs(sol(P * L) / L - EXACT))) < 0.05
        """,
    ),
    expect="correct",
)
case(
    "cloud/2-D circle",
    """
    t = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    cloud = ts.surfaces.from_points(0.5 * np.c_[np.cos(t), np.sin(t)])
    sol = ts.solve(cloud, ts.Grid((-1, -1), (1, 1), (61, 61)), [cloud.points[0]])
    ok = float(np.max(np.abs(sol(cloud.points) - 0.5 * np.minimum(t, 2 * np.pi - t)))) < 0.01
    """,
    expect="correct",
)

# ------------------------------------------------------------------------------------------------
# 8d. warm starts: tube.moved, warm=, warm_refused= (docs/moving-surfaces.md, "When a warm start is
# refused"): the sphere grown by 0.4 spacings, warm within ten tolerances of cold
# ------------------------------------------------------------------------------------------------
WARM = """
h = G3.spacing
tube = ts.Tube(SPHERE, G3)
sol = tube.solve([(0, 0, 0.5)])
r = 0.5 + 0.4 * h
moved = tube.moved(ts.surfaces.Sphere(r))
def cold(**kw):
    return ts.solve(ts.surfaces.Sphere(r), G3, [(0, 0, r)], **kw)
def near_cold(s):
    c = cold()
    return bool(np.array_equal(s.linear, c.linear) and np.max(np.abs(s.values - c.values)) <= 10 * c.stats.order2["tol"])
"""
for label, call, message in [
    (
        "another grid",
        "ts.solve(ts.surfaces.Sphere(r), ts.Grid((-1,) * 3, (1,) * 3, (33,) * 3), [(0, 0, r)], warm=sol)",
        "another grid",
    ),
    ("previous solved at order=1", "moved.solve([(0, 0, r)], warm=tube.solve([(0, 0, 0.5)], order=1))", "first order"),
    ("this solve order=1", "moved.solve([(0, 0, r)], warm=sol, order=1)", "order=1 was asked for"),
    (
        "moved 3 spacings",
        "tube.moved(ts.surfaces.Sphere(0.5 + 3 * h)).solve([(0, 0, 0.5 + 3 * h)], warm=sol)",
        "moved farther",
    ),
    ("source moved across the sphere", "moved.solve([(r, 0, 0)], warm=sol)", "source 0 moved"),
    ("two sources instead of one", "moved.solve([(0, 0, r), (r, 0, 0)], warm=sol)", "source(s)"),
    ("a pair with a string", "moved.solve([(0, 0, r)], warm=('older', sol))", "warm must be the Solution"),
    ("three solutions", "moved.solve([(0, 0, r)], warm=(sol, sol, sol))", "pair (older, previous)"),
    ("warm_refused='ignore'", "moved.solve([(0, 0, r)], warm=sol, warm_refused='ignore')", "warm_refused must be"),
    # the docstrings: warm_refused is "raise" or "cold"
    ("warm_refused='ignore' without warm", "moved.solve([(0, 0, r)], warm_refused='ignore')", "warm_refused must be"),
]:
    case(
        f"warm/{label}",
        snippet(WARM, f"s = {call}", "ok = isinstance(s, ts.Solution) and near_cold(s)"),
        expect="error",
        message=message,
    )
OVERWRITE = "sol.values[:] = {}  # the user scribbles on the previous values\ns = moved.solve([(0, 0, r)], warm=sol)"
for label, code, check in [
    (
        "the same surface again",
        "s = tube.solve([(0, 0, 0.5)], warm=sol)",
        "close(s.values, sol.values, 10 * sol.stats.order2['tol'])",
    ),
    ("values overwritten with zeros", OVERWRITE.format("0.0"), "near_cold(s)"),
    ("values overwritten with NaN", OVERWRITE.format("np.nan"), "near_cold(s)"),
    (
        "another grid, warm_refused='cold'",
        "other = ts.solve(SPHERE, ts.Grid((-1,) * 3, (1,) * 3, (33,) * 3), [(0, 0, 0.5)])\n"
        "s = moved.solve([(0, 0, r)], warm=other, warm_refused='cold')",
        "'another grid' in s.stats.order2['warm']['refused'] and close(s.values, cold().values, 0)",
    ),
]:
    case(f"warm/{label}", snippet(WARM, code, f"ok = {check}"), expect="correct")
case(
    "warm/the pair in reverse order",
    snippet(
        WARM,
        """
        s1 = moved.solve([(0, 0, r)], warm=sol)
        r2 = r + 0.4 * h
        s = moved.moved(ts.surfaces.Sphere(r2)).solve([(0, 0, r2)], warm=(s1, sol))  # (previous, older)
        c = ts.solve(ts.surfaces.Sphere(r2), G3, [(0, 0, r2)])
        ok = np.max(np.abs(s.values - c.values)) <= 10 * c.stats.order2["tol"]
        """,
    ),
    expect="correct",
)
TWO_PARTS = """
g = ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3)
h = g.spacing
X = np.stack(g.meshgrid(), axis=-1)
def big(r):  # the sphere with the source
    return np.linalg.norm(X - (-0.45, 0, 0), axis=-1) - r
small = np.linalg.norm(X - (0.55, 0, 0), axis=-1) - 0.2  # 9 spacings away: unreached
r = 0.35 + 0.4 * h
"""
case(
    "warm/topology: a part vanished",
    snippet(
        TWO_PARTS,
        """
        sol = ts.Tube(np.minimum(big(0.35), small), g).solve([(-0.1, 0, 0)])
        s = ts.Tube(big(r), g).solve([(-0.45 + r, 0, 0)], warm=sol)
        ok = False
        """,
    ),
    expect="error",
    message="topology changed",
)
case(
    "warm/topology: a part vanished, warm_refused='cold'",
    snippet(
        TWO_PARTS,
        """
        sol = ts.Tube(np.minimum(big(0.35), small), g).solve([(-0.1, 0, 0)])
        s = ts.Tube(big(r), g).solve([(-0.45 + r, 0, 0)], warm=sol, warm_refused="cold")
        c = ts.solve(big(r), g, [(-0.45 + r, 0, 0)])
        ok = "topology" in s.stats.order2["warm"]["refused"] and close(s.values, c.values, 0)
        """,
    ),
    expect="correct",
)
case(
    "warm/topology: a part appeared",
    snippet(
        TWO_PARTS,
        """
        sol = ts.Tube(big(0.35), g).solve([(-0.1, 0, 0)])
        s = ts.Tube(np.minimum(big(r), small), g).solve([(-0.45 + r, 0, 0)], warm=sol)
        ok = False
        """,
    ),
    expect="error",
    message="outside the previous band",
)

# ------------------------------------------------------------------------------------------------
# 8e. ts.evolve (docs/moving-surfaces.md, "A surface moved by its own solution")
# ------------------------------------------------------------------------------------------------
EVOLVE = """
X, Y, Z = G3.meshgrid()
PHI = np.sqrt(X**2 + Y**2 + Z**2) - 0.5
def run(speed=lambda u: 0.2 + 0 * u, phi=None, **kw):
    kw.setdefault("dt", 0.05)
    kw.setdefault("steps", 2)
    return ts.evolve(PHI if phi is None else phi, G3, [(0, 0, 0.5)], speed, **kw)
def pole_ok(ev, r):  # the source at the north pole rides on the sphere of radius r
    return abs(float(ev.solutions[-1].sources[0][2]) - r) < 0.15 * G3.spacing
"""
for label, call, message in [
    ("speed returns NaN", "run(lambda u: np.where(u > 0.5, np.nan, 0.1))", "NaN or inf"),
    ("speed of shape (M, 2)", "run(lambda u: np.ones((len(u), 2)))", "one normal speed per value of u"),
    ("dt breaks the CFL condition", "run(lambda u: 1.0 + 0 * u, dt=0.1)", "take dt ≤"),
    ("steps=0", "run(steps=0)", "steps must be a positive integer"),
    ("steps=-3", "run(steps=-3)", "steps must be a positive integer"),
    ("dt=0", "run(dt=0.0)", "dt must be a positive"),
    # every numeric argument refuses a bool (tubesweep._numbers, the types/* cases)
    ("dt=True", "run(lambda u: 0.01 + 0 * u, dt=True)", "dt"),
    ("phi of another shape", "run(phi=PHI[:-1])", "grid's shape"),
    ("phi with NaN", "run(phi=np.where(np.abs(PHI) > 0.4, np.nan, PHI))", "NaN or inf"),
]:
    case(
        f"evolve/{label}",
        snippet(EVOLVE, f"ev = {call}", "ok = pole_ok(ev, 0.52)"),
        expect="error",
        message=message,
    )
for label, call, check in [
    # a real number may be a NumPy scalar or a 0-d array (tubesweep._validate.real_scalar, types/*)
    ("dt a 0-d array", "run(dt=np.array(0.05))", "pole_ok(ev, 0.52)"),
    ("speed returns a scalar", "run(lambda u: 0.2)", "pole_ok(ev, 0.52) and ev.times == [0.0, 0.05, 0.1]"),
]:
    case(f"evolve/{label}", snippet(EVOLVE, f"ev = {call}", f"ok = {check}"), expect="correct")
case(
    "evolve/zero speed leaves the distances",
    snippet(
        EVOLVE,
        """
        ev = run(lambda u: 0 * u, steps=4, every=2)
        a = np.linspace(0.3, 2.6, 12)
        d = np.stack([np.sin(a), 0 * a, np.cos(a)], 1)
        first, last = ev.solutions[0](0.5 * d) / 0.5, ev.solutions[-1](0.5 * d) / 0.5
        # the surface does not move: u(0.5 d)/0.5 stays what it was, within the 1e-2 that
        # tests/test_moving.py allows a sphere growing at V = 0.3 over the same steps
        ok = pole_ok(ev, 0.5) and float(np.max(np.abs(last - first))) < 1e-2
        """,
    ),
    expect="correct",
)
case(
    "evolve/speed modifies u in place",
    snippet(
        EVOLVE,
        """
        def speed(u):
            v = 0.2 + 0 * u
            u[:] = -7.0  # the callable scribbles on its argument
            return v
        ev = run(speed)
        ok = pole_ok(ev, 0.52) and all(float(np.min(s.values)) >= 0 for s in ev.solutions)
        """,
    ),
)
case(
    "evolve/2-D circle at constant speed",
    """
    X, Y = G2.meshgrid()
    ev = ts.evolve(np.hypot(X, Y) - 0.5, G2, [(0.5, 0)], lambda u: 0.2 + 0 * u, dt=0.05, steps=4)
    r = 0.5 + 0.2 * 0.2
    ok = abs(ev.solutions[-1]([(-r, 0)])[0] - np.pi * r) < 0.01  # half the circle of radius r
    """,
    expect="correct",
)
case(
    "evolve/a sphere shrinking to nothing",
    """
    X, Y, Z = G3.meshgrid()
    ev = ts.evolve(np.sqrt(X**2 + Y**2 + Z**2) - 0.15, G3, [(0, 0, 0.15)], lambda u: -1 + 0 * u, dt=0.03, steps=8)
    ok = False  # the sphere is gone after 5 steps: there is no solution to return
    """,
)
