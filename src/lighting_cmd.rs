//! Photometric reports shared by `solve` and `verify`: calculation grids in lux, the
//! luminaires with their flux, the scene's unit; the grid CSV; grids against the path
//! tracer.

use std::path::Path;

use anyhow::Result;
use radiosity_core::glam::DVec3;
use radiosity_image::{GridIlluminance, GridParams, Renderer, grid_illuminance, grid_statistics};
use radiosity_reference::{EstimateParams, PathBudget, Reference};
use radiosity_solver::Solution;
use serde_json::{Value, json};

use crate::prepare::Prepared;
use crate::progress::spinning;

/// The illuminance of every grid of the scene (none without grids).
///
/// # Errors
/// A solution that is not for the prepared mesh (a bug).
pub fn compute_grids(prepared: &Prepared, solution: &Solution) -> Result<Vec<GridIlluminance>> {
    let grids = &prepared.scene.lighting.grids;
    if grids.is_empty() {
        return Ok(Vec::new());
    }
    let renderer = Renderer::new(prepared.problem.mesh().clone());
    let blockers = prepared.problem.ray_queries().as_ref();
    let params = GridParams { seed: prepared.params.seed, ..GridParams::default() };
    spinning("calculation grids", || {
        grids
            .iter()
            .map(|g| {
                grid_illuminance(&renderer, solution, blockers, &prepared.scene.lighting, g, &params)
                    .map_err(anyhow::Error::from)
            })
            .collect()
    })
}

/// Illuminance of the scene's sky on an open horizontal plane, lx (`None` without a sky):
/// what daylight factors are taken against (CIE overcast sky; EN 17037).
pub fn sky_lux(scene: &radiosity_core::Scene) -> Option<f64> {
    let to_lux = scene.lighting.unit().lux_per_irradiance();
    scene.lighting.sky.as_ref().map(|s| s.horizontal_irradiance().luminance() * to_lux).filter(|&e| e > 0.0)
}

/// One line per grid: Em, Emin, Emax, U0, and with a sky (`sky_lux`, see [`sky_lux`]) the
/// mean daylight factor Em / E_sky.
pub fn grid_table(grids: &[GridIlluminance], sky_lux: Option<f64>) -> String {
    let df = |g: &GridIlluminance| sky_lux.map_or(String::new(), |e| format!(" {:>7.2}", 100.0 * g.avg / e));
    let mut t = format!(
        "{:<24} {:>7} {:>10} {:>10} {:>10} {:>7}{}\n",
        "grid",
        "points",
        "Em lx",
        "Emin lx",
        "Emax lx",
        "U0",
        if sky_lux.is_some() { format!(" {:>7}", "DF %") } else { String::new() }
    );
    for g in grids {
        t += &format!(
            "{:<24} {:>7} {:>10.1} {:>10.1} {:>10.1} {:>7.3}{}\n",
            g.name,
            g.lux.len(),
            g.avg,
            g.min,
            g.max,
            g.uniformity,
            df(g)
        );
    }
    t
}

/// The report's `units`, `luminaires` and `grids` (positions in the file's frame).
pub fn lighting_json(prepared: &Prepared, grids: &[GridIlluminance]) -> Value {
    let lighting = &prepared.scene.lighting;
    let up = prepared.up;
    let file = |p: DVec3| up.from_y_up(p).to_array();
    let sky = sky_lux(&prepared.scene);
    json!({
        "units": lighting.unit().as_str(),
        "luminaires": lighting.luminaires.iter().map(|l| json!({
            "name": l.name,
            "position": file(l.position),
            "aim": file(l.nadir),
            "lumens": l.flux(),
            "max_candela": l.scale * l.table.max_candela(),
            "opening": json!({
                "length": l.opening.length,
                "width": l.opening.width,
                "round": l.opening.round,
            }),
        })).collect::<Vec<_>>(),
        "grids": grids.iter().map(|g| json!({
            "name": g.name,
            "unit": "lx",
            "points": g.points.iter().zip(&g.lux).zip(&g.direct_lux).map(|((p, e), d)| json!({
                "position": file(*p),
                "illuminance": e,
                "direct": d,
            })).collect::<Vec<_>>(),
            "min": g.min,
            "avg": g.avg,
            "max": g.max,
            "uniformity": g.uniformity,
            "daylight_factor": sky.map(|e| 100.0 * g.avg / e),
        })).collect::<Vec<_>>(),
        "sky_lux": sky,
    })
}

/// Object `index`'s mean luminance (cd/m²) and mean illuminance (lx) from its mean
/// radiosity `o` (front face): L = Y(B) / π and E = Y((B − emission) / ρ), the latter `None`
/// where a channel's reflectance is 0 (a black surface tells nothing of its light) or the
/// object is not a scene object of one material.
pub fn object_photometry(
    scene: &radiosity_core::Scene,
    index: usize,
    o: &radiosity_solver::ObjectRadiosity,
) -> (f64, Option<f64>) {
    let to_lux = scene.lighting.unit().lux_per_irradiance();
    let luminance = o.radiosity.luminance() * to_lux / std::f64::consts::PI;
    let illuminance = scene.objects.get(index).and_then(|object| {
        let m = &scene.materials[object.material];
        let rho = m.reflectance;
        (rho.min_channel() > 0.0 && object.name == o.name)
            .then(|| (o.radiosity - m.emission).zip_map(rho, |b, r| b / r).luminance() * to_lux)
    });
    (luminance, illuminance)
}

/// The grids as CSV: `grid,x,y,z,lux`, positions in the file's frame.
pub fn grid_csv(prepared: &Prepared, grids: &[GridIlluminance]) -> String {
    let mut s = String::from("grid,x,y,z,lux\n");
    for g in grids {
        let name = g.name.replace(['"', ','], " ");
        for (p, e) in g.points.iter().zip(&g.lux) {
            let p = prepared.up.from_y_up(*p);
            s += &format!("{name},{},{},{},{e:.3}\n", p.x, p.y, p.z);
        }
    }
    s
}

/// Writes [`grid_csv`] to `path`.
///
/// # Errors
/// As [`crate::output::write_file`].
pub fn write_grid_csv(
    path: &Path,
    force: bool,
    prepared: &Prepared,
    grids: &[GridIlluminance],
) -> Result<()> {
    crate::output::write_file(path, force, grid_csv(prepared, grids).as_bytes())?;
    crate::output::note(format_args!("wrote {}", path.display()))
}

/// The grids' Em, Emin and U0 from the solve against the path tracer's (`paths` per point),
/// as table text and JSON.
pub fn verify_grids(
    prepared: &Prepared,
    reference: &Reference,
    grids: &[GridIlluminance],
    paths: u64,
    seed: u64,
) -> (String, Value) {
    let to_lux = prepared.scene.lighting.unit().lux_per_irradiance();
    let mut text = format!(
        "{:<16} {:>9} {:>9} {:>7} {:>9} {:>9} {:>7} {:>7} {:>7} {:>7}\n",
        "grid", "Em", "ref Em", "± σ %", "Emin", "ref Emin", "U0", "ref U0", "Em %", "Emin %"
    );
    let mut out = Vec::new();
    for g in grids {
        let normal =
            prepared.scene.lighting.grids.iter().find(|d| d.name == g.name).map_or(DVec3::Y, |d| d.normal);
        let points: Vec<(DVec3, DVec3)> = g.points.iter().map(|&p| (p, normal)).collect();
        let params = EstimateParams {
            budget: PathBudget::Fixed { paths },
            seed,
            time_limit: None,
            max_reflections: u32::MAX,
        };
        let estimates = spinning(&format!("reference grid '{}'", g.name), || {
            reference.estimate_points(&points, &params, &|_| {}, &crate::interrupt::requested)
        });
        let lux: Vec<f64> = estimates.iter().map(|e| e.luminance * to_lux).collect();
        let se: Vec<f64> = estimates.iter().map(|e| e.luminance_stderr * to_lux).collect();
        let (rmin, ravg, _, ru0) = grid_statistics(&lux);
        // The mean's standard error: independent points.
        let avg_se = (se.iter().map(|s| s * s).sum::<f64>()).sqrt() / se.len().max(1) as f64;
        let pct = |a: f64, b: f64| if b > 0.0 { (a / b - 1.0) * 100.0 } else { 0.0 };
        text += &format!(
            "{:<16} {:>9.1} {:>9.1} {:>7.3} {:>9.1} {:>9.1} {:>7.3} {:>7.3} {:>+7.2} {:>+7.2}\n",
            g.name,
            g.avg,
            ravg,
            if ravg > 0.0 { avg_se / ravg * 100.0 } else { 0.0 },
            g.min,
            rmin,
            g.uniformity,
            ru0,
            pct(g.avg, ravg),
            pct(g.min, rmin)
        );
        let max_point_diff = g.lux.iter().zip(&lux).map(|(a, b)| pct(*a, *b).abs()).fold(0.0, f64::max);
        out.push(json!({
            "name": g.name,
            "paths_per_point": paths,
            "solve": {"min": g.min, "avg": g.avg, "max": g.max, "uniformity": g.uniformity},
            "reference": {"min": rmin, "avg": ravg, "uniformity": ru0, "avg_stderr": avg_se},
            "avg_difference_percent": pct(g.avg, ravg),
            "min_difference_percent": pct(g.min, rmin),
            "largest_point_difference_percent": max_point_diff,
        }));
    }
    (text, Value::Array(out))
}
