"""Hostile inputs, group 9 continued (``api_reach`` has 9a–9d and the shared set-ups): 9e the
anisotropic Hamiltonians (``ts.hamiltonians.Metric``, flows) on the sphere and in the box, 9f the
command line run as a user runs it (``python -m tubesweep``), 9g meshes and point clouds with
awkward records at the default (second) order. The names start with ``reach-`` as group 9's.
"""

from hostile.api_reach import CLOUD, ICO, snippet
from hostile.framework import case

# ------------------------------------------------------------------------------------------------
# 9e. the anisotropic Hamiltonians (docs/hamiltonians.md) on the sphere and in the box
# ------------------------------------------------------------------------------------------------
HAM = """
H = ts.hamiltonians
R = np.linalg.norm(np.stack(G3.meshgrid(), axis=-1), axis=-1)
def on_sphere(**kw):
    return ts.solve(SPHERE, G3, [(0.5, 0, 0)], **kw)
"""
case(
    "reach-metric/M = 4 I equals the isotropic solve at speed 2",
    snippet(
        HAM,
        """
        a = on_sphere(hamiltonian=H.Metric(4 * np.eye(3)))
        b = on_sphere(speed=2.0, order=1)
        # sqrt(pᵀ 4I p) = 1 is |p| = 1/2; the upwind solver gives Eq. (3) for M = I to 2e-9
        ok = a.stats.local_solver == "upwind" and close(a.values, b.values, 1e-7)
        """,
    ),
    expect="correct",
)
for label, M, message in [
    ("not symmetric", "[[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]", "symmetric"),
    ("indefinite", "np.diag([1.0, -1.0, 1.0])", "positive definite"),
]:
    case(
        f"reach-metric/{label}",
        snippet(HAM, f"sol = on_sphere(hamiltonian=H.Metric({M}))", "ok = False"),
        expect="error",
        message=message,
    )
for label, bad in [
    ("NaN far from the surface", "np.nan"),
    ("not positive definite far from the surface", "-np.eye(3)"),
]:
    case(
        f"reach-metric/an array field {label}",
        snippet(
            HAM,
            f"""
            M = np.diag([2.0, 1.0, 1.0])
            field = np.broadcast_to(M, G3.shape + (3, 3)).copy()
            field[R > 0.9] = {bad}  # never read: interpolated at the band's closest points only
            a, b = on_sphere(hamiltonian=H.Metric(field)), on_sphere(hamiltonian=H.Metric(M))
            ok = close(a.values, b.values, 1e-9)
            """,
        ),
        expect="correct",
    )
case(
    "reach-metric/an asymmetry of 1e-12 is let through",
    snippet(
        HAM,
        """
        M = np.array([[2.0, 0.3, 0], [0.3, 1, 0], [0, 0, 1]])
        Ma = M.copy(); Ma[0, 1] += 1e-12  # docs: up to 1e-10 of |M| is let through (the symmetric part is used)
        ok = close(on_sphere(hamiltonian=H.Metric(Ma)).values, on_sphere(hamiltonian=H.Metric(M)).values, 1e-9)
        """,
    ),
    expect="correct",
)
case(
    "reach-metric/eigenvalues 1e-6 and 1e6 in the box",
    """
    u = ts.travel_time(G2, [(0.0, 0.0)], hamiltonian=ts.hamiltonians.Metric(np.diag([1e-6, 1e6])))
    # u = sqrt(dᵀ M⁻¹ d): 1000 |x| along x, |y| / 1000 along y (beyond the 1e8 ratio the docs test)
    ax = np.abs(np.linspace(-1, 1, 41))
    ok = bool(np.all(np.isfinite(u)) and np.all(u >= 0))
    ok = ok and close(u[:, 20], 1000 * ax, 0.02 * 1000 * ax + 1e-9) and close(u[20, :], ax / 1000, 0.02 * ax / 1000 + 1e-15)
    """,
)
case(
    "reach-flow/a zero flow array with NaN far from the surface",
    snippet(
        HAM,
        """
        v = np.zeros(G3.shape + (3,)); v[R > 0.9] = np.nan
        ok = close(on_sphere(flow=v).values, on_sphere(flow=(0.0, 0.0, 0.0)).values, 1e-12)
        """,
    ),
    expect="correct",
)
case(
    "reach-flow/NaN next to the surface",
    snippet(
        HAM,
        """
        v = np.zeros(G3.shape + (3,)); v[(np.abs(R - 0.5) < 0.1) & (np.stack(G3.meshgrid(), -1)[..., 0] < 0)] = np.nan
        sol = on_sphere(flow=v)
        ok = False
        """,
    ),
    expect="error",
    message="NaN",
)
case(
    "reach-tt/Metric(I) in the box equals the isotropic solve",
    """
    a = ts.travel_time(G2, [(0.013, -0.1)], hamiltonian=ts.hamiltonians.Metric(np.eye(2)))
    ok = close(a, ts.travel_time(G2, [(0.013, -0.1)]), 1e-8)
    """,
    expect="correct",
)
case(
    "reach-tt/a uniform flow against the exact front",
    """
    v = np.array([0.3, -0.2])
    u = ts.travel_time(G2, [(0.0, 0.0)], flow=tuple(v))
    X, Y = G2.meshgrid()
    d = np.stack([X, Y], axis=-1)
    dv, r2, a = d @ v, np.sum(d * d, axis=-1), 1 - v @ v
    exact = (-dv + np.sqrt(dv**2 + a * r2)) / a  # |d − v t| = t, F = 1
    # first order: 2.8e-2 at N = 101 (docs/hamiltonians.md); N = 41 here
    ok = float(np.max(np.abs(u - exact))) < 0.1
    """,
    expect="correct",
)
case(
    "reach-tt/a metric array with NaN at one node of the box",
    """
    M = np.broadcast_to(np.eye(2), G2.shape + (2, 2)).copy(); M[3, 5] = np.nan
    u = ts.travel_time(G2, [(0.0, 0.0)], hamiltonian=ts.hamiltonians.Metric(M))
    ok = False
    """,
    expect="error",
    message="NaN",
)

# ------------------------------------------------------------------------------------------------
# 9f. the command line as a user runs it (python -m tubesweep): a refusal is an "error: …" line and
# a non-zero exit status, never a traceback (cli.py, cli_distances.py: exit status 2)
# ------------------------------------------------------------------------------------------------
CLI = """
import subprocess
def cli(*args):
    return subprocess.run(
        [sys.executable, "-m", "tubesweep", *map(str, args)], capture_output=True, text=True, timeout=100, cwd=TMP
    )
def refused(r):
    err = r.stderr.strip()
    if "Traceback" in err:
        raise RuntimeError("a traceback: " + err.splitlines()[-1][:240])
    if r.returncode == 0:
        return False  # ran on the bad input
    if not err:
        raise RuntimeError(f"exit status {r.returncode} without a message")
    raise ValueError(f"exit status {r.returncode}: {err.splitlines()[-1][:240]}")
def folder(name):  # this case's own folder under TMP
    p = os.path.join(TMP, name)
    os.makedirs(p, exist_ok=True)
    return p
def at(name):  # a file in this case's folder
    return os.path.join(d, name)
def put(name, text):
    with open(at(name), "w") as fh:
        fh.write(text)
BOX = ["--lower", -1, -1, -1, "--upper", 1, 1, 1]
"""
case(
    "reach-cli/distances on the sphere writes the matrix",
    snippet(
        CLI,
        """
        d = folder("c0")
        r = cli("distances", "--surface", "sphere", "--n", 31, "--sample", 3, "--out", os.path.join(d, "D.npy"), "--quiet")
        if r.returncode:
            raise RuntimeError(r.stderr.strip()[-240:])
        D, P = np.load(os.path.join(d, "D.npy")), np.load(os.path.join(d, "D_points.npy"))
        E = 0.5 * np.arccos(np.clip(P @ P.T / 0.25, -1, 1))
        ok = D.shape == (3, 3) and np.array_equal(D, D.T) and np.all(np.diag(D) == 0) and float(np.max(np.abs(D - E))) < 0.05
        """,
    ),
    expect="correct",
)
for k, (label, setup, args, message) in enumerate(
    [
        (
            "distances --phi an empty .npy",
            "put('phi.npy', '')",
            '"distances", "--phi", at("phi.npy"), *BOX, "--sample", 3, "--out", at("D.npy")',
            None,
        ),
        (
            "distances --points an empty .npy",
            "put('p.npy', '')",
            '"distances", "--surface", "sphere", "--n", 31, "--points", at("p.npy"), "--out", at("D.npy")',
            None,
        ),
        (
            "distances --points a .npy that starts like a zip archive",
            "put('p.npy', 'PK\\x03\\x04 not a zip archive')",
            '"distances", "--surface", "sphere", "--n", 31, "--points", at("p.npy"), "--out", at("D.npy")',
            None,
        ),
        (
            "distances --points text with NaN",
            "put('p.txt', '0.5 0 0\\nnan 0 0\\n0 0 0.5\\n')",
            '"distances", "--surface", "sphere", "--n", 31, "--points", at("p.txt"), "--out", at("D.npy")',
            "NaN",
        ),
        (
            "distances --points off the surface",
            "put('p.csv', '0.5,0,0\\n0,0,0\\n')",
            '"distances", "--surface", "sphere", "--n", 31, "--points", at("p.csv"), "--out", at("D.npy")',
            "farther than the inner tube",
        ),
        (
            "distances --points a missing file",
            "",
            '"distances", "--surface", "sphere", "--n", 31, "--points", at("nope.xyz"), "--out", at("D.npy")',
            None,
        ),
        (
            "solve --mask of 0.5 values",
            "np.save(at('m.npy'), np.full((21, 21, 21), 0.5))",
            '"solve", "--mask", at("m.npy"), *BOX, "--source", 0.5, 0, 0, "--out", at("o"), "--quiet"',
            None,
        ),
        (
            "travel-time --dim 3 with a 2-D source",
            "",
            '"travel-time", "--dim", 3, "--n", 11, "--source", 0, 0, "--out", at("o"), "--quiet"',
            None,
        ),
    ]
):
    case(
        f"reach-cli/{label}",
        snippet(CLI, f"d = folder('c{k + 1}')", setup, f"ok = refused(cli({args}))"),
        expect="error",
        message=message,
    )

# ------------------------------------------------------------------------------------------------
# 9g. meshes and point clouds with awkward records, solved at the default (second) order
# (docs/point-clouds.md: a smooth map of a mesh fine against the grid runs second order)
# ------------------------------------------------------------------------------------------------
case(
    "reach-mesh2/every face twice: the same values, a warning",
    snippet(
        ICO,
        """
        a, ea = mesh_solve(V, F)
        b, eb = mesh_solve(V, np.r_[F, F[::-1]])
        ok = a.stats.order == 2 and a.stats.order2["mesh_map"]["fitted"] > 0 and np.array_equal(a.values, b.values)
        """,
    ),
    expect="warning",
    message="more than once",
)
case(
    "reach-mesh2/every other face flipped",
    snippet(
        ICO,
        """
        f = F.copy(); f[::2] = f[::2, ::-1]  # inconsistent orientation: the mesh is no longer 'closed'
        a, ea = mesh_solve(V, F)
        b, eb = mesh_solve(V, f)
        # the closest-point representation needs no orientation (surfaces/mesh.py)
        ok = b.stats.order == a.stats.order == 2 and eb <= 1.5 * ea + 1e-4
        """,
    ),
    expect="returns",
)
case(
    "reach-mesh2/zero-area triangles added",
    snippet(
        ICO,
        """
        a, ea = mesh_solve(V, F)
        b, eb = mesh_solve(V, np.r_[F, [[0, 0, 7], [9, 9, 9], [11, 12, 11]]])
        ok = b.stats.order == a.stats.order == 2 and eb <= 1.5 * ea + 1e-4
        """,
    ),
    expect="returns",
)
case(
    "reach-mesh2/an unused vertex far away",
    snippet(
        ICO,
        """
        a, ea = mesh_solve(V, F)
        m = ts.surfaces.from_mesh((np.r_[V, [[50.0, 50.0, 50.0]]], F))
        b = ts.solve(m, GM, [V[4]])
        # a vertex no face uses is not part of the surface: not in the mesh's own grid either
        ok = m.grid(41) == ts.surfaces.from_mesh((V, F)).grid(41) and np.array_equal(a.values, b.values)
        """,
    ),
    expect="correct",
)
case(
    "reach-mesh2/an unused vertex just off the surface",
    snippet(
        ICO,
        """
        a, ea = mesh_solve(V, F)
        b, eb = mesh_solve(np.r_[V, [[0.53, 0.02, 0.01]]], F)  # inside the fits' reach
        ok = a.stats.order2["mesh_map"]["fitted"] > 0 and np.array_equal(a.values, b.values)
        """,
    ),
    expect="correct",
)
case(
    "reach-mesh2/a fin on an edge (non-manifold)",
    snippet(
        ICO,
        """
        a, ea = mesh_solve(V, F)
        i, j = F[0, 0], F[0, 1]
        v = np.r_[V, [1.3 * 0.5 * (V[i] + V[j])]]  # a flap standing out of the sphere on the edge (i, j)
        b, eb = mesh_solve(v, np.r_[F, [[i, j, len(V)]]])
        ok = sane(b) and eb <= 2 * ea + 1e-3
        """,
    ),
)
case(
    "reach-cloud2/three stray samples far away, on the cloud's own grid",
    snippet(
        CLOUD,
        """
        # one stray sample is left out with a warning (docs/point-clouds.md, the cloud/* cases); a
        # cluster of three, 8 units from a sphere sampled 0.015 apart, should be too
        cloud = ts.surfaces.from_points(np.r_[P, [[5.0, 5.0, 5.0], [5.1, 5.0, 5.0], [5.0, 5.1, 5.0]]])
        sol = ts.solve(cloud, cloud.grid(41), [P[0]])
        ok = float(np.max(np.abs(sol(P) - EXACT))) < 0.05 and len(cloud.outliers) == 3
        """,
    ),
    expect="warning",
    message="off the surface",
)
case(
    "reach-cloud2/normals flipped at random change nothing",
    snippet(
        CLOUD,
        """
        n = P * rng.choice([-2.0, 2.0], size=(len(P), 1))
        a = ts.solve(ts.surfaces.from_points(P), G3, [P[0]])
        b = ts.solve(ts.surfaces.from_points(P, normals=n), G3, [P[0]])
        ok = a.stats.order == 2 and np.array_equal(a.values, b.values)  # "no orientation is used"
        """,
    ),
    expect="correct",
)
