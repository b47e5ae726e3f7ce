//! Illuminance at calculation-grid points, in lux: what a lighting designer reads off a work
//! plane (EN 12464-1: Em, Emin, Emax, uniformity U0 = Emin / Em).
//!
//! At each point p with normal n:
//!
//!   E(p) = Σ_luminaires I(C, γ) · cos θ / d² · V(p, luminaire)   (direct, exact)
//!        + ∫ B(y)/π · cos θ dω                                    (reflected, gathered)
//!
//! The direct part is the inverse-square law with one shadow ray per luminaire against the
//! scene's input polygons. The rest is gathered from the radiosity solution as the final
//! gather does: stratified cosine-weighted rays from p meet surfaces whose interpolated
//! radiosity B(y) they average (the cosine density makes E = π · mean L = mean B). B(y)
//! includes the surfaces' own emission, so area emitters count there. Grid points cast no
//! shadow and are not part of the solve. Lux are the Rec. 709 Y of the RGB irradiance at
//! 683 lm/W over the scene unit in metres squared ([`radiosity_core::LengthUnit`]).

use std::f64::consts::PI;

use glam::DVec3;
use radiosity_accel::{Bvh, RayQuery};
use radiosity_core::random::Rng;
use radiosity_core::{Grid, Lighting, Rgb};
use radiosity_solver::{Solution, hull_triangles};
use rayon::prelude::*;

use crate::gather::cosine_direction;
use crate::{RenderError, Renderer, Shading};

/// Stream of the grid gathers (`Rng::for_task(seed, GRID_TASK, point)`).
const GRID_TASK: u64 = 0x6772_6964;

/// Settings of the grid calculation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridParams {
    /// Gathering rays per point for the reflected light, stratified (default 1024: on a room
    /// whose reflected light is a third of the total, about 0.3 % noise per point).
    pub gather_rays: u32,
    /// Seed of the gathering rays (default 0).
    pub seed: u64,
}

impl Default for GridParams {
    fn default() -> Self {
        Self { gather_rays: 1024, seed: 0 }
    }
}

/// The illuminance of one grid.
#[derive(Clone, Debug, PartialEq)]
pub struct GridIlluminance {
    /// The grid's name.
    pub name: String,
    /// The points (renderer frame, +y up), scene units.
    pub points: Vec<DVec3>,
    /// Illuminance at each point, lx.
    pub lux: Vec<f64>,
    /// Of it, the luminaires' direct light, lx.
    pub direct_lux: Vec<f64>,
    /// Smallest value, lx.
    pub min: f64,
    /// Mean (Em), lx.
    pub avg: f64,
    /// Largest value, lx.
    pub max: f64,
    /// U0 = min / avg (0 when the mean is 0).
    pub uniformity: f64,
}

/// Min, mean, max and min / mean of `values`.
pub fn grid_statistics(values: &[f64]) -> (f64, f64, f64, f64) {
    if values.is_empty() {
        return (0.0, 0.0, 0.0, 0.0);
    }
    let min = values.iter().copied().fold(f64::INFINITY, f64::min);
    let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let avg = values.iter().sum::<f64>() / values.len() as f64;
    (min, avg, max, if avg > 0.0 { min / avg } else { 0.0 })
}

/// The luminaires' direct irradiance (W/unit²) at `p` facing `n`, shadowed by `blockers`:
/// each luminaire's point sources as `p` sees them ([`radiosity_core::Luminaire::sources_towards`]).
pub fn luminaire_irradiance(lighting: &Lighting, blockers: &dyn RayQuery, p: DVec3, n: DVec3) -> Rgb {
    let mut sum = Rgb::ZERO;
    for l in &lighting.luminaires {
        for (source, share) in l.sources_towards(p) {
            let h = l.irradiance_from(source, p, n);
            if h.max_channel() > 0.0 && !blockers.occluded(source.as_vec3(), p.as_vec3()) {
                sum += h * share;
            }
        }
    }
    sum
}

/// The illuminance of every point of `grid`: the luminaires' and the sun's direct light by shadow rays
/// against `blockers` (the solver's occluders), the reflected light gathered from `solution`
/// through `renderer`, and the sky's where those gathering rays leave the scene.
///
/// # Errors
/// [`RenderError::SolutionMismatch`] when `solution` is for another mesh;
/// [`RenderError::BadParameter`] for zero gathering rays.
pub fn grid_illuminance(
    renderer: &Renderer,
    solution: &Solution,
    blockers: &dyn RayQuery,
    lighting: &Lighting,
    grid: &Grid,
    params: &GridParams,
) -> Result<GridIlluminance, RenderError> {
    if params.gather_rays == 0 {
        return Err(RenderError::BadParameter {
            name: "gather_rays",
            value: 0,
            expected: "at least 1".to_owned(),
        });
    }
    // One trace validates the solution against the mesh.
    renderer.trace(solution, grid.origin, grid.normal, Shading::Smooth)?;
    let to_lux = lighting.unit().lux_per_irradiance();
    let (lo, hi) = renderer.mesh().bounds();
    let lift = 1e-6 * (hi - lo).length().max(f64::MIN_POSITIVE);
    let points = grid.points();
    let n = grid.normal.normalize();
    // The sun's shadow rays leave the scene: a room's own walls, which no ray between two of
    // its surface points crosses and `blockers` leaves out, block them too.
    let hull = lighting.sun.map(|_| Bvh::new(&hull_triangles(renderer.mesh())));
    let reach = 2.0 * (hi - lo).length();
    let sunlight = |from: DVec3, n: DVec3| match (&lighting.sun, &hull) {
        (Some(sun), Some(hull)) => {
            let (from, towards, reach) = (from.as_vec3(), sun.towards.as_vec3(), reach as f32);
            let clear = !blockers.occluded_towards(from, towards, reach)
                && !hull.occluded_towards(from, towards, reach);
            if clear { sun.irradiance_on(n) } else { Rgb::ZERO }
        }
        _ => Rgb::ZERO,
    };
    let columns = f64::from(params.gather_rays).sqrt().ceil() as u32;
    let rows = params.gather_rays.div_ceil(columns);
    let values: Vec<(f64, f64)> = points
        .par_iter()
        .enumerate()
        .map(|(i, &p)| {
            let direct = luminaire_irradiance(lighting, blockers, p, n) + sunlight(p + n * lift, n);
            let mut rng = Rng::for_task(params.seed, GRID_TASK, i as u64);
            let origin = p + n * lift;
            let (mut gathered, mut skylight) = (Rgb::ZERO, Rgb::ZERO);
            for k in 0..columns * rows {
                let (j, r) = (k % columns, k / columns);
                let u = (f64::from(j) + rng.next_f64()) / f64::from(columns);
                let v = (f64::from(r) + rng.next_f64()) / f64::from(rows);
                let dir = cosine_direction(n, u, v);
                match renderer.trace(solution, origin, dir, Shading::Smooth) {
                    Ok(Some(hit)) => gathered += hit.radiance * PI,
                    // A ray that leaves the scene meets the sky: direct light, by the
                    // density that drew it π L (see `Sky::radiosity_towards`).
                    Ok(None) => {
                        skylight += lighting.sky.as_ref().map_or(Rgb::ZERO, |s| s.radiosity_towards(dir))
                    }
                    Err(_) => {}
                }
            }
            let count = f64::from(columns * rows);
            let reflected = gathered / count;
            let direct = direct + skylight / count;
            let direct_lux = direct.luminance() * to_lux;
            (direct_lux + reflected.luminance() * to_lux, direct_lux)
        })
        .collect();
    let lux: Vec<f64> = values.iter().map(|v| v.0).collect();
    let (min, avg, max, uniformity) = grid_statistics(&lux);
    Ok(GridIlluminance {
        name: grid.name.clone(),
        points,
        direct_lux: values.iter().map(|v| v.1).collect(),
        lux,
        min,
        avg,
        max,
        uniformity,
    })
}
