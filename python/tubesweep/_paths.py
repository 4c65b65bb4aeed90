"""Where output is written: checked before the work whose result would go there (the command line's
``--out`` and ``--export``; ``ts.evolve``'s checkpoint)."""

from __future__ import annotations

import tempfile
from pathlib import Path


def writable(path: Path, option: str, folder: bool = False) -> None:
    """A ValueError naming ``option`` unless a file can be created in the folder of ``path`` (in
    ``path`` itself with ``folder``; where that does not exist yet, in its nearest existing
    ancestor): checked before the solve, whose result would otherwise be lost to a bare OSError
    after it."""
    folder_ = path.resolve() if folder else path.resolve().parent
    while not folder_.exists() and folder_ != folder_.parent:
        folder_ = folder_.parent
    if not folder_.is_dir():
        raise ValueError(f"{option} {path}: {folder_} is a file, not a folder")
    try:
        with tempfile.TemporaryFile(dir=folder_):
            pass
    except OSError as e:
        raise ValueError(f"{option} {path}: cannot write in {folder_} ({e.strerror})") from None
