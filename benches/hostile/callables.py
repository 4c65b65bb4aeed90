"""Hostile inputs, group 3: user callables (φ, closest point, speed, flow) that modify their argument,
return views, integers, NaN, the wrong shape, or raise; φ arrays with NaN or inf.
"""

from hostile.framework import SPHERE_CP, SPHERE_PHI, case

# ------------------------------------------------------------------------------------------------
# 3. callables
# ------------------------------------------------------------------------------------------------
mutators = {
    "in place zero": "x[:] = 0",
    "in place shift": "x += 0.1",
    "in place nan": "x[:] = np.nan",
    "in place scale": "x *= 3",
}
for label, mut in mutators.items():
    case(
        f"callable/phi modifies argument ({label})",
        f"""
        def phi(x):
            v = {SPHERE_PHI}
            {mut}
            return v
        sol = ts.solve(phi, G3, [(0.5, 0, 0)])
        ok = close(sol.values, ts.solve(lambda x: {SPHERE_PHI}, G3, [(0.5, 0, 0)]).values, 0)
    """,
        expect="correct",
    )
    case(
        f"callable/cp modifies argument ({label})",
        f"""
        def cp(x):
            c = {SPHERE_CP}
            {mut}
            return c
        sol = ts.solve(ts.ClosestPoint(cp), G3, [(0.5, 0, 0)])
        ok = close(sol.values, ts.solve(ts.ClosestPoint(lambda x: {SPHERE_CP}), G3, [(0.5, 0, 0)]).values, 0)
    """,
        expect="correct",
    )
    case(
        f"callable/speed modifies argument ({label})",
        f"""
        def speed(x):
            v = 1.0 + 0.0 * x[:, 0]
            {mut}
            return v
        src = np.array([(0.5, 0, 0)])
        sol = ts.solve(SPHERE, G3, src, speed=speed)
        ok = close(sol.values, ref_sphere().values, 1e-12) and close(sol.sources, [(0.5, 0, 0)], 0)
    """,
        expect="correct",
    )
    case(
        f"callable/travel_time speed modifies argument ({label})",
        f"""
        def speed(x):
            v = 2.0 + 0.0 * x[:, 0]
            {mut}
            return v
        u = ts.travel_time(G2, [(0.1, 0.2)], speed=speed)
        ok = close(u, ts.travel_time(G2, [(0.1, 0.2)], speed=2.0), 1e-12)
    """,
        expect="correct",
    )
    case(
        f"callable/flow modifies argument ({label})",
        f"""
        def flow(x):
            v = np.zeros_like(x)
            {mut}
            return v
        sol = ts.solve(SPHERE, G3, [(0.5, 0, 0)], flow=flow)
        ref = ts.solve(SPHERE, G3, [(0.5, 0, 0)], flow=lambda x: np.zeros_like(x))
        ok = close(sol.values, ref.values, 0)
    """,
        expect="correct",
    )
case(
    "callable/phi returns a view of its argument",
    """
    def phi(x):
        x[:, 0] = np.linalg.norm(x, axis=1) - 0.5
        return x[:, 0]
    sol = ts.solve(phi, G3, [(0.5, 0, 0)])
    ok = close(sol.values, ts.solve(lambda x: np.linalg.norm(x, axis=1) - 0.5, G3, [(0.5, 0, 0)]).values, 0)
""",
    expect="correct",
)
case(
    "callable/cp returns its argument modified (view)",
    f"""
    def cp(x):
        x[:] = {SPHERE_CP}
        return x
    sol = ts.solve(ts.ClosestPoint(cp), G3, [(0.5, 0, 0)])
    ok = close(sol.values, ts.solve(ts.ClosestPoint(lambda x: {SPHERE_CP}), G3, [(0.5, 0, 0)]).values, 0)
""",
    expect="correct",
)
case(
    "callable/speed returns a cached array it changes later",
    """
    cache = {}
    def speed(x):
        v = cache.setdefault(len(x), np.ones(len(x)))
        out = v.copy(); v[:] = 7.0  # the next call with this length sees 7
        return v if len(x) > 10 else out
    sol = ts.solve(SPHERE, G3, [(0.5, 0, 0)], speed=speed)
    ok = sane(sol)
""",
)
case(
    "callable/phi returns integers",
    """
    sol = ts.solve(lambda x: np.round(40 * (np.linalg.norm(x, axis=1) - 0.5)).astype(int) / 40.0 * 0 + (np.linalg.norm(x, axis=1) - 0.5), G3, [(0.5, 0, 0)])
    ok = sphere_ok(sol)
""",
)
case(
    "callable/speed returns integers",
    """
    sol = ts.solve(SPHERE, G3, [(0.5, 0, 0)], speed=lambda x: np.full(len(x), 2, dtype=np.int64))
    ok = sphere_ok(sol, 2.0)
""",
    expect="correct",
)
case(
    "callable/cp returns integers",
    """
    sol = ts.solve(ts.ClosestPoint(lambda x: np.round(x).astype(int)), G3, [(0.5, 0, 0)])
    ok = sane(sol)
""",
    expect="error",
)
case(
    "callable/speed returns bools",
    """
    sol = ts.solve(SPHERE, G3, [(0.5, 0, 0)], speed=lambda x: np.ones(len(x), bool))
    ok = sphere_ok(sol)
""",
)
for label, body in {
    "identity": "return x.copy()",
    "identity view": "return x",
    "shift by 0.3": f"return {SPHERE_CP} + 0.3",
    "shift by 10": f"return {SPHERE_CP} + 10.0",
    "far points": "return x + 5.0",
    "x + 0.001": "return x + 0.001",
    "one fixed point": "return np.tile([0.5, 0.0, 0.0], (len(x), 1))",
    "antipode": f"return -({SPHERE_CP})",
    "random points on the sphere": "r = np.random.default_rng(len(x)).standard_normal(x.shape); return 0.5 * r / np.linalg.norm(r, axis=1, keepdims=True)",
    "scaled 2x": f"return 2 * ({SPHERE_CP})",
    "zeros": "return np.zeros_like(x)",
    "nan everywhere": "return x * np.nan",
    "inf far": f"c = {SPHERE_CP}; c[np.linalg.norm(x, axis=1) > 0.9] = np.inf; return c",
    "nan far": f"c = {SPHERE_CP}; c[np.linalg.norm(x, axis=1) > 0.9] = np.nan; return c",
    "wrong shape": "return x[:, :2]",
    "transposed": "return x.T",
    "raises": "raise UserError('user error')",
    "returns None": "return None",
    "returns a list": f"return ({SPHERE_CP}).tolist()",
    "returns strings": "return x.astype(str)",
}.items():
    expect = {"nan far": "correct", "inf far": "correct", "returns a list": "correct", "raises": "error"}.get(
        label, "error"
    )
    case(
        f"callable/cp {label}",
        f"""
        def cp(x):
            {body}
        sol = ts.solve(ts.ClosestPoint(cp), G3, [(0.5, 0, 0)])
        ok = sphere_ok(sol)
    """,
        expect=expect,
    )
for label, body in {
    "identity": "return x",
    "nan far": f"v = {SPHERE_PHI}; v[np.linalg.norm(x, axis=1) > 0.9] = np.nan; return v",
    "inf far": f"v = {SPHERE_PHI}; v[np.linalg.norm(x, axis=1) > 0.9] = np.inf; return v",
    "nan near": f"v = {SPHERE_PHI}; v[np.abs(x[:, 0] - 0.5) < 0.1] = np.nan; return v",
    "nan everywhere": "return np.full(len(x), np.nan)",
    "constant": "return np.ones(len(x))",
    "scaled 100x": f"return 100 * ({SPHERE_PHI})",
    "scaled 0.01x": f"return 0.01 * ({SPHERE_PHI})",
    "wrong shape": "return np.ones((len(x), 2))",
    "scalar": "return 0.5",
    "complex": f"return ({SPHERE_PHI}) + 0j",
}.items():
    expect = {"nan far": "correct", "inf far": "correct"}.get(label, "error")
    case(
        f"callable/phi {label}",
        f"""
        def phi(x):
            {body}
        sol = ts.solve(phi, G3, [(0.5, 0, 0)])
        ok = sphere_ok(sol)
    """,
        expect=expect,
    )
case(
    "callable/phi array NaN far from the surface",
    """
    X, Y, Z = G3.meshgrid(); R = np.sqrt(X**2 + Y**2 + Z**2)
    phi = R - 0.5; phi[R > 0.9] = np.nan
    sol = ts.solve(phi, G3, [(0.5, 0, 0)])
    ok = close(sol.values, ts.solve(np.where(np.isnan(phi), 1.0, phi), G3, [(0.5, 0, 0)]).values, 0)
""",
    expect="correct",
)
case(
    "callable/phi array NaN next to the surface",
    """
    X, Y, Z = G3.meshgrid(); R = np.sqrt(X**2 + Y**2 + Z**2)
    phi = R - 0.5; phi[(R > 0.6) & (R < 0.7) & (X > 0)] = np.nan
    sol = ts.solve(phi, G3, [(0.5, 0, 0)])
    ok = sphere_ok(sol)
""",
    expect="error",
    message="next to the surface",
)
case(
    "callable/phi array inf far from the surface",
    """
    X, Y, Z = G3.meshgrid(); R = np.sqrt(X**2 + Y**2 + Z**2)
    phi = R - 0.5; phi[R > 0.9] = np.inf
    sol = ts.solve(phi, G3, [(0.5, 0, 0)])
    ok = sphere_ok(sol)
""",
    expect="correct",
)
for label, body in {
    "nan": "np.full(len(x), np.nan)",
    "zero": "np.zeros(len(x))",
    "negative": "-np.ones(len(x))",
    "inf": "np.full(len(x), np.inf)",
    "wrong shape": "np.ones((len(x), 2))",
    "scalar": "1.0",
    "nan far": "np.where(np.linalg.norm(x, axis=1) > 0.9, np.nan, 1.0)",
}.items():
    # (NaN far from the surface is never read: the speed is evaluated on the band)
    case(
        f"callable/speed {label}",
        f"""
        sol = ts.solve(SPHERE, G3, [(0.5, 0, 0)], speed=lambda x: {body})
        ok = sphere_ok(sol)
    """,
        expect="correct" if label == "nan far" else "error",
    )
for label, body in {
    "nan": "np.full(x.shape, np.nan)",
    "supersonic": "np.tile([0, 3.0, 0], (len(x), 1))",
    "wrong shape": "np.ones(len(x))",
    "integers": "np.zeros(x.shape, int)",
}.items():
    case(
        f"callable/flow {label}",
        f"""
        sol = ts.solve(SPHERE, G3, [(0.5, 0, 0)], flow=lambda x: {body})
        ok = close(sol.values, ts.solve(SPHERE, G3, [(0.5, 0, 0)], flow=lambda x: np.zeros(x.shape)).values, 0)
    """,
        expect="correct" if label == "integers" else "error",
    )
