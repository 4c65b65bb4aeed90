//! The front window ([`SolveOptions::front_window`]): for the Godunov scheme in 3D, the sweeps
//! accept new values only below a moving edge, `first front + width`, so the early iterations do
//! not update far nodes again and again while the front is still on its way; the edge moves on
//! by the iteration's front (or to the nearest waiting node) and opens fully once no node waits
//! beyond it. The values are those of the plain sweeps' fixed point (docs/architecture.md). The
//! layer nodes in upwind 2-cycles (they read each other) are exempt from the window.

use super::problem::*;
use crate::scheme::hamiltonian::InnerScheme;
use rayon::prelude::*;

/// The default [`SolveOptions::front_window`]: the window is `2 h s̄ sqrt(H)` wide. From 1.5 to 3
/// the sweep times measured within about 20% of each other on the sphere from N = 161 to 1001 and
/// on the library's surfaces at N = 161 (`benches/experiments/front_window_surfaces.py --windows 1,1.5,2,3`;
/// `WINDOW=c cargo run --release --example sphere -- N godunov 2`); narrower windows take more
/// iterations, wider ones more updates.
pub const DEFAULT_FRONT_WINDOW: f64 = 2.0;

impl<'a, const D: usize> SweepProblem<'a, D> {
    /// Whether these options run the front window ([`SolveOptions::front_window`]).
    pub(super) fn windowed(&self, options: &SolveOptions) -> bool {
        D == 3 && options.front_window > 0.0 && options.skip_inactive && matches!(self.scheme, InnerScheme::Godunov)
    }

    /// The extension-layer nodes in an upwind 2-cycle: two layer nodes next to each other along
    /// an axis whose updates (5) read each other (their directions point at each other along
    /// that axis, as where the directions from two sheets of the surface meet). `1` marks them.
    pub(super) fn upwind_two_cycles(&self, weights: &[[f32; D]]) -> Vec<u8> {
        let n = self.roles.len();
        if weights.is_empty() {
            return vec![0u8; n];
        }
        let sentinel = self.band.sentinel();
        let roles = self.roles;
        (0..n)
            .into_par_iter()
            .map(|a| {
                if roles[a] != NodeRole::Outer {
                    return 0u8;
                }
                let nb = self.band.neighbours_of(a);
                let reads_back = |b: u32, k: usize, b_reads_minus: bool| {
                    b != sentinel
                        && roles[b as usize] == NodeRole::Outer
                        && if b_reads_minus {
                            weights[b as usize][k] > 0.0
                        } else {
                            weights[b as usize][k] < 0.0
                        }
                };
                // a reads its plus neighbour when w_a[k] < 0, its minus neighbour when w_a[k] > 0;
                // the plus neighbour reads a (its minus neighbour) when its w[k] > 0, and so on
                let cyclic = (0..D).any(|k| {
                    let w = weights[a][k];
                    (w < 0.0 && reads_back(nb[k][1], k, true)) || (w > 0.0 && reads_back(nb[k][0], k, false))
                });
                cyclic as u8
            })
            .collect()
    }
}
