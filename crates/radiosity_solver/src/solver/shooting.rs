//! The shooting loop of Cohen, Chen, Wallace & Greenberg (1988), step by step:
//!
//! 1. pick the shooter: the patch i with the largest unshot power ΔB_i·A_i;
//! 2. find its row of form factors F_{j→i} to every receiving element j (visibility
//!    included): kept from its earlier shot, or computed (see [`super::row`]);
//! 3. shoot: every receiver gains ρ_j · ΔB_i · F_{j→i} in B_j and ΔB_j, and ΔB_i is zeroed
//!    (see [`super::tally`]);
//! 4. keep the row for the shooter's next shot, if memory allows;
//! 5. update the unshot fraction, and stop when a criterion holds (see [`super::stop`]).

use std::time::Instant;

use super::{Solver, StepBudget, StepReport};

impl Solver {
    /// Shoots until the budget is spent or a stop criterion holds.
    pub fn step(&mut self, budget: StepBudget) -> StepReport {
        let start = Instant::now();
        let base = self.progress.elapsed;
        let mut done = 0;
        while self.progress.check(&self.params, self.tally.unshot_fraction).is_none() {
            match budget {
                StepBudget::Shots(n) if done >= n => break,
                StepBudget::Time(t) if done > 0 && start.elapsed() >= t => break,
                _ => {}
            }
            self.shoot();
            done += 1;
            self.progress.elapsed = base + start.elapsed();
        }
        self.progress.report(done, self.tally.unshot_fraction)
    }

    /// Runs to a stop criterion.
    pub fn solve(&mut self) -> StepReport {
        self.step(StepBudget::Shots(u64::MAX))
    }

    /// One shot.
    fn shoot(&mut self) {
        // 1. The shooter.
        let shooter = self.tally.brightest_patch();
        // 2. Its row of form factors.
        let kept = self.rows.take(shooter);
        let was_kept = kept.is_some();
        let row = kept.unwrap_or_else(|| self.compute_row(shooter));
        // 3. Shoot ω ΔB_i through it (ω = 1 unless over-relaxing).
        self.tally.shoot(&self.mesh, &self.tables, shooter, &row, self.params.overshoot.omega());
        // 4. Keep the row (or the plans it was computed with).
        self.rows.keep(shooter, row, was_kept, &self.scratch.plans, &self.params);
        // 5. Progress.
        self.progress.shots += 1;
        self.tally.update_unshot_fraction();
        self.progress.stagnation.record(self.tally.unshot_fraction);
    }
}
