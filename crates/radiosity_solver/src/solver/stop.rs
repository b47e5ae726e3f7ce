//! When a solve stops: the stop criteria (Cohen et al. 1988 stop at a small unshot fraction;
//! shot and time limits; and the rule that ends a solve whose unshot power no longer falls),
//! and the progress they are decided from.

use std::time::Duration;

use super::SolverParams;

/// The least unshot fraction a solve shoots down to, whatever its threshold asks. Below it
/// a shot changes no radiosity by more than this share of the emitted power's: far under
/// the single-precision form factors the rows keep (1e-7), so shooting on moves nothing the
/// solution can show, and the unshot power falls geometrically for ever (to 1e-300 it
/// would run until the time limit, its progress reading 0.000 %).
pub const UNSHOT_FLOOR: f64 = 1e-12;

/// Why a solve stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// Unshot power fell to the threshold.
    Converged,
    /// The shot limit was reached.
    ShotLimit,
    /// The time limit was reached.
    TimeLimit,
    /// Unshot power stopped falling (see the solver's stagnation rule).
    NotConverging,
}

impl StopReason {
    /// The name used in reports: `converged`, `shot_limit`, `time_limit`, `not_converging`.
    pub fn as_str(self) -> &'static str {
        match self {
            StopReason::Converged => "converged",
            StopReason::ShotLimit => "shot_limit",
            StopReason::TimeLimit => "time_limit",
            StopReason::NotConverging => "not_converging",
        }
    }
}

/// How much work one [`crate::Solver::step`] may do.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StepBudget {
    /// At most this many shots.
    Shots(u64),
    /// Shoot until this much time has passed (at least one shot).
    Time(Duration),
}

/// What a step did, and where the solve stands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepReport {
    /// Shots done in this step.
    pub shots: u64,
    /// Shots done since the start.
    pub total_shots: u64,
    /// Unshot power / emitted power.
    pub unshot_fraction: f64,
    /// Visibility rays traced since the start.
    pub rays: u64,
    /// Solving time since the start (time inside `step` only).
    pub elapsed: Duration,
    /// Set when the solve has stopped.
    pub stop_reason: Option<StopReason>,
}

/// The NotConverging rule: a solve whose unshot fraction has not fallen to below
/// [`Stagnation::PROGRESS`] of its best for more than `patience` shots has stopped
/// converging, and ends with [`StopReason::NotConverging`].
///
/// Reflectances are below 1 (validated with the scene), so every shot of a real scene
/// lowers the unshot power, and by a share of it; a run stays put only when round-off
/// (or over-relaxation pushing power back and forth) eats the progress. The patience is
/// four shots per patch, at least 2000: converging solves shoot each patch a few times
/// (the Cornell box ~4), so even a slowly converging scene shows 0.1 % of progress in that
/// many shots, and a stalled one costs only a bounded number of useless shots (the source
/// document's "it would never stop" case ends, never loops).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Stagnation {
    /// The lowest unshot fraction that counted as progress.
    best: f64,
    /// Shots since `best` was set.
    shots_since_best: u64,
    /// Shots without progress that end the solve.
    patience: u64,
}

impl Stagnation {
    /// The share by which the unshot fraction must fall below its best to count as progress.
    pub(super) const PROGRESS: f64 = 1e-3;

    /// Least patience, in shots, whatever the patch count.
    pub(super) const MIN_PATIENCE: u64 = 2000;

    /// The rule for a mesh of `patches` patches, at shot 0 (unshot fraction 1).
    pub(super) fn new(patches: usize) -> Self {
        Self { best: 1.0, shots_since_best: 0, patience: (4 * patches as u64).max(Self::MIN_PATIENCE) }
    }

    /// Records the unshot fraction after a shot.
    pub(super) fn record(&mut self, unshot_fraction: f64) {
        if unshot_fraction < self.best * (1.0 - Self::PROGRESS) {
            self.best = unshot_fraction;
            self.shots_since_best = 0;
        } else {
            self.shots_since_best += 1;
        }
    }

    /// True when the solve has gone more than the patience without progress.
    pub(super) fn stalled(&self) -> bool {
        self.shots_since_best > self.patience
    }
}

/// Where the solve stands: shots, rays and time so far, the stagnation rule, and why it
/// stopped once it has.
#[derive(Clone, Debug)]
pub(super) struct Progress {
    pub(super) shots: u64,
    pub(super) rays: u64,
    /// Time spent inside `step`.
    pub(super) elapsed: Duration,
    pub(super) stagnation: Stagnation,
    pub(super) stop: Option<StopReason>,
}

impl Progress {
    /// Shot 0 of a mesh of `patches` patches.
    pub(super) fn new(patches: usize) -> Self {
        Self { shots: 0, rays: 0, elapsed: Duration::ZERO, stagnation: Stagnation::new(patches), stop: None }
    }

    /// Decides, once, whether the solve stops now; the criteria in order: converged, shot
    /// limit, time limit, not converging.
    pub(super) fn check(&mut self, params: &SolverParams, unshot_fraction: f64) -> Option<StopReason> {
        if self.stop.is_none() {
            self.stop = if unshot_fraction <= params.unshot_threshold.max(UNSHOT_FLOOR) {
                Some(StopReason::Converged)
            } else if params.max_shots.is_some_and(|m| self.shots >= m) {
                Some(StopReason::ShotLimit)
            } else if params.time_limit.is_some_and(|t| self.elapsed >= t) {
                Some(StopReason::TimeLimit)
            } else if self.stagnation.stalled() {
                Some(StopReason::NotConverging)
            } else {
                None
            };
        }
        self.stop
    }

    /// The report of a step that did `shots` shots.
    pub(super) fn report(&self, shots: u64, unshot_fraction: f64) -> StepReport {
        StepReport {
            shots,
            total_shots: self.shots,
            unshot_fraction,
            rays: self.rays,
            elapsed: self.elapsed,
            stop_reason: self.stop,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A run that keeps falling by more than 0.1 % a shot never stalls.
    #[test]
    fn steady_progress_never_stalls() {
        let mut rule = Stagnation::new(10);
        let mut fraction = 1.0;
        for _ in 0..100_000 {
            fraction *= 0.998;
            rule.record(fraction);
            assert!(!rule.stalled());
        }
    }

    /// A flat run stalls after exactly the patience: 2000 shots for a small mesh, four per
    /// patch for a large one.
    #[test]
    fn a_flat_run_stalls_after_the_patience() {
        for (patches, patience) in [(10, 2000), (1000, 4000)] {
            let mut rule = Stagnation::new(patches);
            for shot in 1..=patience + 1 {
                assert!(!rule.stalled(), "{patches} patches, shot {shot}");
                rule.record(0.5);
            }
            // The first record set the best; then `patience` flat shots are allowed.
            assert!(!rule.stalled());
            rule.record(0.5);
            assert!(rule.stalled(), "{patches} patches");
        }
    }

    /// Progress is measured against the best so far: a run creeping down by 0.05 % a shot
    /// counts (every third shot passes the 0.1 % mark), one that wobbles in place does not.
    #[test]
    fn creeping_counts_and_wobbling_does_not() {
        let mut creeping = Stagnation::new(1);
        let mut fraction = 0.5;
        for _ in 0..10 * Stagnation::MIN_PATIENCE {
            fraction *= 1.0 - 0.5 * Stagnation::PROGRESS;
            creeping.record(fraction);
            assert!(!creeping.stalled());
        }
        let mut wobbling = Stagnation::new(1);
        for shot in 0..=Stagnation::MIN_PATIENCE + 1 {
            wobbling.record(if shot % 2 == 0 { 0.5 } else { 0.4999 });
        }
        assert!(wobbling.stalled());
        wobbling.record(0.4);
        assert!(!wobbling.stalled());
    }

    /// The stop criteria in their order, and a decided stop stays.
    #[test]
    fn criteria_are_checked_in_order_and_stick() {
        let params = SolverParams {
            max_shots: Some(5),
            time_limit: Some(Duration::from_secs(1)),
            ..Default::default()
        };
        let mut p = Progress::new(1);
        assert_eq!(p.check(&params, 0.5), None);
        p.shots = 5;
        p.elapsed = Duration::from_secs(2);
        assert_eq!(p.check(&params, 1e-4), Some(StopReason::Converged));
        let mut p = Progress::new(1);
        p.shots = 5;
        p.elapsed = Duration::from_secs(2);
        assert_eq!(p.check(&params, 0.5), Some(StopReason::ShotLimit));
        assert_eq!(p.check(&params, 1e-4), Some(StopReason::ShotLimit));
        let mut p = Progress::new(1);
        p.elapsed = Duration::from_secs(2);
        assert_eq!(p.check(&params, 0.5), Some(StopReason::TimeLimit));
        let mut p = Progress::new(1);
        for _ in 0..=Stagnation::MIN_PATIENCE + 1 {
            p.stagnation.record(0.5);
        }
        assert_eq!(p.check(&SolverParams::default(), 0.5), Some(StopReason::NotConverging));
    }
}
