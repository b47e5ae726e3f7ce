//! The film: every pixel's jittered samples, stratified and seeded by the pixel, traced and
//! averaged row by row in parallel, with the object seen through each pixel's centre.

use std::f64::consts::PI;

use glam::DVec3;
use radiosity_accel::Hit;
use radiosity_core::random::Rng;
use radiosity_core::{Camera, CameraRays, Rgb};
use radiosity_solver::Solution;
use rayon::prelude::*;

use crate::HdrImage;
use crate::cache::{IrradianceCache, Site};
use crate::gather::{Gather, Seen};

use super::final_gather::{Effort, RECORD_TASK, Stratum};
use super::params::{RenderError, RenderParams};
use super::{RECORD_RAYS_PER_GATHER_RAY, Renderer, Rendering};

/// Task key of the pixels' streams (`Rng::for_task(seed, PIXEL_TASK, pixel)`).
pub(super) const PIXEL_TASK: u64 = 0x7069_7865_6c73; // "pixels"

/// `0..n` in an order drawn from `rng` (Fisher–Yates; the modulo's bias is below 2⁻⁵⁰).
pub(super) fn shuffled(n: u32, rng: &mut Rng) -> Vec<u32> {
    let mut order: Vec<u32> = (0..n).collect();
    for i in (1..order.len()).rev() {
        let j = rng.next_u64() % (i as u64 + 1);
        order.swap(i, j as usize);
    }
    order
}

impl Renderer {
    /// Renders `solution` seen from `camera`.
    ///
    /// # Errors
    /// [`RenderError::BadParameter`] for out-of-range settings, [`RenderError::SolutionMismatch`]
    /// when `solution` was computed for another mesh.
    pub fn render(
        &self,
        solution: &Solution,
        camera: &Camera,
        params: &RenderParams,
    ) -> Result<Rendering, RenderError> {
        self.render_with_progress(solution, camera, params, &|| {})
    }

    /// As [`Renderer::render`], calling `row_done` (from any worker thread) after each row.
    ///
    /// # Errors
    /// As [`Renderer::render`].
    pub fn render_with_progress(
        &self,
        solution: &Solution,
        camera: &Camera,
        params: &RenderParams,
        row_done: &(dyn Fn() + Sync),
    ) -> Result<Rendering, RenderError> {
        params.validate()?;
        self.check(solution)?;
        if params.gather == Gather::Direct && !self.has_direct_part(solution) {
            return Err(RenderError::NoDirectPart);
        }
        let (w, h) = (params.width as usize, params.height as usize);
        let rays = CameraRays::new(camera, params.width, params.height);
        // What the centre ray of a pixel, or the ray through a pixel corner, sees: the object
        // and whether it emits (a lamp is often one face of a larger object).
        let what = |hit: &Hit| {
            let e = self.triangle_element[hit.triangle as usize] as usize;
            let emits = self.mesh.element_material(e).emission.max_channel() > 0.0;
            (self.mesh.element_object(e) as u32, emits)
        };
        let first_hit = |dir: DVec3| self.closest_seen(camera.position, dir);
        let seen = |px: f64, py: f64| first_hit(rays.direction(px, py)).as_ref().map(what);
        // Pixel corners: (w + 1) × (h + 1), shared by the four pixels around each.
        let corners: Vec<Option<(u32, bool)>> = (0..=h)
            .into_par_iter()
            .flat_map_iter(|y| (0..=w).map(move |x| (x, y)))
            .map(|(x, y)| if params.edge_factor > 1 { seen(x as f64, y as f64) } else { None })
            .collect();
        let centre_dir = |i: usize| rays.direction((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
        let centre_hits: Vec<Option<Hit>> =
            (0..w * h).into_par_iter().map(|i| first_hit(centre_dir(i))).collect();
        // What each pixel's centre sees of the emitters, neighbours probing with different
        // sets of points (see `gather::PROBE_SETS`): a pixel is then judged by its 3 × 3
        // neighbourhood, four sets' worth of points for the price of one.
        let probed: Vec<Option<Seen>> = (0..w * h)
            .into_par_iter()
            .map(|i| {
                let set = (i % w) % 2 + 2 * ((i / w) % 2);
                self.probe(camera.position, centre_dir(i), centre_hits[i].as_ref()?, params, set)
            })
            .collect();
        let effort_of = |x: usize, y: usize, p: &RenderParams| {
            let around = (y.saturating_sub(1)..(y + 2).min(h))
                .flat_map(|j| (x.saturating_sub(1)..(x + 2).min(w)).map(move |i| j * w + i));
            match probed[y * w + x] {
                Some(own) => Self::effort_from(around.filter_map(|i| probed[i]).fold(own, Seen::union), p),
                None => Effort::PLAIN,
            }
        };
        let cache = (params.gather == Gather::Full).then(|| {
            // One pixel's width per unit of distance from the eye.
            let pixel_angle = 2.0 * (camera.fov_y_deg.to_radians() * 0.5).tan() / f64::from(params.height);
            let sites: Vec<Option<Site>> = (0..w * h)
                .into_par_iter()
                .map(|i| {
                    let (e, point, distance, front) =
                        self.surface_point(camera.position, centre_dir(i), centre_hits[i].as_ref()?);
                    let reflects = self.mesh.element_material(e).reflectance.max_channel() > 0.0;
                    // A thousandth of the way to the element's centre: a centre ray that
                    // meets a corner's edge (within the single-precision hit) would otherwise
                    // gather from the edge itself, half its rays slipping past the other
                    // surface — one dark record as large as its far-travelled rays say.
                    let point = point + (self.mesh.elements[e].centre - point) * 1e-3;
                    // A record's radius is clamped between multiples of this: it must be a
                    // positive number (an eye on a surface would make it 0).
                    let pixel_size = distance * pixel_angle;
                    let sized = pixel_size.is_finite() && pixel_size > 0.0;
                    let (normal, origin) = self.shading_frame(e, point);
                    (front && reflects && sized).then_some(Site { point, normal, origin, pixel_size })
                })
                .collect();
            IrradianceCache::build(w, h, &sites, |i, site, factor| {
                let key = i as u64 * u64::from(crate::cache::MAX_RAY_FACTOR + 1) + u64::from(factor);
                let mut rng = Rng::for_task(params.seed, RECORD_TASK, key);
                let count = params.gather_rays * RECORD_RAYS_PER_GATHER_RAY * factor;
                self.gather_record(solution, site, count, params.shading, &mut rng)
            })
        });
        let mut pixels = vec![Rgb::ZERO; w * h];
        let mut object_ids = vec![None; w * h];
        let plain = *params;
        let edge =
            RenderParams { samples_per_pixel: params.samples_per_pixel * params.edge_factor, ..*params };
        // A lamp's outline: the lamp is tens of times brighter than what lies beside it, so
        // a pixel's share of it, counted in samples, is that much noisier against the
        // pixel's value. These few pixels (a lamp's perimeter) take the edge factor squared.
        let lamp_edge = RenderParams {
            samples_per_pixel: params.samples_per_pixel
                * (params.edge_factor * params.edge_factor).min(RenderParams::MAX_EDGE_FACTOR),
            ..*params
        };
        pixels.par_chunks_mut(w).zip(object_ids.par_chunks_mut(w)).enumerate().for_each(|(y, (row, ids))| {
            for x in 0..w {
                let index = (y * w + x) as u64;
                let mut rng = Rng::for_task(params.seed, PIXEL_TASK, index);
                let centre_hit = centre_hits[y * w + x];
                let centre = centre_hit.as_ref().map(what);
                ids[x] = centre.map(|(object, _)| object);
                // An edge is decided from rays apart from the pixel's samples, so that
                // sampling more where the outline runs does not bias the pixel: a decision
                // taken from its own samples would keep the low estimate of a pixel whose
                // samples all missed a sliver of the lamp.
                let around =
                    [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)].map(|(i, j)| corners[j * (w + 1) + i]);
                let on_edge = params.edge_factor > 1 && around.iter().any(|c| *c != centre);
                let emits = |c: &Option<(u32, bool)>| c.is_some_and(|(_, emits)| emits);
                let on_lamp = on_edge && around.iter().chain([&centre]).any(emits);
                let p = match (on_edge, on_lamp) {
                    (_, true) => &lamp_edge,
                    (true, false) => &edge,
                    (false, false) => &plain,
                };
                let n = p.samples_per_pixel;
                let effort = effort_of(x, y, p);
                // Sample i's place in the pixel is stratum i of the pixel's grid; the strata
                // of the emitters and of the hemisphere it takes are drawn apart from that, so
                // that where only some samples see a surface (the pixels along an outline,
                // all from one side of the pixel) they still sample the whole lamp and not
                // one end of it: tied together, the floor's front edge read up to 45 % bright
                // in the short block's penumbra and 55 % dark beside it.
                let strata = shuffled(n, &mut rng);
                let rotation = rng.next_f64();
                let mut sum = Rgb::ZERO;
                for i in 0..n {
                    let dir = rays.jittered_direction(x as u32, y as u32, i, n, &mut rng);
                    if let Some(hit) = self.trace_unchecked(solution, camera.position, dir, p.shading) {
                        let ray = (camera.position, dir);
                        let seen = |b: Rgb, per_sr: bool| {
                            self.textured(b, per_sr, hit.element as usize, hit.object, ray, hit.distance)
                        };
                        sum += match p.gather {
                            Gather::None if hit.front_facing => seen(hit.radiance, true),
                            Gather::None => hit.radiance,
                            _ if !hit.front_facing => Rgb::ZERO,
                            gather => {
                                let e = hit.element as usize;
                                let cached = cache.as_ref().map(|c| (c, x, y));
                                seen(
                                    self.gathered_sample(
                                        solution,
                                        e,
                                        hit.p_world,
                                        gather,
                                        p,
                                        effort,
                                        Stratum { index: strata[i as usize], rotation },
                                        cached,
                                        &mut rng,
                                    ),
                                    false,
                                ) / PI
                            }
                        };
                    } else {
                        sum += self.background(dir);
                    }
                }
                row[x] = sum / f64::from(n);
            }
            row_done();
        });
        Ok(Rendering { radiance: HdrImage::from_pixels(params.width, params.height, pixels), object_ids })
    }
}
