"""Parts of a surface that face each other across a gap narrower than the tubes
(``_facing._warn_if_tubes_touch``, ``tubesweep_core::band::facing_sheets``): on a level set the solve
warns, says where and how narrow, and records it in ``SolveStats``; a triangle mesh's band is cut
there (``_shortcuts``), its front goes round and its points are read from their own side; surfaces
the grid resolves give no pair."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import tubesweep as ts

PLATE = 0.08  # the thickness of the box 1 × 1 × PLATE


def box_mesh(t: float):
    """The closed box [−½, ½]² × [−t/2, t/2]: 8 vertices, 12 outward triangles."""
    v = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-t / 2, t / 2)])
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    return v, np.array([tri for a, b, c, d in quads for tri in ((a, b, c), (a, c, d))])


@pytest.fixture(scope="module")
def plate():
    return ts.surfaces.from_mesh(box_mesh(PLATE))


def facing_warnings(caught):
    return [w for w in caught if issubclass(w.category, RuntimeWarning) and "faces itself" in str(w.message)]


@pytest.mark.parametrize("n", [41, 81])
def test_a_plate_thinner_than_the_tubes_is_cut_and_the_front_goes_round_it(plate, n, first_order_size):
    # a triangle mesh: the band is cut across the pairs (``_shortcuts``), the source's exact
    # initialisation stops at the cut, and nothing is warned; the stats say it. At n = 41 the
    # first-order fallback (the mesh is coarse against the grid) warns of its size: three spacings
    # are 12% of the distances
    grid = plate.grid(n)
    h = grid.spacing
    with first_order_size(n == 41):
        sol = ts.solve(plate, grid, [[0.0, 0.0, PLATE / 2]])
    assert sol.stats.facing_pairs > 0 and sol.stats.cut_edges >= sol.stats.facing_pairs
    assert sol.stats.narrowest_gap == pytest.approx(PLATE, abs=1e-6)
    # the bottom face's centre, 1 + t away over an edge (it was reached through the plate, 1.9
    # spacings thick at n = 41, at 0.08), and a point 0.1 from an edge, 0.68 away; measured
    # 1.035 / 0.662 at n = 41 and 1.058 / 0.665 at n = 81: two convex edges' first-order error
    u = sol(np.array([[0.0, 0.0, -PLATE / 2], [0.4, 0.0, -PLATE / 2]]))
    assert 1 + PLATE - 2 * h < u[0] < 1 + PLATE
    assert 0.68 - h < u[1] < 0.68


@pytest.mark.parametrize("thickness", [1.5, 1.9])
@pytest.mark.parametrize("shift", [-0.5, -0.2, -0.1, 0.0, 0.1, 0.3])
def test_plates_one_to_two_spacings_thick_are_cut_wherever_they_lie_against_the_grid(
    plate, thickness, shift, first_order_size
):
    # a plate whose face passes within a quarter spacing of a node was missed (review): the
    # pair across its mid-plane was skipped as lying "on the surface"
    grid = plate.grid(41)
    h = grid.spacing
    t = thickness * h
    v, f = box_mesh(t)
    moved = ts.surfaces.from_mesh((v + [0.0, 0.0, shift * h], f))
    with first_order_size(None):  # first order, its errors estimated at 9-12% of the distances
        sol = ts.solve(moved, grid, [[0.0, 0.0, t / 2 + shift * h]])
    u = sol(np.array([[0.0, 0.0, -t / 2 + shift * h]]))[0]
    # exactly 1 + t over an edge; without the cut 0.06–0.08 (through the plate); measured 0.977
    # (thickness 1.5, shift −0.2) to 1.035
    assert 1 + t - 2.5 * h < u < 1 + t
    assert sol.stats.facing_pairs > 0


@pytest.mark.parametrize("shift", [-0.1, 0.0])
def test_points_on_either_face_of_a_thin_plate_are_read_from_their_own_side(plate, shift, first_order_size):
    # the cells of points on a plate 1.5 spacings thick have corners on both faces; the
    # multilinear read-out mixed them (0.26 at the source, 0.87 for 1.06: ``_sheet_readout``)
    grid = plate.grid(41)
    h = grid.spacing
    t = 1.5 * h
    v, f = box_mesh(t)
    moved = ts.surfaces.from_mesh((v + [0.0, 0.0, shift * h], f))
    with first_order_size():
        sol = ts.solve(moved, grid, [[0.0, 0.0, t / 2 + shift * h]])
    x = np.linspace(0.0, 0.45, 10)
    top = sol(np.stack([x, 0 * x, 0 * x + t / 2 + shift * h], 1))
    bottom = sol(np.stack([x, 0 * x, 0 * x - t / 2 + shift * h], 1))
    assert np.max(np.abs(top - x)) < 1e-3  # a straight line from the source: exact
    # over the edge at x = 0.5: 1 + t − x, two convex edges' first-order error (measured ≤ 0.033)
    assert np.max(np.abs(bottom - (1 + t - x))) < h


@pytest.mark.parametrize("as_array", [False, True])
def test_two_spheres_as_min_of_distances_five_spacings_apart_warn(as_array):
    # the central differences of min(d₁, d₂) straddle the ridge between the spheres: the directions
    # there are nearly tangential and the facing test alone missed the crossing (review); the
    # kink of φ (BandGeometry.kink) finds it. The front crosses the gap, but the second sphere's
    # inner tube is another part of the surface, without a source: it stays unreached (``_parts``;
    # before, it got finite, too short distances)
    grid = ts.Grid([-1.2] * 3, [1.2] * 3, (41,) * 3)
    h, r = grid.spacing, 0.45
    axis = np.array([1.0, 1.0, 0.0]) / np.sqrt(2)
    c1, c2 = -(r + 2.5 * h) * axis, (r + 2.5 * h) * axis

    def phi(p):
        return np.minimum(np.linalg.norm(p - c1, axis=1) - r, np.linalg.norm(p - c2, axis=1) - r)

    surface = ts.LevelSet(
        phi(np.stack(grid.meshgrid(), -1).reshape(-1, 3)).reshape(grid.shape) if as_array else phi, lipschitz=1.0
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        # the paper's scheme (order=2 runs node by node here, and its front does not cross)
        sol = ts.solve(surface, grid, [c1 - r * axis], order=1)
    assert np.isinf(sol(np.array([c2 + r * axis]))[0])  # the spheres do not touch
    inner = sol.roles != 2  # the inner tube (role 2: the extension layer, which keeps its values)
    assert np.isinf(sol.values[inner]).sum() > 0.4 * inner.sum()
    assert len(facing_warnings(caught)) == 1 and sol.stats.facing_pairs > 0
    assert 3 * h < sol.stats.narrowest_gap < 7 * h


def test_a_phi_whose_gradient_merely_varies_has_no_kinks():
    # 0.2·(|x/a|² − 1) for a = (0.9, 0.3, 0.3): |∇φ| from 0.36 to 1.56 near the surface, flat
    # towards the tips; the kinks' test against the band's median alone counted 70 pairs there
    # (review); against the node's neighbours too, none
    a = np.array([0.9, 0.3, 0.3])
    grid = ts.Grid((-1.0,) * 3, (1.0,) * 3, (61,) * 3)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = ts.solve(ts.LevelSet(lambda x: 0.2 * (np.sum((x / a) ** 2, -1) - 1)), grid, [(0.9, 0.0, 0.0)])
    assert facing_warnings(caught) == [] and sol.stats.facing_pairs == 0


def test_narrow_gaps_gives_the_pairs_midpoints_inside_the_plate_and_their_gaps(plate, first_order_size):
    grid = plate.grid(41)
    with first_order_size():
        sol = ts.solve(plate, grid, [[0.0, 0.0, PLATE / 2]])
    mid, gap = sol.narrow_gaps()
    assert mid.shape == (sol.stats.facing_pairs, 3) and gap.shape == (sol.stats.facing_pairs,)
    # each midpoint half a spacing from its nodes, the nodes within a spacing of the plate
    assert np.all(np.abs(mid[:, 2]) <= PLATE / 2 + grid.spacing)
    assert np.all(np.abs(mid[:, :2]) <= 0.5 + grid.spacing)
    assert gap.min() == pytest.approx(PLATE, abs=1e-6) and gap.min() == sol.stats.narrowest_gap
    # the copy is the caller's
    gap[:] = 0
    assert sol.narrow_gaps()[1].min() == pytest.approx(PLATE, abs=1e-6)


def test_the_plate_on_the_advised_grid_gives_no_warning_and_first_order_distances(plate):
    grid = plate.grid(121)
    assert grid.spacing < PLATE / 6
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = ts.solve(plate, grid, [[0.0, 0.0, PLATE / 2]])
    assert facing_warnings(caught) == []
    assert sol.stats.facing_pairs == 0 and sol.stats.narrowest_gap == np.inf
    assert sol.narrow_gaps()[0].shape == (0, 3)
    u = sol(np.array([[0.0, 0.0, -PLATE / 2]]))[0]
    # two convex edges on the way, each about 4.5 spacings short (benches/experiments/facing_gaps.py)
    assert 1 + PLATE - 10 * grid.spacing < u < 1 + PLATE


def test_a_tube_on_the_plate_is_cut_at_construction_and_its_solves_record_it(plate, first_order_size):
    with first_order_size(2):  # the solve's and the batch's: first order at n = 41, 12% of the distances
        tube = ts.Tube(plate, plate.grid(41))
        sol = tube.solve([[0.0, 0.0, PLATE / 2]])
        many = tube.solve_many([[0.0, 0.0, PLATE / 2]], at=np.array([[0.0, 0.0, -PLATE / 2]]))
    assert sol.stats.facing_pairs > 0 and sol.stats.cut_edges >= sol.stats.facing_pairs
    # the batch's sources are fixed within the cut too: its row is the single solve's
    u = sol(np.array([[0.0, 0.0, -PLATE / 2]]))[0]
    assert u > 1.0 and np.asarray(many)[0, 0] == u


def test_the_double_torus_body_is_too_thin_for_41_nodes_but_not_for_61():
    surf = ts.surfaces.DoubleTorus()
    lower, upper = surf.default_box
    src = None
    stats = {}
    for n in (41, 61):
        grid = ts.Grid(lower, upper, (n,) * 3)
        if src is None:
            src = np.asarray(surf.project(np.array([[0.9, 0.1, 0.1]]), grid)[1])
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            stats[n] = ts.solve(surf, grid, src).stats
        assert (len(facing_warnings(caught)) == 1) == (n == 41)
    # the body is 2r = 0.24 thick, 4.8 spacings at N = 41
    assert stats[41].facing_pairs > 0 and 0.15 < stats[41].narrowest_gap < 0.25
    assert stats[61].facing_pairs == 0


@pytest.mark.parametrize(
    "name,n",
    [
        ("sphere", 41),
        ("torus", 41),
        ("ellipsoid", 41),
        ("rounded-cube", 41),
        ("hemisphere", 41),
        ("mobius", 41),
        ("plane", 41),
        ("star", 121),
        ("ellipse", 121),
    ],
)
def test_resolved_library_surfaces_give_no_pair(name, n):
    surf = ts.surfaces.REGISTRY[name]()
    lower, upper = surf.default_box
    grid = ts.Grid(lower, upper, (n,) * len(lower))
    src = np.asarray(surf.project(np.array([[0.9, 0.1, 0.1][: len(lower)]]), grid)[1])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = ts.solve(surf, grid, src)
    assert facing_warnings(caught) == []
    assert sol.stats.facing_pairs == 0


@pytest.mark.parametrize("scale,dim", [(0.7, 3), (1.7, 3), (2.2, 3), (2.0, 2), (2.9, 2)])
def test_a_level_set_that_is_only_roughly_a_distance_gives_no_pair(scale, dim):
    # closest points x − |φ| n miss the sphere along n when |∇φ| ≠ 1 (and from |∇φ| = 2 on, two
    # nodes either side of it each lie on its own side of the other's): one sheet all the same
    grid = ts.Grid([-1] * dim, [1] * dim, (61 if dim == 3 else 81,) * dim)
    surf = ts.LevelSet(lambda p: scale * (np.linalg.norm(p, axis=1) - 0.5))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = ts.solve(surf, grid, [[0.5, 0.0, 0.0][:dim]])
    assert facing_warnings(caught) == []
    assert sol.stats.facing_pairs == 0


def test_facing_pairs_are_checked_against_the_band():
    band = ts._native.Band.from_linear([4, 4], np.arange(16, dtype=np.uint64))
    ok = (np.ones(16, bool), np.zeros(16, np.float32), np.zeros((16, 2), np.float32))
    with pytest.raises(ValueError, match="one per band node"):
        band.facing_sheet_pairs(ok[0][1:], ok[1], ok[2], 0.1)
    with pytest.raises(ValueError, match="spacing"):
        band.facing_sheet_pairs(*ok, 0.0)
    with pytest.raises(ValueError, match="shape"):
        band.facing_sheet_pairs(ok[0], ok[1], np.zeros((16, 3), np.float32), 0.1)


def test_a_batch_reads_points_next_to_a_gap_from_their_own_side_as_the_single_solve_does(plate, first_order_size):
    grid = plate.grid(41)
    tube = ts.Tube(plate, grid)
    x = np.linspace(0.0, 0.45, 7)
    at = np.concatenate([np.stack([x, 0 * x, 0 * x + s * PLATE / 2], 1) for s in (1, -1)])
    sources = [[0.0, 0.0, PLATE / 2], [0.3, -0.2, -PLATE / 2]]
    with first_order_size(3):  # first order at n = 41 (the mesh is coarse against the grid)
        rows = tube.solve_many(sources, at=at)
        singles = [tube.solve([s])(at) for s in sources]
    for k, single in enumerate(singles):
        assert np.array_equal(rows[k], single)
    # the source's own face is read from its own side: the straight line from it
    assert np.max(np.abs(rows[0, :7] - x)) < 1e-3


def test_lax_friedrichs_runs_on_the_whole_band_of_a_mesh_and_warns_about_its_gaps(plate):
    # the Lax–Friedrichs update extrapolates a missing neighbour and did not settle beside the
    # cut edges (the bunny at n = 61: 3000 iterations, last change 2e-3): it runs uncut
    grid = plate.grid(41)
    uncut = ts.surfaces.from_mesh(box_mesh(PLATE), cut_shortcuts=False)
    with pytest.warns(RuntimeWarning, match="faces itself across gaps"):
        sol = ts.solve(plate, grid, [[0.0, 0.0, PLATE / 2]], hamiltonian="lxf")
    with pytest.warns(RuntimeWarning, match="faces itself across gaps"):
        ref = ts.solve(uncut, grid, [[0.0, 0.0, PLATE / 2]], hamiltonian="lxf")
    assert sol.stats.converged and sol.stats.cut_edges == 0
    assert np.array_equal(sol.values, ref.values)
    with pytest.warns(RuntimeWarning, match="faces itself across gaps"):
        rows = ts.Tube(plate, grid).solve_many([[0.0, 0.0, PLATE / 2]], hamiltonian="lxf")
    assert np.array_equal(rows[0], ref.values)


@pytest.mark.parametrize("gap", [2.5, 5.0])
def test_a_mesh_part_a_few_spacings_from_the_source_s_part_stays_unreached(gap):
    # two mesh spheres `gap` spacings apart, the source on the left one: the right one is another
    # component, unreached (inf). The front crossed through the extension nodes between them (their
    # closest points on the two spheres) and reached every vertex of it, without a word
    import trimesh

    a = trimesh.creation.icosphere(4, radius=0.35)
    g = ts.Grid((-1,) * 3, (1,) * 3, (81,) * 3)
    d = 0.35 + gap * g.spacing / 2
    left, right = a.vertices - [d, 0, 0], a.vertices + [d, 0, 0]
    mesh = ts.surfaces.from_mesh((np.r_[left, right], np.r_[a.faces, a.faces + len(a.vertices)]))
    src = left[np.argmin(left[:, 0])]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the gap is cut, not warned about; no stranded node either
        sol = ts.solve(mesh, g, [src])
    assert sol.stats.converged and sol.stats.cut_edges > sol.stats.facing_pairs
    assert np.all(np.isinf(sol(right))) and np.all(np.isfinite(sol(left)))
    # the left sphere as a sphere alone would give it, to first order (r·angle)
    exact = ts.surfaces.Sphere(0.35).geodesic_distance(left + [d, 0, 0], src + [d, 0, 0])
    assert np.max(np.abs(sol(left) - exact)) < 3 * g.spacing


def test_parts_of_a_mesh_closer_than_a_spacing_are_said():
    # a flat ellipsoid 0.5 × 0.5 × 0.025: near its rim the two sides lie within a spacing, no
    # facing pair is found there and the front crosses between them (its bottom centre 9 spacings
    # short at N = 61, without a word); the box plate 0.08 thick of the tests above is not warned
    import trimesh

    sphere = trimesh.creation.icosphere(5, radius=1.0)
    v = sphere.vertices * [0.5, 0.5, 0.025]
    mesh = ts.surfaces.from_mesh((v, sphere.faces))
    g = ts.Grid((-0.6,) * 3, (0.6,) * 3, (61,) * 3)
    with pytest.warns(
        RuntimeWarning, match=r"about 18% of the mesh's area lies within about a grid spacing of another"
    ):
        sol = ts.solve(mesh, g, [v[np.argmax(v[:, 2])]])
    # what it warns of: the bottom centre (exact polyhedral geodesic 1.005) several spacings short
    # (3.2; 9 before the facing test also read the mesh's inside and cut the band across more of
    # the rim)
    assert 1.005 - sol.on_mesh(v[[np.argmin(v[:, 2])]])[0] > 2 * g.spacing
    # and a Tube says it once, at construction (kept per spacing on the surface)
    with pytest.warns(RuntimeWarning, match="within about a grid spacing of another part"):
        ts.Tube(mesh, g)


@pytest.mark.parametrize(
    "kind, width, crossed",
    [("plate", 1.0, True), ("plate", 1.1, False), ("slot", 1.5, True), ("slot", 1.75, False)],
)
def test_plates_and_slots_about_a_spacing_across_are_said_where_the_front_crosses_them(
    kind, width, crossed, experiment
):
    # the band is cut between facing parts only from a spacing apart, and a slot's mouth is spanned
    # by the tube above it while the closest points jump across it by less than 1.5 spacings: a
    # plate 0.96–1.0 spacings thick and slots 0.96–1.5 wide were crossed without a word (a helper's
    # review); now parts thinner than 1.05 spacings and gaps narrower than 1.6 are said
    grid = ts.Grid((-0.2,) * 3, (1.2,) * 3, (41,) * 3)
    h = grid.spacing
    w = width * h
    cells_surface = experiment("thin_parts_meshes").cells_surface
    if kind == "plate":
        mesh = cells_surface([[0, 1], [0, 1], [0, w]], np.ones((1, 1, 1), bool))
        source, probe, exact = (0.5, 0.5, w), (0.5, 0.5, 0.0), 1.0 + w
    else:
        filled = np.ones((3, 1, 2), bool)
        filled[1, 0, 1] = False  # a slot 0.3 deep in a block 0.4 high
        mesh = cells_surface([[0, 0.45, 0.45 + w, 0.9 + w], [0, 0.4], [0, 0.1, 0.4]], filled)
        source, probe, exact = (0.2, 0.2, 0.4), (0.7 + w, 0.2, 0.4), 1.1 + w
    surface = ts.surfaces.from_mesh((mesh.vertices, mesh.faces))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sol = ts.solve(surface, grid, [source])
    said = [w for w in caught if "within about a grid spacing of another part" in str(w.message)]
    u = sol.on_mesh(np.array([probe]))[0]
    if crossed:
        assert len(said) == 1 and exact - u > 10 * h  # straight through the plate, across the slot's mouth
    else:
        assert not said and abs(u - exact) < 2 * h
    # the first-order scheme's own error is warned of as ever (the box's edges: order=1)
    others = [str(w.message) for w in caught if w not in said]
    assert all("first-order" in m or "order=1" in m for m in others), others


def test_a_thin_part_is_said_whichever_way_its_faces_are_wound():
    # a plate 0.016 thick with its bottom wound like its top: the thin-part test looked for faces
    # whose normal is opposite to their own and found none (no warning, the bottom's centre 98%
    # short); the normals are now oriented across the mesh's edges first (a review)
    import trimesh
    from tubesweep.surfaces._mesh_checks import oriented_normals

    box = trimesh.creation.box(extents=(1, 1, 0.016))
    for _ in range(4):
        box = box.subdivide()
    v, f = np.asarray(box.vertices), np.asarray(box.faces)
    turned = f.copy()
    bottom = box.triangles_center[:, 2] < 0
    turned[bottom] = turned[bottom][:, ::-1]
    consistent, mixed = ts.surfaces.from_mesh((v, f)), ts.surfaces.from_mesh((v, turned))
    assert not mixed.closed and mixed._flipped_edges > 0
    # oriented as the consistent mesh is (most faces keep the winding given)
    np.testing.assert_array_equal(oriented_normals(mixed), consistent.face_normals)
    grid = mixed.grid(61)
    for mesh in (consistent, mixed):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            sol = ts.solve(mesh, grid, [(0.0, 0.0, 0.008)])
        said = [str(w.message) for w in caught]
        assert any("about 97% of the mesh's area lies within about a grid spacing" in m for m in said), said
        assert sol([(0.0, 0.0, -0.008)])[0] < 0.1  # (what it warns of: exact about 1.016)
