//! `radiosity solve`: headless solve, summary and JSON report.

use anyhow::Result;
use clap::Args;
use serde_json::json;

use crate::output::{self, Targets};
use crate::prepare::{Prepared, prepare, run_solver};
use crate::solve_opts::SolveOpts;

/// Arguments of `radiosity solve`.
#[derive(Args)]
pub struct SolveArgs {
    /// The scene to load: see [`SCENE_HELP`](crate::solve_opts::SCENE_HELP).
    #[arg(help = crate::solve_opts::SCENE_HELP)]
    pub scene: String,
    /// Write the JSON report here (`-` for stdout).
    #[arg(long)]
    pub json: Option<String>,
    /// Write every calculation grid's illuminance here as CSV (`grid,x,y,z,lux`).
    #[arg(long, value_name = "FILE")]
    pub grid_csv: Option<String>,
    /// Overwrite an existing report file.
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub solve: SolveOpts,
}

/// Runs `solve`.
pub fn run(a: SolveArgs) -> Result<()> {
    // The report's target is checked before the solve, so no solve is lost to it.
    let mut targets = Targets::new(a.force);
    if let Some(path) = &a.json
        && path != "-"
    {
        targets.file(std::path::Path::new(path), "--json")?;
    }
    if let Some(path) = &a.grid_csv {
        targets.file(std::path::Path::new(path), "--grid-csv")?;
    }
    let prepared = prepare(&a.scene, &a.solve)?;
    let (solver, report) = run_solver(&prepared)?;
    let Prepared { scene, problem, .. } = &prepared;
    let mesh = problem.mesh();
    let objects = solver.object_radiosity();
    let energy = solver.energy();
    let grids = if scene.lighting.grids.is_empty() {
        Vec::new()
    } else {
        crate::lighting_cmd::compute_grids(&prepared, &solver.solution())?
    };
    drop(solver);
    let secs = report.elapsed.as_secs_f64();
    let stop = report.stop_reason.map_or("running", |s| s.as_str());
    // The source document's figures (S13): facets, iterations, time.
    output::note(format_args!(
        "{}: {} patches, {} elements, {} shots, {:.3} s, {} rays ({:.2} M rays/s), unshot {:.4} %, {}",
        scene.name,
        mesh.patches.len(),
        mesh.elements.len(),
        report.total_shots,
        secs,
        report.rays,
        report.rays as f64 / secs.max(1e-9) / 1e6,
        report.unshot_fraction * 100.0,
        stop
    ))?;
    // The parts of surfaces that solids stand on are left out of the mesh: an object's mean is
    // over what was meshed, where `verify` spreads it over the whole input area.
    let covered: Vec<(usize, f64)> =
        mesh.hidden_area.iter().copied().enumerate().filter(|&(_, h)| h > 0.0).collect();
    if !covered.is_empty() {
        let total: f64 = covered.iter().map(|&(_, h)| h).sum();
        let who = match covered.len() {
            1 => "1 object has parts covered by solids standing on it".to_owned(),
            n => format!("{n} objects have parts covered by solids standing on them"),
        };
        output::note(format_args!(
            "note: {who} ({total:.4e} unit² in all), left out of the solve: means are over the \
             meshed area (`verify` spreads them over the whole input area; the JSON's covered_area)"
        ))?;
    }
    if a.json.as_deref() != Some("-") {
        let mut table = format!(
            "{:<24} {:>12} {:>36} {:>36}\n",
            "object", "area", "emitted power [r g b]", "mean radiosity [r g b]"
        );
        for o in &objects {
            let f = |c: radiosity_core::Rgb| format!("{:>11.4e} {:>11.4e} {:>11.4e}", c.r, c.g, c.b);
            table += &format!(
                "{:<24} {:>12.4e} {:>36} {:>36}\n",
                o.name,
                o.area,
                f(o.emitted_power),
                f(o.radiosity)
            );
            if let Some(back) = o.radiosity_back {
                table += &format!("{:<24} {:>12} {:>36} {:>36}\n", "  (back face)", "", "", f(back));
            }
        }
        if !grids.is_empty() {
            table += &crate::lighting_cmd::grid_table(&grids, crate::lighting_cmd::sky_lux(&prepared.scene));
        }
        output::stdout(&table)?;
    }
    if let Some(path) = &a.grid_csv {
        crate::lighting_cmd::write_grid_csv(std::path::Path::new(path), a.force, &prepared, &grids)?;
    }
    if let Some(path) = &a.json {
        let mut doc = json!({
            "scene": scene.name,
            "patches": mesh.patches.len(),
            "elements": mesh.elements.len(),
            "shots": report.total_shots,
            "unshot_fraction": report.unshot_fraction,
            "stop_reason": stop,
            "seconds": secs,
            "rays": report.rays,
            "energy": output::energy_json(&energy),
            "objects": objects.iter().enumerate().map(|(i, o)| {
                let mut entry = json!({
                    "name": o.name,
                    "area": o.area,
                    "emitted_power": o.emitted_power.to_array(),
                    "radiosity": o.radiosity.to_array(),
                });
                if let Some(back) = o.radiosity_back {
                    entry["radiosity_back"] = json!(back.to_array());
                }
                if let Some(&hidden) = mesh.hidden_area.get(i).filter(|&&h| h > 0.0) {
                    entry["covered_area"] = json!(hidden);
                }
                if scene.lighting.is_photometric() {
                    let (luminance, illuminance) = crate::lighting_cmd::object_photometry(scene, i, o);
                    entry["luminance"] = json!(luminance);
                    entry["illuminance"] = json!(illuminance);
                }
                entry
            }).collect::<Vec<_>>(),
        });
        if scene.lighting.is_photometric() {
            let lighting = crate::lighting_cmd::lighting_json(&prepared, &grids);
            for key in ["units", "luminaires", "grids", "sky_lux"] {
                doc[key] = lighting[key].clone();
            }
        }
        let text = serde_json::to_string_pretty(&doc)? + "\n";
        if path == "-" {
            output::stdout(&text)?;
        } else {
            output::write_file(std::path::Path::new(path), a.force, text.as_bytes())?;
        }
    }
    Ok(())
}
