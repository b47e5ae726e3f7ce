//! Shooter clusters: the small facets of a tessellated model shoot in groups, so the number of
//! shots follows the light and the scene's extent, not its triangle count.
//!
//! Every non-coplanar triangle of a model is a surface and a patch of its own; shot one by
//! one, a 30 k-triangle room took 31 000 shots to reach 1 % unshot, each visiting every
//! element. Here the one-patch surfaces of a model that has many are grouped by object, side,
//! facing (the dominant axis of the normal, so a group's normals lie within ~55° of one axis)
//! and a cell of 1/[`CELLS_PER_DIAGONAL`] of the scene's diagonal; a group is one shooter.
//! As the triangle count of the same room grows, the groups hold more facets but their number
//! stays the same.
//!
//! A group's shot treats its members as one emitter of its unshot power, spread as it was at
//! its first shot (frozen, like a patch's, so a kept row stays right):
//!
//! * far away (beyond [`FAR`] group radii), by the group's power-weighted normals per bin b
//!   of similar normals, w_b = (Σ_k w_k) Σ_k w_k n_k / |Σ_k w_k n_k| (w_k the members' shares
//!   of the unshot power; scaled so that the bin sends out its whole share): the irradiance
//!   at a receiver at distance r in direction d is
//!   ΔΦ Σ_b (w_b·d)⁺ cos θ_r / (π r²) — the sum of the members' point-to-point terms with one
//!   distance and one clamp per bin (face-cluster radiosity keeps one such vector per
//!   cluster, Willmott, Heckbert & Garland 1999, §4);
//! * near, by [`POINTS`] points drawn over the members by unshot power, each a disc of
//!   1/[`POINTS`] of the area (Wallace, Elmquist & Haines 1989: a cos θ cos θ' / (π r² + a),
//!   finite at contact);
//! * visibility: `dim_rays` rays per receiving element (`visibility_rays` when the group is
//!   bright) to those points, through the scene's ray structure.
//!
//! Members receive from their own group's other facets (a fold of the model lights itself),
//! by the near field.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicU64, Ordering};

use glam::{DVec3, Vec3, Vec4};
use radiosity_accel::RayQuery;
use radiosity_core::Rgb;
use radiosity_mesh::Mesh;

use super::SolverParams;
use super::first_shots::DRIFT;
use super::mesh_tables::MeshTables;
use super::parallel::for_each_maybe_parallel;
use super::receive::corners_of;
use super::row::Row;
use super::shot::ShotScratch;
use crate::sampling::{Rng, point_on, point_on_f32};

/// Cells per scene diagonal: a group spans at most one cell. Measured against the path
/// tracer (`verify … --paths 1000000 --unshot-threshold 0.001`), 24 → 16: the 221 k-triangle
/// knot room solved in 49.7 s instead of 70.8 s (4 152 shots, not 5 754), its worst knot
/// −0.87 % (was −0.62 %), median 0.51 % (0.41 %); the 139 k bunny room in 9.3 s instead of
/// 12.0 s, its bunnies −1.56 / −1.04 % (−1.85 / −1.33 %). At 12 the knot room took 32.7 s
/// and its worst knot came out −1.32 %: larger groups send a knot's light round itself
/// through fewer near-field points.
const CELLS_PER_DIAGONAL: f64 = 16.0;

/// The patches of a surface of several are facets when their mean area is at most this many
/// cells² (a patch a quarter of a cell across).
const SMALL_PATCH: f64 = 1.0 / 16.0;

/// An object's facets are grouped when it has at least this many.
const MIN_FACETS: usize = 32;

/// Receivers farther than this many group radii from the group's centre take the far field.
const FAR: f64 = 2.5;

/// Points drawn over a group for its near field and its rays' ends (a square).
///
/// Each point stands for a disc of 1/`POINTS` of the group's area, and its kernel
/// a cos θ cos θ' / (π r² + a) levels off within about a disc radius of it. A receiver that
/// near the group (the table under a model's belly, a fold of the model) is therefore lit
/// short on average: for a receiver at height h under a flat group, the points' expected sum
/// is ln(1 + u)/u of the true form factor, u = a/(π h²) — 69 % at one disc radius. More,
/// smaller discs move that zone closer in. Against the path tracer (`verify bunroom.obj
/// --paths 1000000 --unshot-threshold 0.001`, the 139 k-triangle room with two bunnies on a
/// table and `proximity_refinement` 1, whose fine ground elements give the bunnies' dark
/// ground its own value): 64 points −2.15 / −1.72 %, 256 points −1.47 / −1.11 %, 1024
/// points −1.18 / −0.85 %, solving in 15.6 / 17.6 / 26.0 s; on the 834 k-triangle room 256
/// points bring every object within 1.5 %. Lucy in McGuire's box read −2.62 % with 64,
/// −2.03 % with 256 and −1.29 % with every facet shooting alone.
const POINTS: usize = 256;

/// Draws of a far receiver's ray end before its ray is given up (no point of the group
/// faces it: a grazing receiver).
const FAR_TRIES: usize = 16;

/// A group is cut into tiles of at most this many facets, which share their visibility on
/// their own when the whole group is too near the shooter to (see [`super::shared`]).
const TILE_FACETS: usize = 64;

/// No group.
const NONE: u32 = u32::MAX;

/// The solve's shooter groups.
pub(super) struct Clusters {
    /// Per patch, its group, or [`NONE`].
    of_patch: Vec<u32>,
    /// Per patch, whether it is in a group.
    members: Vec<bool>,
    /// Per element of a group's patch, its place in the group's `elements`.
    slot: Vec<u32>,
    /// The groups, in order of their first member.
    groups: Vec<Group>,
    /// The groups' tiles, group after group.
    tiles: Vec<Tile>,
    /// Per group, Σ |unshot power| over its members, kept up to date by [`Clusters::update`].
    power: Vec<f64>,
    /// The patches in no group, in index order.
    singles: Vec<u32>,
    /// Updates since `power` was summed afresh.
    since_sum: u32,
}

/// One group of facets that shoots as one.
pub(super) struct Group {
    /// Its patches, tile after tile (see [`Tile`]).
    pub(super) patches: Vec<u32>,
    /// Their elements, in the same order.
    pub(super) elements: Vec<u32>,
    /// Per element, its vertex mean (its one quadrature point far away, as
    /// `MeshTables::vertex_means`) and its normal: a group is received whole, and these
    /// read from the mesh's scattered elements were most of that time.
    pub(super) receivers: Vec<(DVec3, DVec3)>,
    /// Σ of their areas.
    pub(super) area: f64,
    /// Area-weighted centroid.
    pub(super) centre: DVec3,
    /// Largest distance from `centre` to a member's corner.
    pub(super) radius: f64,
    /// Some member emits (see [`patch_emits`]).
    pub(super) emits: bool,
    /// Its tiles, a range of [`Clusters`]' tiles.
    pub(super) tiles: std::ops::Range<u32>,
    /// What its first shot fixed, or its last shot whose spread had drifted.
    frozen: Option<Frozen>,
    /// Whether its first shot was bright (see `SolverParams::bright_share`), once it shot.
    first_bright: Option<bool>,
}

/// A run of a group's facets that lie together: the group's patches cut in halves across
/// their longest extent until at most [`TILE_FACETS`] are left. A shooter too near a group
/// for the whole of it to share one visibility estimate may still be far from each tile.
pub(super) struct Tile {
    /// Its elements: a range of its group's `elements` (and `receivers`).
    pub(super) elements: std::ops::Range<u32>,
    /// Its number of patches.
    pub(super) patches: u32,
    /// Area-weighted centroid.
    pub(super) centre: DVec3,
    /// Largest distance from `centre` to a member's corner.
    pub(super) radius: f64,
}

/// A group's unshot power as its first shot spread it.
struct Frozen {
    /// Σ_k w_k n_k over its elements, w_k their shares of its unshot power, summed per bin of
    /// normals (see [`normal_bin`]); empty bins left out. Four to a lane group by
    /// coordinate, in single precision, the last group padded with zero axes: every far
    /// receiver of the group's row weighs them all (one by one in double precision, that
    /// was 8 % of a knot room's solve).
    axes: Vec<[Vec4; 3]>,
    /// Points drawn over it by unshot power, with their element's normal and patch.
    points: Vec<(DVec3, DVec3, u32)>,
    /// The same points lifted off their facets, in single precision: the rays' ends.
    lifted: Vec<Vec3>,
    /// The same points and normals by coordinate, and their patches: the near field's loop
    /// over them then runs several points at a time (it was 13 % of a big room's solve).
    near: NearPoints,
    /// Its first shot carried at least `bright_share` of the solve's first shot.
    bright: bool,
    /// Its elements (as `Group::elements`) and the cumulative shares of its unshot power
    /// over them when it was fixed: what [`Clusters::refresh_if_drifted`] compares with.
    cdf: Vec<f64>,
}

impl Frozen {
    /// Σ_a max(a · d, 0) over its axes: the group's far field towards unit direction `d`
    /// (see [`unoccluded`]).
    fn lobe(&self, d: DVec3) -> f64 {
        let d = d.as_vec3();
        let sum = self
            .axes
            .iter()
            .fold(Vec4::ZERO, |sum, [x, y, z]| sum + (*x * d.x + *y * d.y + *z * d.z).max(Vec4::ZERO));
        f64::from(sum.element_sum())
    }
}

/// Who shoots next.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Shooter {
    /// A patch on its own.
    Patch(usize),
    /// A group of patches.
    Group(usize),
}

impl Clusters {
    /// Groups the facets of `mesh` (none when `enabled` is false).
    pub(super) fn new(mesh: &Mesh, enabled: bool) -> Self {
        let mut of_patch = vec![NONE; mesh.patches.len()];
        let (mut groups, mut tiles) = (Vec::new(), Vec::new());
        if enabled && !mesh.patches.is_empty() {
            let mut patches_of_surface = vec![0u32; mesh.surfaces.len()];
            let mut surface_area = vec![0.0f64; mesh.surfaces.len()];
            for p in &mesh.patches {
                patches_of_surface[p.surface as usize] += 1;
                surface_area[p.surface as usize] += p.area;
            }
            let (lo, hi) = mesh.bounds();
            let cell = (hi - lo).length() / CELLS_PER_DIAGONAL;
            // A facet: a surface of one patch, or a patch of a surface made of many small
            // ones (the coplanar triangles of a CAD model's flat face keep a patch each; left
            // out, each of them shot alone and a 39 k-triangle room took 25 000 shots to 0.1 %
            // unshot). A room's wall is cut into patches of the patch size, far larger.
            let facet = |q: usize| {
                let p = &mesh.patches[q];
                let s = p.surface as usize;
                let mean_area = surface_area[s] / f64::from(patches_of_surface[s]);
                (patches_of_surface[s] == 1 || mean_area <= SMALL_PATCH * cell * cell)
                    && p.corners().iter().all(|c| c.distance(p.centre) < cell)
            };
            let mut facets_of_object = vec![0usize; mesh.object_names.len()];
            for q in (0..mesh.patches.len()).filter(|&q| facet(q)) {
                facets_of_object[mesh.surfaces[mesh.patches[q].surface as usize].object as usize] += 1;
            }
            // Key: object, side, facing, cell. A BTreeMap of first-member order keeps the
            // numbering the same from run to run.
            let mut by_key: BTreeMap<(u32, bool, u8, [i64; 3]), Vec<u32>> = BTreeMap::new();
            for q in (0..mesh.patches.len()).filter(|&q| facet(q)) {
                let p = &mesh.patches[q];
                let surface = &mesh.surfaces[p.surface as usize];
                if facets_of_object[surface.object as usize] < MIN_FACETS {
                    continue;
                }
                let c = ((p.centre - lo) / cell).floor().as_i64vec3().to_array();
                by_key.entry((surface.object, surface.back, facing(p.normal), c)).or_default().push(q as u32);
            }
            let mut lists: Vec<Vec<u32>> = by_key.into_values().filter(|m| m.len() > 1).collect();
            lists.sort_unstable_by_key(|m| m[0]);
            for mut patches in lists {
                let (centre, radius, area) = extent(mesh, &patches);
                let mut cuts = Vec::new();
                cut_into_tiles(mesh, &mut patches, 0, &mut cuts);
                let mut elements = Vec::new();
                let first_tile = tiles.len() as u32;
                for cut in cuts {
                    let start = elements.len() as u32;
                    for &q in &patches[cut.clone()] {
                        of_patch[q as usize] = groups.len() as u32;
                        elements.extend(mesh.patches[q as usize].elements.clone());
                    }
                    let (centre, radius, _) = extent(mesh, &patches[cut.clone()]);
                    tiles.push(Tile {
                        elements: start..elements.len() as u32,
                        patches: cut.len() as u32,
                        centre,
                        radius,
                    });
                }
                let receivers = (elements.iter())
                    .map(|&e| {
                        let (e, el) = (e as usize, &mesh.elements[e as usize]);
                        (mesh.element_corners(e).sum::<DVec3>() / f64::from(el.vertex_count), el.normal)
                    })
                    .collect();
                let emits = patches.iter().any(|&q| patch_emits(mesh, q as usize));
                groups.push(Group {
                    patches,
                    elements,
                    receivers,
                    area,
                    centre,
                    radius,
                    emits,
                    tiles: first_tile..tiles.len() as u32,
                    frozen: None,
                    first_bright: None,
                });
            }
        }
        let members = of_patch.iter().map(|&g| g != NONE).collect();
        let mut slot = vec![NONE; mesh.elements.len()];
        for group in &groups {
            for (k, &e) in group.elements.iter().enumerate() {
                slot[e as usize] = k as u32;
            }
        }
        let singles = (0..of_patch.len() as u32).filter(|&q| of_patch[q as usize] == NONE).collect();
        Self { of_patch, members, slot, power: vec![0.0; groups.len()], singles, since_sum: 0, groups, tiles }
    }

    /// Tile `t`.
    pub(super) fn tile(&self, t: usize) -> &Tile {
        &self.tiles[t]
    }

    /// Number of elements in the mesh the groups were made for.
    pub(super) fn element_count(&self) -> usize {
        self.slot.len()
    }

    /// Per patch, whether it is in a group.
    pub(super) fn members(&self) -> &[bool] {
        &self.members
    }

    /// Element `e`'s place in its group's `elements` (meaningless for elements in no group).
    pub(super) fn slot(&self, e: usize) -> usize {
        self.slot[e] as usize
    }

    /// Number of groups.
    pub(super) fn len(&self) -> usize {
        self.groups.len()
    }

    /// The reach of group `g`'s near field from its centre: the receivers within it take
    /// its points' kernel (see [`FAR`]).
    pub(super) fn near_reach(&self, g: usize) -> f64 {
        FAR * self.groups[g].radius
    }

    /// Group `g`'s near-field points with their normals, as its last shot fixed them (none
    /// before its first shot): where its probe rays start (see `enclosure`).
    pub(super) fn probe_points(&self, g: usize) -> Vec<(DVec3, DVec3)> {
        let Some(frozen) = &self.groups[g].frozen else { return Vec::new() };
        let near = &frozen.near;
        (0..POINTS)
            .filter(|&i| near.patch[i] != NONE)
            .map(|i| {
                let at = |v: &[[f32; POINTS]; 3]| glam::Vec3::new(v[0][i], v[1][i], v[2][i]).as_dvec3();
                (near.origin + at(&near.x), at(&near.n).normalize_or_zero())
            })
            .collect()
    }

    /// Group `g`.
    pub(super) fn group(&self, g: usize) -> &Group {
        &self.groups[g]
    }

    /// Counts the patches' |unshot power| (`patch_abs`) afresh into the groups' sums.
    pub(super) fn sum(&mut self, patch_abs: &[f64]) {
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
    /// [`super::tally::RESUM`] shots, so rounding cannot pile up.
    pub(super) fn update(&mut self, changed: &[(u32, f64)], patch_abs: &[f64]) {
        self.since_sum += 1;
        if self.since_sum >= super::tally::RESUM {
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
    pub(super) fn brightest(&self, patch_abs: &[f64]) -> Shooter {
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

    /// Fixes group `g`'s spread at its first shot (nothing on later ones): `first_power`
    /// is the power of the solve's first shot.
    pub(super) fn freeze(
        &mut self,
        g: usize,
        mesh: &Mesh,
        unshot: &[Rgb],
        tables: &MeshTables,
        params: &SolverParams,
        first_power: f64,
    ) {
        let group = &mut self.groups[g];
        if group.frozen.is_some() {
            return;
        }
        let elements: Vec<usize> = group.elements.iter().map(|&e| e as usize).collect();
        let weight = |e: usize| (unshot[e] * mesh.elements[e].area).abs().sum();
        let mut total: f64 = elements.iter().map(|&e| weight(e)).sum();
        let by_area = !(total > 0.0 && total.is_finite());
        let share = |e: usize| if by_area { mesh.elements[e].area } else { weight(e) };
        if by_area {
            total = elements.iter().map(|&e| mesh.elements[e].area).sum();
        }
        let mut bins = [(DVec3::ZERO, 0.0); BINS * BINS];
        for &e in &elements {
            let n = mesh.elements[e].normal;
            let bin = &mut bins[normal_bin(n)];
            bin.0 += n * (share(e) / total);
            bin.1 += share(e) / total;
        }
        // Each bin's summed normal at the length of the bin's share: the clamped lobe of a
        // vector a sends out π|a| over the sphere, and |Σ w_k n_k| < Σ w_k when the normals
        // differ, so unscaled the far field lost what a curved group's bins spread (the
        // members' own lobes send out exactly their shares).
        let axes: Vec<DVec3> = bins
            .into_iter()
            .filter(|(a, _)| *a != DVec3::ZERO)
            .map(|(a, w)| a.normalize_or_zero() * w)
            .collect();
        let axes = axes
            .chunks(4)
            .map(|four| {
                let mut lanes = [Vec4::ZERO; 3];
                for (lane, a) in four.iter().enumerate() {
                    let a = a.as_vec3();
                    (lanes[0][lane], lanes[1][lane], lanes[2][lane]) = (a.x, a.y, a.z);
                }
                lanes
            })
            .collect();
        let mut cdf = Vec::with_capacity(elements.len());
        let mut acc = 0.0;
        for &e in &elements {
            acc += share(e) / total;
            cdf.push(acc);
        }
        // A jittered √POINTS × √POINTS grid mapped by the shares: u picks the element, v and
        // the rest of u place the point in it (as a patch's ray ends, `ray_ends.rs`).
        let side = (POINTS as f64).sqrt() as usize;
        let mut rng = Rng::for_task(params.seed, GROUP_STREAM ^ g as u64, u64::MAX);
        let mut points = Vec::with_capacity(POINTS);
        for b in 0..side {
            for a in 0..side {
                let u = (a as f64 + rng.next_f64()) / side as f64;
                let v = (b as f64 + rng.next_f64()) / side as f64;
                let k = cdf.partition_point(|&c| c <= u).min(cdf.len() - 1);
                let below = if k == 0 { 0.0 } else { cdf[k - 1] };
                let width = cdf[k] - below;
                let u = if width > 0.0 { ((u - below) / width).clamp(0.0, 1.0 - f64::EPSILON) } else { 0.5 };
                let e = elements[k];
                let corners = corners_of(mesh, e);
                let corners = &corners[..mesh.elements[e].vertex_count as usize];
                points.push((point_on(corners, u, v), mesh.elements[e].normal, mesh.elements[e].patch));
            }
        }
        let lifted = points.iter().map(|(p, n, _)| (*p + *n * tables.ray_offset).as_vec3()).collect();
        // Bright or dim by its first shot's power: a spread fixed again keeps it.
        let bright = group.first_bright.unwrap_or_else(|| {
            total_power(&group.patches, mesh, unshot) >= params.bright_share * first_power
        });
        group.first_bright = Some(bright);
        let near = NearPoints::new(group.centre, &points);
        group.frozen = Some(Frozen { axes, points, lifted, near, bright, cdf });
    }

    /// Lets group `g`'s spread be fixed again (by the next [`Clusters::freeze`]) when the
    /// spread of its unshot power has drifted from the fixed one by more than [`DRIFT`] (half
    /// the summed differences of its elements' shares: the share of its power that moved);
    /// whether it did. Its brightness stays.
    ///
    /// A group's first shot carries the direct light on its facets: a cushion's lit top. Its
    /// later shots carry the light of the room, which also reaches the facets turned away
    /// from the lamp, towards the backrest the cushion leans on. Shot from the first spread,
    /// that light left from the lit top instead, and the crevice between the two went dark:
    /// a sofa's cushions (ρ = 0.95) came out 17–29 % dark, and its frame 8 %.
    pub(super) fn refresh_if_drifted(&mut self, g: usize, mesh: &Mesh, unshot: &[Rgb]) -> bool {
        let group = &mut self.groups[g];
        let Some(frozen) = &group.frozen else { return false };
        let power = |e: u32| (unshot[e as usize] * mesh.elements[e as usize].area).abs().sum();
        let total: f64 = group.elements.iter().map(|&e| power(e)).sum();
        if !(total > 0.0 && total.is_finite()) {
            return false;
        }
        let mut below = 0.0;
        let mut moved = 0.0;
        for (&e, &c) in group.elements.iter().zip(&frozen.cdf) {
            moved += (power(e) / total - (c - below)).abs();
            below = c;
        }
        if moved / 2.0 <= DRIFT {
            return false;
        }
        group.frozen = None;
        true
    }

    /// Group `g`'s row (it must be frozen): every element's form factor to it, visibility
    /// included, for the patches that receive any; and the rays traced. Receiving groups
    /// far from a dim group share their visibility (`sharing`, see [`super::shared`]).
    pub(super) fn row(
        &self,
        g: usize,
        mesh: &Mesh,
        tables: &MeshTables,
        accel: &dyn RayQuery,
        params: &SolverParams,
        scratch: &mut ShotScratch,
    ) -> (Row, u64) {
        let group = &self.groups[g];
        let frozen = group.frozen.as_ref().expect("a group is frozen before its row is computed");
        let share = params.clustering && params.shared_visibility;
        scratch.sharing.choose(self, group.centre, group.radius, group.emits, share, Some(g));
        let (sharing, factors) = (&scratch.sharing, &mut scratch.group_factors);
        let stream = GROUP_STREAM ^ g as u64;
        let aim = Aim {
            frozen,
            mesh,
            tables,
            accel,
            rays: if frozen.bright { super::row::facet_rays(params) } else { params.dim_rays },
            seed: params.seed,
            stream,
        };
        factors.clear();
        factors.resize(mesh.elements.len(), 0.0);
        // Rays traced, for the progress figures (an integer sum: the same in any order).
        let traced = AtomicU64::new(0);
        // Elements in no sharing group, with their own rays; the sharing groups' below.
        for_each_maybe_parallel(factors, |e, out| {
            if sharing.shares(e) {
                return;
            }
            let el = &mesh.elements[e];
            let mut shares = [0.0; POINTS];
            let (f, near) =
                unoccluded(group, frozen, tables.vertex_means[e], el.normal, el.patch, &mut shares);
            *out = f as f32;
            if f > 0.0 {
                let (visible, n) = aim.trace(e, f, near, &shares);
                *out = if n == 0 { f as f32 } else { (f * f64::from(visible) / f64::from(n)) as f32 };
                traced.fetch_add(u64::from(n), Ordering::Relaxed);
            }
        });
        let mut traced = traced.into_inner();
        if sharing.any() {
            let unoccluded_at = |e: usize, shares: &mut [f64; POINTS]| {
                let el = &mesh.elements[e];
                unoccluded(group, frozen, tables.vertex_means[e], el.normal, el.patch, shares)
            };

            let (received, rays) = sharing.receive(
                self,
                &tables.element_area,
                (params.seed, stream),
                // Another group's members: none is a patch of the shooting group.
                |r, range| {
                    let receivers = &self.groups[r].receivers[range];
                    receivers
                        .iter()
                        .map(|&(p, n)| unoccluded(group, frozen, p, n, NONE, &mut [0.0; POINTS]).0)
                        .collect()
                },
                |e| {
                    let mut shares = [0.0; POINTS];
                    let (f, near) = unoccluded_at(e, &mut shares);
                    aim.trace(e, f, near, &shares)
                },
            );
            traced += rays;
            for_each_maybe_parallel(factors, |e, out| {
                if let Some((u, k)) = sharing.member(self, e) {
                    let r = &received[u];
                    *out = (r.factors[k] * r.visibility()) as f32;
                }
            });
        }
        let factors: &[f32] = factors;
        let (row, _) = Row::by_blocks(tables, |q, row| {
            let range = tables.patch_elements[q].clone();
            let span = &factors[range.clone()];
            if span.iter().any(|&f| f > 0.0) {
                row.push(range, span.iter().copied());
            }
            0
        });
        (row, traced)
    }
}

/// What a group's row aims its visibility rays with.
struct Aim<'a> {
    frozen: &'a Frozen,
    mesh: &'a Mesh,
    tables: &'a MeshTables,
    accel: &'a dyn RayQuery,
    /// Rays per receiving element.
    rays: u32,
    seed: u64,
    /// The group's random stream.
    stream: u64,
}

impl Aim<'_> {
    /// Element `e`'s visibility rays to the group, whose unoccluded form factor to it is
    /// `f`, near or not, with its points' `shares` of it when near: (unblocked, traced),
    /// from the element's own stream.
    ///
    /// Rays end at points that give the receiver light: a ray to a point on a facet turned
    /// away would cross the model and count as blocked (the model then came out 2 % dark).
    /// Near the group, points by their share of the form factor, stratified; far, points by
    /// the cosine at them (rejection).
    fn trace(&self, e: usize, f: f64, near: bool, shares: &[f64; POINTS]) -> (u32, u32) {
        let Self { frozen, mesh, tables, accel, rays, seed, stream } = *self;
        let el = &mesh.elements[e];
        let p = tables.vertex_means[e];
        let corners = &tables.lifted_corners[e][..el.vertex_count as usize];
        let mut rng = Rng::for_task(seed, stream, e as u64);
        let (mut visible, mut traced) = (0u32, 0u32);
        let (mut walked, mut at) = (0.0, 0);
        for j in 0..rays {
            let target = if near {
                let t = (f64::from(j) + rng.next_f64()) / f64::from(rays) * f;
                while at + 1 < POINTS && walked + shares[at] < t {
                    walked += shares[at];
                    at += 1;
                }
                Some(at)
            } else {
                let mut found = None;
                for _ in 0..FAR_TRIES {
                    // Kept with probability cos θ at the point: its share of the far field
                    // (one distance for all).
                    let i = (rng.next_u64() % POINTS as u64) as usize;
                    let (q, nq, _) = frozen.points[i];
                    let d = p - q;
                    if el.normal.dot(q - p) > 0.0 && rng.next_f64() * d.length() < nq.dot(d) {
                        found = Some(i);
                        break;
                    }
                }
                found
            };
            let Some(i) = target else { continue };
            let (u, v) = (rng.next_f64() as f32, rng.next_f64() as f32);
            let from = Vec3::from(point_on_f32(corners, u, v));
            visible += u32::from(!accel.occluded(from, frozen.lifted[i]));
            traced += 1;
        }
        (visible, traced)
    }
}

/// Whether patch `q` emits: its shots carry direct light, whose sharp shadows receiving
/// groups must not share (see [`super::shared`]).
pub(super) fn patch_emits(mesh: &Mesh, q: usize) -> bool {
    mesh.element_material(mesh.patches[q].elements.start as usize).emission.max_channel() > 0.0
}

/// Random streams of groups are keyed apart from patches' (whose keys are patch indices).
const GROUP_STREAM: u64 = 0x6772_6f75_7000_0000;

/// Which of the six axis directions a normal is closest to.
fn facing(n: DVec3) -> u8 {
    let a = n.abs();
    let (axis, value) = if a.x >= a.y && a.x >= a.z {
        (0, n.x)
    } else if a.y >= a.z {
        (1, n.y)
    } else {
        (2, n.z)
    };
    2 * axis + u8::from(value < 0.0)
}

/// The area-weighted centroid of `patches`, the largest distance from it to one of their
/// corners, and their area.
fn extent(mesh: &Mesh, patches: &[u32]) -> (DVec3, f64, f64) {
    let area: f64 = patches.iter().map(|&q| mesh.patches[q as usize].area).sum();
    let centre = patches
        .iter()
        .map(|&q| mesh.patches[q as usize].centre * mesh.patches[q as usize].area)
        .sum::<DVec3>()
        / area;
    let radius = (patches.iter())
        .flat_map(|&q| mesh.patches[q as usize].corners().iter())
        .map(|c| c.distance(centre))
        .fold(0.0, f64::max);
    (centre, radius, area)
}

/// Orders `patches` (starting at `offset` in their group) into tiles of at most
/// [`TILE_FACETS`], halved at the median of their centres along the longest side of the
/// centres' box, and pushes each tile's range. Ties are broken by index, so the order is
/// the same from run to run.
fn cut_into_tiles(mesh: &Mesh, patches: &mut [u32], offset: usize, cuts: &mut Vec<std::ops::Range<usize>>) {
    if patches.len() <= TILE_FACETS {
        cuts.push(offset..offset + patches.len());
        return;
    }
    let centre = |q: u32| mesh.patches[q as usize].centre;
    let (lo, hi) = patches
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &q| (lo.min(centre(q)), hi.max(centre(q))));
    let axis = (hi - lo).max_position();
    let half = patches.len() / 2;
    patches
        .select_nth_unstable_by(half, |&a, &b| centre(a)[axis].total_cmp(&centre(b)[axis]).then(a.cmp(&b)));
    let (left, right) = patches.split_at_mut(half);
    cut_into_tiles(mesh, left, offset, cuts);
    cut_into_tiles(mesh, right, offset + half, cuts);
}

/// Σ |unshot power| over `patches`' elements.
fn total_power(patches: &[u32], mesh: &Mesh, unshot: &[Rgb]) -> f64 {
    (patches.iter())
        .flat_map(|&q| {
            let r = &mesh.patches[q as usize].elements;
            r.start as usize..r.end as usize
        })
        .map(|e| (unshot[e] * mesh.elements[e].area).abs().sum())
        .sum()
}

/// Bins per side of the grid that sorts a group's normals by their two minor components
/// (the major one is the group's facing): 16 bins of about 20° each, so that the clamp of
/// each bin's summed normal loses little (Σ_k w_k (n_k·d)⁺ ≥ (Σ_k w_k n_k · d)⁺, equal when
/// no member of the bin faces away from d). One vector for the whole group left its far
/// receivers 1–4 % dark.
const BINS: usize = 4;

/// The bin of normal `n` (see [`BINS`]).
fn normal_bin(n: DVec3) -> usize {
    let minor = match facing(n) / 2 {
        0 => (n.y, n.z),
        1 => (n.x, n.z),
        _ => (n.x, n.y),
    };
    // The minor components of a normal whose major axis is largest lie within ±1/√2.
    let cell = |c: f64| {
        (((c * std::f64::consts::FRAC_1_SQRT_2.recip() + 1.0) * 0.5 * BINS as f64) as usize).min(BINS - 1)
    };
    cell(minor.0) * BINS + cell(minor.1)
}

/// The form factor from a receiver at `p` (normal `n`, on patch `patch`) to the group,
/// without visibility, such that the receiver's irradiance is the group's mean unshot
/// radiosity ΔΦ/A times it, and whether it is near (then `shares` holds each point's part of
/// it). A member receives from the group's other facets (a fold of the model), not from its
/// own.
fn unoccluded(
    group: &Group,
    frozen: &Frozen,
    p: DVec3,
    n: DVec3,
    patch: u32,
    shares: &mut [f64; POINTS],
) -> (f64, bool) {
    let to_centre = group.centre - p;
    // All of the group behind the receiver's plane.
    if n.dot(to_centre) <= -group.radius {
        return (0.0, false);
    }
    let r2 = to_centre.length_squared();
    if r2 > (FAR * group.radius).powi(2) {
        let r = r2.sqrt();
        let d = -to_centre / r; // from the group towards the receiver
        let cos_r = -n.dot(d);
        if cos_r <= 0.0 {
            return (0.0, false);
        }
        let out = frozen.lobe(d);
        return (group.area * out * cos_r / (std::f64::consts::PI * r2), false);
    }
    let disc = group.area / POINTS as f64;
    let pts = &frozen.near;
    // In single precision about the group's centre (7 digits, far below the points' own
    // scatter), four points to a register where f64 took two: the loop's divisions were
    // most of its time.
    let d0 = (p - pts.origin).as_vec3();
    let (n, a) = (n.as_vec3(), disc as f32);
    let mut lanes = [0.0f32; POINTS];
    for (i, lane) in lanes.iter_mut().enumerate() {
        let d = [d0.x - pts.x[0][i], d0.y - pts.x[1][i], d0.z - pts.x[2][i]];
        let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        let out = pts.n[0][i] * d[0] + pts.n[1][i] * d[1] + pts.n[2][i] * d[2];
        let cos_r = -(n.x * d[0] + n.y * d[1] + n.z * d[2]);
        // cos θ cos θ' a / (π r² + a), with both cosines times r.
        let term = a * out * cos_r / (r2 * (std::f32::consts::PI * r2 + a));
        *lane = if pts.patch[i] != patch && out > 0.0 && cos_r > 0.0 { term } else { 0.0 };
    }
    // Four running sums, not one: a single chain of additions took as long as the terms.
    let mut sums = [0.0f64; 4];
    for (four, shares) in lanes.chunks_exact(4).zip(shares.chunks_exact_mut(4)) {
        for k in 0..4 {
            shares[k] = f64::from(four[k]);
            sums[k] += shares[k];
        }
    }
    ((sums[0] + sums[1]) + (sums[2] + sums[3]), true)
}

/// A group's near-field points by coordinate, about its centre (see [`Frozen::near`]).
struct NearPoints {
    /// The group's centre, which the coordinates are taken from.
    origin: DVec3,
    /// x, y and z of each point.
    x: [[f32; POINTS]; 3],
    /// x, y and z of each point's normal.
    n: [[f32; POINTS]; 3],
    /// Each point's patch.
    patch: [u32; POINTS],
}

impl NearPoints {
    fn new(origin: DVec3, points: &[(DVec3, DVec3, u32)]) -> Self {
        let mut near = Self { origin, x: [[0.0; POINTS]; 3], n: [[0.0; POINTS]; 3], patch: [NONE; POINTS] };
        for (i, (q, nq, patch)) in points.iter().enumerate() {
            let (q, nq) = ((*q - origin).as_vec3(), nq.as_vec3());
            for axis in 0..3 {
                near.x[axis][i] = q[axis];
                near.n[axis][i] = nq[axis];
            }
            near.patch[i] = *patch;
        }
        near
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiosity_core::{Material, MeshParams, Object, PolygonMesh, Scene, Shape, Sides, cornell_box};

    /// A latitude–longitude sphere of `rings × segments` planar quads (triangles at the
    /// poles), facing outwards: every facet its own surface.
    fn globe(rings: u32, segments: u32) -> Mesh {
        use std::f64::consts::{PI, TAU};
        let mut positions = Vec::new();
        for i in 0..=rings {
            let theta = PI * f64::from(i) / f64::from(rings);
            for j in 0..segments {
                let phi = TAU * f64::from(j) / f64::from(segments);
                positions.push(DVec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin()));
            }
        }
        let at = |i: u32, j: u32| i * segments + j % segments;
        let mut faces = Vec::new();
        for i in 0..rings {
            for j in 0..segments {
                let quad = [at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)];
                match i {
                    0 => faces.push(vec![quad[0], quad[2], quad[3]]),
                    _ if i == rings - 1 => faces.push(vec![quad[0], quad[1], quad[2]]),
                    _ => faces.push(quad.to_vec()),
                }
            }
        }
        let white = Material::try_new("white", Rgb::splat(0.5), Rgb::splat(1.0)).unwrap();
        let globe = PolygonMesh::try_new(positions, faces).unwrap();
        let object =
            Object { name: "globe".into(), material: 0, shape: Shape::Mesh(globe), sides: Sides::One };
        let scene = Scene::try_new("globe", None, vec![white], vec![object]).unwrap();
        Mesh::build(&scene, &MeshParams::try_new(1.0, 1.0).unwrap()).unwrap()
    }

    /// A group's tiles cover its elements once, in runs of at most [`TILE_FACETS`] patches,
    /// each within its own radius of its centre and smaller than the group.
    #[test]
    fn tiles_cut_each_group_into_small_runs_that_cover_it() {
        let mesh = globe(96, 192);
        let clusters = Clusters::new(&mesh, true);
        let mut cut = 0;
        for g in 0..clusters.len() {
            let group = clusters.group(g);
            let mut next = 0;
            for t in group.tiles.clone().map(|t| t as usize) {
                let tile = clusters.tile(t);
                assert_eq!(tile.elements.start, next, "group {g}: tiles in order, no gaps");
                next = tile.elements.end;
                assert!(tile.patches as usize <= TILE_FACETS && tile.patches > 0);
                assert!(tile.radius <= group.radius + 1e-12);
                for &e in &group.elements[tile.elements.start as usize..tile.elements.end as usize] {
                    assert!(tile.elements.contains(&(clusters.slot(e as usize) as u32)));
                    for c in mesh.element_corners(e as usize) {
                        assert!(c.distance(tile.centre) <= tile.radius + 1e-12);
                    }
                }
            }
            assert_eq!(next as usize, group.elements.len());
            cut += usize::from(group.tiles.len() > 1);
        }
        assert!(cut > 0, "some group larger than a tile");
    }

    /// Polygon scenes have no facets to group; a tessellated sphere's facets fall into groups
    /// of one facing each, every facet in at most one, the groups' areas those of their members.
    #[test]
    fn facets_group_by_facing_and_cell_and_polygons_stay_alone() {
        let cornell = Mesh::build(&cornell_box(), &cornell_box().mesh_params()).unwrap();
        assert_eq!(Clusters::new(&cornell, true).len(), 0);
        let mesh = globe(24, 48);
        assert_eq!(Clusters::new(&mesh, false).len(), 0);
        let clusters = Clusters::new(&mesh, true);
        assert!(clusters.len() > 20, "{} groups", clusters.len());
        let mut seen = vec![0; mesh.patches.len()];
        for g in 0..clusters.len() {
            let group = clusters.group(g);
            assert!(group.patches.len() > 1);
            let facings: Vec<u8> =
                group.patches.iter().map(|&q| facing(mesh.patches[q as usize].normal)).collect();
            assert!(facings.iter().all(|&f| f == facings[0]), "group {g}: {facings:?}");
            let area: f64 = group.patches.iter().map(|&q| mesh.patches[q as usize].area).sum();
            assert!((area - group.area).abs() < 1e-12 * area);
            for &q in &group.patches {
                seen[q as usize] += 1;
                assert!(clusters.members()[q as usize]);
            }
        }
        assert!(seen.iter().all(|&n| n <= 1));
        assert!(seen.iter().filter(|&&n| n == 1).count() > mesh.patches.len() / 2);
    }

    /// A flat face tessellated into many small coplanar triangles (a CAD model's disc, fanned
    /// from its centre) is one surface of many patches: its patches are facets and shoot in
    /// groups, while a wall cut into patch-size pieces stays alone.
    #[test]
    fn a_tessellated_flat_face_groups_and_a_wall_does_not() {
        let n = 128u32;
        let rim = (0..n).map(|k| {
            let a = std::f64::consts::TAU * f64::from(k) / f64::from(n);
            DVec3::new(0.1 * a.cos(), 0.1 * a.sin(), 0.0)
        });
        let positions: Vec<DVec3> = std::iter::once(DVec3::ZERO).chain(rim).collect();
        let faces: Vec<Vec<u32>> = (0..n).map(|k| vec![0, 1 + k, 1 + (k + 1) % n]).collect();
        let plate = PolygonMesh::try_new(positions, faces).unwrap();
        let white = Material::try_new("white", Rgb::splat(0.5), Rgb::splat(1.0)).unwrap();
        let wall = radiosity_core::Polygon::try_new(vec![
            DVec3::new(-1.0, -2.0, -2.0),
            DVec3::new(-1.0, 2.0, -2.0),
            DVec3::new(-1.0, 2.0, 2.0),
            DVec3::new(-1.0, -2.0, 2.0),
        ])
        .unwrap();
        let objects = vec![
            Object { name: "plate".into(), material: 0, shape: Shape::Mesh(plate), sides: Sides::One },
            Object {
                name: "wall".into(),
                material: 0,
                shape: Shape::Polygons(vec![wall]),
                sides: Sides::One,
            },
        ];
        let scene = Scene::try_new("plate and wall", None, vec![white], objects).unwrap();
        let mesh = Mesh::build(&scene, &MeshParams::try_new(1.0, 0.5).unwrap()).unwrap();
        let object_of = |q: usize| mesh.surfaces[mesh.patches[q].surface as usize].object;
        let plate_patches: Vec<usize> = (0..mesh.patches.len()).filter(|&q| object_of(q) == 0).collect();
        let plate_surfaces: std::collections::BTreeSet<u32> =
            plate_patches.iter().map(|&q| mesh.patches[q].surface).collect();
        assert!(
            plate_patches.len() >= 100 && plate_surfaces.len() < 4,
            "{} patches, {} surfaces",
            plate_patches.len(),
            plate_surfaces.len()
        );
        let clusters = Clusters::new(&mesh, true);
        assert!(clusters.len() > 0);
        assert!(
            plate_patches.iter().all(|&q| clusters.members()[q]),
            "every piece of the plate shoots in a group"
        );
        assert!(
            (0..mesh.patches.len()).filter(|&q| object_of(q) == 1).all(|q| !clusters.members()[q]),
            "the wall shoots alone"
        );
    }

    /// The brightest shooter is the patch or group of largest |unshot power|, and the
    /// groups' sums follow the patches that change.
    #[test]
    fn the_brightest_shooter_follows_changed_patches() {
        let mesh = globe(24, 48);
        let mut clusters = Clusters::new(&mesh, true);
        let mut abs = vec![0.0; mesh.patches.len()];
        let single = (0..mesh.patches.len()).find(|&q| !clusters.members()[q]).unwrap();
        abs[single] = 1.0;
        clusters.sum(&abs);
        assert_eq!(clusters.brightest(&abs), Shooter::Patch(single));
        // Two members of one group, each dimmer than the single patch, together brighter.
        let group = clusters.group(3).patches.clone();
        abs[group[0] as usize] = 0.6;
        abs[group[1] as usize] = 0.6;
        clusters.update(&[(group[0], 0.6), (group[1], 0.6)], &abs);
        assert_eq!(clusters.brightest(&abs), Shooter::Group(3));
        abs[group[0] as usize] = 0.0;
        clusters.update(&[(group[0], -0.6)], &abs);
        assert_eq!(clusters.brightest(&abs), Shooter::Patch(single));
    }

    /// The 24 × 48 globe grouped, unit unshot radiosity everywhere, and the groups `pick`
    /// chooses from the number of groups frozen (returned with the mesh and the clusters).
    fn frozen_globe(pick: impl Fn(usize) -> Vec<usize>) -> (Mesh, Clusters, Vec<usize>) {
        let mesh = globe(24, 48);
        let mut clusters = Clusters::new(&mesh, true);
        let unshot = vec![Rgb::splat(1.0); mesh.elements.len()];
        let tables = MeshTables::new(&mesh);
        let groups = pick(clusters.len());
        for &g in &groups {
            clusters.freeze(g, &mesh, &unshot, &tables, &SolverParams::default(), 1.0);
        }
        (mesh, clusters, groups)
    }

    /// A group's spread is fixed again once a fifth of its power has moved between its
    /// facets (light from the room reaching the facets the lamp missed), not before, and its
    /// points then follow the power; its brightness stays that of its first shot.
    #[test]
    fn a_group_whose_power_moved_is_fixed_again() {
        let (mesh, mut clusters, groups) = frozen_globe(|n| vec![n / 3]);
        let g = groups[0];
        let elements: Vec<usize> = clusters.groups[g].elements.iter().map(|&e| e as usize).collect();
        let bright = clusters.groups[g].frozen.as_ref().unwrap().bright;
        // The facets split in two halves of equal area.
        let total: f64 = elements.iter().map(|&e| mesh.elements[e].area).sum();
        let mut acc = 0.0;
        let half = elements
            .iter()
            .position(|&e| {
                acc += mesh.elements[e].area;
                acc >= total / 2.0
            })
            .unwrap();
        // 10 % of the power moved to the first half: kept.
        let mut unshot = vec![Rgb::splat(0.0); mesh.elements.len()];
        for (k, &e) in elements.iter().enumerate() {
            unshot[e] = Rgb::splat(if k < half { 1.2 } else { 0.8 });
        }
        assert!(!clusters.refresh_if_drifted(g, &mesh, &unshot));
        assert!(clusters.groups[g].frozen.is_some());
        // All of it on the first half: half the power moved, fixed again.
        for &e in &elements[half..] {
            unshot[e] = Rgb::splat(0.0);
        }
        assert!(clusters.refresh_if_drifted(g, &mesh, &unshot));
        assert!(clusters.groups[g].frozen.is_none());
        let tables = MeshTables::new(&mesh);
        // A first shot 1000 times brighter would make this one dim, were it judged afresh.
        clusters.freeze(g, &mesh, &unshot, &tables, &SolverParams::default(), 1000.0);
        let frozen = clusters.groups[g].frozen.as_ref().unwrap();
        assert_eq!(frozen.bright, bright);
        let first_half: std::collections::HashSet<u32> =
            elements[..half].iter().map(|&e| mesh.elements[e].patch).collect();
        assert!(frozen.points.iter().all(|(_, _, q)| first_half.contains(q)), "points on the lit half only");
    }

    /// A group's far field sends out all its power: over the sphere of directions,
    /// ∫ Σ_b (a_b·d)⁺ dω / π = 1, the sum of its members' shares (each member's clamped lobe
    /// sends out π times its share). Directions on a 400 × 800 grid in (θ, φ), which integrates
    /// a lobe within 2e-6; asserted within 0.1 %. With each bin's summed normal unscaled, this
    /// ball's groups sent out 0.15–0.17 % less.
    #[test]
    fn the_far_field_sends_out_the_groups_power() {
        let (_, clusters, groups) = frozen_globe(|n| vec![0, n / 3, n / 2]);
        let (rows, columns) = (400, 800);
        for g in groups {
            let frozen = clusters.groups[g].frozen.as_ref().unwrap();
            let mut sent = 0.0;
            for i in 0..rows {
                let theta = std::f64::consts::PI * (f64::from(i) + 0.5) / f64::from(rows);
                for j in 0..columns {
                    let phi = std::f64::consts::TAU * (f64::from(j) + 0.5) / f64::from(columns);
                    let d = DVec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin());
                    let lobe = frozen.lobe(d);
                    sent += lobe * theta.sin();
                }
            }
            let cell = std::f64::consts::PI / f64::from(rows) * std::f64::consts::TAU / f64::from(columns);
            let sent = sent * cell / std::f64::consts::PI;
            assert!((sent - 1.0).abs() < 0.001, "group {g} sends out {sent} of its power");
        }
    }

    /// Far from a group, its binned normals give the members' own point-to-point sum: a
    /// receiver ten radii away along each axis agrees within 2 % (the spread of distances
    /// across the group, ±10 %, mostly cancels).
    #[test]
    fn the_far_field_is_the_members_sum() {
        let (mesh, clusters, groups) = frozen_globe(|n| vec![0, n / 2]);
        for g in groups {
            let (group, frozen) = (clusters.group(g), clusters.groups[g].frozen.as_ref().unwrap());
            let sum = |k: usize| frozen.axes.iter().map(|a| f64::from(a[k].element_sum())).sum::<f64>();
            let axis = DVec3::new(sum(0), sum(1), sum(2)).normalize();
            for tilt in [DVec3::ZERO, DVec3::X * 0.5, DVec3::Z * 0.5] {
                let dir = (axis + tilt).normalize();
                let p = group.centre + dir * 10.0 * group.radius;
                let n = -dir;
                let mut shares = [0.0; POINTS];
                let (far, near) = unoccluded(group, frozen, p, n, u32::MAX, &mut shares);
                assert!(!near);
                let exact: f64 = (group.patches.iter())
                    .map(|&q| {
                        let patch = &mesh.patches[q as usize];
                        crate::form_factor::point_to_point(p, n, patch.centre, patch.normal, patch.area)
                    })
                    .sum();
                assert!((far / exact - 1.0).abs() < 0.02, "group {g}, tilt {tilt}: {far} vs {exact}");
            }
        }
    }
}
