"""mkdocs hook: the docstrings' Sphinx roles (``:func:`tubesweep.solve```) shown as code.

The docstrings are written for Python's ``help()`` and Sphinx-style readers; mkdocstrings renders
the role's target as code but leaves the role's name in front of it (":func:solve"). This drops
the name, and a leading ``~`` shows only the last part of the target, as Sphinx does.
"""

import re

_ROLE = re.compile(r":(?:func|class|meth|mod|data|attr|exc|obj):<code>(~?)([^<]*)</code>")


def _code(match: "re.Match[str]") -> str:
    target = match.group(2)
    if match.group(1):
        target = target.rsplit(".", 1)[-1]
    return f"<code>{target}</code>"


def on_page_content(html: str, **kwargs: object) -> str:
    return _ROLE.sub(_code, html)
