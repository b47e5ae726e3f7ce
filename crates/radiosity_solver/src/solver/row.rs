//! One shooter's row of form factors F_{j→i} (visibility included) to every receiving
//! element j, as runs of consecutive elements ([`Row`]); with it, what geometry alone decided
//! for a patch shooter ([`Geometry`]) and the receivers that touch it ([`NearField`]). Plain
//! data: a patch's row is computed in `patch_row`, a group's in `clusters::row`, and a shot
//! applies one in `tally`.

use std::ops::Range;

use rayon::prelude::*;

use super::mesh_tables::MeshTables;
use super::parallel::blocks_in_parallel;
use super::plans::PatchPlan;

/// One shooter's form factors F_{j→shooter} (visibility included) to the elements of every
/// patch that can receive from it, as runs of consecutive elements.
pub(super) struct Row {
    /// `(first element, element count)` of each run of whole consecutive receiving patches
    /// (at most [`MAX_RUN`] elements unless one patch has more), in element order. A model's
    /// facets are one-element patches: a span each took twice the memory of their factors.
    pub(super) spans: Vec<(u32, u32)>,
    /// The factors, span after span, in f32 (7 digits, far below the visibility noise); a
    /// row applied fresh is rounded the same way, so keeping it changes nothing.
    pub(super) factors: Vec<f32>,
    /// The receivers that touch the shooter, weighted at each shot by the part of it they
    /// see (see [`NearField`]).
    pub(super) near: NearField,
    /// What geometry alone decided for a patch shooter's row, kept with it when the budget
    /// allows, so that the row computed again after its spread moves traces rays only.
    pub(super) geometry: Option<Box<Geometry>>,
    /// While the row is built: pushes merge only into a span that starts at this element or
    /// later (the first of the block of patches being pushed, see [`Row::by_blocks`]).
    floor: u32,
}

/// The part of a patch shooter's row that geometry alone decides: its receiving patches'
/// plans and every element's form factor without visibility, before any weighting.
///
/// When the shooter's spread is fixed again (see `first_shots`), its ray ends move and its
/// rays are traced again, but none of this changes; a Cornell box's row spends about four
/// fifths of its time here (plans a tenth, form factors nearly half, the near field's shares
/// a quarter), and a third of its rows are such refreshes. The factors are kept in single
/// precision and rounded so wherever they are computed, so a row built from them is the
/// row computed afresh, bit for bit (`tests/suite/fast_paths.rs`).
pub(super) struct Geometry {
    pub(super) plans: Vec<PatchPlan>,
    /// Per mesh element, its unweighted form factor (0 where its patch does not receive or
    /// takes its group's visibility).
    pub(super) unweighted: Vec<f32>,
    /// Heap and inline bytes, counted once: the row cache asks for every kept row's size
    /// whenever it makes room, and the plans' candidate lists would be walked each time.
    bytes: usize,
}

impl Geometry {
    /// Kept geometry of `plans` and the `unweighted` factors, its size counted once.
    pub(super) fn new(plans: Vec<PatchPlan>, unweighted: Vec<f32>) -> Self {
        let bytes = std::mem::size_of::<Self>()
            + plans.len() * std::mem::size_of::<PatchPlan>()
            + 4 * plans.iter().map(|p| p.candidates.len()).sum::<usize>()
            + 4 * unweighted.len();
        Self { plans, unweighted, bytes }
    }

    /// Geometry of `elements` zero factors and no plans, for the cache's tests.
    #[cfg(test)]
    pub(super) fn zeros(elements: usize) -> Self {
        Self::new(Vec::new(), vec![0.0; elements])
    }

    /// What kept geometry costs for a mesh of `patches` and `elements` (at most: candidate
    /// lists aside, a few triangles per patch).
    pub(super) fn estimate(patches: usize, elements: usize) -> usize {
        patches * (std::mem::size_of::<PatchPlan>() + 16) + 4 * elements
    }
}

/// The receiving elements that touch a patch shooter (across or on its plane: a floor strip
/// at the foot of a wall, a wall strip in a room's corner), and how much of each of the
/// shooter's elements each of them sees.
///
/// Such a receiver sees the shooter's near edge under a far larger form factor than the
/// rest, so the patch's mean unshot radiosity is wrong for it whenever the radiosity over
/// the patch is uneven: the transfer is Σ_k ΔB_k F_{j→k} = F_j Σ_k φ_jk ΔB_k, with
/// φ_jk = F_{j→k} / F_j. Weighting by the spread fixed at the patch's first shot missed
/// what changes between shots: an inside corner's indirect light dims towards the corner
/// while the direct light of the first shot does not, and the strips on both sides of the
/// Cornell box's back corners came out 1.5–2.5 % bright (element means against the path
/// tracer). The shares φ are geometry, kept with the row; the weighting is done at each
/// shot with the unshot radiosity the shooter has then (`Tally::shoot`).
#[derive(Default)]
pub(super) struct NearField {
    /// (element, its factor F_j as in the row, first term, term count).
    pub(super) receivers: Vec<(u32, f32, u32, u32)>,
    /// (part of the shooter, share φ), receiver after receiver. A part is one shooter
    /// element, or, flagged by [`CLUSTER_TERM`], a cluster of nearby ones seen from far
    /// enough to count as one (`uneven::cluster_elements`, four radii: the point-to-point
    /// factor is then within ~2 %). Shares below `near_field::MIN_SHARE` are left out and their part
    /// of the shooter counts at its mean.
    pub(super) terms: Vec<(u32, f32)>,
    /// The clusters' elements (mesh indices): cluster c's are
    /// `members[clusters[c].0..clusters[c].1]`.
    pub(super) members: Vec<u32>,
    /// Each cluster's range of `members`.
    pub(super) clusters: Vec<(u32, u32)>,
    /// Σ A_j F_j over the row's other receivers but a model's grouped facets (which take the
    /// mean), which take what the near ones do not.
    pub(super) rest: f64,
}

/// A [`NearField`] term whose part is a cluster (its index with this bit set).
pub(super) const CLUSTER_TERM: u32 = 1 << 31;

impl NearField {
    fn bytes(&self) -> usize {
        16 * self.receivers.len() + 8 * (self.terms.len() + self.clusters.len()) + 4 * self.members.len()
    }
}

/// Receiving patches merge into one span up to this many elements, so that a shot's
/// chunks of spans (see `Tally::shoot`) stay small enough to share among threads.
const MAX_RUN: u32 = 1024;

impl Row {
    /// An empty row.
    pub(super) fn new() -> Self {
        Self { spans: Vec::new(), factors: Vec::new(), near: NearField::default(), geometry: None, floor: 0 }
    }

    /// Appends the factors of a receiving patch whose elements are `elements` (after those
    /// of the patches pushed before it), merging it into the last span when it follows it.
    pub(super) fn push(&mut self, elements: std::ops::Range<usize>, factors: impl IntoIterator<Item = f32>) {
        let (first, count) = (elements.start as u32, elements.len() as u32);
        match self.spans.last_mut() {
            Some((start, n)) if *start >= self.floor && *start + *n == first && *n + count <= MAX_RUN => {
                *n += count
            }
            _ => self.spans.push((first, count)),
        }
        self.factors.extend(factors);
    }

    /// The row that `patch(q, row)` pushes patch after patch (returning a count, summed),
    /// built in the mesh's blocks of patches (see [`super::parallel::patch_blocks`]), on
    /// the thread pool when the mesh is large, and joined in order. A span never crosses a
    /// block, so the row is the same on one thread or many.
    pub(super) fn by_blocks(
        tables: &MeshTables,
        patch: impl Fn(usize, &mut Row) -> u64 + Sync,
    ) -> (Row, u64) {
        let blocks = &tables.patch_blocks;
        let first_element = |b: &Range<usize>| tables.patch_elements[b.start].start as u32;
        if !blocks_in_parallel(tables.element_area.len(), false) {
            // One row grown in place: a small scene's rows need no per-block rows allocated,
            // grown and copied.
            let mut row = Row::new();
            let mut count = 0;
            for b in blocks {
                row.floor = first_element(b);
                count += b.clone().map(|q| patch(q, &mut row)).sum::<u64>();
            }
            row.floor = 0;
            return (row, count);
        }
        let parts: Vec<(Row, u64)> = blocks
            .par_iter()
            .map(|b| {
                let mut row = Row::new();
                row.floor = first_element(b);
                let count = b.clone().map(|q| patch(q, &mut row)).sum::<u64>();
                (row, count)
            })
            .collect();
        let mut row = Row::new();
        row.spans.reserve_exact(parts.iter().map(|p| p.0.spans.len()).sum());
        row.factors.reserve_exact(parts.iter().map(|p| p.0.factors.len()).sum());
        let mut count = 0;
        for (part, n) in parts {
            row.spans.extend(part.spans);
            row.factors.extend(part.factors);
            count += n;
        }
        (row, count)
    }

    /// Heap and inline bytes the row holds.
    pub(super) fn bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + 8 * self.spans.len()
            + 4 * self.factors.len()
            + self.near.bytes()
            + self.geometry.as_ref().map_or(0, |g| g.bytes)
    }
}
