"""The point sources' exact initialisation (``_sources.py``): the nodes fixed around each source,
in batches, against a source-by-source loop written out here."""

import numpy as np
import pytest

import tubesweep as ts
from tubesweep._prepare import _prepare_tube
from tubesweep._roles import ROLE_INNER
from tubesweep._sources import SOURCE_RADIUS, _fix_sources


def one_by_one(surface, grid, band, linear, roles, sources, slowness_at, inner_width):
    """Each source on its own: the inner-tube nodes whose closest points lie within the radius
    of the source's foot (its nearest ones where none does), fixed to the chord times the mean
    slowness; per node the smallest value, the first source among equal ones."""
    h = grid.spacing
    _, feet = surface.project(sources, grid)
    inner = np.flatnonzero(roles == ROLE_INNER)
    _, cp = surface.project(grid.node_points(linear[inner]), grid)
    best = {}
    for i, foot in enumerate(feet):
        geo = np.linalg.norm(cp - foot, axis=1)
        near = geo <= SOURCE_RADIUS * h
        if not near.any():
            near = geo <= geo.min()
        slow = 0.5 * (slowness_at(cp[near]) + slowness_at(foot[None])[0])
        for p, v in zip(inner[near], geo[near] * slow):
            if p not in best or v < best[p][0]:
                best[p] = (v, i)
    keys = sorted(best)
    return np.array(keys), np.array([best[k][0] for k in keys]), np.array([best[k][1] for k in keys])


@pytest.mark.parametrize("speed", [1.0, lambda p: 1.0 + 0.5 * p[:, 0]])
def test_the_sources_batched_fix_the_nodes_a_loop_over_them_fixes(speed):
    grid = ts.Grid((-1,) * 3, (1,) * 3, (31,) * 3)
    surface = ts.surfaces.Sphere(0.5)
    rng = np.random.default_rng(0)
    x = rng.normal(size=(700, 3))  # more than one batch, with near and repeated sources
    sources = 0.5 * x / np.linalg.norm(x, axis=1, keepdims=True)
    sources[600:650] = sources[:50]
    sources[650:] = sources[:50] + 1e-3 * rng.normal(size=(50, 3))
    tube = _prepare_tube(surface, grid, 2.0, 4.0, "two-layer", False)
    band, linear, roles = tube.band, tube.linear, tube.roles

    def slowness_at(p):
        return 1.0 / (speed(p) if callable(speed) else np.full(len(p), speed))

    got = _fix_sources(surface, grid, band, linear, roles, sources, slowness_at, "exact", 2.0 * grid.spacing)
    want = one_by_one(surface, grid, band, linear, roles, sources, slowness_at, 2.0 * grid.spacing)
    order = np.argsort(got[0])
    assert np.array_equal(got[0][order], want[0])
    np.testing.assert_allclose(got[1][order], want[1], rtol=1e-15, atol=0)
    assert np.array_equal(got[2][order], want[2])


def test_a_source_whose_closest_point_is_not_defined_is_refused_by_name():
    # a sphere of samples, the source at its centre: the message said "is nan from the surface"
    # (and a surface whose projection gave NaN passed the check); the fits found no surface there
    # (every sample at one distance weighed nothing), and since they weigh alike, the centre's
    # closest point lies among the samples, half the sphere's radius away
    x = np.random.default_rng(0).normal(size=(3000, 3))
    cloud = ts.surfaces.from_points(0.5 * x / np.linalg.norm(x, axis=1, keepdims=True))
    with pytest.raises(
        ValueError, match=r"sources\[0\] = \(0\.0, 0\.0, 0\.0\) is 0\.5 from the surface, farther than the inner tube"
    ):
        ts.solve(cloud, ts.Grid((-1,) * 3, (1,) * 3, (31,) * 3), [(0.0, 0.0, 0.0)])

    class Undefined(ts.surfaces.Sphere):
        def project(self, points, grid):
            d, cp = super().project(points, grid)
            return np.where(np.linalg.norm(points, axis=1) < 1e-9, np.nan, d), cp

    with pytest.raises(ValueError, match=r"is far from the surface \(its closest point there is not defined"):
        ts.solve(Undefined(0.5), ts.Grid((-1,) * 3, (1,) * 3, (31,) * 3), [(0.0, 0.0, 0.0)], order=1)
