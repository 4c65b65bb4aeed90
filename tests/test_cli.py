"""The tubesweep command line."""

import re
import subprocess
import sys
import warnings

import numpy as np
import pytest

import tubesweep as ts
from tubesweep.cli import build_parser, main


def test_help_explains_itself(capsys):
    with pytest.raises(SystemExit) as e:
        main(["--help"])
    assert e.value.code == 0
    out = capsys.readouterr().out
    for word in ("solve", "travel-time", "reproduce", "demo", "Wong & Leung"):
        assert word in out


def test_solve_builtin_circle_writes_band_and_picture(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    assert (
        main(
            [
                "solve",
                "--surface",
                "circle",
                "--n",
                "101",
                "--out",
                str(tmp_path),
                "--png",
                "--dense",
                "--npz",
                "--quiet",
            ]
        )
        == 0
    )
    data = np.load(tmp_path / "solution.npz")
    idx, vals = data["indices"], data["values"]
    assert idx.shape[1] == 2 and len(vals) == len(idx)
    # the node nearest the far side of the circle (0.5, 0) holds ≈ π/2 · 0.5
    h = 0.02
    pts = -1 + h * idx
    far = np.argmin(np.linalg.norm(pts - [0.5, 0.0], axis=1))
    assert vals[far] == pytest.approx(np.pi / 2, abs=0.05)
    assert (tmp_path / "solution.png").stat().st_size > 10_000
    dense = np.load(tmp_path / "solution_dense.npy")
    assert dense.shape == (101, 101)
    assert "iterations" in capsys.readouterr().out


def test_solve_phi_file(tmp_path):
    x = np.linspace(-1, 1, 61)
    X, Y = np.meshgrid(x, x, indexing="ij")
    np.save(tmp_path / "phi.npy", np.hypot(X, Y) - 0.5)
    rc = main(
        [
            "solve",
            "--phi",
            str(tmp_path / "phi.npy"),
            "--lower",
            "-1",
            "-1",
            "--upper",
            "1",
            "1",
            "--source",
            "0.5",
            "0",
            "--hamiltonian",
            "lxf",
            "--out",
            str(tmp_path / "o"),
            "--quiet",
        ]
    )
    assert rc == 0
    assert (tmp_path / "o" / "solution.npz").exists()


def test_bad_input_is_a_clear_error_with_exit_code_2(tmp_path, capsys):
    rc = main(["solve", "--surface", "circle", "--n", "51", "--source", "0", "0", "--out", str(tmp_path), "--quiet"])
    assert rc == 2
    assert "farther than the inner tube" in capsys.readouterr().err


def test_a_refusal_names_the_flag_typed(tmp_path, capsys):
    # the library's refusals name its own arguments (shape, sources, ...): on the command line the
    # error line leads with the flag the user typed
    for argv, head in (
        (["--n", "2"], "error: --n: shape[0] = 2: every axis needs at least 3 nodes"),
        (["--n", "21", "--source", "5", "5", "5"], "error: --source: sources[0] = (5.0, 5.0, 5.0) lies outside"),
        (["--n", "21", "--tol=-1"], "error: --tol: tol must be a positive finite number"),
        (["--n", "21", "--max-iterations", "0"], "error: --max-iterations: max_iterations must be an integer"),
        (["--n", "21", "--max-it", "0"], "error: --max-iterations: max_iterations must be an integer"),  # (abbreviated)
    ):
        assert main(["solve", "--surface", "sphere", "--out", str(tmp_path / "o"), *argv]) == 2
        assert capsys.readouterr().err.strip().startswith(head), argv
    # a phi file's shape is no flag's
    np.save(tmp_path / "phi.npy", np.zeros((2, 5, 5)))
    phi = ["--phi", str(tmp_path / "phi.npy"), "--lower", "-1", "-1", "-1", "--upper", "1", "1", "1"]
    assert main(["solve", *phi, "--source", "0", "0", "0", "--out", str(tmp_path / "o"), "--n", "21"]) == 2
    assert capsys.readouterr().err.strip() == "error: shape[0] = 2: every axis needs at least 3 nodes"
    # a mesh's grid from --n and --padding: its refusal leads with both (it named neither)
    assert main(["solve", "--mesh", "bunny", "--n", "2", "--out", str(tmp_path / "o")]) == 2
    assert capsys.readouterr().err.strip().startswith("error: --n 2 --padding 8: n = 2 nodes cannot hold 8.0 spacings")


def test_travel_time(tmp_path):
    assert (
        main(["travel-time", "--n", "41", "--dim", "2", "--source", "0.1", "0", "--out", str(tmp_path), "--quiet"]) == 0
    )
    u = np.load(tmp_path / "travel_time.npy")
    assert u[20, 20] == pytest.approx(0.1, abs=1e-12)


def test_reproduce_lists_experiments(capsys):
    assert main(["reproduce", "list"]) == 0
    assert "source-init" in capsys.readouterr().out


def test_module_entry_point():
    r = subprocess.run([sys.executable, "-m", "tubesweep", "info"], capture_output=True, text=True, check=True)
    assert "tubesweep" in r.stdout


def test_demo_quick(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    assert main(["demo", "--quick", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "sphere" in out and "star" in out
    # the default runs second order with Godunov and the paper's first order with Lax–Friedrichs
    rows = [line.split() for line in out.splitlines() if " godunov " in line or " lxf " in line]
    assert len(rows) == 4
    assert all(int(r[3]) == (2 if r[2] == "godunov" else 1) for r in rows), rows
    # the paths' lengths against great circles at N = 61 (h = 1/30)
    err = float(out.split("length error max ")[1].split()[0])
    assert err < 0.5 / 30
    for name in ("sphere.png", "sphere_paths.png", "star.png", "layered.png"):
        assert (tmp_path / name).stat().st_size > 10_000


def test_solve_traces_paths_and_labels_cells(tmp_path, capsys):
    args = [
        "solve",
        "--surface",
        "sphere",
        "--n",
        "61",
        "--source",
        "0.5",
        "0",
        "0",
        "--source",
        "-0.5",
        "0",
        "0",
        "--path-from",
        "0",
        "0.5",
        "0",
        "--path-from",
        "0.3",
        "0",
        "0.4",
        "--out",
        str(tmp_path),
        "--quiet",
        "--npz",
    ]
    assert main(args) == 0
    out = capsys.readouterr().out.splitlines()
    line = next(ln for ln in out if ln.startswith("path 1 from (0.3, 0.0, 0.4): length"))
    assert "to source 0," in line
    paths = np.load(tmp_path / "paths.npz")
    assert sorted(paths.keys()) == ["path_0", "path_1"]
    assert np.array_equal(paths["path_1"][-1], [0.5, 0.0, 0.0])
    # the quarter circle from (0, 0.5, 0): π/4 to either source
    assert np.linalg.norm(np.diff(paths["path_0"], axis=0), axis=1).sum() == pytest.approx(np.pi / 4, abs=0.01)
    data = np.load(tmp_path / "solution.npz")
    x = -1 + (2 / 60) * data["indices"][:, 0]
    clear = np.abs(x) > 0.1
    assert np.array_equal(data["nearest_source"][clear], np.where(x[clear] > 0, 0, 1))
    assert (
        main(
            ["solve", "--surface", "sphere", "--n", "41", "--path-from-vertex", "3", "--out", str(tmp_path), "--quiet"]
        )
        == 2
    )
    assert "needs --mesh" in capsys.readouterr().err
    assert (
        main(
            ["solve", "--surface", "sphere", "--n", "41", "--path-from", "0", "0.5", "--out", str(tmp_path), "--quiet"]
        )
        == 2
    )
    assert "3 coordinates" in capsys.readouterr().err


def test_files_and_arguments_are_checked_before_the_solve(tmp_path, capsys):
    # φ in an .npz (it was read as an NpzFile and failed on .shape)
    g = np.linspace(-1, 1, 41)
    x, y = np.meshgrid(g, g, indexing="ij")
    np.savez(tmp_path / "phi.npz", phi=np.hypot(x, y) - 0.5)
    rc = main(
        [
            "solve",
            "--phi",
            str(tmp_path / "phi.npz"),
            "--lower",
            "-1",
            "-1",
            "--upper",
            "1",
            "1",
            "--source",
            "0.5",
            "0",
            "--out",
            str(tmp_path / "o"),
            "--quiet",
        ]
    )
    assert rc == 0 and (tmp_path / "o" / "solution.npz").exists()
    (tmp_path / "empty.npy").write_bytes(b"")
    assert (
        main(
            [
                "solve",
                "--phi",
                str(tmp_path / "empty.npy"),
                "--lower",
                "-1",
                "-1",
                "--upper",
                "1",
                "1",
                "--source",
                "0.5",
                "0",
                "--out",
                str(tmp_path / "o1"),
            ]
        )
        == 2
    )
    assert "not a NumPy .npy or .npz file" in capsys.readouterr().err
    (tmp_path / "notnumpy.txt").write_text("hello")
    assert (
        main(
            [
                "solve",
                "--phi",
                str(tmp_path / "notnumpy.txt"),
                "--lower",
                "-1",
                "-1",
                "--upper",
                "1",
                "1",
                "--source",
                "0.5",
                "0",
                "--out",
                str(tmp_path / "o2"),
            ]
        )
        == 2
    )
    assert "not a NumPy .npy or .npz file" in capsys.readouterr().err
    # --out an existing file, an unknown export format: refused before solving (no traceback)
    (tmp_path / "afile").write_text("")
    assert main(["solve", "--surface", "circle", "--n", "41", "--out", str(tmp_path / "afile")]) == 2
    assert "exists and is not a directory" in capsys.readouterr().err
    assert (
        main(
            [
                "solve",
                "--surface",
                "circle",
                "--n",
                "41",
                "--export",
                str(tmp_path / "x.xyz"),
                "--out",
                str(tmp_path / "o3"),
            ]
        )
        == 2
    )
    assert "unknown format '.xyz'" in capsys.readouterr().err
    assert not (tmp_path / "o3").exists()
    # a mesh file nothing can read: an error line and exit code 2
    (tmp_path / "m.unknownext").write_text("1 2 3")
    assert main(["solve", "--mesh", str(tmp_path / "m.unknownext"), "--out", str(tmp_path / "o4"), "--quiet"]) == 2
    assert "error:" in capsys.readouterr().err


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--source", "-0.5", "0", "0", "--source", "1", "1"], "--source needs 3 coordinates"),
        (["--lower", "-1", "-1", "-1"], "give both --lower and --upper"),
        (["--padding", "3"], "--padding applies to --mesh only"),
        (["--normalize"], "--normalize applies to --mesh only"),
        (["--up", "x"], "--up sets the vertical axis of --png's 3D picture: add --png"),
        (["--path-from", "0", "0", "0"], "farther than the inner tube"),
    ],
)
def test_contradictory_or_incomplete_arguments_are_refused_before_the_solve(tmp_path, capsys, argv, message):
    # NumPy's "inhomogeneous shape", silently ignored --lower/--padding, a path start off the
    # surface found only after the solve had written its files
    out = tmp_path / "o"
    assert main(["solve", "--surface", "sphere", "--n", "41", "--out", str(out), "--quiet", *argv]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


def test_a_curve_cannot_be_exported_to_ply_and_a_directory_is_not_a_mesh(tmp_path, capsys):
    out = tmp_path / "o"
    assert (
        main(["solve", "--surface", "circle", "--n", "41", "--export", str(tmp_path / "c.ply"), "--out", str(out)]) == 2
    )
    assert ".ply holds surfaces only" in capsys.readouterr().err and not out.exists()
    # nor to .obj (meshio's own error, and a traceback, before)
    assert (
        main(["solve", "--surface", "circle", "--n", "41", "--export", str(tmp_path / "c.obj"), "--out", str(out)]) == 2
    )
    assert ".obj holds surfaces only" in capsys.readouterr().err and not out.exists()
    assert main(["solve", "--mesh", str(tmp_path), "--out", str(out)]) == 2
    assert "is a directory" in capsys.readouterr().err


def test_an_unknown_experiment_is_an_error_line_with_exit_status_2(capsys):
    assert main(["reproduce", "nosuch"]) == 2
    assert "unknown experiment" in capsys.readouterr().err


@pytest.mark.filterwarnings("default::RuntimeWarning")  # the CLI prints what a user sees: the default filter
def test_warnings_are_one_line_each_without_the_library_source_line(tmp_path, capsys):
    # two spheres five grid spacings apart, as a sampled φ = min(d₁, d₂): the solve warns that the
    # surface faces itself across a narrow gap (a level set keeps the paper's scheme there)
    n, r = 41, 0.45
    x = np.linspace(-1.2, 1.2, n)
    h = x[1] - x[0]
    c = (r + 2.5 * h) * np.array([1.0, 1.0, 0.0]) / np.sqrt(2)
    p = np.stack(np.meshgrid(x, x, x, indexing="ij"), -1)
    phi = np.minimum(np.linalg.norm(p + c, axis=-1) - r, np.linalg.norm(p - c, axis=-1) - r)
    np.save(tmp_path / "spheres.npy", phi)
    source = [str(v) for v in -c - r * c / np.linalg.norm(c)]
    box = ["--lower", "-1.2", "-1.2", "-1.2", "--upper", "1.2", "1.2", "1.2"]
    rc = main(
        ["solve", "--phi", str(tmp_path / "spheres.npy"), *box, "--source", *source, "--out", str(tmp_path), "--quiet"]
    )
    assert rc == 0
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if "faces itself" in ln]
    assert len(lines) == 1 and lines[0].startswith("warning: the surface faces itself")
    assert "RuntimeWarning" not in err and "sol = solve(" not in err


def test_solve_order_auto_says_which_order_ran_and_why(tmp_path, capsys):
    argv = ["solve", "--n", "41", "--out", str(tmp_path), "--order", "auto"]
    assert main([*argv, "--quiet", "--surface", "sphere"]) == 0
    assert "order 2" in capsys.readouterr().out
    assert main([*argv, "--surface", "circle", "--hamiltonian", "lxf"]) == 0
    out = capsys.readouterr().out
    assert "order 1" in out and "order=2 does not apply, so order 1 ran: order=2 solves the isotropic" in out
    # --quiet keeps the summary line (which says order 1) and drops the note
    assert main([*argv, "--quiet", "--surface", "circle", "--hamiltonian", "lxf"]) == 0
    out = capsys.readouterr().out
    assert "order 1" in out and "does not apply" not in out and "Use order=1" not in out
    assert main(["solve", "--surface", "sphere", "--n", "41", "--out", str(tmp_path), "--quiet", "--order", "1"]) == 0
    assert "order 1" in capsys.readouterr().out


def test_solve_writes_the_band_values_only_when_asked_or_when_nothing_else_is(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    argv = ["solve", "--surface", "circle", "--n", "51", "--quiet"]
    assert main([*argv, "--out", str(tmp_path / "a")]) == 0  # nothing else asked: the band values
    assert sorted(p.name for p in (tmp_path / "a").iterdir()) == ["solution.npz"]
    assert main([*argv, "--out", str(tmp_path / "b"), "--png"]) == 0  # a picture only
    assert sorted(p.name for p in (tmp_path / "b").iterdir()) == ["solution.png"]
    assert main([*argv, "--out", str(tmp_path / "c"), "--export", str(tmp_path / "c" / "u.vtp")]) == 0
    assert sorted(p.name for p in (tmp_path / "c").iterdir()) == ["u.vtp"]
    assert main([*argv, "--out", str(tmp_path / "d"), "--png", "--npz"]) == 0  # both asked for
    assert sorted(p.name for p in (tmp_path / "d").iterdir()) == ["solution.npz", "solution.png"]
    assert "solution.npz" in build_parser()._subparsers._group_actions[0].choices["solve"].format_help()


def test_a_phi_box_that_is_not_phis_own_is_named_as_the_cause(tmp_path, capsys):
    x = np.linspace(-1, 1, 41)
    X, Y, Z = np.meshgrid(x, x, x, indexing="ij")
    np.save(tmp_path / "phi.npy", np.sqrt(X**2 + Y**2 + Z**2) - 0.5)  # sampled on [-1, 1]^3
    argv = ["solve", "--phi", str(tmp_path / "phi.npy"), "--source", "0.5", "0", "0", "--out", str(tmp_path), "--quiet"]
    # the box twice too large: φ falls by 0.5 per unit, the source is 0.25 inside the surface
    assert main([*argv, "--lower", "-2", "-2", "-2", "--upper", "2", "2", "2"]) == 2
    err = capsys.readouterr().err
    assert "φ is -0.25 there on the grid --lower -2 -2 -2 --upper 2 2 2" in err
    assert "changes by 0.499 per unit length" in err and "sampled on a box 0.499 times this one's size" in err
    assert "Check that --lower/--upper are the corners of the grid φ was sampled on (φ has shape 41×41×41)" in err
    # a source outside the box
    assert main([*argv[:4], "3", "0", "0", *argv[7:], "--lower", "-1", "-1", "-1", "--upper", "1", "1", "1"]) == 2
    assert "--source 3 0 0: outside the grid box --lower -1 -1 -1 --upper 1 1 1" in capsys.readouterr().err
    # a box that cuts the surface: a sphere of radius 0.5 in [-0.4, 0.4]^3 (the same spacing)
    y = np.linspace(-0.4, 0.4, 17)
    X, Y, Z = np.meshgrid(y, y, y, indexing="ij")
    np.save(tmp_path / "cut.npy", np.sqrt(X**2 + Y**2 + Z**2) - 0.5)
    cut = ["solve", "--phi", str(tmp_path / "cut.npy"), "--source", "0.4", "0.4", "0.4", "--out", str(tmp_path)]
    assert main([*cut, "--quiet", "--lower", "-0.4", "-0.4", "-0.4", "--upper", "0.4", "0.4", "0.4"]) == 2
    assert "φ's zero level set reaches the box's faces (the box cuts the surface)" in capsys.readouterr().err
    # the right box solves
    assert main([*argv, "--lower", "-1", "-1", "-1", "--upper", "1", "1", "1"]) == 0


def test_distances_reads_points_from_numpy_and_text_files(tmp_path, capsys):
    pts = 0.5 * np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]])
    np.save(tmp_path / "p.npy", pts)
    np.savetxt(tmp_path / "p.txt", pts)
    np.savetxt(tmp_path / "p.csv", pts, delimiter=",", header="x,y,z")
    (tmp_path / "p.bin").write_bytes(b"\x00\x01")
    base = ["distances", "--surface", "sphere", "--n", "41", "--quiet"]
    results = []
    for name in ("p.npy", "p.txt", "p.csv"):
        out = tmp_path / f"D_{name.replace('.', '_')}.npy"
        assert main([*base, "--points", str(tmp_path / name), "--out", str(out)]) == 0
        results.append(np.load(out))
    assert np.array_equal(results[0], results[1]) and np.array_equal(results[0], results[2])
    assert results[0][0, 1] == pytest.approx(np.pi / 4, abs=0.05)  # a quarter great circle, within a spacing
    capsys.readouterr()
    assert main([*base, "--points", str(tmp_path / "p.bin"), "--out", str(tmp_path / "D.npy")]) == 2
    err = capsys.readouterr().err
    assert "give a .npy file (numpy.save) or a text file (.txt .csv .xyz .dat)" in err and "allow_pickle" not in err
    (tmp_path / "two.txt").write_text("0.5 0\n0 0.5\n")
    assert main([*base, "--points", str(tmp_path / "two.txt"), "--out", str(tmp_path / "D.npy")]) == 2
    assert "needs M points of 3 coordinates (an (M, 3) array); got shape (2, 2)" in capsys.readouterr().err
    (tmp_path / "words.txt").write_text("a b c\n")
    assert main([*base, "--points", str(tmp_path / "words.txt"), "--out", str(tmp_path / "D.npy")]) == 2
    assert "not a text file of numbers with 3 per line" in capsys.readouterr().err
    # an empty .npy and one that starts like a zip archive: numpy raises EOFError and BadZipFile,
    # which went out as tracebacks (for --points and for --phi)
    (tmp_path / "empty.npy").write_bytes(b"")
    (tmp_path / "zip.npy").write_bytes(b"PK\x03\x04 not a zip archive")
    for name in ("empty.npy", "zip.npy"):
        assert main([*base, "--points", str(tmp_path / name), "--out", str(tmp_path / "D.npy")]) == 2
        assert "not a NumPy .npy file of numbers" in capsys.readouterr().err
        argv = ["distances", "--phi", str(tmp_path / name), "--lower", "-1", "-1", "-1", "--upper", "1", "1", "1"]
        assert main([*argv, "--sample", "3", "--out", str(tmp_path / "D.npy"), "--quiet"]) == 2
        assert "not a NumPy .npy file of numbers" in capsys.readouterr().err


def test_output_paths_that_cannot_be_written_are_refused_before_the_solve(tmp_path, capsys):
    # (a bare OSError after the solve before, naming no option: the solve's work lost)
    afile = tmp_path / "afile"
    afile.write_text("")
    assert main(["solve", "--surface", "sphere", "--n", "21", "--out", str(afile / "o")]) == 2
    assert f"--out {afile / 'o'}: {afile} is a file, not a folder" in capsys.readouterr().err
    out = tmp_path / "o"
    assert main(["solve", "--surface", "sphere", "--n", "21", "--export", str(afile / "x.vtp"), "--out", str(out)]) == 2
    assert f"--export {afile / 'x.vtp'}: {afile} is a file, not a folder" in capsys.readouterr().err
    assert not out.exists()
    assert main(["distances", "--surface", "sphere", "--n", "21", "--sample", "3", "--out", str(afile / "D.npy")]) == 2
    assert f"--out {afile / 'D.npy'}: {afile} is a file, not a folder" in capsys.readouterr().err


def test_a_solve_that_stops_at_max_iterations_writes_its_files_and_exits_3(tmp_path, capsys):
    # a script must not take the last iterate for the answer: status 3 (2 is refused input); the
    # warning is a line on stderr, as on a user's command line (not an error as in the tests)
    argv = ["--out", str(tmp_path), "--quiet", "--max-iterations", "1"]
    with warnings.catch_warnings():
        warnings.simplefilter("always", RuntimeWarning)
        assert main(["solve", "--surface", "sphere", "--n", "41", "--order", "1", *argv]) == 3
        assert (tmp_path / "solution.npz").exists()
        err = capsys.readouterr().err
        assert "warning: the sweeps did not converge in max_iterations=1" in err
        assert "error: the solve stopped at --max-iterations 1 without converging" in err
        assert main(["travel-time", "--n", "41", "--dim", "2", "--source", "0.1", "0", *argv]) == 3
        assert np.isfinite(np.load(tmp_path / "travel_time.npy")).any()
        err = capsys.readouterr().err
        assert "warning: the sweeps did not converge" in err and "error: the solve stopped at --max-iterations 1" in err
    # converged: 0, and no error line
    assert main(["travel-time", "--n", "41", "--dim", "2", "--out", str(tmp_path), "--quiet"]) == 0
    assert "error" not in capsys.readouterr().err
    # reported not converged before the limit (values the solve could not settle): the warning
    # says why, not --max-iterations
    from tubesweep.cli import _unconverged

    assert _unconverged(24, 10000) == ("the solve ended", "see the warning above for why")


@pytest.mark.parametrize("flag", [["--padding", "2"], ["--normalize"]])
def test_distances_refuses_mesh_options_for_a_library_surface(tmp_path, capsys, flag):
    # both were ignored for a --surface, silently (a helper's review)
    out = tmp_path / "d.npy"
    argv = ["distances", "--surface", "sphere", "--n", "21", "--sample", "5", "--out", str(out), *flag]
    assert main(argv) == 2
    assert f"{flag[0]} applies to --mesh only" in capsys.readouterr().err and not out.exists()


def test_separate_parts_are_said_not_reached_and_phi_flags_it_ignores_are_refused(tmp_path, capsys):
    # two spheres apart, a source on one: the solve said only converged=True (and a NumPy warning
    # from the picture's contours), distances printed "largest 0" for a matrix of inf; --n was
    # ignored with --phi (a review)
    g = ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41))
    x, y, z = g.meshgrid()
    phi = np.minimum(np.sqrt((x + 0.5) ** 2 + y**2 + z**2), np.sqrt((x - 0.5) ** 2 + y**2 + z**2)) - 0.3
    np.save(tmp_path / "two.npy", phi)
    box = ["--phi", str(tmp_path / "two.npy"), "--lower", "-1", "-1", "-1", "--upper", "1", "1", "1"]
    assert main(["solve", *box, "--source", "-0.8", "0", "0", "--png", "--out", str(tmp_path / "o")]) == 0
    said = capsys.readouterr()
    assert re.search(r"\n\d+ of the \d+ band nodes are not reached \(u = inf, grey in pictures\)", said.out)
    assert "warning" not in said.err
    assert main(["distances", *box, "--sample", "2", "--out", str(tmp_path / "D.npy"), "--quiet"]) == 0
    assert (
        "(1 of the 1 pairs lie on parts of the surface that do not join: inf in the matrix)" in capsys.readouterr().out
    )
    assert main(["solve", *box, "--source", "-0.8", "0", "0", "--n", "11", "--out", str(tmp_path / "p")]) == 2
    assert "--n applies to --surface, --mesh and --points: the grid of --phi" in capsys.readouterr().err
