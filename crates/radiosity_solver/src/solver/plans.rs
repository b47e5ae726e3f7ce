//! Patch plans: what one shooter's row decides once for a whole receiving patch, so that its
//! elements need not. A patch receives only if part of it is in front of the shooter and part
//! of the shooter is in front of it; then its shaft (Haines & Wallace 1991, see
//! [`crate::shaft`]) says which triangles can block its rays, and its distance whether all
//! its elements may use one midpoint.

use glam::DVec3;
use radiosity_mesh::Mesh;

use super::mesh_tables::{MeshTables, patch_radius};
use super::parallel::for_each_maybe_parallel;
use super::quadrature::MIDPOINT_RATIO;
use crate::form_factor::distance_to_polygon;
use crate::shaft::{Pair, Visibility};

/// What one shot decides once for a whole receiving patch, so its elements need not.
#[derive(Clone, Debug)]
pub(super) struct PatchPlan {
    /// Some part of the patch and of the shooter face each other.
    pub(super) live: bool,
    /// Every element is far enough for the single-midpoint rule.
    pub(super) far: bool,
    /// The patch lies strictly in front of the shooter's plane and the shooter strictly in
    /// front of the patch's, so no receiver point needs hemisphere clipping.
    pub(super) facing: bool,
    /// The shooter lies in front of the patch's plane or on it: those of its elements that
    /// lie strictly in front of the shooter's see all of it (see `receive`).
    pub(super) shooter_ahead: bool,
    /// The patch and the shooter are live but not strictly facing: they meet or cross each
    /// other's planes (a wall on the floor, a block standing on it). Set on both paths.
    pub(super) touching: bool,
    /// How its rays are answered.
    pub(super) visibility: Visibility,
    /// The blocking triangles that may meet its rays, when `visibility` is `Few`.
    pub(super) candidates: Vec<u32>,
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

/// Entries of one shooter's plans (receiving patches plus candidate triangles): what keeping
/// them costs.
pub(super) fn plan_entries(plans: &[PatchPlan]) -> usize {
    plans.len() + plans.iter().map(|p| p.candidates.len()).sum::<usize>()
}

/// Plans every receiving patch of `mesh` for shooter patch `shooter`, into `plans` (one per
/// patch). On the reference path only `live` and `touching` are set: every element then
/// takes the plain path. A patch that `shares` its group's visibility (see
/// [`super::shared`]) is only marked live: its group is received whole, and the few rays it
/// traces go through the ray structure.
pub(super) fn plan_patches(
    mesh: &Mesh,
    shooter: usize,
    tables: &MeshTables,
    reference_path: bool,
    shares: impl Fn(usize) -> bool + Sync,
    plans: &mut [PatchPlan],
) {
    for_each_maybe_parallel(plans, |q, plan| {
        plan_patch(mesh, q, shooter, tables, reference_path, shares(q), plan);
    });
}

/// Plans receiving patch `q` for patch `shooter`.
fn plan_patch(
    mesh: &Mesh,
    q: usize,
    shooter: usize,
    tables: &MeshTables,
    reference_path: bool,
    shares: bool,
    plan: &mut PatchPlan,
) {
    if shares {
        // Not `facing`: the group's few rays then keep to the part of the shooter in front
        // of each member, which is the part its form factor counts (a ray to a point behind
        // a facet's plane crosses its own model and counts as blocked).
        *plan = PatchPlan { live: true, far: true, ..PatchPlan::default() };
        return;
    }
    let is_shooter = q == shooter;
    let shooter = &mesh.patches[shooter];
    let corners = shooter.corners();
    let in_front =
        |pts: &[DVec3], c: DVec3, n: DVec3| pts.iter().any(|p| n.dot(*p - c) > 1e-12 * shooter.area.sqrt());
    let r = &mesh.patches[q];
    plan.live = !is_shooter
        && in_front(r.corners(), shooter.centre, shooter.normal)
        && in_front(corners, r.centre, r.normal);
    let strictly =
        |pts: &[DVec3], c: DVec3, n: DVec3| pts.iter().all(|p| n.dot(*p - c) > 1e-9 * shooter.area.sqrt());
    let receiver_point = mesh.elements[r.elements.start as usize].centre;
    let facing = plan.live
        && strictly(r.corners(), corners[0], shooter.normal)
        && strictly(corners, receiver_point, r.normal);
    // The shooter on or in front of the patch's plane (a floor patch along a wall's
    // foot): clipping it at the plane changes nothing.
    let shooter_ahead =
        plan.live && corners.iter().all(|p| r.normal.dot(*p - receiver_point) > -1e-9 * shooter.area.sqrt());
    plan.touching = plan.live && !facing;
    if !plan.live || reference_path {
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
    let patch_radius = patch_radius(r);
    plan.far = (MIDPOINT_RATIO + 1.0) * tables.patch_element_radius[q]
        < distance_to_polygon(r.centre, shooter.normal, corners) - patch_radius;
    plan.visibility = tables.blockers.gather(
        Pair { a: corners, na: shooter.normal, b: r.corners(), nb: r.normal, offset: tables.ray_offset },
        &mut plan.candidates,
    );
}
