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
    for call in (
        lambda: ts.travel_time(G2, [(0, 0)], speed=speed),
        lambda: ts.solve(circle, G2, [(0.5, 0)], speed=speed),
    ):
        with pytest.raises(ValueError, match=r"at \(0\.5, 0\.0\)"):
            call()


G3 = ts.Grid((-1,) * 3, (1,) * 3, (31,) * 3)
SPHERE = ts.surfaces.Sphere(0.5)


def test_tol_must_be_positive_and_max_iterations_bounded():
    # tol = 0 used to run all max_iterations (a change of exactly 0 never passed `< tol`)
    for bad in (0, 0.0, True):
        with pytest.raises(ValueError, match="tol must be a positive"):
            ts.solve(SPHERE, G3, [(-0.5, 0, 0)], tol=bad)
    with pytest.raises(ValueError, match="max_iterations"):
        ts.solve(SPHERE, G3, [(-0.5, 0, 0)], max_iterations=2**70)


@pytest.mark.parametrize("speed", [1e15, 1e9])
def test_a_tol_not_small_against_a_cell_s_travel_time_is_refused_and_the_default_scales(speed):
    # at speed 1e15 a tol of 1e-10 exceeds every travel time: the sweeps stopped at once, half the
    # band at the numerical infinity, reported converged. Given, it is refused; the default (an
    # absolute 1e-10 that was refused too, though the caller never gave it) is now 1e-10 of the
    # travel time across the grid
    with pytest.raises(ValueError, match=r"tol=1e-10 is not small against the travel times of this problem"):
        ts.solve(SPHERE, G3, [(-0.5, 0, 0)], speed=speed, order=1, tol=1e-10)
    with pytest.raises(ValueError, match=r"tol=1e-10 is not small against the travel times"):
        ts.solve(SPHERE, G3, [(-0.5, 0, 0)], speed=speed, hamiltonian=ts.hamiltonians.Isotropic(), order=1, tol=1e-10)
    with pytest.raises(ValueError, match="travel times"):
        ts.travel_time(G2, [(0, 0)], speed=speed, tol=1e-10)
    u1 = ts.solve(SPHERE, G3, [(-0.5, 0, 0)], order=1)([(0.5, 0, 0)])[0]
    # the fix the message names works, and gives the speed-1 answer scaled; so does the default
    cell = G3.spacing / speed
    u = ts.solve(SPHERE, G3, [(-0.5, 0, 0)], speed=speed, tol=1e-10 * cell, order=1)([(0.5, 0, 0)])[0]
    assert abs(u * speed - u1) < 1e-6 * u1
    for kw in (dict(), dict(hamiltonian=ts.hamiltonians.Isotropic())):
        unit = ts.solve(SPHERE, G3, [(-0.5, 0, 0)], order=1, **kw)([(0.5, 0, 0)])[0]
        u = ts.solve(SPHERE, G3, [(-0.5, 0, 0)], speed=speed, order=1, **kw)([(0.5, 0, 0)])[0]
        assert abs(u * speed - unit) < 1e-9 * unit
    box = ts.travel_time(G2, [(0, 0)], speed=speed, order=1) * speed
    np.testing.assert_allclose(box, ts.travel_time(G2, [(0, 0)], order=1), rtol=1e-9)


def test_a_metric_that_shrinks_the_travel_times_sets_the_default_tol_on_their_scale():
    # M = 1e30·I makes every travel time 1e-15 of the isotropic one: a tol of 1e-10 stopped the
    # sweeps after two iterations with 87% of the band at infinity, reported converged; given, it
    # is refused, and the default is 1e-10 of the metric's travel time across the grid
    big = ts.hamiltonians.Metric(1e30 * np.eye(3))
    with pytest.raises(ValueError, match=r"tol=1e-10 is not small against the travel times.*Hamiltonian"):
        ts.solve(SPHERE, G3, [(-0.5, 0, 0)], hamiltonian=big, tol=1e-10)
    u1 = ts.solve(SPHERE, G3, [(-0.5, 0, 0)], hamiltonian=ts.hamiltonians.Metric(np.eye(3)))([(0.5, 0, 0)])[0]
    # the tol it names works, and gives the identity metric's answer scaled by 1e-15; so does the default
    cell = 1e-15 * G3.spacing
    u = ts.solve(SPHERE, G3, [(-0.5, 0, 0)], hamiltonian=big, tol=1e-10 * cell)([(0.5, 0, 0)])[0]
    assert abs(u * 1e15 - u1) < 1e-6 * u1
    u = ts.solve(SPHERE, G3, [(-0.5, 0, 0)], hamiltonian=big)([(0.5, 0, 0)])[0]
    assert abs(u * 1e15 - u1) < 1e-9 * u1
    # a metric that lengthens the travel times is no reason to refuse the default tol
    slow = ts.solve(SPHERE, G3, [(-0.5, 0, 0)], hamiltonian=ts.hamiltonians.Metric(1e-30 * np.eye(3)))([(0.5, 0, 0)])[0]
    assert abs(slow * 1e-15 - u1) < 1e-6 * u1


def test_a_small_grid_in_small_units_needs_a_tol_in_those_units_and_the_default_has_it():
    s = 1e-12
    grid = ts.Grid((-s,) * 3, (s,) * 3, (31,) * 3)
    with pytest.raises(ValueError, match="tol"):
        ts.solve(ts.surfaces.Sphere(0.5 * s), grid, [(-0.5 * s, 0, 0)], order=1, tol=1e-10)
    u1 = ts.solve(SPHERE, G3, [(-0.5, 0, 0)], order=1)([(0.5, 0, 0)])[0]
    for tol in (1e-10 * grid.spacing, None):
        u = ts.solve(ts.surfaces.Sphere(0.5 * s), grid, [(-0.5 * s, 0, 0)], tol=tol, order=1)([(0.5 * s, 0, 0)])[0]
        assert abs(u / s - u1) < 1e-6


@pytest.mark.parametrize(
    "value, match, at_node",
    [
        (np.nan, "speed is nan", "speed is NaN or inf at"),
        (-1.0, "speed is -1.0", "speed must be positive; got -1 at"),
        (0.0, "speed is 0.0", "speed must be positive; got 0 at"),
    ],
)
def test_a_speed_callable_is_checked_at_the_source_too(value, match, at_node):
    # the callable is also evaluated at the source and at closest points, which used to go unchecked
    def bad_at(source):
        return lambda p: np.where(np.linalg.norm(p - source, axis=1) < 1e-12, value, 1.0)

    # a source between the nodes: only the source's own value is bad
    source = 0.5 * np.array([-np.cos(0.3), np.sin(0.3), 0.0])
    with pytest.raises(ValueError, match=match):
        ts.solve(SPHERE, G3, [tuple(source)], speed=bad_at(source))
    # on a node of the surface: the nodes' own values are read at their closest points, and that
    # node's meets it first
    with pytest.raises(ValueError, match=at_node + r" \(-0\.5, 0\.0, 0\.0\)"):
        ts.solve(SPHERE, G3, [(-0.5, 0, 0)], speed=bad_at(np.array([-0.5, 0, 0])))

    def speed2(p):
        return np.where(np.linalg.norm(p - [0.013, 0.011], axis=1) < 1e-12, value, 1.0)

    with pytest.raises(ValueError, match=match):
        ts.travel_time(G2, [(0.013, 0.011)], speed=speed2)


def test_a_grid_too_coarse_for_the_surface_is_refused():
    # at N = 4 every band node lay within two spacings of the source and was fixed to the chord:
    # u(0.5, 0, 0) = 0.876 against pi/2, reported converged
    with pytest.raises(ValueError, match="too coarse"):
        ts.solve(SPHERE, ts.Grid((-1,) * 3, (1,) * 3, (4,) * 3), [(-0.5, 0, 0)])


@pytest.mark.parametrize(
    "surface", [ts.surfaces.Disc(radius=1e-3), ts.surfaces.PlanePatch(half_size=1e-3), ts.surfaces.Disc(radius=0.04)]
)
def test_an_open_surface_smaller_than_two_cells_is_refused(surface):
    # a disc of radius 0.02 h with sources at its rim gave distances 29% short (0.5 h: 15%),
    # with no warning; from a radius of one spacing on it is within the coarse grid's error
    grid = ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3)
    with pytest.raises(ValueError, match="too coarse for this surface: the surface spans only"):
        ts.solve(surface, grid, [(1e-3, 0, 0), (-1e-3, 0, 0)])
    with pytest.raises(ValueError, match="spans only"):
        ts.Tube(surface, grid)
    r = grid.spacing
    sol = ts.solve(ts.surfaces.Disc(radius=r), grid, [(r, 0, 0), (-r, 0, 0)])
    assert abs(sol([(0, r, 0)])[0] - np.sqrt(2) * r) < 0.02 * r


def test_threads_beyond_the_cores_run_on_all_cores():
    # threads=100000 used to start OS threads for minutes; the bits are those of any thread count
    a = ts.solve(SPHERE, G3, [(-0.5, 0, 0)], threads=100_000).values
    assert np.array_equal(a, ts.solve(SPHERE, G3, [(-0.5, 0, 0)], threads=1).values)
    with pytest.raises(ValueError, match="threads"):
        ts.solve(SPHERE, G3, [(-0.5, 0, 0)], threads=True)


def test_the_grid_tied_tolerance_and_many_seeds_are_accepted():
    # the README's tol = 1e-3 h at a high speed, and 40 seeds that fix every inner node of a circle
    g = ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3)
    fast = ts.solve(SPHERE, g, [(-0.5, 0, 0)], speed=100.0, tol=1e-3 * g.spacing, order=1)([(0.5, 0, 0)])[0]
    slow = ts.solve(SPHERE, g, [(-0.5, 0, 0)], order=1)([(0.5, 0, 0)])[0]
    assert abs(100 * fast - slow) < 1e-3
    t = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    seeds = 0.5 * np.c_[np.cos(t), np.sin(t)]
    sol = ts.solve(ts.surfaces.Circle(0.5), ts.Grid((-1, -1), (1, 1), (101, 101)), seeds)
    assert len(set(sol.nearest_source().tolist())) == 40


def test_mobius_newton_iterations_are_bounded():
    with pytest.raises(ValueError, match="newton_iterations"):
        ts.surfaces.MobiusBand(newton_iterations=10**12)


def test_a_surface_smaller_than_the_tube_says_to_refine_the_grid():
    # the library's exact distance was refused as "not close to a signed distance function" with
    # redistancing as the only advice, which then failed the same way
    with pytest.raises(ValueError, match="refine the grid"):
        ts.solve(ts.surfaces.Sphere(0.05), G3, [(-0.05, 0, 0)])


@pytest.mark.parametrize(
    "make",
    [
        lambda: ts.surfaces.Sphere(0.5, center=(np.nan, 0, 0)),
        lambda: ts.surfaces.Circle(center=(np.nan, 0)),
        lambda: ts.surfaces.Sphere(0.5, center=(0, 0)),
        lambda: ts.surfaces.Torus(center=(0, 0, np.inf)),
        lambda: ts.surfaces.Ellipsoid(center=(0, 0, np.nan)),
        lambda: ts.surfaces.RoundedCube(center=(np.nan, 0, 0)),
        lambda: ts.surfaces.Ellipse(center="ab"),
    ],
)
def test_surface_centres_must_be_finite_coordinates(make):
    # a NaN centre gave "the band is empty ... check that the surface passes through the grid"
    with pytest.raises(ValueError, match="center must be [23] finite coordinates"):
        make()


def test_a_band_too_large_for_the_memory_is_refused_before_the_search():
    # at N = 100000 the sphere's band (6e10 nodes) was searched until the Rust allocator aborted
    # the process (or, for the hemisphere, NumPy raised from deep inside the search)
    huge3 = ts.Grid((-1,) * 3, (1,) * 3, (100_000,) * 3)
    for surface in (SPHERE, ts.surfaces.Hemisphere(0.5), ts.LevelSet(lambda p: np.linalg.norm(p, axis=1) - 0.5)):
        with pytest.raises(MemoryError, match="the band .* needs about .* GiB"):
            ts.solve(surface, huge3, [(-0.5, 0, 0)])
    with pytest.raises(MemoryError, match="coarser grid"):
        ts.Tube(SPHERE, huge3)
    with pytest.raises(MemoryError, match="the band"):
        ts.solve(ts.surfaces.Circle(0.5), ts.Grid((-1, -1), (1, 1), (10**9, 10**9)), [(-0.5, 0)])


@pytest.mark.parametrize(
    "surface, grid",
    [
        (SPHERE, ts.Grid((-1,) * 3, (1,) * 3, (161,) * 3)),
        (ts.surfaces.Torus(0.5, 0.25), ts.Grid((-1,) * 3, (1,) * 3, (121,) * 3)),
        (ts.surfaces.Hemisphere(0.5), ts.Grid((-1,) * 3, (1,) * 3, (121,) * 3)),
        (ts.surfaces.Circle(0.5), ts.Grid((-1, -1), (1, 1), (401, 401))),
    ],
)
def test_the_memory_check_s_band_estimate_is_close_to_the_band(surface, grid):
    from tubesweep._prepare import _estimated_band_nodes

    sol = ts.solve(surface, grid, [surface.default_source])
    estimate = _estimated_band_nodes(surface, grid, 4 * grid.spacing)
    assert 0.7 < estimate / sol.stats.band_points < 1.3, (estimate, sol.stats.band_points)


def test_grid_shapes_are_whole_numbers_and_flags_are_booleans():
    with pytest.raises(TypeError, match="shape must be a sequence of whole numbers"):
        ts.Grid((-1, -1), (1, 1), "abc")
    for shape in [(31.7, 31), (True, 31)]:
        with pytest.raises(ValueError, match="shape must hold whole numbers"):
            ts.Grid((-1, -1), (1, 1), shape)
    assert ts.Grid((-1, -1), (1, 1), (31.0, np.int64(31))).shape == (31, 31)
    with pytest.raises(TypeError, match="lower and upper"):
        ts.Grid((-1 + 1j, -1), (1, 1), (31, 31))
    with pytest.raises(TypeError, match="paper_sweeps must be True or False"):
        ts.solve(SPHERE, G3, [(-0.5, 0, 0)], paper_sweeps="no")


def test_the_band_estimate_survives_a_closest_point_map_undefined_far_from_the_surface():
    from tubesweep._prepare import _estimated_band_nodes

    def cp(x):  # the upper hemisphere, NaN on the axis below it and at the centre (far from it)
        with np.errstate(invalid="ignore", divide="ignore"):
            up = 0.5 * x / np.linalg.norm(x, axis=1, keepdims=True)
            rim = np.c_[0.5 * x[:, :2] / np.linalg.norm(x[:, :2], axis=1, keepdims=True), 0 * x[:, 2]]
        return np.where(x[:, 2:] >= 0, up, rim)

    g = ts.Grid((-1,) * 3, (1,) * 3, (801,) * 3)
    est = _estimated_band_nodes(ts.ClosestPoint(cp), g, 4 * g.spacing)
    exact = _estimated_band_nodes(ts.surfaces.Hemisphere(0.5), g, 4 * g.spacing)
    assert est == 0.0 or 0.5 < est / exact < 2.0


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda: ts.solve(ts.LevelSet(np.zeros((31,) * 3) + 0j), G3, [(-0.5, 0, 0)]), "phi array"),
        (
            lambda: ts.solve(ts.LevelSet(lambda p: np.linalg.norm(p, axis=1) - 0.5 + 0j), G3, [(-0.5, 0, 0)]),
            "phi callable",
        ),
        (lambda: ts.solve(SPHERE, G3, np.array([(-0.5 + 0j, 0, 0)])), "sources"),
        (lambda: ts.solve(SPHERE, G3, [(-0.5, 0, 0)], speed=np.ones(G3.shape) + 0j), "speed array"),
        (lambda: ts.solve(SPHERE, G3, [(-0.5, 0, 0)], speed=lambda p: np.ones(len(p)) + 0j), "speed callable"),
        (lambda: ts.solve(SPHERE, G3, [(-0.5, 0, 0)], hamiltonian=ts.hamiltonians.Metric(np.eye(3) + 0j)), "M"),
        (lambda: ts.solve(SPHERE, G3, [(-0.5, 0, 0)])(np.array([(0.5 + 0j, 0, 0)])), "points"),
    ],
)
def test_complex_input_is_refused_not_cut_to_its_real_part(call, name):
    # NumPy dropped the imaginary parts with only a ComplexWarning
    with pytest.raises(TypeError, match=f"{name}.* must hold real numbers"):
        call()


def test_surface_lengths_and_tube_widths_are_real_numbers():
    # Sphere('0.5') raised "'>' not supported between str and int"; True was a radius of 1 and
    # inner=True a tube of one spacing
    for bad in ("0.5", 0.5j, True, [0.5]):
        with pytest.raises(TypeError, match="radius must be a positive real number"):
            ts.surfaces.Sphere(bad)
    for bad in (-1, 0, np.inf, np.nan):
        with pytest.raises(ValueError, match="radius must be positive and finite"):
            ts.surfaces.Sphere(bad)
    with pytest.raises(ValueError, match="R must be positive and finite"):
        ts.surfaces.Torus(R=np.inf, r=0.2)
    with pytest.raises(TypeError, match="half_size must be a positive real number"):
        ts.surfaces.PlanePatch(half_size="big")
    with pytest.raises(TypeError, match="b must be a positive real number"):
        ts.surfaces.Ellipsoid(0.5, None, 0.3)
    assert ts.surfaces.Sphere(np.float32(0.5)).radius == 0.5
    with pytest.raises(ValueError, match="inner must be a finite number"):
        ts.solve(SPHERE, G3, [(-0.5, 0, 0)], inner=True)


def test_travel_times_too_large_to_square_are_refused():
    # at speed 1e-200 the squared travel times overflowed: travel_time returned 1/20 of the answer,
    # reported converged, and solve ran 10,001 iterations
    with pytest.raises(ValueError, match="too large to compute"):
        ts.travel_time(G2, [(0, 0)], speed=1e-200)
    with pytest.raises(ValueError, match="too large to compute"):
        ts.solve(SPHERE, G3, [(-0.5, 0, 0)], speed=1e-200)


def test_the_solution_keeps_its_own_copy_of_the_sources():
    src = np.array([[-0.5, 0, 0.0], [0.5, 0, 0]])
    sol = ts.solve(SPHERE, G3, src)
    src[:] = 0.0
    assert np.array_equal(sol.sources, [[-0.5, 0, 0], [0.5, 0, 0]])


def test_a_tube_refuses_to_solve_after_its_phi_array_changed():
    x = np.stack(G3.meshgrid(), -1)
    phi = np.linalg.norm(x, axis=-1) - 0.5
    tube = ts.Tube(phi, G3)
    tube.solve([(-0.5, 0, 0)])
    phi -= 0.2  # a source at the new surface was accepted on the old band
    with pytest.raises(ValueError, match="was changed after the Tube was built"):
        tube.solve([(-0.7, 0, 0)])


def test_a_solution_refuses_paths_after_its_phi_array_changed():
    x = np.stack(G3.meshgrid(), -1)
    phi = np.linalg.norm(x, axis=-1) - 0.5
    sol = ts.solve(phi, G3, [(-0.5, 0, 0)])
    assert len(sol.geodesic_path((0.5, 0, 0))) > 2
    phi -= 0.2  # the paths would be projected onto the new surface, r = 0.7, far from the band's
    with pytest.raises(ValueError, match="was changed after the solve"):
        sol.geodesic_path((0.5, 0, 0))
    # a copy leaves the solution free of the caller's array
    phi2 = np.linalg.norm(x, axis=-1) - 0.5
    sol2 = ts.solve(ts.LevelSet(phi2.copy()), G3, [(-0.5, 0, 0)])
    phi2 -= 0.2
    assert len(sol2.geodesic_path((0.5, 0, 0))) > 2


@pytest.mark.parametrize(
    "call, error, match",
    [
        (lambda: ts.solve(SPHERE, G3, [(-0.5, 0, 0)], speed=np.complex128(2 + 1j)), TypeError, "speed must be a real"),
        (lambda: ts.hamiltonians.Isotropic(sigma=np.array([1.5 + 1j] * 3)), TypeError, "sigma must hold real"),
        (
            lambda: ts.flows.point_vortices(np.array([[0.5, 0, 0]]), np.array([0.1 + 1j])),
            TypeError,
            "strengths must hold",
        ),
        (lambda: ts.surfaces.Star("0.5"), TypeError, "r0 must be a positive real"),
        (lambda: ts.surfaces.Star(np.inf), ValueError, "r0 must be positive and finite"),
        (lambda: ts.surfaces.Star(0.5, eps=-1), ValueError, "eps must be"),
        (
            lambda: ts.LevelSet(lambda p: p[:, 0], lipschitz=np.complex128(1 + 1j)),
            TypeError,
            "lipschitz must be a real",
        ),
        (lambda: ts.solve(SPHERE, G3, {"a": 1}), TypeError, r"sources must be an array-like of shape \(M, 3\)"),
        (lambda: ts.surfaces.Sphere(10**400), ValueError, "radius must be positive and finite"),
        (
            lambda: ts.solve(SPHERE, G3, [(-0.5, 0, 0)], hamiltonian=ts.hamiltonians.Metric(np.diag([1e30, 1, 1]))),
            ValueError,
            "numerically singular",
        ),
    ],
)
def test_more_bad_arguments_name_themselves(call, error, match):
    with pytest.raises(error, match=match):
        call()


@pytest.mark.parametrize("bad", [True, "2", [2.0], 2 + 0j, -1.0])
def test_infinity_is_checked_whichever_order_runs(bad):
    # the default order="auto" runs second order, which has no use for infinity: a bad value is
    # still refused, by ts.solve and Tube.solve alike
    grid = ts.Grid((-1, -1, -1), (1, 1, 1), (21, 21, 21))
    with pytest.raises((TypeError, ValueError), match="infinity must be"):
        ts.solve(ts.surfaces.Sphere(0.5), grid, [(0, 0, 0.5)], infinity=bad)
    with pytest.raises((TypeError, ValueError), match="infinity must be"):
        ts.Tube(ts.surfaces.Sphere(0.5), grid).solve([(0, 0, 0.5)], infinity=bad)


def test_warm_refused_is_checked_without_warm():
    grid = ts.Grid((-1, -1, -1), (1, 1, 1), (21, 21, 21))
    with pytest.raises(ValueError, match="warm_refused must be 'raise'"):
        ts.solve(ts.surfaces.Sphere(0.5), grid, [(0, 0, 0.5)], warm_refused="ignore")


@pytest.mark.parametrize(
    "name, call",
    [
        ("signed", lambda v: ts.surfaces.from_mesh(_tetra(), signed=v)),
        ("normalize", lambda v: ts.surfaces.from_mesh(_tetra(), normalize=v)),
        ("redistance", lambda v: ts.LevelSet(lambda p: np.linalg.norm(p, axis=1) - 0.5, redistance=v)),
        ("allow_supersonic", lambda v: ts.solve(ts.surfaces.Circle(0.5), _G2, [(0.5, 0)], allow_supersonic=v)),
        ("return_stats", lambda v: ts.travel_time(_G2, [(0, 0)], return_stats=v)),
        ("return_solution", lambda v: ts.travel_time(_G2, [(0, 0)], return_solution=v)),
        ("return_stats", lambda v: ts.Tube(ts.surfaces.Circle(0.5), _G2).solve_many([(0.5, 0)], return_stats=v)),
        ("info", lambda v: ts.distance_matrix(ts.surfaces.Circle(0.5), _G2, [(0.5, 0), (-0.5, 0)], info=v)),
    ],
)
def test_yes_no_options_refuse_other_values_by_name(name, call):
    # a truthy string was taken for True: from_mesh(signed='no') signed the mesh, LevelSet(φ,
    # redistance='no') re-distanced, travel_time(return_stats='no') returned a tuple
    for bad in ("no", 1, None):
        if bad is None and name == "signed":
            continue  # signed=None: as the mesh is (closed or not)
        with pytest.raises(TypeError, match=rf"{name} must be True or False"):
            call(bad)


_G2 = ts.Grid((-1, -1), (1, 1), (41, 41))


def _tetra():
    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    return v, np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def test_a_vertex_index_as_a_source_points_to_the_vertex_s_coordinates():
    g = ts.Grid((-1,) * 3, (1,) * 3, (21,) * 3)
    with pytest.raises(ValueError, match=r"got shape \(1,\) \(to start at vertex i of a mesh .*surface\.vertices\[i\]"):
        ts.solve(ts.surfaces.Sphere(0.5), g, [4])
    with pytest.raises(ValueError, match=r"got shape \(2,\)$"):  # not whole numbers: no such note
        ts.solve(ts.surfaces.Sphere(0.5), g, [0.5, 0.1])


def test_a_callable_phi_undefined_over_a_region_that_reaches_the_surface_is_named():
    # NaN for x > 0.3: four widenings of the extension layer, then "φ is far from a distance
    # function", NaN never mentioned
    def phi(p):
        return np.where(p[:, 0] > 0.3, np.nan, np.linalg.norm(p, axis=1) - 0.5)

    with pytest.raises(ValueError, match=r"phi callable returned NaN or inf at \(0\.3"):
        ts.solve(phi, G3, [(-0.5, 0, 0)])


def test_a_solution_or_an_array_in_the_wrong_place_and_a_wide_tube_are_named():
    # a review: a Solution as the surface read as "phi callable returned NaN or inf", an array
    # where a tube's grid goes as numpy's "truth value of an array is ambiguous", and a tube too
    # wide for the sphere was told only to refine the grid
    g = ts.Grid((-1,) * 3, (1,) * 3, (31,) * 3)
    sphere = ts.surfaces.Sphere(0.5)
    sol = ts.solve(sphere, g, [(0.5, 0, 0)])
    with pytest.raises(TypeError, match=r"surface is a Solution \(a solve's result\).*sol\.surface"):
        ts.solve(sol, g, [(0.5, 0, 0)])
    tube = ts.Tube(sphere, g)
    points = 0.5 * np.eye(3)
    with pytest.raises(TypeError, match=r"grid must be a ts\.Grid or None .* got ndarray.*farthest_point_sampling\(tube, None, k\)"):  # fmt: skip
        ts.farthest_point_sampling(tube, points, 4)
    with pytest.raises(TypeError, match=r"grid must be a ts\.Grid or None .* got ndarray"):
        ts.distance_matrix(tube, points, points)
    with pytest.raises(
        ValueError,
        match=r"refine the grid, or narrow the tube \(its band reaches 30 grid spacings .*4 by default, set by outer=",
    ):
        ts.solve(sphere, g, [(0.5, 0, 0)], outer=30)
    with pytest.raises(ValueError, match=r"refine the grid, or narrow the tube \(its band reaches 30 grid spacings"):
        ts.solve(lambda p: np.linalg.norm(p, axis=1) - 0.5, g, [(0.5, 0, 0)], outer=30)


def test_a_second_order_solution_refuses_values_near_a_source_after_its_phi_array_changed():
    x = np.stack(G3.meshgrid(), -1)
    phi = np.linalg.norm(x, axis=-1) - 0.5
    sol = ts.solve(phi, G3, [(-0.5, 0, 0)])
    near = [(-0.5 * np.cos(0.05), 0.5 * np.sin(0.05), 0.0)]  # exactly 0.025 from the source
    assert sol.stats.order == 2 and abs(sol(near)[0] - 0.025) < 1e-4
    phi[...] = np.linalg.norm(x - [0.2, 0, 0], axis=-1) - 0.5  # a buffer reused: read 0.20 here, silently
    for interpolation in ("linear", "cubic"):
        with pytest.raises(ValueError, match="was changed after the solve"):
            sol(near, interpolation=interpolation)
    first = ts.solve(ts.LevelSet(phi.copy()), G3, [(-0.3, 0, 0)], order=1)  # no projection: free to change
    before = first(near)
    phi -= 0.1
    assert np.array_equal(first(near), before, equal_nan=True)


@pytest.mark.parametrize("as_array", [True, False])
def test_a_phi_without_a_zero_level_set_is_named_so(as_array):
    x = np.stack(G3.meshgrid(), -1)
    phi = np.linalg.norm(x, axis=-1) + 0.1  # positive everywhere: no surface
    surface = ts.LevelSet(phi) if as_array else (lambda p: np.linalg.norm(p, axis=1) + 0.1)
    with pytest.raises(ValueError, match=r"φ has no zero level set on the grid: it is > 0 at every node"):
        ts.solve(surface, G3, [(-0.5, 0, 0)])
    with pytest.raises(ValueError, match=r"it is < 0 at every node"):
        ts.solve(ts.LevelSet(-phi) if as_array else (lambda p: -np.linalg.norm(p, axis=1) - 0.1), G3, [(-0.5, 0, 0)])


def test_a_phi_callable_that_is_nowhere_finite_and_a_mask_path_are_named():
    # "the band is empty ... check that the surface passes through the grid", and "mask has shape ()"
    with pytest.raises(ValueError, match=r"the φ callable returned NaN or inf at every point of a 5\^3 lattice"):
        ts.solve(lambda p: np.full(len(p), np.nan), G3, [(0.5, 0, 0)])
    with pytest.raises(TypeError, match=r"mask must be an array of the grid's shape; got the path 'mask.npy'"):
        ts.LevelSet.from_mask("mask.npy", G3)


def test_sources_of_true_and_false_are_refused():
    # taken as 1.0 and 0.0 (Grid refuses bools): a helper's review
    with pytest.raises(TypeError, match="sources must hold coordinates"):
        ts.solve(ts.surfaces.Sphere(0.5), G3, [(True, False, False)])
    with pytest.raises(TypeError, match="sources must hold coordinates"):
        ts.solve(ts.surfaces.Sphere(0.5), G3, np.array([[True, False, False]]))


def test_a_negative_linear_index_is_named_as_such():
    # reported as "linear index 18446744073709551615" (its uint64 view): a helper's review
    with pytest.raises(
        ValueError, match=r"linear indices must lie in \[0, 125\) \(grid.size\): -1 is outside the grid"
    ):
        ts.Grid((-1,) * 3, (1,) * 3, (5,) * 3).node_points([-1])


def test_masked_arrays_with_masked_entries_are_refused_naming_the_argument():
    # np.asarray drops a mask: a speed masked where it was set to 0.01 was taken as 0.01 there
    # (35 instead of 0.785), a masked source row used as a point (a review)
    g = ts.Grid((-1,) * 3, (1,) * 3, (21,) * 3)
    x = np.stack(g.meshgrid(), -1)
    sphere = ts.surfaces.Sphere(0.5)
    speed = np.ma.masked_array(np.ones(g.shape), mask=x[..., 2] > 0.3)
    with pytest.raises(ValueError, match=r"speed array is a masked array with \d+ masked entries.*speed.filled"):
        ts.solve(sphere, g, [(0, 0, 0.5)], speed=speed)
    points = np.ma.masked_array(0.5 * np.eye(3), mask=[[0, 0, 0], [1, 1, 1], [0, 0, 0]])
    with pytest.raises(ValueError, match=r"sources is a masked array with 3 masked entries"):
        ts.solve(sphere, g, points)
    phi = np.ma.masked_array(np.linalg.norm(x, axis=-1) - 0.5, mask=x[..., 0] > 0.9)
    with pytest.raises(ValueError, match=r"phi array is a masked array"):
        ts.LevelSet(phi)
    # nothing masked: taken as the plain array
    assert ts.solve(sphere, g, np.ma.masked_array([[0.0, 0.0, 0.5]])).stats.converged
