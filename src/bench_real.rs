//! `radiosity bench --real SCENE`: a real room (a public model with a lamp placed by
//! `scripts/real_rooms.py`, or any scene the CLI takes) loaded, meshed and solved exactly as
//! `solve` does with no options, then judged against `verify`'s path tracer.
//!
//! One solve gives both convergence figures: it shoots one shot per step and notes the
//! solve time at which the unshot fraction first falls to 1 % and then to 0.1 %. The peak
//! heap covers loading, meshing and solving (not the reference, which is `verify`'s cost,
//! not the renderer's). The comparison is `verify`'s per-object one, summed only over the
//! objects with at least 1 % of the scene's area: a real model has hundreds of small parts
//! (screws, leaves, picture frames) whose few reference paths in a time budget make their
//! differences mostly noise, and whose median would then measure the budget, not the solver.

use std::time::{Duration, Instant};

use anyhow::Result;
use radiosity_reference::{EstimateParams, PathBudget, Reference};
use radiosity_solver::{StepBudget, StepReport};
use serde_json::{Value, json};

use crate::alloc;
use crate::comparison::{Comparison, Summary};
use crate::errors::InputError;
use crate::output;
use crate::prepare::{Prepared, prepare};
use crate::solve_opts::SolveOpts;

/// The first unshot fraction whose crossing is timed: "good enough to look at" (`bench
/// --big` solves to it).
const COARSE: f64 = 1e-2;
/// The second, where the solve stops: `solve`'s default threshold.
const FINE: f64 = 1e-3;

/// Objects with less than this share of the scene's (front-face) area are left out of the
/// summary (see the module notes).
const MIN_AREA_SHARE: f64 = 0.01;

/// Longest reference budget accepted, seconds: a day; more is a typo, not a benchmark.
const MAX_REFERENCE_SECONDS: f64 = 86_400.0;

/// `solve`'s options with no flag given: read from clap itself, so that a default changed
/// there is the default here too.
fn solve_defaults() -> SolveOpts {
    #[derive(clap::Parser)]
    struct Defaults {
        #[command(flatten)]
        solve: SolveOpts,
    }
    <Defaults as clap::Parser>::parse_from(["radiosity"]).solve
}

/// Checks `--real-reference-seconds` before any case runs, so a typo costs no solve.
///
/// # Errors
/// A budget that is not a finite number of seconds in (0, a day] (exit code 2).
pub fn check_reference_seconds(seconds: f64) -> Result<()> {
    if seconds.is_finite() && seconds > 0.0 && seconds <= MAX_REFERENCE_SECONDS {
        Ok(())
    } else {
        Err(InputError(format!(
            "--real-reference-seconds must be a number of seconds in (0, {MAX_REFERENCE_SECONDS}], got {seconds}"
        ))
        .into())
    }
}

/// The header of the table the rows of [`real_case`] go under.
pub fn header() -> String {
    format!(
        "(f) real rooms: solved as `solve` does, against `verify`'s path tracer (objects ≥ {:.0} % of the area)\n{:<28} {:>8} {:>7} {:>7} {:>8} {:>7} {:>8} {:>8} {:>8} {:>9} {:>8} {:>8} {:>8} {:>7}\n",
        MIN_AREA_SHARE * 100.0,
        "scene",
        "tris",
        "surfs",
        "patches",
        "elements",
        "mesh s",
        "1 % s",
        "0.1 % s",
        "heap MB",
        "residual",
        "median %",
        "worst %",
        "area %",
        ">3σ",
    )
}

/// Steps `solver` one shot at a time until it stops, noting the solve time of the first
/// report at or below each of [`COARSE`] and [`FINE`], with a progress line on stderr every
/// [`LOG_INTERVAL`](crate::progress::LOG_INTERVAL), as `solve` gives when not on a terminal:
/// a big room takes minutes, and a silent benchmark looks hung.
///
/// # Errors
/// stderr cannot be written.
fn timed_solve(solver: &mut radiosity_solver::Solver) -> Result<(StepReport, Option<f64>, Option<f64>)> {
    let (mut coarse, mut fine) = (None, None);
    let mut last_log = Instant::now();
    loop {
        // A shot per step: the crossing is timed to the shot, and a step's own cost (a stop
        // check and a clock read) is nothing next to a shot over the whole mesh.
        let r = solver.step(StepBudget::Shots(1));
        let secs = r.elapsed.as_secs_f64();
        if coarse.is_none() && r.unshot_fraction <= COARSE {
            coarse = Some(secs);
        }
        if fine.is_none() && r.unshot_fraction <= FINE {
            fine = Some(secs);
        }
        if r.stop_reason.is_some() {
            return Ok((r, coarse, fine));
        }
        if last_log.elapsed() >= crate::progress::LOG_INTERVAL {
            last_log = Instant::now();
            output::note(format_args!(
                "[{secs:.0} s] solving: {} shots, unshot {:.3} %",
                r.total_shots,
                r.unshot_fraction * 100.0
            ))?;
        }
    }
}

/// `(name, area, luminance difference %, difference σ, reference paths)` of the `judged`
/// objects, largest first, for the JSON.
fn compared_objects(
    judged: &[(usize, f64, f64)],
    solved: &[radiosity_solver::ObjectRadiosity],
    rows: &[Comparison],
) -> Value {
    let mut order: Vec<&(usize, f64, f64)> = judged.iter().collect();
    order.sort_by(|x, y| solved[y.0].area.total_cmp(&solved[x.0].area));
    Value::Array(
        order
            .into_iter()
            .map(|&(i, p, z)| {
                json!({
                    "name": solved[i].name,
                    "area": solved[i].area,
                    "radiosity_luminance": rows[i].solve.luminance(),
                    "reference_luminance": rows[i].reference.luminance,
                    "difference_percent": crate::comparison::num(p),
                    "difference_sigma": crate::comparison::num(z),
                    "paths": rows[i].reference.paths,
                })
            })
            .collect(),
    )
}

fn fmt_secs(s: Option<f64>) -> String {
    s.map_or_else(|| "—".into(), |s| format!("{s:.2}"))
}

fn fmt_pct(p: Option<f64>) -> String {
    p.map_or_else(|| "—".into(), |p| format!("{p:+.2}"))
}

/// One real room: load, mesh, solve to 0.1 % unshot (timing 1 % on the way), audit the
/// energy, estimate every object with the reference for `reference_seconds`, and print the
/// row; returns the case's JSON.
///
/// # Errors
/// Scenes that do not load or solve (exit code 2), output that cannot be written.
pub fn real_case(scene_arg: &str, reference_seconds: f64) -> Result<Value> {
    let opts = solve_defaults();
    alloc::reset_peak();
    let before = alloc::live();
    let start = Instant::now();
    // `solve`'s own path with no flags: the same loading, sealing, mesh settings and solver
    // settings, so the figures are those a user of `solve` gets.
    let mut prepared = prepare(scene_arg, &opts)?;
    let mesh_secs = start.elapsed().as_secs_f64();
    // Both stops are timed in one solve: down to 0.1 % whatever the scene file says (its
    // shot or time limits still apply, and then the row says where it stopped).
    prepared.params.unshot_threshold = FINE;
    let Prepared { scene, problem, params, .. } = &prepared;
    let mesh = problem.mesh();
    let triangles = mesh.occluders.len();
    let (surfaces, patches, elements) = (mesh.surfaces.len(), mesh.patches.len(), mesh.elements.len());
    let mut solver = problem.solver(params.clone())?;
    let (report, coarse, fine) = timed_solve(&mut solver)?;
    let energy = solver.energy();
    let objects = solver.object_radiosity();
    drop(solver);
    let peak = alloc::peak().saturating_sub(before);
    let stop = report.stop_reason.map_or("running", |s| s.as_str());
    output::note(format_args!(
        "{}: solved {patches} patches, {elements} elements, {} shots, {:.2} s, unshot {:.4} %, {stop}",
        scene.name,
        report.total_shots,
        report.elapsed.as_secs_f64(),
        report.unshot_fraction * 100.0
    ))?;

    // `verify`'s comparison: the same per-object means (spread over the whole input area,
    // back faces as objects of their own) against the reference's.
    let fronts = crate::comparison::over_whole_area(objects, &mesh.hidden_area);
    let front_count = fronts.len();
    let front_area: f64 = fronts.iter().map(|o| o.area).sum();
    let solved = crate::comparison::with_back_faces(fronts);
    let reference = Reference::new(scene);
    let ref_params = EstimateParams {
        budget: PathBudget::Adaptive { relative_stderr: 0.001, max_paths: 1 << 26 },
        seed: opts.seed,
        time_limit: Some(Duration::from_secs_f64(reference_seconds)),
        max_reflections: u32::MAX,
    };
    let progress = crate::reference_run::reference_progress("reference");
    let estimates =
        reference.estimate_objects(&ref_params, &|p| crate::reference_run::report_progress(&progress, p));
    drop(progress);
    let ref_secs = estimates.elapsed.as_secs_f64();
    let rows = crate::comparison::compare_objects(&estimates, &solved, false)?;
    let judged = crate::comparison::judged(&rows);
    let large: Vec<(usize, f64, f64)> =
        judged.iter().copied().filter(|&(i, ..)| solved[i].area >= MIN_AREA_SHARE * front_area).collect();
    let (front, back): (Vec<_>, Vec<_>) = large.iter().partition(|j| j.0 < front_count);
    let front = Summary::of(&front, &solved);
    let back = (!back.is_empty()).then(|| Summary::of(&back, &solved));

    // The worst channel's round-off: what the audit says about energy the solve lost or made.
    let residual = energy.residual().to_array().iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    let name: String = scene.name.chars().take(28).collect();
    let mut row = format!(
        "{name:<28} {triangles:>8} {surfaces:>7} {patches:>7} {elements:>8} {mesh_secs:>7.2} {:>8} {:>8} {:>8.0} {residual:>9.1e} {:>8} {:>8} {:>8} {:>7}\n",
        fmt_secs(coarse),
        fmt_secs(fine),
        peak as f64 / 1e6,
        front.median_abs.map_or_else(|| "—".into(), |m| format!("{m:.2}")),
        fmt_pct(front.worst.as_ref().map(|w| w.1)),
        fmt_pct(front.area_weighted),
        format!("{}/{}", front.over, front.objects),
    );
    row += &format!("    front faces: {}\n", front.text);
    if let Some(back) = &back {
        row += &format!("    back faces: {}\n", back.text);
    }
    row += &format!(
        "    {} objects compared of {}; reference {:.1} M paths in {:.0} s{}; solve stopped: {stop} at unshot {:.2e}\n",
        large.len(),
        rows.len(),
        estimates.paths as f64 / 1e6,
        ref_secs,
        if estimates.timed_out { " (time limit)" } else { "" },
        report.unshot_fraction,
    );
    output::stdout(&row)?;

    let mut summary = json!({"front_faces": front.json(&front.text)});
    if let Some(back) = &back {
        summary["back_faces"] = back.json(&back.text);
    }
    Ok(json!({
        "case": "real",
        "scene": scene_arg,
        "name": scene.name,
        "triangles": triangles,
        "surfaces": surfaces,
        "patches": patches,
        "elements": elements,
        "load_mesh_seconds": mesh_secs,
        "seconds_to_1_percent": coarse.map_or(Value::Null, crate::comparison::num),
        "seconds_to_0_1_percent": fine.map_or(Value::Null, crate::comparison::num),
        "solve_seconds": report.elapsed.as_secs_f64(),
        "shots": report.total_shots,
        "rays": report.rays,
        "unshot_fraction": report.unshot_fraction,
        "stop_reason": stop,
        "peak_heap_bytes": peak,
        "energy": output::energy_json(&energy),
        "reference": {
            "seconds_budget": reference_seconds,
            "seconds": ref_secs,
            "paths": estimates.paths,
            "timed_out": estimates.timed_out,
            "seed": opts.seed,
        },
        "min_area_share": MIN_AREA_SHARE,
        // The compared objects one by one, largest first: which parts of a room are off.
        "objects": compared_objects(&large, &solved, &rows),
        "objects_total": rows.len(),
        "objects_compared": large.len(),
        "summary": summary,
    }))
}
