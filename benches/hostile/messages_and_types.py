"""Hostile inputs, groups 5 and 5b: misleading messages on valid input, 0-d arrays, and every numeric
argument given as a bool, a string, None, a list, a complex, a 0-d array or a NumPy scalar.
"""

from hostile.framework import SPHERE_CP, case

# ------------------------------------------------------------------------------------------------
# 5. messages on valid input
# ------------------------------------------------------------------------------------------------
for outer in ("3", "3.5", "4"):
    case(
        f"message/exact distance, outer={outer}",
        f"""
        g = ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3)
        X, Y, Z = g.meshgrid()
        sol = ts.solve(np.sqrt(X**2 + Y**2 + Z**2) - 0.5, g, [(0.5, 0, 0)], outer={outer})
        ok = sane(sol) and abs(sol([(-0.5, 0, 0)])[0] - np.pi * 0.5) < 0.25  # (N = 41: 1.41)
        bad = [str(w.message) for w in W if "not close to a distance" in str(w.message)]
        if bad:
            raise AssertionError("misleading: " + bad[0])
    """,
        expect="correct" if outer != "3" else "warning",
        message=None if outer != "3" else "too thin",
    )
for eps in ("1e-6", "1e-4", "1e-3", "1e-2", "3e-2"):
    case(
        f"message/closest-point noise {eps} spacings",
        f"""
        rng = np.random.default_rng(0)
        h = G3.spacing
        def cp(x):
            c = {SPHERE_CP}
            return c + {eps} * h * rng.standard_normal(c.shape)
        sol = ts.solve(ts.ClosestPoint(cp), G3, [(0.5, 0, 0)])
        # (order 2 differentiates the offsets twice: noise of 3e-2 spacings moves the antipode by
        # 1.1% of the noiseless 1.554, still a sixth of order 1's error; 2% allowed)
        ok = sphere_ok(sol, rel=2e-2) and sol.stats.facing_pairs == 0
    """,
        expect="correct",
    )
for what, code in {
    "phi 0-d array": "ts.solve(np.array(0.5), G3, [(0.5, 0, 0)])",
    "LevelSet 0-d": "ts.LevelSet(np.array(0.5))",
    "mesh 0-d": "ts.surfaces.from_mesh((np.array(0.0), np.array(0)))",
    "sources 0-d": "ts.solve(SPHERE, G3, np.array(0.5))",
    "points 0-d": "ts.solve(SPHERE, G3, [(0.5, 0, 0)])(np.array(0.5))",
    "speed 0-d array": "ts.solve(SPHERE, G3, [(0.5, 0, 0)], speed=np.array([[2.0]]))",
}.items():
    case(
        f"message/{what}",
        f"""
        {code}
        ok = True
    """,
        expect=None if what == "speed 0-d array" else "error",
        message=None if what == "speed 0-d array" else "()",
    )

# ------------------------------------------------------------------------------------------------
# 5b. types: bools, strings, None, 0-d arrays, complex, lists for every numeric argument
# ------------------------------------------------------------------------------------------------
args = {
    "tol": ("ts.solve(SPHERE, G3, [(0.5, 0, 0)], tol={})", "1e-8"),
    "max_iterations": ("ts.solve(SPHERE, G3, [(0.5, 0, 0)], max_iterations={})", "100"),
    "inner": ("ts.solve(SPHERE, G3, [(0.5, 0, 0)], inner={})", "2.0"),
    "outer": ("ts.solve(SPHERE, G3, [(0.5, 0, 0)], outer={})", "4.0"),
    "infinity": ("ts.solve(SPHERE, G3, [(0.5, 0, 0)], infinity={})", "100.0"),
    "threads": ("ts.solve(SPHERE, G3, [(0.5, 0, 0)], threads={})", "1"),
    "speed": ("ts.solve(SPHERE, G3, [(0.5, 0, 0)], speed={})", "1.0"),
    "tt speed": ("ts.travel_time(G2, [(0.1, 0.2)], speed={})", "1.0"),
    "tt tol": ("ts.travel_time(G2, [(0.1, 0.2)], tol={})", "1e-8"),
    "radius": ("ts.solve(ts.surfaces.Sphere({}), G3, [(0.5, 0, 0)])", "0.5"),
    "grid upper": ("ts.travel_time(ts.Grid((-1, -1), ({}, 1), (41, 41)), [(0.1, 0.2)])", "1.0"),
    "grid shape": ("ts.travel_time(ts.Grid((-1, -1), (1, 1), ({}, 41)), [(0.1, 0.2)])", "41"),
    "fill": ("ts.solve(CIRCLE, G2, [(0.5, 0)]).to_dense(fill={})", "0.0"),
}
values = {
    "True": "error",
    "False": "error",
    "np.True_": "error",
    "'2'": "error",
    "b'2'": "error",
    "None": None,
    "[2]": "error",
    "2+0j": "error",
    "np.array({g})": "correct",
    "np.float32({g})": "correct",
}
for arg, (template, good) in args.items():
    for value, expect in values.items():
        v = value.format(g=good)
        if value == "None" and arg in ("infinity", "tt tol"):  # (None: the default; travel_time's tol by its order)
            expect = "correct"
        elif value == "None":
            expect = "error"
        if value == "np.float32({g})" and arg in ("max_iterations", "threads", "grid shape"):
            v = f"np.int32({good})"
        case(
            f"types/{arg}={v}",
            f"""
            r = {template.format(v)}
            ok = True
        """,
            expect=expect,
        )
