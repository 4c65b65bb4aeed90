"""A battery of hostile and edge-case inputs, each run in its own process with a timeout, counted
per outcome class (issue 35).

Usage::

    .venv/bin/python benches/hostile_inputs.py              # every case (about 5 minutes on 2 cores)
    .venv/bin/python benches/hostile_inputs.py --only mesh  # the cases whose name contains "mesh"
    .venv/bin/python benches/hostile_inputs.py --list       # the cases' names
    .venv/bin/python benches/hostile_inputs.py --verbose    # one line per case, with its message

Each case is a snippet that calls the public API (or the private native module) and, when the
call returns, sets ``ok`` to whether the answer is right (against an exact value, a reference
solve or an invariant). Its outcome is one of

* ``error``   — a clean exception (ValueError, TypeError, MemoryError, FloatingPointError,
  FileNotFoundError, ImportError naming the extra …) with a message;
* ``warning`` — it returned and warned (a RuntimeWarning or UserWarning said what is off);
* ``correct`` — it returned the right answer without a warning;

and the classes that must stay at zero:

* ``wrong``   — it returned a wrong answer (``ok`` False) without a warning;
* ``unclean`` — any other exception (IndexError, AttributeError, OverflowError, a Rust panic …);
* ``crash``   — the process died (a signal, an abort);
* ``hang``    — it did not finish within the timeout.

Some cases also name the outcome they must have (``expect``): a case whose outcome differs is
listed as ``unexpected`` (e.g. a valid input refused, or a misleading message). The script exits
with status 1 when a bad class or an unexpected outcome occurs.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import textwrap
import time
from collections import Counter
from typing import Dict, List, Optional, Tuple

BAD = ("wrong", "unclean", "crash", "hang")

PRELUDE = """
import json, sys, warnings, os
import numpy as np
import tubesweep as ts
import tubesweep._native as N
G2 = ts.Grid((-1, -1), (1, 1), (41, 41))
G3 = ts.Grid((-1,) * 3, (1,) * 3, (31,) * 3)
SPHERE = ts.surfaces.Sphere(0.5)
CIRCLE = ts.surfaces.Circle(0.5)
TMP = os.environ["HOSTILE_TMP"]

def close(a, b, tol):
    a, b = np.asarray(a, float), np.asarray(b, float)
    return a.shape == b.shape and bool(np.all(np.abs(a - b) <= tol))

def ref_sphere(**kw):
    return ts.solve(SPHERE, G3, [(0.5, 0, 0)], **kw)

def sane(sol, diameter=None):
    # the invariants of a converged surface solve: u >= 0, u = 0 at a source's node, finite on the
    # inner tube (one component), bounded by the surface's geodesic diameter (times the slowness)
    v = sol.values
    inner = sol.roles != 2
    good = bool(np.all(v[np.isfinite(v)] >= 0) and np.all(np.isfinite(v[inner])) and sol.stats.converged)
    if diameter is not None:
        good = good and float(np.max(v[inner])) <= diameter
    return good

_REF = {}

def sphere_ok(sol, speed=1.0, scale=1.0):
    # u at the antipode of (0.5, 0, 0): pi * 0.5 / speed, to the first-order error of the grid
    # G3 (31 nodes: 1.385); a solve in other units or at another speed gives the same digits
    if "u" not in _REF:
        _REF["u"] = float(ts.solve(SPHERE, G3, [(0.5, 0, 0)])([(-0.5, 0, 0)])[0])
    u = sol([(-scale * 0.5, 0, 0)])[0] * speed / scale
    # (1%: a closest-point or sampled sphere gives slightly other digits than the level set)
    return sane(sol) and abs(u - _REF["u"]) < 1e-2 * _REF["u"] and abs(u - np.pi * 0.5) < 0.2

class UserError(Exception):
    '''Raised by a case's own callable: passing it on unchanged is the right outcome.'''

def write(name, text, mode="w"):
    p = os.path.join(TMP, name)
    with open(p, mode) as fh:
        fh.write(text)
    return p
"""

RUNNER = """
CLEAN = (ValueError, TypeError, MemoryError, FloatingPointError, FileNotFoundError, IsADirectoryError, ImportError,
         KeyError, UserError)
if NATIVE:  # PyO3's conversion of a negative int to an unsigned argument
    CLEAN = CLEAN + (OverflowError,)
out = {"outcome": None, "message": "", "warnings": []}
ns = dict(globals())
with warnings.catch_warnings(record=True) as W:
    warnings.simplefilter("always")
    ns["W"] = W
    try:
        exec(compile(CODE, "<case>", "exec"), ns)
        ok = ns.get("ok", None)
        out["outcome"] = "unchecked" if ok is None else "correct" if ok else "wrong"
    except CLEAN as e:
        out["outcome"] = "error" if str(e) else "unclean"
        out["message"] = f"{type(e).__name__}: {e}"
    except BaseException as e:  # a Rust panic is a BaseException (PanicException)
        out["outcome"] = "unclean"
        out["message"] = f"{type(e).__name__}: {e}"
    out["warnings"] = [str(w.message)[:300] for w in W if issubclass(w.category, (RuntimeWarning, UserWarning))]
    if out["outcome"] in ("correct", "wrong") and out["warnings"]:
        out["outcome"] = "warning"  # it returned and said what is off
sys.stdout.write("\\n@@RESULT@@" + json.dumps(out) + "\\n")
"""


class Case:
    def __init__(
        self, name: str, code: str, expect: Optional[str] = None, timeout: float = 60.0, message: Optional[str] = None
    ):
        self.name, self.code, self.expect, self.timeout, self.message = (
            name,
            textwrap.dedent(code),
            expect,
            timeout,
            message,
        )


CASES: List[Case] = []


def case(
    name: str, code: str, expect: Optional[str] = None, timeout: float = 60.0, message: Optional[str] = None
) -> None:
    """``expect``: "error", "warning", "correct", or "returns" (correct or warning); ``message``: a
    substring the error or a warning must contain (the right diagnosis)."""
    CASES.append(Case(name, code, expect, timeout, message))


# ------------------------------------------------------------------------------------------------
# 1. sizes
# ------------------------------------------------------------------------------------------------
for shape in [
    "(2**21, 2**21, 2**21)",
    "(2**21 + 1,) * 3",
    "(2**21 - 1,) * 3",
    "(2**31, 2**31, 3)",
    "(2**32, 3, 3)",
    "(2**40, 2**40)",
    "(2**62, 3)",
    "(2**63, 3)",
    "(2**64, 3)",
    "(2**64 + 5, 2**64 + 5)",
    "(10**30, 10**30)",
    "(100000, 100000)",
    "(5000, 5000, 5000)",
    "(1024, 1024, 1024)",
]:
    if shape == "(5000, 5000, 5000)":  # the solve is valid and large (a band of about 1.6e8 nodes)
        continue
    case(
        f"size/travel_time {shape}",
        f"""
        g = ts.Grid((0,) * len({shape}), (1,) * len({shape}), {shape})
        u = ts.travel_time(g, [(0.5,) * g.ndim])
        ok = u.shape == g.shape
    """,
        expect="error",
    )
    case(
        f"size/solve {shape}",
        f"""
        s = {shape}
        g = ts.Grid((-1,) * len(s), (1,) * len(s), s)
        surf = SPHERE if len(s) == 3 else CIRCLE
        sol = ts.solve(surf, g, [(0.5,) + (0,) * (len(s) - 1)])
        ok = sane(sol)
    """,
        expect=None,
        timeout=120,
    )
for shape in ["(0, 5)", "(1, 5)", "(2, 5)", "(-3, 5)", "(3, 3)", "(3, 3, 3)", "(5,)", "(3, 3, 3, 3)", "()"]:
    case(
        f"size/grid {shape}",
        f"""
        g = ts.Grid((0,) * max(1, len({shape})), (1,) * max(1, len({shape})), {shape})
        u = ts.travel_time(g, [(0.5,) * g.ndim])
        ok = u.shape == g.shape and np.all(np.isfinite(u))
    """,
    )
case(
    "size/grid size is a python int",
    """
    g = ts.Grid((0,) * 3, (1,) * 3, (2**21 - 1,) * 3)
    ok = g.size == (2**21 - 1) ** 3 and g.size > 0
""",
    expect="correct",
)
case(
    "size/to_dense of a huge grid",
    """
    g = ts.Grid((-1,) * 3, (1,) * 3, (4001,) * 3)  # 6.4e10 nodes, a band of about 4e4
    sol = ts.solve(ts.surfaces.Sphere(0.01), g, [(0.01, 0, 0)])
    d = sol.to_dense()
    ok = d.shape == g.shape
""",
    expect="error",
    timeout=240,
)
case(
    "size/cli travel-time huge n",
    """
    from tubesweep.cli import main
    try:
        rc = main(["travel-time", "--n", "3000000", "--dim", "3", "--out", TMP, "--quiet"])
    except SystemExit as e:
        rc = e.code
    ok = rc != 0
    if ok:
        raise ValueError("refused with exit status %s" % rc)
""",
    expect="error",
)
case(
    "size/cli solve huge n",
    """
    from tubesweep.cli import main
    try:
        rc = main(["solve", "--surface", "sphere", "--n", "3000000", "--out", TMP, "--quiet"])
    except SystemExit as e:
        rc = e.code
    ok = rc != 0
    if ok:
        raise ValueError("refused with exit status %s" % rc)
""",
    expect="error",
)
# (not a box the core accepts and the machine cannot hold: under Linux's overcommit the allocation
# succeeds and the process is killed when it touches the pages; the public API's memory guard
# refuses those before they reach the core)
for shape in [
    "[2**40, 2**40]",
    "[2**63, 2**63, 3]",
    "[2**21] * 3",
    "[100000, 100000]",
    "[70000, 70000]",
    "[2**32, 2]",
    "[0, 5]",
    "[5]",
    "[5, 5, 5, 5]",
]:
    case(
        f"size/native full_box {shape}",
        f"""
        b = N.Band.full_box({shape})
        ok = len(b) > 0
    """,
        expect="error",
    )
    case(
        f"size/native from_linear {shape}",
        f"""
        b = N.Band.from_linear({shape}, np.array([0, 1, 2], np.uint64))
        ok = len(b) == 3
    """,
    )
case(
    "size/native split_pair_blocks huge shape",
    """
    lin = N.split_pair_blocks([2**40, 2**40, 2**40], np.zeros((1, 3), np.int64))
    ok = len(lin) == 8
""",
)
case(
    "size/native node_points overflow",
    """
    p = N.node_points([2**40, 2**40], np.array([2**64 - 1], np.uint64), [0.0, 0.0], 1.0)
    ok = False
""",
    expect="error",
)

# ------------------------------------------------------------------------------------------------
# 2. numeric range
# ------------------------------------------------------------------------------------------------
for inf in [
    "1e308",
    "1e200",
    "1e155",
    "1e150",
    "1e101",
    "1e100",
    "1e20",
    "10.0",
    "2.0",
    "1.2",
    "0.5",
    "0.01",
    "1e-300",
    "float('inf')",
    "float('nan')",
    "-1.0",
    "0.0",
]:
    for ham in ("godunov", "lxf"):
        case(
            f"range/solve infinity={inf} {ham}",
            f"""
            sol = ts.solve(SPHERE, G3, [(0.5, 0, 0)], hamiltonian="{ham}", infinity={inf})
            ref = ts.solve(SPHERE, G3, [(0.5, 0, 0)], hamiltonian="{ham}")
            ok = sane(sol) and close(sol.values, ref.values, 1e-8)
        """,
        )
    case(
        f"range/travel_time infinity={inf}",
        f"""
        u = ts.travel_time(G2, [(0.1, 0.2)], hamiltonian="lxf", infinity={inf})
        ref = ts.travel_time(G2, [(0.1, 0.2)], hamiltonian="lxf")
        ok = close(u, ref, 1e-8)
    """,
    )
    case(
        f"range/tube infinity={inf}",
        f"""
        tube = ts.Tube(SPHERE, G3)
        sol = tube.solve([(0.5, 0, 0)], infinity={inf})
        ok = sane(sol) and close(sol.values, ref_sphere().values, 1e-8)
    """,
    )
for speed in ["1e300", "1e200", "1e101", "1e90", "1e50", "1e-50", "1e-90", "1e-101", "1e-200", "1e-300", "5e-324"]:
    case(
        f"range/solve speed={speed}",
        f"""
        sol = ts.solve(SPHERE, G3, [(0.5, 0, 0)], speed={speed}, tol=1e-10 / {speed})
        ok = sphere_ok(sol, {speed})
    """,
    )
    case(
        f"range/travel_time speed={speed}",
        f"""
        u = ts.travel_time(G2, [(0.0, 0.0)], speed={speed}, tol=1e-10 / {speed})
        ref = ts.travel_time(G2, [(0.0, 0.0)])
        ok = close(u * {speed}, ref, 1e-6 * ref.max()) and abs(u[0, 0] * {speed} - np.sqrt(2)) < 0.05
    """,
    )
for scale in ["1e-120", "1e-99", "1e-60", "1e-20", "1e20", "1e60", "1e99", "1e120", "1e200", "1e305"]:
    case(
        f"range/grid scale {scale}",
        f"""
        L = {scale}
        g = ts.Grid((-L,) * 3, (L,) * 3, (31,) * 3)
        sol = ts.solve(ts.surfaces.Sphere(0.5 * L), g, [(0.5 * L, 0, 0)], tol=1e-10 * L)
        ok = sphere_ok(sol, 1.0, L)
    """,
    )
for offset, span in [
    ("1e9", "1e-6"),
    ("1e6", "1e-6"),
    ("1e12", "1.0"),
    ("1e15", "10.0"),
    ("1e3", "1e-9"),
    ("1e8", "1.0"),
]:
    case(
        f"range/spacing vs coordinates offset={offset} span={span}",
        f"""
        o, s = {offset}, {span}
        g = ts.Grid((o - s, o - s), (o + s, o + s), (41, 41))
        u = ts.travel_time(g, [(o, o)], tol=1e-12 * s)
        ref = ts.travel_time(G2, [(0.0, 0.0)])
        ok = close(u / s, ref, 1e-6)
    """,
    )
case(
    "range/infinite spacing",
    """
    g = ts.Grid((-1e308, -1e308), (1e308, 1e308), (41, 41))
    ok = np.isfinite(g.spacing)
""",
    expect="error",
)
case(
    "range/speed array with a huge range",
    """
    sp = np.ones(G2.shape); sp[:5] = 1e200
    u = ts.travel_time(G2, [(0.0, 0.0)], speed=sp)
    ok = np.all(np.isfinite(u)) and abs(u[20, 40] - 1.0) < 0.02
""",
)
case(
    "range/tol subnormal",
    """
    sol = ts.solve(SPHERE, G3, [(0.5, 0, 0)], tol=5e-324, max_iterations=200)
    ok = sane(sol) and close(sol.values, ref_sphere().values, 1e-9)
""",
)
case(
    "range/max_iterations 1",
    """
    sol = ts.solve(SPHERE, G3, [(0.5, 0, 0)], max_iterations=1)
    ok = sphere_ok(sol)
""",
    expect="warning",
)

# ------------------------------------------------------------------------------------------------
# 3. callables
# ------------------------------------------------------------------------------------------------
SPHERE_PHI = "np.linalg.norm(x, axis=1) - 0.5"
SPHERE_CP = "0.5 * x / np.maximum(np.linalg.norm(x, axis=1, keepdims=True), 1e-300)"
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

# ------------------------------------------------------------------------------------------------
# 4. mesh files
# ------------------------------------------------------------------------------------------------
TETRA_V = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
TETRA_F = "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
mesh_files: Dict[str, Tuple[str, str, Optional[str], Optional[str]]] = {
    # name: (file name, text, expect, message)
    "obj plain": ("a.obj", TETRA_V + TETRA_F, "correct", None),
    "obj indented": ("a.obj", "  " + TETRA_V.replace("\n", "\n  ") + TETRA_F.replace("\n", "\n\t"), "correct", None),
    "obj tabs and spaces": ("a.obj", TETRA_V.replace(" ", "\t  ") + TETRA_F.replace(" ", " \t "), "correct", None),
    "obj comments after values": (
        "a.obj",
        TETRA_V.replace("\n", " # c\n") + "# a comment\n" + TETRA_F,
        "correct",
        None,
    ),
    "obj crlf": ("a.obj", (TETRA_V + TETRA_F).replace("\n", "\r\n"), "correct", None),
    "obj line continuation": ("a.obj", TETRA_V + "f 1 3 \\\n 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n", "correct", None),
    "obj slashes": (
        "a.obj",
        TETRA_V + "vt 0 0\nvn 0 0 1\nf 1/1/1 3/1/1 2/1/1\nf 1//1 2//1 4//1\nf 1/1 4/1 3/1\nf 2 3 4\n",
        "correct",
        None,
    ),
    "obj negative indices": ("a.obj", TETRA_V + "f -4 -2 -3\nf -4 -3 -1\nf -4 -1 -2\nf -3 -2 -1\n", "correct", None),
    "obj quads": (
        "a.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
        "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n",
        "correct",
        None,
    ),
    "obj two-vertex face": ("a.obj", TETRA_V + TETRA_F + "f 1 2\n", "warning", "fewer than three"),
    "obj lines and points": ("a.obj", TETRA_V + TETRA_F + "l 1 2\np 3\n", "warning", "line and point"),
    "obj vertex with 2 coords": ("a.obj", "v 0 0\n" + TETRA_V + TETRA_F, "error", "three coordinates"),
    "obj vertex not a number": ("a.obj", "v 0 zero 0\n" + TETRA_V + TETRA_F, "error", "not a number"),
    "obj index 0": ("a.obj", TETRA_V + "f 0 1 2\n", "error", "start at 1"),
    "obj index out of range": ("a.obj", TETRA_V + "f 1 2 9\n", "error", "does not exist"),
    "obj nan vertex": ("a.obj", TETRA_V.replace("v 0 0 1", "v nan 0 1") + TETRA_F, "error", "NaN"),
    "obj huge vertex": ("a.obj", TETRA_V.replace("v 0 0 1", "v 0 0 1e300") + TETRA_F, "error", "1e+30"),
    "obj duplicate triangles": ("a.obj", TETRA_V + TETRA_F + "f 1 3 2\nf 2 3 4\n", "warning", "more than once"),
    "obj degenerate triangle": ("a.obj", TETRA_V + TETRA_F + "f 1 1 2\n", "correct", None),
    "obj all degenerate": ("a.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", "error", "degenerate"),
    "obj empty": ("a.obj", "", "error", None),
    "obj comments only": ("a.obj", "# nothing\n# here\n", "error", None),
    "obj point cloud": ("a.obj", TETRA_V, "error", "no faces"),
    "obj not a mesh": ("a.obj", "hello world\nthis is not a mesh\n", "error", None),
    "off plain": (
        "a.off",
        "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
        "correct",
        None,
    ),
    "off comments and blank lines": (
        "a.off",
        "OFF\n# c\n\n4 4 0\n0 0 0 # v\n1 0 0\n\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
        "correct",
        None,
    ),
    "off counts on the OFF line": (
        "a.off",
        "OFF 4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
        "correct",
        None,
    ),
    "off colours after faces": (
        "a.off",
        "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1 255 0 0\n3 0 1 3 1 1 1\n3 0 3 2 0 0 0\n3 1 2 3 9 9 9\n",
        "correct",
        None,
    ),
    "off quad": ("a.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n", "correct", None),
    "off truncated": ("a.off", "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n", "error", "declares"),
    "off bad count": ("a.off", "OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2\n", "error", "declares"),
    "off not a mesh": ("a.off", "hello\n", "error", None),
    "ply ascii": (
        "a.ply",
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 4\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
        "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
        "correct",
        None,
    ),
    "ply quad": (
        "a.ply",
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n",
        "correct",
        None,
    ),
    "ply not a mesh": ("a.ply", "hello\n", "error", None),
    "ply vertices only": (
        "a.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n",
        "error",
        None,
    ),
    "stl ascii": (
        "a.stl",
        "solid x\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\n"
        "endfacet\nendsolid x\n",
        "correct",
        None,
    ),
    "stl not a mesh": ("a.stl", "hello\n", "error", None),
}
for label, (fname, text, expect, message) in mesh_files.items():
    case(
        f"mesh/{label}",
        f"""
        p = write({fname!r}, {text!r})
        m = ts.surfaces.from_mesh(p)
        v, f = m.vertices, m.faces
        # the tetrahedron's, the cube's or one quad's faces, all read (degenerate ones kept apart)
        ok = len(m._good) in (4, 12, 2, 1) and len(v) in (3, 4, 8) and np.all(np.isfinite(v))
    """,
        expect=expect,
        message=message,
    )
for fname in ["a.obj", "a.off", "a.ply", "a.stl"]:
    case(
        f"mesh/random bytes {fname}",
        f"""
        p = write({fname!r}, np.random.default_rng(1).bytes(400), "wb")
        m = ts.surfaces.from_mesh(p)
        ok = False
    """,
        expect="error",
    )
case("mesh/a directory", "m = ts.surfaces.from_mesh(TMP); ok = False", expect="error")
case("mesh/missing file", "m = ts.surfaces.from_mesh(TMP + '/nope.obj'); ok = False", expect="error")
case(
    "mesh/solve on a read tetrahedron",
    f"""
    p = write("t.obj", {TETRA_V + TETRA_F!r})
    m = ts.surfaces.from_mesh(p, normalize=True)
    sol = ts.solve(m, m.grid(41), [m.vertices[0]])
    ok = sane(sol, 3.0)
""",
    expect="returns",
)

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
        ok = sphere_ok(sol) and sol.stats.facing_pairs == 0
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

# ------------------------------------------------------------------------------------------------
# 7. the private native module: garbage in, a clean exception out (no panic)
# ------------------------------------------------------------------------------------------------
native_calls = [
    "N.Band.full_box([-1, 5])",
    "N.Band.full_box([])",
    "N.Band.full_box(None)",
    "N.Band.full_box(['a', 'b'])",
    "N.Band.from_linear([5, 5], np.array([3, 1], np.uint64))",
    "N.Band.from_linear([5, 5], np.array([0, 100], np.uint64))",
    "N.Band.from_linear([5, 5], np.zeros((2, 2), np.uint64))",
    "N.Band.from_linear([5, 5], np.array([0.5]))",
    "N.node_points([5, 5], np.array([0], np.uint64), [0.0], 1.0)",
    "N.node_points([5, 5], np.array([99], np.uint64), [0.0, 0.0], 1.0)",
    "N.node_points([5, 5], np.array([0], np.uint64), [0.0, 0.0], float('nan'))",
    "N.split_pair_blocks([5, 5, 5], -np.ones((1, 3), np.int64))",
    "N.split_pair_blocks([5, 5, 5], np.zeros((1, 2), np.int64))",
    "N.block_children([5, 5, 5], np.zeros((1, 3), np.int64), 0, [0.0] * 3, 1.0)",
    "N.block_children([5, 5, 5], np.zeros((1, 3), np.int64), 2**62, [0.0] * 3, 1.0)",
    "N.children_radius_max([5, 5, 5], np.zeros((1, 3), np.int64), 0)",
    "N.neighbour_table([5, 5], np.array([0, 1], np.uint64), 0, 100)",
    "N.neighbour_table([5, 5], np.array([0, 1], np.uint64), 2, 1)",
    "N.band_of_samples(np.zeros((5, 5)), float('nan'))",
    "N.band_of_samples(np.zeros(5), 1.0)",
    "N.band_of_samples(np.zeros((2, 2)), 1.0)",
    "N.band_of_samples(np.zeros((5, 5, 5, 5)), 1.0)",
    "N.keep_within(np.arange(10, dtype=np.uint64), np.zeros(10), 1.0, np.zeros(2, np.uint64), np.zeros(2))",
    "N.keep_within(np.arange(10, dtype=np.uint64), np.zeros(3), 1.0, np.zeros(10, np.uint64), np.zeros(10))",
    "N.TriangleTree(np.zeros((3, 3)), np.array([[0, 1, 5]]))",
    "N.TriangleTree(np.zeros((0, 3)), np.zeros((0, 3), np.int64))",
    "N.TriangleTree(np.zeros((3, 2)), np.array([[0, 1, 2]]))",
    "N.TriangleTree(np.zeros((3, 3)), np.array([[0, 1, -1]]))",
    "N.TriangleTree(np.eye(3), np.array([[0, 1, 2]])).closest(np.zeros((2, 2)), 1.0)",
    "N.TriangleTree(np.eye(3), np.array([[0, 1, 2]])).closest(np.full((2, 3), np.nan), 1.0)",
    "N.TriangleTree(np.eye(3), np.array([[0, 1, 2]])).any_within(np.zeros((2, 3)), np.zeros(5))",
    "N.analytic_level_set_band('blob', [0.5], [5] * 3, [-1.0] * 3, 0.5, 1.0, 1.5)",
    "N.analytic_level_set_band('sphere', [], [5] * 3, [-1.0] * 3, 0.5, 1.0, 1.5)",
    "N.analytic_level_set_band('sphere', [0, 0, 0, 0.5], [5] * 3, [-1.0] * 3, 0.0, 1.0, 1.5)",
    "N.analytic_level_set_band('sphere', [0, 0, 0, 0.5], [5] * 3, [-1.0] * 3, 0.5, float('nan'), 1.5)",
    "N.sphere_signed_distance(np.zeros((2, 2)), [0.0] * 3, 0.5)",
    "N.sphere_signed_distance(np.zeros((2, 3)), [0.0], 0.5)",
    "N.first_non_finite(np.zeros(0))",
    "N.project_to_sampled_level_set(np.zeros((5, 5)), [0.0, 0.0], 0.1, np.zeros((2, 2)))",
    "N.Band.full_box([5, 5]).solve(np.ones(3, np.uint8), np.zeros(1, np.int64), np.zeros(1), 0.1, 1.0, None, 'godunov', 'extrapolate', 1e-10, 100, None, None, 1, True, 1e-12)",
    "N.Band.full_box([5, 5]).solve(np.full(25, 7, np.uint8), np.zeros(1, np.int64), np.zeros(1), 0.1, 1.0, None, 'godunov', 'extrapolate', 1e-10, 100, None, None, 1, True, 1e-12)",
    "N.Band.full_box([5, 5]).solve(np.ones(25, np.uint8), np.array([99], np.int64), np.zeros(1), 0.1, 1.0, None, 'godunov', 'extrapolate', 1e-10, 100, None, None, 1, True, 1e-12)",
    "N.Band.full_box([5, 5]).solve(np.ones(25, np.uint8), np.zeros(1, np.int64), np.zeros(1), -0.1, 1.0, None, 'godunov', 'extrapolate', 1e-10, 100, None, None, 1, True, 1e-12)",
    "N.Band.full_box([5, 5]).solve(np.ones(25, np.uint8), np.zeros(1, np.int64), np.zeros(1), 0.1, np.ones(3), None, 'godunov', 'extrapolate', 1e-10, 100, None, None, 1, True, 1e-12)",
    "N.Band.full_box([5, 5]).solve(np.ones(25, np.uint8), np.zeros(1, np.int64), np.zeros(1), 0.1, 1.0, None, 'nope', 'extrapolate', 1e-10, 100, None, None, 1, True, 1e-12)",
    "N.Band.full_box([5, 5]).solve(np.ones(25, np.uint8), np.zeros(1, np.int64), np.zeros(1), 0.1, 1.0, None, 'godunov', 'extrapolate', 1e-10, 100, float('nan'), None, 1, True, 1e-12)",
    "N.Band.full_box([5, 5]).solve(np.ones(25, np.uint8), np.zeros(1, np.int64), np.zeros(1), 0.1, 1.0, None, 'godunov', 'extrapolate', 1e-10, 100, None, 'notcallable', 1, True, 1e-12)",
    "N.Band.full_box([5, 5]).interpolate(np.zeros(3), [0.0, 0.0], 0.1, np.zeros((2, 2)))",
    "N.Band.full_box([5, 5]).find(np.zeros((2, 3), np.int64))",
    "N.Band.full_box([5, 5]).find(np.full((2, 2), -5, np.int64))",
    "N.Band.full_box([5, 5]).rim_nodes(3, 1)",
    "N.Band.full_box([5, 5]).nodes_missing_neighbours(np.zeros(3, bool))",
    "N.Band.full_box([5, 5]).nearest_source_labels(np.zeros(25), np.array([99], np.int64), np.array([0], np.int64))",
]
for call in native_calls:
    case(
        f"native/{call[:90]}",
        f"""
        r = {call}
        ok = True
    """,
        expect=None,
    )


# ------------------------------------------------------------------------------------------------
def run_case(c: Case, tmp: str) -> Dict:
    src = PRELUDE + f"\nCODE = {c.code!r}\nNATIVE = {c.name.startswith('native/')}\n" + RUNNER
    env = dict(os.environ, HOSTILE_TMP=tmp, OPENBLAS_NUM_THREADS="1", RUST_BACKTRACE="0")
    t = time.perf_counter()
    try:
        r = subprocess.run([sys.executable, "-c", src], capture_output=True, text=True, timeout=c.timeout, env=env)
    except subprocess.TimeoutExpired:
        return {"outcome": "hang", "message": f"no answer within {c.timeout:g} s", "seconds": c.timeout, "warnings": []}
    seconds = time.perf_counter() - t
    marker = "@@RESULT@@"
    if marker not in r.stdout:
        tail = (r.stderr.strip().splitlines() or [""])[-1]
        return {
            "outcome": "crash",
            "message": f"exit status {r.returncode}: {tail[:200]}",
            "seconds": seconds,
            "warnings": [],
        }
    out = json.loads(r.stdout.split(marker, 1)[1].strip().splitlines()[0])
    out["seconds"] = seconds
    return out


def judge(c: Case, out: Dict) -> Optional[str]:
    """Why the outcome does not match what the case expects (None when it does)."""
    o = out["outcome"]
    if c.expect == "returns" and o in ("correct", "warning"):
        pass
    elif c.expect is not None and o != c.expect:
        return f"expected {c.expect}"
    if c.message is not None:
        text = out["message"] + " ".join(out["warnings"])
        if c.message not in text:
            return f"the message lacks {c.message!r}"
    return None


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", default="", help="run the cases whose name contains this")
    ap.add_argument("--list", action="store_true")
    ap.add_argument("--verbose", action="store_true")
    args = ap.parse_args()
    cases = [c for c in CASES if args.only in c.name]
    if args.list:
        for c in cases:
            print(c.name)
        return 0
    counts: Counter = Counter()
    unexpected: List[Tuple[str, str, Dict]] = []
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        for i, c in enumerate(cases):
            out = run_case(c, tmp)
            counts[out["outcome"]] += 1
            why = judge(c, out)
            if why is not None or out["outcome"] in BAD:
                unexpected.append((c.name, why or out["outcome"], out))
            if args.verbose:
                msg = out["message"] or ("; ".join(out["warnings"]))
                print(
                    f"[{i + 1:3}/{len(cases)}] {out['outcome']:8} {out['seconds']:5.1f}s {c.name}"
                    f"{'  <-- ' + why if why else ''}\n           {msg[:240]}",
                    flush=True,
                )
    print(f"\n{len(cases)} cases in {time.perf_counter() - t0:.0f} s, each in its own process")
    for k in ("error", "warning", "correct", "unchecked") + BAD:
        print(f"  {k:9} {counts.get(k, 0):4}")
    if unexpected:
        print(f"\n{len(unexpected)} cases with an unexpected outcome:")
        for name, why, out in unexpected:
            print(f"  {name}: {out['outcome']} ({why}) {(out['message'] or '; '.join(out['warnings']))[:300]}")
    return 1 if unexpected or any(counts.get(k) for k in BAD) else 0


if __name__ == "__main__":
    sys.exit(main())
