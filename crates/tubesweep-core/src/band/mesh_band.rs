//! The band of a triangle mesh (the closest-point representation of the paper's Sect. 5.2) from
//! the candidate nodes the coarse-to-fine search keeps: for every candidate within the band's
//! half-width of the mesh, its distance `|x − cp(x)|`, its signed distance on a closed mesh, and
//! the extension direction `(x − cp(x)) / |x − cp(x)|` of Eq. (8).
//!
//! The sign is that of `(x − cp(x))·n`, with `n` the angle-weighted pseudo-normal of the feature
//! (face, edge or vertex) that holds the closest point, which is exact for a closed, consistently
//! oriented mesh (Bærentzen & Aanæs). At nodes on the mesh, where the direction is undefined, it is
//! the face's normal. The arithmetic is that of the Python `MeshSurface.band` before this module
//! took it over, so the band, its distances and its directions are the same bits.

use crate::error::{Error, Result};
use crate::surface::mesh::{dot, sub, ClosestSearch, TriangleTree, QUERY_BLOCK};
use rayon::prelude::*;

/// The normals the band needs, per triangle of the tree (in the tree's triangle order).
pub struct MeshNormals<'a> {
    /// Each triangle's unit normal: the direction at nodes on the mesh.
    pub face: &'a [[f64; 3]],
    /// For a closed, oriented mesh, per triangle the outward angle-weighted pseudo-normals of its
    /// seven features, in the order of [`crate::surface::mesh::Feature`] (face, vertices a, b, c, edges
    /// ab, ac, bc); `None` for the unsigned closest-point representation.
    pub pseudo: Option<&'a [[[f64; 3]; 7]]>,
}

/// The band found among the candidates.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct MeshBand {
    /// Positions of the kept candidates, increasing.
    pub kept: Vec<u32>,
    /// `|x − cp(x)|`, one per kept candidate.
    pub distance: Vec<f64>,
    /// The signed distance (negative inside) on a closed mesh, else the distance.
    pub signed: Vec<f64>,
    /// The extension directions, three per kept candidate.
    pub direction: Vec<f32>,
}

/// The band of the mesh in `tree` among the candidate `points` (`M` rows of 3 coordinates, in
/// C order of the grid, so that each query starts near the previous one's answer): the points
/// within `half_width` of the mesh, with their distances, signs and directions. Points within
/// `on_surface` of the mesh take their triangle's normal as the direction.
pub fn mesh_band(
    tree: &TriangleTree,
    points: &[f64],
    half_width: f64,
    on_surface: f64,
    normals: &MeshNormals<'_>,
) -> Result<MeshBand> {
    if !points.len().is_multiple_of(3) {
        return Err(Error::invalid("points", "expected an (M, 3) array"));
    }
    if points.len() / 3 > u32::MAX as usize {
        return Err(Error::invalid(
            "points",
            format!("at most {} candidates are supported", u32::MAX),
        ));
    }
    if normals.face.len() != tree.len() || normals.pseudo.is_some_and(|p| p.len() != tree.len()) {
        return Err(Error::invalid(
            "normals",
            format!("expected one per triangle of the tree ({})", tree.len()),
        ));
    }
    if !(half_width >= 0.0) {
        return Err(Error::invalid("half_width", "must be non-negative"));
    }
    // the search reaches a hair past the half-width, so that rounding never loses a node at it
    let reach = half_width * (1.0 + 1e-12);
    let parts: Vec<MeshBand> = points
        .par_chunks(3 * QUERY_BLOCK)
        .enumerate()
        .map(|(b, block)| {
            let mut search = ClosestSearch::new(tree);
            let mut part = MeshBand::default();
            for (i, c) in block.chunks_exact(3).enumerate() {
                let x = [c[0], c[1], c[2]];
                let Some(found) = search.closest(x, reach) else {
                    continue;
                };
                let dist = found.distance;
                if !(dist <= half_width) {
                    continue;
                }
                let diff = sub(x, found.point);
                let direction = if dist <= on_surface {
                    normals.face[found.triangle]
                } else {
                    [diff[0] / dist, diff[1] / dist, diff[2] / dist]
                };
                let signed = match normals.pseudo {
                    Some(pseudo) => {
                        let n = pseudo[found.triangle][found.feature as usize];
                        if dot(diff, n) < 0.0 {
                            -dist
                        } else {
                            dist
                        }
                    }
                    None => dist,
                };
                part.kept.push((b * QUERY_BLOCK + i) as u32);
                part.distance.push(dist);
                part.signed.push(signed);
                part.direction.extend(direction.map(|v| v as f32));
            }
            part
        })
        .collect();
    let mut out = MeshBand::default();
    for part in parts {
        out.kept.extend(part.kept);
        out.distance.extend(part.distance);
        out.signed.extend(part.signed);
        out.direction.extend(part.direction);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An octahedron |x| + |y| + |z| = 1, outward-oriented, with its face normals and its
    /// pseudo-normals, which by its symmetry point along the feature's centre: the face's centroid,
    /// the vertex, the edge's midpoint.
    fn octahedron() -> (TriangleTree, Vec<[f64; 3]>, Vec<[[f64; 3]; 7]>) {
        let unit = |v: [f64; 3]| {
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            [v[0] / n, v[1] / n, v[2] / n]
        };
        let mid = |p: [f64; 3], q: [f64; 3]| unit([p[0] + q[0], p[1] + q[1], p[2] + q[2]]);
        let (mut tris, mut face, mut pseudo) = (Vec::new(), Vec::new(), Vec::new());
        for sx in [-1.0, 1.0] {
            for sy in [-1.0, 1.0] {
                for sz in [-1.0, 1.0] {
                    let (a, b, c) = ([sx, 0.0, 0.0], [0.0, sy, 0.0], [0.0, 0.0, sz]);
                    // outward: (b − a) × (c − a) along (sx, sy, sz)
                    let [a, b, c] = if sx * sy * sz > 0.0 { [a, b, c] } else { [a, c, b] };
                    tris.push([a, b, c]);
                    let n = unit([sx, sy, sz]);
                    face.push(n);
                    pseudo.push([n, unit(a), unit(b), unit(c), mid(a, b), mid(a, c), mid(b, c)]);
                }
            }
        }
        (TriangleTree::new(tris), face, pseudo)
    }

    #[test]
    fn band_of_an_octahedron_keeps_the_nodes_within_the_half_width_with_signs_and_directions() {
        let (tree, face, pseudo) = octahedron();
        let mut points = Vec::new();
        let n = 21;
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let c = |t: usize| -1.5 + 3.0 * t as f64 / (n - 1) as f64;
                    points.extend_from_slice(&[c(i), c(j), c(k)]);
                }
            }
        }
        // a node exactly on a face
        points.extend_from_slice(&[1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0]);
        let half_width = 0.3;
        for signed in [true, false] {
            let normals = MeshNormals {
                face: &face,
                pseudo: if signed { Some(&pseudo) } else { None },
            };
            let band = mesh_band(&tree, &points, half_width, 1e-12, &normals).unwrap();
            let mut expected = Vec::new();
            for (m, c) in points.chunks_exact(3).enumerate() {
                let l1 = c[0].abs() + c[1].abs() + c[2].abs();
                let q = tree.closest([c[0], c[1], c[2]], f64::INFINITY).unwrap();
                if q.distance <= half_width {
                    expected.push(m as u32);
                }
                if let Ok(pos) = band.kept.binary_search(&(m as u32)) {
                    assert_eq!(band.distance[pos], q.distance);
                    // (on the surface the sign is rounding's)
                    let inside = l1 < 1.0;
                    let want = if signed && inside { -q.distance } else { q.distance };
                    if q.distance > 1e-12 {
                        assert_eq!(band.signed[pos], want, "point {c:?}");
                    } else {
                        assert_eq!(band.signed[pos].abs(), q.distance);
                    }
                    let d = &band.direction[3 * pos..3 * pos + 3];
                    let norm = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                    assert!((norm - 1.0).abs() < 1e-6, "direction {d:?} at {c:?}");
                    if q.distance <= 1e-12 {
                        assert_eq!(d, face[q.triangle].map(|v| v as f32));
                    } else {
                        // points away from the closest point
                        let away = (0..3).map(|k| d[k] as f64 * (c[k] - q.point[k])).sum::<f64>();
                        assert!(away > 0.0);
                    }
                }
            }
            assert_eq!(band.kept, expected);
            assert!(band.kept.contains(&((n * n * n) as u32)));
        }
    }

    #[test]
    fn rejects_mismatched_normals() {
        let (tree, face, _) = octahedron();
        let normals = MeshNormals {
            face: &face[..3],
            pseudo: None,
        };
        assert!(mesh_band(&tree, &[0.0, 0.0, 0.0], 0.1, 0.0, &normals).is_err());
        let normals = MeshNormals {
            face: &face,
            pseudo: None,
        };
        assert!(mesh_band(&tree, &[0.0, 0.0], 0.1, 0.0, &normals).is_err());
        assert!(mesh_band(&tree, &[0.0, 0.0, 0.0], f64::NAN, 0.0, &normals).is_err());
    }
}
