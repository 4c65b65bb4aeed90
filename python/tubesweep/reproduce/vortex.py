"""Figs. 10 and 11 of the paper: the anisotropic eikonal equation in a moving medium (Sect. 6.3),
``|∇_Σ u| = |1 − v·∇u| / F`` on the sphere of radius 0.5 with F = 3, N-point vortex flows of
strength s_j = 4 and the source at (−0.5, 0, 0).

The paper's vortices sit *on* the sphere, where ``|v| = (s/4π) cot(θ/2)`` exceeds F = 3 within an
angle θ ≈ 0.21 of each centre. We therefore compute

* the paper's flow with ``allow_supersonic=True`` (the figures), and
* the same flow with a Lamb–Oseen vortex core ``δ = CORE`` (subsonic everywhere, the same flow
  to within ``exp(−r²/δ²)`` away from the centres), and report how much the
  two differ, near the cores and away from them;
* the unperturbed (v = 0) solution (magenta dotted contours in panels c, d).

Each figure has four orthographic views of the sphere: (a, b) contours of u (black) over the flow
(arrows, coloured by |v|; the red dashed line is |v| = F, red stars are the vortex centres,
the green dot the source); (c, d) the same contours against the unperturbed ones (magenta
dotted). A second figure ``<name>_core.png`` compares the singular and the cored flow. All of these
use the paper's Lax–Friedrichs update (Sect. 5.1; ``hamiltonian="lxf"``). A third figure
``<name>_upwind.png`` shows the cored flow solved with the upwind local solver (the default for
``flow=``; it needs a subsonic flow) against the same flow with Lax–Friedrichs (magenta).
"""

from __future__ import annotations

import json
import time
import warnings
from pathlib import Path
from typing import Any, Dict, Sequence

import numpy as np

from ..flows import point_vortices
from ..grid import Grid
from ..solve import solve
from ..surfaces.analytic import Sphere

RADIUS = 0.5
SPEED = 3.0
STRENGTH = 4.0
SOURCE = (-0.5, 0.0, 0.0)
#: Lamb–Oseen vortex core radius δ of the subsonic comparison flow (a single vortex needs
#: δ > 0.068 here; with the other vortices' flow added, 0.1 keeps max |v|/F ≤ 0.88).
CORE = 0.1
LEVEL_STEP = 0.02

_S3 = 1.0 / (2.0 * np.sqrt(3.0))
CASES: Dict[str, Dict[str, Any]] = {
    "fig10": {
        "centers": [(0.0, 0.0, 0.5), (0.0, -0.5, 0.0), (0.5, 0.0, 0.0)],
        "views": [(-1.0, -1.0, 1.0), (1.0, 1.0, -1.0)],
        "title": "Fig. 10: three-vortex flow",
    },
    "fig11": {
        "centers": [(-_S3, sy * _S3, sz * _S3) for sy in (1, -1) for sz in (1, -1)],
        "views": [(-1.0, -0.35, 0.35), (1.0, 0.35, -0.35)],
        "title": "Fig. 11: four-vortex flow",
    },
}


def _plt() -> Any:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise ImportError(
            "figures need matplotlib: pip install 'tubesweep[plot]', or pip install '.[plot]' in a checkout"
        ) from None
    return plt


def _view_basis(w: Sequence[float]) -> np.ndarray:
    w = np.asarray(w, dtype=float)  # type: ignore[assignment]
    w = w / np.linalg.norm(w)  # type: ignore[operator]
    up = np.array([0.0, 0.0, 1.0]) if abs(w[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(up, w)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(w, e1)
    return np.stack([e1, e2, w])


def _disk(basis: np.ndarray, n: int) -> tuple:
    t = np.linspace(-RADIUS, RADIUS, n)
    X, Y = np.meshgrid(t, t)
    r2 = X**2 + Y**2
    inside = r2 < RADIUS**2 * 0.995
    Z = np.sqrt(np.clip(RADIUS**2 - r2, 0, None))
    pts = X[..., None] * basis[0] + Y[..., None] * basis[1] + Z[..., None] * basis[2]
    return X, Y, inside, pts.reshape(-1, 3)


def _image(sol: Any, pts: np.ndarray, inside: np.ndarray) -> np.ndarray:
    u = np.full(inside.size, np.nan)
    m = inside.reshape(-1)
    u[m] = sol(pts[m])
    return u.reshape(inside.shape)


def _solve_all(centers: np.ndarray, n: int) -> Dict[str, Any]:
    grid = Grid(lower=(-0.7,) * 3, upper=(0.7,) * 3, shape=(n,) * 3)
    sphere = Sphere(RADIUS)
    raw = point_vortices(centers, STRENGTH)
    cored = point_vortices(centers, STRENGTH, core=CORE)
    out: Dict[str, Any] = {"grid": grid, "flow": raw, "flow_core": cored}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out["raw"] = solve(
            sphere, grid, [SOURCE], speed=SPEED, flow=raw, allow_supersonic=True, hamiltonian="lxf", order=1
        )
    out["supersonic_warning"] = next((str(w.message) for w in caught if "outruns" in str(w.message)), "")
    out["core"] = solve(sphere, grid, [SOURCE], speed=SPEED, flow=cored, hamiltonian="lxf", order=1)
    out["core_upwind"] = solve(sphere, grid, [SOURCE], speed=SPEED, flow=cored, order=1)
    out["still"] = solve(sphere, grid, [SOURCE], speed=SPEED, hamiltonian="lxf", order=1)
    return out


def _figure(
    name: str, case: Dict[str, Any], res: Dict[str, Any], path: Path, compare: str, n_img: int, main: str = "raw"
) -> None:
    plt = _plt()
    centers = np.asarray(case["centers"])
    fig, axes = plt.subplots(2, 2, figsize=(10, 9.6), layout="constrained")
    levels = np.arange(LEVEL_STEP, 1.0, LEVEL_STEP)
    for col, w in enumerate(case["views"]):
        B = _view_basis(w)
        X, Y, inside, pts = _disk(B, n_img)
        u = _image(res[main], pts, inside)
        other = _image(res[compare], pts, inside)
        v = np.zeros_like(pts)
        v[inside.reshape(-1)] = res["flow" if main == "raw" else "flow_core"](pts[inside.reshape(-1)])
        speed = np.linalg.norm(v, axis=1).reshape(X.shape)
        speed[~inside] = np.nan
        for row in range(2):
            ax = axes[row, col]
            ax.add_patch(plt.Circle((0, 0), RADIUS, fill=False, color="0.3", lw=1.0))
            if row == 0:
                im = ax.pcolormesh(
                    X, Y, np.minimum(speed, 2 * SPEED), cmap="Blues", vmin=0, vmax=2 * SPEED, shading="auto"
                )
                ax.contour(X, Y, speed, levels=[SPEED], colors="red", linestyles="--", linewidths=1.0)
                k = max(1, n_img // 22)
                vx = (v @ B[0]).reshape(X.shape)
                vy = (v @ B[1]).reshape(X.shape)
                mag = np.maximum(np.hypot(vx, vy), 1e-12)
                sl = (slice(k // 2, None, k), slice(k // 2, None, k))
                msk = inside[sl]
                ax.quiver(
                    X[sl][msk],
                    Y[sl][msk],
                    (vx / mag)[sl][msk],
                    (vy / mag)[sl][msk],
                    color="0.25",
                    scale=40,
                    width=0.003,
                    headwidth=3,
                )
                ax.contour(X, Y, u, levels=levels, colors="k", linewidths=0.9)
            else:
                ax.contour(X, Y, other, levels=levels, colors="m", linestyles=":", linewidths=1.2)
                ax.contour(X, Y, u, levels=levels, colors="k", linewidths=0.9)
            for c in centers:
                if c @ B[2] > 0:
                    ax.plot(c @ B[0], c @ B[1], marker="*", color="red", ms=14, mec="k", mew=0.5)
            s = np.asarray(SOURCE)
            if s @ B[2] > 0:
                ax.plot(s @ B[0], s @ B[1], "o", color="limegreen", ms=8, mec="k")
            ax.set_aspect("equal")
            ax.set_xlim(-RADIUS * 1.05, RADIUS * 1.05)
            ax.set_ylim(-RADIUS * 1.05, RADIUS * 1.05)
            ax.set_xticks([])
            ax.set_yticks([])
            wv = np.asarray(w) / np.linalg.norm(w)
            label = "abcd"[2 * row + col]
            sub = (
                "flow |v| and arrows"
                if row == 0
                else {
                    "still": "magenta: v = 0",
                    "core": f"magenta: core δ = {CORE}" if main == "raw" else "magenta: Lax–Friedrichs",
                }[compare]
            )
            ax.set_title(f"({label}) view from ({wv[0]:.2f}, {wv[1]:.2f}, {wv[2]:.2f}); {sub}", fontsize=9)
    fig.colorbar(im, ax=axes[0, :], shrink=0.7, label="|v| (clipped at 2F; red dashed: |v| = F)")
    g = res["grid"]
    fig.suptitle(
        f"{case['title']} — black: u (step {LEVEL_STEP}), F = {SPEED}, s = {STRENGTH}, grid {g.shape[0]}³, "
        + ("allow_supersonic=True, Lax–Friedrichs" if main == "raw" else f"core δ = {CORE}, upwind solver"),
        fontsize=10,
    )
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _angles(points: np.ndarray, centers: np.ndarray) -> np.ndarray:
    p = points / np.linalg.norm(points, axis=1, keepdims=True)
    c = centers / np.linalg.norm(centers, axis=1, keepdims=True)
    return np.arccos(np.clip(p @ c.T, -1, 1)).min(axis=1)


def _run(name: str, out_dir: Path, quick: bool) -> dict:
    case = CASES[name]
    n = 57 if quick else 113
    t0 = time.perf_counter()
    res = _solve_all(np.asarray(case["centers"], dtype=float), n)
    rng = np.random.default_rng(0)
    p = rng.normal(size=(20000, 3))
    p = RADIUS * p / np.linalg.norm(p, axis=1, keepdims=True)
    u, uc, u0 = res["raw"](p), res["core"](p), res["still"](p)
    ang = _angles(p, np.asarray(case["centers"], dtype=float))
    far = ang > 0.6  # chord > 0.3 = 3δ: outside the supersonic discs (θ ≈ 0.21) and the cores
    summary = {
        "grid": n,
        "spacing": res["grid"].spacing,
        "iterations": {k: res[k].stats.iterations for k in ("raw", "core", "still", "core_upwind")},
        "converged": {k: bool(res[k].stats.converged) for k in ("raw", "core", "still", "core_upwind")},
        "seconds": {k: round(res[k].stats.seconds, 3) for k in ("raw", "core", "still", "core_upwind")},
        "max_u": float(np.nanmax(u)),
        "max_abs_u_minus_unperturbed": float(np.nanmax(np.abs(u - u0))),
        "max_abs_raw_minus_core": float(np.nanmax(np.abs(u - uc))),
        "max_abs_raw_minus_core_far_from_vortices": float(np.nanmax(np.abs(u - uc)[far])),
        "mean_abs_raw_minus_core": float(np.nanmean(np.abs(u - uc))),
        # the cored flow with the upwind solver against Lax–Friedrichs
        "max_abs_core_upwind_minus_core_lxf": float(np.nanmax(np.abs(res["core_upwind"](p) - uc))),
        "mean_abs_core_upwind_minus_core_lxf": float(np.nanmean(np.abs(res["core_upwind"](p) - uc))),
        "supersonic_warning": res["supersonic_warning"],
    }
    n_img = 161 if quick else 241
    _figure(name, case, res, out_dir / f"{name}.png", "still", n_img)
    _figure(name, case, res, out_dir / f"{name}_core.png", "core", n_img)
    _figure(name, case, res, out_dir / f"{name}_upwind.png", "core", n_img, main="core_upwind")
    summary["seconds_total"] = round(time.perf_counter() - t0, 2)
    (out_dir / f"{name}.json").write_text(json.dumps(summary, indent=2))
    print(json.dumps({k: v for k, v in summary.items() if k != "supersonic_warning"}, indent=1))
    return summary


def fig10(out_dir: Path, quick: bool) -> dict:
    """Fig. 10: three vortices at (0, 0, 0.5), (0, −0.5, 0), (0.5, 0, 0)."""
    return _run("fig10", Path(out_dir), quick)


def fig11(out_dir: Path, quick: bool) -> dict:
    """Fig. 11: four vortices at (−1, ±1, ±1)/(2√3)."""
    return _run("fig11", Path(out_dir), quick)


EXPERIMENTS = {"fig10": fig10, "fig11": fig11}
