//! The groups' unshot power, kept up to date shot by shot, and who shoots next: the patch
//! or group with the largest |unshot power|.

use super::*;
use crate::solver::tally::RESUM;

impl Clusters {
    /// Counts the patches' |unshot power| (`patch_abs`) afresh into the groups' sums.
    pub(in crate::solver) fn sum(&mut self, patch_abs: &[f64]) {
        self.power.fill(0.0);
        for (q, &g) in self.of_patch.iter().enumerate() {
            if g != NONE {
                self.power[g as usize] += patch_abs[q];
            }
        }
        self.since_sum = 0;
    }

    /// Brings the groups' sums up to date with the patches a shot `changed` (patch, change
    /// of its |unshot power|), and sums them afresh from `patch_abs` every
    /// [`RESUM`] shots, so rounding cannot pile up.
    pub(in crate::solver) fn update(&mut self, changed: &[(u32, f64)], patch_abs: &[f64]) {
        self.since_sum += 1;
        if self.since_sum >= RESUM {
            self.sum(patch_abs);
            return;
        }
        for &(q, delta) in changed {
            let g = self.of_patch[q as usize];
            if g != NONE {
                self.power[g as usize] += delta;
            }
        }
    }

    /// The shooter with the largest |unshot power| (summed over channels, `patch_abs`): a
    /// patch on its own or a group, by the sum over its patches. Ties go to the patch, then
    /// to the lower index.
    pub(in crate::solver) fn brightest(&self, patch_abs: &[f64]) -> Shooter {
        let mut best = (Shooter::Patch(0), f64::NEG_INFINITY);
        for &q in &self.singles {
            if patch_abs[q as usize] > best.1 {
                best = (Shooter::Patch(q as usize), patch_abs[q as usize]);
            }
        }
        for (g, &v) in self.power.iter().enumerate() {
            if v > best.1 {
                best = (Shooter::Group(g), v);
            }
        }
        best.0
    }
}
