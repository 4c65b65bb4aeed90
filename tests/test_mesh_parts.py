"""A triangle mesh's separate parts (``surfaces/_mesh_parts.py``): the band's edges between them
are cut, so a part without a source stays unreached."""

import numpy as np
import pytest

import tubesweep as ts
from tubesweep.surfaces._mesh_parts import face_parts, vertex_parts

from test_mesh import icosphere


def two_spheres(gap_spacings: float, h: float):
    v, f = icosphere(3, 0.3)
    d = 0.6 + gap_spacings * h
    return np.r_[v - [d / 2, 0, 0], v + [d / 2, 0, 0]], np.r_[f, f + len(v)], d


def test_vertex_parts_label_each_part_by_its_smallest_vertex():
    f = np.array([[0, 1, 2], [2, 3, 4], [5, 6, 7], [7, 8, 6]])
    assert vertex_parts(10, f).tolist() == [0, 0, 0, 0, 0, 5, 5, 5, 5, 9]
    # a chain whose indices alternate between its two ends: propagation meets in the middle
    chain = np.array([[i, 99 - i, i + 1] for i in range(50)] + [[99 - i, i + 1, 98 - i] for i in range(49)])
    assert np.all(vertex_parts(100, chain) == 0)


@pytest.mark.parametrize("smooth", [True, False])
def test_a_sphere_without_a_source_next_to_one_with_it_stays_unreached(smooth):
    # two icospheres 1.2 spacings apart at N = 51, the source on the left one: with the smooth map
    # (the default) the right one got finite distances (1.42 at its far pole), converged, unwarned
    g = ts.Grid((-1,) * 3, (1,) * 3, (51,) * 3)
    v, f, d = two_spheres(1.2, g.spacing)
    mesh = ts.surfaces.from_mesh((v, f), smooth=smooth)
    assert face_parts(mesh) is not None and face_parts(mesh).max() == 1
    with pytest.warns(RuntimeWarning, match="ran the paper's first-order scheme"):
        sol = ts.solve(mesh, g, [v[0]])
    assert sol.stats.converged and sol.stats.cut_edges > 0
    right = sol(v[len(v) // 2 :])
    assert np.all(np.isinf(right))
    # the left sphere: great circles from the source (first order, 7.5 spacings across its radius:
    # 3.3Δx short at the antipode, where the fronts meet; the warning says 14% of 0.94)
    left = v[: len(v) // 2]
    centre = np.array([-d / 2, 0, 0])
    cos = np.sum((left - centre) * (v[0] - centre), axis=1) / 0.09
    exact = 0.3 * np.arccos(np.clip(cos, -1, 1))
    assert np.max(np.abs(sol(left) - exact)) < 3.5 * g.spacing


def test_a_mesh_of_one_part_is_not_cut_between_parts():
    v, f = icosphere(3, 0.4)
    mesh = ts.surfaces.from_mesh((v, f))
    assert face_parts(mesh) is None
