"""order="auto" (docs/second-order.md, "order='auto'"): second order where it applies, bit for
bit the explicit order=2; the first-order scheme where it does not, bit for bit the explicit
order=1, with the reason an explicit order=2 gives recorded in sol.stats.order_fallback."""

import contextlib
import re

import numpy as np
import pytest

import tubesweep as ts
from conftest import FIRST_ORDER_SIZE

SPHERE = ts.surfaces.Sphere(0.5)
SRC = (-0.5, 0.0, 0.0)


def box(n, d=3):
    return ts.Grid((-1.0,) * d, (1.0,) * d, (n,) * d)


def _sphere_cp(x):
    r = np.linalg.norm(x, axis=1, keepdims=True)
    return 0.5 * x / np.where(r > 0, r, 1.0)


def sized_if(expected):
    """The first-order fallback's size warning, asserted when ``expected`` (``_fallback``)."""
    return pytest.warns(RuntimeWarning, match=re.escape(FIRST_ORDER_SIZE)) if expected else contextlib.nullcontext()


def paper_creases_if(expected):
    """The warning of order=1 on the paper's tube of a level set with creases, asserted when
    ``expected`` (``_creases.warn_paper_tube_creases``)."""
    return (
        pytest.warns(RuntimeWarning, match=r"in the paper's tube \(order=1\)") if expected else contextlib.nullcontext()
    )


def said_for(words):
    """What ``order="auto"``'s fallback for the refusal ``words`` says: the size of the first-order
    errors, that narrow widths ran it (``second_order.NarrowExtension``), or nothing."""
    if words == "outer ≥ inner":
        return pytest.warns(RuntimeWarning, match="order='auto' ran the first-order scheme")
    if words == "crease":
        # the double torus at N = 61: its φ reads as noisy (its tubes' radius, 3.6 spacings, below
        # the tube's width), and its crease is found through a smoothing (_coarse_creases)
        return pytest.warns(
            RuntimeWarning, match=r"order='auto' ran the first-order scheme, and φ's level sets have creases or corners"
        )
    return sized_if(words in ("refine the grid", "piecewise flat"))


def _refusal(surface, grid, sources, **kw):
    with pytest.raises(ValueError) as info:
        ts.solve(surface, grid, sources, order=2, **kw)
    return str(info.value)


@pytest.mark.parametrize(
    "surface, grid, src",
    [
        (SPHERE, box(41), SRC),
        (ts.ClosestPoint(_sphere_cp), box(41), SRC),
        (ts.surfaces.Circle(0.5), box(101, 2), (-0.5, 0.0)),
    ],
    ids=["sphere level set", "sphere closest-point map", "circle"],
)
def test_auto_is_order_two_where_it_applies(surface, grid, src):
    two = ts.solve(surface, grid, [src], order=2)
    auto = ts.solve(surface, grid, [src], order="auto")
    assert auto.stats.order == 2 and auto.stats.order_fallback is None
    assert np.array_equal(auto.values, two.values)
    assert auto.stats.order2["second_order_iterations"] == two.stats.order2["second_order_iterations"]
    pts = np.array([src])
    assert auto(pts)[0] == 0.0  # the factored evaluation came along
    tube = ts.Tube(surface, grid)
    assert np.array_equal(tube.solve([src], order="auto").values, two.values)


def _cases():
    mesh = ts.surfaces.from_mesh(SPHERE.triangulation(16), smooth=False)  # the exact map (smooth: test_mesh_order2.py)
    dt = ts.surfaces.DoubleTorus()
    g41 = box(41)
    return [
        # (surface, grid, source, options, the refusal's words)
        (mesh, g41, SRC, {}, "piecewise flat"),
        (dt, ts.Grid(*dt.default_box, (61, 61, 61)), dt.default_source, {}, "crease"),
        # radius 0.25 at Δx = 1/15: outer·Δx·κ = 1.07, the curvature not resolved by the tube
        (ts.surfaces.Sphere(0.25), box(31), (-0.25, 0, 0), {}, "refine the grid"),
        (SPHERE, g41, SRC, {"hamiltonian": "lxf"}, "Godunov"),
        (SPHERE, g41, SRC, {"source_init": "node"}, "source_init"),
        (SPHERE, g41, SRC, {"paper_sweeps": True}, "paper_sweeps"),
        (SPHERE, g41, SRC, {"method": "naive", "max_iterations": 20}, "two-layer"),
        (SPHERE, g41, SRC, {"inner": 2, "outer": 3.5}, "outer ≥ inner"),
    ]


@pytest.mark.parametrize(
    "case",
    _cases(),
    ids=[
        "mesh",
        "double torus",
        "unresolved curvature",
        "lxf",
        "node",
        "paper",
        "naive",
        "outer",
    ],
)
def test_auto_falls_back_to_order_one_with_the_reason(case):
    surface, grid, src, kw, words = case
    reason = _refusal(surface, grid, [src], **kw)
    assert words in reason
    with paper_creases_if(words == "crease"):
        one = ts.solve(surface, grid, [src], order=1, **kw)
    # first order on a sphere 7.5 spacings across (22%), and the mesh at N = 41 (3Δx: 10%)
    with said_for(words):
        auto = ts.solve(surface, grid, [src], order="auto", **kw)
    assert auto.stats.order == 1 and one.stats.order == 1
    assert auto.stats.order_fallback == reason and one.stats.order_fallback is None
    if words in ("crease", "refine the grid"):
        # the inner tube thinned at the creases (order=1 keeps the paper's): fewer inner nodes
        # (10,636 → 10,528 at N = 61), the front later on the whole by the shortcut they gave; and
        # where the sphere's two sides' tubes meet at its centre, 3.75 spacings deep (its largest
        # error against the great circles 0.149 of the half-circumference, against 0.241)
        assert np.count_nonzero(auto.inner_mask) < np.count_nonzero(one.inner_mask)
        both = np.isfinite(auto.values) & np.isfinite(one.values)
        assert np.array_equal(both, np.isfinite(one.values))
        change = auto.values[both] - one.values[both]
        assert np.mean(change) > 0 and np.max(np.abs(change)) < 5 * grid.spacing
    else:
        assert np.array_equal(auto.values, one.values)
    if kw.get("method") != "naive":
        tube = ts.Tube(surface, grid, **{k: v for k, v in kw.items() if k in ("inner", "outer")})
        opts = {k: v for k, v in kw.items() if k not in ("inner", "outer", "method", "max_iterations")}
        for _ in range(2):  # the second time from the refusal the tube remembers
            with said_for(words):
                t = tube.solve([src], order="auto", **opts)
            # a Tube's "auto" runs on the same tube as ts.solve's (thinned at creases): the same
            # refusal and the same values
            assert t.stats.order_fallback == auto.stats.order_fallback
            assert np.array_equal(t.values, auto.values)
        # order=1 on the Tube keeps the paper's tube
        with paper_creases_if(words == "crease"):
            assert np.array_equal(tube.solve([src], order=1, **opts).values, one.values)


def test_source_radius_is_first_order():
    reason = _refusal(SPHERE, box(41), [SRC], source_radius=0.1)
    auto = ts.solve(SPHERE, box(41), [SRC], order="auto", source_radius=0.1)
    assert auto.stats.order_fallback == reason and "source_radius" in reason
    assert np.array_equal(auto.values, ts.solve(SPHERE, box(41), [SRC], order=1, source_radius=0.1).values)


def test_other_errors_are_not_fallbacks():
    # a source off the surface is an error whatever the order, not a reason to fall back
    for order in (1, 2, "auto"):
        with pytest.raises(ValueError, match="sources"):
            ts.solve(SPHERE, box(41), [(0.0, 0.0, 0.0)], order=order)


@pytest.mark.parametrize("bad", [3, 0, 1.5, True, "2", "Auto", None, "second"])
def test_bad_order_values(bad):
    for call in (
        lambda: ts.solve(SPHERE, box(21), [SRC], order=bad),
        lambda: ts.Tube(SPHERE, box(21)).solve([SRC], order=bad),
        lambda: ts.travel_time(box(11, 2), [(0.0, 0.0)], order=bad),
    ):
        with pytest.raises(ValueError, match=r"order must be 1 .* or 'auto'.*got"):
            call()


def test_travel_time_auto():
    g = box(41, 2)
    src = [(0.013, -0.2)]
    two, s2 = ts.travel_time(g, src, order=2, return_stats=True)
    auto, sa = ts.travel_time(g, src, order="auto", return_stats=True)
    assert sa.order == 2 and sa.order_fallback is None and np.array_equal(auto, two)
    with pytest.raises(ValueError) as info:
        ts.travel_time(g, src, order=2, hamiltonian="lxf")
    one = ts.travel_time(g, src, order=1, hamiltonian="lxf")
    auto, sa = ts.travel_time(g, src, order="auto", hamiltonian="lxf", return_stats=True)
    assert sa.order == 1 and sa.order_fallback == str(info.value) and np.array_equal(auto, one)


def test_the_default_is_auto():
    # ts.solve and Tube.solve without order=: second order where it applies, order=1 elsewhere
    g = box(31)
    default, auto = ts.solve(SPHERE, g, [SRC]), ts.solve(SPHERE, g, [SRC], order="auto")
    assert default.stats.order == 2 and np.array_equal(default.values, auto.values)
    assert np.array_equal(ts.Tube(SPHERE, g).solve([SRC]).values, auto.values)
    mesh = ts.surfaces.from_mesh(SPHERE.triangulation(12), smooth=False)
    with sized_if(True):  # the mesh at N = 31, first order: 13% of the distances
        default = ts.solve(mesh, g, [SRC])
    assert default.stats.order == 1 and "piecewise flat" in default.stats.order_fallback
    assert np.array_equal(default.values, ts.solve(mesh, g, [SRC], order=1).values)


def test_an_option_of_the_first_order_scheme_runs_the_paper_s_tube_on_a_tube_too():
    # the sphere of radius 0.375 at N = 21 (3.75 spacings): "auto" thins the tube at its centre,
    # where the two sides' tubes meet; source_init="node" chooses the first-order scheme, whose
    # tube ts.solve keeps, and a Tube's solve and solve_many ran the thinned one (a hypothesis
    # example of tests/test_properties.py)
    sphere, g = ts.surfaces.Sphere(0.375), box(21)
    src = [(0.31555162, 0.0, 0.20261336)]
    one = ts.solve(sphere, g, src, source_init="node")
    tube = ts.Tube(sphere, g)
    auto = tube.solve(src, source_init="node")
    many = tube.solve_many(src, source_init="node")
    assert one.stats.order == auto.stats.order == 1
    assert np.array_equal(auto.values, one.values) and np.array_equal(many[0], one.values)
    with pytest.warns(RuntimeWarning, match="whose errors are a few grid spacings"):
        assert tube.solve(src).stats.crease_thinned > 0  # "auto" on its own thins it
