"""Hostile input, one test per class of issue 35 (sizes, numeric range, callables, mesh files,
messages on valid input). ``benches/hostile_inputs.py`` runs the whole battery, each case in its
own process."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import tubesweep as ts
import tubesweep._native as N
from tubesweep._validate import ArgumentTypeError

G2 = ts.Grid((-1, -1), (1, 1), (41, 41))
G3 = ts.Grid((-1,) * 3, (1,) * 3, (31,) * 3)
SPHERE = ts.surfaces.Sphere(0.5)


def _sphere_cp(x):
    return 0.5 * x / np.maximum(np.linalg.norm(x, axis=1, keepdims=True), 1e-300)


# ------------------------------------------------------------------------------------ 1. sizes
@pytest.mark.parametrize("shape", [(2**21,) * 3, (2**21 + 1,) * 3, (2**40, 2**40), (2**64, 3), (2**63, 3)])
def test_grids_of_2_63_nodes_or_more_are_refused_without_wrapping(shape):
    # (2^21)^3 = 2^63 wrapped to a negative int64 size, and the memory guard passed it
    with pytest.raises(ValueError, match="at most 2\\^63 - 1"):
        ts.Grid((0,) * len(shape), (1,) * len(shape), shape)


def test_grid_sizes_are_python_integers():
    g = ts.Grid((0,) * 3, (1,) * 3, (2**21 - 1,) * 3)
    assert g.size == (2**21 - 1) ** 3 and isinstance(g.size, int)


@pytest.mark.parametrize("shape", [[2**40, 2**40], [2**63, 2**63, 3], [2**21] * 3])
def test_the_core_refuses_shapes_whose_product_overflows(shape):
    # full_box([2^40, 2^40]) aborted the process (the product wrapped, then a 2^40-row allocation)
    for build in (lambda: N.Band.full_box(shape), lambda: N.Band.from_linear(shape, np.arange(3, dtype=np.uint64))):
        with pytest.raises(ValueError, match="2\\^63"):
            build()


def test_the_memory_guard_runs_before_the_box_or_a_dense_copy_is_allocated():
    with pytest.raises(MemoryError, match="GiB"):
        ts.travel_time(ts.Grid((0,) * 3, (1,) * 3, (60000,) * 3), [(0.5, 0.5, 0.5)])
    big = ts.Grid((-1,) * 3, (1,) * 3, (4001,) * 3)  # a small band, a box of 6.4e10 nodes
    sol = ts.solve(ts.surfaces.Sphere(0.01), big, [(0.01, 0, 0)])
    with pytest.raises(MemoryError, match="dense"):
        sol.to_dense()


def test_the_band_estimate_of_a_mesh_too_coarse_for_its_smooth_map_still_guards_memory():
    # a cube of 12 triangles: the smooth map's fits need 22 samples, the estimate failed and was
    # skipped, and n = 3000 aborted the process in an allocation (a helper's review)
    v = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1]])
    f = np.concatenate([f, [[2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]])
    cube = ts.surfaces.from_mesh((v, f))
    with pytest.raises(MemoryError, match=r"the band \(about .* nodes"):
        ts.solve(cube, cube.grid(n=40000), [v[0]])


def test_the_memory_guard_reads_the_process_s_address_space_limit():
    # under ulimit -v the machine's free memory is not what the process can get: a sphere at
    # N = 4000 aborted in an allocation under an 8 GB limit with 23 GB free (a helper's review)
    import subprocess
    import sys

    code = (
        "import resource\n"
        "from tubesweep._validate import available_memory_bytes\n"
        "size = int(open('/proc/self/status').read().split('VmSize:')[1].split()[0]) * 1024\n"
        "resource.setrlimit(resource.RLIMIT_AS, (size + 2**30, resource.getrlimit(resource.RLIMIT_AS)[1]))\n"
        "print(available_memory_bytes())\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert 0 < int(out) <= 2**30


# ----------------------------------------------------------------------------- 2. numeric range
@pytest.mark.parametrize("infinity", [1e101, 1e155, 1e308, np.inf, np.nan, 0.0, -1.0])
def test_an_infinity_out_of_range_is_refused(infinity):
    # 1e155 and above: the Lax–Friedrichs squares overflowed, every node inf, converged=True
    with pytest.raises(ValueError, match="infinity must be a positive finite number up to 1e\\+100"):
        ts.solve(SPHERE, G3, [(0.5, 0, 0)], hamiltonian="lxf", infinity=infinity)


@pytest.mark.parametrize(
    "solve",
    [
        lambda inf: ts.solve(SPHERE, G3, [(0.5, 0, 0)], infinity=inf, order=1),
        lambda inf: ts.solve(SPHERE, G3, [(0.5, 0, 0)], hamiltonian="lxf", infinity=inf),
        lambda inf: ts.Tube(SPHERE, G3).solve([(0.5, 0, 0)], infinity=inf, order=1),
        lambda inf: ts.travel_time(G2, [(0.1, 0.2)], infinity=inf),
    ],
)
@pytest.mark.parametrize("infinity", [1.0, 0.5, 1e-300])
def test_an_infinity_below_the_travel_times_is_refused_after_the_sweeps(solve, infinity):
    # infinity=0.5 stopped the front there: 7,830 nodes inf and 0.17 errors at finite ones,
    # converged=True
    with pytest.raises(ValueError, match="is not above the travel times"):
        solve(infinity)


def test_an_infinity_above_the_travel_times_gives_the_default_s_values():
    ref = ts.solve(SPHERE, G3, [(0.5, 0, 0)], hamiltonian="lxf")
    sol = ts.solve(SPHERE, G3, [(0.5, 0, 0)], hamiltonian="lxf", infinity=1e100)
    assert np.max(np.abs(sol.values - ref.values)) < 1e-8


@pytest.mark.parametrize("speed", [1e-101, 1e-200, 1e101, 1e300])
def test_travel_times_outside_1e_minus_100_to_1e100_are_refused(speed):
    # at speed 1e300 the squares underflowed: 15x short, with only a convergence warning
    with pytest.raises(ValueError, match="travel times of this problem are too (large|small)"):
        ts.travel_time(G2, [(0.0, 0.0)], speed=speed, tol=1e-10 / speed)


@pytest.mark.parametrize("speed", [1e-90, 1e90])
def test_extreme_speeds_within_range_give_the_same_digits(speed):
    ref = ts.travel_time(G2, [(0.0, 0.0)])
    u = ts.travel_time(G2, [(0.0, 0.0)], speed=speed, tol=1e-10 / speed)
    assert np.max(np.abs(u * speed - ref)) < 1e-8


@pytest.mark.parametrize(
    "lower, upper, match",
    [
        ((-1e60,) * 2, (1e60,) * 2, "within ±1e\\+30"),  # φ overflowed float32
        ((-1e308,) * 2, (1e308,) * 2, "within ±1e\\+30"),  # upper − lower overflowed: spacing inf
        ((0, 0), (1e-200, 1e-200), "below 1e-30"),
        ((1e9, 1e9), (1e9 + 1e-6, 1e9 + 1e-6), "below the resolution of its coordinates"),
    ],
)
def test_grids_beyond_the_float_range_or_resolution_are_refused(lower, upper, match):
    # 1e9 + 1e-6 / 40: the spacing came out 2.38e-8 instead of 2.5e-8, silently
    with pytest.raises(ValueError, match=match):
        ts.Grid(lower, upper, (41, 41))


@pytest.mark.parametrize("scale", [1e-25, 1e25])
def test_grids_in_other_units_give_the_same_digits(scale):
    ref = ts.solve(SPHERE, G3, [(0.5, 0, 0)], order=1)
    g = ts.Grid((-scale,) * 3, (scale,) * 3, (31,) * 3)
    sol = ts.solve(ts.surfaces.Sphere(0.5 * scale), g, [(0.5 * scale, 0, 0)], tol=1e-10 * scale, order=1)
    assert sol.stats.converged and np.max(np.abs(sol.values / scale - ref.values)) < 1e-9


# --------------------------------------------------------------------------------- 3. callables
_MUTATIONS = [lambda x: x.__setitem__(slice(None), 0.0), lambda x: x.__iadd__(0.1), lambda x: x.__imul__(np.nan)]


@pytest.mark.parametrize("mutate", _MUTATIONS)
def test_callables_that_modify_their_argument_change_nothing(mutate):
    def phi(x):
        v = np.linalg.norm(x, axis=1) - 0.5
        mutate(x)
        return v

    def cp(x):
        c = _sphere_cp(x)
        mutate(x)
        return c

    def speed(x):
        v = np.ones(len(x))
        mutate(x)
        return v

    ref_phi = ts.solve(lambda x: np.linalg.norm(x, axis=1) - 0.5, G3, [(0.5, 0, 0)]).values
    assert np.array_equal(ts.solve(phi, G3, [(0.5, 0, 0)]).values, ref_phi)
    ref_cp = ts.solve(ts.ClosestPoint(_sphere_cp), G3, [(0.5, 0, 0)]).values
    assert np.array_equal(ts.solve(ts.ClosestPoint(cp), G3, [(0.5, 0, 0)]).values, ref_cp)
    sol = ts.solve(SPHERE, G3, [(0.5, 0, 0)], speed=speed)
    assert np.array_equal(sol.values, ts.solve(SPHERE, G3, [(0.5, 0, 0)], speed=lambda x: np.ones(len(x))).values)
    assert np.array_equal(sol.sources, [(0.5, 0, 0)])
    assert np.array_equal(ts.travel_time(G2, [(0.1, 0.2)], speed=speed), ts.travel_time(G2, [(0.1, 0.2)]))


def test_callables_returning_views_or_integers_are_copied_as_floats():
    def cp_view(x):
        x[:] = _sphere_cp(x)
        return x

    ref = ts.solve(ts.ClosestPoint(_sphere_cp), G3, [(0.5, 0, 0)]).values
    assert np.array_equal(ts.solve(ts.ClosestPoint(cp_view), G3, [(0.5, 0, 0)]).values, ref)
    two = ts.solve(SPHERE, G3, [(0.5, 0, 0)], speed=lambda x: np.full(len(x), 2, dtype=np.int64)).values
    assert np.array_equal(two, ts.solve(SPHERE, G3, [(0.5, 0, 0)], speed=2.0).values)


@pytest.mark.parametrize(
    "cp, match",
    [
        (lambda x: x.copy(), "returns its argument"),
        (lambda x: x + 0.001, "returns its argument"),
        (lambda x: _sphere_cp(x) + 0.3, "do not lie on a surface|not a closest-point map near the surface"),
        (lambda x: x + 5.0, "do not lie on a surface"),
        (lambda x: -_sphere_cp(x), "not a closest-point map"),
        (lambda x: np.tile([0.5, 0.0, 0.0], (len(x), 1)), "single point"),
    ],
)
def test_maps_that_are_not_closest_point_maps_are_refused(cp, match):
    # the identity made the whole box the band and returned Euclidean distances, converged
    with pytest.raises(ValueError, match=match):
        ts.solve(ts.ClosestPoint(cp), G3, [(0.5, 0, 0)])


@pytest.mark.parametrize("eps", [1e-3, 1e-2, 3e-2])
def test_a_slightly_noisy_closest_point_map_is_not_read_as_facing_sheets(eps):
    # noise of 0.01 spacings gave 13 facing pairs and the "faces itself across gaps" warning
    rng = np.random.default_rng(0)
    h = G3.spacing
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        sol = ts.solve(
            ts.ClosestPoint(lambda x: _sphere_cp(x) + eps * h * rng.standard_normal(x.shape)), G3, [(0.5, 0, 0)]
        )
    assert sol.stats.facing_pairs == 0


# -------------------------------------------------------------------------------- 4. mesh files
TETRA = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"


@pytest.mark.parametrize(
    "text",
    [
        "  " + TETRA.replace("\n", "\n\t "),  # indented with spaces and tabs (the default reader refused it)
        TETRA.replace(" ", " \t  "),
        TETRA.replace("\n", "  # comment\n"),
        TETRA.replace("\n", "\r\n"),
        TETRA.replace("f 1 3 2", "f 1/1/1 3//2 2/5"),
        TETRA.replace("f 1 3 2", "f -4 -2 -3"),
    ],
)
def test_loosely_written_obj_files_are_read_whole(tmp_path, text):
    p = tmp_path / "t.obj"
    p.write_text(text)
    m = ts.surfaces.from_mesh(p)
    assert m.vertices.shape == (4, 3) and len(m.faces) == 4 and m.closed


def test_records_that_cannot_be_used_are_counted(tmp_path):
    p = tmp_path / "t.obj"
    p.write_text(TETRA + "f 1 2\nf 3\nl 1 2\n")
    with pytest.warns(RuntimeWarning, match="1 line and point elements .* were dropped"):
        with pytest.warns(RuntimeWarning, match="2 face records with fewer than three vertices"):
            v, f = ts.surfaces.mesh.read_mesh(p)
    assert len(f) == 4
    p.write_text("v 0 0\n" + TETRA)
    with pytest.raises(ValueError, match="line 1: a vertex needs three coordinates"):
        ts.surfaces.from_mesh(p)


def test_off_files_check_their_declared_counts(tmp_path):
    p = tmp_path / "t.off"
    p.write_text("OFF # tetra\n4 4 0\n0 0 0\n1 0 0\n\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3 255 0 0\n3 0 3 2\n3 1 2 3\n")
    assert len(ts.surfaces.from_mesh(p).faces) == 4
    p.write_text("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n")
    with pytest.raises(ValueError, match="declares 4 vertices and 4 faces"):
        ts.surfaces.from_mesh(p)


@pytest.mark.parametrize("suffix", [".obj", ".off", ".ply", ".stl"])
def test_files_that_are_not_meshes_are_a_value_error(tmp_path, suffix):
    p = tmp_path / f"x{suffix}"
    p.write_bytes(np.random.default_rng(3).bytes(500))  # trimesh raised ModuleNotFoundError on the STL
    with pytest.raises(ValueError, match="x" + suffix):
        ts.surfaces.from_mesh(p)


def test_bad_vertices_and_repeated_triangles_are_reported(tmp_path):
    p = tmp_path / "t.obj"
    p.write_text(TETRA.replace("v 0 0 1", "v nan 0 1"))
    with pytest.raises(ValueError, match="1 vertices .the first, index 3.*used by 3 faces"):
        ts.surfaces.from_mesh(p)
    p.write_text(TETRA.replace("v 0 0 1", "v 0 0 1e300"))  # an OverflowError before
    with pytest.raises(ValueError, match="within ±1e\\+30"):
        ts.surfaces.from_mesh(p)
    p.write_text(TETRA + "f 1 3 2\nf 4 2 3\n")
    with pytest.warns(RuntimeWarning, match="2 triangles more than once"):
        m = ts.surfaces.from_mesh(p)
    assert len(m.faces) == 4 and m.closed  # the repeats made it open before


# ----------------------------------------------------------------- 5. messages on valid input
def test_an_exact_distance_with_a_thin_extension_layer_is_not_called_a_bad_phi():
    g = ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3)
    X, Y, Z = g.meshgrid()
    with pytest.warns(RuntimeWarning, match="extension layer .outer − inner = 1 grid spacings. is too thin") as seen:
        with pytest.warns(RuntimeWarning, match=r"order='auto' ran the first-order scheme.*pass outer=4"):
            ts.solve(np.sqrt(X**2 + Y**2 + Z**2) - 0.5, g, [(0.5, 0, 0)], outer=3)
    assert not any("not close to a distance" in str(w.message) for w in seen)


def test_phi_undefined_far_from_the_surface_is_accepted():
    X, Y, Z = G3.meshgrid()
    R = np.sqrt(X**2 + Y**2 + Z**2)
    for bad in (np.nan, np.inf):
        phi = np.where(R > 0.9, bad, R - 0.5)
        assert np.array_equal(ts.solve(phi, G3, [(0.5, 0, 0)]).values, ts.solve(R - 0.5, G3, [(0.5, 0, 0)]).values)
    fn = ts.solve(
        lambda p: np.where(np.linalg.norm(p, axis=1) > 0.9, np.nan, np.linalg.norm(p, axis=1) - 0.5), G3, [(0.5, 0, 0)]
    )
    assert np.array_equal(fn.values, ts.solve(lambda p: np.linalg.norm(p, axis=1) - 0.5, G3, [(0.5, 0, 0)]).values)


def test_zero_dimensional_arrays_are_called_zero_dimensional():
    with pytest.raises(ValueError, match="got 0 dimensions"):
        ts.LevelSet(np.array(0.5))
    with pytest.raises(ValueError, match="got \\(\\) .0 dimensions"):
        ts.surfaces.from_mesh((np.array(0.0), np.array(0)))


_TAKE_ARRAYS = [
    lambda v: ts.solve(SPHERE, G3, [(0.5, 0, 0)], speed=v),
    lambda v: ts.travel_time(G2, [(0.0, 0.0)], speed=v),
]


def _with_tol(v):
    return ts.solve(SPHERE, G3, [(0.5, 0, 0)], tol=v)


@pytest.mark.parametrize("bad", [True, np.True_, "2", b"2", None, [[2.0]], 2 + 0j])
@pytest.mark.parametrize(
    "call",
    [
        _with_tol,
        lambda v: ts.solve(SPHERE, G3, [(0.5, 0, 0)], max_iterations=v),
        lambda v: ts.solve(SPHERE, G3, [(0.5, 0, 0)], inner=v),
        lambda v: ts.solve(SPHERE, G3, [(0.5, 0, 0)], threads=v),
        lambda v: ts.Grid((-1, -1), (v, 1), (41, 41)),
        lambda v: ts.Grid((-1, -1), (1, 1), (v, 41)),
    ]
    + _TAKE_ARRAYS,
)
def test_bools_strings_and_sequences_are_refused_alike_as_numbers(call, bad):
    # speed=True and speed="2" solved at speed 1 and 2; inner=True was a ValueError, Sphere(True)
    # a TypeError: now one ArgumentTypeError (a TypeError and a ValueError) everywhere
    if isinstance(bad, list) and call in _TAKE_ARRAYS:
        return  # an array is a speed too (refused for its shape)
    if bad is None and call is _with_tol:
        return  # tol=None is the default (the order's own tolerance)
    with pytest.raises(ArgumentTypeError):
        call(bad)


def test_numpy_scalars_and_zero_dimensional_arrays_are_numbers_everywhere():
    ref = ts.solve(SPHERE, G3, [(0.5, 0, 0)]).values
    # an explicit tol is used as given (the default, None, is the order's own)
    tight = ts.solve(SPHERE, G3, [(0.5, 0, 0)], tol=1e-10).values
    assert np.array_equal(ts.solve(SPHERE, G3, [(0.5, 0, 0)], tol=np.array(1e-10)).values, tight)
    for kw in (
        dict(inner=np.array(2.0)),
        dict(infinity=np.array(100.0)),
        dict(threads=np.array(1)),
        dict(max_iterations=np.int32(10000)),
        dict(speed=np.float32(1.0)),
    ):
        assert np.max(np.abs(ts.solve(SPHERE, G3, [(0.5, 0, 0)], **kw).values - ref)) < 1e-9


@pytest.mark.parametrize("scale", [2.0**-20, 2.0**10, 2.0**20])
def test_order2_in_other_units_gives_the_same_bits(scale):
    # the limiter's ramp (σΔx²/ℓ) and the default tolerances (∝ Δx²σ̄/ℓ) scale with the problem:
    # in units 2^k apart every operation scales exactly, so the values do too
    ref = ts.solve(SPHERE, G3, [(0.5, 0, 0)], order=2)
    g = ts.Grid((-scale,) * 3, (scale,) * 3, (31,) * 3)
    sol = ts.solve(ts.surfaces.Sphere(0.5 * scale), g, [(0.5 * scale, 0, 0)], order=2)
    assert sol.stats.converged and sol.stats.order2["fallback_iteration"] is None
    assert np.array_equal(sol.values / scale, ref.values)


@pytest.mark.parametrize("scale, speed", [(1e3, 1.0), (1e-6, 1.0), (1.0, 1e3), (1.0, 1e-3)])
def test_order2_accuracy_does_not_depend_on_units_or_speed_scale(scale, speed):
    # before the ramp was made dimensionless, 1e3 (or a speed of 100) ramped the update to first
    # order: mean error 3.9e-3 instead of 1.1e-4 at N = 101
    n = 41
    ref = ts.solve(SPHERE, ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3), [(-0.5, 0, 0)], order=2)
    g = ts.Grid((-scale,) * 3, (scale,) * 3, (n,) * 3)
    sol = ts.solve(ts.surfaces.Sphere(0.5 * scale), g, [(-0.5 * scale, 0, 0)], order=2, speed=speed)
    assert sol.stats.converged
    rng = np.random.default_rng(3)
    p = rng.normal(size=(2000, 3))
    p = 0.5 * p / np.linalg.norm(p, axis=1)[:, None]
    exact = 0.5 * np.arccos(np.clip(-p[:, 0] / 0.5, -1, 1))
    e_ref = np.mean(np.abs(ref(p) - exact))
    e = np.mean(np.abs(sol(p * scale) * speed / scale - exact))
    assert e == pytest.approx(e_ref, rel=1e-3)


@pytest.mark.parametrize(
    "scale, speed", [(2.0**60, 1.0), (2.0**-60, 1.0), (1.0, 2.0**200), (1.0, 2.0**-280), (2.0**60, 2.0**-200)]
)
def test_order2_at_extreme_units_and_speeds_gives_the_same_bits(scale, speed):
    # the per-node data kept in f32 (∇u₀, |φ|) is stored in units of a power of two near its
    # size: at a speed of 2^200 ∇u₀ underflowed f32 (answers 1.6x off, reported converged), at
    # 2^-280 it overflowed (every node but the fixed ones unreached, reported converged)
    ref = ts.solve(SPHERE, G3, [(0.5, 0, 0)], order=2)
    g = ts.Grid((-scale,) * 3, (scale,) * 3, (31,) * 3)
    sol = ts.solve(ts.surfaces.Sphere(0.5 * scale), g, [(0.5 * scale, 0, 0)], order=2, speed=speed)
    assert sol.stats.converged
    assert np.array_equal(sol.values * speed / scale, ref.values)
