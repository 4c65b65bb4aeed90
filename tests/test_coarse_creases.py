"""The crease test through a smoothing (tubesweep._coarse_creases): creases of voxel masks and
noisy φ, whose kinks at the grid's scale hide them from the crease tests that compare neighbours."""

import warnings

import numpy as np
import pytest

import tubesweep as ts
from tubesweep._coarse_creases import READ_SHARE, TURN, TURN_CONCAVE, faces_of_turn, smoothed_turning
from tubesweep._prepare import _prepare_tube


def _fused_balls(n, faces_degrees, r=0.5):
    """Two balls of radius r whose faces meet at ``faces_degrees`` (joined by min), on the grid of
    n nodes per axis over [-1, 1]³; the source at the far pole of the first, points along the
    second's meridian beyond the crease and their exact distances."""
    grid = ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3)
    x = np.stack(grid.meshgrid(), axis=-1)
    c = r * np.sin(np.radians(faces_degrees / 2))
    d = np.minimum(np.linalg.norm(x + [c, 0, 0], axis=-1), np.linalg.norm(x - [c, 0, 0], axis=-1)) - r
    crease = np.arccos(-c / r)  # the crease's polar angle from the second ball's pole
    beta = np.linspace(0.05, crease - 0.1, 40)
    points = np.c_[c + r * np.cos(beta), r * np.sin(beta), 0 * beta]
    return grid, d, (-c - r, 0, 0), points, r * (2 * crease - beta)


def _capsule(x, p, q, r):
    p, q = np.asarray(p, float), np.asarray(q, float)
    t = np.clip(((x - p) @ (q - p)) / ((q - p) @ (q - p)), 0, 1)
    return np.linalg.norm(x - p - t[..., None] * (q - p), axis=-1) - r


def _smooth_min(a, b, k):
    blend = np.clip(0.5 + 0.5 * (b - a) / k, 0, 1)
    return b * (1 - blend) + a * blend - k * blend * (1 - blend)


def _turning(surface, grid):
    with warnings.catch_warnings():  # (the fused balls' narrow gap at the crease: tested below)
        warnings.simplefilter("ignore", RuntimeWarning)
        tube = _prepare_tube(surface, grid, 2.0, 4.0, "two-layer", keep_geometry=False)
    return smoothed_turning(grid, tube.band, tube.phi)[1]


@pytest.mark.parametrize("n", [41, 81])
def test_a_mask_s_crease_reads_through_the_smoothing_and_its_smooth_parts_do_not(n):
    grid = ts.Grid((-1,) * 3, (1,) * 3, (n,) * 3)
    x = np.stack(grid.meshgrid(), axis=-1)
    ball = ts.LevelSet.from_mask(np.linalg.norm(x, axis=-1) < 0.5, grid)  # 10 and 20 voxels in radius
    torus = ts.LevelSet.from_mask(np.hypot(np.hypot(x[..., 0], x[..., 1]) - 0.5, x[..., 2]) < 0.25, grid)
    # a ball 10 and 20 voxels in radius, a torus's tube 5 and 10: 27.7/20.5°, 57.8/29.9°
    for surface, most in ((ball, 30.0), (torus, TURN)):
        turning = _turning(surface, grid)
        assert turning.size > 1000 and np.max(turning) < most
    _, d, _, _, _ = _fused_balls(n, 122)
    turning = _turning(ts.LevelSet.from_mask(d < 0, grid), grid)
    # the faces' 122° read as 77° (a share of 0.63)
    assert READ_SHARE * 122 < np.max(turning) < 0.75 * 122
    assert np.count_nonzero(turning > TURN) >= 200  # along the crease's circle: 216 and 408


def test_auto_on_a_mask_with_a_crease_says_how_early_the_front_arrives_beyond_it():
    # two balls fused at 122° given as a voxel mask: "auto" runs first order (the staircase), and
    # beyond the crease the front came out 4.0Δx early on average at N = 41 (5.0 at worst) with no
    # warning: the crease tests stand down on a mask's staircase
    grid, d, source, points, exact = _fused_balls(41, 122)
    with pytest.warns(RuntimeWarning, match="faces itself across gaps"):
        with pytest.warns(
            RuntimeWarning,
            match=r"order='auto' ran the first-order scheme, and φ's level sets have creases or corners \(216 tube "
            r"nodes next to the surface where .* turns by 76° within two spacings, taken for faces whose normals differ by up to "
            r"127°.* arrives early by up to about 0\.405 \(8\.1·Δx\) per crease",
        ):
            sol = ts.solve(ts.LevelSet.from_mask(d < 0, grid), grid, [source])
    assert sol.stats.order == 1 and sol.stats.creases["nodes"] == 216
    assert sol.stats.creases["smoothed_turn_degrees"] == pytest.approx(76.46, abs=0.01)
    early = sol(points) - exact
    assert -0.405 < np.min(early) < -4.5 * grid.spacing and np.mean(early) < -3.5 * grid.spacing


def test_order_1_on_a_noisy_phi_with_a_crease_says_how_early_the_front_arrives_beyond_it():
    # the same balls at 106° as a distance with noise of 0.3Δx, re-distanced, order=1 at N = 61:
    # 5.6Δx early on average beyond the crease (7.2 at worst), with no warning
    grid, d, source, points, exact = _fused_balls(61, 106)
    noisy = d + 0.3 * grid.spacing * np.random.default_rng(0).normal(size=d.shape)
    with pytest.warns(RuntimeWarning, match="faces itself across gaps"):
        with pytest.warns(
            RuntimeWarning,
            match=r"creases or corners \(130 tube nodes next to the surface where .* faces whose normals differ by up to "
            r"107°.* in the paper's tube \(order=1\) a front crossing one cuts the corner and arrives early by up to about "
            r"0\.27 \(8\.1·Δx\) per crease it crosses",
        ):
            sol = ts.solve(ts.LevelSet(noisy, redistance=True), grid, [source], order=1)
    said = 1.5 * sol.stats.creases["shortcut_per_inner_width"] * 2 * grid.spacing
    early = sol(points) - exact
    assert -said < np.min(early) and np.mean(early) < -5 * grid.spacing


def test_masks_of_smooth_objects_report_no_crease():
    grid = ts.Grid((-1,) * 3, (1,) * 3, (61,) * 3)
    x = np.stack(grid.meshgrid(), axis=-1)
    ellipsoid = np.sqrt((x[..., 0] / 0.8) ** 2 + (x[..., 1] / 0.5) ** 2 + (x[..., 2] / 0.3) ** 2) < 1
    torus = np.hypot(np.hypot(x[..., 0], x[..., 1]) - 0.5, x[..., 2]) < 0.2
    # two balls at 90° joined by a smooth minimum blending over 6 voxels: a concave neck, no crease
    c = 0.5 * np.sin(np.radians(45))
    a, b = (np.linalg.norm(x + [s * c, 0, 0], axis=-1) - 0.5 for s in (1, -1))
    neck = _smooth_min(a, b, 0.2) < 0
    # a trunk and two branches blended over 2.4 voxels: the crotch turns by 43–50° at a few nodes,
    # and nothing beyond it came out earlier than elsewhere (said 4.3Δx before MIN_CONCAVE_NODES)
    tree = _smooth_min(_capsule(x, (0, -0.6, 0), (0, 0, 0), 0.2), _capsule(x, (0, 0, 0), (0.55, 0.65, 0.1), 0.15), 0.08)
    tree = _smooth_min(tree, _capsule(x, (0, 0, 0), (-0.55, 0.65, -0.1), 0.15), 0.08) < 0
    cases = ((ellipsoid, (0, 0, 0.3)), (torus, (0.7, 0, 0)), (neck, (-c - 0.5, 0, 0)), (tree, (0.636, 0.773, 0.1)))
    for mask, source in cases:
        for order in ("auto", 1):
            sol = ts.solve(ts.LevelSet.from_mask(mask, grid), grid, [source], order=order)
            assert sol.stats.order == 1 and (sol.stats.creases is None or sol.stats.creases["nodes"] == 0)


def test_a_concave_crease_is_read_from_a_lower_turn_than_a_convex_edge():
    # two balls fused at 90° as a voxel mask, N = 41: the smoothing reads their concave crease as a
    # turn of 49°, below TURN, which a torus's tube five voxels in radius reaches (52–58°, convex);
    # "auto" came out 2.9Δx early at worst beyond the crease with no warning
    grid, d, source, points, exact = _fused_balls(41, 90)
    with pytest.warns(
        RuntimeWarning,
        match=r"order='auto' ran the first-order scheme, and φ's level sets have creases or corners \(184 tube nodes "
        r".* turns by 49° within two spacings, taken for faces whose normals differ by up to 99° .* or a concave part "
        r"curved more tightly than about three spacings\): .* early by up to about 0\.233 \(4\.7·Δx\) per crease",
    ):
        sol = ts.solve(ts.LevelSet.from_mask(d < 0, grid), grid, [source])
    creases = sol.stats.creases
    assert creases["concave"] and TURN_CONCAVE < creases["smoothed_turn_degrees"] < TURN
    early = exact - sol(points)
    assert 2.5 * grid.spacing < np.max(early) < 0.233  # 2.93Δx
    # the faces' angle read back: 90° for a concave turn of 45°, 100° for 50–60°, turn/0.6 above
    assert [round(faces_of_turn(t, False)) for t in (45, 50, 55, 60, 72)] == [90, 100, 100, 100, 120]
    assert faces_of_turn(60, True) == pytest.approx(80)


def test_a_mask_smoothed_over_a_voxel_says_its_rounded_crease_at_second_order():
    # the fused balls as a mask with smooth=1: the smoothing rounds the crease, which the crease
    # test, comparing neighbours, read at N = 41 as none (4.6Δx early at worst beyond it with no
    # warning, second order) and at N = 61, 140°, as 75° (2.5Δx said, 3.3Δx measured)
    grid, d, source, points, exact = _fused_balls(41, 122)
    with pytest.warns(
        RuntimeWarning,
        match=r"creases or corners \(176 tube nodes next to the surface where .* turns by 67° within two spacings, taken for "
        r"faces whose normals differ by up to 111°.* arrives early by up to about 0\.293 \(5\.9·Δx, 2·tan\(θ/2\)",
    ):
        sol = ts.solve(ts.LevelSet.from_mask(d < 0, grid, smooth=1), grid, [source])
    creases = sol.stats.order2["creases"]
    assert sol.stats.order == 2 and creases["smoothing_only"] and creases["nodes"] == 176
    early = sol(points) - exact
    assert -0.293 < np.min(early) < -4.5 * grid.spacing  # -4.58Δx
    grid, d, source, points, exact = _fused_balls(61, 140)
    with pytest.warns(
        RuntimeWarning,
        match=r"\(24 tube nodes, the normal turning by up to 75°, the faces by up to 133° \(read through a smoothing "
        r"of φ\)\): a front that crosses one arrives early by up to about 0\.191 \(5\.7·Δx with the inner tube",
    ):
        sol = ts.solve(ts.LevelSet.from_mask(d < 0, grid, smooth=1), grid, [source])
    assert sol.stats.order2["creases"]["smoothed_turn_degrees"] == pytest.approx(79.72, abs=0.01)
    early = sol(points) - exact
    assert -0.191 < np.min(early) < -3.2 * grid.spacing  # -3.32Δx


def test_order_1_on_a_mask_smoothed_over_a_voxel_reads_its_crease_s_faces_through_the_smoothing():
    # N = 61, 122°: the crease test read the rounded crease's faces at 84° and said 5.4Δx, where
    # the front came out 8.3Δx early at worst
    grid, d, source, points, exact = _fused_balls(61, 122)
    with pytest.warns(
        RuntimeWarning,
        match=r"\(104 tube nodes next to the surface where .* faces whose normals differ by up to 119°.* in the paper's "
        r"tube \(order=1\) a front crossing one cuts the corner and arrives early by up to about 0\.342 \(10·Δx\) per "
        r"crease it crosses",
    ):
        sol = ts.solve(ts.LevelSet.from_mask(d < 0, grid, smooth=1), grid, [source], order=1)
    assert sol.stats.creases["smoothed_turn_degrees"] == pytest.approx(71.61, abs=0.01)
    early = sol(points) - exact
    assert -0.342 < np.min(early) < -8 * grid.spacing  # -8.30Δx


def test_a_closed_cylinder_s_mask_says_its_rims_and_a_thin_capsule_s_says_no_crease():
    # a closed cylinder (r = 0.5, height 0.8) as a voxel mask at N = 61: "auto" refused it for its
    # unresolved curvature, not for noise, and said nothing of its rims (2.9Δx early across two,
    # a helper's review); its 90° rims, convex edges, read as 77° and were taken for 128° (8.2Δx
    # said per rim) until convex edges got their own share; a capsule four voxels in radius,
    # smooth, read as creased at N = 81
    grid = ts.Grid((-1,) * 3, (1,) * 3, (61,) * 3)
    x = np.stack(grid.meshgrid(), axis=-1)
    cylinder = np.maximum(np.hypot(x[..., 0], x[..., 1]) - 0.5, np.abs(x[..., 2]) - 0.4) < 0
    with pytest.warns(
        RuntimeWarning,
        match=r"order='auto' ran the first-order scheme, and φ's level sets have creases or corners \(1374 tube nodes "
        r".* faces whose normals differ by up to 102°.* arrives early by up to about 0\.166 \(5·Δx\) per crease",
    ):
        sol = ts.solve(ts.LevelSet.from_mask(cylinder, grid), grid, [(0, 0, -0.4)])
    t = np.linspace(0.05, 0.45, 30)  # the top cap, across two rims from the bottom centre
    early = 0.5 + 0.8 + (0.5 - t) - sol(np.c_[t, 0 * t, 0 * t + 0.4])
    assert 2.5 * grid.spacing < np.max(early) < 2 * 0.166  # 2.90Δx across two rims
    grid = ts.Grid((-1,) * 3, (1,) * 3, (81,) * 3)
    x = np.stack(grid.meshgrid(), axis=-1)
    axis = np.clip(x[..., 2], -0.6, 0.6)
    capsule = np.sqrt(x[..., 0] ** 2 + x[..., 1] ** 2 + (x[..., 2] - axis) ** 2) < 0.1
    sol = ts.solve(ts.LevelSet.from_mask(capsule, grid), grid, [(0, 0, -0.7)])
    assert sol.stats.order == 1 and sol.stats.creases is None
