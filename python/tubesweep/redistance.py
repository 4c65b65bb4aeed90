"""Re-distancing a level set function that is not a distance function, in the band only.

Used by ``LevelSet(phi, redistance=True)``. For each candidate band node x:

1. the first-order estimate ``φ/|∇φ|`` — one Newton step ``y = x − φ(x) ∇φ(x) / |∇φ(x)|²``;
2. more Newton steps onto the zero level set, ``y ← y − φ(y) ∇φ(y) / |∇φ(y)|²``;
3. orthogonality iterations: move y in the tangent plane towards the foot of x,
   ``y ← y + (I − n nᵀ)(x − y)``, and project back with Newton steps, until ``x − y`` is parallel
   to the normal ``n(y)`` — then y is the closest point cp(x).

The signed distance is ``sgn φ(x) · |x − cp(x)|`` and the extension direction
``sgn φ(x) (x − cp(x)) / |x − cp(x)|`` is the paper's ``sgn(φ) n`` of Eq. (8) (equivalently the
closest-point direction of Sect. 5.2). Gradients are central differences of φ with step
``GRADIENT_STEP · Δx`` (a callable φ) or ``0.5 Δx`` (a sampled φ, multilinearly interpolated).

For a sampled φ (an array) the same iterations, with the same arithmetic and bits, run in Rust on
all threads (``tubesweep_core::surface::redistance``), with the points kept in the grid's box, where φ is
known (``box`` of :func:`project_to_level_set`): they project given points (sources, paths). The band of
a sampled φ does not start from its nodes but from the zero level set located cell by cell
(:func:`_sampled_redistanced_band`, ``tubesweep_core::surface::redistance_band``), so it works from any
φ with a sign change (masks, plateaus); this module's NumPy code runs the projection for a callable
φ, which only Python can evaluate.
"""

from __future__ import annotations

import warnings
from typing import Callable, Optional, Tuple

import numpy as np

from . import _native
from ._warn import user_stacklevel

__all__ = ["project_to_level_set", "GRADIENT_STEP", "SAMPLED_GRADIENT_STEP"]

#: Finite-difference step for ∇φ of a callable φ, in grid spacings.
GRADIENT_STEP = 1e-3


def _gradient(phi: Callable[[np.ndarray], np.ndarray], y: np.ndarray, eps: float) -> np.ndarray:
    d = y.shape[1]
    g = np.empty_like(y)
    for k in range(d):
        e = np.zeros(d)
        e[k] = eps
        g[:, k] = (phi(y + e) - phi(y - e)) / (2 * eps)
    return g


#: Newton steps before the orthogonality iterations, the most orthogonality iterations, and the
#: move (relative to ``max(1, max |x|)``) below which a point has settled.
NEWTON_STEPS, ORTHOGONALITY_STEPS, SETTLED = 6, 30, 1e-12

#: :data:`SETTLED` for a callable φ, whose gradient comes from differences of its values: their
#: rounding stalls the moves just above 1e-12 where φ is flat across the surface (the sphere
#: φ = (|x| − 0.5)³ at N = 41, the torus quartic at N = 61: moves of 1.45e-12 that never settled,
#: and the band refused for "sharp edges"; at 1e-10 both run order 2, the torus 0.004Δx off).
CALLABLE_SETTLED = 1e-10

#: The most orthogonality iterations of a second projection of the band's candidates that did not
#: settle in :data:`ORTHOGONALITY_STEPS` but lie within 1.5 × the band's half-width of a point on
#: the zero level set (:func:`redistanced_band`). The iterations converge linearly, by about the
#: ratio of the distance to the radius of curvature per step: nodes half a radius away needed more
#: than 30. Only those candidates get the extra steps; the many far ones that never settle (the
#: tube of a torus quartic at N = 81: 237k of 327k candidates) stop at 30.
ORTHOGONALITY_RETRY_STEPS = 300


def project_to_level_set(
    phi: Callable[[np.ndarray], np.ndarray],
    x: np.ndarray,
    eps: float,
    newton_steps: int = NEWTON_STEPS,
    orthogonality_steps: int = ORTHOGONALITY_STEPS,
    tol: float = SETTLED,
    box: Optional[Tuple[np.ndarray, np.ndarray]] = None,
    max_step: Optional[float] = None,
) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Closest points of ``x`` (M, d) on ``{φ = 0}`` by Newton projection and orthogonality
    iterations (see the module docstring).

    Without ``box`` (a callable φ) the Newton steps are damped (:func:`_damped`), each first cut
    to ``max_step`` when given (the band's: twice its half-width, farther than any of its nodes'
    closest points).

    ``box`` (lower, upper corners): where φ is known, for a φ sampled on a grid; the Newton steps
    then keep the points in it (clamped before the first step and after each), as the Rust
    projection of a sampled φ does (``tubesweep_core::surface::redistance``). A callable φ, known
    everywhere, is projected without one.

    Returns ``(cp (M, d), signed distance (M,), converged (M,) bool)``. ``converged`` is False
    where ∇φ vanished or the iterations did not settle (such nodes are far from the surface
    compared with its reach).
    """
    x = np.asarray(x, dtype=float)
    phix = phi(x)
    y = x.copy()
    ok = np.ones(len(x), bool)

    def into_box(y: np.ndarray) -> np.ndarray:
        return y if box is None else np.minimum(np.maximum(y, box[0]), box[1])

    def newton(y: np.ndarray, steps: int) -> Tuple[np.ndarray, np.ndarray]:
        good = np.ones(len(y), bool)
        y = into_box(y)
        if box is not None:  # a sampled φ: the steps stay in the box (and match the Rust bits)
            for _ in range(steps):
                g = _gradient(phi, y, eps)
                n2 = np.sum(g * g, axis=1)
                good &= n2 > 1e-24
                y = into_box(y - np.where(good, phi(y) / np.where(good, n2, 1.0), 0.0)[:, None] * g)
            return y, good
        f = phi(y)
        for _ in range(steps):
            g = _gradient(phi, y, eps)
            n2 = np.sum(g * g, axis=1)
            good &= n2 > 1e-24
            step = np.where(good, f / np.where(good, n2, 1.0), 0.0)[:, None] * g
            if max_step is not None:
                length = np.linalg.norm(step, axis=1)
                step *= np.minimum(1.0, max_step / np.maximum(length, 1e-300))[:, None]
            y, f = _damped(phi, y, f, step, eps)
        return y, good

    y, good = newton(y, newton_steps)
    ok &= good
    active = np.flatnonzero(ok)
    for _ in range(orthogonality_steps):
        if active.size == 0:
            break
        ya, xa = y[active], x[active]
        g = _gradient(phi, ya, eps)
        n = g / np.maximum(np.linalg.norm(g, axis=1, keepdims=True), 1e-300)
        r = xa - ya
        tangential = r - np.sum(r * n, axis=1, keepdims=True) * n
        z, good = newton(ya + tangential, 2)
        y[active] = z
        ok[active] &= good
        move = np.linalg.norm(z - ya, axis=1)
        active = active[(move > tol * max(1.0, float(np.max(np.abs(x))))) & good]
    ok[active] = False  # did not settle
    dist = np.linalg.norm(x - y, axis=1)
    signed = np.where(phix < 0, -dist, dist)
    return y, signed, ok


#: Finite-difference step for ∇φ of a sampled φ, in grid spacings.
SAMPLED_GRADIENT_STEP = 0.5

#: The most halvings of a Newton step of a callable φ that does not decrease |φ| (:func:`_damped`).
NEWTON_HALVINGS = 40


def _damped(
    phi: Callable[[np.ndarray], np.ndarray], y: np.ndarray, f: np.ndarray, step: np.ndarray, eps: float
) -> Tuple[np.ndarray, np.ndarray]:
    """``y − t·step`` and φ there (``step`` is changed), a damped Newton step: t = 1, halved (at
    most :data:`NEWTON_HALVINGS` times, else the point stays) where the step is longer than the
    gradient's step ``eps`` and |φ| does not fall by the Armijo fraction, ``|φ(y − t·step)| ≤
    (1 − 10⁻⁴ t)|φ(y)|``. A callable φ that flattens away from its zero level set
    (0.05·tanh(d/0.05)) has |∇φ| ≈ 0 a few spacings off, where a full step φ/|∇φ| leaps far
    across the surface, and a capped one can swing between two points of equal |φ|: the
    projection never settled, or settled on the node itself (distance 0), and the band was
    refused for sharp edges (a review). Near the surface Newton's steps decrease |φ| at once and
    are taken whole."""
    new = y - step
    fn = phi(new)
    t = np.ones(len(y))

    def short(i: np.ndarray) -> np.ndarray:
        with np.errstate(invalid="ignore"):
            return (~(np.abs(fn[i]) <= (1.0 - 1e-4 * t[i]) * np.abs(f[i]))) & (np.linalg.norm(step[i], axis=1) > eps)

    worse = np.flatnonzero(short(np.arange(len(y))))
    for _ in range(NEWTON_HALVINGS):
        if worse.size == 0:
            break
        step[worse] *= 0.5
        t[worse] *= 0.5
        new[worse] = y[worse] - step[worse]
        fn[worse] = phi(new[worse])
        worse = worse[short(worse)]
    new[worse], fn[worse] = y[worse], f[worse]
    return new, fn


def _project(
    surface, grid, x: np.ndarray, orthogonality_steps: int = ORTHOGONALITY_STEPS, max_step: Optional[float] = None
) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`project_to_level_set` of the points ``x`` (M, d) for the surface's φ: in Rust for a
    sampled φ (the same iterations and bits), in NumPy for a callable."""
    if surface.is_dense:
        return _native.project_to_sampled_level_set(
            _scaled_samples(surface),
            [float(c) for c in grid.lower],
            grid.spacing,
            np.ascontiguousarray(x, dtype=float),
            SAMPLED_GRADIENT_STEP * grid.spacing,
            NEWTON_STEPS,
            orthogonality_steps,
            SETTLED,
        )
    return project_to_level_set(
        lambda p: surface.phi(p, grid),
        x,
        GRADIENT_STEP * grid.spacing,
        orthogonality_steps=orthogonality_steps,
        tol=CALLABLE_SETTLED,
        max_step=max_step,
    )


#: :func:`estimate_lipschitz`'s bound over the largest |∇φ| it reads.
LIPSCHITZ_MARGIN = 1.25


def estimate_lipschitz(surface, grid, n: int = 17) -> float:
    """1.25 × the largest |∇φ| on an n^d lattice over the grid box (central differences; for an
    array, over all its nodes), at least 1e-12: the bound on |∇φ| that finds the candidate band
    of a re-distanced callable φ (an array's candidates use a bound near each node instead, see
    :func:`redistanced_band`)."""
    if surface.is_dense:
        # the largest |∇φ| of numpy.gradient over every node, in one pass with nothing stored
        return max(LIPSCHITZ_MARGIN * _native.max_gradient_norm_of_samples(surface._array, grid.spacing), 1e-12)
    axes = [np.linspace(lo, hi, n) for lo, hi in zip(grid.lower, grid.upper)]
    pts = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, grid.ndim)
    step = (grid.upper[0] - grid.lower[0]) / (n - 1) * 0.25
    try:
        g = _gradient(lambda p: surface.phi(p, grid), pts, step)
    except ValueError as e:
        if "returned NaN or inf" not in str(e):
            raise
        # (a φ undefined far from its surface was told "it must be finite near the surface" for a
        # point 8 spacings from it; a helper's review)
        raise ValueError(
            f"{str(e).split('; it must be')[0]}, while re-distancing looked for a bound on |∇φ| over the whole grid "
            f"box (a {n}^{grid.ndim} lattice): pass lipschitz= (a bound on |∇φ|, e.g. 1.5 for a distance) so that φ is "
            "evaluated near its surface only, or make φ finite over the box"
        ) from None
    return max(LIPSCHITZ_MARGIN * float(np.max(np.linalg.norm(g, axis=1))), 1e-12)


#: Passes of :func:`_narrowed_by_candidate_gradients`.
CANDIDATE_BOUND_PASSES = 2


def _narrowed_by_candidate_gradients(
    surface, grid, half_width: float, L: float, cand: np.ndarray, values: np.ndarray
) -> np.ndarray:
    """The candidates of a re-distanced callable φ, narrowed: ``L`` (1.25 × the largest |∇φ| on a
    lattice over the whole box) is replaced by 1.25 × the largest |∇φ| at the candidates
    themselves, which hold every node within ``half_width`` of the surface and so the segments
    from the band's nodes to their closest points; the candidates are kept where
    ``|φ| ≤ L·half_width`` with that bound, and the step repeated with the fewer candidates
    (:data:`CANDIDATE_BOUND_PASSES` in all, stopping when the bound does not fall). The same
    estimate as the whole box's, taken where the band is: for ``|x|² − r²`` the whole box's
    steepest part is its corners, several times the gradient at the surface."""
    from .band import EVAL_CHUNK

    fn = lambda p: surface.phi(p, grid)  # noqa: E731
    for _ in range(CANDIDATE_BOUND_PASSES):
        if cand.size == 0:
            break
        steepest = 0.0
        for lo in range(0, len(cand), EVAL_CHUNK):
            g = _gradient(fn, grid.node_points(cand[lo : lo + EVAL_CHUNK]), GRADIENT_STEP * grid.spacing)
            steepest = max(steepest, float(np.max(np.sum(g * g, axis=1))))
        near = max(1.25 * np.sqrt(steepest), 1e-12)
        if not near < L:
            break
        keep = np.abs(values) <= near * half_width
        cand, values, L = cand[keep], values[keep], near
    return cand


def _warn_if_band_nodes_unprojected(
    surface, grid, x: np.ndarray, cp: np.ndarray, ok: np.ndarray, half_width: float
) -> None:
    """Warns where candidates whose projection failed lie within the band for certain: their last
    iterate is on the zero level set (|φ| there below 1e-6 of |φ| at the node), so the node's
    distance is at most its distance to that point, and that is within ``half_width``. Such nodes
    are left out of the band (their closest point is not known), and band nodes that extend from
    them may stay unreached: that happens where the tube is about as wide as the surface's radius
    of curvature (a grid too coarse for the surface) or where the zero level set has a sharp edge
    or corner (the box's |x|_∞ − r), whose nodes never settle on one closest point."""
    failed = np.flatnonzero(~ok)
    if failed.size == 0:
        return
    within = _on_zero_set_within(surface, grid, x[failed], cp[failed], half_width)
    if np.any(within):
        warnings.warn(
            f"{int(np.count_nonzero(within))} nodes within the tube (at most {half_width:.3g} from the zero level set) "
            "could not be projected onto it (the closest-point iterations did not settle): they are left out of the "
            "band, and nodes beyond them may stay unreached (inf). Either the tube is about as wide as the surface's "
            "radius of curvature there (refine the grid), or φ's zero level set has a sharp edge or corner there "
            f"(smooth φ: refining does not help), e.g. near {tuple(round(float(c), 6) for c in x[failed][np.argmax(within)])}",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )


def _on_zero_set_within(surface, grid, x: np.ndarray, y: np.ndarray, reach: float) -> np.ndarray:
    """Where a point of the zero level set lies within ``reach`` of ``x``, found from the last
    iterate ``y`` of an unsettled projection by Newton steps alone (no orthogonality iterations):
    where the point they reach is on the zero level set (|φ| below 1e-6 of |φ(x)|) and within
    ``reach``, the distance of ``x`` from the surface is at most ``reach``."""
    if len(x) == 0:
        return np.zeros(0, bool)
    on, _, _ = _project(surface, grid, y, orthogonality_steps=0)
    with np.errstate(invalid="ignore"):
        on_surface = np.abs(surface.phi(on, grid)) <= 1e-6 * np.abs(surface.phi(x, grid))
    return on_surface & (np.linalg.norm(x - on, axis=1) <= reach)


#: Candidates of a callable φ on which :func:`_refuse_flat_callable` reads its slope (a sample).
FLAT_SAMPLE = 20000


def _refuse_flat_callable(surface, grid, cand: np.ndarray) -> None:
    """Refuses, before projecting, a callable φ whose slope nearly vanishes on its zero level set
    (φ = d³ or d·|d|): its slope at the candidates whose Newton distance |φ|/|∇φ| is within half a
    spacing, against those 1.5 to 2.5 spacings off (medians, over at most :data:`FLAT_SAMPLE`
    candidates), below :data:`FLAT_AT_SURFACE`. The projections crawl there: φ = (|x| − 0.5)³ at
    N = 41 took 36–40 s and 13,659 calls of φ, then was refused for "sharp edges or corners" (a
    helper's review), where an array of the same φ solves, with :func:`_warn_if_flat_at_surface`'s
    warning."""
    h = grid.spacing
    if cand.size < 16:
        return
    pick = cand if cand.size <= FLAT_SAMPLE else cand[np.linspace(0, cand.size - 1, FLAT_SAMPLE).astype(np.int64)]
    x = grid.node_points(pick)
    fn = lambda p: surface.phi(p, grid)  # noqa: E731
    with np.errstate(all="ignore"):
        value = np.abs(fn(x))
        slope = np.linalg.norm(_gradient(fn, x, GRADIENT_STEP * h), axis=1)
        newton = value / slope
    ok = np.isfinite(newton) & (slope > 0)
    near, far = slope[ok & (newton <= 0.5 * h)], slope[ok & (newton >= 1.5 * h) & (newton <= 2.5 * h)]
    if near.size < 8 or far.size < 8:
        return
    share = float(np.median(near) / np.median(far))
    if share >= FLAT_AT_SURFACE:
        return
    raise ValueError(
        f"surface: φ's slope nearly vanishes on its zero level set (|∇φ| there is {share:.2f} of its value a few "
        "spacings away, as for φ = d·|d| or d³): re-distancing a callable projects each node onto the zero level set "
        "along ∇φ, which crawls where the slope vanishes. Pass a φ whose slope does not vanish there (for φ = d³, "
        "np.cbrt(φ); for d·|d|, np.sign(φ)·np.sqrt(np.abs(φ))), or sample φ on the grid and pass the array, which "
        "LevelSet(phi_array, redistance=True) re-distances (with a warning: the surface is then placed to first "
        "order between the nodes)"
    )


def redistanced_band(surface, grid, half_width: float):
    """The band of ``LevelSet(phi, redistance=True)``.

    An array: :func:`_sampled_redistanced_band` (sub-cell interface points, from any φ with a sign
    change). A callable: candidates ``|φ| ≤ L·half_width`` (L a bound on |∇φ|, so every node within
    ``half_width`` of the surface is a candidate); then the exact signed distance by
    :func:`project_to_level_set`; keep ``|d| ≤ half_width``. L is the given bound or
    :func:`estimate_lipschitz`, and the candidates are found coarse-to-fine; without a given bound
    they are then narrowed by the gradient at the candidates themselves
    (:func:`_narrowed_by_candidate_gradients`)."""
    from .band import BandGeometry, discover_band

    d = grid.ndim
    if surface.is_dense:
        return _sampled_redistanced_band(surface, grid, half_width)
    L = surface.lipschitz if surface.lipschitz is not None else estimate_lipschitz(surface, grid)
    cand, values = discover_band(surface._fn, grid, L * half_width, L)
    if surface.lipschitz is None:
        cand = _narrowed_by_candidate_gradients(surface, grid, half_width, L, cand, values)
    if cand.size == 0:
        return BandGeometry(cand, np.zeros(0), np.zeros(0), np.zeros((0, d), np.float32))
    _refuse_flat_callable(surface, grid, cand)
    x = grid.node_points(cand)
    reach = 2.0 * half_width  # (no closest point of a band node is farther: longer Newton steps leap across)
    cp, signed, ok = _project(surface, grid, x, max_step=reach)
    # candidates that did not settle but lie near the band (their last iterate on the zero level
    # set within 1.5 half-widths): projected again with more steps (ORTHOGONALITY_RETRY_STEPS)
    unsettled = np.flatnonzero(~ok)
    retry = unsettled[_on_zero_set_within(surface, grid, x[unsettled], cp[unsettled], 1.5 * half_width)]
    if retry.size:
        cp[retry], signed[retry], ok[retry] = _project(surface, grid, x[retry], ORTHOGONALITY_RETRY_STEPS, reach)
    _warn_if_band_nodes_unprojected(surface, grid, x, cp, ok, half_width)
    keep = ok & (np.abs(signed) <= half_width * (1 + 1e-9))  # ties on the band edge: rounding
    lin, x, cp, signed = cand[keep], x[keep], cp[keep], signed[keep]
    diff = x - cp
    norm = np.abs(signed)
    good = norm > 1e-9 * grid.spacing
    direction = np.zeros((len(lin), d))
    direction[good] = diff[good] / norm[good, None]
    return BandGeometry(lin, norm, signed, direction.astype(np.float32), consumable=True)


#: The most refinement iterations per node of a sampled φ's re-distanced band
#: (``tubesweep_core::surface::redistance_band``): a node starts from a point of the zero level set
#: next to its closest point (its neighbour's), so smooth φ settles in a few.
REFINE_STEPS = 40

#: A node's closest point y has settled when the part of x − y along the zero level set at y, t,
#: is small: ``|t|² ≤ 2 · REFINE_SETTLED · Δx · |x − y|`` (``tubesweep_core::surface::redistance_band``;
#: then |x − y| is within REFINE_SETTLED · Δx of the distance to the tangent plane). The normal of the
#: iterations is that of the central differences, not exactly the zero set's, so the distance errs
#: linearly in |t|: 1e-12 keeps the band within 2e-7 Δx of the projection from the node (1e-9: 7e-6 Δx,
#: on the skewed sphere quadric at N = 41, ``tests/test_surfaces.py``).
REFINE_SETTLED = 1e-12


#: Re-distancing rescales a φ whose |values| next to its zero level set lie outside [2⁻ᴿ, 2ᴿ] (only
#: the zero level set matters): squares of differences of φ ≈ 1e±200 under- or overflow.
RESCALE_BEYOND = 60
#: ... and clips |φ| at 2^CLIP_BITS times those values: a single sample of 1e150 far from the
#: surface (a sentinel, a stray value) scaled the whole φ by 2⁻⁴⁹⁹, and the surface's samples, near
#: 1e-152, lost their precision (the largest error 4% instead of 0.95% at N = 41, unwarned; a
#: helper's review).
CLIP_BITS = 30


def _in_range(array: np.ndarray) -> np.ndarray:
    """``array`` scaled by a power of two (exactly: only the zero level set matters to the
    re-distancing) when its largest finite |value| next to the zero level set (at samples with a
    neighbour of the other sign, or anywhere where φ keeps one sign) lies outside [2⁻⁶⁰, 2⁶⁰], and
    its values clipped at ``2^CLIP_BITS`` times that (signs and zero set kept); else itself."""
    top = _straddling_magnitude(array)
    if top == 0.0:
        finite = np.abs(array[np.isfinite(array)])
        top = float(finite.max()) if finite.size else 0.0
    if top == 0.0:
        return array
    out = array
    if not 2.0**-RESCALE_BEYOND <= top <= 2.0**RESCALE_BEYOND:
        shift = int(np.frexp(top)[1])
        out, top = np.ldexp(array, -shift), float(np.ldexp(top, -shift))
    bound = float(np.ldexp(top, CLIP_BITS))
    with np.errstate(invalid="ignore"):
        if np.any(np.abs(out) > bound):
            out = np.clip(out, -bound, bound)
    return out


def _straddling_magnitude(array: np.ndarray) -> float:
    """The largest finite |φ| at the samples with a neighbour of the other sign along an axis (the
    samples on either side of the zero level set; 0 where there is none)."""
    top = 0.0
    negative = array < 0
    for k in range(array.ndim):
        lo = [slice(None)] * array.ndim
        hi = [slice(None)] * array.ndim
        lo[k], hi[k] = slice(None, -1), slice(1, None)
        a, b = array[tuple(lo)], array[tuple(hi)]
        change = negative[tuple(lo)] != negative[tuple(hi)]
        for side in (a[change], b[change]):
            side = np.abs(side[np.isfinite(side)])
            if side.size:
                top = max(top, float(side.max()))
    return top


def _scaled_samples(surface) -> np.ndarray:
    """The surface's samples :func:`_in_range`, kept on the surface for the projections that follow
    (keyed by the array, which a solve checks has not changed)."""
    array = surface._array
    kept = getattr(surface, "_in_range_samples", None)
    if kept is None or kept[0] is not array:
        kept = (array, _in_range(array))
        surface._in_range_samples = kept
    return kept[1]


def _refuse_zero_region(array: np.ndarray) -> None:
    """Refuses a φ that is 0 on a whole region (a sample whose neighbours along every axis are 0
    too): its zero level set is that region, not a surface. Of one sign, a 0/1 mask passed as φ
    (``(r > 0.5).astype(float)`` ran first order, 12% off, and the warning advised the
    ``redistance=True`` given already); changing sign, a φ rounded to a few values (``round(10·d)``
    is 0 on a shell two spacings thick: in ``ts.evolve`` the surface jumped by 9 times its law).
    A plane of zeros, φ = z on a grid with z = 0 nodes, has no such sample."""
    zero = array == 0
    interior = zero.copy()
    for axis in range(array.ndim):
        interior &= np.roll(zero, 1, axis) & np.roll(zero, -1, axis)
    count = int(np.count_nonzero(interior))
    if not count:
        return
    if array.min() < 0 < array.max():  # (NaN fails both: checked elsewhere)
        raise ValueError(
            f"phi is exactly 0 on a whole region between its negative and positive values ({count} samples inside it): "
            "its zero level set is that region, not a surface, as when φ is rounded to a few values. Pass φ at full "
            "precision (a signed distance or any function whose zero level set is the surface)"
        )
    raise ValueError(
        f"phi is {'≥' if not np.any(array < 0) else '≤'} 0 everywhere and exactly 0 on a whole region ({count} samples "
        "inside it): its zero level set is that region, not a surface. A 0/1 mask is given as "
        "ts.LevelSet.from_mask(mask, grid) (mask True inside); else pass φ < 0 inside and > 0 outside"
    )


def _sampled_redistanced_band(surface, grid, half_width: float):
    """The re-distanced band of a sampled φ, from any φ whose zero level set crosses the grid:
    sub-cell interface points on the edges of the cells with a sign change, closest points carried
    from them layer by layer through the band and refined on the multilinear interpolant, in Rust
    (``tubesweep_core::surface::redistance_band``). Where φ is smooth the closest points are those of
    :func:`project_to_level_set` from the node (the same iterations and fixed point, to the settling
    tolerance); unlike it, no step reads ∇φ away from the zero level set, so masks, plateaus and φ
    far from a distance work too."""
    from .band import BandGeometry

    _refuse_zero_region(surface._array)
    samples = _scaled_samples(surface)
    linear, signed, direction, crossed, _, medial = _native.redistanced_band_of_samples(
        samples,
        [float(c) for c in grid.lower],
        grid.spacing,
        float(half_width),
        SAMPLED_GRADIENT_STEP * grid.spacing,
        REFINE_STEPS,
        REFINE_SETTLED,
    )
    if crossed == 0:
        raise ValueError(
            "phi has no sign change on the grid (every sample is "
            + ("> 0" if np.min(surface._array) > 0 else "≤ 0")
            + "), so its zero level set does not cross the grid and there is no surface to re-distance: pass a φ that "
            "is negative inside the surface and positive outside, on a grid that holds the surface"
        )
    if medial:
        warnings.warn(
            f"{medial} nodes within {0.5 * half_width:.3g} of the zero level set lie near points "
            "equidistant from two parts of it (their neighbours' closest points are more than 5 grid spacings apart): "
            "the tube is about as wide as the surface's radius of curvature there, or two sheets of the surface face "
            "each other within the tube; the travel times there may be wrong. Refine the grid",
            RuntimeWarning,
            stacklevel=user_stacklevel(),
        )
    _warn_if_flat_at_surface(samples, grid, np.ascontiguousarray(linear.view(np.int64)), signed)
    return BandGeometry(linear.view(np.int64), None, signed, direction, consumable=True)


#: φ's slope at its zero level set, as a share of its slope two spacings away, below which the
#: surface is placed only to first order between the nodes: φ = d·|d| reads 0.125 and φ = d³ 0.09
#: by central differences (a distance 1, a smoothed mask's step more); the circle R = 0.5
#: re-distanced from d³ came out 0.17, 0.89, 2.1Δx off at N = 101, 201, 401 (from d: 1e-3Δx)
FLAT_AT_SURFACE = 0.5


def _warn_if_flat_at_surface(array: np.ndarray, grid, linear: np.ndarray, signed: np.ndarray) -> None:
    """A RuntimeWarning when φ's slope (central differences of the samples ``array``) at the band nodes
    within half a spacing of its zero level set is under :data:`FLAT_AT_SURFACE` of its slope at
    those 1.5 to 2.5 spacings away (medians): the multilinear interpolant then places the zero
    level set between the nodes only to first order."""
    h = grid.spacing
    away = np.abs(signed)
    near, far = linear[away <= 0.5 * h], linear[(away >= 1.5 * h) & (away <= 2.5 * h)]
    if near.size < 8 or far.size < 8:
        return

    def slope(at: np.ndarray) -> float:
        # central differences of the samples, as the band's own directions take them
        # (one-sided at the grid's faces)
        scratch = np.empty((at.size, grid.ndim), np.float32)
        return float(np.median(_native.outward_directions_of_samples(array, h, at.view(np.uint64), scratch)))

    at_surface, beyond = slope(near), slope(far)
    if not (beyond > 0 and at_surface < FLAT_AT_SURFACE * beyond):
        return
    warnings.warn(
        f"φ's slope nearly vanishes on its zero level set (|∇φ| there is {at_surface / beyond:.2f} of its value two "
        "spacings away, as for φ = d·|d| or d³): interpolated between the nodes, the surface lies a fraction of a grid "
        "spacing off, so the distances stay first order in Δx whatever the order of the solve. Pass a φ whose slope "
        "does not vanish there (for φ = d³, np.cbrt(φ); for d·|d|, np.sign(φ)·np.sqrt(np.abs(φ)))",
        RuntimeWarning,
        stacklevel=user_stacklevel(),
    )


#: A projection that did not settle still reached the zero level set when it moved and φ at its
#: end is below this share of φ at its start (near a crease only the orthogonality iterations fail
#: to settle: the cube's re-distanced φ within half a spacing of its surface, at most 0.24).
REACHED = 0.5

#: Where the projection stalls on a sampled φ (its slope zero: a voxel mask's plateau more than a
#: voxel from its edge), the zero level set is looked for among the sign changes within this many
#: cells of the point.
CROSSING_REACH = 4


def redistanced_project(surface, points: np.ndarray, grid):
    """Unsigned distance and closest points of ``points`` on the zero level set of φ. Where the
    projection did not reach it — ∇φ vanished on the way, as at a ball's centre, or Newton's steps
    on a voxel mask's plateaus went back and forth between two nodes and ended where they started
    (settled, at φ = ±½: a point 0.6 spacings off a ball's mask was placed 6.4 spacings away, and
    a fifth of the nodes next to it at distance 0 on themselves; a helper's review) — the closest
    point and distance are those of the nearest of a sampled φ's sign changes within
    :data:`CROSSING_REACH` cells (:func:`_nearest_crossing`); where there is none, or for a
    callable φ, the distance is +∞ (a source there was taken for one on the surface, 0 from it)
    and the closest point stays where the projection ended. A projection reached the zero level
    set when φ at its end is below :data:`REACHED` of φ at its start (next to a crease only the
    orthogonality iterations fail to settle), or at the round-off of the sampled φ."""
    x = np.asarray(points, dtype=float)
    cp, signed, converged = _project(surface, grid, x)
    distance = np.abs(signed)
    # a callable φ is smooth: only its projections that did not settle are looked at
    check = np.arange(len(x)) if surface.is_dense else np.flatnonzero(~np.asarray(converged, dtype=bool))
    start = np.abs(surface.phi(x[check], grid))
    end = np.abs(surface.phi(cp[check], grid))
    round_off = 1e-12 * _sample_scale(surface) if surface.is_dense else 0.0
    moved = np.any(cp[check] != x[check], axis=1)
    reached = np.ones(len(x), dtype=bool)
    reached[check] = (end <= round_off) | (moved & (end <= REACHED * start))
    for i in np.flatnonzero(~reached):
        crossing = _nearest_crossing(surface, grid, x[i]) if surface.is_dense else None
        if crossing is None:
            distance[i] = np.inf
        else:
            distance[i], cp[i] = crossing
    if surface.is_dense:
        # a step from where a mask's plateau begins is long (its slope small) and can land on the
        # zero level set far away (a point 0.6 spacings off a ball's mask, 19.6 spacings): beyond a
        # spacing, the nearest sign change is taken where it is nearer
        for i in np.flatnonzero(reached & (distance > grid.spacing)):
            crossing = _nearest_crossing(surface, grid, x[i])
            if crossing is not None and crossing[0] < distance[i]:
                distance[i], cp[i] = crossing
    return distance, cp


def _sample_scale(surface) -> float:
    """The largest |φ| of a sampled φ (kept on the surface, keyed by the array as
    :func:`_scaled_samples`): the scale of its round-off."""
    array = surface._array
    kept = getattr(surface, "_sample_scale", None)
    if kept is None or kept[0] is not array:
        kept = (array, float(np.max(np.abs(array), initial=0.0)))
        surface._sample_scale = kept
    return kept[1]


def _nearest_crossing(surface, grid, x: np.ndarray) -> Optional[Tuple[float, np.ndarray]]:
    """The distance from ``x`` to the nearest point of the zero level set on a sampled φ's edges
    within :data:`CROSSING_REACH` cells (linear along each grid edge whose ends differ in sign),
    and that point; None when there is none."""
    array = surface._array
    h = grid.spacing
    centre = np.rint(grid.continuous_index(x[None])[0]).astype(np.int64)
    lo = np.maximum(centre - CROSSING_REACH, 0)
    hi = np.minimum(centre + CROSSING_REACH + 1, np.asarray(array.shape))
    if np.any(hi <= lo):
        return None
    block = array[tuple(slice(a, b) for a, b in zip(lo, hi))]
    origin = np.asarray(grid.lower, dtype=float) + lo * h
    best: Optional[Tuple[float, np.ndarray]] = None
    for k in range(block.ndim):
        a = np.take(block, np.arange(block.shape[k] - 1), axis=k)
        b = np.take(block, np.arange(1, block.shape[k]), axis=k)
        crossing = (a < 0) != (b < 0)
        if not np.any(crossing):
            continue
        idx = np.argwhere(crossing)
        t = a[crossing] / (a[crossing] - b[crossing])
        pts = origin + idx * h
        pts[:, k] += t * h
        d = np.linalg.norm(pts - x, axis=1)
        j = int(np.argmin(d))
        if best is None or d[j] < best[0]:
            best = (float(d[j]), pts[j])
    return best
