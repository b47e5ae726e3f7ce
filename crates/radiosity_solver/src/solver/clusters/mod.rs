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
//!   finite at contact); an emitting group's direct light so at every distance;
//! * visibility: `dim_rays` rays per receiving element (`visibility_rays` when the group is
//!   bright) to those points, through the scene's ray structure.
//!
//! Members receive from their own group's other facets (a fold of the model lights itself),
//! by the near field.
//!
//! Here: the groups and their tiles, as data (what `shared` and `shot` read of them);
//! `power`: the groups' unshot power and who shoots next; `frozen`: a group's spread fixed at
//! its first shot; `row`: a group's row, far field, near field and visibility. The last three
//! read the tally, the first shots and the shot's scratch, which read the groups, so they are
//! files of their own above those.

use std::collections::BTreeMap;

use glam::{DVec3, Vec3, Vec4};
use radiosity_core::Rgb;
use radiosity_mesh::Mesh;

mod frozen;
mod power;
mod row;

#[cfg(test)]
mod tests;

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

/// A facet's corners lie within this many cells of its centre. At 1, Sponza's long thin
/// facets (a column's flutes, an arch's soffit strips: 3 950 of its 115 k patches) each shot
/// alone; at 2 they join groups and the atrium reaches 5 % unshot in 152 s instead of 226 s
/// (6 106 shots, not 7 814). Bitterli's *Grey & White Room* (2 128 such facets) takes 6 402
/// shots and 392 M rays to 0.1 % unshot instead of 8 039 and 545 M; against the path tracer
/// its white sofa's three parts come out 0.8–1.1 % nearer, its curtains 0.1–0.5 % farther
/// (all six within 1.8 %), the median object of at least 1 % of the area 1.01 % (0.89 %).
const FACET_REACH: f64 = 2.0;

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
                    && p.corners().iter().all(|c| c.distance(p.centre) < FACET_REACH * cell)
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
