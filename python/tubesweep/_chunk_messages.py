"""The messages of a batch solved in chunks (the Dask tasks of :mod:`tubesweep.distributed`),
said as the batch solved on this machine says them: a warning or a fallback reason that each chunk
gave with its own counts ("1 of 1 solves", "sources [2]") is said once, with the counts of the whole
batch ("2 of 4 solves, sources [0, 2]"). Each chunk named only its own sources before, and the
fallback reason was the first chunk's alone (a helper's review)."""

from __future__ import annotations

import re
from typing import Dict, List, Sequence, Tuple

#: How many solves of a chunk a message counts (``many``, ``many_order2``: "2 of 8 solves").
_COUNT = re.compile(r"(\d+) of (\d+) solves")

#: The sources it names, numbered among all the batch's (the first five, "…" after them).
_SOURCES = re.compile(r"sources \[([\d, ]*)\](…?)")

#: As many sources as a message of the batch names (``many``).
_NAMED = 5


def merged(messages: Sequence[str], total: int) -> List[str]:
    """``messages`` of the chunks of a batch of ``total`` solves, in their order of first
    appearance: those equal but for their count of solves and their sources said once, with the
    counts added up over the chunks ("of ``total`` solves") and the sources of all of them (the
    first five in order, "…" when more were counted); any other message once, as it is."""
    groups: Dict[str, Tuple[str, int, List[int], bool]] = {}
    for message in messages:
        count = _COUNT.search(message)
        sources = _SOURCES.search(message)
        if count is None and sources is None:
            groups.setdefault(message, (message, 0, [], False))
            continue
        key = _SOURCES.sub("sources []", _COUNT.sub("# of # solves", message, count=1), count=1)
        first, n, named, more = groups.get(key, (message, 0, [], False))
        if count is not None:
            n += int(count.group(1))
        if sources is not None:
            named = named + [int(s) for s in sources.group(1).split(",") if s.strip()]
            more = more or bool(sources.group(2))
        groups[key] = (first, n, named, more)
    out = []
    for first, n, named, more in groups.values():
        text = first
        if _COUNT.search(text) is not None:
            text = _COUNT.sub(f"{n} of {total} solves", text, count=1)
        if _SOURCES.search(text) is not None:
            named = sorted(set(named))
            ellipsis = "…" if more or len(named) > _NAMED else ""
            listed = ", ".join(str(s) for s in named[:_NAMED])
            text = _SOURCES.sub(lambda _: f"sources [{listed}]{ellipsis}", text, count=1)
        out.append(text)
    return out
