"""Type stubs of the compiled core (private; use the tubesweep package)."""

from typing import Any, Callable, Dict, List, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

DEFAULT_INFINITY: float

def split_pair_blocks(shape: List[int], origins: npt.NDArray[np.int64]) -> npt.NDArray[np.uint64]: ...
def children_radius_max(shape: List[int], parents: npt.NDArray[np.int64], block: int) -> float: ...
def block_children(
    shape: List[int], parents: npt.NDArray[np.int64], block: int, lower: List[float], spacing: float
) -> Tuple[npt.NDArray[np.int64], npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def node_points(
    shape: List[int], linear: npt.NDArray[np.uint64], lower: List[float], spacing: float
) -> npt.NDArray[np.float64]: ...
def keep_within(
    linear: npt.NDArray[np.uint64],
    values: npt.NDArray[np.float64],
    half_width: float,
    linear_out: npt.NDArray[np.uint64],  # written from the front
    values_out: npt.NDArray[np.float64],  # written from the front
) -> int: ...
def first_non_finite(phi: npt.NDArray[np.float64]) -> Optional[int]: ...  # C order, C-contiguous
def band_of_samples(
    phi: npt.NDArray[np.float64],
    half_width: float,  # φ at every grid node, C-contiguous
) -> Tuple[npt.NDArray[np.uint64], npt.NDArray[np.float64]]: ...
def max_gradient_norm_of_samples(phi: npt.NDArray[np.float64], spacing: float) -> float: ...
def redistance_candidates_of_samples(
    phi: npt.NDArray[np.float64], spacing: float, half_width: float
) -> Tuple[npt.NDArray[np.uint64], npt.NDArray[np.float64]]: ...
def project_to_sampled_level_set(
    phi: npt.NDArray[np.float64],  # φ at every grid node, C-contiguous
    lower: List[float],
    spacing: float,
    points: npt.NDArray[np.float64],  # (M, d)
    eps: float,
    newton_steps: int,
    orthogonality_steps: int,
    tol: float,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.bool_]]: ...
def redistanced_band_of_samples(
    phi: npt.NDArray[np.float64],  # φ at every grid node, C-contiguous
    lower: List[float],
    spacing: float,
    half_width: float,
    eps: float,
    max_steps: int,
    tol: float,
) -> Tuple[npt.NDArray[np.uint64], npt.NDArray[np.float64], npt.NDArray[np.float32], int, int, int]: ...
def analytic_level_set_band(
    kind: str,  # "sphere", "torus", "ellipsoid", "star", "rounded-cube" or "double-torus"
    parameters: List[float],
    shape: List[int],
    lower: List[float],
    spacing: float,
    half_width: float,
    lipschitz: float,
) -> Tuple[
    npt.NDArray[np.uint64], npt.NDArray[np.float64], Optional["Band"], npt.NDArray[np.float32], npt.NDArray[np.float32]
]: ...
def outward_directions_of_samples(
    phi: npt.NDArray[np.float64],
    spacing: float,
    linear: npt.NDArray[np.uint64],
    direction: npt.NDArray[np.float32],  # (len(linear), d), written
) -> npt.NDArray[np.float64]: ...
def neighbour_table(
    shape: List[int], linear: npt.NDArray[np.uint64], start: int, stop: int
) -> npt.NDArray[np.int32]: ...  # (2·(d − 1), stop − start)
def rim_nodes(
    shape: List[int],
    linear: npt.NDArray[np.uint64],
    start: int,
    stop: int,
    neighbours: Optional[npt.NDArray[np.int32]] = None,
) -> Tuple[npt.NDArray[np.int64], List[int]]: ...
def outward_directions(
    shape: List[int],
    spacing: float,
    linear: npt.NDArray[np.uint64],
    phi: npt.NDArray[np.float64],
    start: int,
    stop: int,
    rim_phi: npt.NDArray[np.float64],
    direction: npt.NDArray[np.float32],  # (stop − start, d) C-contiguous, written
    neighbours: Optional[npt.NDArray[np.int32]] = None,  # neighbour_table(shape, linear, start, stop)
) -> npt.NDArray[np.float64]: ...
def row_prefetch_above() -> (
    int
): ...  # bytes of an iteration's rows above which the next prefetches its rows (a share of the last-level cache)
def sphere_signed_distance(
    points: npt.NDArray[np.float64], centre: List[float], radius: float
) -> npt.NDArray[np.float64]: ...
def torus_signed_distance(
    points: npt.NDArray[np.float64], centre: List[float], major: float, minor: float
) -> npt.NDArray[np.float64]: ...
def ellipsoid_signed_distance(
    points: npt.NDArray[np.float64], centre: List[float], axes: List[float]
) -> npt.NDArray[np.float64]: ...
def star_signed_distance(points: npt.NDArray[np.float64], r0: float, eps: float) -> npt.NDArray[np.float64]: ...
def mesh_vertex_parts(n_vertices: int, faces: npt.NDArray[np.int64]) -> npt.NDArray[np.int64]: ...
def solve_many_on_band(  # crates/tubesweep-py/src/many_sources.rs: K solves, in parallel across the sources
    band: "Band",
    roles: npt.NDArray[np.uint8],  # (n,) without fixed nodes
    fixed_positions: npt.NDArray[np.int64],  # the sources' fixed nodes, concatenated
    fixed_values: npt.NDArray[np.float64],
    offsets: npt.NDArray[np.int64],  # (K + 1,) source k's run is offsets[k]:offsets[k + 1]
    spacing: float,
    slowness: Union[float, npt.NDArray[np.float64]],
    directions: Optional[npt.NDArray[np.float32]],  # (n, d) C-contiguous; overwritten with the extension weights
    scheme: str,
    missing: str,
    tol: float,
    max_iterations: int,
    infinity: Optional[float],
    progress: Optional[Callable[[int, int], Any]] = None,  # (done, K)
    threads: int = 0,  # solves at once, each on one thread
    activation_threshold: float = 0.0,
    coupled: bool = True,
    defer_outer_rim: bool = True,
    front_window: float = 0.0,
    at: Optional[npt.NDArray[np.float64]] = None,  # (M, d): return the values there, (K, M)
    lower: Optional[List[float]] = None,  # the grid's lower corner, with `at`
) -> Tuple[npt.NDArray[np.float64], Dict[str, npt.NDArray[Any]]]: ...
def factored_box_solve(  # crates/tubesweep-py/src/box_order2.rs: travel_time(..., order=2)
    shape: List[int],
    lower: List[float],
    spacing: float,
    slowness: Union[float, npt.NDArray[np.float64]],  # a float or one per node (C order)
    sources: npt.NDArray[np.float64],  # (K, d)
    source_slowness: npt.NDArray[np.float64],  # (K,)
    fixed_nodes: npt.NDArray[np.int64],  # linear indices
    fixed_values: npt.NDArray[np.float64],
    tol: float,
    max_iterations: int,
    second_order: bool = True,
    ramp_length: float = 1.0,
    threads: int = 0,
    progress: Optional[Callable[[int, float, int], Any]] = None,
    activation_threshold: float = 0.0,
) -> Tuple[npt.NDArray[np.float64], Dict[str, Any]]: ...
def second_order_solve(  # crates/tubesweep-py/src/second_order.rs: solve(..., order=2) on a band
    band: "Band",
    roles: npt.NDArray[np.uint8],
    phi: npt.NDArray[np.float64],
    directions: npt.NDArray[np.float32],  # (K, d)
    lower: List[float],
    spacing: float,
    sources: npt.NDArray[np.float64],  # (S, d) foot points
    source_slowness: npt.NDArray[np.float64],  # (S,)
    slowness: Union[float, npt.NDArray[np.float64]],  # a float or one per band node
    fix_radius: float,
    outer_width: float,
    tol_first: float,
    tol: float,
    max_iterations: int,
    progress: Optional[Callable[[int, float, int], Any]] = None,
    stall_ratio: float = 0.98,
    stall_window: int = 10,
    threads: int = 0,
    front_window: float = 2.0,
    own_first_phase: bool = False,
    offsets: Optional[npt.NDArray[np.float64]] = None,  # (K, d) x − cp(x) for a closest-point surface
    window_first: float = 0.0,  # front windows of the two phases (factors of the first-order width)
    window_second: float = 0.0,
    ramp_length: float = 1.0,  # ℓ: the limiter's ramp width is σΔx²/ℓ (second_order.ramp_length)
    extension_limit: float = ...,  # the extension's BDF2 correction limited beyond this many σΔx (default ∞)
    warm: Optional[npt.NDArray[np.float64]] = None,  # a warm start: the previous values on this band (moving.rs)
    warm_older: Optional[npt.NDArray[np.float64]] = None,  # the values before those (a start extrapolated in time)
    warm_previous_linear: Optional[npt.NDArray[np.uint64]] = None,  # the previous band's grid positions
    warm_previous_digests: Optional[npt.NDArray[np.uint64]] = None,  # and its nodes' digests (st["digests"])
    keep_digests: bool = False,  # return this solve's digests in st["digests"] (8 bytes per node)
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.uint8], Dict[str, Any]]: ...
def carry_band_values(  # crates/tubesweep-py/src/moving.rs: previous values onto a new band (+inf where new)
    old_linear: npt.NDArray[np.uint64], old_values: npt.NDArray[np.float64], new_linear: npt.NDArray[np.uint64]
) -> npt.NDArray[np.float64]: ...
def band_component_labels(
    band: Band, select: npt.NDArray[np.bool_]
) -> npt.NDArray[np.uint32]: ...  # moving.rs: each node's component
def second_order_solve_many(  # crates/tubesweep-py/src/many_sources.rs: K second-order solves, the geometry shared
    band: "Band",
    roles: npt.NDArray[np.uint8],
    phi: npt.NDArray[np.float64],
    directions: npt.NDArray[np.float32],
    lower: List[float],
    spacing: float,
    feet: npt.NDArray[np.float64],  # (P, d) every source's foot points, concatenated
    source_slowness: npt.NDArray[np.float64],  # (P,)
    offsets: npt.NDArray[np.int64],  # (K + 1,) source k is feet[offsets[k]:offsets[k + 1]]
    slowness: Union[float, npt.NDArray[np.float64]],
    fix_radius: float,
    outer_width: float,
    tol_first: float,
    tol: float,
    max_iterations: int,
    progress: Optional[Callable[[int, int], Any]] = None,  # (done, K)
    threads: int = 0,
    front_window: float = 2.0,
    own_first_phase: bool = True,
    cp_offsets: Optional[npt.NDArray[np.float64]] = None,
    window_first: float = 0.0,
    window_second: float = 0.0,
    ramp_length: float = 1.0,
    extension_limit: float = ...,
    stall_ratio: float = 0.98,
    stall_window: int = 20,
    at: Optional[npt.NDArray[np.float64]] = None,  # (M, d)
    at_feet: Optional[npt.NDArray[np.float64]] = None,  # (M, d) their feet on the surface
    reach_spacings: float = 3.0,
    reach_curvature_radii: float = 0.0,
) -> Tuple[npt.NDArray[np.float64], Dict[str, Any]]: ...
def source_feet_within(  # crates/tubesweep-py/src/second_order.rs: points within reach of a source (kd-tree)
    feet: npt.NDArray[np.float64], slowness: npt.NDArray[np.float64], points: npt.NDArray[np.float64], reach: float
) -> npt.NDArray[np.bool_]: ...
def source_feet_chords(  # the smallest σ_s |p − x_s| per point
    feet: npt.NDArray[np.float64], slowness: npt.NDArray[np.float64], points: npt.NDArray[np.float64]
) -> npt.NDArray[np.float64]: ...
def nearest_feet(  # the nearest foot per point
    feet: npt.NDArray[np.float64], points: npt.NDArray[np.float64]
) -> npt.NDArray[np.int64]: ...
def band_interpolate_cubic(  # crates/tubesweep-py/src/box_order2.rs: Catmull-Rom, multilinear where incomplete
    band: "Band", values: npt.NDArray[np.float64], lower: List[float], spacing: float, points: npt.NDArray[np.float64]
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.bool_]]: ...
def rounded_cube_signed_distance(
    points: npt.NDArray[np.float64], centre: List[float], half_size: float, radius: float
) -> npt.NDArray[np.float64]: ...
def double_torus_signed_distance(
    points: npt.NDArray[np.float64], major: float, minor: float, offset: float
) -> npt.NDArray[np.float64]: ...
def mobius_closest_parameters(
    points: npt.NDArray[np.float64], r: float, w: float, iterations: int
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def open_surface_closest_points(
    kind: str, points: npt.NDArray[np.float64], centre: List[float], size: float
) -> npt.NDArray[np.float64]: ...

__version__: str

class Band:
    @staticmethod
    def from_linear(shape: List[int], linear: npt.NDArray[np.uint64]) -> "Band": ...
    @staticmethod
    def full_box(shape: List[int]) -> "Band": ...
    def __len__(self) -> int: ...
    @property
    def ndim(self) -> int: ...
    @property
    def n_rows(self) -> int: ...
    @property
    def nbytes(self) -> int: ...
    def linear(self) -> npt.NDArray[np.int64]: ...
    def indices(self) -> npt.NDArray[np.int64]: ...
    def neighbours(self) -> npt.NDArray[np.int64]: ...
    def rim_nodes(self, start: int, stop: int) -> Tuple[npt.NDArray[np.int64], List[int]]: ...
    def outward_directions(
        self,
        spacing: float,
        phi: npt.NDArray[np.float64],
        start: int,
        stop: int,
        rim_phi: npt.NDArray[np.float64],
        direction: npt.NDArray[np.float32],  # (stop − start, d) C-contiguous, written
    ) -> npt.NDArray[np.float64]: ...
    def find(self, indices: npt.NDArray[np.int64]) -> npt.NDArray[np.int64]: ...
    def nodes_missing_neighbours(self, select: npt.NDArray[np.bool_]) -> npt.NDArray[np.int64]: ...
    def facing_sheet_pairs(
        self,
        inner: npt.NDArray[np.bool_],
        phi: npt.NDArray[np.float32],
        direction: npt.NDArray[np.float32],  # (K, d) C-contiguous
        spacing: float,
    ) -> Tuple[npt.NDArray[np.int64], npt.NDArray[np.int64], npt.NDArray[np.float64]]: ...
    def across_candidates(
        self,
        inner: npt.NDArray[np.bool_],
        phi: npt.NDArray[np.float32],  # unsigned
        direction: npt.NDArray[np.float32],  # (K, d) C-contiguous
        spacing: float,
    ) -> npt.NDArray[np.int64]: ...
    def neighbours_of_nodes(self, positions: npt.NDArray[np.int64]) -> npt.NDArray[np.int64]: ...
    def smoothed_turning(
        self, phi: npt.NDArray[np.float64], spacing: float, passes: int, reach: int, near: float
    ) -> Tuple[npt.NDArray[np.int64], npt.NDArray[np.float64]]: ...
    def smoothed_creases(
        self,
        phi: npt.NDArray[np.float64],
        spacing: float,
        passes: int,
        reach: int,
        near: float,
        turn: float,
        turn_concave: float,
        min_concave_nodes: int,
        face: float,
        sheets: float,
        percentile: float,
    ) -> Tuple[int, float, float]: ...
    def crease_ridge_nodes(
        self,
        inner: npt.NDArray[np.bool_],
        phi: npt.NDArray[np.float32],
        direction: npt.NDArray[np.float32],  # (K, d) C-contiguous
        spacing: float,
    ) -> npt.NDArray[np.int64]: ...
    def creases_of_level_set(
        self,
        inner: npt.NDArray[np.bool_],
        phi: npt.NDArray[np.float32],
        direction: npt.NDArray[np.float32],  # (K, d) C-contiguous
        spacing: float,
    ) -> Tuple[int, float]: ...
    def creases_of_redistanced(  # the second-order geometry's crease test, for order=1 on a re-distanced φ
        self,
        roles: npt.NDArray[np.uint8],
        phi: npt.NDArray[np.float64],
        direction: npt.NDArray[np.float32],  # (K, d) C-contiguous
        spacing: float,
        outer_width: float,
    ) -> Tuple[int, float, bool, float]: ...
    def medial_edges(
        self,
        inner: npt.NDArray[np.bool_],
        phi: npt.NDArray[np.float32],
        direction: npt.NDArray[np.float32],  # (K, d) C-contiguous
        spacing: float,
        jump: float,
    ) -> Tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]: ...
    def with_edges_cut(self, node: npt.NDArray[np.int64], neighbour: npt.NDArray[np.int64]) -> Tuple["Band", int]: ...
    def interpolate(
        self, values: npt.NDArray[np.float64], lower: List[float], spacing: float, points: npt.NDArray[np.float64]
    ) -> npt.NDArray[np.float64]: ...
    def nearest_source_labels(
        self,
        values: npt.NDArray[np.float64],
        fixed_positions: npt.NDArray[np.int64],
        fixed_labels: npt.NDArray[np.int64],
    ) -> npt.NDArray[np.int64]: ...
    def solve(
        self,
        roles: npt.NDArray[np.uint8],
        fixed_positions: npt.NDArray[np.int64],  # (F,) band positions of the fixed nodes
        fixed_values: npt.NDArray[np.float64],  # (F,) their values (a fixed node not listed starts from 0)
        spacing: float,
        slowness: Union[float, npt.NDArray[np.float64]],
        directions: Optional[npt.NDArray[np.float32]],  # (K, d) C-contiguous; overwritten with the extension weights
        scheme: str,
        missing: str,
        tol: float,
        max_iterations: int,
        infinity: Optional[float],
        progress: Optional[Callable[[int, float, int], Any]] = None,
        threads: int = 0,
        skip_inactive: bool = True,
        activation_threshold: float = 0.0,
        coupled: bool = True,
        defer_outer_rim: bool = True,
        front_window: float = 0.0,  # Godunov on 3D bands: sweep behind a front window front_window·h·s̄·sqrt(H) wide; 0: off
    ) -> Tuple[npt.NDArray[np.float64], Dict[str, Any]]: ...
    def solve_general(
        self,
        roles: npt.NDArray[np.uint8],
        fixed_positions: npt.NDArray[np.int64],  # (F,) band positions of the fixed nodes
        fixed_values: npt.NDArray[np.float64],  # (F,) their values (a fixed node not listed starts from 0)
        spacing: float,
        hamiltonian: str,
        slowness: npt.NDArray[np.float64],
        directions: Optional[npt.NDArray[np.float32]],  # (K, d) C-contiguous; overwritten with the extension weights
        missing: str,
        tol: float,
        max_iterations: int,
        infinity: Optional[float],
        flow: Optional[npt.NDArray[np.float64]] = None,
        metric: Optional[npt.NDArray[np.float64]] = None,
        sigma: Optional[npt.NDArray[np.float64]] = None,
        progress: Optional[Callable[[int, float, int], Any]] = None,
        threads: int = 0,
        skip_inactive: bool = True,
        activation_threshold: float = 0.0,
        defer_outer_rim: bool = True,
        scheme: str = "lxf",  # "godunov": the upwind local solver (tubesweep_core::scheme::upwind); "lxf": Sect. 5.1
    ) -> Tuple[npt.NDArray[np.float64], Dict[str, Any]]: ...

class PointCloud:
    """A point cloud's kd-tree and moving-least-squares closest points (Rust core)."""

    def __init__(self, points: npt.NDArray[np.float64], neighbours: int) -> None: ...
    def __len__(self) -> int: ...
    @property
    def reach(self) -> float: ...
    @property
    def rim(self) -> npt.NDArray[np.bool_]: ...
    def analyse(
        self,
        bridge: Optional[float] = None,
    ) -> Tuple[
        npt.NDArray[np.float64],
        npt.NDArray[np.float64],
        npt.NDArray[np.float64],
        npt.NDArray[np.float64],
        npt.NDArray[np.uint32],
    ]: ...
    def nearest_samples(self, which: npt.NDArray[np.int64], k: int) -> npt.NDArray[np.uint32]: ...
    def set_noise(self, noise: float) -> None: ...
    def mark_rim(self, gap: npt.NDArray[np.float64]) -> int: ...
    def isolated(
        self,
        spacing: npt.NDArray[np.float64],
        radius: npt.NDArray[np.float64],
        median_radius: float,
        min_size: int,
    ) -> npt.NDArray[np.bool_]: ...
    def closest(
        self, points: npt.NDArray[np.float64], rho: float = 0.0, trust: float = 0.0
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint8]]: ...
    def lower_bounds(self, points: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]: ...

class SmoothMesh:
    """The smooth closest-point map of a triangle mesh (Rust core, surface/mesh_smooth.rs)."""

    def __init__(
        self, vertices: npt.NDArray[np.float64], faces: npt.NDArray[np.int64], neighbours: int, spacing: float
    ) -> None: ...
    @property
    def oriented(self) -> bool: ...
    @property
    def boundary_edges(self) -> int: ...
    def closest(
        self, points: npt.NDArray[np.float64], h: float, max_distance: float = ..., mode: str = "auto"
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint8]]: ...

class TriangleTree:
    """Exact closest points on a triangle mesh (AABB tree of the Rust core)."""

    def __init__(self, vertices: npt.NDArray[np.float64], faces: npt.NDArray[np.int64]) -> None: ...
    def __len__(self) -> int: ...
    @property
    def nbytes(self) -> int: ...
    def closest(
        self, points: npt.NDArray[np.float64], max_distance: float
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.int64], npt.NDArray[np.uint8]]: ...
    def any_within(
        self, points: npt.NDArray[np.float64], thresholds: npt.NDArray[np.float64]
    ) -> npt.NDArray[np.bool_]: ...
    def band(
        self,
        points: npt.NDArray[np.float64],
        half_width: float,
        on_surface: float,
        face_normals: npt.NDArray[np.float64],
        pseudo_normals: Optional[npt.NDArray[np.float64]],
    ) -> Tuple[npt.NDArray[np.uint32], npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float32]]: ...
