"""Hostile inputs, group 7: the private native module given garbage (negative, empty, out-of-range and
mis-shaped arguments): a clean exception out, no panic.
"""

from hostile.framework import case

# ------------------------------------------------------------------------------------------------
# 7. the private native module: garbage in, a clean exception out (no panic)
# ------------------------------------------------------------------------------------------------
native_calls = [
    "N.Band.full_box([-1, 5])",
    "N.Band.full_box([])",
    "N.Band.full_box(None)",
    "N.Band.full_box(['a', 'b'])",
    "N.Band.from_linear([5, 5], np.array([3, 1], np.uint64))",
    "N.Band.from_linear([5, 5], np.array([0, 100], np.uint64))",
    "N.Band.from_linear([5, 5], np.zeros((2, 2), np.uint64))",
    "N.Band.from_linear([5, 5], np.array([0.5]))",
    "N.node_points([5, 5], np.array([0], np.uint64), [0.0], 1.0)",
    "N.node_points([5, 5], np.array([99], np.uint64), [0.0, 0.0], 1.0)",
    "N.node_points([5, 5], np.array([0], np.uint64), [0.0, 0.0], float('nan'))",
    "N.split_pair_blocks([5, 5, 5], -np.ones((1, 3), np.int64))",
    "N.split_pair_blocks([5, 5, 5], np.zeros((1, 2), np.int64))",
    "N.block_children([5, 5, 5], np.zeros((1, 3), np.int64), 0, [0.0] * 3, 1.0)",
    "N.block_children([5, 5, 5], np.zeros((1, 3), np.int64), 2**62, [0.0] * 3, 1.0)",
    "N.children_radius_max([5, 5, 5], np.zeros((1, 3), np.int64), 0)",
    "N.neighbour_table([5, 5], np.array([0, 1], np.uint64), 0, 100)",
    "N.neighbour_table([5, 5], np.array([0, 1], np.uint64), 2, 1)",
    "N.band_of_samples(np.zeros((5, 5)), float('nan'))",
    "N.band_of_samples(np.zeros(5), 1.0)",
    "N.band_of_samples(np.zeros((2, 2)), 1.0)",
    "N.band_of_samples(np.zeros((5, 5, 5, 5)), 1.0)",
    "N.keep_within(np.arange(10, dtype=np.uint64), np.zeros(10), 1.0, np.zeros(2, np.uint64), np.zeros(2))",
    "N.keep_within(np.arange(10, dtype=np.uint64), np.zeros(3), 1.0, np.zeros(10, np.uint64), np.zeros(10))",
    "N.TriangleTree(np.zeros((3, 3)), np.array([[0, 1, 5]]))",
    "N.TriangleTree(np.zeros((0, 3)), np.zeros((0, 3), np.int64))",
    "N.TriangleTree(np.zeros((3, 2)), np.array([[0, 1, 2]]))",
    "N.TriangleTree(np.zeros((3, 3)), np.array([[0, 1, -1]]))",
    "N.TriangleTree(np.eye(3), np.array([[0, 1, 2]])).closest(np.zeros((2, 2)), 1.0)",
    "N.TriangleTree(np.eye(3), np.array([[0, 1, 2]])).closest(np.full((2, 3), np.nan), 1.0)",
    "N.TriangleTree(np.eye(3), np.array([[0, 1, 2]])).any_within(np.zeros((2, 3)), np.zeros(5))",
    "N.analytic_level_set_band('blob', [0.5], [5] * 3, [-1.0] * 3, 0.5, 1.0, 1.5)",
    "N.analytic_level_set_band('sphere', [], [5] * 3, [-1.0] * 3, 0.5, 1.0, 1.5)",
    "N.analytic_level_set_band('sphere', [0, 0, 0, 0.5], [5] * 3, [-1.0] * 3, 0.0, 1.0, 1.5)",
    "N.analytic_level_set_band('sphere', [0, 0, 0, 0.5], [5] * 3, [-1.0] * 3, 0.5, float('nan'), 1.5)",
    "N.sphere_signed_distance(np.zeros((2, 2)), [0.0] * 3, 0.5)",
    "N.sphere_signed_distance(np.zeros((2, 3)), [0.0], 0.5)",
    "N.first_non_finite(np.zeros(0))",
    "N.project_to_sampled_level_set(np.zeros((5, 5)), [0.0, 0.0], 0.1, np.zeros((2, 2)))",
    "N.Band.full_box([5, 5]).solve(np.ones(3, np.uint8), np.zeros(1, np.int64), np.zeros(1), 0.1, 1.0, None, 'godunov', 'extrapolate', 1e-10, 100, None, None, 1, True, 1e-12)",
    "N.Band.full_box([5, 5]).solve(np.full(25, 7, np.uint8), np.zeros(1, np.int64), np.zeros(1), 0.1, 1.0, None, 'godunov', 'extrapolate', 1e-10, 100, None, None, 1, True, 1e-12)",
    "N.Band.full_box([5, 5]).solve(np.ones(25, np.uint8), np.array([99], np.int64), np.zeros(1), 0.1, 1.0, None, 'godunov', 'extrapolate', 1e-10, 100, None, None, 1, True, 1e-12)",
    "N.Band.full_box([5, 5]).solve(np.ones(25, np.uint8), np.zeros(1, np.int64), np.zeros(1), -0.1, 1.0, None, 'godunov', 'extrapolate', 1e-10, 100, None, None, 1, True, 1e-12)",
    "N.Band.full_box([5, 5]).solve(np.ones(25, np.uint8), np.zeros(1, np.int64), np.zeros(1), 0.1, np.ones(3), None, 'godunov', 'extrapolate', 1e-10, 100, None, None, 1, True, 1e-12)",
    "N.Band.full_box([5, 5]).solve(np.ones(25, np.uint8), np.zeros(1, np.int64), np.zeros(1), 0.1, 1.0, None, 'nope', 'extrapolate', 1e-10, 100, None, None, 1, True, 1e-12)",
    "N.Band.full_box([5, 5]).solve(np.ones(25, np.uint8), np.zeros(1, np.int64), np.zeros(1), 0.1, 1.0, None, 'godunov', 'extrapolate', 1e-10, 100, float('nan'), None, 1, True, 1e-12)",
    "N.Band.full_box([5, 5]).solve(np.ones(25, np.uint8), np.zeros(1, np.int64), np.zeros(1), 0.1, 1.0, None, 'godunov', 'extrapolate', 1e-10, 100, None, 'notcallable', 1, True, 1e-12)",
    "N.Band.full_box([5, 5]).interpolate(np.zeros(3), [0.0, 0.0], 0.1, np.zeros((2, 2)))",
    "N.Band.full_box([5, 5]).find(np.zeros((2, 3), np.int64))",
    "N.Band.full_box([5, 5]).find(np.full((2, 2), -5, np.int64))",
    "N.Band.full_box([5, 5]).rim_nodes(3, 1)",
    "N.Band.full_box([5, 5]).nodes_missing_neighbours(np.zeros(3, bool))",
    "N.Band.full_box([5, 5]).nearest_source_labels(np.zeros(25), np.array([99], np.int64), np.array([0], np.int64))",
]
for call in native_calls:
    case(
        f"native/{call[:90]}",
        f"""
        r = {call}
        ok = True
    """,
        expect=None,
    )
