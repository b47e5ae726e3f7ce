//! The near field of a patch's row: the receivers that touch the shooter, and their shares
//! of the shooter's parts (see [`NearField`]), weighed at each shot by the unshot radiosity
//! the shooter has then (`Tally::shoot`).

use rayon::prelude::*;

use super::mesh_tables::MeshTables;
use super::plans::PatchPlan;
use super::row::{CLUSTER_TERM, NearField, Row};
use super::shot::Shot;
use super::uneven::cluster_elements;
use crate::form_factor::point_to_point;

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
pub(super) fn near_field(
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
