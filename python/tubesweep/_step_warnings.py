"""The warnings of an evolution's surface solves (``ts.evolve``), said once per kind at the end
with the steps that gave them, instead of once per step: a coarse grid's first-order fallback or
a narrow gap on the way to a merge warned at every step (a shrinking sphere at N = 31: three
kinds over its 8 steps, ``tests/test_step_warnings.py``)."""

from __future__ import annotations

import contextlib
import re
import warnings
from typing import Dict, Iterator, List, Tuple, Type

from ._warn import user_stacklevel

_NUMBER = re.compile(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?")


def _ranges(steps: List[int]) -> str:
    """``[0, 1, 2, 5, 7, 8]`` as ``"0–2, 5, 7–8"``."""
    out: List[str] = []
    start = prev = steps[0]
    for s in [*steps[1:], None]:
        if s is not None and s == prev + 1:
            prev = s
            continue
        out.append(f"{start}" if start == prev else f"{start}–{prev}")
        if s is not None:
            start = prev = s
    return ", ".join(out)


class StepWarnings:
    """Collects the warnings of each step (:meth:`step`) and says each kind once (:meth:`say`):
    warnings whose texts differ only in their numbers are one kind, said with the last step's
    text and the steps that gave it."""

    def __init__(self) -> None:
        self._kinds: Dict[Tuple[Type[Warning], str], Tuple[str, List[int]]] = {}

    @contextlib.contextmanager
    def step(self, step: int) -> Iterator[None]:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            yield
        for w in caught:
            text = str(w.message)
            key = (w.category, _NUMBER.sub("#", text))
            steps = self._kinds.setdefault(key, (text, []))[1]
            if not steps or steps[-1] != step:
                steps.append(step)
            self._kinds[key] = (text, steps)

    def say(self) -> None:
        """Warns each kind once, then forgets them."""
        kinds, self._kinds = self._kinds, {}
        for (category, _), (text, steps) in kinds.items():
            where = f"step {steps[0]}" if len(steps) == 1 else f"steps {_ranges(steps)}, the last one's figures"
            warnings.warn(f"{text} (evolve: {where})", category, stacklevel=user_stacklevel())
