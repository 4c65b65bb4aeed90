//! The set-up of the second-order solve in one pass over the band: per node the geometry
//! ([`super::geometry`]: n, B, the curvature found) and the factoring ([`super::factoring`]: u₀,
//! ∇u₀, the fixed nodes) from a single evaluation of φ's differences ([`Implicit::local`]), which
//! both read (computed once instead of twice: on the sphere at N = 201 that saves a fifth of the
//! set-up's instructions). The band is cut into chunks of consecutive nodes that run
//! in parallel on the solve's thread count (one thread: on the calling thread), each node's
//! values the same as [`super::tube_geometry_of`]'s and [`super::factor_sources_of`]'s, and the
//! summary's maxima, minima and counts the same whatever the split.

use rayon::prelude::*;

use crate::band::NarrowBand;
use crate::error::{Error, Result};
use crate::sweep::NodeRole;

use super::creases::creases_of;
use super::factoring::{
    check_source_arguments, check_sources_fixed, factor_at, grad_u0_unit_of, node_foot, Factoring, NodeFoot, TubeFeet,
};
use super::geometry::{
    abs_phi_of, check_tube_inputs, node_geometry, GeometrySummary, NodeGeometry, TubeGeometry, WIDE_FIT,
};
use super::implicit::Implicit;
use super::joined::{keep_joined, FixedNode};

/// Nodes per chunk of the parallel pass.
const CHUNK: usize = 4096;

/// What one chunk of consecutive nodes gives.
struct Chunk<const D: usize> {
    nodes: Vec<NodeGeometry>,
    grad_u0: Vec<[f32; D]>,
    u0: Vec<f64>,
    /// The chunk's nodes fixed by a source (ranks within the chunk).
    fixed: Vec<FixedNode<D>>,
    fixed_per_source: Vec<usize>,
    summary: GeometrySummary,
    /// [`TubeFeet`]'s parts for the chunk (when asked for).
    closest_points: Vec<[f64; D]>,
    feet: Vec<NodeFoot<D>>,
}

/// [`super::tube_geometry_of`] and [`super::factor_sources_of`] together, on `threads` threads
/// (0: the default count, [`crate::sweep::thread_choice::threads_for_default`]). The factoring's
/// own errors (its arguments, a source with no inner-tube node near it) come back inside, so
/// that the caller can check the geometry first ([`super::check_geometry_of`]), as with the two
/// functions one after the other.
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub fn tube_setup_of<const D: usize>(
    band: &NarrowBand<D>,
    roles: &[NodeRole],
    surface: &Implicit<'_, D>,
    directions: &[[f32; D]],
    lower: [f64; D],
    spacing: f64,
    outer_width: f64,
    sources: &[[f64; D]],
    source_slowness: &[f64],
    fix_radius: f64,
    threads: usize,
) -> Result<(TubeGeometry, Result<Factoring<D>>)> {
    let (geometry, factoring, _) = setup(
        band,
        roles,
        surface,
        directions,
        lower,
        spacing,
        outer_width,
        sources,
        source_slowness,
        fix_radius,
        threads,
        false,
    )?;
    Ok((geometry, factoring))
}

/// The set-up of a batch of solves on one band ([`super::many`]): the tube's geometry as
/// [`tube_setup_of`] computes it, and the source-independent part of the factoring
/// ([`TubeFeet`]) from the same differences of φ, so that each source's factoring
/// ([`super::factoring::factor_sources_at`]) is the single solve's, bit for bit.
#[allow(clippy::too_many_arguments)]
pub fn batch_setup_of<const D: usize>(
    band: &NarrowBand<D>,
    roles: &[NodeRole],
    surface: &Implicit<'_, D>,
    directions: &[[f32; D]],
    lower: [f64; D],
    spacing: f64,
    outer_width: f64,
    threads: usize,
) -> Result<(TubeGeometry, TubeFeet<D>)> {
    let (geometry, _, feet) = setup(
        band,
        roles,
        surface,
        directions,
        lower,
        spacing,
        outer_width,
        &[],
        &[],
        0.0,
        threads,
        true,
    )?;
    Ok((geometry, feet))
}

/// [`tube_setup_of`], and with `keep_feet` the [`TubeFeet`] (empty otherwise).
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn setup<const D: usize>(
    band: &NarrowBand<D>,
    roles: &[NodeRole],
    surface: &Implicit<'_, D>,
    directions: &[[f32; D]],
    lower: [f64; D],
    spacing: f64,
    outer_width: f64,
    sources: &[[f64; D]],
    source_slowness: &[f64],
    fix_radius: f64,
    threads: usize,
    keep_feet: bool,
) -> Result<(TubeGeometry, Result<Factoring<D>>, TubeFeet<D>)> {
    let n = band.len();
    check_tube_inputs(n, roles, surface, directions, spacing, outer_width)?;
    let abs_phi = abs_phi_of(surface, spacing);
    let factoring_arguments = check_source_arguments(sources, source_slowness);
    let factor = factoring_arguments.is_ok();
    let unit = grad_u0_unit_of(source_slowness);
    let indices = band.indices();
    let chunk = |c: usize, fitted: bool| -> Chunk<D> {
        let (s, e) = (c * CHUNK, ((c + 1) * CHUNK).min(n));
        let inner = roles[s..e].iter().filter(|&&r| r != NodeRole::Outer).count();
        let mut out = Chunk {
            nodes: Vec::with_capacity(inner),
            grad_u0: Vec::with_capacity(if factor { inner } else { 0 }),
            u0: Vec::with_capacity(if factor { e - s } else { 0 }),
            fixed: Vec::new(),
            fixed_per_source: vec![0; sources.len()],
            summary: GeometrySummary {
                fitted_everywhere: fitted,
                ..GeometrySummary::empty()
            },
            closest_points: Vec::with_capacity(if keep_feet { e - s } else { 0 }),
            feet: Vec::with_capacity(if keep_feet { inner } else { 0 }),
        };
        for i in s..e {
            let is_inner = roles[i] != NodeRole::Outer;
            let mut local = if is_inner {
                surface.local(band, i, spacing)
            } else {
                None
            };
            if is_inner {
                out.nodes.push(node_geometry(
                    surface.phi(i),
                    &directions[i],
                    &mut local,
                    outer_width,
                    &mut out.summary,
                    || surface.local_fitted(band, i, spacing, WIDE_FIT && fitted),
                ));
            }
            if !(factor || keep_feet) {
                continue;
            }
            let mut x = [0.0; D];
            for k in 0..D {
                x[k] = lower[k] + spacing * indices[i][k] as f64;
            }
            // (with a local that the geometry refitted, the refitted one, as the sweeps' B)
            let (cp, foot) = node_foot(surface, i, &x, &directions[i], local.as_ref());
            if factor {
                let node = factor_at(
                    &cp,
                    is_inner.then_some(&foot),
                    sources,
                    source_slowness,
                    unit,
                    fix_radius,
                    &mut out.fixed_per_source,
                );
                out.u0.push(node.u0);
                out.fixed.extend(node.fixed_node(i, out.grad_u0.len()));
                if is_inner {
                    out.grad_u0.push(node.grad_u0);
                }
            }
            if keep_feet {
                out.closest_points.push(cp);
                if is_inner {
                    out.feet.push(foot);
                }
            }
        }
        out
    };
    let chunks = n.div_ceil(CHUNK);
    let count = if threads == 0 {
        crate::sweep::thread_choice::threads_for_default()
    } else {
        threads
    };
    let pool = if count > 1 && chunks > 1 {
        Some(
            rayon::ThreadPoolBuilder::new()
                .num_threads(count)
                .build()
                .map_err(|e| Error::invalid("threads", format!("could not start {count} threads: {e}")))?,
        )
    } else {
        None
    };
    let pass = |fitted: bool| -> Vec<Chunk<D>> {
        match &pool {
            Some(pool) => pool.install(|| (0..chunks).into_par_iter().map(|c| chunk(c, fitted)).collect()),
            None => (0..chunks).map(|c| chunk(c, fitted)).collect(),
        }
    };
    let mut parts = pass(false);
    // φ noisy: every node's derivatives again, from the local fits (geometry::NOISY_FRACTION)
    let first = parts.iter().fold(GeometrySummary::empty(), |a, p| a.merge(p.summary));
    if first.noisy() {
        let fitted = pass(true);
        let second = fitted.iter().fold(GeometrySummary::empty(), |a, p| a.merge(p.summary));
        if first.fit_is_kept(&second, outer_width, spacing, surface.is_closest_point()) {
            parts = fitted;
        }
    }
    drop(indices);
    let n_inner: usize = parts.iter().map(|p| p.nodes.len()).sum();
    let mut nodes = Vec::with_capacity(n_inner);
    let mut summary = GeometrySummary::empty();
    let (mut u0, mut grad_u0) = if factor {
        (Vec::with_capacity(n), Vec::with_capacity(n_inner))
    } else {
        (Vec::new(), Vec::new())
    };
    let mut out_roles = roles.to_vec();
    let mut fixed_per_source = vec![0usize; sources.len()];
    let mut fixed = Vec::new();
    let mut feet = TubeFeet {
        closest_points: Vec::with_capacity(if keep_feet { n } else { 0 }),
        inner: Vec::with_capacity(if keep_feet { n_inner } else { 0 }),
    };
    for part in parts {
        feet.closest_points.extend_from_slice(&part.closest_points);
        feet.inner.extend_from_slice(&part.feet);
        nodes.extend_from_slice(&part.nodes);
        summary = summary.merge(part.summary);
        for f in &part.fixed {
            out_roles[f.node as usize] = NodeRole::Fixed;
            fixed.push(FixedNode {
                rank: f.rank + grad_u0.len() as u32,
                ..*f
            });
        }
        u0.extend_from_slice(&part.u0);
        grad_u0.extend_from_slice(&part.grad_u0);
        for (total, c) in fixed_per_source.iter_mut().zip(&part.fixed_per_source) {
            *total += c;
        }
    }
    summary.finish();
    if !surface.is_closest_point() && !summary.fitted_everywhere {
        summary.creases = creases_of(band, roles, surface, spacing, directions, &nodes);
    }
    let geometry = TubeGeometry {
        nodes,
        abs_phi,
        summary,
    };
    if factor {
        keep_joined(band, roles, &fixed, &mut out_roles, &mut grad_u0, &mut fixed_per_source);
    }
    let factoring = factoring_arguments.and_then(|()| {
        check_sources_fixed(&fixed_per_source, fix_radius)?;
        Ok(Factoring {
            u0,
            grad_u0,
            grad_u0_unit: unit,
            roles: out_roles,
            fixed_per_source,
        })
    });
    Ok((geometry, factoring, feet))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::second_order::{factor_sources_of, tube_geometry_of};

    /// The one pass gives the two functions' geometry and factoring, bit for bit, on 1 and 3
    /// threads, a level set and a closest-point map.
    #[test]
    fn one_pass_gives_the_two_functions_values() {
        let (band, roles, dirs, h) = crate::test_bands::shell_band(41, 0.5, &[0.0]);
        let (phi, offsets) = crate::test_bands::sphere_phi_and_offsets(&band, h);
        let sources = [[-0.5, 0.0, 0.0], [0.0, 0.5, 0.0]];
        let slowness = [1.0, 1.5];
        for surface in [Implicit::LevelSet(&phi), Implicit::ClosestPoint(&offsets)] {
            let geo = tube_geometry_of(&band, &roles, &surface, &dirs, h, 4.0 * h).unwrap();
            let fac = factor_sources_of(
                &band,
                &roles,
                &surface,
                &dirs,
                [-1.0; 3],
                h,
                &sources,
                &slowness,
                2.0 * h,
            )
            .unwrap();
            for threads in [1, 3] {
                let (g, f) = tube_setup_of(
                    &band,
                    &roles,
                    &surface,
                    &dirs,
                    [-1.0; 3],
                    h,
                    4.0 * h,
                    &sources,
                    &slowness,
                    2.0 * h,
                    threads,
                )
                .unwrap();
                let f = f.unwrap();
                assert_eq!(g.nodes, geo.nodes);
                assert_eq!(g.summary, geo.summary);
                assert_eq!(g.abs_phi, geo.abs_phi);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&f.u0), bits(&fac.u0));
                assert_eq!(f.grad_u0, fac.grad_u0);
                assert_eq!(f.grad_u0_unit, fac.grad_u0_unit);
                assert_eq!(f.roles, fac.roles);
                assert_eq!(f.fixed_per_source, fac.fixed_per_source);
            }
        }
        // a source far from the surface: the same error from both, after the geometry
        let (_, f) = tube_setup_of(
            &band,
            &roles,
            &Implicit::LevelSet(&phi),
            &dirs,
            [-1.0; 3],
            h,
            4.0 * h,
            &[[0.0, 0.0, 0.0]],
            &[1.0],
            2.0 * h,
            2,
        )
        .unwrap();
        assert!(f.is_err());
    }

    /// A batch's factoring from the shared feet ([`batch_setup_of`], `factor_sources_at`) is the
    /// one pass's bit for bit, on a level set, a closest-point map and a noisy φ whose
    /// derivatives the geometry refits everywhere (there the factoring reads the refitted ones,
    /// which `factor_sources_of` does not: its ∇u₀ differs).
    #[test]
    fn the_batch_factoring_is_the_one_pass_factoring() {
        use crate::second_order::factoring::factor_sources_at;
        let (band, roles, dirs, h) = crate::test_bands::shell_band(41, 0.5, &[0.0]);
        let (phi, offsets) = crate::test_bands::sphere_phi_and_offsets(&band, h);
        let mut next = crate::test_random::uniform(46);
        let noisy: Vec<f64> = phi.iter().map(|p| p + 0.1 * h * (2.0 * next() - 1.0)).collect();
        let sources = [[-0.5, 0.0, 0.0], [0.0, 0.3, 0.4]];
        let slowness = [1.0, 1.5];
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for (name, surface) in [
            ("level set", Implicit::LevelSet(&phi)),
            ("closest points", Implicit::ClosestPoint(&offsets)),
            ("noisy level set", Implicit::LevelSet(&noisy)),
        ] {
            for threads in [1, 3] {
                let (geo, feet) =
                    batch_setup_of(&band, &roles, &surface, &dirs, [-1.0; 3], h, 4.0 * h, threads).unwrap();
                for k in [1, 2] {
                    let (g, f) = tube_setup_of(
                        &band,
                        &roles,
                        &surface,
                        &dirs,
                        [-1.0; 3],
                        h,
                        4.0 * h,
                        &sources[..k],
                        &slowness[..k],
                        2.0 * h,
                        threads,
                    )
                    .unwrap();
                    let f = f.unwrap();
                    assert_eq!(g.nodes, geo.nodes, "{name}");
                    assert_eq!(g.summary, geo.summary, "{name}");
                    let b = factor_sources_at(&band, &feet, &roles, &sources[..k], &slowness[..k], 2.0 * h).unwrap();
                    assert_eq!(bits(&b.u0), bits(&f.u0), "{name}");
                    assert_eq!(b.grad_u0, f.grad_u0, "{name}");
                    assert_eq!(b.grad_u0_unit, f.grad_u0_unit, "{name}");
                    assert_eq!(b.roles, f.roles, "{name}");
                    assert_eq!(b.fixed_per_source, f.fixed_per_source, "{name}");
                    if name == "noisy level set" {
                        assert!(
                            geo.summary.fitted_everywhere,
                            "the noise is meant to make the geometry refit"
                        );
                        let plain = factor_sources_of(
                            &band,
                            &roles,
                            &surface,
                            &dirs,
                            [-1.0; 3],
                            h,
                            &sources[..k],
                            &slowness[..k],
                            2.0 * h,
                        )
                        .unwrap();
                        assert_ne!(plain.grad_u0, f.grad_u0);
                    }
                }
            }
        }
        // a source with no inner-tube node near it: the single solve's error
        let (_, feet) = batch_setup_of(
            &band,
            &roles,
            &Implicit::LevelSet(&phi),
            &dirs,
            [-1.0; 3],
            h,
            4.0 * h,
            1,
        )
        .unwrap();
        let err = factor_sources_at(&band, &feet, &roles, &[[0.0, 0.0, 0.0]], &[1.0], 2.0 * h)
            .err()
            .unwrap();
        assert!(err.to_string().contains("sources[0]"), "{err}");
    }
}
