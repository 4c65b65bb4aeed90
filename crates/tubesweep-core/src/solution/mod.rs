//! What a solve's values are used for afterwards: multilinear interpolation at arbitrary points
//! in the band, and which source reaches each node first (nearest-source labels).

pub mod interpolate;
pub mod interpolate_cubic;
pub mod nearest_source;
