//! Loops over receivers that run on the thread pool only when there is enough work. Each item
//! is written by exactly one call, so one thread and many give the same numbers.
//!
//! The loops over every patch of a row (a million-facet model has a million patches) run in
//! fixed blocks of consecutive patches ([`patch_blocks`]): the blocks are a property of the
//! mesh, not of the thread count, so sums taken per block and then added in block order are
//! the same numbers on one thread or many.

use std::ops::Range;

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

/// Items per run of [`for_each_run_maybe_parallel`].
const RUN: usize = 64;

/// `f(first index, run)` for consecutive runs of [`RUN`] items (the last may be shorter), on
/// the thread pool when there are enough items: per-item work whose scratch is too large to
/// set up for each item sets it up once per run. Each item is in exactly one run, so the
/// result is the same either way.
pub(super) fn for_each_run_maybe_parallel<T: Send>(
    items: &mut [T],
    f: impl Fn(usize, &mut [T]) + Sync + Send,
) {
    if items.len() < PARALLEL_MIN || rayon::current_num_threads() == 1 {
        items.chunks_mut(RUN).enumerate().for_each(|(c, run)| f(c * RUN, run));
    } else {
        items.par_chunks_mut(RUN).enumerate().for_each(|(c, run)| f(c * RUN, run));
    }
}

/// A mesh is cut into about this many blocks...
const BLOCKS: usize = 256;

/// ... of at least this many elements each (unless it is the last, or the mesh is small: see
/// [`patch_blocks`]): a pass over a block of cheap per-element work (gathering a row,
/// summing its power) then outweighs handing the block to a thread.
const BLOCK_ELEMENTS: usize = 2048;

/// Below this many elements the cheap per-patch passes run on the calling thread: they take
/// a few microseconds there (the Cornell box's 11 k elements), less than the pool's
/// hand-over. The same bound as applying a shot (`tally`).
const BLOCKS_PARALLEL_MIN: usize = 32_768;

/// Consecutive patches cut into blocks of whole patches, in patch order: [`BLOCKS`] blocks
/// of [`PARALLEL_MIN`] to [`BLOCK_ELEMENTS`] elements each (a small mesh's blocks are small,
/// so that its costly passes, the form factors and rays of a row, still spread over the
/// threads). `patch_elements` are the patches' element ranges, each following the one
/// before.
pub(super) fn patch_blocks(patch_elements: &[Range<usize>]) -> Vec<Range<usize>> {
    let total: usize = patch_elements.iter().map(|r| r.len()).sum();
    let size = (total / BLOCKS).clamp(PARALLEL_MIN, BLOCK_ELEMENTS);
    let mut blocks = Vec::new();
    let (mut start, mut count) = (0, 0);
    for (q, range) in patch_elements.iter().enumerate() {
        count += range.len();
        if count >= size {
            blocks.push(start..q + 1);
            (start, count) = (q + 1, 0);
        }
    }
    if start < patch_elements.len() {
        blocks.push(start..patch_elements.len());
    }
    blocks
}

/// Whether a pass over `elements` elements is worth the thread pool: `costly` passes (form
/// factors and rays) from [`PARALLEL_MIN`] elements, cheap ones from
/// [`BLOCKS_PARALLEL_MIN`].
pub(super) fn blocks_in_parallel(elements: usize, costly: bool) -> bool {
    let min = if costly { PARALLEL_MIN } else { BLOCKS_PARALLEL_MIN };
    elements >= min && rayon::current_num_threads() > 1
}

/// `f(patches)` for every block of `blocks`, results in block order; on the thread pool when
/// the mesh has enough `elements` for cheap work.
pub(super) fn map_blocks<R: Send>(
    blocks: &[Range<usize>],
    elements: usize,
    f: impl Fn(Range<usize>) -> R + Sync + Send,
) -> Vec<R> {
    if blocks_in_parallel(elements, false) {
        blocks.par_iter().map(|b| f(b.clone())).collect()
    } else {
        blocks.iter().map(|b| f(b.clone())).collect()
    }
}

/// `f(patches, their elements' items)` for every block of `blocks`, where `items` holds one
/// item per element (`patch_elements` give each patch's); on the thread pool when there are
/// enough items for work as `costly` as it is. Each item is in exactly one block, so the
/// result is the same either way.
pub(super) fn for_each_block_mut<T: Send>(
    blocks: &[Range<usize>],
    patch_elements: &[Range<usize>],
    items: &mut [T],
    costly: bool,
    f: impl Fn(Range<usize>, &mut [T]) + Sync + Send,
) {
    let elements_of = |b: &Range<usize>| match (b.clone().next(), b.clone().last()) {
        (Some(first), Some(last)) => patch_elements[first].start..patch_elements[last].end,
        _ => 0..0,
    };
    if !blocks_in_parallel(items.len(), costly) {
        for b in blocks {
            f(b.clone(), &mut items[elements_of(b)]);
        }
        return;
    }
    let mut items = Carve::new(items);
    let parts: Vec<(Range<usize>, &mut [T])> =
        blocks.iter().map(|b| (b.clone(), items.take(elements_of(b)))).collect();
    parts.into_par_iter().for_each(|(b, items)| f(b, items));
}

/// Cuts a slice into disjoint mutable pieces, given in increasing order by their ranges in the
/// whole slice, so that each can go to its own task.
pub(super) struct Carve<'a, T> {
    rest: &'a mut [T],
    /// Index in the whole slice of `rest[0]`.
    at: usize,
}

impl<'a, T> Carve<'a, T> {
    /// Ready to cut `whole`.
    pub(super) fn new(whole: &'a mut [T]) -> Self {
        Self { rest: whole, at: 0 }
    }

    /// The piece `range` of the whole slice; what lies before it is dropped.
    ///
    /// # Panics
    /// When `range` starts before the end of the last piece taken or runs past the slice.
    pub(super) fn take(&mut self, range: Range<usize>) -> &'a mut [T] {
        let (own, after) = std::mem::take(&mut self.rest)[range.start - self.at..].split_at_mut(range.len());
        (self.rest, self.at) = (after, range.end);
        own
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Patches of `sizes` elements each, one after the other.
    fn ranges(sizes: &[usize]) -> Vec<Range<usize>> {
        let mut at = 0;
        sizes
            .iter()
            .map(|&n| {
                at += n;
                at - n..at
            })
            .collect()
    }

    #[test]
    fn blocks_cover_every_patch_once_in_order() {
        let sizes: Vec<usize> = (0..5000).map(|q| 1 + (q * 7919) % 13).collect();
        let patches = ranges(&sizes);
        let blocks = patch_blocks(&patches);
        assert!(blocks.len() > 1);
        let mut next = 0;
        for (i, b) in blocks.iter().enumerate() {
            assert_eq!(b.start, next, "block {i} starts where the last ended");
            assert!(b.end > b.start);
            let elements: usize = sizes[b.clone()].iter().sum();
            if i + 1 < blocks.len() {
                assert!(elements >= PARALLEL_MIN, "block {i} holds {elements} elements");
            }
            next = b.end;
        }
        assert_eq!(next, patches.len());
        assert!(patch_blocks(&[]).is_empty());
    }

    #[test]
    fn every_element_is_visited_once_on_one_thread_or_many() {
        let sizes: Vec<usize> = (0..40_000).map(|q| 1 + q % 4).collect();
        let patches = ranges(&sizes);
        let blocks = patch_blocks(&patches);
        let total: usize = sizes.iter().sum();
        assert!(total >= BLOCKS_PARALLEL_MIN, "the test must take the parallel path");
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let mut items = vec![0usize; total];
            pool.install(|| {
                for_each_block_mut(&blocks, &patches, &mut items, false, |b, items| {
                    let first = patches[b.start].start;
                    for (k, item) in items.iter_mut().enumerate() {
                        *item += first + k + 1;
                    }
                });
            });
            let sums = pool.install(|| map_blocks(&blocks, total, |b| sizes[b].iter().sum::<usize>()));
            (items, sums)
        };
        let (one, sums_one) = run(1);
        assert_eq!(one, (1..=total).collect::<Vec<_>>());
        assert_eq!(run(2), (one, sums_one.clone()));
        assert_eq!(sums_one.iter().sum::<usize>(), total);
    }
}
