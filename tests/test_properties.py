"""Property-based tests (hypothesis): random grids, surfaces, sources and options within the
documented limits, checked against invariants; a fuzz of the mesh reader and of the private
native module's entry points (issue 35, item 7).

The example counts are small (the suite runs on 2 cores in CI): about 15 s in all. ``benches/
hostile_inputs.py`` is the hand-made battery that goes with them.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import tubesweep as ts  # noqa: E402
import tubesweep._native as N  # noqa: E402
from tubesweep.surfaces.mesh import read_mesh  # noqa: E402

FAST = settings(
    max_examples=12,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)


def _on_circle(centre, r, angles):
    return np.c_[centre[0] + r * np.cos(angles), centre[1] + r * np.sin(angles)]


def _on_sphere(centre, r, angles):
    th, ph = angles
    return np.asarray(centre) + r * np.c_[np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)]


@st.composite
def surface_problems(draw):
    """A circle or sphere (radius, centre), a grid that resolves it, 1–3 sources on it and options."""
    d = draw(st.sampled_from([2, 3]))
    n = draw(st.integers(31, 61)) if d == 2 else draw(st.integers(21, 31))
    r = draw(st.floats(0.35, 0.7))
    centre = [draw(st.floats(-0.15, 0.15)) for _ in range(d)]
    k = draw(st.integers(1, 3))
    if d == 2:
        surface = ts.surfaces.Circle(r, centre)
        sources = _on_circle(centre, r, np.asarray(draw(st.lists(st.floats(0, 2 * np.pi), min_size=k, max_size=k))))
    else:
        surface = ts.surfaces.Sphere(r, centre)
        th = np.asarray(draw(st.lists(st.floats(0.2, np.pi - 0.2), min_size=k, max_size=k)))
        ph = np.asarray(draw(st.lists(st.floats(0, 2 * np.pi), min_size=k, max_size=k)))
        sources = _on_sphere(centre, r, (th, ph))
    grid = ts.Grid((-1,) * d, (1,) * d, (n,) * d)
    inner = draw(st.sampled_from([1.5, 2.0, 2.5]))
    options = dict(
        hamiltonian=draw(st.sampled_from(["godunov", "lxf"])),
        inner=inner,
        outer=inner + draw(st.sampled_from([2.0, 2.5])),
        source_init=draw(st.sampled_from(["exact", "node"])),
        speed=draw(st.floats(0.5, 4.0)),
        tol=1e-9,
    )
    return surface, grid, sources, r, options


@FAST
@given(surface_problems())
def test_surface_solves_keep_their_invariants(problem):
    surface, grid, sources, r, options = problem
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # e.g. the facing-sheets note on a coarse grid
        sol = ts.solve(surface, grid, sources, **options)
        one = ts.solve(surface, grid, sources, threads=1, **options)
        tube = ts.Tube(surface, grid, inner=options["inner"], outer=options["outer"])
        opts = {k: v for k, v in options.items() if k not in ("inner", "outer")}
        again = tube.solve(sources, **opts)
    v = sol.values
    inner = sol.roles != 2
    h = grid.spacing
    slowness = 1.0 / options["speed"]
    assert sol.stats.converged
    assert np.all(np.isfinite(v[inner])), "finite on the surface (one component, every node reached)"
    assert np.all(v[np.isfinite(v)] >= 0)
    # bounded by the surface's geodesic diameter (half a great circle) plus the first-order error
    assert float(np.max(v[inner])) <= (np.pi * r + 4 * h) * slowness
    # zero at the sources: the interpolated value there is within a few cells' travel time; never
    # negative next to them (order=2's u₀ + w rounded to −9e-22 once)
    at = sol(sources)
    # (Lax–Friedrichs from the paper's node initialisation reaches 3.07 h at a source on a 28³ grid:
    # the sphere of radius 0.625 centred at (0.125, 0.03125, 0), a hypothesis example)
    assert np.all(at <= 3.5 * h * slowness) and np.all(at >= 0)
    near = np.repeat(sources, 4, axis=0) + 0.3 * h * np.sin(np.arange(4 * len(sources) * grid.ndim)).reshape(
        -1, grid.ndim
    )
    assert np.all(np.nan_to_num(sol(near)) >= 0)
    # the thread count and the reusable tube change no bit
    assert np.array_equal(v, one.values)
    assert np.array_equal(v, again.values)


@FAST
@given(st.integers(2, 3), st.data())
def test_box_travel_times_keep_their_invariants(d, data):
    shape = tuple(data.draw(st.integers(5, 40 if d == 2 else 14)) for _ in range(d))
    h = data.draw(st.floats(0.01, 10.0))
    lower = [data.draw(st.floats(-100, 100)) for _ in range(d)]
    grid = ts.Grid(lower, [lo + h * (n - 1) for lo, n in zip(lower, shape)], shape)
    k = data.draw(st.integers(1, 3))
    sources = np.asarray(lower) + np.asarray(
        data.draw(st.lists(st.lists(st.floats(0, 1), min_size=d, max_size=d), min_size=k, max_size=k))
    ) * h * (np.asarray(shape) - 1)
    speed = data.draw(st.floats(0.1, 10.0))
    ham = data.draw(st.sampled_from(["godunov", "lxf"]))
    u = ts.travel_time(grid, sources, speed=speed, hamiltonian=ham, tol=1e-10 * h / speed)
    assert np.all(np.isfinite(u)) and np.all(u >= 0)
    diagonal = h * np.sqrt(np.sum((np.asarray(shape) - 1.0) ** 2))
    assert float(u.max()) <= diagonal / speed * 1.1 + 4 * h / speed
    assert np.array_equal(
        u, ts.travel_time(grid, sources, speed=speed, hamiltonian=ham, tol=1e-10 * h / speed, threads=1)
    )


# ---------------------------------------------------------------------------------------- fuzz
_OBJ_TOKENS = st.sampled_from(
    [
        "v",
        "f",
        "vt",
        "vn",
        "l",
        "p",
        "#",
        "o",
        "g",
        "s",
        "1",
        "2",
        "3",
        "-1",
        "0",
        "0.5",
        "nan",
        "inf",
        "1e300",
        "x",
        "1/2/3",
        "2//1",
        "",
        "\\",
    ]
)
_WS = st.sampled_from([" ", "  ", "\t", " \t "])


@st.composite
def obj_texts(draw):
    lines = []
    for _ in range(draw(st.integers(0, 14))):
        tokens = draw(st.lists(_OBJ_TOKENS, min_size=0, max_size=6))
        lead = draw(st.sampled_from(["", " ", "\t"]))
        lines.append(lead + draw(_WS).join(tokens))
    return draw(st.sampled_from(["\n", "\r\n"])).join(lines)


def _read_or_refuse(path):
    """A mesh reader's outcome: valid arrays, or a clean ValueError (a warning may come with
    arrays: it says how many records were dropped)."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            v, f = read_mesh(path)
    except ValueError as e:
        assert str(e)
        return
    assert v.ndim == 2 and v.shape[1] == 3 and f.ndim == 2 and f.shape[1] == 3
    assert f.size and f.min() >= 0 and f.max() < len(v)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(obj_texts(), st.sampled_from([".obj", ".off"]))
def test_the_mesh_reader_reads_or_refuses_cleanly(tmp_path_factory, text, suffix):
    path = tmp_path_factory.mktemp("fuzz") / f"m{suffix}"
    path.write_text(("OFF\n" if suffix == ".off" and text[:1] != "O" else "") + text)
    _read_or_refuse(path)


@settings(max_examples=25, deadline=None, derandomize=True)
@given(st.binary(min_size=0, max_size=300), st.sampled_from([".obj", ".off", ".ply", ".stl"]))
def test_the_mesh_reader_refuses_random_bytes_cleanly(tmp_path_factory, data, suffix):
    path = tmp_path_factory.mktemp("bytes") / f"m{suffix}"
    path.write_bytes(data)
    _read_or_refuse(path)


_INTS = st.one_of(
    st.integers(-5, 12), st.sampled_from([0, 1, 2, 2**31, 2**32, 2**40, 2**62, 2**63 - 1, 2**63, 2**64 - 1])
)
_FLOATS = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.sampled_from([0.0, -1.0, 1e-300, 1e300]))
# (results with a Python exception are fine; a Rust panic reaches Python as PanicException, a
# BaseException, and fails the test)
_CLEAN = (ValueError, TypeError, OverflowError, MemoryError)


def _small_box(shape):
    """Shapes whose box the fuzz may allocate (the others must be refused before allocating)."""
    total = 1
    for n in shape:
        total *= max(n, 0)
    return total <= 10**6 or total >= 2**32


@settings(max_examples=80, deadline=None, derandomize=True)
@given(st.lists(_INTS, min_size=0, max_size=4), st.lists(_INTS, min_size=0, max_size=6), _FLOATS, _FLOATS)
def test_the_native_entry_points_raise_python_errors_not_panics(shape, values, a, b):
    lin = np.asarray([v % 2**64 for v in values], dtype=np.uint64)
    ints = np.asarray([max(min(v, 2**62), -(2**62)) for v in values], dtype=np.int64)
    calls = [
        lambda: N.Band.from_linear(shape, np.unique(lin)),
        lambda: N.node_points(shape, lin, [a] * len(shape), b),
        lambda: N.split_pair_blocks(
            shape, ints[: (len(ints) // max(len(shape), 1)) * len(shape)].reshape(-1, max(len(shape), 1))
        ),
        lambda: N.band_of_samples(np.zeros([min(max(n, 0), 6) for n in shape]), a),
        lambda: N.keep_within(lin, np.full(len(lin), a), b, np.zeros(len(lin), np.uint64), np.zeros(len(lin))),
        lambda: N.children_radius_max(
            shape,
            ints[: (len(ints) // max(len(shape), 1)) * len(shape)].reshape(-1, max(len(shape), 1)),
            abs(int(values[0])) if values else 1,
        ),
        lambda: N.TriangleTree(
            np.full((3, 3), a), ints[:3].reshape(1, -1) if len(ints) >= 3 else np.zeros((0, 3), np.int64)
        ),
        lambda: N.sphere_signed_distance(np.full((2, 3), a), [b, 0.0, 0.0], a),
    ]
    if _small_box(shape):
        calls.append(lambda: N.Band.full_box(shape))
    for call in calls:
        try:
            call()
        except _CLEAN:
            pass
