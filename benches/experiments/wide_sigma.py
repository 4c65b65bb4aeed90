"""How a constant Lax–Friedrichs ``sigma=`` above its bound grows the error
(``_hamiltonian_solve.WIDE_SIGMA``): the sphere of radius 0.5 at N = 41 with the identity metric,
the source at (−0.5, 0, 0); relative errors at the quarter-way point (0, 0.5, 0) and the
antipode for σ = 1, 1.5, 2, 3, 5, 10, 100 (the bound is 1)::

    .venv/bin/python benches/experiments/wide_sigma.py
"""

from __future__ import annotations

import warnings

import numpy as np


def main() -> None:
    import tubesweep as ts

    grid = ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3)
    exact = np.array([np.pi / 4, np.pi / 2])
    for sigma in (1.0, 1.5, 2.0, 3.0, 5.0, 10.0, 100.0):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            sol = ts.solve(ts.surfaces.Sphere(0.5), grid, [(-0.5, 0, 0)],
                           hamiltonian=ts.hamiltonians.Metric(np.eye(3), sigma=sigma))  # fmt: skip
        u = sol([(0, 0.5, 0), (0.5, 0, 0)])
        off = np.abs(u - exact) / exact
        print(f"sigma = {sigma:g}: quarter-way {u[0]:.3f} ({off[0]:.1%} off), antipode {u[1]:.3f} ({off[1]:.1%} off)")


if __name__ == "__main__":
    main()
