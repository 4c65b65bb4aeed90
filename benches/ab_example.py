"""Paired A/B timing of two builds of the Rust ``sphere`` example (two commits, or two settings).

Single timings on a shared 2-core machine move by 20–40% between runs, far more than most kernel
changes are worth. Two ways to pair the runs so that a drift of the machine hits both sides:

* ``--mode simultaneous`` (default; one thread each): A and B start together, each pinned to its
  own core with ``taskset``, swapping cores every round. A slow spell of the host then slows both.
  Run A against A as a control first: on this machine its paired ratios stayed within
  1.000–1.016 (quartiles, 30 rounds at N = 201), while sequential runs scatter by ±10%.
* ``--mode alternate``: A and B one after the other, in alternating order, with ``--threads``
  threads each (the way to compare multi-threaded runs).

Prints the medians and the median of the per-round ratios B/A (< 1: B faster) with its
quartiles, and in how many rounds B was faster; then each side's mean, 90th percentile and the
rounds above 1.3 times its median (the slow runs a median hides). Usage, with two builds of the example copied
aside (``cargo build --release -p tubesweep-core --example sphere`` at each commit)::

    .venv/bin/python benches/ab_example.py /tmp/sphere_a /tmp/sphere_b --n 201 --rounds 30
    .venv/bin/python benches/ab_example.py /tmp/sphere_a /tmp/sphere_a --n 201   # the control
    .venv/bin/python benches/ab_example.py A B --mode alternate --threads 2 --env-b WINDOW=3

The time taken is the example's ``sweeps=`` figure: the native solve, not the band's
construction. ``--env-a`` / ``--env-b`` set environment variables (``KEY=VALUE,...``) for one
side, e.g. the example's ``WINDOW``, ``SOURCE_AXIS`` or ``PLAIN``.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys
from typing import Dict, List


def parse_env(spec: str) -> Dict[str, str]:
    env = dict(os.environ)
    for kv in filter(None, spec.split(",")):
        key, _, value = kv.partition("=")
        env[key] = value
    return env


def sweep_seconds(out: str, binary: str) -> float:
    m = re.search(r"sweeps=([0-9.]+)s", out)
    if m is None:
        raise SystemExit(f"{binary} printed no 'sweeps=' figure; is it the sphere example?\n{out}")
    return float(m.group(1))


def command(binary: str, n: int, scheme: str, threads: int) -> List[str]:
    return [binary, str(n), scheme, str(threads)]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("a", help="the first build of the sphere example (the reference)")
    ap.add_argument("b", help="the second build")
    ap.add_argument("--n", type=int, default=201)
    ap.add_argument("--scheme", default="godunov", choices=["godunov", "lxf"])
    ap.add_argument("--rounds", type=int, default=30)
    ap.add_argument("--mode", default="simultaneous", choices=["simultaneous", "alternate"])
    ap.add_argument("--threads", type=int, default=1, help="threads per run (alternate mode only)")
    ap.add_argument("--env-a", default="", help="KEY=VALUE,... for A's runs")
    ap.add_argument("--env-b", default="", help="KEY=VALUE,... for B's runs")
    a = ap.parse_args()
    if a.mode == "simultaneous":
        if a.threads != 1:
            ap.error("--mode simultaneous runs one thread per side; use --mode alternate for more")
        if shutil.which("taskset") is None:
            ap.error("--mode simultaneous needs taskset (util-linux)")
        if (os.cpu_count() or 1) < 2:
            ap.error("--mode simultaneous needs two cores")
    env_a, env_b = parse_env(a.env_a), parse_env(a.env_b)
    ta: List[float] = []
    tb: List[float] = []
    for i in range(a.rounds):
        if a.mode == "simultaneous":
            core_a, core_b = (0, 1) if i % 2 == 0 else (1, 0)
            pa = subprocess.Popen(
                ["taskset", "-c", str(core_a)] + command(a.a, a.n, a.scheme, 1),
                env=env_a,
                stdout=subprocess.PIPE,
                text=True,
            )
            pb = subprocess.Popen(
                ["taskset", "-c", str(core_b)] + command(a.b, a.n, a.scheme, 1),
                env=env_b,
                stdout=subprocess.PIPE,
                text=True,
            )
            out_a, out_b = pa.communicate()[0], pb.communicate()[0]
            if pa.returncode or pb.returncode:
                raise SystemExit(f"a run failed (exit codes {pa.returncode}, {pb.returncode})")
        else:
            runs = {}
            for side in ("a", "b") if i % 2 == 0 else ("b", "a"):
                binary, env = (a.a, env_a) if side == "a" else (a.b, env_b)
                runs[side] = subprocess.run(
                    command(binary, a.n, a.scheme, a.threads), env=env, check=True, stdout=subprocess.PIPE, text=True
                ).stdout
            out_a, out_b = runs["a"], runs["b"]
        ta.append(sweep_seconds(out_a, a.a))
        tb.append(sweep_seconds(out_b, a.b))
    ratios = sorted(y / x for x, y in zip(ta, tb))
    q = len(ratios) // 4
    threads = 1 if a.mode == "simultaneous" else a.threads
    print(
        f"{a.scheme} N={a.n} {a.mode}, {threads} thread(s) each, {a.rounds} rounds: "
        f"A median {1e3 * statistics.median(ta):.1f} ms, B median {1e3 * statistics.median(tb):.1f} ms"
    )
    print(
        f"  B/A per round: median {statistics.median(ratios):.3f} (quartiles {ratios[q]:.3f}–{ratios[-1 - q]:.3f}), "
        f"B faster in {sum(r < 1 for r in ratios)} of {a.rounds}"
    )

    def tail(t: List[float]) -> str:
        s = sorted(t)
        slow = sum(x > 1.3 * statistics.median(s) for x in s)
        return (
            f"mean {1e3 * statistics.mean(s):.1f} ms, 90th percentile {1e3 * s[int(0.9 * len(s))]:.1f} ms, "
            f"{slow} of {len(s)} above 1.3 × its median"
        )

    # the slow runs a median hides (threads that start on one core, a slow spell)
    print(f"  A: {tail(ta)}")
    print(f"  B: {tail(tb)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
