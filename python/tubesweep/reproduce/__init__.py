"""Reproduction of the paper's numerical experiments (``tubesweep reproduce``).

Each module in this package registers experiments by defining a module-level dict
``EXPERIMENTS = {"name": run}`` where ``run(out_dir: pathlib.Path, quick: bool) -> dict`` writes
its CSV / Markdown / PNG files into ``out_dir`` and returns a summary. Modules are discovered
automatically, so adding an experiment means adding one file.
"""

from __future__ import annotations

import importlib
import pkgutil
from pathlib import Path
from typing import Callable, Dict

Runner = Callable[[Path, bool], dict]


def experiments() -> Dict[str, Runner]:
    """All registered experiments, by name, in a stable order."""
    found: Dict[str, Runner] = {}
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda m: m.name):
        if info.name.startswith("_"):
            continue
        mod = importlib.import_module(f"{__name__}.{info.name}")
        found.update(getattr(mod, "EXPERIMENTS", {}))
    return dict(sorted(found.items()))


def run(names, out_dir: Path, quick: bool = False) -> Dict[str, dict]:
    """Runs the named experiments (``"all"`` for every one) and returns their summaries."""
    table = experiments()
    if not table:
        print("nothing to reproduce yet")
        return {}
    if "all" in names:
        names = list(table)
    unknown = [n for n in names if n not in table]
    if unknown:
        raise ValueError(f"unknown experiment(s) {unknown}; choose from {sorted(table)} or 'all'")
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    results = {}
    for n in names:
        print(f"== {n}{' (quick)' if quick else ''}", flush=True)
        results[n] = table[n](out_dir, quick)
    return results
