//! Loops over receivers that run on the thread pool only when there is enough work. Each item
//! is written by exactly one call, so one thread and many give the same numbers.

use rayon::prelude::*;

/// Below this many items a loop runs on the calling thread: handing a job to the pool and
/// waiting for it costs tens of microseconds, more than a few dozen receivers take (the
/// source document's 145 facets are still worth two threads).
pub(super) const PARALLEL_MIN: usize = 64;

/// `f(index, item)` for every item, on the thread pool when there are enough items. Each item
/// is written by exactly one call, so the result is the same either way.
pub(super) fn for_each_maybe_parallel<T: Send>(items: &mut [T], f: impl Fn(usize, &mut T) + Sync + Send) {
    if items.len() < PARALLEL_MIN || rayon::current_num_threads() == 1 {
        items.iter_mut().enumerate().for_each(|(i, x)| f(i, x));
    } else {
        items.par_iter_mut().enumerate().with_min_len(64).for_each(|(i, x)| f(i, x));
    }
}
