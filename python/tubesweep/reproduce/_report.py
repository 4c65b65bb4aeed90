"""Shared helpers of the reproduction experiments: convergence orders, run records, and the
CSV / Markdown / PNG writers that put our numbers next to the paper's.

Everything here is plain numpy and the standard library except the PNG writers, which import
matplotlib lazily (``pip install 'tubesweep[plot]'``, or ``pip install '.[plot]'`` in a checkout).
"""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple

import numpy as np

__all__ = [
    "fit_order",
    "local_orders",
    "run_record",
    "write_csv",
    "markdown_table",
    "write_markdown",
    "fmt",
    "ratio",
    "loglog_png",
    "plt",
]


def fit_order(h: Sequence[float], err: Sequence[float]) -> float:
    """Least-squares slope of ``log err`` against ``log h`` (the convergence order for errors; for
    iteration counts pass ``h = N`` to get the growth exponent). NaN with fewer than two points."""
    h = np.asarray(h, dtype=float)  # type: ignore[assignment]
    err = np.asarray(err, dtype=float)  # type: ignore[assignment]
    ok = np.isfinite(h) & np.isfinite(err) & (h > 0) & (err > 0)  # type: ignore[operator]
    if np.count_nonzero(ok) < 2:
        return float("nan")
    return float(np.polyfit(np.log(h[ok]), np.log(err[ok]), 1)[0])


def local_orders(h: Sequence[float], err: Sequence[float]) -> List[float]:
    """Orders between consecutive refinements, ``log(e_i/e_{i+1}) / log(h_i/h_{i+1})``."""
    out = []
    for (h0, e0), (h1, e1) in zip(zip(h, err), zip(h[1:], err[1:])):
        out.append(math.log(e0 / e1) / math.log(h0 / h1) if e0 > 0 and e1 > 0 else float("nan"))
    return out


def run_record(sol: Any, wall_seconds: float) -> Dict[str, Any]:
    """The cost of one solve: band points, iterations (passes of 2^d sweeps), sweeps, local
    updates, whether it converged, and seconds (the native solve, the set-up, and wall clock)."""
    s = sol.stats
    return {
        "band_points": int(s.band_points),
        "iterations": int(s.iterations),
        "sweeps": int(s.sweeps),
        "updates": int(s.updates),
        "converged": bool(s.converged),
        "sweep_seconds": round(float(s.seconds), 4),
        "setup_seconds": round(float(s.setup_seconds), 4),
        "wall_seconds": round(float(wall_seconds), 4),
    }


def ratio(ours: Optional[float], paper: Optional[float]) -> float:
    """ours / paper, NaN where either is missing."""
    if ours is None or paper is None or not np.isfinite(ours) or not np.isfinite(paper) or paper == 0:
        return float("nan")
    return float(ours) / float(paper)


def fmt(v: Any, digits: int = 4) -> str:
    """A table cell: floats in 4 significant digits (scientific where small), ints as is."""
    if v is None:
        return "–"
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        if not np.isfinite(v):
            return "–"
        a = abs(float(v))
        if a != 0 and (a < 1e-3 or a >= 1e5):
            return f"{float(v):.{digits - 1}e}"
        return f"{float(v):.{digits}g}"
    return str(v)


def write_csv(path: Path, rows: Sequence[Mapping[str, Any]]) -> Path:
    """Writes ``rows`` (dicts with the same keys, in order of first appearance) as CSV."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    keys: List[str] = []
    for r in rows:
        for k in r:
            if k not in keys:
                keys.append(k)
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        for r in rows:
            w.writerow({k: r.get(k, "") for k in keys})
    return path


def markdown_table(header: Sequence[str], rows: Iterable[Sequence[Any]]) -> str:
    """A GitHub-flavoured Markdown table; cells are formatted with :func:`fmt`."""
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    for r in rows:
        lines.append("| " + " | ".join(c if isinstance(c, str) else fmt(c) for c in r) + " |")
    return "\n".join(lines)


def write_markdown(path: Path, title: str, sections: Sequence[Tuple[str, str]]) -> Path:
    """Writes a Markdown file: ``# title`` then each ``(heading, body)`` section."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    parts = [f"# {title}", ""]
    for heading, body in sections:
        if heading:
            parts += [f"## {heading}", ""]
        parts += [body.rstrip(), ""]
    path.write_text("\n".join(parts))
    return path


def plt() -> Any:
    """matplotlib.pyplot with the Agg backend, or a clear error naming the extra."""
    from .._figures import _plt

    return _plt()


def loglog_png(
    path: Path,
    series: Sequence[Dict[str, Any]],
    *,
    xlabel: str,
    ylabel: str,
    title: str = "",
    refs: Sequence[float] = (),
    ref_anchor: Optional[Tuple[float, float]] = None,
    ax: Any = None,
) -> Any:
    """Log–log plot of ``series`` (dicts with ``x``, ``y``, ``label`` and optional ``style``) with
    reference lines of the given ``refs`` slopes through ``ref_anchor`` (default: the first point
    of the first series, shifted down by 2x so the lines do not hide the data). Saves to ``path``
    unless an ``ax`` is given (then the caller saves)."""
    p = plt()
    own = ax is None
    if own:
        fig, ax = p.subplots(figsize=(6, 4.6))
    for s in series:
        ax.loglog(s["x"], s["y"], s.get("style", "o-"), label=s["label"], ms=5, lw=1.3)
    if refs:
        x0, y0 = ref_anchor if ref_anchor is not None else (series[0]["x"][0], series[0]["y"][0] / 2.0)
        xs = np.array([min(min(s["x"]) for s in series), max(max(s["x"]) for s in series)], dtype=float)
        for slope, ls in zip(refs, (":", "--", "-.")):
            ax.loglog(xs, y0 * (xs / x0) ** slope, "k" + ls, lw=0.9, label=f"slope {slope:g}")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    if own:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        fig.tight_layout()
        fig.savefig(path, dpi=110)
        p.close(fig)
    return ax
