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
    {
        let end = end.min(len);
        let size = std::mem::size_of::<T>();
        if start >= end || size == 0 {
            return;
        }
        let first = base as usize + start * size;
        let last = base as usize + end * size - 1;
        let mut line = first & !(CACHE_LINE - 1);
        while line <= last {
            // SAFETY: prefetching is a hint with no effect on memory; the lines overlap the
            // elements, and even an invalid address would not fault
            unsafe { std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(line as *const i8) };
            line += CACHE_LINE;
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (base, len, start, end);
}

/// The cache-line size of x86-64 processors.
#[cfg(target_arch = "x86_64")]
const CACHE_LINE: usize = 64;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prefetching_any_range_reads_and_changes_nothing() {
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
