//! A patch shooter's row, computed: plan the receiving patches, fix the shooter's first-shot
//! spread, lay out its ray ends, then two passes over the receivers (form factors and pilot
//! rays; penumbra rays where the neighbours saw a penumbra), the receiving groups that share
//! their visibility, and gather the factors into a [`Row`] with its near field.

use std::ops::Range;
use std::sync::Arc;

use super::Solver;
use super::mesh_tables::MeshTables;
use super::near_field::near_field;
use super::parallel::{for_each_block_mut, for_each_maybe_parallel, map_blocks};
use super::penumbra::{heavy, wants_penumbra_rays};
use super::plans::{PatchPlan, plan_patches};
use super::ray_ends::draw_ray_ends;
use super::rays::{Rays, SINGLE_STREAM, trace};
use super::receive::receive_patch;
use super::received::Received;
use super::row::{Geometry, Row};
use super::shot::{Shot, facet_rays};
use super::uneven::{Uneven, cluster_elements};
use crate::form_factor::{point_to_polygon, points_to_polygon_in_front_x4};
use crate::sampling::{Rng, Strata};

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
/// [`wants_penumbra_rays`]) or where the receiver takes a large share of the shot (see
/// [`heavy`]), added to `factors`; `flags` is scratch, one per element.
fn penumbra_pass(
    shot: &Shot,
    plans: &[PatchPlan],
    tables: &MeshTables,
    flags: &mut [bool],
    factors: &mut [Received],
) {
    let first: &[Received] = factors;
    let shooter_area = shot.shooter.area;
    for_each_maybe_parallel(flags, |e, out| {
        *out = wants_penumbra_rays(first, e, tables.neighbours_of(e))
            || heavy(first, e, tables.element_area[e], shooter_area);
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
    // Members of a unit whose rays disagree trace their own.
    let own = std::sync::atomic::AtomicU64::new(0);
    for_each_maybe_parallel(factors, |e, r| {
        if let Some((u, k)) = sharing.member(clusters, e) {
            let f = received[u].factors[k];
            (r.unoccluded, r.unweighted) = (f, f);
            (r.visible, r.traced) = if f <= 0.0 {
                (0, 0)
            } else if received[u].mixed() {
                let seen = trace(shot, plan_of(e), e, Rays::Pilot);
                own.fetch_add(u64::from(seen.traced), std::sync::atomic::Ordering::Relaxed);
                (seen.visible, seen.traced)
            } else {
                received[u].seen
            };
        }
    });
    rays + own.into_inner()
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
