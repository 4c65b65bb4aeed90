"""Solving again on a surface that moved (docs/moving-surfaces.md): the warm start.

``tube.moved(phi_new)`` gives the :class:`~tubesweep.Tube` of the moved surface on the same grid
with the same widths, and ``tube.solve(sources, warm=previous)`` (or ``ts.solve(...,
warm=previous)``) starts the second-order sweeps from ``previous``'s values carried onto the new
band instead of from the sources alone. The result is the cold solve's fixed point: the sweeps
from the carried values are phase 2 of the second-order solve (plain assignment, values may rise
or fall), and a safeguard that would leave that path (the stagnation test, the runaway guard)
makes the solve start again cold (``tubesweep_core::second_order::warm`` has the argument).

A warm start is refused, with :class:`WarmStartRefused` naming the cause and the fix, when the
previous solution cannot be carried: another grid, an ``order=1`` solution or a solve that runs
first order, other sources (or sources that moved farther than the tube), a surface that moved
farther than ``outer − inner`` grid spacings (nodes of the new inner tube outside the previous
band), or a change of topology (the inner tube's connected components changed). With
``warm_refused="cold"`` the solve runs cold instead and records why in
``sol.stats.order2["warm"]`` (a solve that runs first order has no ``order2`` report:
``sol.stats.order == 1`` says the warm start was not used).
"""

from __future__ import annotations

import zlib
from typing import Any, Dict, Optional, Tuple

import numpy as np

from . import _native
from ._roles import ROLE_OUTER

__all__ = ["WarmStartRefused", "WARM_REFUSED"]

#: What a solve does when its warm start is refused: raise :class:`WarmStartRefused`, or solve cold.
WARM_REFUSED = ("raise", "cold")


class WarmStartRefused(ValueError):
    """The previous solution given as ``warm=`` cannot start this solve; the message says why and
    what to do (``warm_refused="cold"`` solves cold instead)."""


def check_warm_refused(warm_refused: Any) -> str:
    """``warm_refused`` as one of :data:`WARM_REFUSED`, or a ValueError naming the choices."""
    if not isinstance(warm_refused, str) or warm_refused not in WARM_REFUSED:
        raise ValueError(
            f"warm_refused must be 'raise' (a refused warm start raises WarmStartRefused) or 'cold' (the solve runs "
            f"cold instead, the reason in sol.stats.order2['warm']); got {warm_refused!r}"
        )
    return warm_refused


def check_previous(warm: Any, grid: Any, which: str = "previous") -> Any:
    """``warm`` as a second-order :class:`~tubesweep.Solution` on ``grid``, or the refusal;
    ``which`` names it ("previous", or "older" of a pair ``(older, previous)``)."""
    from .solution import Solution

    what = "warm" if which == "previous" else "warm=(older, previous): older"
    if not isinstance(warm, Solution):
        raise TypeError(
            f"{what} must be the Solution of a previous solve (ts.solve or Tube.solve); got {type(warm).__name__}"
        )
    if warm.grid != grid:
        raise WarmStartRefused(
            f"warm: the {which} solution is on another grid ({warm.grid!r}, this solve's is {grid!r}); a warm start "
            "carries values node by node, so both solves need the same grid. Solve cold (leave out warm=)"
        )
    if getattr(warm, "order", 1) != 2 or warm._factoring is None:
        cure = (
            "Solve the previous step with order=2 or 'auto' where second order applies, or solve cold (leave out warm=)"
            if which == "previous"
            else "Pass warm=previous alone (a start carried from one step, not extrapolated from two)"
        )
        raise WarmStartRefused(
            f"warm: the {which} solution was solved at first order (order=1, or order='auto' fell back to it); warm "
            f"starts run the second-order solve from second-order solutions. {cure}"
        )
    return warm


def refusal_for_order1(reason: Optional[str]) -> WarmStartRefused:
    """The refusal of a warm start on a solve that runs first order (``reason``: why second order
    did not apply, None for ``order=1`` asked for)."""
    why = "order=1 was asked for" if reason is None else f"second order does not apply here ({reason})"
    return WarmStartRefused(
        f"warm: warm starts run the second-order solve, and {why}. Leave out warm= (or pass warm_refused='cold')"
    )


def values_checksum(values: np.ndarray) -> int:
    """A CRC-32 of a solution's values, kept with its digests: values edited after the solve
    (``sol.values`` is a plain array) no longer match it, and a warm start then sweeps every node."""
    return zlib.crc32(np.ascontiguousarray(values, dtype=np.float64).data)


#: How much looser than a warm solve's tolerance the previous solve's may be for its digests to
#: be trusted (:func:`_digests_to_trust`).
TOL_SLACK = 1.1


def _digests_to_trust(warm: Any, tol: float) -> Tuple[Optional[np.ndarray], Optional[str]]:
    """The previous solution's digests, when its values are the fixed point of the updates they
    describe at this solve's tolerance; else None and why every node starts active. A node whose
    digest is unchanged is not visited until a node it reads moves, so its previous value must be
    converged, at a tolerance no looser than this solve's, and as the solve left it."""
    digests, digested = getattr(warm, "_digests", None), getattr(warm, "_digested", None)
    if isinstance(digested, str):
        return None, f"{digested}: every node started"
    if digests is None or digested is None:
        return None, "the previous solution kept no digests (a one-off ts.solve): every node started"
    prev_tol, checksum = digested
    # (a tenth looser is kept: its values are then within 1.1 of this solve's tolerance of their fixed
    # point, and a speed changed by 1e-6 moves the default tolerance, which scales with the slowness)
    if prev_tol > tol * TOL_SLACK:
        return None, (
            f"the previous solve's tolerance {prev_tol:.6g} is looser than this one's {tol:.6g} by more than "
            f"{TOL_SLACK - 1:.0%}: every node started (the default tolerance scales with the mean slowness: pass the "
            "same tol= to both solves to keep the local start)"
        )
    if values_checksum(warm.values) != checksum:
        return None, "the previous solution's values were changed after its solve: every node started"
    return digests, None


def _linear(sol_or_tube: Any) -> np.ndarray:
    return np.ascontiguousarray(sol_or_tube.linear, dtype=np.int64).view(np.uint64)


def inner_components(band: Any, roles: np.ndarray, known: Optional[Tuple[Any, ...]]) -> Tuple[int, int, np.ndarray]:
    """The connected components of the inner tube (the nodes of ``roles`` other than the
    extension layer's) on ``band``, as ``(count, checksum of the inner flags, each node's
    component label)``: ``known``, kept from an earlier call, is used when the flags' checksum
    matches (a warm solve's tube is the next step's previous tube: its components are labelled
    once)."""
    inner = np.ascontiguousarray(roles != ROLE_OUTER)
    crc = zlib.crc32(inner.view(np.uint8).data)
    if known is not None and known[1] == crc:
        return known
    labels = _native.band_component_labels(band, inner)  # a component's label: its smallest position
    return int(np.count_nonzero(labels == np.arange(len(labels), dtype=np.uint32))), crc, labels


def _topology_change(
    warm: Any,
    old: Tuple[int, int, np.ndarray],
    tube: Any,
    new: Tuple[int, int, np.ndarray],
    old_position: np.ndarray,
) -> Optional[str]:
    """Why the inner tube's topology changed from ``warm``'s to ``tube``'s, or None: another
    number of connected components, or, with the same number, a component that meets two of the
    other's through the nodes in both inner tubes (a count alone let a part pinch off while two
    others merged, and the part that lost its source kept finite carried values). A component
    that shares no inner node with the other tube (moved farther than the inner tube is wide,
    within outer − inner) is not held against it. ``old_position``: each of ``tube``'s band nodes'
    position in ``warm``'s band (+∞ when new to it), as ``carried_values`` merged them."""
    if old[0] != new[0]:
        return (
            f"the inner tube has {new[0]} connected component(s), the previous one had {old[0]} (a part pinched off "
            "or two parts merged)"
        )
    at_new = np.flatnonzero(np.isfinite(old_position))
    at_old = old_position[at_new].astype(np.int64)
    both = (np.asarray(warm.roles)[at_old] != ROLE_OUTER) & (np.asarray(tube.roles)[at_new] != ROLE_OUTER)
    # the (previous, new) label pairs, as one 64-bit key each (np.unique over rows is slow)
    keys = np.unique((old[2][at_old[both]].astype(np.uint64) << np.uint64(32)) | new[2][at_new[both]].astype(np.uint64))
    before, after = keys >> np.uint64(32), keys & np.uint64(0xFFFFFFFF)
    split = np.unique(before).size < before.size  # a previous component meets two new ones
    merged = np.unique(after).size < after.size  # a new component meets two previous ones
    if not (split or merged):
        return None
    how = (
        "a part pinched off while two others merged"
        if split and merged
        else "a part pinched off while another appeared"
        if split
        else "two parts merged while another vanished"
    )
    return (
        f"the inner tube's {new[0]} connected component(s) do not match the previous ones one to one ({how}, keeping "
        "the count)"
    )


def carried_values(
    warm: Any, tube: Any, feet: np.ndarray, inner_width: float, tol: float
) -> Tuple[np.ndarray, Dict[str, Any], Dict[str, Any]]:
    """The previous solution ``warm`` carried onto ``tube`` (a ``_prepare._PreparedTube``) for a
    solve from the sources' foot points ``feet``: a node in both bands keeps its value, a node new
    to the band starts at +∞ (``tubesweep_core::second_order::warm::carry_values``). ``warm`` may
    be a pair ``(older, previous)`` of the two previous steps' solutions: the start is then
    extrapolated in time, ``2·previous − older``, where both have a value and the node's update
    changed (error O(δ²) instead of O(δ) for a surface moving smoothly by δ per step; about a
    quarter fewer updates). Returns the carried values, the other warm arguments of the native
    solve (the older values, the previous band's positions and digests: the sweeps start from
    the nodes whose update changed, when the previous values are the converged, unedited values of
    a solve at a tolerance no looser than ``tol``) and the report. Raises :class:`WarmStartRefused` when the
    previous solution does not fit (see the module)."""
    grid = tube.grid
    older = None
    if isinstance(warm, (tuple, list)):
        if len(warm) != 2:
            raise TypeError(
                f"warm must be a Solution or a pair (older, previous) of the two previous steps' Solutions; got a "
                f"sequence of {len(warm)}"
            )
        older, warm = warm
    check_previous(warm, grid)
    if older is not None:
        check_previous(older, grid, "older")
    if older is not None and len(older._factoring[1]) != len(warm._factoring[1]):
        raise WarmStartRefused(
            f"warm: the older solution has {len(older._factoring[1])} source(s), the previous one "
            f"{len(warm._factoring[1])}; warm=(older, previous) takes the two previous steps of the same problem"
        )
    h = grid.spacing
    slack = tube.outer_eff * h - inner_width  # how far the surface may move: outer − inner spacings
    old_feet = warm._factoring[1]
    if len(old_feet) != len(feet):
        raise WarmStartRefused(
            f"warm: the previous solution has {len(old_feet)} source(s), this solve {len(feet)}; a warm start needs the "
            "same sources, moved with the surface. Solve cold (leave out warm=)"
        )
    old_linear, new_linear = _linear(warm), _linear(tube)
    carried = _native.carry_band_values(old_linear, np.ascontiguousarray(warm.values, dtype=float), new_linear)
    more: Dict[str, Any] = {}
    if older is not None:
        more["warm_older"] = _native.carry_band_values(
            _linear(older), np.ascontiguousarray(older.values, dtype=float), new_linear
        )
    digests, all_started = _digests_to_trust(warm, tol)
    anchor: Optional[np.ndarray] = None
    if digests is not None:
        digests, anchor, drifted = _unpropagated_drift(warm, digests, tol)
        more["warm_previous_linear"] = old_linear
        more["warm_previous_digests"] = np.ascontiguousarray(digests, dtype=np.uint64)
    inner_new = tube.roles != ROLE_OUTER
    # whether each node of the new band was in the previous one: the same merge as the values,
    # carrying the previous positions (+∞ for a node new to the band)
    old_position = _native.carry_band_values(old_linear, np.arange(len(old_linear), dtype=float), new_linear)
    in_both = np.isfinite(old_position)
    # nodes of the new inner tube outside the previous band (a node in it that the previous solve
    # never reached, on a part without a source, stays unreached: the sweeps leave it at +∞)
    missing = int(np.count_nonzero(inner_new & ~in_both))
    if missing:
        # the previous band's width is the limit (the new tube's may be wider)
        prev_outer = float(getattr(warm, "outer", tube.outer_eff))
        if prev_outer <= inner_width / h + 1e-9:
            raise WarmStartRefused(
                f"warm: {missing} nodes of the new inner tube lie outside the previous band: this tube's inner tube "
                f"(inner = {inner_width / h:g} grid spacings) is as wide as the previous solution's whole band (outer = "
                f"{prev_outer:g}) or wider. Build both tubes with the same widths (tube.moved keeps them), or solve cold "
                "(leave out warm=)"
            )
        raise WarmStartRefused(
            f"warm: {missing} nodes of the new inner tube lie outside the previous band: the surface moved by "
            f"the previous solution's outer − inner = {prev_outer - inner_width / h:g} grid spacings or more since it. "
            "Move in smaller steps (less than outer − inner spacings per solve), build the tubes of both steps wider "
            "(ts.Tube(..., outer=6); tube.moved keeps the widths), or solve cold (leave out warm=)"
        )
    old = inner_components(warm._band, warm.roles, getattr(warm, "_inner_components", None))
    # (kept: the next step's warm start from this solve reads it)
    tube.inner_components = inner_components(tube.band, tube.roles, tube.inner_components)
    changed = _topology_change(warm, old, tube, tube.inner_components, old_position)
    if changed is not None:
        raise WarmStartRefused(
            f"warm: the topology changed: {changed}; carried values on a part that lost its source would never "
            "settle. Solve cold (leave out warm=) across the change, then warm again"
        )
    if older is not None:
        _check_older(older, warm, old_linear, slack, h)
    # the sources as a set, in any order: each one's nearest previous source, and the other way
    old_feet = np.ascontiguousarray(old_feet, dtype=float)
    moved = np.linalg.norm(old_feet[_native.nearest_feet(old_feet, feet)] - feet, axis=1)
    back = np.linalg.norm(feet[_native.nearest_feet(feet, old_feet)] - old_feet, axis=1)
    # (a twentieth of a spacing beyond the slack: the feet are projections onto the discrete
    # surface, which moved a source carried exactly outer − inner spacings 0.004 spacings farther)
    if moved.size and max(float(np.max(moved)), float(np.max(back))) > slack + 0.05 * h:
        new_side = float(np.max(moved)) >= float(np.max(back))
        i = int(np.argmax(moved if new_side else back))
        far = float((moved if new_side else back)[i])
        which = f"source {i} lies" if new_side else f"the previous solution's source {i} lies"
        other = "the previous solution's sources" if new_side else "this solve's sources"
        raise WarmStartRefused(
            f"warm: {which} {far:.4g} from the nearest of {other} ({far / h:.2f} grid spacings), farther than the "
            f"surface may move between warm solves (outer − inner = {slack / h:g} spacings); a source that leaves the "
            "surface's path is another problem. Pass the previous sources moved with the surface, move in smaller "
            "steps, or solve cold (leave out warm=)"
        )
    info = {
        "carried": int(np.count_nonzero(np.isfinite(carried))),
        # nodes new to the band, and nodes of both that the previous solve left unreached: both start at +∞
        "new_nodes": int(np.count_nonzero(~in_both)),
        "unreached_before": int(np.count_nonzero(in_both & ~np.isfinite(carried))),
        "all_started": all_started,
    }
    if anchor is not None:
        info["drifted"] = drifted
        # the anchors carried onto the new band (NaN: the node's readers are woken in this solve,
        # or it is new to the band; keep_for_warm_starts puts its new value there)
        more[_ANCHOR] = _native.carry_band_values(old_linear, anchor, new_linear)
    return np.ascontiguousarray(carried), more, info


#: The key under which ``carried_values`` hands the carried anchors to ``keep_for_warm_starts``
#: (taken out of the native solve's arguments before it runs).
_ANCHOR = "_anchors"


def _unpropagated_drift(warm: Any, digests: np.ndarray, tol: float) -> Tuple[np.ndarray, np.ndarray, int]:
    """The drift a chain of warm solves has not passed on. A node whose update is unchanged is
    not visited until a node it reads moves by more than the tolerance in one update, so a node
    that moves by less in every solve (a speed changed by 1e-6 per solve) never wakes its readers:
    at N = 41 they lagged 457 tolerances behind after 1000 solves. Each solution keeps, per node,
    its *anchor*: its value when its readers were last brought up to date. A node whose value has
    drifted more than a tenth of a tolerance from its anchor has its digest changed here, so that it
    and its readers start active, and its anchor is renewed (NaN here). Returns the digests, the
    anchors (NaN where renewed) and how many nodes drifted."""
    values = np.asarray(warm.values, dtype=float)
    anchor = getattr(warm, "_anchor", None)
    if anchor is None or len(anchor) != len(values):
        return digests, np.full(len(values), np.nan), 0
    both_inf = np.isinf(values) & np.isinf(anchor)
    with np.errstate(invalid="ignore"):
        drift = np.where(both_inf, 0.0, np.abs(values - anchor))
    drifted = ~(drift <= 0.1 * tol)
    count = int(np.count_nonzero(drifted))
    anchor = np.where(drifted, np.nan, anchor)
    if count:
        digests = np.array(digests, dtype=np.uint64, copy=True)
        digests[drifted] = ~digests[drifted]
    return digests, anchor, count


def _check_older(older: Any, previous: Any, previous_linear: np.ndarray, slack: float, h: float) -> None:
    """Refuses ``warm=(older, previous)`` whose ``older`` is not the step before ``previous`` of the
    same problem: its sources farther from the previous ones, or the previous inner tube farther
    outside its band, than two steps may move (2·(outer − inner) spacings). Such a pair (a torus's
    solution, a source at the other pole, a sphere 6 spacings smaller) was taken without a word and
    only cost time (a review of issue 47)."""
    reach = 2.0 * slack * (1 + 1e-9)
    a = np.ascontiguousarray(older._factoring[1], dtype=float)
    b = np.ascontiguousarray(previous._factoring[1], dtype=float)
    far = max(
        float(np.max(np.linalg.norm(a[_native.nearest_feet(a, b)] - b, axis=1))),
        float(np.max(np.linalg.norm(b[_native.nearest_feet(b, a)] - a, axis=1))),
    )
    if far > reach:
        raise WarmStartRefused(
            f"warm=(older, previous): a source of one lies {far:.4g} ({far / h:.2f} grid spacings) from the nearest of "
            f"the other's, farther than two steps may move (2·(outer − inner) = {reach / h:g} spacings): the pair must "
            "be the two previous steps of this problem, older first. Pass warm=previous alone, or the right pair"
        )
    position = _native.carry_band_values(_linear(older), np.zeros(len(older.values)), previous_linear)
    outside = int(np.count_nonzero((previous.roles != ROLE_OUTER) & ~np.isfinite(position)))
    if outside:
        raise WarmStartRefused(
            f"warm=(older, previous): {outside} nodes of the previous solution's inner tube lie outside the older "
            "one's band: the surface moved farther between them than two steps may, or they are of different "
            "surfaces. The pair must be the two previous steps of this problem, older first. Pass warm=previous alone, "
            "or the right pair"
        )
