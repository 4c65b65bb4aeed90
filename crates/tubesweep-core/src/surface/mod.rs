//! Surfaces: how the solver evaluates Σ at grid nodes — exact signed distances of the analytic
//! surfaces (level sets, paper Sect. 4), closest points on meshes and on the library's open
//! surfaces (the closest-point representation, Sect. 5.2), closest points on the zero level set
//! of a sampled φ (re-distancing: `redistance.rs` projects points onto it, `interface_cells.rs`
//! locates it cell by cell, `redistance_band.rs` re-distances the band from any φ), and on point
//! clouds (moving-least-squares projection, `point_cloud/`; `mesh_smooth.rs` uses it for the smooth
//! closest-point map of a mesh). A new kind of surface is one more
//! file here, evaluated in bulk on the candidate nodes the band's search hands it (see
//! [`crate::band`]).

pub mod analytic;
pub mod interface_cells;
pub mod mesh;
pub mod mesh_parts;
pub mod mesh_smooth;
pub mod mobius;
pub mod open_surfaces;
pub mod point_cloud;
pub mod redistance;
pub mod redistance_band;
