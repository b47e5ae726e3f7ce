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

use super::Overshoot;
use super::clusters::Shooter;
use super::enclosure::Probes;
use super::tally::{Delivery, Shooters};
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
        // 1. The shooter: a patch, or a group of a model's facets (`clusters`).
        let shooter = self.clusters.brightest(&self.tally.patch_abs);
        let key = match shooter {
            Shooter::Patch(p) => p,
            Shooter::Group(g) => self.mesh.patches.len() + g,
        };
        // 2. Its row of form factors: kept, unless the spread of its unshot power has moved
        //    since the row was computed (see `FirstShots::refresh_if_drifted`). Not when
        //    overshooting: what is left unshot then swings above and below zero, no spread of
        //    power to follow (the ρ = 0.8 furnace ended 0.2 % off).
        //    The row it had then lends what geometry alone decided.
        let mut previous = None;
        if let Shooter::Patch(p) = shooter
            && self.params.overshoot == Overshoot::Off
            && self.first_shots.refresh_if_drifted(&self.mesh, p, &self.tally)
        {
            previous = self.rows.take_out(key);
        }
        if let Shooter::Group(g) = shooter
            && self.params.overshoot == Overshoot::Off
            && self.clusters.refresh_if_drifted(g, &self.mesh, &self.tally.unshot)
        {
            // A group's row holds nothing its next spread could reuse.
            self.rows.take_out(key);
        }
        let kept = self.rows.take(key);
        let was_kept = kept.is_some();
        let row = kept.unwrap_or_else(|| self.compute_any_row(key, previous));
        // 3. Shoot ω ΔB_i through it (ω = 1 unless over-relaxing).
        let omega = self.params.overshoot.omega();
        let patch = key as u32;
        let delivers = self.delivers(shooter, key);
        let by = match shooter {
            Shooter::Patch(p) => Shooters {
                patches: std::slice::from_ref(&patch),
                area: self.mesh.patches[p].area,
                near_reach: None,
                delivers,
            },
            Shooter::Group(g) => {
                let group = self.clusters.group(g);
                let near_reach = Some((group.centre, self.clusters.near_reach(g)));
                Shooters { patches: &group.patches, area: group.area, near_reach, delivers }
            }
        };
        self.tally.shoot(&self.mesh, &self.tables, by, &row, omega, self.clusters.members());
        // 4. Keep the row (or the plans it was computed with).
        let plans = if key < self.mesh.patches.len() { &self.scratch.plans[..] } else { &[] };
        self.rows.keep(key, row, was_kept, plans, &self.params);
        // 5. Progress.
        self.progress.shots += 1;
        self.tally.update_unshot_fraction();
        self.clusters.update(&self.tally.changed, &self.tally.patch_abs);
        self.progress.stagnation.record(self.tally.unshot_fraction);
    }

    /// The row of shooter `key`: a patch's index, or the patch count plus a group's. A patch
    /// keeps its row's geometry when the row budget has room for it beside the rows and the
    /// patches are few beside the elements (a model's facets, one patch each, would keep a
    /// plan per facet: more than the row).
    fn compute_any_row(&mut self, key: usize, previous: Option<super::row::Row>) -> super::row::Row {
        let Some(g) = key.checked_sub(self.mesh.patches.len()) else {
            let (patches, elements) = (self.mesh.patches.len(), self.mesh.elements.len());
            let geometry = super::row::Geometry::estimate(patches, elements);
            let keep_geometry = !self.params.reference_path
                && geometry <= 8 * elements
                && self.rows.room_for(geometry + 8 * elements);
            return self.compute_row(key, previous, keep_geometry);
        };
        if self.progress.shots == 0 {
            self.first_shots.first_shot_power = self.first_shots.start_power;
        }
        let (mesh, tables, params) = (&*self.mesh, &self.tables, &self.params);
        let first_power = self.first_shots.first_shot_power;
        self.clusters.freeze(g, mesh, &self.tally.unshot, tables, params, first_power);
        let (row, rays) = self.clusters.row(g, mesh, tables, &*self.accel, params, &mut self.scratch);
        self.progress.rays += rays;
        row
    }
}

impl Solver {
    /// The share of `shooter`'s power (shooter index `key`) its shots must deliver (see
    /// [`super::enclosure`]): all of it when every probe ray meets a surface; where some
    /// leave, for a shooter that does not emit, what the probes do not see leave
    /// ([`super::enclosure::escaping_share`]); none for an emitter that sees out, whose row
    /// (drawn with many rays, and the largest shot of a solve) is taken as it is. Probed once
    /// per shooter, the first time it shoots.
    fn delivers(&mut self, shooter: Shooter, key: usize) -> Option<Delivery> {
        if let Some(known) = self.delivers[key] {
            return known;
        }
        let mesh = &*self.mesh;
        // With alpha-masked faces a row is no measure of what stays in the scene: a masked
        // receiver takes its whole form factor (reflecting only from the part that is there,
        // `radiosity_mesh::masks`) while the rest of that light goes on through it to what lies
        // behind. Probes, which pass the clear texels, then scaled rows down (a masked sheet's
        // underside −22 % against the path tracer); every row is taken as it is.
        if !mesh.masked_occluders.is_empty() {
            self.delivers[key] = Some(None);
            return None;
        }
        let hull = self
            .hull
            .get_or_insert_with(|| radiosity_accel::Bvh::new(&crate::occluders::hull_triangles(mesh)));
        let (points, emits): (Vec<(glam::DVec3, glam::DVec3)>, bool) = match shooter {
            Shooter::Patch(p) => {
                let patch = &mesh.patches[p];
                let inner = patch.corners().iter().map(|c| (patch.centre + *c) * 0.5);
                let points = std::iter::once(patch.centre).chain(inner).map(|x| (x, patch.normal)).collect();
                (points, super::clusters::patch_emits(mesh, p))
            }
            Shooter::Group(g) => (self.clusters.probe_points(g), self.clusters.group(g).emits),
        };
        let probes = Probes { accel: &*self.accel, hull, reach: self.probe_reach, seed: self.params.seed };
        let known = if probes.encloses(&points, key as u64) {
            Some(Delivery { share: 1.0, error: 0.0 })
        } else if emits || points.is_empty() {
            None
        } else {
            let (escaping, error) = probes.escaping_share(&points, key as u64);
            Some(Delivery { share: 1.0 - escaping, error })
        };
        self.delivers[key] = Some(known);
        known
    }
}
