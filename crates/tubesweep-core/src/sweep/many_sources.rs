//! Many independent solves on one band, run in parallel across the sources.
//!
//! Distances from many sources on one surface (all-pairs matrices, farthest-point sampling) need
//! one solve of Algorithm 3 per source on the same band. A single solve at N = 101 is too small to
//! keep two cores busy inside its sweeps; independent solves are not. [`solve_many`] runs each
//! source's solve sequentially (`threads = 1`: the same bits as any thread count, see
//! [`crate::band::schedule`]) and the sources on `threads` worker threads at once, each thread taking
//! the next source when it finishes one (dynamic hand-off, so one slow source does not hold the
//! others back). Each solve is [`SweepProblem::solve`] with the template's band, slowness,
//! extension weights and scheme and the template's roles with the source's nodes made
//! [`NodeRole::Fixed`]: the values of one source are those of a single solve of it, bit for bit.
//!
//! The workers are plain scoped threads, not a rayon pool: every solve starts a one-thread pool
//! of its own (see [`SweepProblem::solve`]), and a rayon worker that waits on another pool steals
//! more work of its own pool meanwhile, which would start more solves (and band-sized arrays)
//! than there are threads. A worker holds one band-sized vector of values and one of roles at a
//! time; with [`Output::AtPoints`] only the values at the points are kept, so the memory is
//! O(band · threads + K · M).

use crate::error::{Error, Result};
use crate::solution::interpolate::interpolate;
use crate::sweep::{Control, IterationReport, NodeRole, SolveOptions, SolveStats, SweepProblem};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Duration;

/// The nodes one source fixes: band positions and their starting values (a point source's
/// exact local distances, or several points' for a multi-source solve).
#[derive(Debug, Clone, Copy)]
pub struct FixedSet<'a> {
    pub positions: &'a [usize],
    pub values: &'a [f64],
}

/// Where the values of each solve go.
pub enum Output<'o, const D: usize> {
    /// Every band value: row `k` of `values` (`K × n`, C order) is source `k`'s solution.
    Band(&'o mut [f64]),
    /// The values interpolated at `points` (`M × D`, flattened) on the grid with lower corner
    /// `lower` (as [`interpolate`]): row `k` of `values` (`K × M`). Nodes never reached count as
    /// `+inf` before the interpolation, as in a solution's values.
    AtPoints {
        lower: [f64; D],
        points: &'o [f64],
        values: &'o mut [f64],
    },
}

/// How often the caller's `progress` is called while the solves run.
const POLL: Duration = Duration::from_millis(50);

/// Solves `template` once per entry of `sources` (the template's roles must hold no
/// [`NodeRole::Fixed`] node; each source's positions become fixed in a copy of them), on
/// `threads` worker threads (0: rayon's default number), each solve with `options` but one
/// thread. Nodes whose value reaches the solve's numerical infinity are set to `+inf`.
///
/// `progress(done)` runs on the calling thread about every 50 ms and once at the end, with the
/// number of finished solves; [`Control::Stop`] stops every solve after its current iteration
/// and the call returns [`Error::Interrupted`]. On any error no statistics are returned and the
/// output is to be discarded (rows may be partly written). Returns each source's statistics.
pub fn solve_many<const D: usize>(
    template: &SweepProblem<'_, D>,
    sources: &[FixedSet<'_>],
    options: &SolveOptions,
    threads: usize,
    mut output: Output<'_, D>,
    progress: &mut dyn FnMut(usize) -> Control,
) -> Result<Vec<SolveStats>> {
    let n = template.band.len();
    let k = sources.len();
    if template.roles.len() != n {
        return Err(Error::invalid(
            "roles",
            format!("expected {n} roles, got {}", template.roles.len()),
        ));
    }
    if template.roles.contains(&NodeRole::Fixed) {
        return Err(Error::invalid(
            "roles",
            "the template's roles must not hold fixed nodes (each source fixes its own)",
        ));
    }
    for (i, s) in sources.iter().enumerate() {
        if s.positions.len() != s.values.len() {
            return Err(Error::invalid(
                "sources",
                format!(
                    "source {i}: {} positions but {} values",
                    s.positions.len(),
                    s.values.len()
                ),
            ));
        }
        if let Some(&p) = s.positions.iter().find(|&&p| p >= n) {
            return Err(Error::invalid(
                "sources",
                format!("source {i}: {p} is not a position in the band of {n} nodes"),
            ));
        }
    }
    let width = match &output {
        Output::Band(v) => {
            if v.len() != k * n {
                return Err(Error::invalid(
                    "values",
                    format!("expected {k} × {n} values, got {}", v.len()),
                ));
            }
            n
        }
        Output::AtPoints { points, values, .. } => {
            if points.len() % D != 0 {
                return Err(Error::invalid(
                    "points",
                    format!("expected {D} coordinates per point, got {} numbers", points.len()),
                ));
            }
            let m = points.len() / D;
            if values.len() != k * m {
                return Err(Error::invalid(
                    "values",
                    format!("expected {k} × {m} values, got {}", values.len()),
                ));
            }
            m
        }
    };
    let one = SolveOptions { threads: 1, ..*options };
    let (rows, at) = match &mut output {
        Output::Band(v) => (&mut **v, None),
        Output::AtPoints { lower, points, values } => (&mut **values, Some((*lower, *points))),
    };
    run_across_sources(
        k,
        width,
        threads,
        rows,
        || template.roles.to_vec(),
        |roles, i, stop, row| {
            let (values, st) = solve_one(template, roles, sources[i], &one, stop)?;
            match at {
                None => row.copy_from_slice(&values),
                Some((lower, points)) => {
                    row.copy_from_slice(&interpolate(template.band, &values, lower, template.spacing, points))
                }
            }
            Ok(st)
        },
        progress,
    )
}

/// The scheduler of [`solve_many`], for any solver: `k` independent solves on `threads` worker
/// threads (0: rayon's default number, at most `k`), each thread taking the next source when it
/// finishes one. A thread starts with `scratch()` (its reusable working memory); `solve(scratch,
/// i, stop, row)` solves source `i`, writes row `i` of `rows` (`k × width`, C order) and returns
/// its statistics, stopping with [`Error::Interrupted`] when `stop` is set (another solve failed,
/// or the caller asked to stop).
///
/// `progress(done)` runs on the calling thread about every 50 ms and once at the end;
/// [`Control::Stop`] stops every solve and the call returns [`Error::Interrupted`]. On any error
/// (the first failing source's, a real error before an interruption) no statistics are returned
/// and `rows` are to be discarded (they may be partly written). A panic in `solve` (a bug) ends
/// the call with an error, not a hang or an abort.
#[allow(clippy::too_many_arguments)]
pub fn run_across_sources<W, S, I, F>(
    k: usize,
    width: usize,
    threads: usize,
    rows: &mut [f64],
    scratch: I,
    solve: F,
    progress: &mut dyn FnMut(usize) -> Control,
) -> Result<Vec<S>>
where
    S: Send,
    I: Fn() -> W + Sync,
    F: Fn(&mut W, usize, &AtomicBool, &mut [f64]) -> Result<S> + Sync,
{
    if rows.len() != k * width {
        return Err(Error::invalid(
            "values",
            format!("expected {k} × {width} values, got {}", rows.len()),
        ));
    }
    if k == 0 {
        progress(0);
        return Ok(Vec::new());
    }
    let threads = if threads == 0 {
        rayon::current_num_threads()
    } else {
        threads
    }
    .clamp(1, k);
    let rows: Vec<Mutex<Option<&mut [f64]>>> = if width == 0 {
        (0..k).map(|_| Mutex::new(None)).collect()
    } else {
        rows.chunks_mut(width).map(|r| Mutex::new(Some(r))).collect()
    };
    let next = AtomicUsize::new(0);
    let done = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    let first_error: Mutex<Option<(usize, Error)>> = Mutex::new(None);
    let results: Vec<Mutex<Option<S>>> = (0..k).map(|_| Mutex::new(None)).collect();
    let mut interrupted = false;
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                let mut work = scratch();
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= k || stop.load(Ordering::Relaxed) {
                        break;
                    }
                    // a panic (a bug) ends this call with an error, not a hang or an abort
                    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                        // the row is taken once, by the one thread that solves source i
                        let mut row = rows.get(i).and_then(|r| r.lock().ok()?.take());
                        let mut empty: [f64; 0] = [];
                        let row: &mut [f64] = match row.as_mut() {
                            Some(r) => r,
                            None => &mut empty,
                        };
                        solve(&mut work, i, &stop, row)
                    }))
                    .unwrap_or_else(|_| {
                        Err(Error::BadBand {
                            message: format!("the solve of source {i} failed unexpectedly (a bug)"),
                        })
                    });
                    match outcome {
                        Ok(st) => {
                            if let Ok(mut slot) = results[i].lock() {
                                *slot = Some(st);
                            }
                            done.fetch_add(1, Ordering::Release);
                        }
                        Err(e) => {
                            // a solve stopped because another failed reports Interrupted: the
                            // failure itself is kept (the first source's, of several)
                            if let Ok(mut first) = first_error.lock() {
                                let real = !matches!(e, Error::Interrupted { .. });
                                let replace = match first.as_ref() {
                                    None => true,
                                    Some((j, f)) => {
                                        let f_real = !matches!(f, Error::Interrupted { .. });
                                        (real && !f_real) || (real == f_real && i < *j)
                                    }
                                };
                                if replace {
                                    *first = Some((i, e));
                                }
                            }
                            stop.store(true, Ordering::Relaxed);
                            break;
                        }
                    }
                }
            });
        }
        // the calling thread reports progress until every worker has finished
        let mut last = usize::MAX;
        loop {
            let d = done.load(Ordering::Acquire);
            let finished = d == k || (stop.load(Ordering::Relaxed) && first_error.lock().map_or(true, |e| e.is_some()));
            if d != last || finished {
                if !interrupted && progress(d) == Control::Stop {
                    interrupted = true;
                    stop.store(true, Ordering::Relaxed);
                }
                last = d;
            }
            if finished || interrupted {
                break;
            }
            std::thread::sleep(POLL);
        }
    });
    if interrupted {
        return Err(Error::Interrupted { iterations: 0 });
    }
    if let Some((_, e)) = first_error.into_inner().unwrap_or(None) {
        return Err(e);
    }
    results
        .into_iter()
        .map(|r| {
            r.into_inner()
                .unwrap_or(None)
                .ok_or(Error::Interrupted { iterations: 0 })
        })
        .collect()
}

/// One source's solve on `roles` (the template's, restored before returning): its nodes fixed
/// and started from their values, every other node from zero as in a single solve (the solver
/// sets them to the numerical infinity); the nodes left at that infinity (never reached) are
/// returned as `+inf`, as a single solve's Python front end does.
fn solve_one<const D: usize>(
    template: &SweepProblem<'_, D>,
    roles: &mut [NodeRole],
    src: FixedSet<'_>,
    options: &SolveOptions,
    stop: &AtomicBool,
) -> Result<(Vec<f64>, SolveStats)> {
    let n = template.band.len();
    // one spare slot for the sentinel the solver appends (as a single solve's starting values)
    let mut values = Vec::with_capacity(n + 1);
    values.resize(n, 0.0);
    for (&p, &v) in src.positions.iter().zip(src.values) {
        values[p] = v;
        roles[p] = NodeRole::Fixed;
    }
    let problem = SweepProblem {
        band: template.band,
        roles,
        spacing: template.spacing,
        slowness: template.slowness,
        extension: template.extension,
        scheme: template.scheme,
        missing: template.missing,
    };
    let mut check = |_: &IterationReport| {
        if stop.load(Ordering::Relaxed) {
            Control::Stop
        } else {
            Control::Continue
        }
    };
    let result = problem.solve(&mut values, options, &mut check);
    for &p in src.positions {
        roles[p] = template.roles[p];
    }
    let st = result?;
    values.truncate(n);
    for v in values.iter_mut() {
        if *v >= st.infinity {
            *v = f64::INFINITY;
        }
    }
    Ok((values, st))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::band::NarrowBand;
    use crate::scheme::hamiltonian::InnerScheme;
    use crate::sweep::{default_row_prefetch_above, Extension, MissingNeighbour, Slowness};

    /// The whole 2D box as a band (Algorithm 1's setting: no layer), point sources at nodes.
    fn square(n: usize) -> NarrowBand<2> {
        NarrowBand::<2>::full_box([n, n]).unwrap()
    }

    fn options() -> SolveOptions {
        SolveOptions {
            tol: 1e-12,
            max_iterations: 100,
            infinity: None,
            threads: 1,
            skip_inactive: true,
            activation_threshold: 0.0,
            coupled: true,
            defer_outer_rim: true,
            front_window: 0.0,
            spread_threads: true,
            row_prefetch_above: default_row_prefetch_above(),
        }
    }

    #[test]
    fn rows_equal_single_solves_bit_for_bit() {
        let band = square(41);
        let n = band.len();
        let roles = vec![NodeRole::Inner; n];
        let template = SweepProblem {
            band: &band,
            roles: &roles,
            spacing: 0.05,
            slowness: Slowness::Constant(1.0),
            extension: Extension::None,
            scheme: InnerScheme::Godunov,
            missing: MissingNeighbour::Infinity,
        };
        let pos: Vec<Vec<usize>> = vec![vec![0], vec![41 * 20 + 20], vec![5, 1600], vec![n - 1]];
        let vals: Vec<Vec<f64>> = pos.iter().map(|p| vec![0.0; p.len()]).collect();
        let sources: Vec<FixedSet> = pos
            .iter()
            .zip(&vals)
            .map(|(p, v)| FixedSet {
                positions: p,
                values: v,
            })
            .collect();
        for threads in [1, 2, 3] {
            let mut out = vec![0.0; sources.len() * n];
            let st = solve_many(
                &template,
                &sources,
                &options(),
                threads,
                Output::Band(&mut out),
                &mut |_| Control::Continue,
            )
            .unwrap();
            assert_eq!(st.len(), sources.len());
            for (i, s) in sources.iter().enumerate() {
                let mut r = roles.clone();
                let mut single = vec![0.0; n];
                for &p in s.positions {
                    r[p] = NodeRole::Fixed;
                }
                let problem = SweepProblem {
                    roles: &r,
                    ..template_clone(&template)
                };
                let one = problem
                    .solve(&mut single, &options(), &mut |_| Control::Continue)
                    .unwrap();
                single.truncate(n);
                for v in single.iter_mut() {
                    if *v >= one.infinity {
                        *v = f64::INFINITY;
                    }
                }
                let row = &out[i * n..(i + 1) * n];
                assert!(
                    row.iter().zip(&single).all(|(a, b)| a.to_bits() == b.to_bits()),
                    "source {i}, {threads} threads"
                );
                assert_eq!(one.iterations, st[i].iterations);
            }
        }
    }

    fn template_clone<'a>(t: &SweepProblem<'a, 2>) -> SweepProblem<'a, 2> {
        SweepProblem {
            band: t.band,
            roles: t.roles,
            spacing: t.spacing,
            slowness: t.slowness,
            extension: t.extension,
            scheme: t.scheme,
            missing: t.missing,
        }
    }

    #[test]
    fn values_at_points_and_stop() {
        let band = square(21);
        let n = band.len();
        let roles = vec![NodeRole::Inner; n];
        let template = SweepProblem {
            band: &band,
            roles: &roles,
            spacing: 0.1,
            slowness: Slowness::Constant(1.0),
            extension: Extension::None,
            scheme: InnerScheme::Godunov,
            missing: MissingNeighbour::Infinity,
        };
        let pos = [vec![0usize], vec![n - 1]];
        let vals = [vec![0.0], vec![0.0]];
        let sources: Vec<FixedSet> = pos
            .iter()
            .zip(&vals)
            .map(|(p, v)| FixedSet {
                positions: p,
                values: v,
            })
            .collect();
        // the corner nodes themselves: the values there are the fixed ones and the far corner's
        let points = [0.0, 0.0, 2.0, 2.0];
        let mut out = vec![0.0; 4];
        solve_many(
            &template,
            &sources,
            &options(),
            2,
            Output::AtPoints {
                lower: [0.0, 0.0],
                points: &points,
                values: &mut out,
            },
            &mut |_| Control::Continue,
        )
        .unwrap();
        assert_eq!(out[0], 0.0);
        assert_eq!(out[3], 0.0);
        assert!((out[1] - 2.0 * 2f64.sqrt()).abs() < 0.3, "{}", out[1]);
        assert_eq!(out[1].to_bits(), out[2].to_bits());
        // a caller that stops at once gets Interrupted, never a partial result
        let mut out = vec![0.0; 4];
        let err = solve_many(
            &template,
            &sources,
            &options(),
            2,
            Output::AtPoints {
                lower: [0.0, 0.0],
                points: &points,
                values: &mut out,
            },
            &mut |_| Control::Stop,
        );
        assert!(matches!(err, Err(Error::Interrupted { .. })));
        // a bad position is refused before anything runs
        let bad = [FixedSet {
            positions: &[n],
            values: &[0.0],
        }];
        let mut out = vec![0.0; n];
        assert!(
            solve_many(&template, &bad, &options(), 1, Output::Band(&mut out), &mut |_| {
                Control::Continue
            })
            .is_err()
        );
        let mut out: Vec<f64> = Vec::new();
        assert!(
            solve_many(&template, &[], &options(), 1, Output::Band(&mut out), &mut |_| {
                Control::Continue
            })
            .unwrap()
            .is_empty()
        );
    }
}
