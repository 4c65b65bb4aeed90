"""What a new user meets first: warnings they can act on (said once, on their own line), messages
that name the real cause, objects that explain themselves when printed, and a command line whose
options all say what they do."""

import re
import warnings

import numpy as np
import pytest

import tubesweep as ts
from tubesweep.cli import build_parser, main


def two_spheres_across_a_narrow_gap():
    """Two spheres (φ = min of their distances) five spacings apart at grid 41: a level set, which
    keeps the paper's scheme and warns where its tubes touch (a triangle mesh is cut there)."""
    grid = ts.Grid([-1.2] * 3, [1.2] * 3, (41,) * 3)
    h, r = grid.spacing, 0.45
    axis = np.array([1.0, 1.0, 0.0]) / np.sqrt(2)
    c1, c2 = -(r + 2.5 * h) * axis, (r + 2.5 * h) * axis

    def phi(p):
        return np.minimum(np.linalg.norm(p - c1, axis=1) - r, np.linalg.norm(p - c2, axis=1) - r)

    return ts.LevelSet(phi, lipschitz=1.0), grid, c1 - r * axis


def test_the_facing_gaps_warning_is_short_says_how_much_and_points_at_the_users_line():
    surface, grid, source = two_spheres_across_a_narrow_gap()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = ts.solve(surface, grid, [source])
    facing = [w for w in caught if "faces itself" in str(w.message)]
    assert len(facing) == 1
    w = facing[0]
    assert w.filename == __file__  # this line, not a library line
    text = str(w.message)
    assert len(text) < 450
    share = float(re.search(r"about ([0-9.]+)% of the surface", text).group(1))
    assert 0 < share < 5
    assert "distances not reached across one hold" in text and "sol.narrow_gaps()" in text
    assert sol.stats.facing_pairs > 0


def test_a_repeated_solve_warns_once_with_the_default_filter():
    surface, grid, source = two_spheres_across_a_narrow_gap()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")
        warnings.filterwarnings("default", category=RuntimeWarning)
        for _ in range(3):
            ts.solve(surface, grid, [source])
    assert sum("faces itself" in str(w.message) for w in caught) == 1


def test_a_mesh_is_cut_across_its_narrow_gaps_instead_of_warned_about():
    # Spot at grid 60 faces itself across gaps narrower than the tubes (legs, ears): on a mesh the
    # band is cut there (and above the concave edges), so nothing is warned and the stats say it
    spot = ts.surfaces.from_mesh(ts.data.spot())
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sol = ts.solve(spot, spot.grid(60), [spot.vertices[285]])
    assert sol.stats.facing_pairs > 0 and sol.stats.cut_edges > sol.stats.facing_pairs


def test_every_library_warning_names_a_line_outside_the_package():
    # the band's widening warning used to be attributed to a line of tubesweep
    X, Y = np.meshgrid(np.linspace(-1, 1, 61), np.linspace(-1, 1, 61), indexing="ij")
    phi = 3.0 * (np.hypot(X, Y) - 0.5)  # |∇φ| = 3: not a distance, warned about
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ts.solve(ts.LevelSet(phi), ts.Grid((-1, -1), (1, 1), (61, 61)), [(0.5, 0.0)])
    assert caught and all(w.filename == __file__ for w in caught), [(w.filename, str(w.message)[:60]) for w in caught]


def test_a_library_surface_on_a_too_coarse_grid_is_told_so_first():
    with pytest.raises(ValueError, match=r"^the grid is too coarse for this surface"):
        ts.solve(ts.surfaces.Sphere(0.2), ts.Grid((-1,) * 3, (1,) * 3, (21,) * 3), [(0.2, 0, 0)])
    # a user's φ that is a distance (|∇φ| ≈ 1 but at the centre the tube reaches) is told of the
    # grid first, not to re-distance
    with pytest.raises(
        ValueError, match=r"falls to .* though it is ≈ 1 elsewhere .*If φ is a distance, the grid is too"
    ):
        ts.solve(lambda p: np.linalg.norm(p, axis=1) - 0.2, ts.Grid((-1,) * 3, (1,) * 3, (21,) * 3), [(0.2, 0, 0)])
    # a user's φ that is not a distance is still pointed to re-distancing, CLI option included
    X, Y = np.meshgrid(np.linspace(-1, 1, 41), np.linspace(-1, 1, 41), indexing="ij")
    with pytest.raises(ValueError, match=r"redistance=True\) \(on the command line: --redistance\)"):
        ts.solve(ts.LevelSet(20 * (X**2 + Y**2 - 0.25)), ts.Grid((-1, -1), (1, 1), (41, 41)), [(0.5, 0.0)])


def test_library_surfaces_and_solutions_explain_themselves():
    assert repr(ts.surfaces.Sphere(0.5)) == "Sphere(radius=0.5, center=(0, 0, 0))"
    assert repr(ts.surfaces.Ellipsoid()) == "Ellipsoid(a=0.6, b=0.45, c=0.3, center=(0, 0, 0))"
    assert repr(ts.surfaces.MobiusBand()).startswith("MobiusBand(R=0.6, w=0.3")
    assert repr(ts.LevelSet(np.ones((5, 5)), redistance=True)) == "LevelSet(array 5×5, redistance=True)"
    for make in ts.surfaces.REGISTRY.values():
        s = make()
        assert repr(s).startswith(type(s).__name__ + "(") and "object at" not in repr(s)
    s = ts.surfaces.Sphere(0.5)
    sol = ts.solve(s, ts.Grid((-1,) * 3, (1,) * 3, (41,) * 3), [s.default_source])
    text = repr(sol)
    for part in (
        "surface=Sphere(radius=0.5",
        "grid=41×41×41 (spacing 0.05)",
        f"band_nodes={sol.stats.band_points:,}",
        "hamiltonian='godunov'",
        f"order={sol.stats.order}",
        f"iterations={sol.stats.iterations}",
        "converged=True",
    ):
        assert part in text, part


def test_every_command_line_option_says_what_it_does_and_its_default():
    parser = build_parser()
    subs = next(a for a in parser._actions if a.dest == "command").choices
    for name, sub in subs.items():
        for action in sub._actions:
            if action.dest == "help":
                continue
            assert action.help, f"{name} {action.option_strings or action.dest}: no help"
            if action.default not in (None, False) and action.option_strings:
                assert "default" in action.help, f"{name} {action.option_strings}: default {action.default!r} unstated"


def test_redistance_on_the_command_line(tmp_path, capsys):
    X, Y = np.meshgrid(np.linspace(-1, 1, 81), np.linspace(-1, 1, 81), indexing="ij")
    phi_file = tmp_path / "phi.npy"
    np.save(phi_file, 5 * (X**2 + Y**2 - 0.25))  # a level set, not a distance: |∇φ| = 5 on the circle
    args = [
        "solve",
        "--phi",
        str(phi_file),
        "--lower",
        "-1",
        "-1",
        "--upper",
        "1",
        "1",
        "--source",
        "0.5",
        "0",
        "--quiet",
        "--out",
        str(tmp_path),
    ]
    assert main(args) == 2
    assert "--redistance" in capsys.readouterr().err
    assert main(args + ["--redistance"]) == 0
    out = capsys.readouterr().out
    # the times are named as in docs/benchmarks.md
    assert re.search(r"wall [0-9.]+ s \(sweeps [0-9.]+ s, set-up [0-9.]+ s\)", out)
    data = np.load(tmp_path / "solution.npz")
    # the command line solved what the library solves, and the antipode of the circle is π/2 away
    g = ts.Grid((-1, -1), (1, 1), (81, 81))
    sol = ts.solve(ts.LevelSet(5 * (X**2 + Y**2 - 0.25), redistance=True), g, [(0.5, 0.0)])
    assert np.array_equal(data["values"], sol.values)
    assert abs(sol([(-0.5, 0.0)])[0] - np.pi / 2) < 3 * g.spacing  # 2.3 Δx at the antipode
    assert main(["solve", "--surface", "sphere", "--redistance", "--out", str(tmp_path)]) == 2
    assert "--redistance applies to --phi only" in capsys.readouterr().err
