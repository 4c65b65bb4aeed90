"""The cases of ``benches/hostile_inputs.py``, one module per group, and its machinery
(:mod:`hostile.framework`). Each group module registers its cases with ``framework.case`` when it
is imported; :func:`load_cases` imports them in the order of :data:`GROUPS`, which is the order the
cases run and ``--list`` prints them.
"""

from __future__ import annotations

import importlib
from typing import List

#: the group modules, in the order their cases run
GROUPS = (
    "sizes_and_ranges",  # 1, 2: grid sizes and numeric ranges
    "callables",  # 3: user callables and φ arrays with NaN or inf
    "mesh_files",  # 4: mesh files
    "messages_and_types",  # 5, 5b: messages on valid input, argument types
    "native",  # 7: the private native module
    "any_phi_and_motion",  # 8: masks, re-distanced φ, point clouds, warm starts, ts.evolve
    "api_reach",  # 9a-d: many sources, Solution methods, export and evolve's files
    "api_reach_more",  # 9e-g: anisotropic Hamiltonians, the command line, awkward meshes and clouds
)


def load_cases() -> List:
    """Every case (a list of ``framework.Case``), the groups imported in the order of :data:`GROUPS`."""
    from .framework import CASES

    for name in GROUPS:
        importlib.import_module(f"{__name__}.{name}")
    return CASES
