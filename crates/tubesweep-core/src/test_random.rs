//! A reproducible pseudo-random sequence for the unit tests: Knuth's 64-bit linear congruential
//! generator (MMIX constants), its top 53 bits as a uniform number in [0, 1).

/// The next uniform number of the sequence whose state is `state`.
pub(crate) fn next_uniform(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// The sequence from `seed`, as a closure.
pub(crate) fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || next_uniform(&mut state)
}
