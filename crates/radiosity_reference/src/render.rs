//! Pictures by path tracing: the radiance the camera sees, B/π of the first surface a ray
//! meets, with B estimated by a path from that point.

use radiosity_core::random::Rng;
use radiosity_core::{Camera, CameraRays, Rgb};
use rayon::prelude::*;

use crate::geometry::Geometry;
use crate::{Picture, PictureParams};

/// Task key of the pixels' streams.
const PIXEL_TASK: u64 = 0x7069_7800_0000_0000; // "pix"

pub(crate) fn render(
    g: &Geometry,
    camera: &Camera,
    params: &PictureParams,
    row_done: &(dyn Fn() + Sync),
) -> Picture {
    let (w, h) = (params.width as usize, params.height as usize);
    let rays = CameraRays::new(camera, params.width, params.height);
    let n = params.samples_per_pixel.max(1);
    let mut radiance = vec![Rgb::ZERO; w * h];
    let mut stderr = vec![Rgb::ZERO; w * h];
    radiance.par_chunks_mut(w).zip(stderr.par_chunks_mut(w)).enumerate().for_each(|(y, (row, se_row))| {
        for x in 0..w {
            let mut rng = Rng::for_task(params.seed, PIXEL_TASK, (y * w + x) as u64);
            let (mut sum, mut sum_sq) = (Rgb::ZERO, Rgb::ZERO);
            for i in 0..n {
                let dir = rays.jittered_direction(x as u32, y as u32, i, n, &mut rng);
                let l = match g.intersect(camera.position, dir) {
                    Some(hit) if hit.front => {
                        g.radiosity_at(hit.point, u32::MAX, &mut rng) * std::f64::consts::FRAC_1_PI
                    }
                    Some(_) => Rgb::ZERO,
                    // The sky where the view leaves the scene, as the solve's picture shows it.
                    None => g
                        .sky
                        .as_ref()
                        .map_or(Rgb::ZERO, |s| s.radiosity_towards(dir) * std::f64::consts::FRAC_1_PI),
                };
                sum += l;
                sum_sq += l * l;
            }
            let k = f64::from(n);
            let mean = sum / k;
            row[x] = mean;
            // Sample variance of the pixel's samples over n: the pixel's own standard error
            // (conservative for the stratified film positions).
            se_row[x] = if n > 1 {
                ((sum_sq - mean * mean * k) / (k - 1.0) / k).map(|v| v.max(0.0).sqrt())
            } else {
                Rgb::splat(f64::INFINITY)
            };
        }
        row_done();
    });
    Picture { width: params.width, height: params.height, radiance, stderr }
}
