//! The narrow band (paper Fig. 4): the grid nodes of the computational tube, found from a surface
//! without touching the whole box (the coarse-to-fine search, a sampled φ, a mesh's candidates),
//! their extension directions (Eq. (8)), where the tubes of facing sheets touch, the nodes at a
//! crease that the inner tube gives up, and the order in
//! which the sweeps visit the band's rows (tiles and strips).

pub mod crease_ridges;
mod cut_edges;
pub mod discovery;
pub mod facing_sheets;
pub mod medial_edges;
pub mod mesh_band;
mod narrow_band;
mod node_blocks;
pub mod normals;
pub mod sampled;
pub mod schedule;

pub use narrow_band::*;
