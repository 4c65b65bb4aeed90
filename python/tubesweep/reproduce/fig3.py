"""Fig. 3 of the paper (Sect. 3): the naive single tube (Algorithm 2) on the line y = x does not
converge for a tube of width O(Δx); Algorithm 3 (two layers) does.

Set-up (Sect. 3): Σ = {y = x} with φ(x, y) = (y − x)/√2 (exact signed distance), the point source
at the origin, the box [0, 1]² with Δx = 1/N (N + 1 nodes per axis), Godunov update (3),
``source_init="node"`` (u = 0 at the origin node). The quantity is u(1, 1), exact value √2.

* Fig. 3a/b: fixed ratios h/Δx = k/√2, k = 2.5, 3.5, …, 7.5. For k = 2.5 (h/Δx = 5/√8, in
  [√2, 3/√2)) Proposition 3.2 gives the closed form
  ``u(1,1) = α₊Δx + (N − 1)Δx·(α₊ + √(2 − α₋²))/2`` with α± = 1 ± 1/√2 (the paper's formula with
  the origin as node 1, so (1, 1) is node N + 1), whose limit is (α₊ + √(2 − α₋²))/2 ≈ 1.54533,
  not √2. We check our solver against it to round-off.
* Fig. 3a/c: h = 1.5 Δx^γ for γ = 0.7 and 0.8: slow convergence; the paper fits the slope 0.6546
  for γ = 0.7 and says γ = 0.8 converges slower than O(√Δx).
* Algorithm 3 (inner 2Δx, outer 4Δx, Godunov) on the same line: first-order convergence to √2.
"""

from __future__ import annotations

import math
import time
from pathlib import Path
from typing import Any, Dict, List

import numpy as np

from ..grid import Grid
from ..solve import solve
from . import _report as R

__all__ = ["run", "naive_limit", "closed_form", "EXPERIMENTS", "PAPER_SLOPE_GAMMA07"]

ALPHA_P = 1.0 + 1.0 / math.sqrt(2.0)
ALPHA_M = 1.0 - 1.0 / math.sqrt(2.0)
#: Limit of Algorithm 2's u(1, 1) for h/Δx ∈ [√2, 3/√2) (Sect. 3, after Proposition 3.2).
NAIVE_LIMIT = 0.5 * (ALPHA_P + math.sqrt(2.0 - ALPHA_M**2))
#: The paper's least-squares slope of the error for h = 1.5 Δx^0.7 (caption of Fig. 3).
PAPER_SLOPE_GAMMA07 = 0.6546
KS = (2.5, 3.5, 4.5, 5.5, 6.5, 7.5)
GAMMAS = (0.7, 0.8)


def naive_limit() -> float:
    """(α₊ + √(2 − α₋²))/2 ≈ 1.5453289."""
    return NAIVE_LIMIT


def closed_form(n: int) -> float:
    """Proposition 3.2's u(1, 1) for Δx = 1/n and h/Δx ∈ [√2, 3/√2)."""
    dx = 1.0 / n
    return ALPHA_P * dx + (n - 1) * dx * NAIVE_LIMIT


def _phi(p: np.ndarray) -> np.ndarray:
    """Signed distance to the line y = x."""
    p = np.asarray(p, dtype=float)
    return (p[:, 1] - p[:, 0]) / math.sqrt(2.0)


def _u11(n: int, **kw: Any) -> Dict[str, Any]:
    grid = Grid((0.0, 0.0), (1.0, 1.0), (n + 1, n + 1))
    t = time.perf_counter()
    sol = solve(_phi, grid, [(0.0, 0.0)], source_init="node", order=1, **kw)
    wall = time.perf_counter() - t
    u = float(sol(np.array([[1.0, 1.0]]))[0])
    return {"N": n, "dx": 1.0 / n, "u11": u, "error": abs(u - math.sqrt(2.0)), **R.run_record(sol, wall)}


def run(out_dir: Path, quick: bool) -> dict:
    """Runs Fig. 3 and writes ``fig3.csv``, ``fig3.md`` and ``fig3.png`` into ``out_dir``."""
    out_dir = Path(out_dir)
    ns_fixed = [25, 50, 100, 200, 400] if quick else [25, 50, 100, 200, 400, 800, 1600]
    ns_gamma = [25, 50, 100, 200, 400, 800] if quick else [25, 50, 100, 200, 400, 800, 1600, 3200]
    ns_alg3 = [25, 50, 100, 200, 400] if quick else [25, 50, 100, 200, 400, 800, 1600]
    rows: List[Dict[str, Any]] = []
    for k in KS:
        for n in ns_fixed:
            r = _u11(n, method="naive", hamiltonian="godunov", inner=k / math.sqrt(2.0))
            r.update(case=f"h/dx={k:g}/sqrt2", h_over_dx=k / math.sqrt(2.0))
            if k == 2.5:
                r["closed_form"] = closed_form(n)
            rows.append(r)
    for g in GAMMAS:
        for n in ns_gamma:
            dx = 1.0 / n
            r = _u11(n, method="naive", hamiltonian="godunov", inner=1.5 * dx**g / dx)
            r.update(case=f"h=1.5dx^{g:g}", h_over_dx=1.5 * dx**g / dx)
            rows.append(r)
    for n in ns_alg3:
        r = _u11(n, method="two-layer", hamiltonian="godunov", inner=2.0, outer=4.0)
        r.update(case="Algorithm 3 (Godunov, 2dx/4dx)", h_over_dx=2.0)
        rows.append(r)
    order = ["case", "N", "dx", "h_over_dx", "u11", "closed_form", "error"]
    rows = [{**{k: r.get(k, "") for k in order}, **{k: v for k, v in r.items() if k not in order}} for r in rows]
    R.write_csv(out_dir / "fig3.csv", rows)

    def sel(case: str) -> List[Dict[str, Any]]:
        return [r for r in rows if r["case"] == case]

    k25 = sel("h/dx=2.5/sqrt2")
    closed_dev = max(abs(r["u11"] - r["closed_form"]) for r in k25)
    slopes = {
        g: R.fit_order([r["dx"] for r in sel(f"h=1.5dx^{g:g}")], [r["error"] for r in sel(f"h=1.5dx^{g:g}")])
        for g in GAMMAS
    }
    alg3 = sel("Algorithm 3 (Godunov, 2dx/4dx)")
    alg3_order = R.fit_order([r["dx"] for r in alg3], [r["error"] for r in alg3])
    finest = {k: sel(f"h/dx={k:g}/sqrt2")[-1]["u11"] for k in KS}

    # --- Markdown -------------------------------------------------------------------------
    head = ["N"] + [f"k={k:g}" for k in KS] + ["closed form (k=2.5)"]
    body = []
    for i, n in enumerate(ns_fixed):
        body.append([n] + [f"{sel(f'h/dx={k:g}/sqrt2')[i]['u11']:.6f}" for k in KS] + [f"{k25[i]['closed_form']:.6f}"])
    gam_head = ["N"] + [f"u(1,1), γ={g:g}" for g in GAMMAS] + [f"error, γ={g:g}" for g in GAMMAS]
    gam_body = []
    for i, n in enumerate(ns_gamma):
        gam_body.append(
            [n]
            + [f"{sel(f'h=1.5dx^{g:g}')[i]['u11']:.6f}" for g in GAMMAS]
            + [sel(f"h=1.5dx^{g:g}")[i]["error"] for g in GAMMAS]
        )
    slope_tab = R.markdown_table(
        ["γ", "fitted slope (ours)", "paper", "ratio ours/paper"],
        [
            [0.7, slopes[0.7], PAPER_SLOPE_GAMMA07, R.ratio(slopes[0.7], PAPER_SLOPE_GAMMA07)],
            [0.8, slopes[0.8], "< 0.5 (“slower than O(√Δx)”)", "–"],
        ],
    )
    alg3_tab = R.markdown_table(
        ["N", "u(1,1)", "error", "iterations", "band points"],
        [[r["N"], f"{r['u11']:.6f}", r["error"], r["iterations"], r["band_points"]] for r in alg3],
    )
    cost_tab = R.markdown_table(
        ["case", "N", "band points", "iterations", "updates", "seconds"],
        [[r["case"], r["N"], r["band_points"], r["iterations"], r["updates"], r["wall_seconds"]] for r in rows],
    )
    R.write_markdown(
        out_dir / "fig3.md",
        "Fig. 3 — the naive tube on the line y = x" + (" (quick)" if quick else ""),
        [
            (
                "",
                "u(1,1) for Algorithm 2 (naive tube, Godunov, source node), Δx = 1/N on [0,1]², exact √2 = 1.414214. "
                f"Limit for h/Δx = 5/√8 (k = 2.5): (α₊+√(2−α₋²))/2 = {NAIVE_LIMIT:.6f}. "
                f"Largest |ours − closed form (Prop. 3.2)| for k = 2.5: {closed_dev:.2e}.",
            ),
            ("Fixed ratio h/Δx = k/√2 (Fig. 3a, b)", R.markdown_table(head, body)),
            ("h = 1.5 Δx^γ (Fig. 3a, c)", R.markdown_table(gam_head, gam_body) + "\n\n" + slope_tab),
            ("Algorithm 3 on the same line", alg3_tab + f"\n\nFitted order: {alg3_order:.4f} (converges to √2)."),
            ("Cost of every run", cost_tab),
        ],
    )

    # --- figure -----------------------------------------------------------------------------
    p = R.plt()
    fig, axs = p.subplots(1, 3, figsize=(16, 4.6))
    ax = axs[0]
    cmap = p.get_cmap("Blues")
    for j, k in enumerate(KS):
        rr = sel(f"h/dx={k:g}/sqrt2")
        ax.semilogx(
            [r["dx"] for r in rr], [r["u11"] for r in rr], "o-", color=cmap(0.9 - 0.1 * j), ms=4, label=f"h/Δx={k:g}/√2"
        )
    for g, mk in zip(GAMMAS, ("s--", "D--")):
        rr = sel(f"h=1.5dx^{g:g}")
        ax.semilogx([r["dx"] for r in rr], [r["u11"] for r in rr], "k" + mk, ms=4, label=f"h=1.5Δx^{g:g}")
    ax.semilogx([r["dx"] for r in alg3], [r["u11"] for r in alg3], "g^-", ms=4, label="Algorithm 3")
    ax.axhline(NAIVE_LIMIT, color="r", ls=":", lw=1)
    ax.axhline(math.sqrt(2.0), color="r", ls=":", lw=1)
    ax.set_xlabel("Δx")
    ax.set_ylabel("u(1,1)")
    ax.set_title("(a) u(1,1) vs Δx (red: √2 and the k=2.5 limit)", fontsize=10)
    ax.invert_xaxis()
    ax.legend(fontsize=7)
    ax.grid(True, alpha=0.3)
    ax = axs[1]
    ratios = np.array(KS) / math.sqrt(2.0)
    ax.plot(ratios, [finest[k] for k in KS], "bo-", label=f"naive, N={ns_fixed[-1]}")
    ax.axhline(math.sqrt(2.0), color="r", ls=":", lw=1, label="√2")
    ax.axhline(NAIVE_LIMIT, color="r", ls="--", lw=1, label="k=2.5 limit")
    ax.set_xlabel("h/Δx")
    ax.set_ylabel("u(1,1)")
    ax.set_title("(b) fixed h/Δx: converged value ≠ √2", fontsize=10)
    ax.legend(fontsize=8)
    ax.grid(True, alpha=0.3)
    series = [
        {
            "x": [r["dx"] for r in sel(f"h=1.5dx^{g:g}")],
            "y": [r["error"] for r in sel(f"h=1.5dx^{g:g}")],
            "label": f"γ={g:g} (slope {slopes[g]:.3f})",
            "style": mk,
        }
        for g, mk in zip(GAMMAS, ("ks-", "kD--"))
    ]
    series.append(
        {
            "x": [r["dx"] for r in alg3],
            "y": [r["error"] for r in alg3],
            "label": f"Algorithm 3 (slope {alg3_order:.3f})",
            "style": "g^-",
        }
    )
    R.loglog_png(
        None,  # type: ignore[arg-type]
        series,
        xlabel="Δx",
        ylabel="|u(1,1) − √2|",
        refs=(0.5, 1.0),
        title=f"(c) error; paper: slope {PAPER_SLOPE_GAMMA07} for γ=0.7",
        ax=axs[2],
        ref_anchor=(series[0]["x"][0], series[0]["y"][0] * 1.5),
    )
    from matplotlib.ticker import NullFormatter

    for a in (axs[0], axs[2]):
        a.xaxis.set_minor_formatter(NullFormatter())
    fig.tight_layout()
    fig.savefig(out_dir / "fig3.png", dpi=100)
    p.close(fig)
    summary = {
        "naive_limit": NAIVE_LIMIT,
        "k2.5_finest": finest[2.5],
        "closed_form_max_dev": closed_dev,
        "slope_gamma07": slopes[0.7],
        "slope_gamma08": slopes[0.8],
        "alg3_order": alg3_order,
        "alg3_finest_error": alg3[-1]["error"],
        "rows": rows,
    }
    print(
        f"   k=2.5 u(1,1)={finest[2.5]:.6f} (limit {NAIVE_LIMIT:.6f}); slope γ=0.7 {slopes[0.7]:.4f} "
        f"(paper {PAPER_SLOPE_GAMMA07}), γ=0.8 {slopes[0.8]:.4f}; Algorithm 3 order {alg3_order:.3f}",
        flush=True,
    )
    return summary


EXPERIMENTS = {"fig3": run}
