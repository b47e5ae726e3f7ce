//! Rows kept across shots. A patch shoots several times as light comes back to it; its rays
//! come from a stream keyed by the shooter and end where its unshot power was at its first
//! shot, so its shots have the same row of form factors until that spread is fixed again
//! (see `first_shots`; the row is then taken out, [`RowCache::take_out`], and lends the new
//! one what geometry alone decided, see `row::Geometry`). The row is kept (within
//! `SolverParams::row_cache_bytes`) and a later shot is one multiply-add per receiver; past
//! the budget, the row's patch plans (geometry only) are kept instead, up to
//! [`PLAN_CACHE_ENTRIES`]. A row's geometry is kept with it only in room the rows leave.
//!
//! When the rows do not all fit, the ones kept are those of the shooters that have shot most
//! often: a shooter that has shot often (a big wall, lit from everywhere) will shoot again,
//! while most of a model's groups and the lamps shoot once or twice. Kept first come, first
//! served, the 480 k-triangle room's budget went to its first shooters and its room patches'
//! rows were computed again up to 13 times each. Which rows are kept changes the speed only:
//! a row computed again is the same row.

use super::SolverParams;
use super::plans::{PatchPlan, plan_entries};
use super::row::Row;

/// Most plan entries (receiving patches plus candidate triangles) kept across shots: about
/// 40 MB, every shooter's row for a scene of a thousand patches.
const PLAN_CACHE_ENTRIES: usize = 1 << 20;

/// Each shooter's kept row, or its kept plans.
pub(super) struct RowCache {
    /// Each shooter's form factors to its receivers, kept up to `params.row_cache_bytes`.
    /// Boxed: a row inline is some 150 bytes, and a table of millions of patches that keeps
    /// a few hundred rows was 350 MB of empty slots.
    rows: Vec<Option<Box<Row>>>,
    row_bytes: usize,
    /// Plans depend on geometry only, so each shooter's plans are kept for its next shots
    /// when its form factors are not, up to [`PLAN_CACHE_ENTRIES`] in all.
    plans: Vec<Option<Box<[PatchPlan]>>>,
    plan_entries: usize,
    /// Bytes the rows may take (see `SolverParams::row_cache_budget`).
    budget: usize,
    /// Per shooter, its shots so far.
    shots: Vec<u32>,
    /// The shooters whose rows are kept (or taken out for a shot).
    kept: Vec<usize>,
}

impl RowCache {
    /// Nothing kept, for `patches` shooters, rows kept within `budget` bytes.
    pub(super) fn new(patches: usize, budget: usize) -> Self {
        Self {
            budget,
            rows: (0..patches).map(|_| None).collect(),
            row_bytes: 0,
            plans: vec![None; patches],
            plan_entries: 0,
            shots: vec![0; patches],
            kept: Vec::new(),
        }
    }

    /// Takes `shooter`'s kept row out, if it has one; hand it back with [`RowCache::keep`].
    pub(super) fn take(&mut self, shooter: usize) -> Option<Row> {
        self.rows[shooter].take().map(|row| *row)
    }

    /// Takes `shooter`'s kept row out for good, if it has one: it no longer holds (its
    /// spread was fixed again), but what geometry decided in it still does.
    pub(super) fn take_out(&mut self, shooter: usize) -> Option<Row> {
        let row = self.rows[shooter].take()?;
        self.row_bytes -= row.bytes();
        self.kept.retain(|&k| k != shooter);
        Some(*row)
    }

    /// Whether `bytes` more fit the budget beside the rows kept now.
    pub(super) fn room_for(&self, bytes: usize) -> bool {
        self.row_bytes + bytes <= self.budget
    }

    /// `shooter`'s kept plans, if its row was computed before and its plans kept.
    pub(super) fn plans(&self, shooter: usize) -> Option<&[PatchPlan]> {
        self.plans[shooter].as_deref()
    }

    /// After `shooter`'s shot: keeps its row when it was kept before (`was_kept`), fits the
    /// budget, or fits once the rows of shooters that have shot fewer times are dropped
    /// (never on the reference path); else keeps `plans`, the ones its row was just
    /// computed with, when it has none kept and they fit.
    pub(super) fn keep(
        &mut self,
        shooter: usize,
        row: Row,
        was_kept: bool,
        plans: &[PatchPlan],
        params: &SolverParams,
    ) {
        self.shots[shooter] += 1;
        if was_kept {
            self.rows[shooter] = Some(Box::new(row));
            return;
        }
        // Kept geometry only fills room the rows leave: it never displaces a row.
        let mut row = row;
        if row.geometry.is_some() && !self.room_for(row.bytes()) {
            row.geometry = None;
        }
        let bytes = row.bytes();
        if !params.reference_path && self.make_room(shooter, bytes) {
            self.row_bytes += bytes;
            self.rows[shooter] = Some(Box::new(row));
            self.kept.push(shooter);
        } else if self.plans[shooter].is_none() {
            // The row will be computed again: keep its plans.
            let entries = plan_entries(plans);
            if self.plan_entries + entries <= PLAN_CACHE_ENTRIES {
                self.plan_entries += entries;
                self.plans[shooter] = Some(plans.to_vec().into_boxed_slice());
            }
        }
    }

    /// Frees `bytes` within the budget for `shooter`'s row by dropping the rows of shooters
    /// that have shot fewer times than it (fewest first, then the later shooter index), if
    /// that is enough; whether the row now fits.
    fn make_room(&mut self, shooter: usize, bytes: usize) -> bool {
        let budget = self.budget;
        if self.row_bytes + bytes <= budget {
            return true;
        }
        // Kept geometry goes first, oldest rows first: it only fills room rows leave.
        for &k in &self.kept {
            if self.row_bytes + bytes <= budget {
                return true;
            }
            if let Some(row) = self.rows[k].as_deref_mut() {
                let before = row.bytes();
                row.geometry = None;
                self.row_bytes -= before - row.bytes();
            }
        }
        if self.row_bytes + bytes <= budget {
            return true;
        }
        let shots = self.shots[shooter];
        let mut victims: Vec<usize> = self.kept.iter().copied().filter(|&k| self.shots[k] < shots).collect();
        let freeable: usize = victims.iter().filter_map(|&k| self.rows[k].as_deref()).map(Row::bytes).sum();
        if self.row_bytes - freeable + bytes > budget {
            return false;
        }
        victims.sort_unstable_by_key(|&k| (self.shots[k], std::cmp::Reverse(k)));
        for k in victims {
            if self.row_bytes + bytes <= budget {
                break;
            }
            if let Some(row) = self.rows[k].take() {
                self.row_bytes -= row.bytes();
                self.kept.retain(|&x| x != k);
            }
        }
        self.row_bytes + bytes <= budget
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A row of `n` factors over elements from 0.
    fn row(n: usize) -> Row {
        let mut row = Row::new();
        row.push(0..n, std::iter::repeat_n(0.5, n));
        row
    }

    /// Past the budget, a row takes the place of rows whose shooters shot fewer times than
    /// its own, fewest first, and never of rows shot as often.
    #[test]
    fn rows_of_shooters_that_shoot_more_often_displace_the_others() {
        let size = row(100).bytes();
        let params = SolverParams::default();
        let mut cache = RowCache::new(4, 2 * size);
        cache.keep(0, row(100), false, &[], &params);
        cache.keep(1, row(100), false, &[], &params);
        // Shooter 1 shoots again (its kept row taken out and handed back).
        let kept = cache.take(1).expect("kept");
        cache.keep(1, kept, true, &[], &params);
        // A third shooter's first row does not fit and displaces nobody.
        cache.keep(2, row(100), false, &[], &params);
        assert!(cache.take(2).is_none());
        // Its second computation (two shots) displaces shooter 0 (one shot), not 1 (two).
        cache.keep(2, row(100), false, &[], &params);
        assert!(cache.take(0).is_none());
        assert!(cache.take(1).is_some());
        assert!(cache.take(2).is_some());
        // The reference path keeps nothing.
        let reference = SolverParams { reference_path: true, ..params };
        let mut cache = RowCache::new(1, usize::MAX);
        cache.keep(0, row(1), false, &[], &reference);
        assert!(cache.take(0).is_none());
    }

    /// Kept geometry fills the room rows leave and never displaces a row: a row that needs
    /// the room takes it from the geometry first, and a row that does not fit with its
    /// geometry is kept without it.
    #[test]
    fn geometry_gives_way_to_rows() {
        let params = SolverParams::default();
        let size = row(100).bytes();
        let with_geometry = || {
            let mut r = row(100);
            r.geometry = Some(Box::new(super::super::row::Geometry::zeros(400)));
            r
        };
        let heavy = with_geometry().bytes();
        assert!(heavy > 2 * size);
        let mut cache = RowCache::new(3, heavy + size - 1);
        cache.keep(0, with_geometry(), false, &[], &params);
        // Shooter 1 shot as often as 0: only 0's geometry can make room for its row.
        cache.keep(1, row(100), false, &[], &params);
        let (zero, one) = (cache.take(0).expect("row 0 kept"), cache.take(1).expect("row 1 kept"));
        assert!(zero.geometry.is_none(), "the geometry gave way");
        assert!(one.geometry.is_none());
        // A row whose geometry does not fit is kept without it.
        let mut cache = RowCache::new(1, heavy - 1);
        cache.keep(0, with_geometry(), false, &[], &params);
        assert!(cache.take(0).expect("kept").geometry.is_none());
    }
}
