//! The connected parts of a triangle mesh (the pieces whose tubes the band is cut between, the
//! sheets that meet at a pinch, the loops of a mesh's boundary: `python/tubesweep/surfaces/
//! _mesh_parts.py` and its users). Union–find over the triangles' edges ([`SmallestRoot`]),
//! O(faces · α); each part is labelled by its smallest vertex index, so the labels do not depend
//! on the order of the faces.

use crate::error::{Error, Result};
use crate::union_find::SmallestRoot;

/// Per vertex `0..n_vertices` the smallest vertex index of its connected part, the vertices joined
/// by the edges AB, BC and CA of each face `[A, B, C]` (a face `[a, b, b]` is the edge ab alone).
/// A vertex of no face is a part of its own. Errors on an index outside `0..n_vertices`.
pub fn vertex_parts(n_vertices: usize, faces: &[[i64; 3]]) -> Result<Vec<i64>> {
    if let Some(bad) = faces
        .iter()
        .flatten()
        .find(|&&k| k < 0 || k as u64 >= n_vertices as u64)
    {
        return Err(Error::invalid(
            "faces",
            format!("vertex index {bad} outside 0..{n_vertices} (the number of vertices)"),
        ));
    }
    let mut parts = SmallestRoot::new(n_vertices);
    for f in faces {
        for (a, b) in [(f[0], f[1]), (f[1], f[2]), (f[2], f[0])] {
            parts.join(a as u32, b as u32);
        }
    }
    Ok((0..n_vertices as u32).map(|k| parts.root(k) as i64).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_pieces_and_a_lone_vertex() {
        // two triangles sharing an edge (0..3), one apart (4..6), vertex 3 in none
        let faces = [[2, 1, 0], [0, 2, 7], [6, 5, 4]];
        assert_eq!(vertex_parts(8, &faces).unwrap(), vec![0, 0, 0, 3, 4, 4, 4, 0]);
    }

    #[test]
    fn labels_do_not_depend_on_the_order_of_the_faces() {
        // a strip 0-1-2-...-9 joined one edge at a time, from either end
        let forward: Vec<[i64; 3]> = (0..9).map(|k| [k, k + 1, k + 1]).collect();
        let backward: Vec<[i64; 3]> = forward.iter().rev().cloned().collect();
        let want = vec![0i64; 10];
        assert_eq!(vertex_parts(10, &forward).unwrap(), want);
        assert_eq!(vertex_parts(10, &backward).unwrap(), want);
    }

    #[test]
    fn an_index_out_of_range_is_refused() {
        assert!(vertex_parts(3, &[[0, 1, 3]]).is_err());
        assert!(vertex_parts(3, &[[0, -1, 2]]).is_err());
    }
}
