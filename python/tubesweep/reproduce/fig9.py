"""Fig. 9 of the paper (Sect. 6.2): eikonal solutions on surfaces in the closest-point
representation — the upper hemisphere (open) and the Möbius band (open and non-orientable) —
solved on a Cartesian band and interpolated onto a triangulated surface.

Writes ``fig9.png`` (both surfaces from two viewpoints, coloured by u, the source marked),
``fig9_convergence.png``, ``fig9_errors.csv`` and ``fig9.md``. Errors: the hemisphere against the
great-circle distance (exact: a closed hemisphere is geodesically convex), over the whole
triangulation and on the rim circle alone; the Möbius band against exact polyhedral geodesics
(pygeodesic, MMP algorithm) on a fine triangulation — skipped with a note if pygeodesic is not
installed (``pip install pygeodesic``).
"""

from __future__ import annotations

import csv
import time
from pathlib import Path
from typing import Dict, List

import numpy as np

from ..grid import Grid
from ..solve import solve
from ..surfaces import Hemisphere, MobiusBand

HAMILTONIANS = ("godunov", "lxf")


def _plt():
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    except ImportError:
        raise ImportError(
            "fig9 needs matplotlib: pip install 'tubesweep[plot]', or pip install '.[plot]' in a checkout"
        ) from None
    return plt, Poly3DCollection


def mobius_reference(m: MobiusBand, source: np.ndarray, n: int):
    """Polyhedral geodesic distances from ``source`` on ``m.triangulation(n)``, or None without pygeodesic."""
    try:
        import pygeodesic.geodesic as geo
    except ImportError:
        return None
    V, F = m.triangulation(n)
    i = int(np.argmin(np.linalg.norm(V - source, axis=1)))
    d, _ = geo.PyGeodesicAlgorithmExact(V, F).geodesicDistances(np.array([i]), None)
    return V, np.asarray(d)


def _draw(ax, Poly3DCollection, V, F, u, vmax, source, title, elev, azim, cmap) -> None:
    face_u = u[F].mean(axis=1)
    colours = cmap(np.clip(face_u / vmax, 0, 1))
    # edges in the face colour: no anti-aliasing seams between the small triangles
    coll = Poly3DCollection(V[F], facecolors=colours, edgecolors=colours, linewidths=0.3)
    ax.computed_zorder = False  # keep the source marker on top even where the surface hides it
    coll.set_zorder(1)
    ax.add_collection3d(coll)
    ax.scatter(
        *np.asarray(source).reshape(1, 3).T, c="r", s=70, marker="o", edgecolors="w", depthshade=False, zorder=10
    )
    lo, hi = V.min(0), V.max(0)
    c = 0.5 * (lo + hi)
    r = 0.5 * (hi - lo).max()
    ax.set_xlim(c[0] - r, c[0] + r), ax.set_ylim(c[1] - r, c[1] + r), ax.set_zlim(c[2] - r, c[2] + r)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev, azim)
    ax.set_title(title, fontsize=10)
    ax.set_axis_off()


def run(out_dir: Path, quick: bool = False) -> dict:
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    hemi = Hemisphere()
    mob = MobiusBand()
    h_src = hemi.default_source
    m_src = mob.point(np.pi / 2, 0.0)  # type: ignore[arg-type]
    h_sizes = (41, 81) if quick else (41, 81, 161, 321)
    m_sizes = (41, 81) if quick else (41, 81, 161)
    Vh, Fh = hemi.triangulation(48)
    rim = Vh[np.abs(Vh[:, 2] - hemi.center[2]) < 1e-12]
    exact_h = hemi.geodesic_distance(Vh, h_src)  # type: ignore[arg-type]
    ref = mobius_reference(mob, m_src, 16 if quick else 32)
    rows: List[Dict[str, object]] = []
    last: Dict[str, np.ndarray] = {}
    for ham in HAMILTONIANS:
        for n in h_sizes:
            t0 = time.perf_counter()
            sol = solve(hemi, Grid(*hemi.default_box, (n,) * 3), [h_src], hamiltonian=ham, order=1)
            wall = time.perf_counter() - t0
            u = sol(Vh)
            e = np.abs(u - exact_h)
            er = np.abs(sol(rim) - hemi.geodesic_distance(rim, h_src))  # type: ignore[arg-type]
            rows.append(
                dict(
                    surface="hemisphere",
                    hamiltonian=ham,
                    N=n,
                    max_error=float(np.max(e)),
                    mean_error=float(np.mean(e)),
                    rim_max_error=float(np.max(er)),
                    iterations=sol.stats.iterations,
                    band_points=sol.stats.band_points,
                    seconds=round(wall, 3),
                )
            )
            if ham == "godunov":
                last["hemisphere"] = u
        for n in m_sizes:
            t0 = time.perf_counter()
            sol = solve(mob, Grid(*mob.default_box, (n,) * 3), [m_src], hamiltonian=ham, order=1)
            wall = time.perf_counter() - t0
            row: Dict[str, object] = dict(
                surface="mobius",
                hamiltonian=ham,
                N=n,
                max_error=np.nan,
                mean_error=np.nan,
                rim_max_error=np.nan,
                iterations=sol.stats.iterations,
                band_points=sol.stats.band_points,
                seconds=round(wall, 3),
            )
            if ref is not None:
                Vr, dr = ref
                e = np.abs(sol(Vr) - dr)
                row.update(max_error=float(np.max(e)), mean_error=float(np.mean(e)))
                bnd = (
                    np.abs(
                        np.abs(
                            np.einsum(
                                "ij,ij->i",
                                Vr - mob.point(np.arctan2(Vr[:, 1], Vr[:, 0]), 0.0),
                                mob._derivs(np.arctan2(Vr[:, 1], Vr[:, 0]), np.zeros(len(Vr)))[2],
                            )
                        )
                        - mob.w
                    )
                    < 1e-9
                )
                row["rim_max_error"] = float(np.max(e[bnd])) if np.any(bnd) else np.nan
            rows.append(row)
            if ham == "godunov":
                last["mobius_sol"] = sol  # type: ignore[assignment]
    # ---------------------------------------------------------------- tables
    keys = list(rows[0])
    with open(out_dir / "fig9_errors.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)

    def order(surface: str, ham: str, key: str) -> List[str]:
        r = [x for x in rows if x["surface"] == surface and x["hamiltonian"] == ham]
        out = ["–"]
        for a, b in zip(r[:-1], r[1:]):
            ea, eb = float(a[key]), float(b[key])  # type: ignore[arg-type]
            out.append(f"{np.log2(ea / eb):.2f}" if np.isfinite(ea) and np.isfinite(eb) and eb > 0 else "–")
        return out

    lines = [
        "# Fig. 9 — closest-point surfaces (paper Sect. 6.2)",
        "",
        "Hemisphere: radius 0.5, source at polar angle π/4, error against the great-circle distance at the "
        f"{len(Vh)} vertices of its triangulation (rim: the {len(rim)} vertices on the boundary circle). "
        "Möbius band: R = 0.6, half-width 0.3, source X(π/2, 0); error against exact polyhedral geodesics "
        + (
            f"(pygeodesic) on a {len(ref[0])}-vertex triangulation (rim: its boundary vertices)."
            if ref is not None
            else "— **skipped: pygeodesic is not installed** (`pip install pygeodesic`)."
        ),
        "Grid: the cube [-1, 1]³ with N nodes per side; inner/outer widths 2Δx/4Δx; source_init='exact'.",
        "",
        "| surface | H | N | max error | order | mean error | rim max error | iterations | band points | seconds |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for surface in ("hemisphere", "mobius"):
        for ham in HAMILTONIANS:
            r = [x for x in rows if x["surface"] == surface and x["hamiltonian"] == ham]
            for x, o in zip(r, order(surface, ham, "max_error")):
                lines.append(
                    f"| {surface} | {ham} | {x['N']} | {x['max_error']:.4g} | {o} | {x['mean_error']:.4g} | "
                    f"{x['rim_max_error']:.4g} | {x['iterations']} | {x['band_points']} | {x['seconds']} |"
                )
    (out_dir / "fig9.md").write_text("\n".join(lines) + "\n")
    # ---------------------------------------------------------------- pictures
    plt, Poly3DCollection = _plt()
    cmap = plt.get_cmap("viridis")
    Vm, Fm = mob.triangulation(48)
    um = last["mobius_sol"](Vm)  # type: ignore[operator]
    uh = last["hemisphere"]
    fig = plt.figure(figsize=(11, 9.5))
    panels = [
        (Vh, Fh, uh, h_src, "(a) upper hemisphere", 30, -60),
        (Vh, Fh, uh, h_src, "(b) upper hemisphere from below (source seen through)", -35, 30),
        (Vm, Fm, um, m_src, "(c) Möbius band", 35, -60),
        (Vm, Fm, um, m_src, "(d) Möbius band, other side", 50, 120),
    ]
    for i, (V, F, u, s, title, elev, azim) in enumerate(panels):
        ax = fig.add_subplot(2, 2, i + 1, projection="3d")
        vmax = float(np.nanmax(u))
        _draw(ax, Poly3DCollection, V, F, np.nan_to_num(u, nan=vmax), vmax, s, title, elev, azim, cmap)
        sm = plt.cm.ScalarMappable(cmap=cmap, norm=plt.Normalize(0, vmax))
        fig.colorbar(sm, ax=ax, shrink=0.6, label="u (geodesic distance)")
    n_h, n_m = h_sizes[-1], m_sizes[-1]
    fig.suptitle(
        f"Fig. 9: Godunov two-layer solutions interpolated onto triangulated surfaces "
        f"(hemisphere N={n_h}, Möbius N={n_m}); red dot = source",
        fontsize=11,
    )
    fig.tight_layout()
    fig.savefig(out_dir / "fig9.png", dpi=110)
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for surface, marker in (("hemisphere", "o"), ("mobius", "s")):
        for ham, ls in (("godunov", "-"), ("lxf", "--")):
            r = [x for x in rows if x["surface"] == surface and x["hamiltonian"] == ham]
            if all(np.isfinite(float(x["max_error"])) for x in r):  # type: ignore[arg-type]
                ax.loglog(
                    [2.0 / (int(x["N"]) - 1) for x in r],  # type: ignore[call-overload]
                    [x["max_error"] for x in r],
                    ls,
                    marker=marker,
                    label=f"{surface}, {ham}",
                )
    hs = np.array([2.0 / 40, 2.0 / 320])
    ax.loglog(hs, 2.0 * hs, "k:", label="first order")
    ax.set_xlabel("Δx"), ax.set_ylabel("max error on the triangulation")
    ax.legend(fontsize=8)
    ax.grid(True, which="both", alpha=0.3)
    ax.set_title("Fig. 9 surfaces: convergence")
    fig.tight_layout()
    fig.savefig(out_dir / "fig9_convergence.png", dpi=110)
    plt.close(fig)
    files = ["fig9.png", "fig9_convergence.png", "fig9_errors.csv", "fig9.md"]
    for f in files:  # type: ignore[assignment]
        print(f"wrote {out_dir / f}")  # type: ignore[operator]
    return {"rows": rows, "files": [str(out_dir / f) for f in files]}


EXPERIMENTS = {"fig9": run}
