"""The command line's exit status for a solve reported not converged (``tubesweep solve``,
``travel-time``, ``distances``): stopped at its iteration limit, or with values it could not
settle (a warning says which). Its files are written, but a script must not take them for the
answer, so the command says so on stderr and exits non-zero."""

from __future__ import annotations

import re
import sys
from typing import Sequence

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


#: The library's names for what a command-line flag sets, as its refusals begin: the error line
#: names the flag the user typed (``--n 2`` said "shape[0] = 2: every axis needs at least 3 nodes").
_FLAGS = (
    (re.compile(r"shape\[\d+\] = "), "--n"),
    (re.compile(r"sources\[\d+\] = "), "--source"),
    (re.compile(r"inner = "), "--inner"),
    (re.compile(r"outer = "), "--outer"),
    (re.compile(r"tol "), "--tol"),
    (re.compile(r"max_iterations "), "--max-iterations"),
)


def flag_named(message: str, argv: Sequence[str]) -> str:
    """``message`` led by the flag it is about (``--n: shape[0] = 2: ...``) when it begins with
    the library's name for what that flag sets and the flag is among ``argv``."""
    for pattern, flag in _FLAGS:
        if pattern.match(message) and any(a == flag or a.startswith(flag + "=") for a in argv):
            return f"{flag}: {message}"
    return message
