//! Rows kept across shots. A patch shoots several times as light comes back to it; its rays
//! come from a stream keyed by the shooter and end where its unshot power was at its first
//! shot, so each of its shots has the same row of form factors. The row is kept (within
//! `SolverParams::row_cache_bytes`) and a later shot is one multiply-add per receiver; past
//! the budget, the row's patch plans (geometry only) are kept instead, up to
//! [`PLAN_CACHE_ENTRIES`].

use super::SolverParams;
use super::plans::{PatchPlan, plan_entries};
use super::row::Row;

/// Most plan entries (receiving patches plus candidate triangles) kept across shots: about
/// 40 MB, every shooter's row for a scene of a thousand patches.
const PLAN_CACHE_ENTRIES: usize = 1 << 20;

/// Each shooter's kept row, or its kept plans.
pub(super) struct RowCache {
    /// Each shooter's form factors to its receivers, kept up to `params.row_cache_bytes`.
    rows: Vec<Option<Row>>,
    row_bytes: usize,
    /// Plans depend on geometry only, so each shooter's plans are kept for its next shots
    /// when its form factors are not, up to [`PLAN_CACHE_ENTRIES`] in all.
    plans: Vec<Option<Box<[PatchPlan]>>>,
    plan_entries: usize,
}

impl RowCache {
    /// Nothing kept, for `patches` shooters.
    pub(super) fn new(patches: usize) -> Self {
        Self {
            rows: (0..patches).map(|_| None).collect(),
            row_bytes: 0,
            plans: vec![None; patches],
            plan_entries: 0,
        }
    }

    /// Takes `shooter`'s kept row out, if it has one; hand it back with [`RowCache::keep`].
    pub(super) fn take(&mut self, shooter: usize) -> Option<Row> {
        self.rows[shooter].take()
    }

    /// `shooter`'s kept plans, if its row was computed before and its plans kept.
    pub(super) fn plans(&self, shooter: usize) -> Option<&[PatchPlan]> {
        self.plans[shooter].as_deref()
    }

    /// After `shooter`'s shot: keeps its row when it was kept before (`was_kept`) or fits
    /// the budget (never on the reference path); else keeps `plans`, the ones its row was
    /// just computed with, when it has none kept and they fit.
    pub(super) fn keep(
        &mut self,
        shooter: usize,
        row: Row,
        was_kept: bool,
        plans: &[PatchPlan],
        params: &SolverParams,
    ) {
        let bytes = row.bytes();
        if was_kept || (!params.reference_path && self.row_bytes + bytes <= params.row_cache_bytes) {
            self.row_bytes += if was_kept { 0 } else { bytes };
            self.rows[shooter] = Some(row);
        } else if self.plans[shooter].is_none() {
            // The row will be computed again: keep its plans.
            let entries = plan_entries(plans);
            if self.plan_entries + entries <= PLAN_CACHE_ENTRIES {
                self.plan_entries += entries;
                self.plans[shooter] = Some(plans.to_vec().into_boxed_slice());
            }
        }
    }
}
