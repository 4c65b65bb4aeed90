//! Many second-order solves on one band (`Tube.solve_many(..., order=2)`), in parallel across the
//! sources: the tube's geometry (n, B per node, [`super::geometry`]) and the source-independent
//! part of the factoring (each node's closest point, normal, φ and D²φ: [`TubeFeet`]) computed
//! once by [`super::setup::batch_setup_of`] and shared by every solve of the batch, and per source
//! its own factoring ([`super::factoring::factor_sources_at`]: u₀, ∇u₀, the fixed nodes, from the
//! shared feet) and sweeps ([`super::solver`]) on one thread. The scheduler is the first-order
//! batch's ([`crate::sweep::many_sources::run_across_sources`]).
//!
//! Each source's values are those of a single second-order solve of it, bit for bit: the
//! factoring from the shared feet is [`super::tube_setup_of`]'s, node by node (the same
//! differences of φ, refitted where the geometry refits them), and the sweeps give the same
//! values on any thread count. With [`Order2Output::AtPoints`] the values
//! are evaluated as a second-order solution's `sol(points)` does (`python/tubesweep/_factoring.py`):
//! multilinear interpolation of u, and within `reach` of a source w = u − u₀ interpolated plus the
//! chord from the point's foot on the surface to the source
//! ([`crate::solution::source_feet`], as the Python evaluation does), so that only the K × M values are kept.

use std::sync::atomic::{AtomicBool, Ordering};

use crate::band::NarrowBand;
use crate::error::{Error, Result};
use crate::solution::interpolate::interpolate;
use crate::solution::source_feet::SourceFeet;
use crate::sweep::many_sources::run_across_sources;
use crate::sweep::{Control, IterationReport, NodeRole, Slowness};

use super::factoring::{factor_sources_at, TubeFeet};
use super::geometry::TubeGeometry;
use super::solver::{sweep_second_order, SecondOrderOptions, SecondOrderStats};
use super::start::first_order_start;
use super::starting_values;

/// What every solve of the batch shares: the band, its roles (no fixed node), the outward
/// directions, and the geometry and the feet computed once ([`super::setup::batch_setup_of`],
/// the geometry checked by [`super::check_geometry_of`]).
pub struct BatchTube<'a, const D: usize> {
    pub band: &'a NarrowBand<D>,
    pub roles: &'a [NodeRole],
    pub directions: &'a [[f32; D]],
    pub geometry: &'a TubeGeometry,
    pub feet: &'a TubeFeet<D>,
    pub lower: [f64; D],
    pub spacing: f64,
    pub slowness: Slowness<'a>,
    /// Inner-tube nodes within this of a source are fixed at u₀.
    pub fix_radius: f64,
    /// The stopping rules; `threads` is ignored (each solve runs on one thread).
    pub options: SecondOrderOptions,
    /// The first-order driver's front window, for a phase 1 run there (`own_first_phase` false).
    pub front_window: f64,
}

/// One source of the batch: the foot points of its point sources on the surface and the slowness
/// at each (several points: one multi-source solve, the nearest of them).
#[derive(Clone, Copy)]
pub struct BatchSource<'a, const D: usize> {
    pub feet: &'a [[f64; D]],
    pub slowness: &'a [f64],
}

/// Where the values of each solve go.
pub enum Order2Output<'o, const D: usize> {
    /// Row `k` of `values` (`K × n`) is source `k`'s band values (+∞ where never reached).
    Band(&'o mut [f64]),
    /// Row `k` of `values` (`K × M`) holds source `k`'s solution at `points`, as `sol(points)`
    /// evaluates a second-order solution: `feet` are the points' feet on the surface (the point
    /// itself where it is on the surface, or where `reach` is only a few grid spacings), `reach`
    /// the distance from a source within which the factored form is evaluated.
    AtPoints {
        lower: [f64; D],
        points: &'o [[f64; D]],
        feet: &'o [[f64; D]],
        reach: f64,
        values: &'o mut [f64],
    },
}

/// K second-order solves on `tube`, one per source, on `threads` threads (0: rayon's default
/// number), each solve on one thread. `progress(done)` runs on the calling thread about every
/// 50 ms; [`Control::Stop`] stops every solve ([`Error::Interrupted`]). On an error no statistics
/// are returned and the output is to be discarded. Returns each source's statistics.
pub fn solve_many_second_order<const D: usize>(
    tube: &BatchTube<'_, D>,
    sources: &[BatchSource<'_, D>],
    threads: usize,
    mut output: Order2Output<'_, D>,
    progress: &mut dyn FnMut(usize) -> Control,
) -> Result<Vec<SecondOrderStats>> {
    let n = tube.band.len();
    let k = sources.len();
    if tube.roles.len() != n || tube.directions.len() != n || tube.feet.closest_points.len() != n {
        return Err(Error::invalid(
            "roles",
            format!("roles, directions and the feet need one entry per band node ({n})"),
        ));
    }
    if tube.roles.contains(&NodeRole::Fixed) {
        return Err(Error::invalid(
            "roles",
            "the tube's roles must not hold fixed nodes (each source fixes its own)",
        ));
    }
    for (i, s) in sources.iter().enumerate() {
        if s.feet.is_empty() || s.feet.len() != s.slowness.len() {
            return Err(Error::invalid(
                "sources",
                format!(
                    "source {i}: {} points but {} slownesses (at least one point)",
                    s.feet.len(),
                    s.slowness.len()
                ),
            ));
        }
    }
    let options = SecondOrderOptions {
        threads: 1,
        ..tube.options
    };
    let (rows, at, width) = match &mut output {
        Order2Output::Band(v) => (&mut **v, None, n),
        Order2Output::AtPoints {
            lower,
            points,
            feet,
            reach,
            values,
        } => {
            if feet.len() != points.len() {
                return Err(Error::invalid("at", "one foot point per point"));
            }
            let m = points.len();
            (&mut **values, Some((*lower, *points, *feet, *reach)), m)
        }
    };
    run_across_sources(
        k,
        width,
        threads,
        rows,
        || (),
        |_, i, stop, row| {
            let (values, u0, st) = solve_one(tube, &options, sources[i], stop).map_err(|e| match e {
                Error::InvalidArgument { argument, message } => Error::InvalidArgument {
                    argument,
                    message: format!("source {i}: {message}"),
                },
                e => e,
            })?;
            match at {
                None => row.copy_from_slice(&values),
                Some((lower, points, feet, reach)) => {
                    evaluate_at(tube, &values, &u0, sources[i], lower, points, feet, reach, row)
                }
            }
            Ok(st)
        },
        progress,
    )
}

/// One source's second-order solve: its values and u₀.
fn solve_one<const D: usize>(
    tube: &BatchTube<'_, D>,
    options: &SecondOrderOptions,
    src: BatchSource<'_, D>,
    stop: &AtomicBool,
) -> Result<(Vec<f64>, Vec<f64>, SecondOrderStats)> {
    let factoring = factor_sources_at(
        tube.band,
        tube.feet,
        tube.roles,
        src.feet,
        src.slowness,
        tube.fix_radius,
    )?;
    let mut values = starting_values(&factoring);
    let mut check = |_: &IterationReport| {
        if stop.load(Ordering::Relaxed) {
            Control::Stop
        } else {
            Control::Continue
        }
    };
    let mut first = None;
    if !options.own_first_phase {
        first = Some(first_order_start(
            tube.band,
            &tube.geometry.nodes,
            &factoring,
            tube.directions,
            tube.slowness,
            tube.spacing,
            options.tol_first,
            options.max_iterations,
            1,
            tube.front_window,
            &mut values,
            &mut check,
        )?);
    }
    // max_iterations bounds both phases together, as in the single solve
    let options = SecondOrderOptions {
        max_iterations: options
            .max_iterations
            .saturating_sub(first.as_ref().map_or(0, |st| st.iterations)),
        ..*options
    };
    let mut stats = sweep_second_order(
        tube.band,
        tube.geometry,
        &factoring,
        tube.directions,
        tube.slowness,
        tube.spacing,
        &mut values,
        &options,
        &mut check,
    )?;
    if let Some(st) = first {
        stats.first_order_iterations += st.iterations;
        stats.seconds += st.seconds;
    }
    values.truncate(tube.band.len());
    // a travel time is never negative: u = u₀ + w rounds to just below 0 next to a source, and
    // the single solve clamps its values at 0 after its sweeps (whose runaway guard reads the
    // sign), so the batch's rows and their read-outs do too (NaN stays NaN, as numpy's maximum)
    for v in values.iter_mut() {
        if *v < 0.0 {
            *v = 0.0;
        }
    }
    Ok((values, factoring.u0, stats))
}

/// `sol(points)` of one source's solution into `row` (see [`Order2Output::AtPoints`]).
#[allow(clippy::too_many_arguments)]
fn evaluate_at<const D: usize>(
    tube: &BatchTube<'_, D>,
    values: &[f64],
    u0: &[f64],
    src: BatchSource<'_, D>,
    lower: [f64; D],
    points: &[[f64; D]],
    feet: &[[f64; D]],
    reach: f64,
    row: &mut [f64],
) {
    let flat = |p: &[[f64; D]]| -> Vec<f64> { p.iter().flat_map(|x| x.iter().copied()).collect() };
    let u = interpolate(tube.band, values, lower, tube.spacing, &flat(points));
    row.copy_from_slice(&u);
    let near = SourceFeet::new(src.feet, src.slowness);
    let close: Vec<usize> = (0..points.len())
        .filter(|&m| row[m].is_finite() && near.within(&points[m], reach))
        .collect();
    if close.is_empty() {
        return;
    }
    let w: Vec<f64> = values.iter().zip(u0).map(|(v, z)| v - z).collect();
    let q: Vec<[f64; D]> = close.iter().map(|&m| points[m]).collect();
    let wq = interpolate(tube.band, &w, lower, tube.spacing, &flat(&q));
    for (&m, wm) in close.iter().zip(wq) {
        row[m] = wm + near.chord_min(&feet[m]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::second_order::implicit::Implicit;
    use crate::second_order::setup::batch_setup_of;
    use crate::second_order::{check_geometry_of, tube_setup_of};

    fn options() -> SecondOrderOptions {
        SecondOrderOptions {
            tol_first: f64::INFINITY,
            tol: 1e-3 * 0.05 * 0.05,
            max_iterations: 500,
            stall_ratio: crate::second_order::STALL_RATIO,
            stall_window: 20,
            own_first_phase: true,
            window_first: 2.0,
            window_second: 2.0,
            extension_limit: 2.0,
            threads: 2,
            ramp_length: 1.0,
        }
    }

    /// Each row is the single solve of its source (the set-up of `tube_setup_of` with that source,
    /// its sweeps on two threads), bit for bit, on 1 and 2 threads, for a point source and a group;
    /// the values at points are the interpolated u, and 0 at a source.
    #[test]
    fn rows_equal_single_second_order_solves_bit_for_bit() {
        let (band, roles, dirs, h) = crate::test_bands::shell_band(41, 0.5, &[0.0]);
        let (phi, _) = crate::test_bands::sphere_phi_and_offsets(&band, h);
        let surface = Implicit::LevelSet(&phi);
        let (geometry, tube_feet) = batch_setup_of(&band, &roles, &surface, &dirs, [-1.0; 3], h, 4.0 * h, 1).unwrap();
        check_geometry_of(&geometry.summary, 4.0 * h, h, false).unwrap();
        let feet = [[-0.5, 0.0, 0.0], [0.0, 0.3, 0.4], [0.0, 0.0, -0.5]];
        let slowness = [1.0, 1.0, 1.0];
        let sources = [
            BatchSource {
                feet: &feet[..1],
                slowness: &slowness[..1],
            },
            BatchSource {
                feet: &feet[1..],
                slowness: &slowness[1..],
            },
        ];
        let tube = BatchTube {
            band: &band,
            roles: &roles,
            directions: &dirs,
            geometry: &geometry,
            feet: &tube_feet,
            lower: [-1.0; 3],
            spacing: h,
            slowness: Slowness::Constant(1.0),
            fix_radius: 2.0 * h,
            options: options(),
            front_window: 2.0,
        };
        let n = band.len();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let singles: Vec<Vec<f64>> = sources
            .iter()
            .map(|s| {
                let (g, f) = tube_setup_of(
                    &band,
                    &roles,
                    &surface,
                    &dirs,
                    [-1.0; 3],
                    h,
                    4.0 * h,
                    s.feet,
                    s.slowness,
                    2.0 * h,
                    2,
                )
                .unwrap();
                let f = f.unwrap();
                let mut values = starting_values(&f);
                sweep_second_order(
                    &band,
                    &g,
                    &f,
                    &dirs,
                    Slowness::Constant(1.0),
                    h,
                    &mut values,
                    &options(),
                    &mut |_| Control::Continue,
                )
                .unwrap();
                values.truncate(n);
                values
            })
            .collect();
        for threads in [1, 2] {
            let mut out = vec![0.0; 2 * n];
            let st = solve_many_second_order(&tube, &sources, threads, Order2Output::Band(&mut out), &mut |_| {
                Control::Continue
            })
            .unwrap();
            assert!(st.iter().all(|s| s.converged));
            for (k, single) in singles.iter().enumerate() {
                assert_eq!(
                    bits(&out[k * n..(k + 1) * n]),
                    bits(single),
                    "source {k}, {threads} threads"
                );
            }
            // at the sources and far from them: 0 at a source (its cell's nodes are fixed), the
            // interpolated u beyond the reach (at the antipode, 1.558 for π/2 at N = 41: the ridge)
            let points = [feet[0], feet[2], [0.5, 0.0, 0.0]];
            let mut at = vec![0.0; 2 * 3];
            solve_many_second_order(
                &tube,
                &sources,
                threads,
                Order2Output::AtPoints {
                    lower: [-1.0; 3],
                    points: &points,
                    feet: &points,
                    reach: 3.0 * h,
                    values: &mut at,
                },
                &mut |_| Control::Continue,
            )
            .unwrap();
            assert_eq!((at[0], at[4]), (0.0, 0.0));
            let far = interpolate(&band, &singles[0], [-1.0; 3], h, &points[2]);
            assert_eq!(at[2].to_bits(), far[0].to_bits());
            assert!((at[2] - 0.5 * std::f64::consts::PI).abs() < 0.02, "{}", at[2]);
        }
        // a source with no inner-tube node near it: an error naming it, no rows
        let off = [[0.0, 0.0, 0.0]];
        let bad = [
            sources[0],
            BatchSource {
                feet: &off,
                slowness: &[1.0],
            },
        ];
        let mut out = vec![0.0; 2 * n];
        let err = solve_many_second_order(&tube, &bad, 2, Order2Output::Band(&mut out), &mut |_| Control::Continue)
            .err()
            .unwrap();
        assert!(err.to_string().contains("source 1"), "{err}");
        // stopped at once: Interrupted
        let err = solve_many_second_order(&tube, &sources, 2, Order2Output::Band(&mut out), &mut |_| Control::Stop);
        assert!(matches!(err, Err(Error::Interrupted { .. })));
    }
}
