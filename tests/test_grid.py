import numpy as np
import pytest

import tubesweep as ts


def test_spacing_points_and_indices_round_trip():
    g = ts.Grid((-1, -1, -1), (1, 1, 1), (21, 21, 21))
    assert g.spacing == pytest.approx(0.1)
    assert g.ndim == 3 and g.size == 21**3
    idx = np.array([[0, 0, 0], [20, 10, 3]])
    p = g.points(idx)
    np.testing.assert_allclose(p, [[-1, -1, -1], [1, 0, -0.7]])
    np.testing.assert_array_equal(g.nearest_index(p - 0.02 * np.sign(p)), idx)
    np.testing.assert_array_equal(g.unravel(g.linear_index(idx)), idx)
    np.testing.assert_array_equal(g.cell_index([[1.0, 1.0, 1.0]]), [[19, 19, 19]])


def test_non_uniform_spacing_names_the_axis():
    with pytest.raises(ValueError, match="axis 1"):
        ts.Grid((0, 0), (1, 2), (11, 11))


@pytest.mark.parametrize("shape", [(2, 10), (10, 1)])
def test_too_few_nodes(shape):
    with pytest.raises(ValueError, match="at least 3"):
        ts.Grid((0, 0), (1, 1), shape)


def test_bad_dimensions_and_bounds():
    with pytest.raises(ValueError, match="2D and 3D"):
        ts.Grid((0,), (1,), (10,))
    with pytest.raises(ValueError, match="greater"):
        ts.Grid((0, 1), (1, 1), (5, 5))
    with pytest.raises(ValueError, match="same length"):
        ts.Grid((0, 0), (1, 1, 1), (5, 5))


def test_grids_are_equal_up_to_rounding_in_units_of_their_spacing():
    # numpy's relative tolerance let two boxes near x = 1000, 0.18 spacings apart, compare equal
    # (and a warm start from the one grid was taken on the other)
    a = ts.Grid((1000.0,) * 3, (1002.0,) * 3, (41,) * 3)
    assert a != ts.Grid((1000.009,) * 3, (1002.009,) * 3, (41,) * 3)
    assert a == ts.Grid((1000.0 + 1e-12,) * 3, (1002.0,) * 3, (41,) * 3)
    b = ts.Grid((0.1 + 0.2, 0.0), (1.3, 1.0), (11, 11))
    assert b == ts.Grid((0.3, 0.0), (1.3, 1.0), (11, 11)) and hash(b) == hash(ts.Grid((0.3, 0.0), (1.3, 1.0), (11, 11)))
    assert b != ts.Grid((0.3, 0.0), (1.3 + 1e-4, 1.0 + 1e-4), (11, 11))
