//! Software prefetch hints: requests that the processor fetch memory into cache before it is
//! read. A hint has no effect on memory and cannot fault, so a wrong guess costs only the
//! instruction and the cache space; on other architectures than x86-64 nothing happens.

/// Asks the processor to fetch the cache line holding `x`.
#[inline(always)]
pub(crate) fn prefetch<T>(x: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: prefetching is a hint with no effect on memory; the pointer is valid
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>((x as *const T).cast());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}

/// Asks the processor to fetch every cache line of `slice[start..end]` (`end` clamped to the
/// slice's length; nothing when the range is empty).
#[inline(always)]
pub(crate) fn prefetch_range<T>(slice: &[T], start: usize, end: usize) {
    prefetch_raw_range(slice.as_ptr(), slice.len(), start, end);
}

/// [`prefetch_range`] for the `len` elements at `base`, which other threads may be writing
/// (no reference to them is formed).
#[inline(always)]
pub(crate) fn prefetch_raw_range<T>(base: *const T, len: usize, start: usize, end: usize) {
    #[cfg(target_arch = "x86_64")]
    if let Some((first, lines)) = cache_lines(base as usize, std::mem::size_of::<T>(), len, start, end) {
        for k in 0..lines {
            // SAFETY: prefetching is a hint with no effect on memory; the lines overlap the
            // elements `start..end`, and even an invalid address would not fault
            unsafe {
                std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(
                    (first + k * CACHE_LINE) as *const i8,
                )
            };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (base, len, start, end);
}

/// The cache lines that hold the elements `start..end` (`end` clamped to `len`) of an array of
/// `len` elements of `size` bytes at address `base`: the first line's address and how many.
/// `None` when the range is empty or the elements have no size.
#[inline(always)]
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]
fn cache_lines(base: usize, size: usize, len: usize, start: usize, end: usize) -> Option<(usize, usize)> {
    let end = end.min(len);
    if start >= end || size == 0 {
        return None;
    }
    let first = (base + start * size) & !(CACHE_LINE - 1);
    let last = (base + end * size - 1) & !(CACHE_LINE - 1);
    Some((first, (last - first) / CACHE_LINE + 1))
}

/// The cache-line size of x86-64 processors (and the unit of [`cache_lines`] elsewhere).
const CACHE_LINE: usize = 64;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_range_covers_the_lines_of_its_elements_and_nothing_past_the_array() {
        // 8-byte elements at an address 8 bytes into a line
        let base = 0x1000 + 8;
        assert_eq!(cache_lines(base, 8, 100, 0, 1), Some((0x1000, 1)));
        assert_eq!(cache_lines(base, 8, 100, 0, 7), Some((0x1000, 1)));
        assert_eq!(cache_lines(base, 8, 100, 0, 8), Some((0x1000, 2)));
        assert_eq!(cache_lines(base, 8, 100, 7, 9), Some((0x1040, 1)));
        assert_eq!(cache_lines(base, 8, 100, 3, 40), Some((0x1000, 6)));
        // the end is clamped to the array
        assert_eq!(
            cache_lines(base, 8, 100, 90, 10_000),
            cache_lines(base, 8, 100, 90, 100)
        );
        assert_eq!(cache_lines(base, 8, 100, 90, 100), Some((0x1000 + 11 * 64, 2)));
        // empty, reversed, past the end, zero-sized
        for (s, e) in [(0, 0), (5, 5), (7, 3), (100, 200)] {
            assert_eq!(cache_lines(base, 8, 100, s, e), None);
        }
        assert_eq!(cache_lines(base, 0, 100, 0, 10), None);
        // one-byte flags and 12-byte weights
        assert_eq!(cache_lines(0x2000, 1, 1000, 60, 70), Some((0x2000, 2)));
        assert_eq!(cache_lines(0x2000, 12, 1000, 5, 11), Some((0x2000, 3)));
    }

    #[test]
    fn prefetching_any_range_changes_nothing() {
        let v: Vec<f64> = (0..1000).map(|i| i as f64).collect();
        for (s, e) in [(0, 0), (0, 1), (3, 17), (500, 2000), (999, 1000), (1000, 1000), (7, 3)] {
            prefetch_range(&v, s, e);
        }
        prefetch(&v[10]);
        let empty: [u8; 0] = [];
        prefetch_range(&empty, 0, 5);
        assert!(v.iter().enumerate().all(|(i, &x)| x == i as f64));
    }
}
