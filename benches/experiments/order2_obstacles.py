"""``order=2`` with obstacles: the default tolerance against slow regions and single slow nodes.

The default tolerances of ``order=2`` (``ts.solve`` and ``ts.travel_time``) scale with a slowness.
The mean slowness is pulled up by an obstacle (a region or a node far slower than the rest, which
the fronts go around) by its slowness times its share of the nodes; the tolerance then stops the
sweeps after an iteration or two, far from the solution where the fronts do travel. The default
is now the mean capped at twice the lower quartile (``_validate.tolerance_slowness``). This
script prints, for each case, the error with the default tolerance, with the mean-based
tolerance of before (passed explicitly) and with a tight explicit one::

    .venv/bin/python benches/experiments/order2_obstacles.py

Cases: the sphere of radius 0.5 in [-1, 1]³ at N = 41, the source at (−0.5, 0, 0), the error on
the circle x = 0 (exact π/4), without an obstacle, with the cap x > 0.3 at speed 1e-6 and with one
band node near (0.35, 0.35, 0) at speed 1e-30 or 1e-90; the box [-1, 1]² at N = 101, the source
at (−0.5, 0), without an obstacle, with the disc |x − (0.2, 0)| < 0.3 at speed 1e-6 and with the
node nearest (0, 0.02) at speed 1e-30: the distance to the converged solution off the obstacle and
the error where x < −0.1 (straight rays from the source, the exact answer known).
"""

from __future__ import annotations

import warnings

import numpy as np

import tubesweep as ts
from tubesweep._validate import tolerance_slowness
from tubesweep.box_order2 import order2_tol
from tubesweep.second_order import default_tol, ramp_length

SPHERE = ts.surfaces.Sphere(0.5)
SOURCE3 = (-0.5, 0.0, 0.0)
SOURCE2 = (-0.5, 0.0)


def sphere_case(n: int, speed_kind: str):
    grid = ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3)
    x = np.stack(grid.meshgrid(), axis=-1)
    speed = np.ones(grid.shape)
    if speed_kind == "cap":
        speed[x[..., 0] > 0.3] = 1e-6
    elif speed_kind.startswith("node"):
        i = grid.nearest_index(np.array([[0.35, 0.35, 0.0]]))[0]
        speed[tuple(i)] = float(speed_kind.split()[1])
    theta = np.linspace(0, 2 * np.pi, 200, endpoint=False)
    ring = np.stack([0 * theta, 0.5 * np.cos(theta), 0.5 * np.sin(theta)], axis=1)
    return grid, speed, ring, np.pi / 4


def box_case(n: int, speed_kind: str):
    grid = ts.Grid((-1,) * 2, (1,) * 2, (n,) * 2)
    x = np.stack(grid.meshgrid(), axis=-1)
    speed = np.ones(grid.shape)
    if speed_kind == "disc":
        speed[np.hypot(x[..., 0] - 0.2, x[..., 1]) < 0.3] = 1e-6
    elif speed_kind.startswith("node"):
        i = grid.nearest_index(np.array([[0.0, 0.02]]))[0]
        speed[tuple(i)] = float(speed_kind.split()[1])
    return grid, speed, x


def main() -> None:
    print("sphere R=0.5, N=41, source (-0.5,0,0): max error on the circle x = 0 (order=2)")
    for kind in ["none", "cap", "node 1e-30", "node 1e-90"]:
        grid, speed, ring, exact = sphere_case(41, kind)
        row = {}
        for label, tol in [("default", None), ("mean-based", "mean"), ("tol=1e-6", 1e-6)]:
            if tol == "mean":
                # the default of before: the mean slowness over the band (ts.Tube's band)
                tube = ts.Tube(SPHERE, grid)
                s = 1.0 / speed.reshape(-1)[tube._tube.linear]
                tol = default_tol(grid.spacing, float(np.mean(s)), ramp_length(grid), 3)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                sol = ts.solve(SPHERE, grid, [SOURCE3], speed=speed, order=2, **({} if tol is None else {"tol": tol}))
            row[label] = (float(np.max(np.abs(sol(ring) - exact))), sol.stats.order2["second_order_iterations"])
        print(f"  {kind:11s} " + "  ".join(f"{k}: {e:.3g} ({it} it)" for k, (e, it) in row.items()))
    print(
        "box [-1,1]^2, N=101, source (-0.5,0), order=2: max |u - u converged (tol=1e-13)| off the obstacle; "
        "max error where x < -0.1 (straight rays)"
    )
    for kind in ["none", "disc", "node 1e-30"]:
        grid, speed, x = box_case(101, kind)
        exact = np.hypot(x[..., 0] - SOURCE2[0], x[..., 1] - SOURCE2[1])
        free = speed == 1.0
        before = x[..., 0] < -0.1
        ref = ts.travel_time(grid, [SOURCE2], speed=speed, order=2, tol=1e-13)
        row = {}
        for label, tol in [("default", None), ("mean-based", "mean")]:
            if tol == "mean":
                tol = order2_tol(grid, float(np.mean(1.0 / speed)))
            u = ts.travel_time(grid, [SOURCE2], speed=speed, order=2, **({} if tol is None else {"tol": tol}))
            row[label] = (float(np.max(np.abs(u - ref)[free])), float(np.max(np.abs(u - exact)[before])))
        print(
            f"  {kind:11s} "
            + "  ".join(f"{k}: {a:.3g} from converged, {b:.3g} from exact" for k, (a, b) in row.items())
        )
    print(
        "tolerance slowness (mean -> used): cap "
        + ", ".join(
            f"{k}: {np.mean(1 / s):.3g} -> {tolerance_slowness(1 / s):.3g}"
            for k, s in [("cap", sphere_case(41, "cap")[1]), ("disc", box_case(101, "disc")[1])]
        )
    )


if __name__ == "__main__":
    main()
