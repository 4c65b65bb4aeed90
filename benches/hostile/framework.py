"""The battery's machinery: the prelude and runner each case's subprocess executes, the case
registry (:func:`case` appends to :data:`CASES`), running one case and judging its outcome.

The outcome classes are described in ``benches/hostile_inputs.py``. A case's code runs after
:data:`PRELUDE` (``np``, ``ts``, the native module ``N``, the grids ``G2``/``G3``, ``SPHERE``,
``CIRCLE``, ``TMP`` and the helpers ``close``, ``ref_sphere``, ``sane``, ``sphere_ok``, ``write``,
``UserError``) and sets ``ok``; :data:`RUNNER` classifies what happened.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
import time
from typing import Dict, List, Optional

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

def sphere_ok(sol, speed=1.0, scale=1.0, rel=1e-2):
    # u at the antipode of (0.5, 0, 0): pi * 0.5 / speed, to the error of the default solve on the
    # grid G3 (31 nodes: 1.554 at order 2, 1.385 at order 1); a solve in other units or at another
    # speed gives the same digits
    if "u" not in _REF:
        _REF["u"] = float(ts.solve(SPHERE, G3, [(0.5, 0, 0)])([(-0.5, 0, 0)])[0])
    u = sol([(-scale * 0.5, 0, 0)])[0] * speed / scale
    # (rel = 1%: a closest-point or sampled sphere gives slightly other digits than the level set)
    return sane(sol) and abs(u - _REF["u"]) < rel * _REF["u"] and abs(u - np.pi * 0.5) < 0.2

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


#: snippets shared by the groups: the sphere of radius 0.5's φ and closest point, of ``x`` (M, 3)
SPHERE_PHI = "np.linalg.norm(x, axis=1) - 0.5"
SPHERE_CP = "0.5 * x / np.maximum(np.linalg.norm(x, axis=1, keepdims=True), 1e-300)"


def run_case(c: Case, tmp: str) -> Dict:
    """Runs the case in its own process (the prelude, its code, the runner) with its timeout; its outcome,
    message, warnings and seconds."""
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
