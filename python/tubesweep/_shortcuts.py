"""Cutting the band's neighbour table where the front would take a shortcut the surface does not
have (``tubesweep_core::band::cut_edges``).

The two-layer method (Algorithm 3) lets a node's update read every band neighbour, taking a step
of one grid spacing in the tube for the step between the two nodes' closest points on the
surface. Three kinds of edges break that:

* across a gap narrower than the tubes, between two parts of the surface that face each other
  (``_facing._warn_if_tubes_touch``, ``tubesweep_core::band::facing_sheets``): the front would
  cross the gap;
* on a triangle mesh, above each concave edge, where the exact closest points of two neighbours
  lie on the two faces far apart (``tubesweep_core::band::medial_edges``): the front would cut
  across the valley;
* on a triangle mesh of separate pieces, between nodes whose nearest triangles lie on two of them
  (``surfaces._mesh_parts``): the facing test reads the band's closest points, which the smooth
  map can blend across a gap narrower than its fits.

On a triangle mesh all three are removed, so that the front travels only where closest points move
continuously along the surface. On a point cloud only the first: its closest points come from
local fits, which fold where the samples are sparse or off the surface, and cutting there left
parts of a connected cloud unreached (a hemisphere sampled 50 times more sparsely than the
other, in a scratch run of ``tests/test_point_cloud.py``'s sparse hemisphere with them cut: 387
edges cut, 5 of 2000 points at inf); across narrow gaps the cut keeps a thin shell's
two sheets apart (``benches/experiments/cloud_gaps.py``). On Spot and the Stanford bunny at n = 200 the first-order mean
error against exact polyhedral geodesics falls from 0.83 % and 0.87 % of the largest distance to
0.29 % and 0.41 % (the heat method: 0.59 % and 0.44 %; ``benches/mesh_order2.py``). Other surfaces
keep the paper's scheme bit for bit (their narrow gaps are warned about instead).
"""

from __future__ import annotations

from typing import Any, Optional, Tuple

import numpy as np

#: ``tubesweep_core::band::medial_edges::MEDIAL_JUMP``: the jump of the closest point between two
#: neighbours, in grid spacings, above which their edge is cut on a mesh.
MEDIAL_JUMP = 1.5


def cuts_shortcuts(surf: Any) -> bool:
    """Whether the band of ``surf`` is cut across narrow gaps (triangle meshes and point clouds:
    see the module's documentation)."""
    return bool(getattr(surf, "cuts_shortcuts", False))


def cuts_medial_edges(surf: Any) -> bool:
    """Whether the band of ``surf`` is cut at its medial edges too (triangle meshes, whose
    closest-point map is that of a polyhedron)."""
    return cuts_shortcuts(surf) and bool(getattr(surf, "cuts_medial_edges", True))


def cut_shortcuts(
    band: Any,
    inner: np.ndarray,
    phi: np.ndarray,
    direction: np.ndarray,
    spacing: float,
    facing: Tuple[np.ndarray, np.ndarray, np.ndarray],
    medial: bool = True,
) -> Tuple[Any, int]:
    """The band without the edges across narrow gaps (``facing``'s pairs) and, with ``medial``,
    the medial edges (closest points more than :data:`MEDIAL_JUMP` spacings apart where one node
    is in the inner tube, more than a resolved sheet's jump at their |φ| between two extension
    nodes: two parts of a mesh 4–8 spacings apart), and the number of edges removed. The band
    itself when there is none."""
    node = facing[0].astype(np.int64)
    neighbour = facing[1].astype(np.int64)
    if medial:
        phi32 = np.ascontiguousarray(phi, dtype=np.float32)
        dir32 = np.ascontiguousarray(direction, dtype=np.float32).reshape(len(phi32), -1)
        medial_node, medial_neighbour = band.medial_edges(inner, phi32, dir32, spacing, MEDIAL_JUMP)
        node = np.concatenate([node, medial_node])
        neighbour = np.concatenate([neighbour, medial_neighbour])
    if node.size == 0:
        return band, 0
    return band.with_edges_cut(node, neighbour)


def cut_pinches(surf: Any, grid: Any, band: Any, linear: np.ndarray) -> Tuple[Any, int]:
    """The band without its edges between two sheets of ``surf`` that meet at a point only, but
    round that point (a triangle mesh's ``_pinch_cut_pairs``: ``surfaces._mesh_pinches``), and
    the number of edges removed; the band itself and 0 on other surfaces and where there is none."""
    pairs = getattr(surf, "_pinch_cut_pairs", None)
    if pairs is None:
        return band, 0
    node, neighbour = pairs(grid, band, linear)
    if node.size == 0:
        return band, 0
    return band.with_edges_cut(node, neighbour)


def cut_between_parts(surf: Any, grid: Any, band: Any, linear: np.ndarray) -> Tuple[Any, int, Optional[np.ndarray]]:
    """The band without its edges between two separate parts of ``surf`` (a triangle mesh's
    ``_part_cut_pairs``: ``surfaces._mesh_parts``), the number of edges removed, and each band
    node's part; the band itself, 0 and None on other surfaces and on a mesh of one part."""
    pairs = getattr(surf, "_part_cut_pairs", None)
    if pairs is None:
        return band, 0, None
    node, neighbour, pieces = pairs(grid, band, linear)
    if node.size == 0:
        return band, 0, pieces
    band, cut = band.with_edges_cut(node, neighbour)
    return band, cut, pieces
