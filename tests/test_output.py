"""Results out: Solution.on_mesh, triangulate (marching cubes / squares, a surface's own mesh),
export (meshio round trips, VTK XML PolyData) and plot (matplotlib figures, 2D and 3D)."""

import base64
import re

import numpy as np
import pytest

import tubesweep as ts
from tubesweep.output import read_vtp
from tubesweep.surface import Surface


@pytest.fixture(scope="module")
def sphere_sol():
    grid = ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41))
    return ts.solve(ts.surfaces.Sphere(), grid, [(-0.5, 0, 0)])


@pytest.fixture(scope="module")
def circle_sol():
    grid = ts.Grid((-1, -1), (1, 1), (81, 81))
    return ts.solve(ts.surfaces.Circle(), grid, [(-0.5, 0)])


def test_marching_cubes_of_the_level_set(sphere_sol):
    pytest.importorskip("skimage")
    v, f = ts.triangulate(sphere_sol)
    h = sphere_sol.grid.spacing
    r = np.linalg.norm(v, axis=1)
    assert np.abs(r - 0.5).max() < 0.05 * h  # linear interpolation of an exact distance: ≪ h
    assert f.shape[1] == 3 and f.max() < len(v)
    # one closed surface: Euler characteristic 2
    e = np.unique(np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1), axis=0)
    assert len(v) - len(e) + len(f) == 2


def test_marching_squares_of_a_curve(circle_sol):
    pytest.importorskip("skimage")
    v, e = ts.triangulate(circle_sol)
    assert e.shape[1] == 2
    assert np.abs(np.linalg.norm(v, axis=1) - 0.5).max() < 0.1 * circle_sol.grid.spacing
    deg = np.bincount(e.reshape(-1), minlength=len(v))
    assert np.all(deg == 2)  # a closed loop


def test_on_mesh_is_finite_on_the_surface_and_falls_back_near_the_band_edge(sphere_sol):
    sol = sphere_sol
    h = sol.grid.spacing
    rng = np.random.default_rng(0)
    d = rng.normal(size=(500, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    on = 0.5 * d
    u = sol.on_mesh(on)
    exact = ts.surfaces.Sphere().geodesic_distance(on, (-0.5, 0, 0))
    assert np.all(np.isfinite(u)) and np.abs(u - exact).max() < 4 * h
    assert np.array_equal(u, sol(on))  # interpolation where the stencil is in the band
    # 3.7 h off the surface the multilinear stencil leaves the band (outer = 4): fallback values
    off = (0.5 + 3.7 * h) * d
    with pytest.warns(RuntimeWarning, match=r"points within about 3 spacings read values"):
        plain = sol(off)
    assert np.any(np.isnan(plain))
    fb = sol.on_mesh(off)
    assert np.all(np.isfinite(fb))
    assert np.abs(fb - exact).max() < 5 * h  # the band values are constant along normals
    # far from the band: NaN
    with pytest.warns(RuntimeWarning, match=r"on_mesh: 1 of 1 vertices lie off the band"):
        assert np.isnan(sol.on_mesh([[0.0, 0.0, 0.0]]))[0]


def test_on_mesh_names_a_mesh_s_own_vertices_that_no_face_uses():
    # (it asked "are they this surface's vertices? pass surface.vertices", which they were)
    trimesh = pytest.importorskip("trimesh")
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=0.5)
    vertices = np.r_[sphere.vertices, [[3.0, 3.0, 3.0]], sphere.vertices[:1] * 0.2]
    mesh = ts.surfaces.from_mesh((vertices, sphere.faces))
    sol = ts.solve(mesh, mesh.grid(41), [sphere.vertices[0]])
    with pytest.warns(RuntimeWarning, match=r"on_mesh: 2 of 644 vertices are used by no face of the mesh") as caught:
        u = sol.on_mesh(mesh.vertices)
    assert len(caught) == 1 and "pass surface.vertices" not in str(caught[0].message)
    assert np.isnan(u[-2:]).all() and np.isfinite(u[:-2]).all()
    with pytest.warns(RuntimeWarning, match=r"on_mesh: 2 of 2 vertices lie off the band"):
        sol.on_mesh(vertices[-2:])  # (not the mesh's own array: the general advice)


@pytest.mark.parametrize("suffix", [".vtu", ".vtk", ".ply"])
def test_export_round_trip_with_meshio(sphere_sol, tmp_path, suffix):
    meshio = pytest.importorskip("meshio")
    v, f = ts.triangulate(sphere_sol)
    path = ts.export(sphere_sol, tmp_path / f"s{suffix}")
    m = meshio.read(str(path))
    assert np.allclose(m.points, v, atol=1e-6)
    assert np.array_equal(m.cells_dict["triangle"], f)
    assert np.allclose(m.point_data["u"], sphere_sol.on_mesh(v), atol=1e-6, equal_nan=True)


def test_export_vtp_and_curves(sphere_sol, circle_sol, tmp_path):
    meshio = pytest.importorskip("meshio")
    v, f = ts.triangulate(sphere_sol)
    p, cells, data = read_vtp(ts.export(sphere_sol, tmp_path / "s.vtp", point_data={"x": v[:, 0]}))
    assert np.allclose(p, v) and np.array_equal(cells, f)
    assert np.allclose(data["u"], sphere_sol.on_mesh(v)) and np.allclose(data["x"], v[:, 0])
    # a 2D curve: line cells, z = 0
    v2, e2 = ts.triangulate(circle_sol)
    m = meshio.read(str(ts.export(circle_sol, tmp_path / "c.vtu")))
    assert np.array_equal(m.cells_dict["line"], e2) and np.allclose(m.points[:, 2], 0.0)
    p2, c2, d2 = read_vtp(ts.export(circle_sol, tmp_path / "c.vtp"))
    assert np.array_equal(c2, e2) and np.allclose(p2[:, :2], v2)
    with pytest.raises(ValueError, match="unknown format"):
        ts.export(sphere_sol, tmp_path / "s.xyz")
    with pytest.raises(ValueError, match="surfaces only"):
        ts.export(circle_sol, tmp_path / "c.ply")
    with pytest.raises(ValueError, match="point_data"):
        ts.export(sphere_sol, tmp_path / "s.vtu", point_data={"bad": np.zeros(3)})


def test_a_vtp_export_holds_unreached_values_as_binary_nan_bit_for_bit(sphere_sol, tmp_path):
    # VTK's ASCII reader stops at "nan" (ParaView then fails to read the file): the arrays are
    # inline base64 binary, the byte count first (UInt64: a UInt32 overflows past 4 GiB), and read
    # back bit for bit
    v, _ = ts.triangulate(sphere_sol)
    x = np.where(v[:, 2] > 0.2, np.nan, v[:, 0] / 3)
    path = ts.export(sphere_sol, tmp_path / "s.vtp", point_data={"x": x})
    text = path.read_text()
    assert not re.search(r"(^|\s)nan(\s|$)", text, re.IGNORECASE) and 'format="ascii"' not in text
    assert text.count('format="binary"') == 5  # u, x, the points, connectivity, offsets
    p, _, data = read_vtp(path)
    assert np.array_equal(p, v) and np.array_equal(data["x"], x, equal_nan=True)
    assert np.isnan(data["x"]).sum() == np.count_nonzero(v[:, 2] > 0.2) > 0
    block = text.split('Name="x" format="binary">\n')[1].split("\n")[0]
    assert 'header_type="UInt64"' in text and int(np.frombuffer(base64.b64decode(block[:12]), "<u8")[0]) == 8 * len(v)


def test_export_uses_the_meshs_own_triangulation(tmp_path):
    meshio = pytest.importorskip("meshio")
    from test_mesh import icosphere

    v, f = icosphere(2)
    m = ts.surfaces.from_mesh((v, f))
    sol = ts.solve(m, m.grid(41), [v[0]])
    out = meshio.read(str(ts.export(sol, tmp_path / "ico.vtu")))
    assert np.array_equal(out.points, v) and np.array_equal(out.cells_dict["triangle"], f)


class _CpSphere(Surface):
    """A closest-point sphere with no triangulation (to check the error message)."""

    ndim = 3

    def band(self, grid, half_width):
        from tubesweep.band import BandGeometry

        x = grid.points(grid.unravel(np.arange(grid.size)))
        r = np.linalg.norm(x, axis=1)
        keep = np.abs(r - 0.5) <= half_width
        d = np.abs(r - 0.5)[keep]
        direction = (np.sign(r - 0.5)[keep, None] * x[keep] / r[keep, None]).astype(np.float32)
        return BandGeometry(np.flatnonzero(keep).astype(np.int64), d, d, direction)

    def project(self, points, grid):
        r = np.linalg.norm(points, axis=1)
        return np.abs(r - 0.5), 0.5 * points / r[:, None]


def test_triangulate_needs_a_mesh_for_bare_closest_point_surfaces(tmp_path):
    grid = ts.Grid((-1, -1, -1), (1, 1, 1), (25, 25, 25))
    with pytest.warns(RuntimeWarning, match="whose errors are a few grid spacings"):  # first order at N = 25
        sol = ts.solve(_CpSphere(), grid, [(-0.5, 0, 0)])
    with pytest.raises(ValueError, match="mesh=\\(vertices, faces\\)"):
        ts.triangulate(sol)
    from test_mesh import icosphere

    v, f = icosphere(1)
    vv, ff = ts.triangulate(sol, mesh=(v, f))
    assert vv.shape == v.shape and np.array_equal(ff, f)


def test_plot_returns_figures(sphere_sol, circle_sol, tmp_path):
    pytest.importorskip("matplotlib")
    from matplotlib.figure import Figure

    fig = ts.plot(circle_sol, title="circle")
    assert isinstance(fig, Figure) and len(fig.axes) == 2  # the plot and its colour bar
    fig.savefig(tmp_path / "c.png")
    fig = ts.plot(sphere_sol, levels=[0.2, 0.4, 0.6])
    assert isinstance(fig, Figure) and len(fig.axes) == 3  # two views and a colour bar
    fig.savefig(tmp_path / "s.png")
    assert (tmp_path / "s.png").stat().st_size > 10_000
    # into a given 3D axes, y up
    f2 = Figure()
    ax = f2.add_subplot(projection="3d")
    assert ts.plot(sphere_sol, ax=ax, colorbar=False, up="y") is f2
    with pytest.raises(ValueError, match="up must be"):
        ts.plot(sphere_sol, up="w")


def test_fig8_is_registered():
    from tubesweep import reproduce

    assert "fig8" in reproduce.experiments()


def test_export_checks_a_user_mesh_and_writes_vectors_and_odd_names(sphere_sol, tmp_path):
    v, f = ts.triangulate(sphere_sol)
    # faces pointing past the vertices, negative or fractional: refused, no file written
    for faces, match in [
        (np.array([[0, 1, len(v)]]), f"index vertex {len(v)}"),
        (np.array([[0, -1, 2]]), "index vertex -1"),
        (np.array([[0, 1, 2.7]]), "whole-number"),
        (np.array([0, 1, 2]), "shape"),
    ]:
        with pytest.raises(ValueError, match=match):
            ts.export(sphere_sol, tmp_path / "bad.vtp", mesh=(v, faces))
    with pytest.raises(ValueError, match="NaN or inf"):
        ts.export(sphere_sol, tmp_path / "bad.vtp", mesh=(np.where(np.arange(len(v))[:, None] == 3, np.nan, v), f))
    assert not (tmp_path / "bad.vtp").exists()
    with pytest.raises(ValueError, match="control characters"):
        ts.export(sphere_sol, tmp_path / "s.vtp", point_data={"a\x01b": v[:, 0]})
    with pytest.raises(ValueError, match=r"point_data\['t'\] must have shape"):
        ts.export(sphere_sol, tmp_path / "s.vtp", point_data={"t": np.zeros((len(v), 5, 2))})
    # a vector per vertex and a name with XML's special characters: a well-formed file, read back
    name = 'a "b" <c> & d'
    p, cells, data = read_vtp(ts.export(sphere_sol, tmp_path / "s.vtp", point_data={name: v, "x": v[:, 0]}))
    assert np.array_equal(data[name], v) and np.array_equal(data["x"], v[:, 0]) and np.array_equal(cells, f)


def test_plot_levels_and_dense_fill_are_checked(circle_sol):
    # levels=-3 raised from matplotlib's locator, 2.5 was cut to 2, fill='x' from NumPy
    pytest.importorskip("matplotlib")
    for bad in (-3, 2.5, True):
        with pytest.raises(ValueError, match="levels must be a number of iso-lines"):
            ts.plot(circle_sol, levels=bad)
    with pytest.raises(ValueError, match="levels must be finite"):
        ts.plot(circle_sol, levels=[0.5, np.nan])
    with pytest.raises(TypeError, match="levels must hold real numbers"):
        ts.plot(circle_sol, levels=[0.5 + 1j])
    ts.plot(circle_sol, levels=4.0)
    for bad in ("x", 1j, True, [1, 2]):
        with pytest.raises(TypeError, match="fill must be a real number"):
            circle_sol.to_dense(fill=bad)
    dense = circle_sol.to_dense(fill=-1)
    assert np.count_nonzero(dense == -1) == circle_sol.grid.size - len(circle_sol.values)


def test_export_quads_point_data_and_bad_files(sphere_sol, tmp_path):
    pytest.importorskip("meshio")
    v, f = ts.surfaces.Sphere(0.5).triangulation(10)
    ts.export(sphere_sol, tmp_path / "q.vtu", mesh=(v, [[0, 1, 2, 3]]))  # quads: meshio's WriteError before
    with pytest.raises(ValueError, match="mesh must have vertices and faces"):
        ts.export(sphere_sol, tmp_path / "e.vtp", mesh=(v, np.zeros((0, 3), int)))
    assert not list(tmp_path.glob("e.vtp*"))  # no truncated file left behind
    with pytest.raises(ValueError, match="the solution's own field"):  # silently replaced u
        ts.export(sphere_sol, tmp_path / "p.vtp", mesh=(v, f), point_data={"u": np.zeros(len(v))})
    with pytest.raises(TypeError, match="point_data must be a dict"):
        ts.export(sphere_sol, tmp_path / "p.vtp", point_data=[1, 2])
    with pytest.raises(TypeError, match="must hold real numbers"):
        ts.export(sphere_sol, tmp_path / "p.vtp", mesh=(v, f), point_data={"c": np.zeros(len(v)) + 1j})
    junk = tmp_path / "junk.vtp"
    junk.write_text("hello")
    with pytest.raises(ValueError, match="junk.vtp: not an XML VTK file"):
        ts.output.read_vtp(junk)


def test_vtp_export_keeps_the_target_s_mode_and_writes_through_symlinks(circle_sol, tmp_path):
    import os

    target = tmp_path / "a.vtp"
    ts.export(circle_sol, target)
    os.chmod(target, 0o600)  # a private file stays private (the rename made it 0644)
    ts.export(circle_sol, target)
    assert os.stat(target).st_mode & 0o777 == 0o600
    link = tmp_path / "l.vtp"
    link.symlink_to(target)
    ts.export(circle_sol, link)
    assert link.is_symlink() and len(ts.output.read_vtp(target)[0]) > 0
    (tmp_path / "d.vtp").mkdir()
    with pytest.raises(IsADirectoryError):
        ts.export(circle_sol, tmp_path / "d.vtp")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.vtp", "d.vtp", "l.vtp"]


def test_an_export_that_cannot_be_written_names_the_path_given(sphere_sol, tmp_path):
    # a missing folder is made; a file where a folder should be is named with the path given
    # (the error named only the file)
    assert ts.export(sphere_sol, tmp_path / "missing" / "x.vtp").exists()
    (tmp_path / "afile").write_text("")
    target = tmp_path / "afile" / "x.vtp"
    with pytest.raises(FileExistsError, match=rf"cannot write {re.escape(str(target))}: its folder"):
        ts.export(sphere_sol, target)


def test_export_and_triangulate_refuse_what_is_not_a_surface_solution(tmp_path):
    # a box solution raised "AttributeError: 'BoxSolution' object has no attribute 'surface'"
    box = ts.travel_time(ts.Grid((-1,) * 3, (1,) * 3, (21,) * 3), [(0, 0, 0)], return_solution=True)
    with pytest.raises(TypeError, match=r"export: sol must be a solution on a surface .* got BoxSolution: .*np.save"):
        ts.export(box, tmp_path / "b.vtu")
    with pytest.raises(TypeError, match=r"triangulate: sol must be a solution on a surface .* got BoxSolution"):
        ts.triangulate(box)
    with pytest.raises(TypeError, match=r"got int$"):
        ts.export(5, tmp_path / "x.vtp")
    assert not any(tmp_path.iterdir())


def test_on_mesh_leaves_points_beyond_the_tube_nan_with_the_warning():
    # the sphere's centre, 7.5 spacings inside, read 0.29 from a band node 3.5 spacings away
    g = ts.Grid((-1,) * 3, (1,) * 3, (31,) * 3)
    sol = ts.solve(ts.surfaces.Sphere(0.5), g, [(-0.5, 0, 0)])
    with pytest.warns(RuntimeWarning, match="on_mesh: 2 of 4 vertices lie off the band"):
        u = sol.on_mesh([(0.0, 0.0, 0.0), (0.9, 0.0, 0.0), (0.5, 0.0, 0.0), (0.2, 0.0, 0.0)])
    assert np.isnan(u[0]) and np.isnan(u[1])
    assert abs(u[2] - np.pi / 2) < 0.03 and abs(u[3] - np.pi / 2) < 0.05  # the antipode; (0.2, 0, 0): 4.5 spacings in
