"""The command line's ``error:`` lines and exit status: for a solve reported not converged
(``tubesweep solve``, ``travel-time``, ``distances``: stopped at its iteration limit, or with
values it could not settle, a warning says which) its files are written, but a script must not
take them for the answer, so the command says so on stderr and exits non-zero; a refused input's
line names the flag the user typed (:func:`flag_named`)."""

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


#: Inputs whose array sets the grid's shape: with one of them ``--n`` is not what a shape is about.
_SHAPE_FROM_FILE = ("--phi", "--mask")


def _typed(flag: str, argv: Sequence[str], options: Sequence[str]) -> bool:
    """Whether ``flag`` is among ``argv``, also as ``--flag=value`` or as an abbreviation that
    argparse takes for it (a prefix of no other of the command's ``options``)."""
    for a in argv:
        name = a.split("=", 1)[0]
        if not name.startswith("--"):
            continue
        if name == flag or (flag.startswith(name) and [o for o in options if o.startswith(name)] == [flag]):
            return True
    return False


def flag_named(message: str, argv: Sequence[str], options: Sequence[str] = ()) -> str:
    """``message`` led by the flag it is about (``--n: shape[0] = 2: ...``) when it begins with
    the library's name for what that flag sets and the flag is among ``argv`` (``options``: the
    command's long options, for abbreviations); ``--n`` not where ``--phi`` or ``--mask`` gave
    the shape."""
    for pattern, flag in _FLAGS:
        if not pattern.match(message) or not _typed(flag, argv, options or [flag]):
            continue
        if flag == "--n" and any(_typed(f, argv, options or [f]) for f in _SHAPE_FROM_FILE):
            continue
        return f"{flag}: {message}"
    return message
