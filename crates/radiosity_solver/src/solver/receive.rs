//! The receivers' side of a row's first pass: each element's form factor to the shooter
//! without visibility (Lambert's exact point-to-polygon formula integrated over the element,
//! see [`crate::form_factor`]), then its pilot rays.

use glam::DVec3;
use radiosity_accel::Segments4;

use super::FormFactorMethod;
use super::elements::{corners_of, element_facing};
use super::near_field::in_near_field;
use super::plans::PatchPlan;
use super::quadrature::element_quadrature;
use super::rays::{Packet, Rays, draw, near, patch_near, trace};
use super::received::{Received, Seen};
use super::shot::Shot;
use super::uneven::density_weight;
use crate::form_factor::{
    Rule, for_each_point, point_to_point, point_to_polygon, point_to_polygon_in_front,
    point_to_polygon_in_front_x4, point_to_polygon_x4, points_to_polygon_in_front_x4,
};
use crate::shaft::{FEW, Visibility};

/// Element `e`'s form factor to the shooter without visibility, before any weighting: what
/// geometry alone gives, rounded to single precision so that a row computed from the kept
/// factors (see [`super::row::Geometry`]) is the row computed afresh.
fn unweighted(shot: &Shot, plan: &PatchPlan, e: usize) -> f64 {
    let Shot { mesh, shooter, params, .. } = *shot;
    let el = &mesh.elements[e];
    let f = match params.form_factor {
        FormFactorMethod::Exact => {
            let pts = corners_of(mesh, e);
            let receiver = &pts[..el.vertex_count as usize];
            let corners = shooter.corners();
            let facing = element_facing(shooter, plan, receiver);
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
                // The receiver crosses the shooter's plane or the shooter its: points behind
                // the shooter see none of it, and the shooter is clipped to the hemisphere
                // of each point it is partly behind (in f64). A point that sees it whole
                // takes the fast path's lanes: they keep their precision beside the shooter
                // (`simd_kernel_holds_beside_the_shooter`).
                let eval = if fast { point_to_polygon_x4 } else { point_to_polygon };
                for_each_point(receiver, n, rule, |p, w| {
                    if shooter.normal.dot(p - corners[0]) > 0.0 {
                        f += w * eval(p, el.normal, corners);
                    }
                });
            }
            f
        }
        FormFactorMethod::PointToPoint => {
            point_to_point(el.centre, el.normal, shooter.centre, shooter.normal, shooter.area)
        }
    };
    round(f)
}

/// `f` in single precision, at least 0.
fn round(f: f64) -> f64 {
    f64::from(f.max(0.0) as f32)
}

/// The first pass for the elements of receiving patch `q` (`first` is its first element,
/// `out` its slice): their unoccluded form factors (taken from `kept`, one per mesh element,
/// when the shooter's geometry was kept), then their pilot rays (nothing when its group
/// shares its visibility: the group is received whole, see `patch_row::receive_shared`).
#[inline]
pub(super) fn receive_patch(
    shot: &Shot,
    plan: &PatchPlan,
    q: usize,
    first: usize,
    kept: Option<&[f32]>,
    out: &mut [Received],
) {
    out.fill(Received::default());
    if !plan.live || shot.shares(q) {
        return;
    }
    match kept {
        Some(kept) => {
            for (r, &f) in out.iter_mut().zip(&kept[first..]) {
                (r.unoccluded, r.unweighted) = (f64::from(f), f64::from(f));
            }
        }
        None => unoccluded_factors(shot, plan, first, out),
    }
    weigh(shot, plan, q, first, out);
    if plan.visibility == Visibility::Clear {
        return;
    }
    if shot.pilot_for(first).count() == 1 && plan.visibility == Visibility::Few {
        single_rays_in_packets(shot, plan, first, out);
        return;
    }
    for (k, r) in out.iter_mut().enumerate() {
        if r.unoccluded > 0.0 {
            *r += trace(shot, plan, first + k, Rays::Pilot);
        }
    }
}

/// The unoccluded form factors of one receiving patch's elements, before any weighting. A
/// patch that faces the shooter from far away takes them four at a time (one midpoint each,
/// nothing to clip: the same formula and points as [`unweighted`]).
fn unoccluded_factors(shot: &Shot, plan: &PatchPlan, first: usize, out: &mut [Received]) {
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
                r.unoccluded = round(f);
                r.unweighted = r.unoccluded;
            }
        }
    } else {
        for (k, r) in out.iter_mut().enumerate() {
            r.unweighted = unweighted(shot, plan, first + k);
            r.unoccluded = r.unweighted;
        }
    }
}

/// An uneven shooter's weighting of the receivers near it. A receiver near the shooter sees
/// its near part under a larger form factor than the rest (a sofa's back 20 cm from a wall
/// patch lit above the sofa and dark behind it), so the shooter's mean unshot radiosity is
/// wrong for it when that radiosity is uneven: the transfer is Σ_k ΔB_k F_{j→k} = ΔB̄ Σ_k d_k
/// F_{j→k}, d_k = ΔB_k/ΔB̄, weighted here by the spread fixed with the row. The form factor
/// keeps its quadrature; the weighting is taken at the centre. Receivers that touch the
/// shooter are weighted so too when they are a model's grouped facets or far from it, else
/// at each shot, by the spread it has then (`row::NearField`).
fn weigh(shot: &Shot, plan: &PatchPlan, q: usize, first: usize, out: &mut [Received]) {
    let Some(uneven) = shot.uneven else { return };
    // Only a touching patch's elements may be weighted beyond `near` (those outside the
    // near field).
    if !plan.touching && !patch_near(shot, q) {
        return;
    }
    let Shot { mesh, shooter, shooter_elements, .. } = *shot;
    for (k, r) in out.iter_mut().enumerate() {
        let e = first + k;
        let weighted = if plan.touching { !in_near_field(shot, e) } else { near(shot, e) };
        if weighted && r.unweighted > 0.0 {
            let el = &mesh.elements[e];
            let weight = density_weight(el.centre, el.normal, shooter.normal, &uneven, shooter_elements);
            r.unoccluded = (r.unweighted * weight).max(0.0);
        }
    }
}

/// One pilot ray per element against the patch's candidate list: four elements' rays share
/// a packet (the same rays as one packet each, a quarter of the tests).
#[inline]
fn single_rays_in_packets(shot: &Shot, plan: &PatchPlan, first: usize, out: &mut [Received]) {
    let mut order = [0u32; FEW];
    let candidates = &mut order[..plan.candidates.len()];
    candidates.copy_from_slice(&plan.candidates);
    let mut packet = Packet::default();
    let mut weights = [0.0f32; 4];
    let mut test = |packet: &mut Packet, weights: &[f32; 4], out: &mut [Received]| {
        let blocked =
            shot.blockers.occluded_x4(&Segments4::new(&packet.from, &packet.to, packet.n), candidates);
        for (lane, &k) in packet.owner[..packet.n].iter().enumerate() {
            let mut seen = Seen::default();
            seen.add(blocked >> lane & 1 == 0, weights[lane]);
            out[k as usize] += seen;
        }
        packet.n = 0;
    };
    for k in 0..out.len() {
        if out[k].unoccluded <= 0.0 {
            continue;
        }
        draw(shot, plan, first + k, Rays::Pilot, |from, to, weight| {
            weights[packet.n] = weight;
            packet.push(from, to, k as u32);
        });
        if packet.n == 4 {
            test(&mut packet, &weights, out);
        }
    }
    if packet.n > 0 {
        test(&mut packet, &weights, out);
    }
}
