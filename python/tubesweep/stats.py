"""Statistics of one solve."""

from __future__ import annotations

from dataclasses import dataclass, asdict
from typing import Any, Dict, Mapping, Optional, Tuple


@dataclass(frozen=True)
class SolveStats:
    """What a solve did.

    Attributes
    ----------
    iterations : int
        Full passes of the 2^d sweep orders; with the outer rim left to the end (the default),
        one more for the rim, whose values are set once the rest of the band has converged.
    sweeps : int
        Directional sweeps (2^d per iteration), and the rim's passes (one in dependency order,
        a few more where rim nodes read each other in a cycle).
    updates : int
        Local updates performed.
    converged : bool
        Whether the largest change in the last iteration fell below ``tol``.
    last_change : float
        Largest change of any value during the last iteration.
    seconds : float
        Wall-clock time of the native solve: its preparation (the grid-path search behind the
        numerical infinity and the front window, the outer rim, the active flags) and the sweeps
        (band construction excluded; see ``setup_seconds``).
    band_points, inner_points, outer_points, fixed_points : int
        Nodes in the band, in the inner tube, in the extension layer, and held fixed (sources).
    setup_seconds : float
        Time spent finding the band, evaluating the surface and initialising the sources.
    band_bytes : int
        Memory held by the band structure and the per-node arrays of the solve.
    window_edge : float
        Where the sweeps' front window stood when the solve ended (Godunov on surfaces,
        docs/architecture.md): ``inf`` when it had opened, always so for a converged solve. After
        a solve stopped by ``max_iterations``, the nodes above it are not reached yet (``inf``)
        and the values just below it are not converged.
    facing_pairs : int
        Pairs of neighbouring band nodes that lie across a gap between two parts of the surface
        facing each other, narrower than the tubes (a thin part, a narrow slot or fold, parts that
        nearly touch): the eikonal equation can cross the gap there, and the solve warned that
        travel times beyond it can be too short (docs/surfaces.md, "Parts of the surface that
        face each other"; the places: ``Solution.narrow_gaps()``). 0 when the grid resolves every
        gap.
    narrowest_gap : float
        The narrowest such gap found, ``|cp(a) − cp(b)|`` over those pairs (``inf`` when there is
        none); the true gap can be narrower. Gaps under about one grid spacing are not found.
    cut_edges : int
        Edges between neighbouring band nodes that the solve removed so that the front cannot
        take a shortcut the surface does not have (triangle meshes only): across the narrow gaps
        of ``facing_pairs``, and above concave edges and between parts a few spacings apart,
        where two neighbours' closest points lie more than 1.5 grid spacings apart (more, between
        two extension nodes: docs/surfaces.md, "Parts of the surface that face each other"). 0 on
        other surfaces, which keep the paper's scheme.
    crease_thinned : int
        Inner-tube nodes at a level set's creases or corners that ran as extension nodes (their
        values read at their closest points) so that the front cannot cut the corner there:
        ``order=2`` and ``order="auto"`` on level sets given as distances (docs/second-order.md,
        the cube's edges). 0 for ``order=1``, smooth surfaces, meshes and re-distanced φ.
    thin_strip_iterations : tuple of two ints
        Parallel iterations (3D, more than one thread) whose sweeps ran strips thin across the
        first and across the second leading axis of the grid, where the iteration's work crossed
        that axis; the others ran square tiles (docs/development/performance-history.md, "Strips thin across the
        front"). ``(0, 0)`` on one thread and in 2D. The values do not depend on it.
    prefetch_iterations : int
        Iterations whose sweeps fetched the rows' data ahead into the cache (x86-64): those after
        an iteration whose visited rows held more data than a quarter of the last-level cache
        (before the first, every row counts as visited, or none with the front window;
        docs/development/performance-history.md, "Rows fetched ahead"). The values do not depend on it.
    local_solver : str
        The local solver that ran in the inner tube: ``"godunov"`` (the Godunov update, Eq. (3)),
        ``"lxf"`` (Lax–Friedrichs: Eq. (4) for the eikonal equation, Sect. 5.1 for the moving
        medium and metrics) or ``"upwind"`` (the upwind, Godunov-type solver of the moving medium
        and metrics, docs/hamiltonians.md).
    order : int
        The order of the scheme that ran: 1 (the paper's) or 2 (docs/second-order.md on surfaces,
        docs/box-second-order.md for ``travel_time(..., order=2)``). With ``order="auto"``, 2
        where it applies and 1 where it does not (then ``order_fallback`` says why).
    order_fallback : str or None
        With ``order="auto"``, when second order did not apply and the solve ran ``order=1``: the
        reason, the text of the ``ValueError`` an explicit ``order=2`` raises (a tube more than
        half unresolved, a cube's convex edges, a mesh with creases coarse against the grid or facing itself
        across narrow gaps, a Hamiltonian or option of the first-order scheme, ...). None
        otherwise.
    order2 : dict or None
        For ``order=2``: ``first_order_iterations`` and ``second_order_iterations`` (the two
        phases), ``fallback_iteration`` (the phase-2 iteration at which the stagnation safeguard
        switched to accepting decreases only, None when it did not fire), ``fallback_change``
        (the largest change of the iterations before it: about how far from settled the values were,
        with a warning above 100 tolerances; None when it did not fire), ``runaway_iteration``
        (on surfaces the phase-2 iteration at which a value fell below zero and the second-order sweeps were
        abandoned for the first phase's values; in the box the iteration, both phases counted, at which the
        factored sweeps fell without bound and were abandoned for the plain first-order scheme, whose
        ``plain_iterations`` follow; with a warning; None when they were not),
        ``unreached`` (nodes
        never reached), ``tol`` (the phases' stopping tolerance) and ``fix_radius`` (the ball of
        nodes fixed around each source); on surfaces also ``max_curvature`` (the largest principal
        curvature found in the tube), ``grad_norm_range`` (|∇φ| in the inner tube),
        ``inner_nodes``, ``first_order_nodes`` (the inner-tube nodes that ran the first-order update:
        second order is decided node by node) and ``first_order_reasons`` (how many for each
        reason: ``curvature``, ``gradient``, ``stencil``, ``runaway``; ``sol.first_order_points()`` shows
        where), ``runaway`` (when the sweeps ran away and were solved again with the nodes where they
        did at first order: ``iteration``, the first attempt's phase-2 iteration at which they ran
        away, ``nodes``, the inner-tube nodes so put, and ``near``, where the values fell farthest;
        None otherwise),
        ``geometry_fitted`` (whether the derivatives of a noisy φ came from least-squares fits),
        ``creases`` (the crease nodes found, ``angle_degrees`` the largest turn of the normal
        between neighbours there, ``faces_angle_degrees`` the widest across a node, which sizes
        the warning on a φ given as it is, and the shortcut per crease), on a mesh ``mesh_map`` (the mesh's smooth map: how it was fitted), and with
        ``warm=`` a ``warm`` dict: ``carried`` (nodes started from the previous values),
        ``new_nodes`` (nodes new to the band), ``unreached_before``, ``all_started``,
        ``restarted`` (why the warm sweeps started again cold, None when they did not:
        ``"runaway"``, ``"stagnation"``, or ``"previous_runaway"`` when the previous solve's sweeps
        ran away and this one started cold at once, ``carried`` then 0), ``changed``
        (the nodes whose update changed, where the sweeps started), ``extrapolated`` (whether
        two previous solutions gave the start) or, for a start refused with
        ``warm_refused="cold"``, ``refused`` (why): docs/moving-surfaces.md.
    creases : dict or None
        For the first-order scheme (``order=1``, and ``order="auto"`` where it ran it) on a level
        set: the creases and corners of its level sets in the tube, as
        ``order2["creases"]`` (``nodes``, ``angle_degrees``: the faces' angle, ``faces_angle_degrees``
        likewise, ``shortcut_per_inner_width``: 2·tan(θ/2)). In the paper's tube (``order=1``) a front crossing one arrives early by about
        ``shortcut_per_inner_width·inner·Δx``, with a ``RuntimeWarning`` (the cube at N = 41: 4.25Δx
        per edge; up to 1.5 times that on a re-distanced φ, for which the dict says
        ``redistanced: True``: found by the second-order geometry's test, which a voxel mask's
        staircase does not trip, and computed for ``order=1`` only); ``crease_thinned`` counts the
        nodes ``"auto"`` took out of the tube there. On a voxel mask or a noisy φ, whose kinks hide
        creases from that test, they are found on φ smoothed over about a spacing, for ``order=1``
        and where ``"auto"`` ran first order on a re-distanced φ (with a ``RuntimeWarning`` giving
        ``shortcut_per_inner_width·inner·Δx``): ``smoothed_turn_degrees`` is the turn of the
        smoothed normal within two spacings, and the faces' angle is read back from it (the
        smoothing reads a crease as 0.5–0.75 of its angle); ``concave`` (with it) says whether most of
        those nodes lie beside a concave crease (between fused parts: read from a lower turn). None for other surfaces and with ``order=2``
        (see ``order2``).
    box_cut : dict or None
        On surfaces, where the grid box cuts the tube (None where the band stays inside it):
        ``surface_cut`` (the surface itself crosses the box's boundary, with a ``RuntimeWarning``:
        the distances are those of the part inside the box), ``faces`` (the faces it crosses, or
        the tube touches), ``cut_length`` (3D: the length of the curve along which it crosses them)
        or ``cut_points`` (2D: the crossings), ``inner_on_boundary`` (inner-tube nodes on the
        boundary) and ``gap`` (the smallest |φ| on the boundary).
    bridged_holes : dict or None
        On an open triangle mesh, its holes narrower than the band (``2·outer`` grid spacings),
        which the band spans: distances reached across such a hole are those of the surface with
        the hole filled, shorter than the mesh's geodesics round it by up to the hole's detour
        (for a convex hole half its perimeter less its width: 0.57 widths for a round one, about
        the length of a slot). On a point cloud, the small holes over which the band's nodes
        meet (read from the rim round them). ``count``, ``widest`` (the widest one's width),
        ``reach`` (the band's span, ``2·outer·Δx``), ``detour`` (the largest detour), ``where``
        and ``width`` (that hole's centre and width), ``size`` (the surface's bounding-box
        diagonal); with a ``RuntimeWarning`` when the detour is over 10% of the size. None
        otherwise.
    slits : dict or None
        On an open triangle mesh, where its open edges come within 4 grid spacings of each
        other edge on, across empty space (a cylinder slit along its length, a comb's teeth):
        ``count`` (vertex pairs across), ``gap`` (the narrowest), ``where`` and ``detour`` (the
        pair with the longest way round along the open edges, less its gap), ``size`` (the
        mesh's bounding-box diagonal), ``joined`` (the pairs narrower than the band keeps apart:
        1.6 grid spacings across a grid axis, 2.6 diagonally) and ``spacing`` (the grid spacing
        that keeps them all apart). Where the band joins a slit's sides, distances reached
        across come out short, by up to ``detour``: a ``RuntimeWarning`` says so when the detour
        is over 10% of the size. None otherwise.
    tube_shortcut : float or None
        For the first-order scheme with an inner tube wider than the paper's (``inner`` above 2):
        the estimated largest share by which the distances come out short, since a path that bends
        with the surface cuts through the tube on the inside of the bend (about 0.7 × inner·Δx ×
        the surface's typical curvature; the sphere of radius 0.5 at N = 81 and ``inner=8``: 0.27
        estimated, 0.28 measured), with a ``RuntimeWarning`` from 10%. None otherwise.

    Examples
    --------
    >>> import tubesweep as ts
    >>> s = ts.surfaces.Sphere(0.5)
    >>> st = ts.solve(s, ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41)), [s.default_source]).stats
    >>> st.converged, st.band_points > 0
    (True, True)
    """

    iterations: int
    sweeps: int
    updates: int
    converged: bool
    last_change: float
    seconds: float
    band_points: int
    inner_points: int
    outer_points: int
    fixed_points: int
    setup_seconds: float = 0.0
    band_bytes: int = 0
    window_edge: float = float("inf")
    facing_pairs: int = 0
    narrowest_gap: float = float("inf")
    cut_edges: int = 0
    crease_thinned: int = 0
    thin_strip_iterations: Tuple[int, int] = (0, 0)
    prefetch_iterations: int = 0
    local_solver: str = "godunov"
    order: int = 1
    order2: Optional[Dict[str, Any]] = None
    order_fallback: Optional[str] = None
    box_cut: Optional[Dict[str, Any]] = None
    creases: Optional[Dict[str, Any]] = None
    bridged_holes: Optional[Dict[str, Any]] = None
    slits: Optional[Dict[str, Any]] = None
    tube_shortcut: Optional[float] = None

    @classmethod
    def of_sweeps(cls, st: Mapping[str, Any], **rest: Any) -> "SolveStats":
        """The stats of a solve from the core's report ``st`` of its sweeps (``iterations``,
        ``sweeps``, ``updates``, ``converged``, ``last_change``, ``seconds``) and the other fields
        by name (``sweeps=`` among them where the report has none)."""
        taken = {
            k: st[k] for k in ("iterations", "sweeps", "updates", "converged", "last_change", "seconds") if k in st
        }
        return cls(**{**taken, **rest})

    @property
    def updates_per_second(self) -> float:
        """Local updates per second of ``seconds`` (the native solve, its preparation included)."""
        return self.updates / self.seconds if self.seconds > 0 else float("nan")

    def as_dict(self) -> Dict[str, Any]:
        """The statistics as a plain dict (for JSON or a table), with ``updates_per_second`` added.

        Returns
        -------
        dict
            Field name → value.

        Examples
        --------
        >>> import tubesweep as ts
        >>> s = ts.surfaces.Sphere(0.5)
        >>> d = ts.solve(s, ts.Grid((-1, -1, -1), (1, 1, 1), (41, 41, 41)), [s.default_source]).stats.as_dict()
        >>> sorted(d)[:2]
        ['band_bytes', 'band_points']
        """
        d = asdict(self)
        d["updates_per_second"] = self.updates_per_second
        return d
