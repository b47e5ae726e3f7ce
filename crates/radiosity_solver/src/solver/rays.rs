//! Visibility rays between a receiving element and the shooter: how they are drawn (seeded
//! streams keyed by shooter and element, stratified, ends from the shooter's ray-end table)
//! and how they are answered (the patch's candidate list four at a time, or the ray
//! structure one by one).

use glam::{DVec3, Vec3};
use radiosity_accel::Segments4;

use super::plans::PatchPlan;
use super::ray_ends::target_cell;
use super::receive::{corners_of, element_facing};
use super::shot::Shot;
use crate::sampling::{Rng, Strata, four_units, point_on, point_on_f32};
use crate::shaft::{FEW, Visibility, bounds};

/// Key bit of an element's penumbra-ray stream, apart from its pilot-ray stream.
const PENUMBRA_STREAM: u64 = 1 << 63;

/// Key of a row's one-ray hashes, apart from every element's streams.
pub(super) const SINGLE_STREAM: u64 = (1 << 63) - 1;

/// Random redraws of a ray whose ends do not face each other, before it is given up.
const REDRAWS: u32 = 16;

/// Which of an element's rays to a shooter.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Rays {
    /// Its first rays: `shot.pilot`'s strata.
    Pilot,
    /// Its penumbra rays: `shot.penumbra`'s strata.
    Penumbra,
}

/// Up to four segments to test together; lane `i` belongs to `owner[i]`.
#[derive(Default)]
pub(super) struct Packet {
    pub(super) from: [Vec3; 4],
    pub(super) to: [Vec3; 4],
    pub(super) owner: [u32; 4],
    pub(super) n: usize,
}

impl Packet {
    /// Adds the segment `from → to` of `owner` (the caller tests a full packet first).
    pub(super) fn push(&mut self, from: Vec3, to: Vec3, owner: u32) {
        (self.from[self.n], self.to[self.n], self.owner[self.n]) = (from, to, owner);
        self.n += 1;
    }
}

/// Draws element `e`'s `rays` to the shooter and hands each segment to `ray` (see
/// [`draw_rays`]). Every path draws an element's rays here, so the fast and the reference
/// paths trace the same rays. Each set has its own stream keyed by the shooter and the
/// element; a lone first ray (from a dim shooter) takes its four coordinates from one hash.
pub(super) fn draw(shot: &Shot, plan: &PatchPlan, e: usize, rays: Rays, ray: impl FnMut(Vec3, Vec3)) {
    let (seed, key) = (shot.params.seed, e as u64);
    match rays {
        Rays::Pilot if shot.pilot_for(e).count() == 1 => {
            let [u, v, a, b] = four_units(shot.single_key, key);
            let mut redraws = Rng::from_state(shot.single_key ^ key);
            draw_rays_from(shot, plan, e, 1, &mut redraws, ray, |_| ((u, v), (a, b)));
        }
        Rays::Pilot => {
            draw_rays(shot, plan, e, shot.pilot_for(e), &mut Rng::for_task(seed, shot.stream, key), ray)
        }
        Rays::Penumbra => {
            let mut rng = Rng::for_task(seed, shot.stream, key | PENUMBRA_STREAM);
            draw_rays(shot, plan, e, shot.penumbra, &mut rng, ray);
        }
    }
}

/// Element `e`'s `rays` to the shooter, traced: (unblocked, traced).
pub(super) fn trace(shot: &Shot, plan: &PatchPlan, e: usize, rays: Rays) -> (u32, u32) {
    let Shot { mesh, shooter, accel, boxes, blockers, offset, .. } = *shot;
    // Every segment between the element and the shooter lies in the box around both; when no
    // blocking triangle comes near that box the pair is fully visible and needs no ray.
    if plan.visibility == Visibility::Clear {
        return (0, 0);
    }
    let few = plan.visibility == Visibility::Few;
    // The patch's candidate triangles, copied so that each packet can move the one that
    // blocked to the front for the next. Narrowing them per element (box and planes) was
    // tried: it dropped few candidates and saved rays for few elements, for more time than
    // it saved.
    let mut order = [0u32; FEW];
    let candidates = &mut order[..if few { plan.candidates.len() } else { 0 }];
    if few {
        candidates.copy_from_slice(&plan.candidates);
    } else {
        let pts = corners_of(mesh, e);
        let (lo, hi) = bounds(pts[..mesh.elements[e].vertex_count as usize].iter().chain(shooter.corners()));
        if !boxes.may_block(lo, hi, 2.0 * offset) {
            return (0, 0);
        }
    }
    // Unblocked segments of a packet: four at once against the candidate list, one by one
    // through the ray structure.
    let mut unblocked = |packet: &Packet| -> u32 {
        if few {
            let blocked =
                blockers.occluded_x4(&Segments4::new(&packet.from, &packet.to, packet.n), candidates);
            packet.n as u32 - blocked.count_ones()
        } else {
            (0..packet.n).filter(|&i| !accel.occluded(packet.from[i], packet.to[i])).count() as u32
        }
    };
    let (mut visible, mut traced) = (0u32, 0u32);
    let mut packet = Packet::default();
    draw(shot, plan, e, rays, |from, to| {
        packet.push(from, to, 0);
        traced += 1;
        if packet.n == 4 {
            visible += unblocked(&packet);
            packet.n = 0;
        }
    });
    if packet.n > 0 {
        visible += unblocked(&packet);
    }
    // None traced: the parts of each that face the other are too small to hit; the caller
    // then takes the pair as unblocked.
    (visible, traced)
}

/// Draws element `e`'s rays to the shooter, one per stratum of `strata` (fresh, at its first
/// stratum), and hands each segment (ends lifted off both surfaces, single precision) to
/// `ray`.
fn draw_rays(
    shot: &Shot,
    plan: &PatchPlan,
    e: usize,
    mut strata: Strata,
    rng: &mut Rng,
    ray: impl FnMut(Vec3, Vec3),
) {
    let count = strata.count();
    draw_rays_from(shot, plan, e, count, rng, ray, |rng| {
        // The same stratum on both ends, each jittered on its own.
        let stratum = strata.next();
        (strata.jitter(stratum, rng), strata.jitter(stratum, rng))
    });
}

/// [`draw_rays`] for `count` rays whose `(u, v)` on the element and `(a, b)` on the shooter
/// come from `sample`; `rng` draws the redraws.
fn draw_rays_from(
    shot: &Shot,
    plan: &PatchPlan,
    e: usize,
    count: u32,
    rng: &mut Rng,
    mut ray: impl FnMut(Vec3, Vec3),
    mut sample: impl FnMut(&mut Rng) -> ((f32, f32), (f32, f32)),
) {
    let Shot { mesh, shooter, targets, lifted_targets, offset, .. } = *shot;
    let el = &mesh.elements[e];
    let corners = shot.lifted_corners[e];
    let lifted = &corners[..el.vertex_count as usize];
    if plan.facing {
        // Nothing to clip (the usual case): origins straight from the lifted corners.
        for _ in 0..count {
            let ((u, v), (a, b)) = sample(rng);
            ray(point_on_f32(lifted, u, v).into(), lifted_targets[target_cell(a, b)]);
        }
        return;
    }
    let pts = corners_of(mesh, e);
    let receiver = &pts[..el.vertex_count as usize];
    // The form factor counts only the part of the shooter in front of the receiver point
    // (and receiver points in front of the shooter), so the visibility must be the fraction
    // of *that* part that is unblocked. A ray to a shooter point behind the receiver's plane
    // would pass through the receiver's own object and count as blocked: the light of a
    // lamp half behind a block's side, say, would be cut twice (the block sides of the
    // Cornell box lost up to 60 % of their direct light that way). Such pairs are redrawn.
    let clipped = !element_facing(shooter, plan, receiver);
    let ahead =
        |from: DVec3, to: DVec3| el.normal.dot(to - from) > 0.0 && shooter.normal.dot(from - to) > 0.0;
    let lift = el.normal * offset;
    for _ in 0..count {
        let ((u, v), (a, b)) = sample(rng);
        let mut cell = target_cell(a, b);
        let from = if clipped {
            let mut from = point_on(receiver, f64::from(u), f64::from(v));
            let mut tries = 0;
            while !ahead(from, targets[cell]) && tries < REDRAWS {
                from = point_on(receiver, rng.next_f64(), rng.next_f64());
                let (a, b) = rng.next_f32_pair();
                cell = target_cell(a, b);
                tries += 1;
            }
            if !ahead(from, targets[cell]) {
                continue;
            }
            (from + lift).as_vec3()
        } else {
            point_on_f32(lifted, u, v).into()
        };
        ray(from, lifted_targets[cell]);
    }
}
