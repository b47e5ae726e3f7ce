//! What every receiver of one shot reads ([`Shot`]), and the per-shot scratch memory it is
//! built in ([`ShotScratch`]). A patch's row (`patch_row`) and a group's (`clusters::row`)
//! both fill the scratch; the rays and the receivers read the shot.

use glam::{DVec3, Vec3, Vec3A};
use radiosity_accel::RayQuery;
use radiosity_mesh::{Mesh, Patch};

use super::SolverParams;
use super::clusters::Clusters;
use super::elements::ShooterElement;
use super::near_runs::NearRuns;
use super::plans::PatchPlan;
use super::received::Received;
use super::shared::Sharing;
use super::uneven::{Cluster, Uneven};
use crate::occluders::OccluderBoxes;
use crate::sampling::Strata;
use crate::shaft::Blockers;

/// What every receiver of one shot reads.
pub(super) struct Shot<'a> {
    pub(super) mesh: &'a Mesh,
    pub(super) shooter: &'a Patch,
    /// Ray ends on the shooter, `TARGETS`² of them, row after row (see
    /// [`super::ray_ends::target_cell`]).
    pub(super) targets: &'a [DVec3],
    /// The same points lifted off the shooter by `offset`, as the rays take them.
    pub(super) lifted_targets: &'a [Vec3],
    /// The shooter's elements.
    pub(super) shooter_elements: &'a [ShooterElement],
    /// Their cumulative shares of its unshot power when its spread was last fixed (see
    /// `first_shots`).
    pub(super) cdf: &'a [f64],
    /// The same, by runs, as near receivers weigh them (see `near_runs::NearEnds`).
    pub(super) near_runs: &'a NearRuns,
    /// Every element's vertex mean (see `MeshTables::vertex_means`).
    pub(super) vertex_means: &'a [DVec3],
    /// Every element's circumradius.
    pub(super) element_radii: &'a [f64],
    /// Every element's corners lifted off it by `offset`, in single precision: where its
    /// rays start (see `MeshTables::lifted_corners`).
    pub(super) lifted_corners: &'a [[Vec3A; 4]],
    /// How the shooter's unshot radiosity is spread, when it is uneven.
    pub(super) uneven: Option<Uneven<'a>>,
    pub(super) accel: &'a dyn RayQuery,
    pub(super) boxes: &'a OccluderBoxes,
    pub(super) blockers: &'a Blockers,
    pub(super) params: &'a SolverParams,
    /// Ray origins and targets are lifted this far off their surfaces.
    pub(super) offset: f64,
    /// Key of the random streams: the shooter, so that every shot of it draws the same rays.
    pub(super) stream: u64,
    /// Key of the one-ray receivers' hashes (see `four_units`).
    pub(super) single_key: u64,
    /// The shooter's circumradius about its centre.
    pub(super) shooter_radius: f64,
    /// Strata of the pilot and of the penumbra rays.
    pub(super) pilot: Strata,
    /// Strata of the pilot rays of a model's small facets (members of a shooter group, see
    /// `facets`): fewer than `pilot` from a bright shooter, since a facet is a small part
    /// of what the eye sees and its noise is pooled with its neighbours' at their shared
    /// vertices.
    pub(super) facet_pilot: Strata,
    /// The shooter groups: which patches are such facets.
    pub(super) clusters: &'a Clusters,
    /// Which receiving groups share one visibility estimate (see [`super::shared`]).
    pub(super) sharing: &'a Sharing,
    /// Per patch, its elements' range (see `MeshTables::patch_elements`).
    pub(super) patch_elements: &'a [std::ops::Range<usize>],
    pub(super) penumbra: Strata,
}

impl Shot<'_> {
    /// Whether patch `q`'s elements take their group's shared visibility instead of rays
    /// of their own.
    pub(super) fn shares(&self, q: usize) -> bool {
        self.sharing.shares(self.patch_elements[q].start)
    }

    /// The pilot-ray strata of element `e`'s patch.
    pub(super) fn pilot_for(&self, e: usize) -> Strata {
        if self.clusters.members()[self.mesh.elements[e].patch as usize] {
            self.facet_pilot
        } else {
            self.pilot
        }
    }
}

/// Memory one shot fills and its receivers read, kept between shots to avoid allocating in
/// the loop; nothing in it outlives the shot.
pub(super) struct ShotScratch {
    /// Per receiving patch, what this shot decided for all its elements.
    pub(super) plans: Vec<PatchPlan>,
    /// Per element, what it received from the shooter's first pass (and penumbra rays).
    pub(super) factors: Vec<Received>,
    /// Per element, whether it takes penumbra rays from the current shooter.
    pub(super) penumbra: Vec<bool>,
    /// The shooter's elements.
    pub(super) shooter_elements: Vec<ShooterElement>,
    /// Ray ends on the shooter (see [`super::ray_ends`]).
    pub(super) targets: Vec<DVec3>,
    /// `targets` lifted off the shooter by the ray offset, in single precision: ray ends.
    pub(super) lifted_targets: Vec<Vec3>,
    /// Clusters of an uneven shooter's elements (see [`super::uneven`]).
    pub(super) clusters: Vec<Cluster>,
    pub(super) cluster_order: Vec<u32>,
    /// Per element, its form factor to the shooting group of facets (see [`super::clusters`]).
    pub(super) group_factors: Vec<f32>,
    /// Which receiving groups share their visibility in this shot.
    pub(super) sharing: Sharing,
    /// The shooter's runs of elements for its near receivers' ray ends.
    pub(super) near_runs: NearRuns,
}

impl ShotScratch {
    /// Scratch for `mesh`.
    pub(super) fn new(mesh: &Mesh) -> Self {
        let n = mesh.elements.len();
        Self {
            plans: vec![PatchPlan::default(); mesh.patches.len()],
            factors: vec![Received::default(); n],
            penumbra: vec![false; n],
            shooter_elements: Vec::new(),
            targets: Vec::new(),
            lifted_targets: Vec::new(),
            clusters: Vec::new(),
            cluster_order: Vec::new(),
            group_factors: Vec::new(),
            sharing: Sharing::default(),
            near_runs: NearRuns::default(),
        }
    }

    /// Copies the elements of `shooter` into [`ShotScratch::shooter_elements`].
    pub(super) fn load_shooter(&mut self, mesh: &Mesh, shooter: &Patch, element_radii: &[f64]) {
        self.shooter_elements.clear();
        for e in shooter.elements.start..shooter.elements.end {
            self.shooter_elements.push(ShooterElement::new(mesh, e as usize, element_radii[e as usize]));
        }
    }
}

/// Pilot rays from a bright shooter to a facet of a shooter group: a quarter of
/// `visibility_rays`, at least `dim_rays`. On a 120 k-triangle room the facets took 84 % of
/// the rays at the full count.
pub(super) fn facet_rays(params: &SolverParams) -> u32 {
    (params.visibility_rays / 4).max(params.dim_rays)
}
