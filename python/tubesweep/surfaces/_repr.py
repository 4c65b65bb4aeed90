"""``repr`` of the library's surfaces: the class and its constructor's arguments, e.g.
``Sphere(radius=0.5, center=(0, 0, 0))``."""

from __future__ import annotations

import inspect
from typing import Any

import numpy as np


def _short(value: Any) -> str:
    if isinstance(value, (bool, np.bool_)):
        return str(bool(value))
    if isinstance(value, (int, float, np.integer, np.floating)):
        return f"{float(value):.6g}"
    if isinstance(value, (tuple, list, np.ndarray)):
        items = [_short(v) for v in np.asarray(value, dtype=float).ravel()]
        return "(" + ", ".join(items) + ("," if len(items) == 1 else "") + ")"
    return repr(value)


def library_repr(surface: Any) -> str:
    """``ClassName(arg=value, ...)`` from the constructor's parameters that the surface keeps as
    attributes of the same name (the others are left out)."""
    params = inspect.signature(type(surface).__init__).parameters
    parts = []
    for name in params:
        if name == "self":
            continue
        if hasattr(surface, name) and not callable(getattr(surface, name)):
            parts.append(f"{name}={_short(getattr(surface, name))}")
        elif name in ("a", "b", "c") and hasattr(surface, "axes"):  # the ellipsoid keeps its semi-axes together
            parts.append(f"{name}={_short(surface.axes['abc'.index(name)])}")
    return f"{type(surface).__name__}({', '.join(parts)})"


def give_repr(*classes: type) -> None:
    """Sets :func:`library_repr` as ``__repr__`` of each class that does not define its own."""
    for cls in classes:
        if "__repr__" not in cls.__dict__:
            cls.__repr__ = library_repr  # type: ignore[method-assign, assignment]
