//! Phase 1 of the second-order solve on the first-order driver ([`crate::sweep`], parallel, with
//! its front window, coupled updates and rim pass): the paper's first-order tube scheme with the
//! *isotropic part* of the metric correction as a per-node slowness, σ / sqrt(tr(P B² P)/(D − 1))
//! (exact on spheres and curves, where B is isotropic on the tangent plane), from the fixed
//! nodes of the factoring. A monotone first-order start for the second-order passes, found in
//! the first-order solve's time.

use crate::band::NarrowBand;
use crate::error::Result;
use crate::scheme::InnerScheme;
use crate::sweep::{
    Control, Extension, IterationReport, MissingNeighbour, NodeRole, Slowness, SolveOptions, SolveStats, SweepProblem,
};

use super::factoring::Factoring;
use super::geometry::{sym, NodeGeometry};

/// The isotropic corrected slowness at each node (σ at the extension-layer nodes, not read).
fn isotropic_slowness<const D: usize>(
    geometry: &[NodeGeometry],
    roles: &[NodeRole],
    slowness: Slowness<'_>,
) -> Vec<f64> {
    // the geometry holds the nodes not in the extension layer, in band order
    let mut inner = geometry.iter();
    roles
        .iter()
        .enumerate()
        .map(|(i, &r)| {
            let sigma = match slowness {
                Slowness::Constant(s) => s,
                Slowness::PerNode(s) => s[i],
            };
            if r == NodeRole::Outer {
                return sigma;
            }
            let Some(g) = inner.next() else { return sigma };
            let b = |k: usize, l: usize| g.b(sym(k.min(l), k.max(l))) as f64;
            let (mut tr, mut bn2) = (0.0, 0.0);
            for k in 0..D {
                let mut bn = 0.0;
                for l in 0..D {
                    tr += b(k, l) * b(k, l);
                    bn += b(k, l) * g.normal[l] as f64;
                }
                bn2 += bn * bn;
            }
            sigma / ((tr - bn2) / (D as f64 - 1.0)).max(1e-12).sqrt()
        })
        .collect()
}

/// Runs the first-order driver for at most `max_iterations` (its deferred rim's pass included);
/// `values` gets its solution (+∞ where not reached, u₀ at the fixed nodes). `directions`: the
/// outward unit directions sgn(φ) n per node.
#[allow(clippy::too_many_arguments)]
pub fn first_order_start<const D: usize>(
    band: &NarrowBand<D>,
    geometry: &[NodeGeometry],
    factoring: &Factoring<D>,
    directions: &[[f32; D]],
    slowness: Slowness<'_>,
    spacing: f64,
    tol: f64,
    max_iterations: usize,
    threads: usize,
    front_window: f64,
    values: &mut Vec<f64>,
    control: &mut dyn FnMut(&IterationReport) -> Control,
) -> Result<SolveStats> {
    let s = isotropic_slowness::<D>(geometry, &factoring.roles, slowness);
    let problem = SweepProblem {
        band,
        roles: &factoring.roles,
        spacing,
        slowness: Slowness::PerNode(&s),
        extension: Extension::Directions(directions),
        scheme: InnerScheme::Godunov,
        missing: MissingNeighbour::Extrapolate,
    };
    let options = SolveOptions {
        tol,
        // the deferred outer rim's pass counts as one more iteration: `max_iterations` in all
        max_iterations: max_iterations.saturating_sub(1),
        infinity: None,
        threads,
        skip_inactive: true,
        activation_threshold: 0.01 * tol,
        coupled: true,
        defer_outer_rim: true,
        front_window,
        spread_threads: true,
        row_prefetch_above: crate::sweep::default_row_prefetch_above(),
    };
    let stats = problem.solve(values, &options, control)?;
    for (v, &r) in values.iter_mut().zip(&factoring.roles) {
        if r != NodeRole::Fixed && *v >= stats.infinity {
            *v = f64::INFINITY;
        }
    }
    Ok(stats)
}
