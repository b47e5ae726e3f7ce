//! Luminaires shoot first, exactly: before the first shot, every element receives the
//! direct irradiance of every luminaire (inverse-square law with the luminaire's
//! goniometric intensity, E = I(C, γ) · cos θ / d², CIE 171:2006 test case 5.2), each sample
//! point tested by a shadow ray to the luminaire, or to each cell of its opening that the
//! point is near enough to see apart (`Luminaire::sources_towards`). The element then holds ρ·E as radiosity and
//! as unshot radiosity, and the surfaces' shooting carries the inter-reflections as for any
//! other light.
//!
//! Each element is sampled at the centroids of the triangles fanned from its centre to its
//! sides, weighted by their areas (one point per side; second order, so a room's elements of
//! a few centimetres integrate the 1/d² falloff to well under 0.1 %).
//!
//! The sun ([`radiosity_core::Sun`]) shoots first the same way: E_sun cos θ times the part of each element
//! whose shadow rays towards the sun leave the scene unblocked, by the blocking triangles or
//! the hull's (see `occluders`), from 16 jittered points ([`sunlit_fraction`]). Its power is
//! what the elements receive (light from infinity has no total of its own), so none of it
//! escapes.
//!
//! The sky ([`Sky`]) too: π L(ω) over the part of each element's hemisphere whose shadow
//! rays leave the scene above the horizon, by [`Sky::rays`] rays per element, stratified by
//! the cosine over the hemisphere and jittered over the element ([`skylight`]).
//!
//! The luminaires' light is not the emitters' *direct part* (`Tally::direct`): a
//! final gather recomputes only area emitters per pixel, and takes this light from the
//! solution.

use radiosity_accel::{Bvh, RayQuery};
use radiosity_core::glam::DVec3;
use radiosity_core::{Daylight, LUMENS_PER_WATT, Luminaire, Rgb, Sky};
use radiosity_mesh::Mesh;
use rayon::prelude::*;

/// Direct light of the luminaires on every element.
pub(super) struct LuminaireLight {
    /// Irradiance per element, W/unit².
    pub(super) irradiance: Vec<Rgb>,
    /// The luminaires' total flux, W per channel (lm / 683 × colour).
    pub(super) power: Rgb,
    /// How many luminaires shine (the sun aside).
    pub(super) count: usize,
}

impl LuminaireLight {
    /// The direct light of `luminaires` and of the sun and sky of `daylight` on the elements
    /// of `mesh`, shadowed by `rays`; `None` without any.
    ///
    /// The daylight comes with the occluder triangles left out of `rays` (a room's own walls,
    /// see `occluders::hull_triangles`): no ray between two surface points crosses them, but a
    /// shadow ray towards the sun or sky, which ends past the scene, does.
    pub(super) fn new(
        mesh: &Mesh,
        rays: &dyn RayQuery,
        luminaires: &[Luminaire],
        daylight: Option<(Daylight, &Bvh)>,
    ) -> Option<Self> {
        let daylight = daylight.filter(|(d, _)| !d.is_none());
        if luminaires.is_empty() && daylight.is_none() {
            return None;
        }
        let (lo, hi) = mesh.bounds();
        let diagonal = (hi - lo).length().max(f64::MIN_POSITIVE);
        let lift = 1e-6 * diagonal;
        // A shadow ray towards the sun or sky ends past the scene, twice its diagonal from
        // any point.
        let infinity = daylight.map(|(d, hull)| Infinity { daylight: d, reach: 2.0 * diagonal, hull, lift });
        let both: Vec<(Rgb, Rgb)> = (0..mesh.elements.len())
            .into_par_iter()
            .with_min_len(64)
            .map(|e| {
                let from_infinity = infinity.as_ref().map_or(Rgb::ZERO, |i| i.irradiance(mesh, e, rays));
                (element_irradiance(mesh, e, rays, luminaires, lift), from_infinity)
            })
            .collect();
        let sun_power: Rgb = both.iter().zip(&mesh.elements).map(|((_, s), el)| *s * el.area).sum();
        let irradiance = both.into_iter().map(|(l, s)| l + s).collect();
        let power =
            luminaires.iter().map(|l| l.colour * (l.flux() / LUMENS_PER_WATT)).sum::<Rgb>() + sun_power;
        Some(Self { irradiance, power, count: luminaires.len() })
    }

    /// Whether no light arrives anywhere.
    pub(super) fn is_dark(&self) -> bool {
        self.irradiance.iter().all(|h| h.max_channel() <= 0.0)
    }
}

/// Sample points of element `e` and their area weights (summing to 1).
fn sample_points(mesh: &Mesh, e: usize) -> ([(DVec3, f64); 4], usize) {
    let el = &mesh.elements[e];
    let corners: Vec<DVec3> = mesh.element_corners(e).collect();
    let n = corners.len().min(4);
    let mut out = [(el.centre, 0.0); 4];
    let mut total = 0.0;
    for k in 0..n {
        let (a, b) = (corners[k], corners[(k + 1) % n]);
        let w = (a - el.centre).cross(b - el.centre).length();
        out[k] = ((el.centre + a + b) / 3.0, w);
        total += w;
    }
    if total > 0.0 {
        for p in &mut out[..n] {
            p.1 /= total;
        }
        (out, n)
    } else {
        ([(el.centre, 1.0); 4], 1)
    }
}

/// Element `e`'s direct irradiance from the luminaires.
fn element_irradiance(
    mesh: &Mesh,
    e: usize,
    rays: &dyn RayQuery,
    luminaires: &[Luminaire],
    lift: f64,
) -> Rgb {
    // Daylight alone: no points to sample for luminaires.
    if luminaires.is_empty() {
        return Rgb::ZERO;
    }
    let n = mesh.elements[e].normal;
    let (points, count) = sample_points(mesh, e);
    let mut sum = Rgb::ZERO;
    for l in luminaires {
        for &(p, w) in &points[..count] {
            for (source, share) in l.sources_towards(p) {
                let h = l.irradiance_from(source, p, n);
                if h.max_channel() > 0.0 && !rays.occluded(source.as_vec3(), (p + n * lift).as_vec3()) {
                    sum += h * (w * share);
                }
            }
        }
    }
    sum
}

/// The sun and sky, with what their shadow rays need.
struct Infinity<'a> {
    daylight: Daylight,
    /// How far a shadow ray goes to leave the scene.
    reach: f64,
    /// The hull's triangles (see [`LuminaireLight::new`]).
    hull: &'a Bvh,
    /// How far a ray's start is lifted off its element.
    lift: f64,
}

impl Infinity<'_> {
    /// Element `e`'s direct irradiance from the sun and the sky.
    fn irradiance(&self, mesh: &Mesh, e: usize, rays: &dyn RayQuery) -> Rgb {
        let n = mesh.elements[e].normal;
        let reach = self.reach as f32;
        let leaves = |p: DVec3, towards: DVec3| {
            let (from, towards) = ((p + n * self.lift).as_vec3(), towards.as_vec3());
            !rays.occluded_towards(from, towards, reach) && !self.hull.occluded_towards(from, towards, reach)
        };
        let mut sum = Rgb::ZERO;
        if let Some(sun) = &self.daylight.sun {
            let h = sun.irradiance_on(n);
            if h.max_channel() > 0.0 {
                sum += h * sunlit_fraction(mesh, e, |p| leaves(p, sun.towards));
            }
        }
        if let Some(sky) = &self.daylight.sky {
            sum += skylight(mesh, e, sky, leaves);
        }
        sum
    }
}

/// Jittered samples per side of an element for the sun's shadow rays (16 in all).
const SUN_STRATA: u32 = 4;

/// Random stream of the sun's samples, apart from every other.
const SUN_STREAM: u64 = 0x73_756e;

/// Random stream of the sky's samples, apart from every other.
const SKY_STREAM: u64 = 0x0073_6b79;

/// Element `e`'s irradiance from `sky` where `leaves(point, direction)` says a shadow ray
/// leaves the scene: E = ∫ L(ω) cos θ dω over the hemisphere, estimated with directions
/// drawn by the cosine (density cos θ / π), so each ray brings π L(ω) (Pharr, Jakob &
/// Humphreys, PBRT 4th ed. §A.5.3, Malley's method), on a √N × √N grid of jittered strata
/// (Cook 1986), each from its own random point of the element, so that a shadow's edge
/// across the element is averaged over it.
/// Directions at or below the horizon bring nothing.
fn skylight(mesh: &Mesh, e: usize, sky: &Sky, leaves: impl Fn(DVec3, DVec3) -> bool) -> Rgb {
    let el = &mesh.elements[e];
    // No part of the sky above this element's horizon: a floor's underside (a map's lower
    // half, the ground at infinity, still lights it).
    let map = matches!(sky.model, radiosity_core::SkyModel::Map { .. });
    if !map && el.normal.dot(sky.zenith) <= -1.0 + 1e-12 {
        return Rgb::ZERO;
    }
    let corners: Vec<DVec3> = mesh.element_corners(e).take(4).collect();
    let side = f64::from(sky.rays).sqrt().ceil().max(1.0) as u32;
    let (rows, columns) = (sky.rays.div_ceil(side), side);
    let mut rng = radiosity_core::random::Rng::for_task(0, SKY_STREAM, e as u64);
    let (t, b) = el.normal.any_orthonormal_pair();
    let mut sum = Rgb::ZERO;
    for k in 0..rows * columns {
        let (j, r) = (k % columns, k / columns);
        let u = (f64::from(j) + rng.next_f64()) / f64::from(columns);
        let v = (f64::from(r) + rng.next_f64()) / f64::from(rows);
        // Malley: a uniform point of the unit disc lifted onto the hemisphere.
        let (radius, phi) = (u.sqrt(), 2.0 * std::f64::consts::PI * v);
        let (x, y) = (radius * phi.cos(), radius * phi.sin());
        let dir = t * x + b * y + el.normal * (1.0 - u).max(0.0).sqrt();
        let light = sky.radiosity_towards(dir);
        if light.max_channel() <= 0.0 {
            continue;
        }
        let p = crate::sampling::point_on(&corners, rng.next_f64(), rng.next_f64());
        if leaves(p, dir) {
            sum += light;
        }
    }
    sum * (1.0 / f64::from(rows * columns))
}

/// The area fraction of element `e` whose points `clear` says the sun reaches: 4 × 4
/// jittered points, each weighted by the area its parameter cell maps to (a quad's bilinear
/// map is not area-uniform unless it is a parallelogram). Unlike the luminaires' fan
/// centroids, which never come within a third of an element's width of its sides, these
/// reach them: a sun shadow's edge is sharp, and in Sponza's colonnades the thin strips of
/// sun on a ledge or between columns fell between those points, the floors −8 %, two
/// mouldings −66 % and −81 % in direct light against the path tracer.
fn sunlit_fraction(mesh: &Mesh, e: usize, clear: impl Fn(DVec3) -> bool) -> f64 {
    let corners: Vec<DVec3> = mesh.element_corners(e).take(4).collect();
    let mut rng = radiosity_core::random::Rng::for_task(0, SUN_STREAM, e as u64);
    let (mut lit, mut total) = (0.0, 0.0);
    for row in 0..SUN_STRATA {
        for column in 0..SUN_STRATA {
            let u = (f64::from(column) + rng.next_f64()) / f64::from(SUN_STRATA);
            let v = (f64::from(row) + rng.next_f64()) / f64::from(SUN_STRATA);
            let p = crate::sampling::point_on(&corners, u, v);
            let w = if corners.len() == 4 {
                let du = (corners[1] - corners[0]) * (1.0 - v) + (corners[2] - corners[3]) * v;
                let dv = (corners[3] - corners[0]) * (1.0 - u) + (corners[2] - corners[1]) * u;
                du.cross(dv).length()
            } else {
                1.0
            };
            total += w;
            if clear(p) {
                lit += w;
            }
        }
    }
    if total > 0.0 { lit / total } else { 0.0 }
}
