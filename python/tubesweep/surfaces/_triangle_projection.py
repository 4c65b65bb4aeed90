"""The exact projection of points onto triangles (vectorised, numpy), and its feature codes.

Re-exported by :mod:`tubesweep.surfaces.mesh`; the solver's closest points come from the Rust core
(``tubesweep_core::surface::mesh``), this is the reference the tests compare it with.
"""

from __future__ import annotations

from typing import Tuple

import numpy as np

__all__ = ["closest_points_on_triangles", "FACE", "VERT_A", "VERT_B", "VERT_C", "EDGE_AB", "EDGE_AC", "EDGE_BC"]

#: Feature codes returned by :func:`closest_points_on_triangles`.
FACE, VERT_A, VERT_B, VERT_C, EDGE_AB, EDGE_AC, EDGE_BC = range(7)


def closest_points_on_triangles(
    p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray
) -> Tuple[np.ndarray, np.ndarray]:
    """Closest point on triangle (a_i, b_i, c_i) to p_i, for arrays of shape (n, 3).

    The Voronoi-region test of the triangle (vertices, edges, interior), vectorised. Returns the
    closest points (n, 3) and the feature code (n,) uint8: ``FACE``, ``VERT_A..C``,
    ``EDGE_AB/AC/BC``. Triangles must be non-degenerate.
    """
    ab = b - a
    ac = c - a
    ap = p - a
    d1 = np.einsum("ij,ij->i", ab, ap)
    d2 = np.einsum("ij,ij->i", ac, ap)
    bp = p - b
    d3 = np.einsum("ij,ij->i", ab, bp)
    d4 = np.einsum("ij,ij->i", ac, bp)
    cq = p - c
    d5 = np.einsum("ij,ij->i", ab, cq)
    d6 = np.einsum("ij,ij->i", ac, cq)
    va = d3 * d6 - d5 * d4
    vb = d5 * d2 - d1 * d6
    vc = d1 * d4 - d3 * d2

    code = np.full(len(p), FACE, dtype=np.uint8)
    done = np.zeros(len(p), dtype=bool)

    def claim(mask: np.ndarray, k: int) -> np.ndarray:
        m = mask & ~done
        code[m] = k
        done[m] = True
        return m

    claim((d1 <= 0) & (d2 <= 0), VERT_A)
    claim((d3 >= 0) & (d4 <= d3), VERT_B)
    m_ab = claim((vc <= 0) & (d1 >= 0) & (d3 <= 0), EDGE_AB)
    claim((d6 >= 0) & (d5 <= d6), VERT_C)
    m_ac = claim((vb <= 0) & (d2 >= 0) & (d6 <= 0), EDGE_AC)
    m_bc = claim((va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0), EDGE_BC)

    # barycentric weights (v on b, w on c) of the face region and of the three edges
    denom = va + vb + vc
    denom = np.where(denom != 0, denom, 1.0)
    v = vb / denom
    w = vc / denom
    with np.errstate(divide="ignore", invalid="ignore"):
        t_ab = d1 / (d1 - d3)
        t_ac = d2 / (d2 - d6)
        t_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
    v = np.where(m_ab, t_ab, v)
    w = np.where(m_ab, 0.0, w)
    v = np.where(m_ac, 0.0, v)
    w = np.where(m_ac, t_ac, w)
    v = np.where(m_bc, 1.0 - t_bc, v)
    w = np.where(m_bc, t_bc, w)
    for k, (vv, ww) in ((VERT_A, (0.0, 0.0)), (VERT_B, (1.0, 0.0)), (VERT_C, (0.0, 1.0))):
        m = code == k
        v = np.where(m, vv, v)
        w = np.where(m, ww, w)
    v = np.nan_to_num(v)
    w = np.nan_to_num(w)
    return a + v[:, None] * ab + w[:, None] * ac, code
