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

``--cylinder N``: a closed cylinder (radius 0.5, height 0.8, its exact signed distance) with its
caps on grid planes (N odd, (N − 1)/2 a multiple of 5), the source at the centre of the top cap,
and the same cylinder moved up by 0.3 spacings. Before the BDF2 ramp closed at a kink through the
node (``second_order/local.rs``, ``KINK2``), whether these cycled depended on how the flat caps
and the rims lie against the grid: at N = 61 the caps on the planes cycled (33 iterations, the
fallback at 31, changes of 0.07Δx) and the moved cylinder converged (13); at N = 101 the reverse
(109 iterations, changes of 5e-6). A node beside the rim read the flat fan of nodes beyond it,
which all take the rim's value, with the ramp t = (u₁ − u₂)/ε in the middle of its range, and
swung with the nodes that read it back. Now all four converge in 14–18 iterations.

    .venv/bin/python benches/experiments/limit_cycles.py [N ...] [--star N] [--perturb E] [--changes]
    # default 191 201, star 801, no perturbation
    .venv/bin/python benches/experiments/limit_cycles.py 0 --star 0 --cylinder 61 --changes
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


def cylinder(n: int, show: bool) -> None:
    grid = ts.Grid((-1.0,) * 3, (1.0,) * 3, (n,) * 3)
    x = np.stack(grid.meshgrid(), axis=-1)
    h = grid.spacing
    for label, up in (("on grid planes", 0.0), ("0.3 spacings above them", 0.3 * h)):
        d = np.stack([np.hypot(x[..., 0], x[..., 1]) - 0.5, np.abs(x[..., 2] - up) - 0.4], axis=-1)
        phi = np.linalg.norm(np.maximum(d, 0), axis=-1) + np.minimum(d.max(axis=-1), 0)
        changes: list = []
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sol = ts.solve(
                ts.LevelSet(phi),
                grid,
                [(0.0, 0.0, 0.4 + up)],
                progress=lambda it, ch, n_up: changes.append((it, ch, n_up)),
            )
        _report(f"closed cylinder N={n}, caps {label}", sol, changes, show)
        print(f"  fallback_change {sol.stats.order2['fallback_change']}", flush=True)


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
    star_n, perturb, cylinder_n = 801, 0.0, 0
    if "--cylinder" in args:
        i = args.index("--cylinder")
        cylinder_n = int(args[i + 1])
        args = args[:i] + args[i + 2 :]
    if "--perturb" in args:
        i = args.index("--perturb")
        perturb = float(args[i + 1])
        args = args[:i] + args[i + 2 :]
    if "--star" in args:
        i = args.index("--star")
        star_n = int(args[i + 1])
        args = args[:i] + args[i + 2 :]
    main([n for n in (int(a) for a in args) if n] if args else [191, 201], star_n, perturb, show)
    if cylinder_n:
        cylinder(cylinder_n, show)
