"""Bad input gets a clear exception that names the argument."""

import numpy as np
import pytest

import tubesweep as ts

G2 = ts.Grid((-1, -1), (1, 1), (21, 21))


def circle(p):
    return np.linalg.norm(p, axis=1) - 0.5


@pytest.mark.parametrize(
    "speed, match",
    [
        (0.0, "positive"),
        (-1.0, "positive"),
        (np.nan, "finite"),
        (np.inf, "finite"),
        (np.full((21, 21), -2.0), "positive"),
        (np.where(np.eye(21) > 0, np.nan, 1.0), "NaN"),
        (np.ones((20, 21)), "shape"),
        (lambda p: np.zeros(len(p)), "positive"),
        (lambda p: np.ones((len(p), 2)), "shape"),
    ],
)
def test_bad_speed(speed, match):
    with pytest.raises(ValueError, match=match):
        ts.travel_time(G2, [(0, 0)], speed=speed)
    with pytest.raises(ValueError, match=match):
        ts.solve(circle, G2, [(0.5, 0)], speed=speed)


@pytest.mark.parametrize(
    "sources, match",
    [
        ([(2.0, 0.0)], "outside the grid"),
        ([(np.nan, 0.0)], "NaN"),
        ([(0.0, 0.0, 0.0)], "shape"),
        (np.zeros((0, 2)), "empty"),
    ],
)
def test_bad_sources(sources, match):
    with pytest.raises(ValueError, match=match):
        ts.travel_time(G2, sources)


def test_float32_and_lists_are_accepted():
    u = ts.travel_time(G2, np.array([[0.1, 0.2]], dtype=np.float32), speed=np.ones((21, 21), np.float32))
    assert u.dtype == np.float64 and np.isfinite(u).all()
    u2 = ts.travel_time(G2, [0.1, 0.2])
    np.testing.assert_allclose(u, u2, atol=1e-7)


def test_bad_hamiltonian_and_tolerances():
    with pytest.raises(ValueError, match="hamiltonian"):
        ts.travel_time(G2, [(0, 0)], hamiltonian="upwind")
    with pytest.raises(ValueError, match="tol"):
        ts.travel_time(G2, [(0, 0)], tol=-1)
    with pytest.raises(ValueError, match="max_iterations"):
        ts.travel_time(G2, [(0, 0)], max_iterations=0)
    with pytest.raises(TypeError, match="Grid"):
        ts.travel_time((21, 21), [(0, 0)])


def test_unconverged_warns():
    with pytest.warns(RuntimeWarning, match="did not converge"):
        ts.travel_time(G2, [(0, 0)], hamiltonian="lxf", max_iterations=2)


def test_progress_callback_sees_every_iteration_and_can_interrupt():
    seen = []
    u, st = ts.travel_time(G2, [(0, 0)], hamiltonian="lxf", return_stats=True, progress=lambda i, c, n: seen.append(i))
    assert seen == list(range(1, st.iterations + 1))

    def stop(i, c, n):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        ts.travel_time(G2, [(0, 0)], progress=stop)


def test_memory_guard():
    with pytest.raises(MemoryError, match="GiB"):
        ts.travel_time(ts.Grid((0, 0, 0), (1, 1, 1), (5001, 5001, 5001)), [(0.5, 0.5, 0.5)])


def test_bad_speed_array_error_names_the_node():
    speed = np.ones((21, 21))
    speed[15, 10] = -1.0
    for call in (lambda: ts.travel_time(G2, [(0, 0)], speed=speed),
                 lambda: ts.solve(circle, G2, [(0.5, 0)], speed=speed)):
        with pytest.raises(ValueError, match=r"at \(0\.5, 0\.0\)"):
            call()
