"""The check stage of a solve (``ts.solve``, ``Tube.solve``): the arguments that do not depend on
the surface, validated once into a :class:`SolveRequest` that the later stages read (surface →
tube → scheme, ``_order_choice`` and ``_first_order.solve_on_tube`` → :class:`~tubesweep.Solution`)."""

from __future__ import annotations

import dataclasses
from typing import Any, Callable, Optional, Tuple, Union

import numpy as np

from . import hamiltonians as _hams
from ._validate import as_sources, check_hamiltonian, check_infinity, check_tolerance, progress_callback
from .grid import Grid
from .moving import check_warm_refused
from .second_order import check_order

#: The point sources' initialisations of the first-order scheme (``source_init``).
SOURCE_INITS = ("exact", "node")


@dataclasses.dataclass(frozen=True)
class SolveRequest:
    """What a solve is asked for, checked (:meth:`checked`): the sources as a (K, d) array on the
    grid, the order (1, 2 or ``"auto"``), the Hamiltonian resolved to ``general`` (a
    ``ts.hamiltonians`` object, or None for the isotropic update) and the local ``scheme``'s label,
    the progress callback, and the other options as given. ``started``: ``time.perf_counter()``
    at the call (the solve's set-up time counts from it)."""

    sources: np.ndarray
    order: Union[int, str]
    general: Any
    scheme: str
    speed: Any
    source_init: str
    source_radius: Optional[float]
    tol: Optional[float]
    max_iterations: int
    progress: Optional[Callable[[int, float, int], None]]
    infinity: Optional[float]
    threads: int
    paper_sweeps: bool
    warm: Any
    warm_refused: str
    started: float

    @classmethod
    def checked(
        cls,
        grid: Grid,
        sources: Any,
        *,
        order: Any,
        hamiltonian: Any,
        flow: Any,
        allow_supersonic: bool,
        speed: Any,
        source_init: str,
        source_radius: Optional[float],
        tol: Optional[float],
        max_iterations: int,
        progress: Any,
        infinity: Optional[float],
        threads: int,
        paper_sweeps: bool,
        warm: Any,
        warm_refused: str,
        started: float,
    ) -> "SolveRequest":
        """The request, or the first error of its arguments (a ValueError or TypeError naming
        the argument and the fix). ``source_radius`` is checked against the grid only where the
        first-order scheme runs (:func:`check_source_radius`): second order refuses it first."""
        order = check_order(order)
        src = as_sources(sources, grid)
        general, scheme = resolve_scheme(hamiltonian, flow, allow_supersonic)
        check_tolerance(tol, max_iterations)
        cb = progress_callback(progress)
        check_source_init(source_init)
        check_infinity(infinity)  # checked whichever order runs (order=2 has no use for it)
        check_warm_refused(warm_refused)
        return cls(
            sources=src,
            order=order,
            general=general,
            scheme=scheme,
            speed=speed,
            source_init=source_init,
            source_radius=source_radius,
            tol=tol,
            max_iterations=max_iterations,
            progress=cb,
            infinity=infinity,
            threads=threads,
            paper_sweeps=paper_sweeps,
            warm=warm,
            warm_refused=warm_refused,
            started=started,
        )


def resolve_scheme(hamiltonian: Any, flow: Any, allow_supersonic: bool) -> Tuple[Any, str]:
    """The Hamiltonian object (None for the isotropic Godunov or Lax–Friedrichs update) and the
    local scheme's label."""
    general = _hams.resolve(hamiltonian, flow, allow_supersonic)
    scheme = check_hamiltonian(hamiltonian) if general is None else general.label
    return general, scheme


def check_source_init(source_init: str) -> None:
    """``source_init`` as one of :data:`SOURCE_INITS`, or a ValueError naming the choices."""
    if source_init not in SOURCE_INITS:
        raise ValueError(f"source_init must be one of {SOURCE_INITS}; got {source_init!r}")


def check_source_radius(source_radius: Any, source_init: str, grid: Optional[Grid] = None) -> None:
    """``source_radius``: a positive distance, with ``source_init="exact"``, below the grid's
    diagonal (the chord's validity within it is checked with the surface, ``_sources``)."""
    if source_radius is None:
        return
    if isinstance(source_radius, bool) or not isinstance(source_radius, (int, float, np.integer, np.floating)):
        raise TypeError(f"source_radius must be a number (a distance) or None; got {source_radius!r}")
    if not (np.isfinite(source_radius) and source_radius > 0):
        raise ValueError(f"source_radius must be a positive finite distance; got {source_radius!r}")
    if grid is not None:
        diagonal = float(np.linalg.norm(np.asarray(grid.upper, float) - np.asarray(grid.lower, float)))
        if source_radius > diagonal:
            raise ValueError(
                f"source_radius = {source_radius:g} exceeds the grid's diagonal ({diagonal:.4g}): it is the radius of the "
                "ball around each source whose nodes are fixed to the straight (chord) distance, which is the "
                "distance along the surface only where the surface is flat. Use a few grid spacings "
                f"(h = {grid.spacing:.4g}) up to a small fraction of the surface's size, or leave it out"
            )
    if source_init != "exact":
        raise ValueError(
            "source_radius applies to source_init='exact' (the nodes near a source fixed to the exact time)"
        )
