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
//! so its shots have the same row of form factors F_{j→i} until the spread of its unshot
//! power moves (see `first_shots`); the row is kept (within `SolverParams::row_cache_bytes`)
//! and a later shot is one multiply-add per receiver.
//!
//! Options: the ambient term of Cohen et al. 1988 §4 for early display, and overshooting by
//! over-relaxation (Gortler, Cohen & Slusallek 1993, "Radiosity and relaxation methods"):
//! shoot ω·ΔB_i and leave (1 − ω)·ΔB_i, which may be negative, unshot.
//!
//! The files, in layers: each imports only files of the layers before it (and of its own
//! layer listed before it), so reading can start at the top of this list or at `shooting`.
//!
//! * settings and per-mesh tables: `error`, `params`, `stop` (stop criteria and the
//!   NotConverging rule), `parallel`, `quadrature`, `enclosure`, `mesh_tables`, `plans` (per
//!   receiving patch);
//! * the geometry of one interaction: `elements` (a shooter element, an element's corners,
//!   whether the two face each other whole), `received` (what a receiver learns),
//!   `ray_ends` (where rays end on the shooter), `near_runs` (near receivers' ray ends by the
//!   form factor), `uneven` (shooters whose unshot radiosity is uneven);
//! * state by lifetime: `row` (a row of form factors, with its geometry and near field),
//!   `luminaires`, `tally` (the physics: B, ΔB and the power bookkeeping, and applying a
//!   row), `first_shots` and `row_cache` (per shooter), `clusters` (the shooter groups) and
//!   `shared` (receiving groups that share their visibility), `shot` (per shot: what
//!   receivers read, and scratch);
//! * a receiver's share of a shot: `rays` (drawing and tracing), `near_field`, `receive`
//!   (form factors and pilot rays), `penumbra` (which receivers take more rays);
//! * the loop: this file ([`Solver`]'s state and snapshots), then the files that add its
//!   steps: `patch_row` (a patch's row, pass by pass), `shooting` (the loop, step by step:
//!   start here) and the shooter groups' `clusters::{power, frozen, row}`.

use std::sync::Arc;
use std::time::Duration;

use radiosity_accel::RayQuery;
use radiosity_core::Rgb;
use radiosity_mesh::Mesh;

mod clusters;
mod elements;
mod enclosure;
mod error;
mod first_shots;
mod luminaires;
mod mesh_tables;
mod near_field;
mod near_runs;
mod parallel;
mod params;
mod patch_row;
mod penumbra;
mod plans;
mod quadrature;
mod ray_ends;
mod rays;
mod receive;
mod received;
mod row;
mod row_cache;
mod shared;
mod shooting;
mod shot;
mod stop;
mod tally;
mod uneven;

pub use error::SolverError;
pub use params::{Ambient, FormFactorMethod, Overshoot, SolverParams};
pub use stop::{StepBudget, StepReport, StopReason, UNSHOT_FLOOR};
pub use tally::EnergyBalance;

use crate::solution::{Solution, vertex_average};
use clusters::Clusters;
use first_shots::FirstShots;
use mesh_tables::MeshTables;
use row_cache::RowCache;
use shot::ShotScratch;
use stop::Progress;
use tally::Tally;

/// The progressive shooting solver. Owns its working state; callers own the loop.
pub struct Solver {
    mesh: Arc<Mesh>,
    accel: Arc<dyn RayQuery>,
    params: SolverParams,
    /// Per mesh: fixed when the solver is made.
    tables: MeshTables,
    /// Per shooter: what its first shot fixed.
    first_shots: FirstShots,
    /// Per shooter: its kept row of form factors, or its kept plans.
    rows: RowCache,
    /// The model facets that shoot in groups.
    clusters: Clusters,
    /// Per shot: scratch memory, kept to avoid allocating in the loop.
    scratch: ShotScratch,
    /// The physics: B, ΔB, power.
    tally: Tally,
    /// Shots, rays, time, stop.
    progress: Progress,
    /// Per shooter (patches, then groups), once probed: the share of its power its shots
    /// must deliver, 1 when it is enclosed; none for an emitter that sees out, whose rows are
    /// taken as they are (see [`enclosure`]).
    delivers: Vec<Option<Option<tally::Delivery>>>,
    /// The occluder triangles left out of `accel` (a room's walls, see
    /// `occluders::hull_triangles`), built with the sun's light or at the first probe.
    hull: Option<radiosity_accel::Bvh>,
    /// How far the probe rays reach: twice the mesh's diagonal, measured once (a walk over
    /// every vertex at each shooter's first shot was 3 % of a furnished room's solve).
    probe_reach: f64,
}

/// How many groups of small model facets would shoot as one in a solve of `mesh` with
/// [`SolverParams::clustering`] on (the default); 0 when it has no such facets.
pub fn shooter_groups(mesh: &Mesh) -> usize {
    Clusters::new(mesh, true).len()
}

impl Solver {
    /// A solver at shot 0: B = E and ΔB = E on every element.
    ///
    /// # Errors
    /// [`SolverError::EmptyMesh`], [`SolverError::NoEmission`], or
    /// [`SolverError::BadParameter`] for out-of-range parameters.
    pub fn new(mesh: Arc<Mesh>, accel: Arc<dyn RayQuery>, params: SolverParams) -> Result<Self, SolverError> {
        Self::with_luminaires(mesh, accel, params, &[])
    }

    /// A solver at shot 0 whose `luminaires` have shot first, exactly: B = E + ρ·E_lum and
    /// ΔB the same on every element, E_lum the luminaires' direct irradiance by shadow rays
    /// (see `luminaires`).
    ///
    /// # Errors
    /// As [`Solver::new`], but when nothing emits: [`SolverError::NoEmission`] only without
    /// luminaires, [`SolverError::DarkLuminaires`] when none of them lights any element.
    pub fn with_luminaires(
        mesh: Arc<Mesh>,
        accel: Arc<dyn RayQuery>,
        params: SolverParams,
        luminaires: &[radiosity_core::Luminaire],
    ) -> Result<Self, SolverError> {
        Self::with_lights(mesh, accel, params, luminaires, radiosity_core::Daylight::default())
    }

    /// [`Solver::with_luminaires`] with the sun and sky of `daylight` shooting first too, the
    /// same way (their direct light by shadow rays towards them).
    ///
    /// # Errors
    /// As [`Solver::with_luminaires`], the sun and sky counting as luminaires.
    pub fn with_lights(
        mesh: Arc<Mesh>,
        accel: Arc<dyn RayQuery>,
        params: SolverParams,
        luminaires: &[radiosity_core::Luminaire],
        daylight: radiosity_core::Daylight,
    ) -> Result<Self, SolverError> {
        params.validate()?;
        mesh_tables::check_patch_runs(&mesh)?;
        // The hull's triangles block the daylight's shadow rays and the enclosure probes
        // alike: built once here when there is daylight, else at the first probe.
        let hull = (!daylight.is_none())
            .then(|| radiosity_accel::Bvh::new(&crate::occluders::hull_triangles(&mesh)));
        let daylight = hull.as_ref().map(|hull| (daylight, hull));
        let light = luminaires::LuminaireLight::new(&mesh, accel.as_ref(), luminaires, daylight);
        let tally = Tally::lit(&mesh, light.as_ref())?;
        let mut clusters = Clusters::new(&mesh, params.clustering);
        clusters.sum(&tally.patch_abs);
        let shooters = mesh.patches.len() + clusters.len();
        Ok(Self {
            tables: MeshTables::new(&mesh),
            first_shots: FirstShots::new(&mesh, &tally),
            rows: RowCache::new(
                mesh.patches.len() + clusters.len(),
                params.row_cache_budget(mesh.elements.len()),
            ),
            clusters,
            scratch: ShotScratch::new(&mesh),
            tally,
            progress: Progress::new(mesh.patches.len()),
            delivers: vec![None; shooters],
            hull,
            probe_reach: {
                let (lo, hi) = mesh.bounds();
                2.0 * (hi - lo).length()
            },
            mesh,
            accel,
            params,
        })
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
        self.progress.stop
    }

    /// Shots done.
    pub fn shots(&self) -> u64 {
        self.progress.shots
    }

    /// How many groups of small model facets shoot as one (see
    /// [`SolverParams::clustering`]); 0 when none.
    pub fn shooter_groups(&self) -> usize {
        self.clusters.len()
    }

    /// Unshot power / emitted power.
    pub fn unshot_fraction(&self) -> f64 {
        self.tally.unshot_fraction
    }

    /// Visibility rays traced.
    pub fn rays(&self) -> u64 {
        self.progress.rays
    }

    /// Time spent inside [`Solver::step`].
    pub fn elapsed(&self) -> Duration {
        self.progress.elapsed
    }

    /// Power bookkeeping, summed fresh from the element state.
    pub fn energy(&self) -> EnergyBalance {
        self.tally.energy(&self.mesh)
    }

    /// Per-object area-weighted mean radiosity now, in scene object order: what
    /// [`Solution::object_radiosity`] gives, without the per-vertex averages a snapshot
    /// holds (on a million-facet model, two tables of hundreds of MB a report never reads).
    pub fn object_radiosity(&self) -> Vec<crate::ObjectRadiosity> {
        crate::solution::object_radiosity(&self.mesh, &self.element_radiosity())
    }

    /// Each element's radiosity now, with the ambient term when it is on.
    fn element_radiosity(&self) -> Vec<Rgb> {
        let tally = &self.tally;
        match self.params.ambient {
            Ambient::Off => tally.radiosity.clone(),
            Ambient::On => {
                let unshot_power: Rgb = tally.patch_unshot_power.iter().copied().sum();
                let r = self.tables.mean_reflectance.map(|m| 1.0 / (1.0 - m));
                let ambient = r * unshot_power / self.tables.total_area;
                let mesh = &self.mesh;
                (tally.radiosity.iter().enumerate())
                    .map(|(e, b)| {
                        *b + self.tables.patch_reflectance[mesh.elements[e].patch as usize] * ambient
                    })
                    .collect()
            }
        }
    }

    /// A snapshot of the current solution.
    pub fn solution(&self) -> Solution {
        let tally = &self.tally;
        let element_radiosity = self.element_radiosity();
        Solution {
            vertex_radiosity: vertex_average(
                &self.mesh,
                &element_radiosity,
                &self.tables.vertex_area,
                &self.tables.rim_fits,
            ),
            element_radiosity,
            vertex_direct: vertex_average(
                &self.mesh,
                &tally.direct,
                &self.tables.vertex_area,
                &self.tables.rim_fits,
            ),
            element_direct: tally.direct.clone(),
            element_unshot: tally.unshot.clone(),
            shots: self.progress.shots,
            unshot_fraction: tally.unshot_fraction,
        }
    }
}
