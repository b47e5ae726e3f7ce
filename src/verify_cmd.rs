//! `radiosity verify`: solve a scene as `solve` would, estimate the same quantities with the
//! independent Monte Carlo reference (`radiosity_reference`), and print both side by side with
//! their difference in per cent and in standard errors (the comparison itself is
//! [`crate::comparison`], the reference runs are [`crate::reference_run`]).

use std::sync::Arc;
use std::time::Duration;

use anyhow::Result;
use clap::Args;
use radiosity_mesh::Mesh;
use radiosity_reference::{EstimateParams, PathBudget, Reference};
use radiosity_solver::{ObjectRadiosity, Problem};
use serde_json::{Value, json};

use crate::comparison::{
    Summary, compare_objects, fmt_pct, fmt_sigma, judged, num, over_whole_area, with_back_faces,
};
use crate::errors::InputError;
use crate::interrupt::Interrupted;
use crate::output::{Targets, write_report};
use crate::prepare::{Prepared, prepare, run_solver};
use crate::progress::spinning;
use crate::reference_run::{compare_elements, reference_progress, report_progress};
use crate::solve_opts::SolveOpts;

/// Arguments of `radiosity verify`.
#[derive(Args)]
pub struct VerifyArgs {
    /// The scene to load: see [`SCENE_HELP`](crate::solve_opts::SCENE_HELP).
    #[arg(help = crate::solve_opts::SCENE_HELP)]
    pub scene: String,
    /// Paths per object for the reference (a fixed count, not cut short by a default time
    /// budget); default: as many as it takes to bring every channel's standard error to
    /// --stderr-target of its mean (at most 2^26), within --reference-time.
    #[arg(long)]
    pub paths: Option<u64>,
    /// Most seconds for the reference, which then reports the precision it reached [default:
    /// --time-limit when given, else 120 without --paths, else none].
    #[arg(long, allow_negative_numbers = true, value_name = "SECONDS")]
    pub reference_time: Option<f64>,
    /// Standard error to reach, relative to the mean, when --paths is not given.
    #[arg(long, default_value_t = 0.001, value_name = "FRACTION")]
    pub stderr_target: f64,
    /// Count at most N reflections in the reference (default: all). With a single-patch
    /// light, `--reflections 1 --max-shots 1` compares the direct light alone: the solver's
    /// form factors and visibility, without the inter-reflection.
    #[arg(long, value_name = "N")]
    pub reflections: Option<u32>,
    /// Also compare a sample of this many elements (default 200 when the flag is given alone):
    /// their solve value against a reference estimate over each element.
    #[arg(long, num_args = 0..=1, default_missing_value = "200", value_name = "N")]
    pub elements: Option<usize>,
    /// Reference paths per sampled element.
    #[arg(long, default_value_t = 65_536, value_name = "N")]
    pub element_paths: u64,
    /// Reference paths per calculation-grid point (scenes with `[[grid]]`).
    #[arg(long, default_value_t = 16_384, value_name = "N")]
    pub grid_paths: u64,
    /// Write the JSON report here (`-` for stdout).
    #[arg(long)]
    pub json: Option<String>,
    /// Overwrite an existing report file.
    #[arg(long)]
    pub force: bool,
    /// Multiply every reflectance the solver sees (not the reference) by this factor: a
    /// deliberately wrong solve, to check that `verify` notices.
    #[arg(long, hide = true)]
    pub solve_reflectance_scale: Option<f64>,
    #[command(flatten)]
    pub solve: SolveOpts,
}

fn input(msg: String) -> anyhow::Error {
    InputError(msg).into()
}

/// Scales the reflectance of every material the mesh carries (and so that the solver sees)
/// by `factor`, leaving the scene — and so the reference — alone: the test hook behind
/// `--solve-reflectance-scale`.
///
/// # Errors
/// A factor that is not finite and > 0, or that takes a reflectance to 1 or above.
pub fn scale_solver_reflectance(mesh: &mut Mesh, factor: f64) -> Result<()> {
    let top = mesh.materials.iter().map(|m| m.reflectance.max_channel()).fold(0.0, f64::max);
    if !(factor.is_finite() && factor > 0.0 && top * factor < 1.0) {
        return Err(input(format!(
            "--solve-reflectance-scale must be > 0 and keep every reflectance below 1, got {factor}"
        )));
    }
    for m in &mut mesh.materials {
        m.reflectance *= factor;
    }
    Ok(())
}

/// Runs `verify`.
pub fn run(a: VerifyArgs) -> Result<()> {
    if a.paths == Some(0) {
        return Err(input("--paths must be at least 1".into()));
    }
    if !(a.stderr_target.is_finite() && a.stderr_target > 0.0 && a.stderr_target < 1.0) {
        return Err(input(format!("--stderr-target must be in (0, 1), got {}", a.stderr_target)));
    }
    if a.element_paths == 0 {
        return Err(input("--element-paths must be at least 1".into()));
    }
    let reference_time = match (a.reference_time, a.solve.time_limit, a.paths) {
        (Some(t), _, _) => {
            if !(t > 0.0 && t <= radiosity_core::MAX_TIME_LIMIT_SECONDS) {
                return Err(input(format!(
                    "--reference-time must be a number of seconds in (0, {:e}], got {t}",
                    radiosity_core::MAX_TIME_LIMIT_SECONDS
                )));
            }
            Some(t)
        }
        // Checked with the solve options.
        (None, Some(t), _) => Some(t),
        (None, None, None) => Some(DEFAULT_REFERENCE_SECONDS),
        // A fixed count asked for is kept whatever it takes: it makes the numbers repeatable.
        (None, None, Some(_)) => None,
    };
    if let Some(path) = &a.json
        && path != "-"
    {
        Targets::new(a.force).file(std::path::Path::new(path), "--json")?;
    }
    // From here a first Ctrl-C stops the step that runs and the table shows what it has.
    crate::interrupt::catch();
    let mut prepared = prepare(&a.scene, &a.solve)?;
    if let Some(k) = a.solve_reflectance_scale {
        // The same mesh and ray queries, only the reflectances the solver sees are scaled.
        let mut mesh = Mesh::clone(prepared.problem.mesh());
        scale_solver_reflectance(&mut mesh, k)?;
        let rays = prepared.problem.ray_queries().clone();
        prepared.problem = Problem::with_ray_queries(Arc::new(mesh), rays)
            .with_luminaires(prepared.scene.lighting.luminaires.clone())
            .with_daylight(prepared.scene.lighting.daylight());
    }
    let (solver, report) = run_solver(&prepared)?;
    let Prepared { scene, problem, .. } = &prepared;
    let mesh = problem.mesh();
    let solution = solver.solution();
    let fronts = over_whole_area(solution.object_radiosity(mesh), &mesh.hidden_area);
    let front_count = fronts.len();
    let solved = with_back_faces(fronts);
    let solve_secs = report.elapsed.as_secs_f64();
    let stop = report.stop_reason.map_or("running", |s| s.as_str());
    crate::output::note(format_args!(
        "{}: solved {} patches, {} elements, {} shots, {:.3} s, unshot {:.4} %, {}",
        scene.name,
        mesh.patches.len(),
        mesh.elements.len(),
        report.total_shots,
        solve_secs,
        report.unshot_fraction * 100.0,
        stop
    ))?;

    if crate::interrupt::requested() {
        return interrupted_solve(&a, &solved, &report);
    }

    let reference = spinning("preparing the reference", || Reference::new(scene));
    let budget = match a.paths {
        Some(paths) => PathBudget::Fixed { paths },
        None => PathBudget::Adaptive { relative_stderr: a.stderr_target, max_paths: 1 << 26 },
    };
    let time_limit = reference_time.map(Duration::from_secs_f64);
    let max_reflections = a.reflections.unwrap_or(u32::MAX);
    let params = EstimateParams { budget, seed: a.solve.seed, time_limit, max_reflections };
    let goal = match a.paths {
        Some(paths) => format!("{paths} paths per object"),
        None => format!("every object to {} % standard error", a.stderr_target * 100.0),
    };
    let limit = match reference_time {
        Some(t) if a.reference_time.is_none() && a.solve.time_limit.is_none() => {
            format!(", at most {t} s (the default budget; --reference-time S for another)")
        }
        Some(t) => format!(", at most {t} s"),
        None => String::new(),
    };
    crate::output::note(format_args!(
        "reference: path tracing {goal}{limit}; Ctrl-C stops it and shows what it has"
    ))?;
    let progress = reference_progress("reference");
    let estimates = reference.estimate_objects_until(
        &params,
        &|p| report_progress(&progress, p),
        &crate::interrupt::requested,
    );
    drop(progress);
    let interrupted = crate::interrupt::requested();
    let ref_secs = estimates.elapsed.as_secs_f64();
    let rows = compare_objects(&estimates, &solved, interrupted)?;

    // The table: luminance for the eye, per-channel differences beside it.
    let mut table = format!(
        "{:<20} {:>10} {:>11} {:>11} {:>9} {:>8} {:>8}   {:>22}\n",
        "object", "area", "solve Y", "reference Y", "± σ %", "diff %", "diff σ", "diff % [r g b]"
    );
    for (o, c) in solved.iter().zip(&rows) {
        let rel_se = if c.reference.luminance > 0.0 {
            c.reference.luminance_stderr / c.reference.luminance * 100.0
        } else {
            0.0
        };
        let per = c.percent().map(fmt_pct);
        table += &format!(
            "{:<20} {:>10.4e} {:>11.5e} {:>11.5e} {:>9.3} {:>8} {:>8}   {:>7} {:>7} {:>7}\n",
            o.name,
            o.area,
            c.solve.luminance(),
            c.reference.luminance,
            rel_se,
            fmt_pct(c.luminance_percent()),
            fmt_sigma(c.luminance_sigma()),
            per[0],
            per[1],
            per[2]
        );
    }
    let judged = judged(&rows);
    // Back faces (the insides of models, the far sides of two-sided sheets) get little
    // light and large relative differences; summed with the front faces they would set the
    // median a reader takes for the whole scene, so each side is summed on its own too.
    let all = Summary::of(&judged, &solved);
    let (front, back): (Vec<(usize, f64, f64)>, _) = judged.iter().partition(|j| j.0 < front_count);
    let sides = (!back.is_empty()).then(|| (Summary::of(&front, &solved), Summary::of(&back, &solved)));
    let summary = match &sides {
        None => all.text.clone(),
        Some((front, back)) => format!("front faces: {}\nback faces: {}", front.text, back.text),
    };
    table += &summary;
    table.push('\n');

    // A sample of elements: local errors (shadow edges, contacts) that object means hide.
    let mut element_part = match a.elements {
        Some(count) if count > 0 && !crate::interrupt::requested() => Some(compare_elements(
            &reference,
            mesh,
            &solution.element_radiosity,
            count,
            a.element_paths,
            a.solve.seed,
            max_reflections,
        )?),
        _ => None,
    };
    if let Some(part) = &mut element_part {
        table += &part.text;
        // Centres in the file's frame, as the user's tools show the model.
        if let Some(elements) = part.json["elements"].as_array_mut() {
            for e in elements {
                if let Ok(c) = serde_json::from_value::<[f64; 3]>(e["centre"].take()) {
                    e["centre"] =
                        json!(prepared.up.from_y_up(radiosity_core::glam::DVec3::from_array(c)).to_array());
                }
            }
        }
    }
    // Calculation grids: Em, Emin and U0 of the solve against the path tracer's.
    let grid_part = if prepared.scene.lighting.grids.is_empty() || crate::interrupt::requested() {
        None
    } else {
        let grids = crate::lighting_cmd::compute_grids(&prepared, &solution)?;
        let (text, json) = crate::lighting_cmd::verify_grids(
            &prepared,
            &reference,
            &grids,
            a.grid_paths.max(1),
            a.solve.seed,
        );
        table += &text;
        Some(json)
    };
    if a.json.as_deref() != Some("-") {
        let mut out = std::io::stdout().lock();
        match std::io::Write::write_all(&mut out, table.as_bytes())
            .and_then(|()| std::io::Write::flush(&mut out))
        {
            Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => return Err(e.into()),
            _ => {}
        }
    }
    if let Some(path) = &a.json {
        let objects: Vec<Value> = solved
            .iter()
            .zip(&rows)
            .zip(&estimates.objects)
            .map(|((o, c), r)| {
                json!({
                    "name": o.name,
                    "area": o.area,
                    "radiosity": o.radiosity.to_array(),
                    "reference": c.reference.mean.to_array(),
                    "stderr": c.reference.stderr.to_array(),
                    "paths": r.estimate.paths,
                    "difference_percent": c.percent().map(|p| p.map_or(Value::Null, num)),
                    "difference_sigma": c.sigma().map(num),
                    "luminance": {
                        "radiosity": c.solve.luminance(),
                        "reference": c.reference.luminance,
                        "stderr": c.reference.luminance_stderr,
                        "difference_percent": c.luminance_percent().map_or(Value::Null, num),
                        "difference_sigma": num(c.luminance_sigma()),
                    },
                })
            })
            .collect();
        let mut doc = json!({
            "scene": scene.name,
            "patches": mesh.patches.len(),
            "elements": mesh.elements.len(),
            "shots": report.total_shots,
            "unshot_fraction": report.unshot_fraction,
            "stop_reason": stop,
            "solve_seconds": solve_secs,
            "paths": estimates.paths,
            "seconds": ref_secs,
            "timed_out": estimates.timed_out,
            "seed": a.solve.seed,
            "reflections": a.reflections,
            "reference_time_limit": reference_time,
            "interrupted": crate::interrupt::requested(),
            "objects": objects,
            "summary": all.json(&summary),
        });
        if let Some((front, back)) = &sides {
            doc["summary"]["front_faces"] = front.json(&front.text);
            doc["summary"]["back_faces"] = back.json(&back.text);
        }
        if let Some(part) = element_part {
            doc["element_sample"] = part.json;
        }
        if let Some(grids) = grid_part {
            doc["grids"] = grids;
        }
        write_report(path, a.force, &serde_json::to_string_pretty(&doc)?)?;
    }
    if crate::interrupt::requested() {
        return Err(Interrupted("the reference stopped early; the table holds what it had".into()).into());
    }
    Ok(())
}

/// Seconds the reference takes at most by default: with a solve of a few minutes, a
/// 100 k-triangle room is verified within five, and every object of such a room gets under
/// a few tenths of a per cent of standard error.
pub const DEFAULT_REFERENCE_SECONDS: f64 = 120.0;

/// What `verify` prints when Ctrl-C stopped the solve: the solve's means so far, no
/// reference.
fn interrupted_solve(
    a: &VerifyArgs,
    solved: &[ObjectRadiosity],
    report: &radiosity_solver::StepReport,
) -> Result<()> {
    let mut table = format!("{:<20} {:>10} {:>11}\n", "object", "area", "solve Y");
    for o in solved {
        table += &format!("{:<20} {:>10.4e} {:>11.5e}\n", o.name, o.area, o.radiosity.luminance());
    }
    if a.json.as_deref() != Some("-") {
        crate::output::stdout(&table)?;
    }
    Err(Interrupted(format!(
        "the solve stopped at {} shots (unshot {:.3} %); the reference was not run",
        report.total_shots,
        report.unshot_fraction * 100.0
    ))
    .into())
}
