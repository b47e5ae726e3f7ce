//! Progressive refinement by shooting (Cohen, Chen, Wallace & Greenberg 1988, "A progressive
//! refinement approach to fast radiosity image generation").
//!
//! Each shot takes the patch i with the largest unshot power ΔB_i·A_i and, for every element
//! j that can see it, adds `ρ_j · ΔB_i · F_{j→i}` to B_j and to ΔB_j (the source document's
//! `dB = ρj dBi Fij Ai/Aj`, by reciprocity F_{j→i} = F_{i→j} A_i/A_j), then zeroes ΔB_i.
//! F_{j→i} is the area-to-polygon form factor (see [`crate::form_factor`]) times the
//! fraction of unblocked stratified rays between the element and the patch.
//!
//! Options: the ambient term of Cohen et al. 1988 §4 for early display, and overshooting by
//! over-relaxation (Gortler, Cohen & Slusallek 1993, "Radiosity and relaxation methods"):
//! shoot ω·ΔB_i and leave (1 − ω)·ΔB_i, which may be negative, unshot.

use std::sync::Arc;
use std::time::{Duration, Instant};

use glam::DVec3;
use radiosity_accel::RayQuery;
use radiosity_core::{Mesh, Rgb};
use rayon::prelude::*;
use thiserror::Error;

use crate::form_factor::{Rule, distance_to_polygon, for_each_point, point_to_point, point_to_polygon};
use crate::occluders::OccluderBoxes;
use crate::sampling::{Rng, point_on, stratified};
use crate::solution::{Solution, vertex_average};

/// How the form factor from a receiving element to a shooting patch is computed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FormFactorMethod {
    /// Exact point-to-polygon form factor integrated over the receiver (accurate at any range).
    #[default]
    Exact,
    /// The source document's `cosθi cosθj A / (π r²)` between centres (wrong up close).
    PointToPoint,
}

/// Whether snapshots add the ambient term.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Ambient {
    /// Snapshots show only the light shot so far.
    #[default]
    Off,
    /// Snapshots add ρ_j · R · (unshot power / total area), R = 1/(1 − mean ρ) (Cohen 1988):
    /// a flat estimate of the light still to come, so early pictures are not too dark.
    On,
}

/// Whether shots over-relax.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Overshoot {
    /// Shoot exactly the unshot radiosity.
    #[default]
    Off,
    /// Shoot ω times the unshot radiosity, ω in [1, 2).
    Relaxation(f64),
}

/// Solver settings; every field has a unit, a range and a default.
#[derive(Clone, Debug, PartialEq)]
pub struct SolverParams {
    /// Form factor method. Default [`FormFactorMethod::Exact`].
    pub form_factor: FormFactorMethod,
    /// Visibility rays per receiving element and shot, ≥ 1. Default 4.
    pub visibility_rays: u32,
    /// Largest receiver quadrature, Gauss cells per side, in 1..=256. Default 8.
    pub max_quadrature: u32,
    /// Stop when unshot power / emitted power ≤ this, in (0, 1). Default 1e-3.
    pub unshot_threshold: f64,
    /// Stop after this many shots. Default none.
    pub max_shots: Option<u64>,
    /// Stop after this much solving time. Default none.
    pub time_limit: Option<Duration>,
    /// Seed of every random stream. Default 0.
    pub seed: u64,
    /// Ambient term in snapshots. Default off.
    pub ambient: Ambient,
    /// Over-relaxation. Default off.
    pub overshoot: Overshoot,
}

impl Default for SolverParams {
    fn default() -> Self {
        Self {
            form_factor: FormFactorMethod::Exact,
            visibility_rays: 4,
            max_quadrature: 8,
            unshot_threshold: 1e-3,
            max_shots: None,
            time_limit: None,
            seed: 0,
            ambient: Ambient::Off,
            overshoot: Overshoot::Off,
        }
    }
}

impl SolverParams {
    /// Fast and rough, for interactive previews: one visibility ray, coarse quadrature,
    /// ambient term on, stop at 1 % unshot.
    pub fn preview() -> Self {
        Self {
            visibility_rays: 1,
            max_quadrature: 4,
            unshot_threshold: 1e-2,
            ambient: Ambient::On,
            ..Self::default()
        }
    }

    /// Slow and accurate: 16 visibility rays, fine quadrature, stop at 0.01 % unshot.
    pub fn accurate() -> Self {
        Self { visibility_rays: 16, max_quadrature: 64, unshot_threshold: 1e-4, ..Self::default() }
    }
}

/// Why solving cannot start.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum SolverError {
    /// Nothing emits: there is no light to shoot.
    #[error("the scene emits no light (total emitted power is 0); give a material an emission > 0")]
    NoEmission,
    /// The mesh has no elements.
    #[error("the mesh has no elements")]
    EmptyMesh,
    /// A parameter is out of range.
    #[error("solver parameter {name} = {value} is out of range: {expected}")]
    BadParameter {
        /// Parameter name.
        name: &'static str,
        /// Value given.
        value: String,
        /// What is expected.
        expected: &'static str,
    },
}

/// Why a solve stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// Unshot power fell to the threshold.
    Converged,
    /// The shot limit was reached.
    ShotLimit,
    /// The time limit was reached.
    TimeLimit,
    /// Unshot power stopped falling.
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

/// How much work one [`Solver::step`] may do.
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

/// Power bookkeeping per channel: emitted = absorbed + unshot + escaped, to round-off.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnergyBalance {
    /// Σ E·A.
    pub emitted: Rgb,
    /// Power absorbed by surfaces, (1 − ρ) of what they received.
    pub absorbed: Rgb,
    /// Power not yet shot, Σ ΔB·A.
    pub unshot: Rgb,
    /// Power shot that reached no element (left an open scene).
    pub escaped: Rgb,
}

/// The progressive shooting solver. Owns its working state; callers own the loop.
pub struct Solver {
    mesh: Arc<Mesh>,
    accel: Arc<dyn RayQuery>,
    params: SolverParams,
    reflectance: Vec<Rgb>,
    radiosity: Vec<Rgb>,
    unshot: Vec<Rgb>,
    patch_unshot_power: Vec<Rgb>,
    vertex_area: Vec<f64>,
    emitted: Rgb,
    absorbed: Rgb,
    escaped: Rgb,
    total_area: f64,
    mean_reflectance: Rgb,
    ray_offset: f64,
    occluder_boxes: OccluderBoxes,
    shots: u64,
    rays: u64,
    elapsed: Duration,
    unshot_fraction: f64,
    best_unshot: f64,
    shots_since_best: u64,
    stop: Option<StopReason>,
    // Per-shot scratch, kept to avoid allocating in the loop.
    patch_live: Vec<bool>,
    factors: Vec<(f64, u32)>,
}

impl Solver {
    /// A solver at shot 0: B = E and ΔB = E on every element.
    ///
    /// # Errors
    /// [`SolverError::EmptyMesh`], [`SolverError::NoEmission`], or
    /// [`SolverError::BadParameter`] for out-of-range parameters.
    pub fn new(mesh: Arc<Mesh>, accel: Arc<dyn RayQuery>, params: SolverParams) -> Result<Self, SolverError> {
        let bad = |name, value: String, expected| Err(SolverError::BadParameter { name, value, expected });
        if !(params.unshot_threshold > 0.0 && params.unshot_threshold < 1.0) {
            return bad("unshot_threshold", params.unshot_threshold.to_string(), "a number in (0, 1)");
        }
        if params.visibility_rays == 0 {
            return bad("visibility_rays", "0".into(), "at least 1");
        }
        if params.max_quadrature == 0 || params.max_quadrature > 256 {
            return bad("max_quadrature", params.max_quadrature.to_string(), "1 to 256");
        }
        if let Overshoot::Relaxation(w) = params.overshoot
            && !(1.0..2.0).contains(&w)
        {
            return bad("overshoot", w.to_string(), "ω in [1, 2)");
        }
        if params.max_shots == Some(0) {
            return bad("max_shots", "0".into(), "at least 1");
        }
        if mesh.elements.is_empty() {
            return Err(SolverError::EmptyMesh);
        }
        let n = mesh.elements.len();
        let reflectance: Vec<Rgb> = (0..n).map(|e| mesh.element_material(e).reflectance).collect();
        let emission: Vec<Rgb> = (0..n).map(|e| mesh.element_material(e).emission).collect();
        let emitted: Rgb = mesh.elements.iter().zip(&emission).map(|(el, e)| *e * el.area).sum();
        if emitted.sum() <= 0.0 {
            return Err(SolverError::NoEmission);
        }
        let mut vertex_area = vec![0.0; mesh.positions.len()];
        for el in &mesh.elements {
            for &v in el.vertex_indices() {
                vertex_area[v as usize] += el.area;
            }
        }
        let total_area = mesh.total_area();
        let mean_reflectance =
            mesh.elements.iter().zip(&reflectance).map(|(el, r)| *r * el.area).sum::<Rgb>() / total_area;
        let (lo, hi) = mesh.bounds();
        let mut s = Self {
            patch_unshot_power: vec![Rgb::ZERO; mesh.patches.len()],
            patch_live: vec![false; mesh.patches.len()],
            factors: vec![(0.0, 0); n],
            ray_offset: 1e-6 * (hi - lo).length(),
            occluder_boxes: OccluderBoxes::new(&mesh),
            mesh,
            accel,
            params,
            reflectance,
            radiosity: emission.clone(),
            unshot: emission,
            vertex_area,
            emitted,
            absorbed: Rgb::ZERO,
            escaped: Rgb::ZERO,
            total_area,
            mean_reflectance,
            shots: 0,
            rays: 0,
            elapsed: Duration::ZERO,
            unshot_fraction: 1.0,
            best_unshot: 1.0,
            shots_since_best: 0,
            stop: None,
        };
        s.refresh_patch_unshot();
        Ok(s)
    }

    fn refresh_patch_unshot(&mut self) {
        let mesh = &self.mesh;
        for (p, patch) in mesh.patches.iter().enumerate() {
            self.patch_unshot_power[p] = (patch.elements.start..patch.elements.end)
                .map(|e| self.unshot[e as usize] * mesh.elements[e as usize].area)
                .sum();
        }
        let total: f64 = self.patch_unshot_power.iter().map(|p| p.abs().sum()).sum();
        self.unshot_fraction = total / self.emitted.sum();
    }

    /// The mesh being solved.
    pub fn mesh(&self) -> &Arc<Mesh> {
        &self.mesh
    }

    /// The parameters.
    pub fn params(&self) -> &SolverParams {
        &self.params
    }

    /// Why the solve stopped, or `None` while it goes on.
    pub fn stop_reason(&self) -> Option<StopReason> {
        self.stop
    }

    /// Shots done.
    pub fn shots(&self) -> u64 {
        self.shots
    }

    /// Unshot power / emitted power.
    pub fn unshot_fraction(&self) -> f64 {
        self.unshot_fraction
    }

    /// Visibility rays traced.
    pub fn rays(&self) -> u64 {
        self.rays
    }

    /// Time spent inside [`Solver::step`].
    pub fn elapsed(&self) -> Duration {
        self.elapsed
    }

    /// Power bookkeeping, summed fresh from the element state.
    pub fn energy(&self) -> EnergyBalance {
        let unshot = self.unshot.iter().zip(&self.mesh.elements).map(|(u, el)| *u * el.area).sum();
        EnergyBalance { emitted: self.emitted, absorbed: self.absorbed, unshot, escaped: self.escaped }
    }

    fn report(&self, shots: u64) -> StepReport {
        StepReport {
            shots,
            total_shots: self.shots,
            unshot_fraction: self.unshot_fraction,
            rays: self.rays,
            elapsed: self.elapsed,
            stop_reason: self.stop,
        }
    }

    fn check_stop(&mut self) -> Option<StopReason> {
        if self.stop.is_none() {
            let p = &self.params;
            self.stop = if self.unshot_fraction <= p.unshot_threshold {
                Some(StopReason::Converged)
            } else if p.max_shots.is_some_and(|m| self.shots >= m) {
                Some(StopReason::ShotLimit)
            } else if p.time_limit.is_some_and(|t| self.elapsed >= t) {
                Some(StopReason::TimeLimit)
            } else if self.shots_since_best > (4 * self.mesh.patches.len() as u64).max(2000) {
                Some(StopReason::NotConverging)
            } else {
                None
            };
        }
        self.stop
    }

    /// Shoots until the budget is spent or a stop criterion holds.
    pub fn step(&mut self, budget: StepBudget) -> StepReport {
        let start = Instant::now();
        let base = self.elapsed;
        let mut done = 0;
        while self.check_stop().is_none() {
            match budget {
                StepBudget::Shots(n) if done >= n => break,
                StepBudget::Time(t) if done > 0 && start.elapsed() >= t => break,
                _ => {}
            }
            self.shoot();
            done += 1;
            self.elapsed = base + start.elapsed();
        }
        self.report(done)
    }

    /// Runs to a stop criterion.
    pub fn solve(&mut self) -> StepReport {
        self.step(StepBudget::Shots(u64::MAX))
    }

    /// A snapshot of the current solution.
    pub fn solution(&self) -> Solution {
        let element_radiosity = match self.params.ambient {
            Ambient::Off => self.radiosity.clone(),
            Ambient::On => {
                let unshot_power: Rgb = self.patch_unshot_power.iter().copied().sum();
                let r = self.mean_reflectance.map(|m| 1.0 / (1.0 - m));
                let ambient = r * unshot_power / self.total_area;
                self.radiosity.iter().zip(&self.reflectance).map(|(b, rho)| *b + *rho * ambient).collect()
            }
        };
        Solution {
            vertex_radiosity: vertex_average(&self.mesh, &element_radiosity, &self.vertex_area),
            element_radiosity,
            element_unshot: self.unshot.clone(),
            shots: self.shots,
            unshot_fraction: self.unshot_fraction,
        }
    }

    /// The patch with the largest |unshot power| (summed over channels); ties go to the lower
    /// index so the choice is deterministic.
    fn pick_shooter(&self) -> usize {
        let mut best = (0, f64::NEG_INFINITY);
        for (p, power) in self.patch_unshot_power.iter().enumerate() {
            let v = power.abs().sum();
            if v > best.1 {
                best = (p, v);
            }
        }
        best.0
    }

    fn shoot(&mut self) {
        let shooter = self.pick_shooter();
        let mesh = Arc::clone(&self.mesh);
        let patch = &mesh.patches[shooter];
        let omega = match self.params.overshoot {
            Overshoot::Off => 1.0,
            Overshoot::Relaxation(w) => w,
        };
        let shot_b = self.patch_unshot_power[shooter] * (omega / patch.area);
        let corners = patch.corners();

        // Cull whole receiving patches first: a patch receives only if part of it is in front
        // of the shooter and part of the shooter is in front of it.
        let in_front =
            |pts: &[DVec3], c: DVec3, n: DVec3| pts.iter().any(|p| n.dot(*p - c) > 1e-12 * patch.area.sqrt());
        self.patch_live.par_iter_mut().enumerate().for_each(|(q, live)| {
            let r = &mesh.patches[q];
            *live = q != shooter
                && in_front(r.corners(), patch.centre, patch.normal)
                && in_front(corners, r.centre, r.normal);
        });

        let shot = Shot {
            mesh: &mesh,
            shooter: patch,
            accel: &*self.accel,
            boxes: &self.occluder_boxes,
            params: &self.params,
            offset: self.ray_offset,
            index: self.shots,
        };
        let patch_live = &self.patch_live;
        self.factors.par_iter_mut().enumerate().for_each(|(e, out)| {
            let el = &mesh.elements[e];
            *out = if patch_live[el.patch as usize] { receive(&shot, e) } else { (0.0, 0) };
        });

        // Apply sequentially in element order: the sums are the same for any thread count.
        let shot_power = shot_b * patch.area;
        let mut received = Rgb::ZERO;
        for (e, &(f, rays)) in self.factors.iter().enumerate() {
            self.rays += u64::from(rays);
            if f == 0.0 {
                continue;
            }
            let area = mesh.elements[e].area;
            let incident = shot_b * f; // irradiance from this shot, W/unit²
            let reflected = self.reflectance[e] * incident;
            self.radiosity[e] += reflected;
            self.unshot[e] += reflected;
            self.patch_unshot_power[mesh.elements[e].patch as usize] += reflected * area;
            received += incident * area;
            self.absorbed += (incident - reflected) * area;
        }
        self.escaped += shot_power - received;
        for e in patch.elements.start..patch.elements.end {
            self.unshot[e as usize] *= 1.0 - omega;
        }
        self.patch_unshot_power[shooter] *= 1.0 - omega;

        self.shots += 1;
        let total: f64 = self.patch_unshot_power.iter().map(|p| p.abs().sum()).sum();
        self.unshot_fraction = total / self.emitted.sum();
        if self.unshot_fraction < self.best_unshot * (1.0 - 1e-3) {
            self.best_unshot = self.unshot_fraction;
            self.shots_since_best = 0;
        } else {
            self.shots_since_best += 1;
        }
    }
}

/// Receiver quadrature: one midpoint when the element is small against its gap to the
/// shooter (radius < gap/16, midpoint error ~4e-3 of the curvature term; the closed-form
/// tests also pass at gap/8, so this keeps a factor of two in hand), else Gauss cells of radius < gap/4
/// (error ~ (1/4)⁴ ≈ 4e-3 of the point form's curvature term, ~1e-5 in practice).
///
/// What matters most is that a receiver's row of form factors sums to 1 in a closed scene —
/// the midpoint rule overestimates (the integrand is convex), and an all-midpoint scheme
/// needed radius < gap/32 everywhere (16× the evaluations) to bring the ρ = 0.9 furnace
/// inside 0.5 %.
fn quadrature(el_radius: f64, gap: f64, max: u32) -> (u32, Rule) {
    let gap = gap.max(1e-12 * el_radius);
    if 16.0 * el_radius < gap {
        return (1, Rule::Midpoint);
    }
    (((4.0 * el_radius / gap).ceil() as u32).clamp(1, max), Rule::Gauss)
}

/// What every receiver of one shot reads.
struct Shot<'a> {
    mesh: &'a Mesh,
    shooter: &'a radiosity_core::Patch,
    accel: &'a dyn RayQuery,
    boxes: &'a OccluderBoxes,
    params: &'a SolverParams,
    /// Ray origins and targets are lifted this far off their surfaces.
    offset: f64,
    /// Shot index, for the random streams.
    index: u64,
}

/// Form factor F_{e→shooter} (with visibility) and the number of rays traced.
fn receive(shot: &Shot, e: usize) -> (f64, u32) {
    let Shot { mesh, shooter, accel, boxes, params, offset, index } = *shot;
    let el = &mesh.elements[e];
    let mut pts = [DVec3::ZERO; 4];
    for (k, p) in mesh.element_corners(e).enumerate() {
        pts[k] = p;
    }
    let receiver = &pts[..el.vertex_count as usize];
    let corners = shooter.corners();
    let unoccluded = match params.form_factor {
        FormFactorMethod::Exact => {
            let el_radius = receiver.iter().map(|p| p.distance(el.centre)).fold(0.0, f64::max);
            let gap = distance_to_polygon(el.centre, shooter.normal, corners) - el_radius;
            let (n, rule) = quadrature(el_radius, gap, params.max_quadrature);
            let mut f = 0.0;
            for_each_point(receiver, n, rule, |p, w| {
                if shooter.normal.dot(p - corners[0]) > 0.0 {
                    f += w * point_to_polygon(p, el.normal, corners);
                }
            });
            f
        }
        FormFactorMethod::PointToPoint => {
            point_to_point(el.centre, el.normal, shooter.centre, shooter.normal, shooter.area)
        }
    };
    if unoccluded <= 0.0 {
        return (0.0, 0);
    }
    // Every segment between the element and the shooter lies in the box around both; when no
    // blocking triangle comes near that box the pair is fully visible and needs no ray.
    let (lo, hi) = receiver
        .iter()
        .chain(corners)
        .fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(a, b), p| {
            (a.min(*p), b.max(*p))
        });
    if !boxes.may_block(lo, hi, 2.0 * offset) {
        return (unoccluded, 0);
    }
    // Visibility: stratified jittered rays between the element and the shooter.
    let k = params.visibility_rays;
    let mut rng = Rng::for_task(params.seed, index, e as u64);
    let mut visible = 0;
    for i in 0..k {
        let (u, v) = stratified(i, k, &mut rng);
        let from = point_on(receiver, u, v) + el.normal * offset;
        let (u, v) = stratified(i, k, &mut rng);
        let to = point_on(corners, u, v) + shooter.normal * offset;
        if !accel.occluded(from.as_vec3(), to.as_vec3()) {
            visible += 1;
        }
    }
    (unoccluded * f64::from(visible) / f64::from(k), k)
}
