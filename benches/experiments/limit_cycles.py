"""Limit cycles of the second-order sweeps (docs/second-order.md; ``second_order/stagnation.rs``):
the smoothed sphere mask (R = 0.5 in [−1, 1]³, ``LevelSet.from_mask(mask, grid, smooth=1.5)``)
solved by default from the band node nearest (−0.5, 0, 0) (as ``redistance_cost.py`` picks it),
and the six-fold star (2D, ``order=2``) as a surface whose second-order sweeps converge slowly
without cycling. Printed per solve: the iterations and local updates, the phase-2 iteration at which the sweeps fell
back to decreases only (None: they did not), and with ``--changes`` the largest change of each
iteration (a cycle repeats them to many digits). ``--perturb E`` solves the mask's φ multiplied by
1 + E·(standard normal noise, seed 0) as well, from the same source. Before the inner update's side
rule had its margin (``second_order/solver.rs``, ``UPWIND_MARGIN``) the mask cycled at N = 191 and
201 (period 1, changes of 5.5876847e-7; perturbed by 1e-12, of 6.0078673e-7) and the test ended
those solves at 38 and 40 iterations; now they converge in 29 and 30.

    .venv/bin/python benches/experiments/limit_cycles.py [N ...] [--star N] [--perturb E] [--changes]
    # default 191 201, star 801, no perturbation
"""

from __future__ import annotations

import sys
import warnings

import numpy as np

import tubesweep as ts
from tubesweep.mask import level_set_function_of_mask
from tubesweep.surfaces import Star


def _report(name: str, sol, changes, show: bool) -> None:
    print(
        f"{name}: {sol.stats.iterations} iterations, {sol.stats.updates:,} updates, "
        f"fallback at {sol.stats.order2['fallback_iteration']}",
        flush=True,
    )
    if show:
        print("  " + "; ".join(f"{it}: {ch!r}" for it, ch, _ in changes))


def main(ns, star_n: int, perturb: float, show: bool) -> None:
    for n in ns:
        grid = ts.Grid((-1.0,) * 3, (1.0,) * 3, (n,) * 3)
        X, Y, Z = grid.meshgrid()
        phi = level_set_function_of_mask(X**2 + Y**2 + Z**2 < 0.25, grid, 1.5)  # as LevelSet.from_mask
        ls = ts.LevelSet(phi, redistance=True)
        geom = ls.band(grid, 4 * grid.spacing)
        x = grid.node_points(geom.linear)
        src = tuple(x[np.argmin(np.abs(geom.signed) + 1e-3 * np.linalg.norm(x - [-0.5, 0.0, 0.0], axis=1))])
        cases = [("", ls)]
        if perturb:
            noise = np.random.default_rng(0).standard_normal(phi.shape)
            cases.append((f", φ·(1 + {perturb:g}·noise)", ts.LevelSet(phi * (1 + perturb * noise), redistance=True)))
        for label, surface in cases:
            changes: list = []
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                sol = ts.solve(surface, grid, [src], progress=lambda it, ch, up: changes.append((it, ch, up)))
            _report(f"smoothed sphere mask N={n}{label}", sol, changes, show)
    if star_n:
        star = Star()
        grid = ts.Grid((-1.0, -1.0), (1.0, 1.0), (star_n, star_n))
        changes = []
        sol = ts.solve(
            star, grid, [star.default_source], order=2, progress=lambda it, ch, up: changes.append((it, ch, up))
        )
        _report(f"six-fold star N={star_n}", sol, changes, show)


if __name__ == "__main__":
    args = sys.argv[1:]
    show = "--changes" in args
    args = [a for a in args if a != "--changes"]
    star_n, perturb = 801, 0.0
    if "--perturb" in args:
        i = args.index("--perturb")
        perturb = float(args[i + 1])
        args = args[:i] + args[i + 2 :]
    if "--star" in args:
        i = args.index("--star")
        star_n = int(args[i + 1])
        args = args[:i] + args[i + 2 :]
    main([int(a) for a in args] or [191, 201], star_n, perturb, show)
