"""The command line's exit status for a solve reported not converged (``tubesweep solve``,
``travel-time``, ``distances``): stopped at its iteration limit, or with values it could not
settle (a warning says which). Its files are written, but a script must not take them for the
answer, so the command says so on stderr and exits non-zero."""

from __future__ import annotations

import sys

#: The exit status of a command whose solve did not converge (2 is refused input, 130 Ctrl-C).
NOT_CONVERGED = 3


def exit_status(converged: bool, what: str, fix: str = "pass a larger --max-iterations or --tol") -> int:
    """0, or :data:`NOT_CONVERGED` after an ``error:`` line on stderr that says ``what`` stopped,
    that the files hold the last iterate, and ``fix``."""
    if converged:
        return 0
    print(
        f"error: {what} without converging (the files written hold the last iterate, not the answer): {fix} "
        f"(exit status {NOT_CONVERGED})",
        file=sys.stderr,
    )
    return NOT_CONVERGED
