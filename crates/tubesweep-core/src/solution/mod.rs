//! What a solve's values are used for afterwards: interpolation at arbitrary points in the band
//! (multilinear, or Catmull–Rom where the 4^d stencil is there), and which source reaches each node
//! first (nearest-source labels).

pub mod interpolate;
pub mod interpolate_cubic;
pub mod nearest_source;
pub mod source_feet;
