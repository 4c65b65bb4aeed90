"""Progress reporting for the command line: a tqdm bar when tqdm is installed, plain lines
otherwise."""

from __future__ import annotations

import sys
from typing import Callable, Optional


class SweepProgress:
    """Callable passed as ``progress=`` to the solvers; shows iterations and the largest change."""

    def __init__(self, description: str, enabled: bool = True, tol: float = 1e-10):
        self.enabled = enabled and sys.stderr.isatty() or enabled == "always"
        self._bar = None
        self._desc = description
        if self.enabled:
            try:
                from tqdm import tqdm

                self._bar = tqdm(desc=description, unit="it", leave=False, file=sys.stderr)
            except ImportError:
                self._bar = None

    def __call__(self, iteration: int, max_change: float, updates: int) -> None:
        if not self.enabled:
            return
        if self._bar is not None:
            self._bar.update(1)
            self._bar.set_postfix(change=f"{max_change:.2e}", refresh=False)
        else:
            print(
                f"\r{self._desc}: iteration {iteration}, largest change {max_change:.2e}",
                end="",
                file=sys.stderr,
                flush=True,
            )

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
        elif self.enabled:
            print(file=sys.stderr)


def make_progress(description: str, quiet: bool) -> Optional[Callable[[int, float, int], None]]:
    return None if quiet else SweepProgress(description)
