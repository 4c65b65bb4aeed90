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

The cases live in ``benches/hostile/``, one module per group (``framework.py`` holds the prelude,
the runner and the registry; ``hostile/__init__.py`` lists the groups in the order they run).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from collections import Counter
from typing import Dict, List, Tuple

from hostile import load_cases
from hostile.framework import BAD, judge, run_case

CASES = load_cases()


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
