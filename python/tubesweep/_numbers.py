"""Numeric arguments: the types every numeric argument refuses (:class:`ArgumentTypeError`) and
whole numbers. The lowest layer of the checks: :mod:`tubesweep.grid` and
:mod:`tubesweep._validate` both use it, and it imports nothing of the package."""

from __future__ import annotations

from typing import Any

import numpy as np


class ArgumentTypeError(TypeError, ValueError):
    """A numeric argument of the wrong type (a bool, a string, None, a sequence): a ``TypeError``
    that is also a ``ValueError``, so that code catching the argument's value errors catches it
    too. Every numeric argument refuses the same types with it (see :func:`real_scalar` and
    :func:`whole_number`)."""


def _type_name(value: Any) -> str:
    if isinstance(value, (bool, np.bool_)):
        return "a bool"
    if isinstance(value, (str, bytes)):
        return "a string"
    if value is None:
        return "None"
    if np.ndim(value) != 0:
        return f"an array of shape {np.shape(value)}"
    return f"a {type(value).__name__}"


def whole_number(value: Any, name: str, what: str = "a whole number") -> int:
    """``value`` as an int: a Python or NumPy integer, a 0-d integer array, or a float with no
    fraction. A bool, a string, None, a sequence, a complex number or a float with a fraction is
    an :class:`ArgumentTypeError` that says ``name`` must be ``what``."""
    if (
        value is None
        or isinstance(value, (bool, np.bool_, str, bytes))
        or np.ndim(value) != 0
        or np.iscomplexobj(value)
        or np.asarray(value).dtype == bool
    ):
        raise ArgumentTypeError(f"{name} must be {what}; got {value!r} ({_type_name(value)})")
    try:
        if isinstance(value, (int, np.integer)) or (
            isinstance(value, np.ndarray) and np.issubdtype(value.dtype, np.integer)
        ):
            return int(value)
        f = float(value)
    except (TypeError, ValueError, OverflowError):
        raise ArgumentTypeError(f"{name} must be {what}; got {value!r} ({_type_name(value)})") from None
    if not (np.isfinite(f) and f == int(f)):
        raise ArgumentTypeError(f"{name} must be {what}; got {value!r}")
    return int(f)
