"""The time-against-error picture of ``benches/run.py`` (``out/bench/time_vs_error.png``,
``docs/img/bench-time-vs-error.png``): one column per problem, the mean and the far max error in
two rows, one line per method over its grid sizes."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Dict, List, Optional, Tuple

#: The errors :func:`plot` draws, one row of panels each: (record key, axis label).
PLOT_ERRORS = (("mean_err", "mean error on the surface"), ("far_max_err", "far max error"))


def plot(
    records: List[Dict[str, Any]], path: Path, problem_order: List[str], method_order: List[str]
) -> Optional[Path]:
    """Log–log wall time against the mean error (top row) and the far max error (bottom row), one
    column per problem (in ``problem_order``), one line per method (``method_order``); each point's N
    written once where methods' points share it."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("(no plot: pip install matplotlib)")
        return None
    ok = [r for r in records if r.get("status") == "ok" and r.get("max_err", 0) > 0]
    problems = [p for p in problem_order if any(r["problem"] == p for r in ok)]
    if not problems:
        return None
    style = {
        "tubesweep-godunov": ("C0", "o", "-"),
        "tubesweep-godunov-order2": ("C5", "*", "-"),
        "tubesweep-godunov-tolh": ("C4", "o", ":"),
        "tubesweep-godunov-1t": ("C7", "o", "-."),
        "tubesweep-lxf": ("C0", "s", "--"),
        "skfmm-tube": ("C1", "^", "-"),
        "heat": ("C2", "D", "-"),
        "mmp": ("C3", "v", "-"),
    }
    from matplotlib.ticker import NullFormatter

    ncol = len(problems)
    fig, axes = plt.subplots(len(PLOT_ERRORS), ncol, figsize=(3.7 * ncol, 3.3 * len(PLOT_ERRORS) + 0.9), squeeze=False)
    for row, (key, label) in zip(axes, PLOT_ERRORS):
        for ax, prob in zip(row, problems):
            labelled: List[Tuple[float, float]] = []
            for m in method_order:
                rs = sorted(
                    (r for r in ok if r["problem"] == prob and r["method"] == m and (r.get(key) or 0) > 0),
                    key=lambda r: r["n"],
                )
                if not rs:
                    continue
                c, mk, ls = style[m]
                ax.loglog([r["wall_s"] for r in rs], [r[key] for r in rs], color=c, marker=mk, ls=ls, label=m)
                for r in (rs[0], rs[-1]):
                    # one label where several methods' points of that N lie within a few per cent
                    at = (math.log10(r["wall_s"]), math.log10(r[key]))
                    if any(abs(at[0] - x) < 0.25 and abs(at[1] - y) < 0.2 for x, y in labelled):
                        continue
                    labelled.append(at)
                    ax.annotate(
                        f"N={r['n']}", (r["wall_s"], r[key]), fontsize=7, xytext=(3, 3), textcoords="offset points"
                    )
            ax.xaxis.set_minor_formatter(NullFormatter())
            if ax.get_ylim()[1] > 10 * ax.get_ylim()[0]:  # (within a decade the minor ticks carry the labels)
                ax.yaxis.set_minor_formatter(NullFormatter())
            ax.set_title(prob)
            ax.set_xlabel("median wall time [s]")
            ax.set_ylabel(label)
            ax.grid(True, which="both", alpha=0.3)
    # one legend for every panel, below them, so that no legend hides a line
    handles: Dict[str, Any] = {}
    for ax in axes.flat:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(lab, h)
    fig.legend(list(handles.values()), list(handles.keys()), loc="lower center", ncol=4, fontsize=9, frameon=False)
    fig.suptitle(
        "Time against error (log–log): each line one method over its grid sizes N; lower left is better "
        "(far max: points at least 0.1 from the source and the largest distances)",
        fontsize=10,
    )
    fig.tight_layout(rect=(0, 0.6 / (3.3 * len(PLOT_ERRORS) + 0.9), 1, 1))
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
