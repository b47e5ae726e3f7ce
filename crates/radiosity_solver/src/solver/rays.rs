//! Visibility rays between a receiving element and the shooter: how they are drawn (seeded
//! streams keyed by shooter and element, stratified, ends from the shooter's ray-end table)
//! and how they are answered (the patch's candidate list four at a time, or the ray
//! structure one by one).

use glam::{DVec3, Vec3};
use radiosity_accel::Segments4;

use super::elements::{corners_of, element_facing};
use super::mesh_tables::patch_radius;
use super::near_runs::NearEnds;
use super::plans::PatchPlan;
use super::ray_ends::{shooter_point, target_cell};
use super::received::Seen;
use super::shot::Shot;
use crate::form_factor::{distance_to_polygon, point_to_polygon};
use crate::sampling::{ONE_BELOW, Rng, Strata, four_units, point_on, point_on_f32};
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

/// Whether some element of patch `q` may be [`near`] the shooter.
pub(super) fn patch_near(shot: &Shot, q: usize) -> bool {
    let patch = &shot.mesh.patches[q];
    patch.centre.distance(shot.shooter.centre) < NEAR * shot.shooter_radius + patch_radius(patch)
}

/// Receivers whose centres are within this many shooter radii of the shooter's centre draw
/// their ray ends by the form factor (see [`NearEnds`]). Beyond it 1/r² varies by less than
/// a factor 1.8 over the shooter, and visibility seldom varies with it.
const NEAR: f64 = 3.0;

/// Whether element `e` is near the shooter: its centre within [`NEAR`] shooter radii of the
/// shooter's centre.
pub(super) fn near(shot: &Shot, e: usize) -> bool {
    let limit = NEAR * shot.shooter_radius;
    shot.vertex_means[e].distance_squared(shot.shooter.centre) < limit * limit
}

/// A near receiver draws its ray ends by the kernel only when its circumradius is at most
/// this share of its centre's distance to the shooter.
const SMALL: f64 = 0.5;

/// Element `e`'s centre's distance to the shooter's polygon when it is [`near`], which both
/// near-field choices ([`by_solid_angle`], [`near_ends`]) weigh its size against.
fn near_distance(shot: &Shot, e: usize) -> Option<f64> {
    near(shot, e)
        .then(|| distance_to_polygon(shot.vertex_means[e], shot.shooter.normal, shot.shooter.corners()))
}

/// The kernel's table for element `e` (see [`NearEnds`]), or `None` when it is far from the
/// shooter (`distance`, from [`near_distance`], is `None`) or sees none of it.
fn near_ends(shot: &Shot, e: usize, distance: Option<f64>) -> Option<NearEnds> {
    // The kernel is taken at the centre, so it must stand for the whole element: not for
    // an element as large as its distance (a floor element along a wall's foot), whose
    // ends would crowd where its centre is nearest.
    if shot.element_radii[e] > SMALL * distance? {
        return None;
    }
    shot.near_runs.weigh(shot.vertex_means[e], shot.mesh.elements[e].normal, shot.shooter.normal)
}

/// Draws element `e`'s `rays` to the shooter and hands each segment to `ray` with its
/// kernel weight (see [`draw_rays`]). Every path draws an element's rays here, so the fast
/// and the reference paths trace the same rays. Each set has its own stream keyed by the
/// shooter and the element; a lone first ray (from a dim shooter) takes its four
/// coordinates from one hash.
///
/// The weight makes the visibility the share of the *transfer* that is unblocked,
/// Σ_k K_k V_k / Σ_k K_k with K = cos θ cos θ' / r² at the ray's ends (Wallace et al. 1989
/// weigh each shooter sample by its own form factor the same way), not the share of rays.
/// Ends drawn from the shooter's table are spread by the shooter's unshot power alone, and
/// where a shadow's edge crosses the pair the visible and the hidden parts do not weigh the
/// same: a wall below a lamp shade sees the far half of the lamp (small K) past the shade's
/// rim and not its near half (large K), and counted ray by ray its direct light read 1.8 %
/// bright over the whole wall (now 0.04 %); the Cornell floor, partly in the blocks'
/// penumbrae, read 0.42 % dark (now 0.03 %, both with 64 + 1024 rays against a reference
/// at 0.05 %). Ends drawn by the kernel (a near receiver, [`NearEnds`]) already follow it,
/// and some receivers count rays ([`weighs_rays`]).
pub(super) fn draw(
    shot: &Shot,
    plan: &PatchPlan,
    e: usize,
    rays: Rays,
    mut ray: impl FnMut(Vec3, Vec3, f32),
) {
    let (seed, key) = (shot.params.seed, e as u64);
    let distance = near_distance(shot, e);
    if by_solid_angle(shot, e, distance) {
        let (count, mut rng) = match rays {
            Rays::Pilot => (shot.pilot_for(e).count(), Rng::for_task(seed, shot.stream, key)),
            Rays::Penumbra => {
                (shot.penumbra.count(), Rng::for_task(seed, shot.stream, key | PENUMBRA_STREAM))
            }
        };
        draw_by_solid_angle(shot, e, count, &mut rng, |from, to| ray(from, to, 1.0));
        return;
    }
    let near = near_ends(shot, e, distance);
    let ends = Ends { shot, near: near.as_ref() };
    let (n, ns) = (shot.mesh.elements[e].normal.as_vec3(), shot.shooter.normal.as_vec3());
    let weighed = weighs_rays(shot, e);
    let ray = |from: Vec3, to: Vec3| {
        let weight = if weighed { kernel(from, to, n, ns) } else { 1.0 };
        ray(from, to, weight)
    };
    match rays {
        Rays::Pilot if shot.pilot_for(e).count() == 1 => {
            let [u, v, a, b] = four_units(shot.single_key, key);
            let mut redraws = Rng::from_state(shot.single_key ^ key);
            draw_rays_from(plan, e, 1, &mut redraws, ends, ray, |_| ((u, v), (a, b)));
        }
        Rays::Pilot => {
            let mut rng = Rng::for_task(seed, shot.stream, key);
            draw_rays(plan, e, shot.pilot_for(e), &mut rng, ends, ray)
        }
        Rays::Penumbra => {
            let mut rng = Rng::for_task(seed, shot.stream, key | PENUMBRA_STREAM);
            draw_rays(plan, e, shot.penumbra, &mut rng, ends, ray);
        }
    }
}

/// Whether element `e` draws its rays by solid angle from its own points
/// ([`draw_by_solid_angle`]): it is [`near`] an even shooter and large beside its distance
/// to it (`distance`, from [`near_distance`]), where neither the kernel's ends nor its
/// weights can stand for the whole element, and the shooter fills at least
/// [`SOLID_ANGLE_LEAST_FACTOR`] of its centre's view, so that its directions meet the
/// shooter often enough to be drawn by rejection.
fn by_solid_angle(shot: &Shot, e: usize, distance: Option<f64>) -> bool {
    let Some(distance) = distance.filter(|_| shot.uneven.is_none()) else { return false };
    let (centre, corners) = (shot.vertex_means[e], shot.shooter.corners());
    let in_front = shot.shooter.normal.dot(centre - corners[0]) > 0.0;
    shot.element_radii[e] > SMALL * distance
        && in_front
        && point_to_polygon(centre, shot.mesh.elements[e].normal, corners) >= SOLID_ANGLE_LEAST_FACTOR
}

/// The least form factor from an element's centre to the shooter for [`by_solid_angle`]: a
/// direction meets the shooter with about that chance, so a ray finds it within
/// [`SOLID_ANGLE_REDRAWS`] tries but 3 % of the time. Below it a receiver that saw none of
/// the shooter in its tries would be taken as unblocked (as a pair that needs no ray is).
const SOLID_ANGLE_LEAST_FACTOR: f64 = 0.1;

/// Draws `count` rays of element `e` by the projected solid angle: a uniform point of the
/// element, a cosine-distributed direction from it, kept where it meets the
/// shooter's front (redrawn up to [`SOLID_ANGLE_REDRAWS`] times, else given up). The share
/// of such rays that are unblocked is the visibility weighted by the form factor kernel over
/// the whole element, Σ V cos θ cos θ' / r² dA dA' over Σ cos θ cos θ' / r² dA dA' (the
/// cosine-weighted hemisphere is the kernel's own measure: Cohen & Wallace §4.9.2), which the
/// form factor without visibility multiplies.
///
/// For an element as large as its distance to the shooter the kernel varies by orders of
/// magnitude over the pair: ends spread by the shooter's area, counted ray by ray, measure
/// the shooter's *area* that each point sees. A lamp panel through a shallow ceiling fitting
/// lights the fitting's inside from 3 mm away: the points there see the panel's part within
/// the fitting, a seventh of its area and nearly all of their hemisphere, and they received
/// 3 % of their light (the panel's row lost 6 % of its power).
fn draw_by_solid_angle(shot: &Shot, e: usize, count: u32, rng: &mut Rng, mut ray: impl FnMut(Vec3, Vec3)) {
    let Shot { mesh, shooter, offset, .. } = *shot;
    let el = &mesh.elements[e];
    let pts = corners_of(mesh, e);
    let receiver = &pts[..el.vertex_count as usize];
    let corners = shooter.corners();
    let (sn, c0) = (shooter.normal, corners[0]);
    // The winding of the shooter's corners about its normal, for the inside test.
    let winding: f64 = (1..corners.len() - 1)
        .map(|k| sn.dot((corners[k] - c0).cross(corners[k + 1] - c0)))
        .sum::<f64>()
        .signum();
    let inside = |p: DVec3| {
        (0..corners.len()).all(|k| {
            let (a, b) = (corners[k], corners[(k + 1) % corners.len()]);
            winding * sn.dot((b - a).cross(p - a)) >= 0.0
        })
    };
    let (t, b) = el.normal.any_orthonormal_pair();
    for _ in 0..count {
        // Directions drawn afresh, not stratified: a stratum kept until one of its directions
        // met the shooter would weigh alike strata that meet it always and ones that meet
        // it rarely (a lamp shade's inside read 50 % bright so).
        for _ in 0..SOLID_ANGLE_REDRAWS {
            let x = point_on(receiver, rng.next_f64(), rng.next_f64());
            let height = sn.dot(x - c0);
            if height <= 0.0 {
                continue;
            }
            let (u, v) = rng.next_f32_pair();
            let (r, phi) = (f64::from(u).sqrt(), std::f64::consts::TAU * f64::from(v));
            let d =
                t * (r * phi.cos()) + b * (r * phi.sin()) + el.normal * (1.0 - f64::from(u)).max(0.0).sqrt();
            let towards = -sn.dot(d);
            if towards <= 0.0 {
                continue;
            }
            let p = x + d * (height / towards);
            if inside(p) {
                ray((x + el.normal * offset).as_vec3(), (p + sn * offset).as_vec3());
                break;
            }
        }
    }
}

/// Tries per ray of [`draw_by_solid_angle`] at a direction that meets the shooter.
const SOLID_ANGLE_REDRAWS: u32 = 32;

/// Whether element `e`'s rays to the shooter weigh by the kernel (see [`draw`]). Not when it
/// is [`near`] the shooter: its ends follow the kernel already, or it is as large as its
/// distance, and a few rays' kernels (spanning orders of magnitude there) say little of the
/// rest of it. Not when it is large beside its distance, for the same reason. And not from
/// an uneven shooter: its ends follow its power, while the form factor the visibility
/// multiplies is the area's (`receive::weigh` corrects only the near receivers), so only the
/// share of rays is consistent with it.
fn weighs_rays(shot: &Shot, e: usize) -> bool {
    if near(shot, e) || shot.uneven.is_some() {
        return false;
    }
    let distance = shot.vertex_means[e].distance(shot.shooter.centre);
    shot.element_radii[e] <= SMALL * distance
}

/// The point-to-point form factor kernel cos θ cos θ' / r² (without 1/π) of a ray from a
/// receiver of normal `n` at `from` to a shooter of normal `ns` at `to`; 0 where either end
/// faces away.
fn kernel(from: Vec3, to: Vec3, n: Vec3, ns: Vec3) -> f32 {
    let d = to - from;
    let r2 = d.length_squared();
    let (cos_r, cos_s) = (n.dot(d).max(0.0), (-ns.dot(d)).max(0.0));
    if r2 > 0.0 { cos_r * cos_s / (r2 * r2) } else { 0.0 }
}

/// How a ray's end is found on the shooter: its cell of the shooter's table, or, for a near
/// receiver, by the form factor kernel (see [`NearEnds`]).
#[derive(Clone, Copy)]
struct Ends<'a> {
    shot: &'a Shot<'a>,
    near: Option<&'a NearEnds>,
}

impl Ends<'_> {
    /// The end at `(a, b)` ∈ [0, 1)² and the same lifted off the shooter, as the ray takes it.
    ///
    /// A near receiver reads `a` alone, as its share of the kernel's mass, to pick a run of
    /// the shooter's elements, then draws a fresh point of it with `rng`. (The shooter's table
    /// of 256 ends would be the only points of it that all its near receivers see, and their
    /// error shared by a whole object, and its cells are not compact: a cell holds a sliver
    /// of every element of a band. Drawn from the table by the kernel, a plate between two
    /// shelves came out anywhere from 14 % dark to 10 % bright with the seed.)
    fn end(&self, a: f32, b: f32, rng: &mut Rng) -> (DVec3, Vec3) {
        let shot = self.shot;
        match self.near {
            Some(near) => {
                let (below, above) = near.run(a, shot.cdf);
                let u = below + rng.next_f64() * (above - below);
                let end = shooter_point(shot.cdf, shot.shooter_elements, u, rng.next_f64());
                (end, (end + shot.shooter.normal * shot.offset).as_vec3())
            }
            None => {
                let cell = target_cell(a, b);
                (shot.targets[cell], shot.lifted_targets[cell])
            }
        }
    }
}

/// Element `e`'s `rays` to the shooter, traced: what they saw (none traced when the pair
/// needs no ray).
pub(super) fn trace(shot: &Shot, plan: &PatchPlan, e: usize, rays: Rays) -> Seen {
    let Shot { mesh, shooter, accel, boxes, blockers, offset, .. } = *shot;
    // Every segment between the element and the shooter lies in the box around both; when no
    // blocking triangle comes near that box the pair is fully visible and needs no ray.
    if plan.visibility == Visibility::Clear {
        return Seen::default();
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
            return Seen::default();
        }
    }
    // Unblocked segments of a packet: four at once against the candidate list, one by one
    // through the ray structure.
    let mut seen = Seen::default();
    let mut unblocked = |packet: &Packet, weights: &[f32; 4], seen: &mut Seen| {
        if few {
            let blocked =
                blockers.occluded_x4(&Segments4::new(&packet.from, &packet.to, packet.n), candidates);
            for (lane, w) in weights[..packet.n].iter().enumerate() {
                seen.add(blocked >> lane & 1 == 0, *w);
            }
        } else {
            for (i, w) in weights[..packet.n].iter().enumerate() {
                seen.add(!accel.occluded(packet.from[i], packet.to[i]), *w);
            }
        }
    };
    let mut packet = Packet::default();
    let mut weights = [0.0f32; 4];
    draw(shot, plan, e, rays, |from, to, weight| {
        weights[packet.n] = weight;
        packet.push(from, to, 0);
        if packet.n == 4 {
            unblocked(&packet, &weights, &mut seen);
            packet.n = 0;
        }
    });
    if packet.n > 0 {
        unblocked(&packet, &weights, &mut seen);
    }
    // None traced: the parts of each that face the other are too small to hit; the caller
    // then takes the pair as unblocked.
    seen
}

/// Draws element `e`'s rays to the shooter, one per stratum of `strata` (fresh, at its first
/// stratum), and hands each segment (ends lifted off both surfaces, single precision) to
/// `ray`.
fn draw_rays(
    plan: &PatchPlan,
    e: usize,
    mut strata: Strata,
    rng: &mut Rng,
    ends: Ends,
    ray: impl FnMut(Vec3, Vec3),
) {
    let count = strata.count();
    if ends.near.is_some() {
        // Stratified over the kernel's mass; the origins drawn apart from the ends: with one
        // stratum for both, a point on one side of the receiver would go with the same part
        // of the kernel's mass, which is not independent of where the point is.
        let mut k = 0;
        draw_rays_from(plan, e, count, rng, ends, ray, |rng| {
            let t = ((f64::from(k) + rng.next_f64()) / f64::from(count)) as f32;
            let t = t.min(ONE_BELOW);
            k += 1;
            (rng.next_f32_pair(), (t, 0.0))
        });
        return;
    }
    draw_rays_from(plan, e, count, rng, ends, ray, |rng| {
        // The same stratum on both ends, each jittered on its own.
        let stratum = strata.next();
        (strata.jitter(stratum, rng), strata.jitter(stratum, rng))
    });
}

/// [`draw_rays`] for `count` rays whose `(u, v)` on the element and `(a, b)` on the shooter
/// come from `sample`; `rng` draws the redraws.
fn draw_rays_from(
    plan: &PatchPlan,
    e: usize,
    count: u32,
    rng: &mut Rng,
    ends: Ends,
    mut ray: impl FnMut(Vec3, Vec3),
    mut sample: impl FnMut(&mut Rng) -> ((f32, f32), (f32, f32)),
) {
    let shot = ends.shot;
    let Shot { mesh, shooter, offset, .. } = *shot;
    let el = &mesh.elements[e];
    let corners = shot.lifted_corners[e];
    let lifted = &corners[..el.vertex_count as usize];
    if plan.facing {
        // Nothing to clip (the usual case): origins straight from the lifted corners.
        for _ in 0..count {
            let ((u, v), (a, b)) = sample(rng);
            let (_, to) = ends.end(a, b, rng);
            ray(point_on_f32(lifted, u, v).into(), to);
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
        let (mut end, mut to) = ends.end(a, b, rng);
        let from = if clipped {
            let mut from = point_on(receiver, f64::from(u), f64::from(v));
            let mut tries = 0;
            while !ahead(from, end) && tries < REDRAWS {
                from = point_on(receiver, rng.next_f64(), rng.next_f64());
                let (a, b) = rng.next_f32_pair();
                (end, to) = ends.end(a, b, rng);
                tries += 1;
            }
            if !ahead(from, end) {
                continue;
            }
            (from + lift).as_vec3()
        } else {
            point_on_f32(lifted, u, v).into()
        };
        ray(from, to);
    }
}
