"""The sweep variants side by side: the paper's pointwise sweeps, the outer rim swept last, the
coupled Godunov update, both, and both behind the front window (the default), on the Rust sphere
example.

The variants solve the same discrete equations; this measures what each costs. Runs are
interleaved (one run of every variant, then the next round), so that a drift in the machine's
speed affects all of them alike; the median and the minimum over the rounds are printed, with the
paper sweeps' median over each variant's median ("× paper" > 1: faster than the paper's sweeps).

    .venv/bin/python benches/experiments/sweep_variants.py [--sizes 201,401] [--threads 1,2] [--repeats 5]

It builds and runs ``cargo run --release --example sphere -- N godunov THREADS [coupled|pointwise]``
(``RIM_IN_EVERY_SWEEP=1`` sweeps the rim in every iteration; ``WINDOW=c`` sets
``SolveOptions::front_window``, 0 switches it off).
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
from pathlib import Path
from typing import Dict, List, Optional, Sequence, Tuple

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "target" / "release" / "examples" / "sphere"

#: name -> (coupled, rim swept last, front window; None: the example's default,
#: ``DEFAULT_FRONT_WINDOW``)
VARIANTS: Dict[str, Tuple[bool, bool, Optional[float]]] = {
    "paper": (False, False, 0.0),
    "rim last": (False, True, 0.0),
    "coupled": (True, False, 0.0),
    "both": (True, True, 0.0),
    "default": (True, True, None),
}

LINE = re.compile(r"iterations=(\d+) updates=(\d+) sweeps=([0-9.]+)s")


def run_once(n: int, threads: int, coupled: bool, rim_last: bool, window: Optional[float]) -> Tuple[int, int, float]:
    env = dict(os.environ)
    env.pop("RIM_IN_EVERY_SWEEP", None)
    env.pop("WINDOW", None)
    if window is not None:
        env["WINDOW"] = repr(window)
    if not rim_last:
        env["RIM_IN_EVERY_SWEEP"] = "1"
    cmd = [str(EXAMPLE), str(n), "godunov", str(threads), "coupled" if coupled else "pointwise"]
    out = subprocess.run(cmd, capture_output=True, text=True, env=env, check=True).stdout
    m = LINE.search(out)
    if m is None:
        raise RuntimeError(f"unexpected output of {' '.join(cmd)}: {out!r}")
    return int(m.group(1)), int(m.group(2)), float(m.group(3))


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="201,401")
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args(argv)
    subprocess.run(
        ["cargo", "build", "--release", "--example", "sphere", "-p", "tubesweep-core"],
        cwd=REPO,
        check=True,
        capture_output=True,
    )
    print(f"sphere r=0.5, Godunov, Rust example; {a.repeats} interleaved rounds; sweep seconds (median, min)")
    print(
        f"{'N':>5} {'threads':>7} {'variant':>9} {'iters':>5} {'updates':>13} {'median s':>9} {'min s':>8} {'× paper':>8}"
    )
    for n in (int(x) for x in a.sizes.split(",")):
        for t in (int(x) for x in a.threads.split(",")):
            times: Dict[str, List[float]] = {v: [] for v in VARIANTS}
            work: Dict[str, Tuple[int, int]] = {}
            for _ in range(a.repeats):
                for name, (coupled, rim_last, window) in VARIANTS.items():
                    it, up, sec = run_once(n, t, coupled, rim_last, window)
                    times[name].append(sec)
                    work[name] = (it, up)
            paper = statistics.median(times["paper"])
            for name in VARIANTS:
                med = statistics.median(times[name])
                it, up = work[name]
                print(
                    f"{n:5d} {t:7d} {name:>9} {it:5d} {up:13,d} {med:9.3f} {min(times[name]):8.3f} {paper / med:8.2f}",
                    flush=True,
                )
    return 0


if __name__ == "__main__":
    sys.exit(main())
