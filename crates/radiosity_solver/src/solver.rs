//! Progressive refinement by shooting (Cohen, Chen, Wallace & Greenberg 1988, "A progressive
//! refinement approach to fast radiosity image generation").
//!
//! Each shot takes the patch i with the largest unshot power ΔB_i·A_i and, for every element
//! j that can see it, adds `ρ_j · ΔB_i · F_{j→i}` to B_j and to ΔB_j (the source document's
//! `dB = ρj dBi Fij Ai/Aj`, by reciprocity F_{j→i} = F_{i→j} A_i/A_j), then zeroes ΔB_i.
//! F_{j→i} is the area-to-polygon form factor (see [`crate::form_factor`]) times the
//! fraction of unblocked stratified rays between the element and the patch.
//!
//! A patch shoots several times as light comes back to it. Its rays are drawn from a stream
//! keyed by the shooter (not the shot) and end where its unshot power was at its first shot,
//! so each of its shots has the same row of form factors F_{j→i}; the row is kept (within
//! `SolverParams::row_cache_bytes`) and a later shot is one multiply-add per receiver.
//!
//! Options: the ambient term of Cohen et al. 1988 §4 for early display, and overshooting by
//! over-relaxation (Gortler, Cohen & Slusallek 1993, "Radiosity and relaxation methods"):
//! shoot ω·ΔB_i and leave (1 − ω)·ΔB_i, which may be negative, unshot.

use std::sync::Arc;
use std::time::{Duration, Instant};

use glam::{DVec3, Vec3, Vec3A};
use radiosity_accel::{RayQuery, Segments4};
use radiosity_core::{Mesh, Rgb};
use rayon::prelude::*;
use thiserror::Error;

use crate::form_factor::{
    Rule, distance_to_polygon, for_each_point, point_to_point, point_to_polygon, point_to_polygon_in_front,
    point_to_polygon_in_front_x4, points_to_polygon_in_front_x4,
};
use crate::occluders::{OccluderBoxes, blocking_triangles};
use crate::sampling::{Rng, Strata, four_units, point_on, point_on_f32};
use crate::shaft::{Blockers, FEW, Pair, Visibility, bounds};
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
    /// Visibility rays per receiving element from a bright shooter (see `bright_share`),
    /// ≥ 1. Default 8.
    pub visibility_rays: u32,
    /// More rays from a bright shooter for a receiver whose neighbours' first
    /// `visibility_rays` saw a penumbra (one of them partly lit, or some lit and some dark),
    /// 0 for none. Default 12.
    pub penumbra_rays: u32,
    /// Visibility rays per receiving element from a dim shooter, ≥ 1. Default 1.
    pub dim_rays: u32,
    /// A shooter is bright when its first shot carries at least this share of the power of
    /// the solve's first (largest) shot, in [0, 1]; 0 makes every shooter bright.
    ///
    /// Rays go where their noise shows: a shooter's visibility noise in a receiver scales
    /// with its power, and the many dim shooters' noises, independent, average out. Measured
    /// on Cornell 15.6 k (seed-to-seed RMS of the vertex radiosity; instructions of the
    /// solve): 4 + 12 penumbra rays from every shooter, 1.09 % and 6.2 G; 8 + 12 from the
    /// bright ones (the lamp and 15 patches) and 1 from the 173 dim ones, 0.87 % and 4.25 G. The
    /// ceiling, lit by dim shooters only, goes from 0.04 % to 0.08 %. Default 0.01.
    pub bright_share: f64,
    /// Largest receiver quadrature, Gauss cells per side, in 1..=256. Default 2: measured on
    /// the ρ = 0.9 furnaces (box, sphere), the worst element is within 3.7e-5 / 2.0e-5 of
    /// E/(1 − ρ) at 2 and 4.2e-5 / 4.5e-5 at 8 (the row sums, not the cells next to the
    /// shooter, limit the accuracy), and the Cornell box's objects move by at most 5.5e-4,
    /// while the source document's case (large facets, all near each other) runs 3× faster.
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
    /// Turns off every shortcut meant to change only the speed, not the answer: per-patch
    /// shaft culling and candidate lists, and per-patch quadrature decisions. Each element
    /// then takes the plain path (its own quadrature choice, rays through the caller's ray
    /// structure), and no shooter's row of form factors is kept (see `row_cache_bytes`).
    /// For tests that the shortcuts give the same answer. Default false.
    pub reference_path: bool,
    /// Memory for keeping each shooter's row of form factors, in bytes. A patch is shot
    /// several times (Cornell: ~4), and its form factors and visibility are the same each
    /// time (its rays are drawn from a stream keyed by the shooter, not by the shot), so a
    /// kept row turns a later shot into one multiply-add per receiving element. Rows cost
    /// 4 bytes per receiving element; past the budget rows are recomputed, which gives the
    /// same numbers, only slower. Default 256 MiB.
    pub row_cache_bytes: usize,
}

impl Default for SolverParams {
    fn default() -> Self {
        Self {
            form_factor: FormFactorMethod::Exact,
            visibility_rays: 8,
            penumbra_rays: 12,
            dim_rays: 1,
            bright_share: 0.01,
            max_quadrature: 2,
            unshot_threshold: 1e-3,
            max_shots: None,
            time_limit: None,
            seed: 0,
            ambient: Ambient::Off,
            overshoot: Overshoot::Off,
            reference_path: false,
            row_cache_bytes: 256 << 20,
        }
    }
}

impl SolverParams {
    /// Fast and rough, for interactive previews: one visibility ray from every shooter,
    /// coarse quadrature, ambient term on, stop at 1 % unshot.
    pub fn preview() -> Self {
        Self {
            visibility_rays: 1,
            dim_rays: 1,
            max_quadrature: 1,
            unshot_threshold: 1e-2,
            ambient: Ambient::On,
            ..Self::default()
        }
    }

    /// Slow and accurate: 16 visibility rays and penumbra rays from every shooter, fine
    /// quadrature, stop at 0.01 % unshot.
    pub fn accurate() -> Self {
        Self {
            visibility_rays: 16,
            bright_share: 0.0,
            max_quadrature: 64,
            unshot_threshold: 1e-4,
            ..Self::default()
        }
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
    /// The patches do not own consecutive runs of all the elements, in order.
    #[error("mesh patch {patch}: patches must own consecutive runs of the elements, in order")]
    BadMesh {
        /// The first patch out of order (the patch count when elements are left over).
        patch: usize,
    },
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
    radiosity: Vec<Rgb>,
    unshot: Vec<Rgb>,
    patch_unshot_power: Vec<Rgb>,
    /// Per element, the radiosity it reflected straight from emission (first bounce).
    direct: Vec<Rgb>,
    /// Per patch, the part of its unshot power that is its own emission, not yet shot.
    patch_unshot_emission: Vec<Rgb>,
    vertex_area: Vec<f64>,
    /// Element areas, packed for the shot loop.
    element_area: Vec<f64>,
    /// Per element, the mean of its vertices: the one quadrature point of a far element (the
    /// centre of the bilinear map, see `for_each_point`), which every row needs.
    vertex_means: Vec<DVec3>,
    /// Per element, its circumradius about its centre (see [`element_radius`]).
    element_radii: Vec<f64>,
    /// Per element, its corners lifted off it by the ray offset (see [`lift_corners`]).
    lifted_corners: Vec<[Vec3A; 4]>,
    /// Per patch, its reflectance (a patch's elements share its surface's material).
    patch_reflectance: Vec<Rgb>,
    emitted: Rgb,
    absorbed: Rgb,
    escaped: Rgb,
    total_area: f64,
    mean_reflectance: Rgb,
    ray_offset: f64,
    occluder_boxes: OccluderBoxes,
    blockers: Blockers,
    /// Largest circumradius of the elements of each patch (about their centres).
    patch_element_radius: Vec<f64>,
    shots: u64,
    rays: u64,
    elapsed: Duration,
    unshot_fraction: f64,
    best_unshot: f64,
    shots_since_best: u64,
    stop: Option<StopReason>,
    // Per-shot scratch, kept to avoid allocating in the loop.
    plans: Vec<PatchPlan>,
    /// Plans depend on geometry only, so each shooter's plans are kept for its next shots
    /// when its form factors are not (see `rows`), up to [`PLAN_CACHE_ENTRIES`] in all.
    plan_rows: Vec<Option<Box<[PatchPlan]>>>,
    plan_entries: usize,
    /// Each shooter's form factors to its receivers, kept up to `params.row_cache_bytes`.
    rows: Vec<Option<Row>>,
    row_bytes: usize,
    factors: Vec<Received>,
    /// Per element, whether it takes penumbra rays from the current shooter.
    penumbra: Vec<bool>,
    /// Elements sharing an edge (see [`element_neighbours`]).
    neighbour_start: Vec<u32>,
    neighbours: Vec<u32>,
    /// Per element, the cumulative share of its patch's unshot power over the patch's
    /// elements, fixed at the patch's first shot (see [`Solver::freeze_cdf`]).
    cdf: Vec<f64>,
    cdf_frozen: Vec<bool>,
    /// Per element, its unshot radiosity over its patch's mean at the patch's first shot;
    /// kept for patches where it strays from 1 (see [`Solver::freeze_cdf`]).
    density: Vec<f64>,
    nonuniform: Vec<bool>,
    /// Per patch, whether its first shot was bright (see `SolverParams::bright_share` and
    /// [`Solver::freeze_cdf`]).
    bright: Vec<bool>,
    /// Power of the solve's first shot, the largest (set by [`Solver::freeze_cdf`]).
    first_shot_power: f64,
    clusters: Vec<Cluster>,
    cluster_order: Vec<u32>,
    targets: Vec<DVec3>,
    /// `targets` lifted off the shooter by the ray offset, in single precision: ray ends.
    lifted_targets: Vec<Vec3>,
    shooter_elements: Vec<ShooterElement>,
}

/// One shooter's form factors F_{j→shooter} (visibility included) to the elements of every
/// patch that can receive from it, as runs of consecutive elements.
struct Row {
    /// `(first element, element count)` of each receiving patch, in patch order.
    spans: Vec<(u32, u32)>,
    /// The factors, span after span, in f32 (7 digits, far below the visibility noise); a
    /// row applied fresh is rounded the same way, so keeping it changes nothing.
    factors: Vec<f32>,
}

impl Row {
    fn bytes(&self) -> usize {
        std::mem::size_of::<Self>() + 8 * self.spans.len() + 4 * self.factors.len()
    }
}

/// Corners of one element of the shooter, copied once per shot so ray ends need no lookups.
#[derive(Clone, Copy, Debug)]
struct ShooterElement {
    corners: [DVec3; 4],
    count: u8,
    centre: DVec3,
    /// Circumradius about `centre`.
    radius: f64,
    area: f64,
}

impl ShooterElement {
    fn corners(&self) -> &[DVec3] {
        &self.corners[..self.count as usize]
    }

    /// Form factor from a differential area at `p` (normal `n`) to this element of a shooter
    /// with normal `ns`: the exact polygon formula up close, else the point-to-point one,
    /// cos θ cos θ' A / (π r²), which is within ~2 % beyond four radii (Cohen & Wallace
    /// §4.9's "five times rule" is the same trade).
    fn factor_from(&self, p: DVec3, n: DVec3, ns: DVec3) -> f64 {
        if self.centre.distance_squared(p) < 16.0 * self.radius * self.radius {
            point_to_polygon(p, n, self.corners())
        } else {
            point_to_point(p, n, self.centre, ns, self.area)
        }
    }
}

/// Up to [`CLUSTER`] nearby elements of an uneven shooter, so that a receiver needs to visit
/// the elements of only the clusters it is close to (see [`density_weight`]).
#[derive(Clone, Debug)]
struct Cluster {
    /// Its elements, as a range of `Solver::cluster_order`.
    members: std::ops::Range<usize>,
    centre: DVec3,
    /// Radius about `centre` that holds all its elements.
    radius: f64,
    area: f64,
    /// Area-weighted mean density of its elements.
    density: f64,
}

/// Most elements in one [`Cluster`].
const CLUSTER: usize = 16;

/// Cuts `order` (indices into `elements`) by median splits along the longest extent of the
/// element centres until each piece holds at most [`CLUSTER`] elements; appends the pieces.
fn build_clusters(
    order: &mut [u32],
    base: usize,
    elements: &[ShooterElement],
    density: &[f64],
    out: &mut Vec<Cluster>,
) {
    let el = |k: &u32| &elements[*k as usize];
    if order.len() > CLUSTER {
        let (lo, hi) = bounds(order.iter().map(|k| &el(k).centre));
        let axis = (hi - lo).max_position();
        let mid = order.len() / 2;
        order.select_nth_unstable_by(mid, |a, b| el(a).centre[axis].total_cmp(&el(b).centre[axis]));
        let (left, right) = order.split_at_mut(mid);
        build_clusters(left, base, elements, density, out);
        build_clusters(right, base + mid, elements, density, out);
        return;
    }
    let area: f64 = order.iter().map(|k| el(k).area).sum();
    let centre = order.iter().map(|k| el(k).centre * el(k).area).sum::<DVec3>() / area;
    let radius = order.iter().map(|k| el(k).centre.distance(centre) + el(k).radius).fold(0.0, f64::max);
    let density = order.iter().map(|k| density[*k as usize] * el(k).area).sum::<f64>() / area;
    out.push(Cluster { members: base..base + order.len(), centre, radius, area, density });
}

/// What one shot decides once for a whole receiving patch, so its elements need not.
#[derive(Clone, Debug)]
struct PatchPlan {
    /// Some part of the patch and of the shooter face each other.
    live: bool,
    /// Every element is far enough for the single-midpoint rule.
    far: bool,
    /// The patch lies strictly in front of the shooter's plane and the shooter strictly in
    /// front of the patch's, so no receiver point needs hemisphere clipping.
    facing: bool,
    /// The shooter lies in front of the patch's plane or on it: those of its elements that
    /// lie strictly in front of the shooter's see all of it (see `receive`).
    shooter_ahead: bool,
    /// The patch and the shooter are live but not strictly facing: they meet or cross each
    /// other's planes (a wall on the floor, a block standing on it). Set on both paths.
    touching: bool,
    /// How its rays are answered.
    visibility: Visibility,
    /// The blocking triangles that may meet its rays, when `visibility` is `Few`.
    candidates: Vec<u32>,
}

impl Default for PatchPlan {
    fn default() -> Self {
        Self {
            live: false,
            far: false,
            facing: false,
            shooter_ahead: false,
            touching: false,
            visibility: Visibility::Tree,
            candidates: Vec::new(),
        }
    }
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
        if params.dim_rays == 0 {
            return bad("dim_rays", "0".into(), "at least 1");
        }
        if !(0.0..=1.0).contains(&params.bright_share) {
            return bad("bright_share", params.bright_share.to_string(), "a share in [0, 1]");
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
        // Patches own consecutive runs of elements, in order (as `Mesh::build` makes them):
        // a row is split into one slice per patch.
        let mut next = 0;
        for (q, p) in mesh.patches.iter().enumerate() {
            if p.elements.start != next || p.elements.end < p.elements.start {
                return Err(SolverError::BadMesh { patch: q });
            }
            next = p.elements.end;
        }
        if next as usize != mesh.elements.len() {
            return Err(SolverError::BadMesh { patch: mesh.patches.len() });
        }
        let n = mesh.elements.len();
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
        let mean_reflectance = (mesh.elements.iter().enumerate())
            .map(|(e, el)| mesh.element_material(e).reflectance * el.area)
            .sum::<Rgb>()
            / total_area;
        let (lo, hi) = mesh.bounds();
        // One scan for both ray-skipping structures (it can cost T × V half-space tests).
        let blocking = blocking_triangles(&mesh);
        let element_radii: Vec<f64> = (0..n).map(|e| element_radius(&mesh, e)).collect();
        let patch_element_radius = mesh
            .patches
            .iter()
            .map(|p| {
                element_radii[p.elements.start as usize..p.elements.end as usize]
                    .iter()
                    .copied()
                    .fold(0.0, f64::max)
            })
            .collect();
        let (neighbour_start, neighbours) = element_neighbours(&mesh);
        let element_area = mesh.elements.iter().map(|el| el.area).collect();
        let ray_offset = 1e-6 * (hi - lo).length();
        let lifted_corners = lift_corners(&mesh, ray_offset);
        let vertex_means = (0..n)
            .map(|e| mesh.element_corners(e).sum::<DVec3>() / f64::from(mesh.elements[e].vertex_count))
            .collect();
        let patch_reflectance = mesh
            .patches
            .iter()
            .map(|p| mesh.materials[mesh.surfaces[p.surface as usize].material as usize].reflectance)
            .collect();
        let patch_unshot_emission = (mesh.patches.iter())
            .map(|p| p.elements.clone().map(|e| emission[e as usize] * mesh.elements[e as usize].area).sum())
            .collect();
        let mut s = Self {
            patch_unshot_power: vec![Rgb::ZERO; mesh.patches.len()],
            direct: vec![Rgb::ZERO; n],
            patch_unshot_emission,
            plans: vec![PatchPlan::default(); mesh.patches.len()],
            plan_rows: vec![None; mesh.patches.len()],
            plan_entries: 0,
            rows: (0..mesh.patches.len()).map(|_| None).collect(),
            row_bytes: 0,
            cdf: vec![0.0; n],
            cdf_frozen: vec![false; mesh.patches.len()],
            density: vec![1.0; n],
            nonuniform: vec![false; mesh.patches.len()],
            bright: vec![false; mesh.patches.len()],
            first_shot_power: 0.0,
            clusters: Vec::new(),
            cluster_order: Vec::new(),
            targets: Vec::new(),
            lifted_targets: Vec::new(),
            shooter_elements: Vec::new(),
            factors: vec![Received::default(); n],
            penumbra: vec![false; n],
            neighbour_start,
            neighbours,
            ray_offset,
            occluder_boxes: OccluderBoxes::new(&blocking),
            blockers: Blockers::new(&mesh, &blocking),
            patch_element_radius,
            mesh,
            accel,
            params,
            radiosity: emission.clone(),
            unshot: emission,
            vertex_area,
            element_area,
            vertex_means,
            element_radii,
            lifted_corners,
            patch_reflectance,
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
                let mesh = &self.mesh;
                (self.radiosity.iter().enumerate())
                    .map(|(e, b)| *b + self.patch_reflectance[mesh.elements[e].patch as usize] * ambient)
                    .collect()
            }
        };
        Solution {
            vertex_radiosity: vertex_average(&self.mesh, &element_radiosity, &self.vertex_area),
            element_radiosity,
            vertex_direct: vertex_average(&self.mesh, &self.direct, &self.vertex_area),
            element_direct: self.direct.clone(),
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
        let omega = match self.params.overshoot {
            Overshoot::Off => 1.0,
            Overshoot::Relaxation(w) => w,
        };
        let (row, kept) = match self.rows[shooter].take() {
            Some(row) => (row, true),
            None => (self.transfer_row(shooter), false),
        };
        self.apply(shooter, &row, omega);
        let bytes = row.bytes();
        if kept || (!self.params.reference_path && self.row_bytes + bytes <= self.params.row_cache_bytes) {
            self.row_bytes += if kept { 0 } else { bytes };
            self.rows[shooter] = Some(row);
        } else if self.plan_rows[shooter].is_none() {
            // The row will be computed again: keep its plans (still in `self.plans`).
            let entries = plan_entries(&self.plans);
            if self.plan_entries + entries <= PLAN_CACHE_ENTRIES {
                self.plan_entries += entries;
                self.plan_rows[shooter] = Some(self.plans.clone().into_boxed_slice());
            }
        }

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

    /// Shoots ω times the shooter's unshot radiosity through its row of form factors.
    fn apply(&mut self, shooter: usize, row: &Row, omega: f64) {
        let mesh = Arc::clone(&self.mesh);
        let patch = &mesh.patches[shooter];
        let shot_b = self.patch_unshot_power[shooter] * (omega / patch.area);
        // Each receiving span (one patch, of one reflectance) takes ρ × the shot's radiosity
        // times F per element, and its Σ F·A; spans own disjoint elements, so they may run
        // in parallel. The sums over spans then run in span order: the same numbers for any
        // thread count.
        let mut spans = Vec::with_capacity(row.spans.len());
        let (mut radiosity, mut unshot) = (&mut self.radiosity[..], &mut self.unshot[..]);
        let (mut at, mut offset) = (0, 0);
        for &(first, count) in &row.spans {
            let (first, count) = (first as usize, count as usize);
            let (r, rest_r) = std::mem::take(&mut radiosity)[first - at..].split_at_mut(count);
            let (u, rest_u) = std::mem::take(&mut unshot)[first - at..].split_at_mut(count);
            (radiosity, unshot, at) = (rest_r, rest_u, first + count);
            let rho = self.patch_reflectance[mesh.elements[first].patch as usize];
            let area = &self.element_area[first..first + count];
            spans.push((rho * shot_b, &row.factors[offset..offset + count], area, r, u));
            offset += count;
        }
        let receive = |(per_factor, factors, area, radiosity, unshot): &mut (
            Rgb,
            &[f32],
            &[f64],
            &mut [Rgb],
            &mut [Rgb],
        )| {
            let mut seen = 0.0;
            for k in 0..factors.len() {
                let f = f64::from(factors[k]);
                let reflected = *per_factor * f; // ρ × irradiance from this shot, W/unit²
                radiosity[k] += reflected;
                unshot[k] += reflected;
                seen += f * area[k];
            }
            seen
        };
        let seen: Vec<f64> = if mesh.elements.len() < APPLY_PARALLEL_MIN || rayon::current_num_threads() == 1
        {
            spans.iter_mut().map(receive).collect()
        } else {
            spans.par_iter_mut().with_min_len(APPLY_SPANS_PER_TASK).map(receive).collect()
        };
        let mut received = Rgb::ZERO;
        for (&(first, _), (span, seen)) in row.spans.iter().zip(spans.iter().zip(seen)) {
            let gained = span.0 * seen;
            let span_received = shot_b * seen;
            received += span_received;
            self.absorbed += span_received - gained;
            self.patch_unshot_power[mesh.elements[first as usize].patch as usize] += gained;
        }
        self.escaped += shot_b * patch.area - received;
        self.tally_direct(shooter, row, omega);
        for e in patch.elements.start..patch.elements.end {
            self.unshot[e as usize] *= 1.0 - omega;
        }
        self.patch_unshot_power[shooter] *= 1.0 - omega;
    }

    /// Adds to each receiver the part of this shot that is the shooter's own emission: the
    /// direct light a final gather recomputes by shadow rays (Chen et al. 1991) and must not
    /// count twice. Only emitters' shots carry any, so the extra pass is rare.
    fn tally_direct(&mut self, shooter: usize, row: &Row, omega: f64) {
        let emission = self.patch_unshot_emission[shooter];
        if emission.max_channel() <= 0.0 {
            return;
        }
        let shot_e = emission * (omega / self.mesh.patches[shooter].area);
        self.patch_unshot_emission[shooter] *= 1.0 - omega;
        let mut offset = 0;
        for &(first, count) in &row.spans {
            let (first, count) = (first as usize, count as usize);
            let rho = self.patch_reflectance[self.mesh.elements[first].patch as usize];
            for (k, f) in row.factors[offset..offset + count].iter().enumerate() {
                self.direct[first + k] += rho * shot_e * f64::from(*f);
            }
            offset += count;
        }
    }

    /// Fixes where on `shooter` its rays end, from its elements' unshot power at its first
    /// shot: a patch lit on one part only (half under a block, half in a shadow) then shoots
    /// from that part instead of spreading its power over the dark part, whose rays would be
    /// blocked and its light lost. The share is kept for its later shots, so that they reuse
    /// the same rays (and its row of form factors); the light a patch receives later comes
    /// mostly the same way as the first. Whether it takes penumbra rays is fixed then too.
    fn freeze_cdf(&mut self, shooter: usize) {
        if self.cdf_frozen[shooter] {
            return;
        }
        self.cdf_frozen[shooter] = true;
        // Bright or dim (see `SolverParams::bright_share`), by the first shot's power too: a
        // recomputed row must be the kept one.
        let power = self.patch_unshot_power[shooter].abs().sum();
        if self.shots == 0 {
            self.first_shot_power = power;
        }
        self.bright[shooter] = power >= self.params.bright_share * self.first_shot_power;
        let range = self.mesh.patches[shooter].elements.clone();
        let (first, end) = (range.start as usize, range.end as usize);
        let elements = &self.mesh.elements[first..end];
        let mut acc = 0.0;
        for ((c, u), el) in self.cdf[first..end].iter_mut().zip(&self.unshot[first..end]).zip(elements) {
            acc += (*u * el.area).abs().sum();
            *c = acc;
        }
        if acc <= 0.0 || !acc.is_finite() {
            acc = 0.0;
            for (c, el) in self.cdf[first..end].iter_mut().zip(elements) {
                acc += el.area;
                *c = acc;
            }
        }
        for c in &mut self.cdf[first..end] {
            *c /= acc;
        }
        // Density of each element's share against an even spread: share_k · A_p / A_k.
        let area = self.mesh.patches[shooter].area;
        let mut below = 0.0;
        let mut nonuniform = false;
        for ((d, &c), el) in self.density[first..end].iter_mut().zip(&self.cdf[first..end]).zip(elements) {
            *d = (c - below) * area / el.area;
            below = c;
            nonuniform |= (*d - 1.0).abs() > NONUNIFORM;
        }
        self.nonuniform[shooter] = nonuniform;
    }

    /// The form factor from every element to `shooter`, visibility included.
    fn transfer_row(&mut self, shooter: usize) -> Row {
        let mesh = Arc::clone(&self.mesh);
        let patch = &mesh.patches[shooter];
        let corners = patch.corners();

        // Decide per receiving patch first. A patch receives only if part of it is in front
        // of the shooter and part of the shooter is in front of it; then its shaft says which
        // triangles can block its rays, and its distance whether all its elements may use
        // one midpoint.
        let in_front =
            |pts: &[DVec3], c: DVec3, n: DVec3| pts.iter().any(|p| n.dot(*p - c) > 1e-12 * patch.area.sqrt());
        let (blockers, offset, reference) = (&self.blockers, self.ray_offset, self.params.reference_path);
        let radius = &self.patch_element_radius;
        let cached = self.plan_rows[shooter].is_some();
        for_each_maybe_parallel(if cached { &mut [] } else { &mut self.plans }, |q, plan| {
            let r = &mesh.patches[q];
            plan.live = q != shooter
                && in_front(r.corners(), patch.centre, patch.normal)
                && in_front(corners, r.centre, r.normal);
            let strictly = |pts: &[DVec3], c: DVec3, n: DVec3| {
                pts.iter().all(|p| n.dot(*p - c) > 1e-9 * patch.area.sqrt())
            };
            let receiver_point = mesh.elements[r.elements.start as usize].centre;
            let facing = plan.live
                && strictly(r.corners(), corners[0], patch.normal)
                && strictly(corners, receiver_point, r.normal);
            // The shooter on or in front of the patch's plane (a floor patch along a wall's
            // foot): clipping it at the plane changes nothing.
            let shooter_ahead = plan.live
                && corners.iter().all(|p| r.normal.dot(*p - receiver_point) > -1e-9 * patch.area.sqrt());
            plan.touching = plan.live && !facing;
            if !plan.live || reference {
                plan.far = false;
                plan.facing = false;
                plan.shooter_ahead = false;
                plan.visibility = Visibility::Tree;
                return;
            }
            plan.facing = facing;
            plan.shooter_ahead = shooter_ahead;
            // Each element's own test (`quadrature`) is k·r_e < d(c_e) − r_e, and d(c_e) ≥ d(c_q) − r_q for
            // every element centre c_e of the patch, so this implies it for all of them.
            let patch_radius = r.corners().iter().map(|p| p.distance(r.centre)).fold(0.0, f64::max);
            plan.far = (MIDPOINT_RATIO + 1.0) * radius[q]
                < distance_to_polygon(r.centre, patch.normal, corners) - patch_radius;
            plan.visibility = blockers.gather(
                Pair { a: corners, na: patch.normal, b: r.corners(), nb: r.normal, offset },
                &mut plan.candidates,
            );
        });

        self.freeze_cdf(shooter);
        self.shooter_elements.clear();
        for e in patch.elements.start..patch.elements.end {
            let mut corners = [DVec3::ZERO; 4];
            for (slot, p) in corners.iter_mut().zip(mesh.element_corners(e as usize)) {
                *slot = p;
            }
            let count = mesh.elements[e as usize].vertex_count;
            let centre = mesh.elements[e as usize].centre;
            let radius = self.element_radii[e as usize];
            let area = mesh.elements[e as usize].area;
            self.shooter_elements.push(ShooterElement { corners, count, centre, radius, area });
        }

        let density = &self.density[patch.elements.start as usize..patch.elements.end as usize];
        let shooter_cdf = &self.cdf[patch.elements.start as usize..patch.elements.end as usize];
        // Ray ends: one jittered point per cell of a TARGETS × TARGETS grid over the unit
        // square, mapped onto the shooter by unshot power. A ray's stratified (u, v) picks its
        // cell's point, so the rays keep their stratification and cost a lookup each.
        let mut rng = Rng::for_task(self.params.seed, shooter as u64, u64::MAX);
        self.targets.clear();
        for b in 0..TARGETS {
            for a in 0..TARGETS {
                let u = (a as f64 + rng.next_f64()) / TARGETS as f64;
                let v = (b as f64 + rng.next_f64()) / TARGETS as f64;
                self.targets.push(shooter_point(shooter_cdf, &self.shooter_elements, u, v));
            }
        }
        let lift = patch.normal * self.ray_offset;
        self.lifted_targets.clear();
        self.lifted_targets.extend(self.targets.iter().map(|t| (*t + lift).as_vec3()));
        self.clusters.clear();
        self.cluster_order.clear();
        if self.nonuniform[shooter] {
            self.cluster_order.extend(0..self.shooter_elements.len() as u32);
            build_clusters(&mut self.cluster_order, 0, &self.shooter_elements, density, &mut self.clusters);
        }
        let shot = Shot {
            mesh: &mesh,
            shooter: patch,
            targets: &self.targets,
            lifted_targets: &self.lifted_targets,
            shooter_elements: &self.shooter_elements,
            vertex_means: &self.vertex_means,
            element_radii: &self.element_radii,
            lifted_corners: &self.lifted_corners,
            uneven: self.nonuniform[shooter].then_some(Uneven {
                density,
                clusters: &self.clusters,
                order: &self.cluster_order,
            }),
            accel: &*self.accel,
            boxes: &self.occluder_boxes,
            blockers: &self.blockers,
            params: &self.params,
            offset: self.ray_offset,
            stream: shooter as u64,
            shooter_radius: corners.iter().map(|c| c.distance(patch.centre)).fold(0.0, f64::max),
            single_key: Rng::for_task(self.params.seed, shooter as u64, SINGLE_STREAM).next_u64(),
            pilot: Strata::new(if self.bright[shooter] {
                self.params.visibility_rays
            } else {
                self.params.dim_rays
            }),
            penumbra: Strata::new(self.params.penumbra_rays),
        };
        let plans: &[PatchPlan] = self.plan_rows[shooter].as_deref().unwrap_or(&self.plans);
        // First pass, patch by patch: each receiving patch writes its own elements' slice.
        let mut slices: Vec<&mut [Received]> = Vec::with_capacity(mesh.patches.len());
        let mut rest = &mut self.factors[..];
        for p in &mesh.patches {
            let (own, after) = rest.split_at_mut(p.elements.len());
            slices.push(own);
            rest = after;
        }
        let receive_one = |q: usize, out: &mut &mut [Received]| {
            receive_patch(&shot, &plans[q], mesh.patches[q].elements.start as usize, out)
        };
        if mesh.elements.len() < PARALLEL_MIN || rayon::current_num_threads() == 1 {
            slices.iter_mut().enumerate().for_each(|(q, out)| receive_one(q, out));
        } else {
            // About 64 elements per task, as `for_each_maybe_parallel` takes them.
            let per_task = (PARALLEL_MIN * mesh.patches.len() / mesh.elements.len()).max(1);
            slices.par_iter_mut().enumerate().with_min_len(per_task).for_each(|(q, out)| receive_one(q, out));
        }
        // Penumbrae: more rays where the neighbours' pilot rays disagree, from shooters
        // bright enough for their noise to show.
        let count = self.params.penumbra_rays;
        if count > 0 && self.bright[shooter] {
            let (first, start, adjacent) = (&self.factors, &self.neighbour_start, &self.neighbours);
            for_each_maybe_parallel(&mut self.penumbra, |e, out| {
                *out = wants_penumbra_rays(first, e, &adjacent[start[e] as usize..start[e + 1] as usize]);
            });
            let flags = &self.penumbra;
            for_each_maybe_parallel(&mut self.factors, |e, out| {
                if flags[e] {
                    let plan = &plans[mesh.elements[e].patch as usize];
                    let (visible, traced) = trace(&shot, plan, e, Rays::Penumbra);
                    out.visible += visible;
                    out.traced += traced;
                }
            });
        }

        let mut row = Row { spans: Vec::new(), factors: Vec::new() };
        for (q, plan) in plans.iter().enumerate() {
            if !plan.live {
                continue;
            }
            let range = mesh.patches[q].elements.clone();
            row.spans.push((range.start, range.end - range.start));
            let factors = &self.factors[range.start as usize..range.end as usize];
            row.factors.extend(factors.iter().map(|r| r.factor() as f32));
            self.rays += factors.iter().map(|r| u64::from(r.traced)).sum::<u64>();
        }
        row
    }
}

/// Key bit of an element's penumbra-ray stream, apart from its pilot-ray stream.
const PENUMBRA_STREAM: u64 = 1 << 63;

/// Key of a row's one-ray hashes, apart from every element's streams.
const SINGLE_STREAM: u64 = (1 << 63) - 1;

/// Each element's neighbours: the elements sharing an edge with it (the mesh shares
/// vertices within a surface, across its patches too), as `(start, list)`: element `e`'s
/// are `list[start[e]..start[e + 1]]`. Edge neighbours, not vertex ones: on Cornell 15.6 k
/// the diagonal neighbours added 7 % more rays (4 % of the solve) and changed neither the
/// object means (0.17 % against 0.19 % RMS from 64 rays) nor the render (0.76 % against
/// 0.73 % RMS pixel difference from a 64-ray render).
fn element_neighbours(mesh: &Mesh) -> (Vec<u32>, Vec<u32>) {
    // Elements around each vertex, then the union over an element's vertices.
    let mut around = vec![Vec::new(); mesh.positions.len()];
    for (e, el) in mesh.elements.iter().enumerate() {
        for &v in el.vertex_indices() {
            around[v as usize].push(e as u32);
        }
    }
    let (mut start, mut list) = (Vec::with_capacity(mesh.elements.len() + 1), Vec::new());
    start.push(0);
    for (e, el) in mesh.elements.iter().enumerate() {
        let first = list.len();
        for &v in el.vertex_indices() {
            for &n in &around[v as usize] {
                let shared = mesh.elements[n as usize]
                    .vertex_indices()
                    .iter()
                    .filter(|v| el.vertex_indices().contains(v))
                    .count();
                if n as usize != e && shared >= 2 && !list[first..].contains(&n) {
                    list.push(n);
                }
            }
        }
        start.push(list.len() as u32);
    }
    (start, list)
}

/// Below this many elements a shot is applied on one thread (a parallel pass costs more).
const APPLY_PARALLEL_MIN: usize = 32_768;

/// Receiving spans per parallel task when a shot is applied.
const APPLY_SPANS_PER_TASK: usize = 16;

/// Entries of one shooter's plans (receiving patches plus candidate triangles).
fn plan_entries(plans: &[PatchPlan]) -> usize {
    plans.len() + plans.iter().map(|p| p.candidates.len()).sum::<usize>()
}

/// A shooter with an element whose unshot density strays from the mean by more than this
/// share weights the form factors of the receivers that touch it (see `receive`). The density
/// is fixed at the shooter's first shot, so only strong, lasting structure is trusted:
/// shadows and contact lines (a block standing on the patch: dark under it on every shot),
/// not the gentle gradients of indirect light, which change from shot to shot. Measured: at
/// 0.05 the ρ = 0.5 furnace's elements drift 2.4 % from E/(1 − ρ); at 0.5 they stay within
/// its 0.5 % test, and the Cornell box's coarse patches match 35 mm shooters to 0.8 % RMS.
const NONUNIFORM: f64 = 0.5;

/// Most plan entries (receiving patches plus candidate triangles) kept across shots: about
/// 40 MB, every shooter's row for a scene of a thousand patches.
const PLAN_CACHE_ENTRIES: usize = 1 << 20;

/// Below this many items a loop runs on the calling thread: handing a job to the pool and
/// waiting for it costs tens of microseconds, more than a few dozen receivers take (the
/// source document's 145 facets are still worth two threads: 0.24 s against 0.38 s).
const PARALLEL_MIN: usize = 64;

/// `f(index, item)` for every item, on the thread pool when there are enough items. Each item
/// is written by exactly one call, so the result is the same either way.
fn for_each_maybe_parallel<T: Send>(items: &mut [T], f: impl Fn(usize, &mut T) + Sync + Send) {
    if items.len() < PARALLEL_MIN || rayon::current_num_threads() == 1 {
        items.iter_mut().enumerate().for_each(|(i, x)| f(i, x));
    } else {
        items.par_iter_mut().enumerate().with_min_len(64).for_each(|(i, x)| f(i, x));
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
    if MIDPOINT_RATIO * el_radius < gap {
        return (1, Rule::Midpoint);
    }
    (((4.0 * el_radius / gap).ceil() as u32).clamp(1, max), Rule::Gauss)
}

/// [`quadrature`] for an element at `centre` with circumradius `radius`, and the shooter
/// (circumradius `shooter_radius` about its centre). The exact distance to the shooter lies
/// between the larger of the distance to its plane and the distance to its centre less its
/// radius, and the distance to its centre; the rule only grows as the gap shrinks, so when
/// both bounds (widened by a millionth, more than the exact distance's rounding) give the
/// same rule, so does the exact distance, which is then not computed (it costs ~10 times
/// as much for elements beside the shooter).
fn element_quadrature(
    centre: DVec3,
    radius: f64,
    shooter: &radiosity_core::Patch,
    shooter_radius: f64,
    max: u32,
) -> (u32, Rule) {
    let corners = shooter.corners();
    let to_centre = centre.distance(shooter.centre);
    let height = shooter.normal.dot(centre - corners[0]).abs();
    let (low, high) = (height.max(to_centre - shooter_radius), to_centre);
    let near = quadrature(radius, low * (1.0 - 1e-6) - radius, max);
    if near == quadrature(radius, high * (1.0 + 1e-6) - radius, max) {
        return near;
    }
    quadrature(radius, distance_to_polygon(centre, shooter.normal, corners) - radius, max)
}

/// An element takes one midpoint when its gap to the shooter exceeds this many of its radii.
const MIDPOINT_RATIO: f64 = 16.0;

/// What every receiver of one shot reads.
struct Shot<'a> {
    mesh: &'a Mesh,
    shooter: &'a radiosity_core::Patch,
    /// Ray ends on the shooter, `TARGETS`² of them, row after row (see [`target_cell`]).
    targets: &'a [DVec3],
    /// The same points lifted off the shooter by `offset`, as the rays take them.
    lifted_targets: &'a [Vec3],
    /// The shooter's elements.
    shooter_elements: &'a [ShooterElement],
    /// Every element's vertex mean (see [`Solver::vertex_means`]).
    vertex_means: &'a [DVec3],
    /// Every element's circumradius.
    element_radii: &'a [f64],
    /// Every element's corners lifted off it by `offset`, in single precision: where its
    /// rays start (see [`lift_corners`]).
    lifted_corners: &'a [[Vec3A; 4]],
    /// How the shooter's unshot radiosity is spread, when it is uneven.
    uneven: Option<Uneven<'a>>,
    accel: &'a dyn RayQuery,
    boxes: &'a OccluderBoxes,
    blockers: &'a Blockers,
    params: &'a SolverParams,
    /// Ray origins and targets are lifted this far off their surfaces.
    offset: f64,
    /// Key of the random streams: the shooter, so that every shot of it draws the same rays.
    stream: u64,
    /// Key of the one-ray receivers' hashes (see [`four_units`]).
    single_key: u64,
    /// The shooter's circumradius about its centre.
    shooter_radius: f64,
    /// Strata of the pilot and of the penumbra rays.
    pilot: Strata,
    penumbra: Strata,
}

/// The point at `(u, v)` ∈ [0,1)² on the shooter, drawn by unshot power: `u` picks the
/// element from the cumulative shares and, rescaled into that element's share, places the
/// point within it with `v`, so stratification in `(u, v)` carries over.
fn shooter_point(cdf: &[f64], elements: &[ShooterElement], u: f64, v: f64) -> DVec3 {
    let k = cdf.partition_point(|&c| c <= u).min(cdf.len() - 1);
    let below = if k == 0 { 0.0 } else { cdf[k - 1] };
    let share = cdf[k] - below;
    let u = if share > 0.0 { ((u - below) / share).clamp(0.0, 1.0 - f64::EPSILON) } else { 0.5 };
    point_on(elements[k].corners(), u, v)
}

/// Ray-end cells per side of the unit square (see `Solver::transfer_row`): 256 points on
/// each shooter, far more than the 4 to 16 rays of one receiver.
const TARGETS: usize = 16;

/// Index in the ray-end table of the cell that holds `(u, v)` ∈ [0,1)².
fn target_cell(u: f32, v: f32) -> usize {
    let cell = |x: f32| ((x * TARGETS as f32) as u32).min(TARGETS as u32 - 1) as usize;
    cell(v) * TARGETS + cell(u)
}

/// Every element's corners lifted off its surface by `offset` along its normal, in single
/// precision (a triangle's fourth slot stays zero): the origins of its rays, the same
/// points every row.
fn lift_corners(mesh: &Mesh, offset: f64) -> Vec<[Vec3A; 4]> {
    (0..mesh.elements.len())
        .map(|e| {
            let lift = mesh.elements[e].normal * offset;
            let mut out = [Vec3A::ZERO; 4];
            for (l, p) in out.iter_mut().zip(mesh.element_corners(e)) {
                *l = (p + lift).as_vec3().into();
            }
            out
        })
        .collect()
}

/// Circumradius of element `e` about its centre.
fn element_radius(mesh: &Mesh, e: usize) -> f64 {
    let c = mesh.elements[e].centre;
    mesh.element_corners(e).map(|p| p.distance(c)).fold(0.0, f64::max)
}

/// What one element learns from one shooter's first pass: its form factor without
/// visibility, and its pilot rays.
#[derive(Clone, Copy, Debug, Default)]
struct Received {
    /// F_{e→shooter} without visibility (weighted for uneven shooters); 0 when it cannot
    /// receive.
    unoccluded: f64,
    /// Unblocked rays among `traced`.
    visible: u32,
    /// Rays traced; 0 when the pair needs none (nothing can block it).
    traced: u32,
}

impl Received {
    /// The element's form factor with visibility.
    fn factor(&self) -> f64 {
        if self.traced == 0 {
            return self.unoccluded;
        }
        self.unoccluded * f64::from(self.visible) / f64::from(self.traced)
    }

    /// How its pilot rays saw the shooter; `None` when it does not receive at all.
    fn light(&self) -> Option<Light> {
        (self.unoccluded > 0.0).then_some(match (self.visible, self.traced) {
            (_, 0) => Light::Full,
            (v, t) if v == t => Light::Full,
            (0, _) => Light::None,
            _ => Light::Partial,
        })
    }
}

/// What an element's pilot rays said.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Light {
    Full,
    Partial,
    None,
}

/// Element `e`'s corners in a fixed array (the first `vertex_count` are its own).
fn corners_of(mesh: &Mesh, e: usize) -> [DVec3; 4] {
    let mut pts = [DVec3::ZERO; 4];
    for (k, p) in mesh.element_corners(e).enumerate() {
        pts[k] = p;
    }
    pts
}

/// Element `e`'s form factor to the shooter without visibility (weighted for an uneven
/// shooter).
fn unoccluded(shot: &Shot, plan: &PatchPlan, e: usize) -> f64 {
    let Shot { mesh, shooter, shooter_elements, uneven, params, .. } = *shot;
    let el = &mesh.elements[e];
    let pts = corners_of(mesh, e);
    let receiver = &pts[..el.vertex_count as usize];
    let corners = shooter.corners();
    let facing = element_facing(shooter, plan, receiver);
    match params.form_factor {
        FormFactorMethod::Exact => {
            let (n, rule) = if plan.far {
                (1, Rule::Midpoint)
            } else {
                let el_radius = shot.element_radii[e];
                element_quadrature(el.centre, el_radius, shooter, shot.shooter_radius, params.max_quadrature)
            };
            // The fast path evaluates the formula in four f32 lanes (within 3e-7 absolute of
            // the f64 loop, see `point_to_polygon_in_front_x4`); the reference path in f64.
            let fast = !params.reference_path;
            let mut f = 0.0;
            if facing && plan.far && fast {
                // One midpoint and nothing to clip.
                let centre = shot.vertex_means[e];
                f = point_to_polygon_in_front_x4(centre, el.normal, corners);
            } else if facing {
                let eval = if fast { point_to_polygon_in_front_x4 } else { point_to_polygon_in_front };
                for_each_point(receiver, n, rule, |p, w| f += w * eval(p, el.normal, corners));
            } else {
                // Clipped polygons keep the f64 loop: their receivers sit next to the shooter,
                // where nearly parallel edge vectors make f32 lose digits.
                for_each_point(receiver, n, rule, |p, w| {
                    if shooter.normal.dot(p - corners[0]) > 0.0 {
                        f += w * point_to_polygon(p, el.normal, corners);
                    }
                });
            }
            if let Some(uneven) = uneven.filter(|_| plan.touching) {
                // A receiver on or across the shooter's plane sees only part of it (a block
                // side sees the floor in front of it, not under it), so the shooter's mean
                // unshot radiosity is wrong for it when that radiosity is uneven: the
                // transfer is Σ_k ΔB_k F_{j→k} = ΔB̄ Σ_k d_k F_{j→k}, d_k = ΔB_k/ΔB̄. The
                // form factor keeps its quadrature; the weighting is taken at the centre.
                // The whole patch is weighted, its elements off the plane too: they are the
                // ones next to the contact line.
                f *= density_weight(el.centre, el.normal, shooter.normal, &uneven, shooter_elements);
            }
            f
        }
        FormFactorMethod::PointToPoint => {
            point_to_point(el.centre, el.normal, shooter.centre, shooter.normal, shooter.area)
        }
    }
}

/// The first pass for the elements of one receiving patch (`first` is its first element,
/// `out` its slice): their unoccluded form factors, then their pilot rays. A patch that faces
/// the shooter from far away takes its elements' form factors four at a time (one midpoint
/// each, nothing to clip: the same formula and points as [`unoccluded`]).
fn receive_patch(shot: &Shot, plan: &PatchPlan, first: usize, out: &mut [Received]) {
    out.fill(Received::default());
    if !plan.live {
        return;
    }
    let params = shot.params;
    if plan.facing && plan.far && !params.reference_path && params.form_factor == FormFactorMethod::Exact {
        let corners = shot.shooter.corners();
        for (c, chunk) in out.chunks_mut(4).enumerate() {
            let base = first + 4 * c;
            let (mut points, mut normals) = ([DVec3::ZERO; 4], [DVec3::ZERO; 4]);
            for (k, (p, n)) in points.iter_mut().zip(&mut normals).take(chunk.len()).enumerate() {
                *p = shot.vertex_means[base + k];
                *n = shot.mesh.elements[base + k].normal;
            }
            let f = points_to_polygon_in_front_x4(&points, &normals, chunk.len(), corners);
            for (r, f) in chunk.iter_mut().zip(f) {
                r.unoccluded = f.max(0.0);
            }
        }
    } else {
        for (k, r) in out.iter_mut().enumerate() {
            r.unoccluded = unoccluded(shot, plan, first + k).max(0.0);
        }
    }
    if plan.visibility == Visibility::Clear {
        return;
    }
    if shot.pilot.count() == 1 && plan.visibility == Visibility::Few {
        // One ray per element: four elements' rays share a packet (the same rays as one
        // packet each, a quarter of the tests).
        let mut order = [0u32; FEW];
        let candidates = &mut order[..plan.candidates.len()];
        candidates.copy_from_slice(&plan.candidates);
        let mut packet = Packet::default();
        let mut test = |packet: &mut Packet, out: &mut [Received]| {
            let blocked =
                shot.blockers.occluded_x4(&Segments4::new(&packet.from, &packet.to, packet.n), candidates);
            for (lane, &k) in packet.owner[..packet.n].iter().enumerate() {
                out[k as usize].visible += u32::from(blocked >> lane & 1 == 0);
                out[k as usize].traced += 1;
            }
            packet.n = 0;
        };
        for k in 0..out.len() {
            if out[k].unoccluded <= 0.0 {
                continue;
            }
            draw(shot, plan, first + k, Rays::Pilot, |from, to| packet.push(from, to, k as u32));
            if packet.n == 4 {
                test(&mut packet, out);
            }
        }
        if packet.n > 0 {
            test(&mut packet, out);
        }
        return;
    }
    for (k, r) in out.iter_mut().enumerate() {
        if r.unoccluded > 0.0 {
            (r.visible, r.traced) = trace(shot, plan, first + k, Rays::Pilot);
        }
    }
}

/// Up to four segments to test together; lane `i` belongs to `owner[i]`.
#[derive(Default)]
struct Packet {
    from: [Vec3; 4],
    to: [Vec3; 4],
    owner: [u32; 4],
    n: usize,
}

impl Packet {
    /// Adds the segment `from → to` of `owner` (the caller tests a full packet first).
    fn push(&mut self, from: Vec3, to: Vec3, owner: u32) {
        (self.from[self.n], self.to[self.n], self.owner[self.n]) = (from, to, owner);
        self.n += 1;
    }
}

/// The element (corners `receiver`) and the shooter see each other whole: no clipping, no
/// redrawn rays. A patch that meets the shooter's plane (a wall standing on the floor) has
/// most of its elements off that plane: those, when no part of the shooter is behind them
/// either, are such elements too. Same test as the patch's, same tolerance.
fn element_facing(shooter: &radiosity_core::Patch, plan: &PatchPlan, receiver: &[DVec3]) -> bool {
    let corner = shooter.corners()[0];
    plan.facing
        || (plan.shooter_ahead
            && receiver.iter().all(|p| shooter.normal.dot(*p - corner) > 1e-9 * shooter.area.sqrt()))
}

/// Does `e` get penumbra rays? When its (edge) neighbours' pilot rays (never its own: the choice
/// must not depend on the rays it is averaged with, or it is biased) saw a penumbra: some
/// neighbour saw the shooter in part, or some saw all of it and others none.
///
/// Ward's (1991) adaptive shadow testing decides from the element's own rays and averages
/// them in; that pushes every penumbra element towards full light or full shadow (its
/// expected visibility for a true V of 0.9 is 0.95), which moved the Cornell floor's mean
/// by 1 % against a 64-ray solution. Deciding from the neighbours keeps every element's
/// estimate unbiased, and penumbrae are wider than an element, so they still find them.
fn wants_penumbra_rays(first: &[Received], e: usize, neighbours: &[u32]) -> bool {
    if first[e].traced == 0 || first[e].unoccluded <= 0.0 {
        return false;
    }
    let (mut full, mut none) = (false, false);
    for &n in neighbours {
        match first[n as usize].light() {
            Some(Light::Partial) => return true,
            Some(Light::Full) => full = true,
            Some(Light::None) => none = true,
            None => {}
        }
    }
    full && none
}

/// Which of an element's rays to a shooter.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Rays {
    /// Its first rays: `shot.pilot`'s strata.
    Pilot,
    /// Its penumbra rays: `shot.penumbra`'s strata.
    Penumbra,
}

/// Draws element `e`'s `rays` to the shooter and hands each segment to `ray` (see
/// [`draw_rays`]). Every path draws an element's rays here, so the fast and the reference
/// paths trace the same rays. Each set has its own stream keyed by the shooter and the
/// element; a lone first ray (from a dim shooter) takes its four coordinates from one hash.
fn draw(shot: &Shot, plan: &PatchPlan, e: usize, rays: Rays, ray: impl FnMut(Vec3, Vec3)) {
    let (seed, key) = (shot.params.seed, e as u64);
    match rays {
        Rays::Pilot if shot.pilot.count() == 1 => {
            let [u, v, a, b] = four_units(shot.single_key, key);
            let mut redraws = Rng::from_state(shot.single_key ^ key);
            draw_rays_from(shot, plan, e, 1, &mut redraws, ray, |_| ((u, v), (a, b)));
        }
        Rays::Pilot => draw_rays(shot, plan, e, shot.pilot, &mut Rng::for_task(seed, shot.stream, key), ray),
        Rays::Penumbra => {
            let mut rng = Rng::for_task(seed, shot.stream, key | PENUMBRA_STREAM);
            draw_rays(shot, plan, e, shot.penumbra, &mut rng, ray);
        }
    }
}

/// Element `e`'s `rays` to the shooter, traced: (unblocked, traced).
fn trace(shot: &Shot, plan: &PatchPlan, e: usize, rays: Rays) -> (u32, u32) {
    let Shot { mesh, shooter, accel, boxes, blockers, offset, .. } = *shot;
    // Every segment between the element and the shooter lies in the box around both; when no
    // blocking triangle comes near that box the pair is fully visible and needs no ray.
    if plan.visibility == Visibility::Clear {
        return (0, 0);
    }
    let few = plan.visibility == Visibility::Few;
    // The patch's candidate triangles, copied so that each packet can move the one that
    // blocked to the front for the next. Narrowing them per element (box and planes) was
    // tried: it dropped 9 % of the candidates and saved rays for 4 % of the elements, for
    // more time than it saved.
    let mut order = [0u32; FEW];
    let candidates = &mut order[..if few { plan.candidates.len() } else { 0 }];
    if few {
        candidates.copy_from_slice(&plan.candidates);
    } else {
        let pts = corners_of(mesh, e);
        let (lo, hi) = bounds(pts[..mesh.elements[e].vertex_count as usize].iter().chain(shooter.corners()));
        if !boxes.may_block(lo, hi, 2.0 * offset) {
            return (0, 0);
        }
    }
    // Unblocked segments of a packet: four at once against the candidate list, one by one
    // through the ray structure.
    let mut unblocked = |packet: &Packet| -> u32 {
        if few {
            let blocked =
                blockers.occluded_x4(&Segments4::new(&packet.from, &packet.to, packet.n), candidates);
            packet.n as u32 - blocked.count_ones()
        } else {
            (0..packet.n).filter(|&i| !accel.occluded(packet.from[i], packet.to[i])).count() as u32
        }
    };
    let (mut visible, mut traced) = (0u32, 0u32);
    let mut packet = Packet::default();
    draw(shot, plan, e, rays, |from, to| {
        packet.push(from, to, 0);
        traced += 1;
        if packet.n == 4 {
            visible += unblocked(&packet);
            packet.n = 0;
        }
    });
    if packet.n > 0 {
        visible += unblocked(&packet);
    }
    // None traced: the parts of each that face the other are too small to hit; the caller
    // then takes the pair as unblocked.
    (visible, traced)
}

/// Draws element `e`'s rays to the shooter, one per stratum of `strata` (fresh, at its first
/// stratum), and hands each segment (ends lifted off both surfaces, single precision) to
/// `ray`.
fn draw_rays(
    shot: &Shot,
    plan: &PatchPlan,
    e: usize,
    mut strata: Strata,
    rng: &mut Rng,
    ray: impl FnMut(Vec3, Vec3),
) {
    let count = strata.count();
    draw_rays_from(shot, plan, e, count, rng, ray, |rng| {
        // The same stratum on both ends, each jittered on its own.
        let stratum = strata.next();
        (strata.jitter(stratum, rng), strata.jitter(stratum, rng))
    });
}

/// [`draw_rays`] for `count` rays whose `(u, v)` on the element and `(a, b)` on the shooter
/// come from `sample`; `rng` draws the redraws.
fn draw_rays_from(
    shot: &Shot,
    plan: &PatchPlan,
    e: usize,
    count: u32,
    rng: &mut Rng,
    mut ray: impl FnMut(Vec3, Vec3),
    mut sample: impl FnMut(&mut Rng) -> ((f32, f32), (f32, f32)),
) {
    let Shot { mesh, shooter, targets, lifted_targets, offset, .. } = *shot;
    let el = &mesh.elements[e];
    let corners = shot.lifted_corners[e];
    let lifted = &corners[..el.vertex_count as usize];
    if plan.facing {
        // Nothing to clip (the usual case): origins straight from the lifted corners.
        for _ in 0..count {
            let ((u, v), (a, b)) = sample(rng);
            ray(point_on_f32(lifted, u, v).into(), lifted_targets[target_cell(a, b)]);
        }
        return;
    }
    let pts = corners_of(mesh, e);
    let receiver = &pts[..el.vertex_count as usize];
    // The form factor counts only the part of the shooter in front of the receiver point
    // (and receiver points in front of the shooter), so the visibility must be the fraction
    // of *that* part that is unblocked. A ray to a shooter point behind the receiver's plane
    // would pass through the receiver's own object and count as blocked: the light of a
    // lamp half behind a block's side, say, would be cut twice (the block sides of the
    // Cornell box lost up to 60 % of their direct light that way). Such pairs are redrawn.
    let clipped = !element_facing(shooter, plan, receiver);
    let ahead =
        |from: DVec3, to: DVec3| el.normal.dot(to - from) > 0.0 && shooter.normal.dot(from - to) > 0.0;
    let lift = el.normal * offset;
    for _ in 0..count {
        let ((u, v), (a, b)) = sample(rng);
        let mut cell = target_cell(a, b);
        let from = if clipped {
            let mut from = point_on(receiver, f64::from(u), f64::from(v));
            let mut tries = 0;
            while !ahead(from, targets[cell]) && tries < REDRAWS {
                from = point_on(receiver, rng.next_f64(), rng.next_f64());
                let (a, b) = rng.next_f32_pair();
                cell = target_cell(a, b);
                tries += 1;
            }
            if !ahead(from, targets[cell]) {
                continue;
            }
            (from + lift).as_vec3()
        } else {
            point_on_f32(lifted, u, v).into()
        };
        ray(from, lifted_targets[cell]);
    }
}

/// Σ_k d_k F_{p→k} / Σ_k F_{p→k} over the shooter's elements k: how much brighter than its
/// mean the shooter looks from `p`; 1 when `p` sees none of it.
/// Clusters more than four radii away count as one element.
fn density_weight(p: DVec3, n: DVec3, ns: DVec3, uneven: &Uneven, elements: &[ShooterElement]) -> f64 {
    let (mut weighted, mut plain) = (0.0, 0.0);
    for c in uneven.clusters {
        if c.centre.distance_squared(p) >= 16.0 * c.radius * c.radius {
            let f = point_to_point(p, n, c.centre, ns, c.area);
            weighted += c.density * f;
            plain += f;
            continue;
        }
        for &k in &uneven.order[c.members.clone()] {
            let f = elements[k as usize].factor_from(p, n, ns);
            weighted += uneven.density[k as usize] * f;
            plain += f;
        }
    }
    if plain > 0.0 { weighted / plain } else { 1.0 }
}

/// How an uneven shooter's unshot radiosity is spread over its elements.
#[derive(Clone, Copy)]
struct Uneven<'a> {
    /// Per shooter element, its unshot radiosity over the shooter's mean.
    density: &'a [f64],
    clusters: &'a [Cluster],
    /// Shooter element indices, cluster after cluster.
    order: &'a [u32],
}

/// Random redraws of a ray whose ends do not face each other, before it is given up.
const REDRAWS: u32 = 16;
