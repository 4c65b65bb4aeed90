//! The parallel, skipping, prefetching and strip-pipelined sweeps give the bits of the plain sequential sweep.

use super::*;

/// Solves `p` with 1 thread and with each of `threads`, asserting the same iterations, local
/// updates and bits; returns the one-thread solution.
fn assert_same_bits_for_threads(p: &SweepProblem<'_, 3>, threads: &[usize]) -> Vec<f64> {
    let run = |threads: usize| {
        let mut u = vec![0.0; p.band.len()];
        let st = p
            .solve(
                &mut u,
                &SolveOptions {
                    threads,
                    ..Default::default()
                },
                &mut |_| Control::Continue,
            )
            .unwrap();
        assert!(st.converged);
        (u, st.iterations, st.updates)
    };
    let (a, ia, ua) = run(1);
    for &t in threads {
        let (b, ib, ub) = run(t);
        assert_eq!((ia, ua), (ib, ub));
        assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()));
    }
    a
}

// elsewhere the sweeps never prefetch (`row_prefetch_ahead`), so there is nothing to count
#[cfg(target_arch = "x86_64")]
#[test]
fn a_constant_slowness_gives_the_bits_of_the_same_slowness_given_per_node() {
    // The kernel takes h/F once per row for a constant slowness and h·s[n] at every node for
    // a per-node one (`NodeArrays::h_times_slowness`): the same product, so the same bits.
    let (band, roles, dirs, h) = sphere_band(41);
    let c = 0.7;
    let per_node = vec![c; band.len()];
    for (scheme, coupled, skip_inactive, front_window) in [
        (InnerScheme::Godunov, true, true, DEFAULT_FRONT_WINDOW),
        (InnerScheme::Godunov, false, true, 0.0),
        (InnerScheme::Godunov, false, false, 0.0),
        (InnerScheme::LaxFriedrichs, false, true, 0.0),
    ] {
        for threads in [1, 2] {
            let opts = SolveOptions {
                threads,
                coupled,
                skip_inactive,
                front_window,
                ..Default::default()
            };
            let solve = |slowness| {
                let p = SweepProblem {
                    slowness,
                    ..sphere_problem(&band, &roles, &dirs, h, scheme)
                };
                let mut u = vec![0.0; band.len()];
                let st = p.solve(&mut u, &opts, &mut |_| Control::Continue).unwrap();
                assert!(st.converged);
                (u, st.updates)
            };
            let (a, ua) = solve(Slowness::Constant(c));
            let (b, ub) = solve(Slowness::PerNode(&per_node));
            assert_eq!(ua, ub);
            assert!(
                a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()),
                "{coupled} {skip_inactive} {threads}"
            );
            // and the slowness counts: unit speed gives other values
            let (one, _) = solve(Slowness::Constant(1.0));
            assert!(a.iter().zip(&one).any(|(x, y)| x != y));
        }
    }
}

#[test]
fn prefetching_the_rows_ahead_gives_the_same_bits_and_follows_the_visited_bytes() {
    let (band, roles, dirs, h) = sphere_band(41);
    let p = sphere_problem(&band, &roles, &dirs, h, InnerScheme::Godunov);
    // plain sweeps, the flags without and with the front window, Lax–Friedrichs; 1 and 2
    // threads; the rows fetched ahead in every iteration or in none
    let cases = [
        (InnerScheme::Godunov, false, 0.0),
        (InnerScheme::Godunov, true, 0.0),
        (InnerScheme::Godunov, true, DEFAULT_FRONT_WINDOW),
        (InnerScheme::LaxFriedrichs, true, 0.0),
    ];
    for (scheme, skip_inactive, front_window) in cases {
        let p = sphere_problem(&band, &roles, &dirs, h, scheme);
        for threads in [1, 2] {
            let run = |above: usize| {
                let opts = SolveOptions {
                    threads,
                    skip_inactive,
                    front_window,
                    row_prefetch_above: above,
                    ..Default::default()
                };
                let mut u = vec![0.0; band.len()];
                let st = p.solve(&mut u, &opts, &mut |_| Control::Continue).unwrap();
                assert!(st.converged);
                (u, st)
            };
            let (a, sa) = run(usize::MAX);
            let (b, sb) = run(0);
            assert_eq!(sa.prefetch_iterations, 0);
            // every iteration of sweeps but the rim's pass (counted as one more) and, with
            // the window, the first (which counts no visited rows before it)
            assert!(
                sb.prefetch_iterations + 2 >= sb.iterations && sb.prefetch_iterations < sb.iterations,
                "{sb:?}"
            );
            assert_eq!((sa.iterations, sa.updates), (sb.iterations, sb.updates));
            assert!(
                a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()),
                "{skip_inactive} {front_window} {threads}"
            );
        }
    }
    // The bound against the rows visited: per node the value, role and neighbour table, the
    // upwind weights, and where the solve has them the active flag, the coupling mask and a
    // per-node slowness.
    use std::mem::size_of;
    let bytes = |flags: bool, coupled: bool, per_node: bool| {
        size_of::<f64>()
            + size_of::<NodeRole>()
            + 2 * 2 * size_of::<u32>()
            + size_of::<u8>()
            + size_of::<[f32; 3]>()
            + usize::from(flags) * size_of::<AtomicU8>()
            + usize::from(coupled) * size_of::<u8>()
            + usize::from(per_node) * size_of::<f64>()
    };
    assert_eq!(bytes(false, false, false), 38);
    let ones = vec![1.0; band.len()];
    let per_node = SweepProblem {
        slowness: Slowness::PerNode(&ones),
        ..sphere_problem(&band, &roles, &dirs, h, InnerScheme::Godunov)
    };
    let n = band.len();
    let count = |p: &SweepProblem<'_, 3>, opts: SolveOptions| {
        let mut u = vec![0.0; n];
        let st = p.solve(&mut u, &opts, &mut |_| Control::Continue).unwrap();
        assert!(st.converged && st.iterations > 3);
        (st.prefetch_iterations, st.iterations)
    };
    let base = SolveOptions {
        threads: 1,
        front_window: 0.0,
        ..Default::default()
    };
    // The plain sweeps visit every row in every sweep: every iteration of sweeps (all but
    // the rim's pass, counted as one more) prefetches when the band's bytes exceed the bound,
    // none when they do not.
    for (p, coupled, slow) in [(&p, false, false), (&per_node, true, true)] {
        let swept = n * bytes(false, coupled, slow);
        let opts = SolveOptions {
            skip_inactive: false,
            coupled,
            ..base
        };
        let (k, it) = count(
            p,
            SolveOptions {
                row_prefetch_above: swept - 1,
                ..opts
            },
        );
        assert_eq!(k, it - 1, "coupled {coupled}, per-node slowness {slow}");
        assert_eq!(
            count(
                p,
                SolveOptions {
                    row_prefetch_above: swept,
                    ..opts
                }
            )
            .0,
            0
        );
    }
    // With the flags the first iteration is taken to visit every row, and the later ones
    // count the rows that ran, fewer: just below the band's bytes only the first prefetches.
    let swept = n * bytes(true, true, true);
    let opts = SolveOptions {
        skip_inactive: true,
        coupled: true,
        ..base
    };
    assert_eq!(
        count(
            &per_node,
            SolveOptions {
                row_prefetch_above: swept - 1,
                ..opts
            }
        )
        .0,
        1
    );
    assert_eq!(
        count(
            &per_node,
            SolveOptions {
                row_prefetch_above: swept,
                ..opts
            }
        )
        .0,
        0
    );
    // With the front window the first iteration counts no row, so even a bound of 0 lets
    // it and the rim's pass go without; every other iteration visits rows and prefetches.
    let opts = SolveOptions {
        front_window: DEFAULT_FRONT_WINDOW,
        row_prefetch_above: 0,
        ..base
    };
    let (k, it) = count(&p, opts);
    assert_eq!(k, it - 2);
    // a 2D box (no extension layer, so no weights; Lax–Friedrichs, which reads its own
    // value next to the box's sides): the same bits, every iteration prefetching
    let n2 = 61;
    let box2 = NarrowBand::<2>::full_box([n2, n2]).unwrap();
    let mut roles2 = vec![NodeRole::Inner; box2.len()];
    roles2[box2.find([30, 20]).unwrap()] = NodeRole::Fixed;
    for scheme in [InnerScheme::Godunov, InnerScheme::LaxFriedrichs] {
        let p2 = box_problem(&box2, &roles2, scheme, 1.0 / (n2 - 1) as f64);
        let run = |above: usize| {
            let mut u = vec![0.0; box2.len()];
            let st = p2
                .solve(
                    &mut u,
                    &SolveOptions {
                        row_prefetch_above: above,
                        ..Default::default()
                    },
                    &mut |_| Control::Continue,
                )
                .unwrap();
            assert!(st.converged);
            (u, st)
        };
        let ((a, sa), (b, sb)) = (run(usize::MAX), run(0));
        assert_eq!((sa.prefetch_iterations, sb.prefetch_iterations), (0, sb.iterations));
        assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()));
    }
}

#[test]
fn parallel_and_skipping_sweeps_are_bit_identical_to_the_plain_sequential_sweep() {
    let (band, roles, dirs, h) = sphere_band(41);
    for (scheme, coupled) in [
        (InnerScheme::Godunov, true),
        (InnerScheme::Godunov, false),
        (InnerScheme::LaxFriedrichs, false),
    ] {
        let p = sphere_problem(&band, &roles, &dirs, h, scheme);
        let mut results = Vec::new();
        for (threads, skip) in [(1, false), (1, true), (2, true), (4, true), (2, false)] {
            // the front window only runs with skipping: compared with plain sweeps without it
            // (its own test is `the_front_window_reaches_the_same_fixed_point_with_fewer_updates`)
            let opts = SolveOptions {
                threads,
                skip_inactive: skip,
                coupled,
                front_window: 0.0,
                ..Default::default()
            };
            let mut u = vec![0.0; band.len()];
            let st = p.solve(&mut u, &opts, &mut |_| Control::Continue).unwrap();
            assert!(st.converged);
            results.push((u, st));
        }
        let (u0, s0) = &results[0];
        // plain sweeps on two threads: the sequential bits and the same count of updates
        let (u_plain, s_plain) = &results[4];
        assert_eq!((s_plain.iterations, s_plain.updates), (s0.iterations, s0.updates));
        assert!(u_plain.iter().zip(u0).all(|(a, b)| a.to_bits() == b.to_bits()));
        // without the rim phase, every node but the fixed ones and the layer nodes without
        // an upwind neighbour, in every one of the 2^3 sweeps of every iteration
        let weights = p.upwind_weights();
        let updated = (0..band.len())
            .filter(|&i| roles[i] != NodeRole::Fixed && weights.get(i).is_none_or(|w| !w[0].is_nan()))
            .count() as u64;
        let opts = SolveOptions {
            threads: 2,
            skip_inactive: false,
            coupled,
            defer_outer_rim: false,
            front_window: 0.0,
            ..Default::default()
        };
        let mut u = vec![0.0; band.len()];
        let st = p.solve(&mut u, &opts, &mut |_| Control::Continue).unwrap();
        assert!(st.converged && st.iterations > 2);
        assert_eq!(st.updates, updated * 8 * st.iterations as u64);
        // every thread count with skipping: bit-identical
        let (u1, s1) = &results[1];
        for (u, s) in &results[2..4] {
            assert_eq!(s.iterations, s1.iterations);
            assert!(u.iter().zip(u1).all(|(a, b)| a.to_bits() == b.to_bits()));
        }
        // skipping against plain sweeps: bit-identical for the pointwise update; the coupled
        // Godunov update re-evaluated with unchanged neighbours may round an ulp lower
        assert_eq!(s1.iterations, s0.iterations);
        if coupled {
            let diff = u1.iter().zip(u0).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            assert!(diff < 1e-13, "{diff}");
        } else {
            assert!(u1.iter().zip(u0).all(|(a, b)| a.to_bits() == b.to_bits()));
        }
        // skipping saves work
        assert!(
            results[1].1.updates < s0.updates,
            "{} vs {}",
            results[1].1.updates,
            s0.updates
        );
        // on the sphere the solution is close to the great-circle distance
        let far = band.find([30, 20, 20]).unwrap();
        eprintln!("far {}", u0[far]);
        assert!((u0[far] - std::f64::consts::PI * 0.5).abs() < 0.2, "{}", u0[far]);
    }
}

#[test]
fn the_strip_pipeline_gives_the_bits_of_the_sequential_sweep() {
    // large enough for many strips per orientation and waves of several tiles; 3 threads take strips out of step with the 2 leading axes
    let (band, roles, dirs, h) = sphere_band(121);
    let sched = band.schedule();
    for lead in 0..4 {
        assert!(sched.strips(lead).len() > 6);
        assert!(sched.waves(lead).windows(2).any(|w| w[1] - w[0] >= 4));
    }
    let p = sphere_problem(&band, &roles, &dirs, h, InnerScheme::Godunov);
    assert_same_bits_for_threads(&p, &[2, 3]);
}

/// A source on the sphere at (−0.5, 0, 0) sends its front across the first axis, one at
/// (0, −0.5, 0) across the second, and one at (0, 0, −0.5) across the rows' own axis: the
/// parallel sweeps pick strips thin across the first, thin across the second, and square
/// tiles, and the values are the sequential sweep's bits every time.
#[test]
fn strips_thin_across_the_front_are_picked_per_iteration_and_keep_the_sequential_bits() {
    let n = 81usize;
    for axis in 0..3 {
        let (band, mut roles, dirs, h) = shell_band(n, 0.5, &[0.0]);
        let mut at = [(n / 2) as i64; 3];
        at[axis] = (n / 4) as i64;
        roles[band.find(at).unwrap()] = NodeRole::Fixed;
        let p = sphere_problem(&band, &roles, &dirs, h, InnerScheme::Godunov);
        let (u1, s1) = converged(
            &p,
            SolveOptions {
                threads: 1,
                ..Default::default()
            },
        );
        assert_eq!(s1.thin_strip_iterations, [0, 0], "one thread runs the sequential sweep");
        for threads in [2, 3] {
            let (u, s) = converged(
                &p,
                SolveOptions {
                    threads,
                    ..Default::default()
                },
            );
            assert!(
                u.iter().zip(&u1).all(|(a, b)| a.to_bits() == b.to_bits()),
                "source on axis {axis}, {threads} threads"
            );
            assert_eq!((s.iterations, s.updates), (s1.iterations, s1.updates));
            let thin = s.thin_strip_iterations;
            match axis {
                2 => assert_eq!(thin, [0, 0]),
                _ => {
                    assert!(
                        2 * thin[axis] > s.iterations,
                        "axis {axis}: {thin:?} of {}",
                        s.iterations
                    );
                    assert_eq!(thin[1 - axis], 0, "axis {axis}: {thin:?}");
                }
            }
        }
    }
}

#[test]
fn the_strip_pipeline_gives_the_sequential_bits_across_missing_strips_and_on_an_empty_band() {
    // two spheres apart along the first axis: whole strips of tiles between them are empty,
    // so the tiles next to the gap have no upstream tile
    let n = 97usize;
    let (r0, centres) = (0.22, [-0.55, 0.55]);
    let (band, mut roles, dirs, h) = shell_band(n, r0, &centres);
    for c in centres {
        let i = ((c - r0 + 1.0) / h).round() as i64;
        let src = band.find([i, (n / 2) as i64, (n / 2) as i64]).unwrap();
        roles[src] = NodeRole::Fixed;
    }
    // the gap: some strip follows a strip that is not its neighbour along the first axis
    let sched = band.schedule();
    let (strip_tiles, strips, upstream) = (sched.strip_tiles(0), sched.strips(0), sched.upstream(0));
    let strips_without_upstream = (0..strips.len() - 1)
        .filter(|&s| {
            strip_tiles[strips[s] as usize..strips[s + 1] as usize]
                .iter()
                .all(|&t| upstream[t as usize] == NO_TILE)
        })
        .count();
    assert!(strips_without_upstream >= 2, "{strips_without_upstream}");
    let p = sphere_problem(&band, &roles, &dirs, h, InnerScheme::Godunov);
    let a = assert_same_bits_for_threads(&p, &[2, 3]);
    assert!(a.iter().all(|v| v.is_finite() && *v < 2.0));
    // an empty band solves to nothing, in parallel too
    let empty = NarrowBand::<3>::from_sorted_linear([9, 9, 9], &[]).unwrap();
    let p = SweepProblem {
        band: &empty,
        roles: &[],
        spacing: 0.25,
        slowness: Slowness::Constant(1.0),
        extension: Extension::None,
        scheme: InnerScheme::Godunov,
        missing: MissingNeighbour::Extrapolate,
    };
    for threads in [1, 2] {
        let mut u = Vec::new();
        let st = p
            .solve(
                &mut u,
                &SolveOptions {
                    threads,
                    ..Default::default()
                },
                &mut |_| Control::Continue,
            )
            .unwrap();
        assert!(st.converged && u.is_empty());
    }
}
