//! Luminaires shoot first, exactly: before the first shot, every element receives the
//! direct irradiance of every point luminaire (inverse-square law with the luminaire's
//! goniometric intensity, E = I(C, γ) · cos θ / d², CIE 171:2006 test case 5.2), each sample
//! point tested by a shadow ray to the luminaire. The element then holds ρ·E as radiosity and
//! as unshot radiosity, and the surfaces' shooting carries the inter-reflections as for any
//! other light.
//!
//! Each element is sampled at the centroids of the triangles fanned from its centre to its
//! sides, weighted by their areas (one point per side; second order, so a room's elements of
//! a few centimetres integrate the 1/d² falloff to well under 0.1 %).
//!
//! The sun ([`Sun`]) shoots first the same way: E_sun cos θ times the part of each element
//! whose shadow rays towards the sun leave the scene unblocked, by the blocking triangles or
//! the hull's (see `occluders`), from 16 jittered points ([`sunlit_fraction`]). Its power is
//! what the elements receive (light from infinity has no total of its own), so none of it
//! escapes.
//!
//! The luminaires' light is not the emitters' *direct part* (`Tally::direct`): a
//! final gather recomputes only area emitters per pixel, and takes this light from the
//! solution.

use radiosity_accel::{Bvh, RayQuery};
use radiosity_core::glam::DVec3;
use radiosity_core::{LUMENS_PER_WATT, Luminaire, Rgb, Sun};
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
    /// The direct light of `luminaires` and the `sun` on the elements of `mesh`, shadowed by
    /// `rays`; `None` without either.
    ///
    /// `hull` holds the occluder triangles left out of `rays` (a room's own walls, see
    /// `occluders::hull_triangles`): no ray between two surface points crosses them, but a
    /// shadow ray towards the sun, which ends past the scene, does. Needed with a sun only.
    pub(super) fn new(
        mesh: &Mesh,
        rays: &dyn RayQuery,
        luminaires: &[Luminaire],
        sun: Option<(&Sun, &Bvh)>,
    ) -> Option<Self> {
        if luminaires.is_empty() && sun.is_none() {
            return None;
        }
        let (lo, hi) = mesh.bounds();
        let diagonal = (hi - lo).length().max(f64::MIN_POSITIVE);
        let lift = 1e-6 * diagonal;
        // A shadow ray towards the sun ends past the scene, twice its diagonal from any point.
        let sun = sun.map(|(s, hull)| (s, 2.0 * diagonal, hull));
        let both: Vec<(Rgb, Rgb)> = (0..mesh.elements.len())
            .into_par_iter()
            .with_min_len(64)
            .map(|e| element_irradiance(mesh, e, rays, luminaires, sun, lift))
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

/// Element `e`'s direct irradiance from the luminaires and from the sun (with the length of
/// its shadow rays), apart.
fn element_irradiance(
    mesh: &Mesh,
    e: usize,
    rays: &dyn RayQuery,
    luminaires: &[Luminaire],
    sun: Option<(&Sun, f64, &Bvh)>,
    lift: f64,
) -> (Rgb, Rgb) {
    let n = mesh.elements[e].normal;
    let (points, count) = sample_points(mesh, e);
    let mut sum = Rgb::ZERO;
    for l in luminaires {
        for &(p, w) in &points[..count] {
            let h = l.irradiance_unblocked(p, n);
            if h.max_channel() <= 0.0 {
                continue;
            }
            if !rays.occluded(l.position.as_vec3(), (p + n * lift).as_vec3()) {
                sum += h * w;
            }
        }
    }
    let mut sunlight = Rgb::ZERO;
    if let Some((sun, reach, hull)) = sun {
        let h = sun.irradiance_on(n);
        if h.max_channel() > 0.0 {
            sunlight = h * sunlit_fraction(mesh, e, |p| {
                let from = p + n * lift;
                let to = (from + sun.towards * reach).as_vec3();
                !rays.occluded(from.as_vec3(), to) && !hull.occluded(from.as_vec3(), to)
            });
        }
    }
    (sum, sunlight)
}

/// Jittered samples per side of an element for the sun's shadow rays (16 in all).
const SUN_STRATA: u32 = 4;

/// Random stream of the sun's samples, apart from every other.
const SUN_STREAM: u64 = 0x73_756e;

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
