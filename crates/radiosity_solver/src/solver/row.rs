//! One shooter's row of form factors F_{j→i} (visibility included) to every receiving
//! element j, and how it is computed: plan the receiving patches, fix the shooter's first-shot
//! spread, lay out its ray ends, then two passes over the receivers (form factors and pilot
//! rays; penumbra rays where the neighbours saw a penumbra) and gather the factors.

use std::ops::Range;
use std::sync::Arc;

use rayon::prelude::*;

use super::Solver;
use super::mesh_tables::MeshTables;
use super::parallel::{blocks_in_parallel, for_each_block_mut, for_each_maybe_parallel, map_blocks};
use super::penumbra::wants_penumbra_rays;
use super::plans::{PatchPlan, plan_patches};
use super::ray_ends::draw_ray_ends;
use super::rays::{Rays, SINGLE_STREAM, trace};
use super::receive::{Received, receive_patch};
use super::shot::Shot;
use super::uneven::{Uneven, cluster_elements};
use crate::form_factor::{point_to_point, point_to_polygon, points_to_polygon_in_front_x4};
use crate::sampling::{Rng, Strata};

/// One shooter's form factors F_{j→shooter} (visibility included) to the elements of every
/// patch that can receive from it, as runs of consecutive elements.
pub(super) struct Row {
    /// `(first element, element count)` of each run of whole consecutive receiving patches
    /// (at most [`MAX_RUN`] elements unless one patch has more), in element order. A model's
    /// facets are one-element patches: a span each took twice the memory of their factors.
    pub(super) spans: Vec<(u32, u32)>,
    /// The factors, span after span, in f32 (7 digits, far below the visibility noise); a
    /// row applied fresh is rounded the same way, so keeping it changes nothing.
    pub(super) factors: Vec<f32>,
    /// The receivers that touch the shooter, weighted at each shot by the part of it they
    /// see (see [`NearField`]).
    pub(super) near: NearField,
    /// What geometry alone decided for a patch shooter's row, kept with it when the budget
    /// allows, so that the row computed again after its spread moves traces rays only.
    pub(super) geometry: Option<Box<Geometry>>,
    /// While the row is built: pushes merge only into a span that starts at this element or
    /// later (the first of the block of patches being pushed, see [`Row::by_blocks`]).
    floor: u32,
}

/// The part of a patch shooter's row that geometry alone decides: its receiving patches'
/// plans and every element's form factor without visibility, before any weighting.
///
/// When the shooter's spread is fixed again (see `first_shots`), its ray ends move and its
/// rays are traced again, but none of this changes; a Cornell box's row spends about four
/// fifths of its time here (plans a tenth, form factors nearly half, the near field's shares
/// a quarter), and a third of its rows are such refreshes. The factors are kept in single
/// precision and rounded so wherever they are computed, so a row built from them is the
/// row computed afresh, bit for bit (`tests/suite/fast_paths.rs`).
pub(super) struct Geometry {
    plans: Vec<PatchPlan>,
    /// Per mesh element, its unweighted form factor (0 where its patch does not receive or
    /// takes its group's visibility).
    unweighted: Vec<f32>,
    /// Heap and inline bytes, counted once: the row cache asks for every kept row's size
    /// whenever it makes room, and the plans' candidate lists would be walked each time.
    bytes: usize,
}

impl Geometry {
    fn new(plans: Vec<PatchPlan>, unweighted: Vec<f32>) -> Self {
        let bytes = std::mem::size_of::<Self>()
            + plans.len() * std::mem::size_of::<PatchPlan>()
            + 4 * plans.iter().map(|p| p.candidates.len()).sum::<usize>()
            + 4 * unweighted.len();
        Self { plans, unweighted, bytes }
    }

    /// Geometry of `elements` zero factors and no plans, for the cache's tests.
    #[cfg(test)]
    pub(super) fn zeros(elements: usize) -> Self {
        Self::new(Vec::new(), vec![0.0; elements])
    }

    /// What kept geometry costs for a mesh of `patches` and `elements` (at most: candidate
    /// lists aside, a few triangles per patch).
    pub(super) fn estimate(patches: usize, elements: usize) -> usize {
        patches * (std::mem::size_of::<PatchPlan>() + 16) + 4 * elements
    }
}

/// The receiving elements that touch a patch shooter (across or on its plane: a floor strip
/// at the foot of a wall, a wall strip in a room's corner), and how much of each of the
/// shooter's elements each of them sees.
///
/// Such a receiver sees the shooter's near edge under a far larger form factor than the
/// rest, so the patch's mean unshot radiosity is wrong for it whenever the radiosity over
/// the patch is uneven: the transfer is Σ_k ΔB_k F_{j→k} = F_j Σ_k φ_jk ΔB_k, with
/// φ_jk = F_{j→k} / F_j. Weighting by the spread fixed at the patch's first shot missed
/// what changes between shots: an inside corner's indirect light dims towards the corner
/// while the direct light of the first shot does not, and the strips on both sides of the
/// Cornell box's back corners came out 1.5–2.5 % bright (element means against the path
/// tracer). The shares φ are geometry, kept with the row; the weighting is done at each
/// shot with the unshot radiosity the shooter has then (`Tally::shoot`).
#[derive(Default)]
pub(super) struct NearField {
    /// (element, its factor F_j as in the row, first term, term count).
    pub(super) receivers: Vec<(u32, f32, u32, u32)>,
    /// (part of the shooter, share φ), receiver after receiver. A part is one shooter
    /// element, or, flagged by [`CLUSTER_TERM`], a cluster of nearby ones seen from far
    /// enough to count as one (`uneven::cluster_elements`, four radii: the point-to-point
    /// factor is then within ~2 %). Shares below [`MIN_SHARE`] are left out and their part
    /// of the shooter counts at its mean.
    pub(super) terms: Vec<(u32, f32)>,
    /// The clusters' elements (mesh indices): cluster c's are
    /// `members[clusters[c].0..clusters[c].1]`.
    pub(super) members: Vec<u32>,
    /// Each cluster's range of `members`.
    pub(super) clusters: Vec<(u32, u32)>,
    /// Σ A_j F_j over the row's other receivers but a model's grouped facets (which take the
    /// mean), which take what the near ones do not.
    pub(super) rest: f64,
}

/// A [`NearField`] term whose part is a cluster (its index with this bit set).
pub(super) const CLUSTER_TERM: u32 = 1 << 31;

/// Receivers farther than this many shooter radii from its centre see it small enough to
/// take its mean. Cornell (`render`, against the path tracer): with no limit 2.70 % per
/// pixel, 1 570 receivers per row and a third more solve time; at 3 radii 2.82 %, 490
/// receivers; at 1.5, 2.95 %.
const NEAR_REACH: f64 = 3.0;

/// Terms of near receivers, one after another: (part of the shooter, share).
type Terms = Vec<(u32, f32)>;

/// Near receivers whose shares one task computes when they are computed in parallel: a
/// receiver's shares cost about a microsecond, so runs of 8 from 16 receivers up keep every
/// thread busy on a small scene's rows (Cornell, two threads: 0.505 → 0.479 s median of
/// seven, against runs of 32 from 64 receivers up).
const NEAR_RUN: usize = 8;

/// Smallest share of a shooter part kept in a near receiver's terms.
const MIN_SHARE: f64 = 1e-3;

impl NearField {
    fn bytes(&self) -> usize {
        16 * self.receivers.len() + 8 * (self.terms.len() + self.clusters.len()) + 4 * self.members.len()
    }
}

/// Receiving patches merge into one span up to this many elements, so that a shot's
/// chunks of spans (see `Tally::shoot`) stay small enough to share among threads.
const MAX_RUN: u32 = 1024;

impl Row {
    /// An empty row.
    pub(super) fn new() -> Self {
        Self { spans: Vec::new(), factors: Vec::new(), near: NearField::default(), geometry: None, floor: 0 }
    }

    /// Appends the factors of a receiving patch whose elements are `elements` (after those
    /// of the patches pushed before it), merging it into the last span when it follows it.
    pub(super) fn push(&mut self, elements: std::ops::Range<usize>, factors: impl IntoIterator<Item = f32>) {
        let (first, count) = (elements.start as u32, elements.len() as u32);
        match self.spans.last_mut() {
            Some((start, n)) if *start >= self.floor && *start + *n == first && *n + count <= MAX_RUN => {
                *n += count
            }
            _ => self.spans.push((first, count)),
        }
        self.factors.extend(factors);
    }

    /// The row that `patch(q, row)` pushes patch after patch (returning a count, summed),
    /// built in the mesh's blocks of patches (see [`super::parallel::patch_blocks`]), on
    /// the thread pool when the mesh is large, and joined in order. A span never crosses a
    /// block, so the row is the same on one thread or many.
    pub(super) fn by_blocks(
        tables: &MeshTables,
        patch: impl Fn(usize, &mut Row) -> u64 + Sync,
    ) -> (Row, u64) {
        let blocks = &tables.patch_blocks;
        let first_element = |b: &Range<usize>| tables.patch_elements[b.start].start as u32;
        if !blocks_in_parallel(tables.element_area.len(), false) {
            // One row grown in place: a small scene's rows need no per-block rows allocated,
            // grown and copied.
            let mut row = Row::new();
            let mut count = 0;
            for b in blocks {
                row.floor = first_element(b);
                count += b.clone().map(|q| patch(q, &mut row)).sum::<u64>();
            }
            row.floor = 0;
            return (row, count);
        }
        let parts: Vec<(Row, u64)> = blocks
            .par_iter()
            .map(|b| {
                let mut row = Row::new();
                row.floor = first_element(b);
                let count = b.clone().map(|q| patch(q, &mut row)).sum::<u64>();
                (row, count)
            })
            .collect();
        let mut row = Row::new();
        row.spans.reserve_exact(parts.iter().map(|p| p.0.spans.len()).sum());
        row.factors.reserve_exact(parts.iter().map(|p| p.0.factors.len()).sum());
        let mut count = 0;
        for (part, n) in parts {
            row.spans.extend(part.spans);
            row.factors.extend(part.factors);
            count += n;
        }
        (row, count)
    }

    /// Heap and inline bytes the row holds.
    pub(super) fn bytes(&self) -> usize {
        std::mem::size_of::<Self>()
            + 8 * self.spans.len()
            + 4 * self.factors.len()
            + self.near.bytes()
            + self.geometry.as_ref().map_or(0, |g| g.bytes)
    }
}

impl Solver {
    /// Computes `shooter`'s row: the form factor from every element to it, visibility
    /// included. `previous`, its row from before its spread was fixed again, lends what
    /// geometry alone decided: its kept [`Geometry`] and its near field's shares. With
    /// `keep_geometry` the new row keeps its geometry.
    pub(super) fn compute_row(&mut self, shooter: usize, previous: Option<Row>, keep_geometry: bool) -> Row {
        let (kept, previous_near) = match previous {
            Some(row) => (row.geometry, Some(row.near)),
            None => (None, None),
        };
        let mesh = Arc::clone(&self.mesh);
        let patch = &mesh.patches[shooter];
        let first_of_solve = self.progress.shots == 0;
        self.first_shots.freeze(&mesh, shooter, &self.tally, first_of_solve, self.params.bright_share);
        let bright = self.first_shots.bright(shooter);
        let penumbra_rays = self.first_shots.penumbra_rays(shooter, self.params.penumbra_rays);
        let shooter_radius = super::mesh_tables::patch_radius(patch);
        let share = self.params.clustering && self.params.shared_visibility;
        let emits = super::clusters::patch_emits(&mesh, shooter);
        self.scratch.sharing.choose(&self.clusters, patch.centre, shooter_radius, emits, share, None);
        if kept.is_none() && self.rows.plans(shooter).is_none() {
            let (sharing, patch_elements) = (&self.scratch.sharing, &self.tables.patch_elements);
            let shares = |q: usize| sharing.shares(patch_elements[q].start);
            let reference = self.params.reference_path;
            plan_patches(&mesh, shooter, &self.tables, reference, shares, &mut self.scratch.plans);
        }
        let scratch = &mut self.scratch;
        scratch.load_shooter(&mesh, patch, &self.tables.element_radii);
        let cdf = self.first_shots.cdf(&mesh, shooter);
        scratch.near_runs.load(&scratch.shooter_elements, cdf, patch.centre);
        let lift = patch.normal * self.tables.ray_offset;
        let (targets, lifted) = (&mut scratch.targets, &mut scratch.lifted_targets);
        draw_ray_ends(
            self.params.seed,
            shooter as u64,
            cdf,
            &scratch.shooter_elements,
            lift,
            targets,
            lifted,
        );
        let density = self.first_shots.uneven_density(&mesh, shooter);
        scratch.clusters.clear();
        scratch.cluster_order.clear();
        if let Some(density) = density {
            let (order, clusters) = (&mut scratch.cluster_order, &mut scratch.clusters);
            cluster_elements(&scratch.shooter_elements, density, order, clusters);
        }

        let (params, tables) = (&self.params, &self.tables);
        let shot = Shot {
            mesh: &mesh,
            shooter: patch,
            targets: &scratch.targets,
            lifted_targets: &scratch.lifted_targets,
            shooter_elements: &scratch.shooter_elements,
            cdf,
            near_runs: &scratch.near_runs,
            vertex_means: &tables.vertex_means,
            element_radii: &tables.element_radii,
            lifted_corners: &tables.lifted_corners,
            uneven: density.map(|_| Uneven { clusters: &scratch.clusters }),
            accel: &*self.accel,
            boxes: &tables.occluder_boxes,
            blockers: &tables.blockers,
            params,
            offset: tables.ray_offset,
            stream: shooter as u64,
            shooter_radius,
            single_key: Rng::for_task(params.seed, shooter as u64, SINGLE_STREAM).next_u64(),
            pilot: Strata::new(if bright { params.visibility_rays } else { params.dim_rays }),
            facet_pilot: Strata::new(if bright { facet_rays(params) } else { params.dim_rays }),
            clusters: &self.clusters,
            sharing: &scratch.sharing,
            patch_elements: &tables.patch_elements,
            penumbra: Strata::new(penumbra_rays),
        };
        let plans: &[PatchPlan] = match &kept {
            Some(kept) => &kept.plans,
            None => self.rows.plans(shooter).unwrap_or(&scratch.plans),
        };
        first_pass(
            &shot,
            plans,
            &tables.patch_blocks,
            kept.as_ref().map(|k| &k.unweighted[..]),
            &mut scratch.factors,
        );
        let fresh = (kept.is_none() && keep_geometry).then(|| {
            let unweighted = scratch.factors.iter().map(|r| r.unweighted as f32).collect();
            Box::new(Geometry::new(plans.to_vec(), unweighted))
        });
        let shared_rays = receive_shared(&shot, plans, &tables.element_area, &mut scratch.factors);
        if penumbra_rays > 0 && bright {
            penumbra_pass(&shot, plans, tables, &mut scratch.penumbra, &mut scratch.factors);
        }
        if shot.uneven.is_some() {
            keep_uneven_power(tables, plans, &mut scratch.factors);
        }
        let (mut row, rays) = gather(tables, plans, &scratch.factors, |q| shot.shares(q));
        row.near = near_field(&shot, plans, tables, &row, previous_near);
        row.geometry = kept.or(fresh);
        self.progress.rays += rays + shared_rays;
        row
    }
}

/// An uneven shooter's weighting moves power between the receivers that touch it or are near
/// it: a block side sees the dark floor in front of it and gets less than the patch's mean
/// would give it. That power is not lost: the shooter's lit elements send it to the rest of
/// the scene, which sees the patch whole (in a closed scene every element of a patch sends all
/// its power somewhere, Σ_j F_kj = 1). So the other (unweighted) receivers' form factors are
/// scaled to keep the row's total Σ_j A_j F_j what it is without the weighting (by reciprocity A_j F_j is
/// the shooter's power share going to j). Without this the Cornell ceiling, lit only by
/// such transfers, came out 1.2 % dark.
fn keep_uneven_power(tables: &MeshTables, plans: &[PatchPlan], factors: &mut [Received]) {
    let MeshTables { element_area, patch_elements, patch_blocks: blocks, .. } = tables;
    let weighted = |r: &Received| r.unoccluded != r.unweighted;
    // Sums per block, added in block order: the same on any thread count.
    let sums = map_blocks(blocks, factors.len(), |patches| {
        let (mut moved, mut rest) = (0.0, 0.0);
        for q in patches.filter(|&q| plans[q].live) {
            for e in patch_elements[q].clone() {
                let (r, area) = (&factors[e], element_area[e]);
                if weighted(r) {
                    moved += area * (r.unweighted_factor() - r.factor());
                } else {
                    rest += area * r.factor();
                }
            }
        }
        (moved, rest)
    });
    let (moved, rest) = sums.iter().fold((0.0, 0.0), |(m, r), s| (m + s.0, r + s.1));
    if rest <= 0.0 || moved == 0.0 {
        return;
    }
    // Bounded: a shooter seen almost only by its weighted neighbours has little to pass on.
    let scale = ((rest + moved) / rest).clamp(0.5, 2.0);
    for_each_block_mut(blocks, patch_elements, factors, false, |patches, out| {
        let first = patch_elements[patches.start].start;
        for q in patches.filter(|&q| plans[q].live) {
            let range = patch_elements[q].start - first..patch_elements[q].end - first;
            for r in out[range].iter_mut().filter(|r| !weighted(r)) {
                r.unoccluded *= scale;
                r.unweighted *= scale;
            }
        }
    });
}

/// First pass, patch by patch: each receiving patch writes its own elements' slice of
/// `factors` (their form factors without visibility, from `kept` when given, and their
/// pilot rays), the mesh's blocks of patches in parallel.
fn first_pass(
    shot: &Shot,
    plans: &[PatchPlan],
    blocks: &[Range<usize>],
    kept: Option<&[f32]>,
    factors: &mut [Received],
) {
    let patch_elements = shot.patch_elements;
    for_each_block_mut(blocks, patch_elements, factors, true, |patches, mut out| {
        for q in patches {
            let (own, rest) = std::mem::take(&mut out).split_at_mut(patch_elements[q].len());
            receive_patch(shot, &plans[q], q, patch_elements[q].start, kept, own);
            out = rest;
        }
    });
}

/// Penumbrae: more rays where the neighbours' pilot rays disagree (see
/// [`wants_penumbra_rays`]), added to `factors`; `flags` is scratch, one per element.
fn penumbra_pass(
    shot: &Shot,
    plans: &[PatchPlan],
    tables: &MeshTables,
    flags: &mut [bool],
    factors: &mut [Received],
) {
    let first: &[Received] = factors;
    for_each_maybe_parallel(flags, |e, out| {
        *out = wants_penumbra_rays(first, e, tables.neighbours_of(e));
    });
    let flags: &[bool] = flags;
    for_each_maybe_parallel(factors, |e, out| {
        // A sharing group's members take its visibility, not rays of their own.
        if flags[e] && !shot.sharing.shares(e) {
            let plan = &plans[tables.element_patch[e] as usize];
            *out += trace(shot, plan, e, Rays::Penumbra);
        }
    });
}

/// The facets of groups that share their visibility (see [`super::shared`]), received group
/// by group: each member's unoccluded form factor (its vertex mean, one point: the group is
/// far), four members at a time where they strictly face the shooter, clipped one by one
/// where they straddle each other's planes, none behind the shooter; then the group's rays,
/// and every member's visibility theirs. Returns the rays traced.
fn receive_shared(shot: &Shot, plans: &[PatchPlan], element_area: &[f64], factors: &mut [Received]) -> u64 {
    if !shot.sharing.any() {
        return 0;
    }
    let Shot { mesh, shooter, clusters, sharing, .. } = *shot;
    let corners = shooter.corners();
    let factors_of = |g: usize, range: std::ops::Range<usize>| -> Vec<f64> {
        let receivers = &clusters.group(g).receivers[range];
        let mut out = vec![0.0; receivers.len()];
        // Strictly facing members, batched four at a time.
        let (mut batch, mut n) = ([0usize; 4], 0);
        let flush = |batch: &[usize; 4], n: usize, out: &mut [f64]| {
            let (mut points, mut normals) = ([glam::DVec3::ZERO; 4], [glam::DVec3::ZERO; 4]);
            for k in 0..n {
                (points[k], normals[k]) = receivers[batch[k]];
            }
            let f = points_to_polygon_in_front_x4(&points, &normals, n, corners);
            for k in 0..n {
                out[batch[k]] = f[k].max(0.0);
            }
        };
        let tolerance = 1e-9 * shooter.area.sqrt();
        for (k, &(p, normal)) in receivers.iter().enumerate() {
            let ahead = shooter.normal.dot(p - corners[0]);
            if ahead <= 0.0 {
                continue;
            }
            // The shooter's corners' heights over the member's plane: all at or below it,
            // the member sees none of the shooter (half of a curved model's facets; the
            // clipping below found so too, and took a fifth of the sharing groups' time).
            let heights = corners.iter().map(|c| normal.dot(*c - p));
            let (facing, highest) =
                heights.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), h| (lo.min(h), hi.max(h)));
            if highest <= 0.0 {
                continue;
            }
            if facing > tolerance && ahead > tolerance {
                batch[n] = k;
                n += 1;
                if n == 4 {
                    flush(&batch, n, &mut out);
                    n = 0;
                }
            } else {
                out[k] = point_to_polygon(p, normal, corners);
            }
        }
        if n > 0 {
            flush(&batch, n, &mut out);
        }
        out
    };
    let plan_of = |e: usize| &plans[mesh.elements[e].patch as usize];
    let (received, rays) =
        sharing.receive(clusters, element_area, (shot.params.seed, shot.stream), factors_of, |e| {
            let seen = trace(shot, plan_of(e), e, Rays::Pilot);
            (seen.visible, seen.traced)
        });
    for_each_maybe_parallel(factors, |e, r| {
        if let Some((u, k)) = sharing.member(clusters, e) {
            let f = received[u].factors[k];
            (r.unoccluded, r.unweighted) = (f, f);
            (r.visible, r.traced) = if f > 0.0 { received[u].seen } else { (0, 0) };
        }
    });
    rays
}

/// Whether element `e`, of a patch that touches the shooter, is weighted at each shot (see
/// [`near_field`]); else it takes the spread fixed with the row, as receivers near the
/// shooter do (`receive`).
pub(super) fn in_near_field(shot: &Shot, e: usize) -> bool {
    let reach = NEAR_REACH * shot.shooter_radius;
    !shot.clusters.members()[shot.mesh.elements[e].patch as usize]
        && shot.mesh.elements[e].centre.distance_squared(shot.shooter.centre) <= reach * reach
}

/// The near field of a patch's row: every receiving element of a patch that touches the
/// shooter, within [`NEAR_REACH`], with its shares of the shooter's parts (see
/// [`NearField`]). Not a model's facets that shoot in groups: a curved model near a shooter
/// has tens of thousands of facets whose planes cut it (a bunny on a floor patch: 71 k): a
/// 139 k-triangle room solved in 26.4 s with them, 24.3 s without, 23.5 s before any near
/// field.
///
/// The shares are geometry: a receiver that was in `previous`, the shooter's near field
/// before its spread was fixed again, takes its terms from there (all of them at once when
/// the receivers are the same).
fn near_field(
    shot: &Shot,
    plans: &[PatchPlan],
    tables: &MeshTables,
    row: &Row,
    mut previous: Option<NearField>,
) -> NearField {
    let mut near = NearField::default();
    let elements = shot.shooter_elements;
    let first_shooter = shot.shooter.elements.start;
    // The receivers (element, factor), and the rest's Σ A F.
    let mut receivers: Vec<(usize, f32)> = Vec::new();
    let mut offset = 0;
    let mut total = 0.0;
    for &(first, count) in &row.spans {
        for k in 0..count as usize {
            let e = first as usize + k;
            let f = row.factors[offset + k];
            let area = tables.element_area[e];
            let patch = tables.element_patch[e] as usize;
            if shot.clusters.members()[patch] {
                continue;
            }
            if f > 0.0 && plans[patch].touching && in_near_field(shot, e) {
                receivers.push((e, f));
            } else {
                total += area * f64::from(f);
            }
        }
        offset += count as usize;
    }
    near.rest = total;
    if receivers.is_empty() {
        return near;
    }
    let (mut order, mut clusters) = (Vec::new(), Vec::new());
    cluster_elements(elements, &vec![1.0; elements.len()], &mut order, &mut clusters);
    for c in &clusters {
        let start = near.members.len() as u32;
        near.members.extend(order[c.members.clone()].iter().map(|&i| first_shooter + i));
        near.clusters.push((start, near.members.len() as u32));
    }
    // Each receiver's shares, written straight after the terms before them: at most one
    // share per shooter element, gathered in `scratch` and cut to those kept.
    let ns = shot.shooter.normal;
    let shares_of = |e: usize, scratch: &mut Vec<(u32, f64)>, out: &mut Vec<(u32, f32)>| {
        let (p, n) = (shot.mesh.elements[e].centre, shot.mesh.elements[e].normal);
        scratch.clear();
        for (c, cluster) in clusters.iter().enumerate() {
            if cluster.centre.distance_squared(p) >= 16.0 * cluster.radius * cluster.radius {
                let phi = point_to_point(p, n, cluster.centre, ns, cluster.area);
                scratch.push((c as u32 | CLUSTER_TERM, phi.max(0.0)));
            } else {
                scratch.extend(
                    order[cluster.members.clone()]
                        .iter()
                        .map(|&i| (first_shooter + i, elements[i as usize].factor_from(p, n, ns).max(0.0))),
                );
            }
        }
        let sum: f64 = scratch.iter().map(|s| s.1).sum();
        if sum > 0.0 {
            let kept = scratch.iter().filter(|s| s.1 >= MIN_SHARE * sum);
            out.extend(kept.map(|&(part, phi)| (part, (phi / sum) as f32)));
        }
    };
    let same = |p: &mut NearField| {
        p.receivers.len() == receivers.len()
            && p.receivers.iter().zip(&receivers).all(|(a, b)| a.0 as usize == b.0)
    };
    if let Some(old) = previous.take_if(same) {
        // The same receivers, each with terms: they are the previous ones, in order.
        near.receivers =
            old.receivers.iter().zip(&receivers).map(|(&(e, _, s, n), &(_, f))| (e, f, s, n)).collect();
        near.terms = old.terms;
        return near;
    }
    let previous = previous.as_ref();
    // A receiver that was in `previous` (receivers in element order, as there: a cursor
    // finds each) takes its terms from there.
    let mut before = previous.map_or(&[][..], |p| &p.receivers[..]);
    let mut from_previous = |e: usize| -> Option<&[(u32, f32)]> {
        let p = previous?;
        before = &before[before.partition_point(|r| (r.0 as usize) < e)..];
        let &(_, _, start, count) = before.first().filter(|r| r.0 as usize == e)?;
        Some(&p.terms[start as usize..(start + count) as usize])
    };
    let reused: Vec<Option<&[(u32, f32)]>> = receivers.iter().map(|&(e, _)| from_previous(e)).collect();
    // The others' terms, in runs of receivers computed in parallel (they are a row's
    // costliest part on a small scene), each run's terms one after another and its
    // receivers' counts, joined in receiver order.
    let fresh_run = |run: &[(usize, f32)], reused: &[Option<&[(u32, f32)]>]| {
        let (mut scratch, mut terms, mut counts) = (Vec::new(), Vec::new(), Vec::with_capacity(run.len()));
        for (&(e, _), old) in run.iter().zip(reused) {
            let before = terms.len();
            if old.is_none() {
                shares_of(e, &mut scratch, &mut terms);
            }
            counts.push((terms.len() - before) as u32);
        }
        (terms, counts)
    };
    let runs: Vec<(Terms, Vec<u32>)> = if receivers.len() < 2 * NEAR_RUN || rayon::current_num_threads() == 1
    {
        vec![fresh_run(&receivers, &reused)]
    } else {
        receivers
            .par_chunks(NEAR_RUN)
            .zip(reused.par_chunks(NEAR_RUN))
            .map(|(r, o)| fresh_run(r, o))
            .collect()
    };
    let mut next = runs.iter().flat_map(|(terms, counts)| {
        let mut at = 0;
        counts.iter().map(move |&n| {
            at += n as usize;
            &terms[at - n as usize..at]
        })
    });
    for (&(e, f), old) in receivers.iter().zip(&reused) {
        let computed = next.next().unwrap_or_default();
        let terms = old.unwrap_or(computed);
        if terms.is_empty() {
            // Sees none of the shooter from its centre: it takes the mean with the rest.
            near.rest += tables.element_area[e] * f64::from(f);
            continue;
        }
        let start = near.terms.len() as u32;
        near.terms.extend_from_slice(terms);
        near.receivers.push((e as u32, f, start, near.terms.len() as u32 - start));
    }
    near
}

/// The row of the live patches' factors (those that receive anything), and the rays traced
/// for them (none counted for patches whose group `shares` its rays).
fn gather(
    tables: &MeshTables,
    plans: &[PatchPlan],
    factors: &[Received],
    shares: impl Fn(usize) -> bool + Sync,
) -> (Row, u64) {
    Row::by_blocks(tables, |q, row| {
        if !plans[q].live {
            return 0;
        }
        let range = tables.patch_elements[q].clone();
        let factors = &factors[range.clone()];
        let rays = if shares(q) { 0 } else { factors.iter().map(|r| u64::from(r.traced)).sum() };
        // A patch that receives nothing (facing, but every ray blocked: the inside of a
        // model, a face in shadow) is left out: applying zeros changes no sum, and a model's
        // rows shrink by about half.
        let f32s = factors.iter().map(|r| r.factor() as f32);
        if f32s.clone().any(|f| f != 0.0) {
            row.push(range, f32s);
        }
        rays
    })
}

/// Pilot rays from a bright shooter to a facet of a shooter group: a quarter of
/// `visibility_rays`, at least `dim_rays`. On a 120 k-triangle room the facets took 84 % of
/// the rays at the full count.
pub(super) fn facet_rays(params: &super::SolverParams) -> u32 {
    (params.visibility_rays / 4).max(params.dim_rays)
}
