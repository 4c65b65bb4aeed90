"""How ``ts.hamiltonians.Metric`` hands M to the native solvers: one matrix for a constant M where
nothing makes it per node (the box, ``tangential=False``), per node otherwise, the upwind solver's
symmetric part of it packed (docs/hamiltonians.md); the storage never changes a bit of the solution."""

from __future__ import annotations

import numpy as np
import pytest

import tubesweep as ts
from tubesweep.surfaces.analytic import Circle

M = np.array([[2.0, 0.3], [0.3, 1.0]])


def _per_node(m: np.ndarray):
    """The same constant M as a callable: evaluated, and stored, per node."""
    return lambda p: np.broadcast_to(m, (len(p),) + m.shape)


def _same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and bool(np.all(a.view(np.int64) == b.view(np.int64)))


@pytest.mark.parametrize("scheme", ["godunov", "lxf"])
def test_one_matrix_for_all_nodes_gives_the_bits_of_the_per_node_storage(scheme):
    g = ts.Grid((-1, -1), (1, 1), (61, 61))
    c = Circle(0.5)
    for tangential in (False, True):  # with True the tangential part of either is per node
        one = ts.solve(c, g, [(-0.5, 0)], hamiltonian=ts.hamiltonians.Metric(M, tangential=tangential, scheme=scheme))
        per = ts.solve(
            c, g, [(-0.5, 0)], hamiltonian=ts.hamiltonians.Metric(_per_node(M), tangential=tangential, scheme=scheme)
        )
        assert one.stats.converged and _same_bits(one.values, per.values)
    u1, s1 = ts.travel_time(g, [(0.1, 0.0)], hamiltonian=ts.hamiltonians.Metric(M, scheme=scheme), return_stats=True)
    up, sp = ts.travel_time(
        g, [(0.1, 0.0)], hamiltonian=ts.hamiltonians.Metric(_per_node(M), scheme=scheme), return_stats=True
    )
    assert _same_bits(u1, up) and np.isfinite(u1).all()
    # the upwind solver stores the symmetric part, 3 numbers (24 B) per node in 2D, and a constant M
    # once; the Lax–Friedrichs update reads the full M (32 B) per node either way
    saved = sp.band_bytes - s1.band_bytes
    assert saved == (8 * 3 * (g.size - 1) if scheme == "godunov" else 0)


def test_a_slightly_asymmetric_metric_is_solved_as_its_symmetric_part():
    g = ts.Grid((-1, -1), (1, 1), (61, 61))
    rng = np.random.default_rng(3)
    asym = M * (1 + 4e-11 * rng.uniform(-1, 1, size=(2, 2)))  # within the validation's 1e-10
    assert asym[0, 1] != asym[1, 0]
    sym = (asym + asym.T) / 2
    for field in (asym, _per_node(asym)):
        got = ts.travel_time(g, [(0.1, 0.0)], hamiltonian=ts.hamiltonians.Metric(field))
        want = ts.travel_time(g, [(0.1, 0.0)], hamiltonian=ts.hamiltonians.Metric(sym))
        assert _same_bits(got, want)
        c = Circle(0.5)
        a = ts.solve(c, g, [(-0.5, 0)], hamiltonian=ts.hamiltonians.Metric(field, tangential=False))
        b = ts.solve(c, g, [(-0.5, 0)], hamiltonian=ts.hamiltonians.Metric(sym, tangential=False))
        assert _same_bits(a.values, b.values)
    # and the asymmetry was not lost before the solver: the Lax–Friedrichs update reads M as given
    lxf = ts.travel_time(g, [(0.1, 0.0)], hamiltonian=ts.hamiltonians.Metric(asym, scheme="lxf"))
    lxf_sym = ts.travel_time(g, [(0.1, 0.0)], hamiltonian=ts.hamiltonians.Metric(sym, scheme="lxf"))
    assert not _same_bits(lxf, lxf_sym)
