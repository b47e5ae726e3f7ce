//! A group's row: its form factor to every receiving element, far field and near field,
//! and the visibility rays aimed at its points.

use std::sync::atomic::{AtomicU64, Ordering};

use radiosity_accel::RayQuery;

use super::*;
use crate::sampling::{Rng, point_on_f32};
use crate::solver::SolverParams;
use crate::solver::mesh_tables::MeshTables;
use crate::solver::parallel::{for_each_maybe_parallel, for_each_run_maybe_parallel};
use crate::solver::row::Row;
use crate::solver::shot::{ShotScratch, facet_rays};

impl Clusters {
    /// Group `g`'s row (it must be frozen): every element's form factor to it, visibility
    /// included, for the patches that receive any; and the rays traced. Receiving groups
    /// far from a dim group share their visibility (`sharing`, see `solver::shared`).
    pub(in crate::solver) fn row(
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
            rays: if frozen.bright { facet_rays(params) } else { params.dim_rays },
            seed: params.seed,
            stream,
        };
        factors.clear();
        factors.resize(mesh.elements.len(), 0.0);
        // Rays traced, for the progress figures (an integer sum: the same in any order).
        let traced = AtomicU64::new(0);
        // Elements in no sharing group, with their own rays; the sharing groups' below. The
        // near points' shares are scratch for a run of elements, not zeroed for each.
        for_each_run_maybe_parallel(factors, |first, run| {
            let mut scratch = [0.0; POINTS];
            for (k, out) in run.iter_mut().enumerate() {
                let e = first + k;
                if sharing.shares(e) {
                    continue;
                }
                let el = &mesh.elements[e];
                let (f, shares) =
                    unoccluded(group, frozen, tables.vertex_means[e], el.normal, el.patch, &mut scratch);
                *out = f as f32;
                if f > 0.0 {
                    let (visible, n) = aim.trace(e, f, shares);
                    *out = if n == 0 { f as f32 } else { (f * f64::from(visible) / f64::from(n)) as f32 };
                    traced.fetch_add(u64::from(n), Ordering::Relaxed);
                }
            }
        });
        let mut traced = traced.into_inner();
        if sharing.any() {
            // A member's own unoccluded factor and its rays: what a unit's chosen members
            // trace for it, and every member of a unit whose rays disagree.
            let own_rays = |e: usize| {
                let el = &mesh.elements[e];
                let mut scratch = [0.0; POINTS];
                let p = tables.vertex_means[e];
                let (f, shares) = unoccluded(group, frozen, p, el.normal, el.patch, &mut scratch);
                let (visible, n) = aim.trace(e, f, shares);
                (f, visible, n)
            };
            let (received, rays) = sharing.receive(
                self,
                &tables.element_area,
                (params.seed, stream),
                // Another group's members: none is a patch of the shooting group.
                |r, range| {
                    let receivers = &self.groups[r].receivers[range];
                    let mut scratch = [0.0; POINTS];
                    receivers
                        .iter()
                        .map(|&(p, n)| unoccluded(group, frozen, p, n, NONE, &mut scratch).0)
                        .collect()
                },
                |e| {
                    let (_, visible, n) = own_rays(e);
                    (visible, n)
                },
            );
            traced += rays;
            // Members of a unit whose rays disagree trace their own (see `Shared::mixed`).
            let own = AtomicU64::new(0);
            for_each_maybe_parallel(factors, |e, out| {
                if let Some((u, k)) = sharing.member(self, e) {
                    let r = &received[u];
                    *out = if r.mixed() && r.factors[k] > 0.0 {
                        let (f, visible, n) = own_rays(e);
                        own.fetch_add(u64::from(n), Ordering::Relaxed);
                        if n == 0 { f as f32 } else { (f * f64::from(visible) / f64::from(n)) as f32 }
                    } else {
                        (r.factors[k] * r.visibility()) as f32
                    };
                }
            });
            traced += own.into_inner();
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
    /// `f`, with its points' `shares` of it when near: (unblocked, traced), from the
    /// element's own stream.
    ///
    /// Rays end at points that give the receiver light: a ray to a point on a facet turned
    /// away would cross the model and count as blocked (the model then came out 2 % dark).
    /// Near the group, points by their share of the form factor, stratified; far, points by
    /// the cosine at them (rejection).
    fn trace(&self, e: usize, f: f64, shares: Option<&[f64; POINTS]>) -> (u32, u32) {
        let Self { frozen, mesh, tables, accel, rays, seed, stream } = *self;
        let el = &mesh.elements[e];
        let p = tables.vertex_means[e];
        let corners = &tables.lifted_corners[e][..el.vertex_count as usize];
        let mut rng = Rng::for_task(seed, stream, e as u64);
        let (mut visible, mut traced) = (0u32, 0u32);
        let (mut walked, mut at) = (0.0, 0);
        let mut far_cdf = None;
        for j in 0..rays {
            let target = if let Some(shares) = shares {
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
                // Few of the group's points face the receiver (a cap of a sphere seen from
                // its side): the same draw from the points' weights, which rejection only
                // spares computing. Counting such a receiver unblocked lit the backs of
                // Sponza's walls through the building from its sun sphere.
                found.or_else(|| {
                    let cdf = far_cdf.get_or_insert_with(|| far_weights(&frozen.near, p, el.normal));
                    draw(cdf, rng.next_f64())
                })
            };
            let Some(i) = target else {
                // No point of the group both faces the receiver and is faced by it: no
                // light reaches it that way, a blocked ray.
                traced += 1;
                continue;
            };
            let (u, v) = (rng.next_f64() as f32, rng.next_f64() as f32);
            let from = Vec3::from(point_on_f32(corners, u, v));
            visible += u32::from(!accel.occluded(from, frozen.lifted[i]));
            traced += 1;
        }
        (visible, traced)
    }
}

/// The cumulative weights of a group's points for a far receiver at `p` with normal `n`:
/// cos θ at the point where the point and the receiver face each other, else 0 (the
/// distribution [`Aim::trace`] draws far ray ends from by rejection). In single precision
/// about the group's centre, as [`near_factor`]: in double precision, one division and one
/// square root per point after another, it was half of the group rows' own time in the
/// furnished room.
fn far_weights(pts: &NearPoints, p: DVec3, n: DVec3) -> [f64; POINTS] {
    let d0 = (p - pts.origin).as_vec3();
    let n = n.as_vec3();
    let mut weights = [0.0f32; POINTS];
    for (i, w) in weights.iter_mut().enumerate() {
        // From the point to the receiver.
        let d = [d0.x - pts.x[0][i], d0.y - pts.x[1][i], d0.z - pts.x[2][i]];
        let out = pts.n[0][i] * d[0] + pts.n[1][i] * d[1] + pts.n[2][i] * d[2];
        let faced = n.x * d[0] + n.y * d[1] + n.z * d[2] < 0.0;
        let r = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        // A group of fewer than `POINTS` points pads the rest with zero normals: weight 0.
        *w = if faced && out > 0.0 { out / r } else { 0.0 };
    }
    let mut cdf = [0.0; POINTS];
    let mut sum = 0.0;
    for (c, w) in cdf.iter_mut().zip(weights) {
        sum += f64::from(w);
        *c = sum;
    }
    cdf
}

/// The point drawn from cumulative weights `cdf` by `u` in [0, 1), or `None` when they are
/// all 0.
fn draw(cdf: &[f64; POINTS], u: f64) -> Option<usize> {
    let total = cdf[POINTS - 1];
    if total.is_nan() || total <= 0.0 {
        return None;
    }
    let t = u * total;
    Some(cdf.partition_point(|&c| c <= t).min(POINTS - 1))
}

/// The form factor from a receiver at `p` (normal `n`, on patch `patch`) to the group,
/// without visibility, such that the receiver's irradiance is the group's mean unshot
/// radiosity ΔΦ/A times it, and when the receiver is near, each point's part of it (written
/// into `scratch`, which far receivers leave alone: zeroed for every receiver of a row, its
/// 256 entries were 4 % of a furnished room's solve). A member receives from the group's other facets (a fold of the model), not from its
/// own.
pub(super) fn unoccluded<'a>(
    group: &Group,
    frozen: &Frozen,
    p: DVec3,
    n: DVec3,
    patch: u32,
    scratch: &'a mut [f64; POINTS],
) -> (f64, Option<&'a [f64; POINTS]>) {
    match far_factor(group, frozen, p, n) {
        Some(f) => (f, None),
        None => {
            let f = near_factor(group, frozen, p, n, patch, scratch);
            (f, Some(scratch))
        }
    }
}

/// The form factor from a receiver at `p` (normal `n`) to the group when the group is all
/// behind the receiver (0) or far from it (its far field); `None` when its points decide.
fn far_factor(group: &Group, frozen: &Frozen, p: DVec3, n: DVec3) -> Option<f64> {
    let to_centre = group.centre - p;
    // All of the group behind the receiver's plane.
    if n.dot(to_centre) <= -group.radius {
        return Some(0.0);
    }
    let r2 = to_centre.length_squared();
    // An emitting group takes its points at any distance: its shot is the direct light, and
    // the far field's one normal per bin, clamped once, misplaces it. On Sponza's sun sphere
    // (12 groups, direct light against the path tracer) the far field put the roof +6.6 %,
    // the parapet +8.0 %, the walls −4.1 %, a gallery floor −11.6 %; the points: −1.5 %,
    // 0.0 %, −0.3 %, −1.7 %, for 0.3 s more over 240 k elements.
    if !group.emits && r2 > (FAR * group.radius).powi(2) {
        let r = r2.sqrt();
        let d = -to_centre / r; // from the group towards the receiver
        let cos_r = -n.dot(d);
        if cos_r <= 0.0 {
            return Some(0.0);
        }
        let out = frozen.lobe(d);
        return Some(group.area * out * cos_r / (std::f64::consts::PI * r2));
    }
    None
}

/// The form factor from a receiver at `p` (normal `n`, on patch `patch`) to the group by its
/// points, each point's part of it in `shares`.
fn near_factor(
    group: &Group,
    frozen: &Frozen,
    p: DVec3,
    n: DVec3,
    patch: u32,
    shares: &mut [f64; POINTS],
) -> f64 {
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
    (sums[0] + sums[1]) + (sums[2] + sums[3])
}
