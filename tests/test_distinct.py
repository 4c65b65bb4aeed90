"""Distinct values and rows by sorting (``_distinct``): each returns exactly what the
``np.unique`` call it replaces returns, and the mesh's parts by union–find (Rust) the labels of
a plain graph search."""

import numpy as np
import pytest

from tubesweep._distinct import distinct, distinct_rows, used_vertices
from tubesweep.surfaces._mesh_parts import vertex_parts

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402
from hypothesis.extra import numpy as hnp  # noqa: E402

SMALL = st.integers(-3, 3)


@settings(max_examples=200, deadline=None)
@given(hnp.arrays(np.int64, hnp.array_shapes(min_dims=1, max_dims=2, max_side=40), elements=SMALL))
def test_distinct_is_np_unique(values):
    got, want = distinct(values), np.unique(values)
    assert got.dtype == want.dtype and np.array_equal(got, want)


@settings(max_examples=200, deadline=None)
@given(hnp.arrays(np.int64, st.tuples(st.integers(0, 40), st.just(3)), elements=st.integers(0, 9)))
def test_used_vertices_is_np_unique_of_the_faces(faces):
    assert np.array_equal(used_vertices(faces, 10), np.unique(faces).astype(np.int64))


@settings(max_examples=200, deadline=None)
@given(
    hnp.arrays(
        np.float64,
        st.tuples(st.integers(0, 40), st.integers(1, 3)),
        elements=st.sampled_from([-1.5, -0.0, 0.0, 0.25, 2.0]),
    )
)
def test_distinct_rows_is_np_unique_by_rows(rows):
    first, inverse = distinct_rows(rows)
    _, want_first, want_inverse = np.unique(rows, axis=0, return_index=True, return_inverse=True)
    assert np.array_equal(first, want_first) and np.array_equal(inverse, want_inverse.ravel())


def test_distinct_rows_refuses_a_flat_array():
    with pytest.raises(ValueError, match="rows must be 2-D"):
        distinct_rows(np.arange(4))


def _parts_by_search(n, faces):
    """The reference: a depth-first search over the faces' edges."""
    neighbours = [[] for _ in range(n)]
    for a, b, c in faces:
        for p, q in ((a, b), (b, c), (c, a)):
            neighbours[p].append(q)
            neighbours[q].append(p)
    label = np.full(n, -1)
    for start in range(n):
        if label[start] < 0:
            stack, label[start] = [start], start
            while stack:
                for q in neighbours[stack.pop()]:
                    if label[q] < 0:
                        label[q] = start
                        stack.append(q)
    return label


@settings(max_examples=200, deadline=None)
@given(st.integers(1, 30).flatmap(lambda n: st.tuples(st.just(n), st.lists(st.tuples(*[st.integers(0, n - 1)] * 3)))))
def test_vertex_parts_are_the_graphs_connected_parts(case):
    n, faces = case
    f = np.array(faces, np.int64).reshape(-1, 3)
    assert vertex_parts(n, f).tolist() == _parts_by_search(n, f).tolist()


def test_vertex_parts_name_an_index_out_of_range():
    with pytest.raises(ValueError, match="faces: vertex index 3 outside 0..3"):
        vertex_parts(3, np.array([[0, 1, 3]]))
