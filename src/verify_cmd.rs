//! `radiosity verify`: solve a scene as `solve` would, estimate the same quantities with the
//! independent Monte Carlo reference (`radiosity_reference`), and print both side by side with
//! their difference in per cent and in standard errors; and the reference picture behind
//! `render --reference`.

use std::sync::Arc;
use std::time::Duration;

use anyhow::Result;
use clap::Args;
use radiosity_core::random::Rng;
use radiosity_core::{Camera, Mesh, Rgb};
use radiosity_image::HdrImage;
use radiosity_reference::{Estimate, EstimateParams, PathBudget, PictureParams, Reference, Region};
use radiosity_solver::{ObjectRadiosity, Problem};
use serde_json::{Value, json};

use crate::interrupt::Interrupted;
use crate::output::{Targets, write_report};
use crate::prepare::{InputError, Prepared, SolveOpts, prepare, run_solver};
use crate::progress::{Progress, spinning};

/// Arguments of `radiosity verify`.
#[derive(Args)]
pub struct VerifyArgs {
    /// The scene to load: see [`SCENE_HELP`](crate::prepare::SCENE_HELP).
    #[arg(help = crate::prepare::SCENE_HELP)]
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

/// `objects`, then the back face of every two-sided one as an object of its own named
/// `NAME (back)`: the order of [`Reference::objects`].
pub(crate) fn with_back_faces(objects: Vec<ObjectRadiosity>) -> Vec<ObjectRadiosity> {
    let backs: Vec<ObjectRadiosity> = objects
        .iter()
        .filter_map(|o| {
            Some(ObjectRadiosity {
                name: format!("{} (back)", o.name),
                area: o.area,
                emitted_power: Rgb::ZERO,
                radiosity: o.radiosity_back?,
                radiosity_back: None,
            })
        })
        .collect();
    objects.into_iter().chain(backs).collect()
}

/// Each object's means spread over its whole input area: the mesh leaves out what solids
/// standing on a surface cover (`Mesh::hidden_area`), while the reference samples the whole
/// input polygon, whose covered part no light reaches (it sees only the inside of the solid).
pub(crate) fn over_whole_area(mut objects: Vec<ObjectRadiosity>, hidden: &[f64]) -> Vec<ObjectRadiosity> {
    for (o, &hidden) in objects.iter_mut().zip(hidden) {
        let whole = o.area + hidden;
        if hidden > 0.0 && whole > 0.0 {
            let f = o.area / whole;
            o.radiosity *= f;
            o.radiosity_back = o.radiosity_back.map(|b| b * f);
            o.area = whole;
        }
    }
    objects
}

/// The reference's progress display ([`report_progress`] feeds it).
pub(crate) fn reference_progress(what: &str) -> Progress {
    Progress::bar(what, 0, "")
}

/// Shows the reference's paths done of those planned, its rate and an ETA.
pub(crate) fn report_progress(progress: &Progress, p: radiosity_reference::Progress) {
    let secs = p.elapsed.as_secs_f64();
    let rate = p.paths_done as f64 / secs.max(1e-9);
    // An adaptive estimate plans round by round: the ETA is to the end of this round.
    let eta = (p.paths_planned.saturating_sub(p.paths_done)) as f64 / rate.max(1e-9);
    progress.set(
        p.paths_done,
        p.paths_planned.max(1),
        format!(
            "{:.1} of {:.1} M paths planned, {:.2} M paths/s, ETA {eta:.0} s",
            p.paths_done as f64 / 1e6,
            p.paths_planned as f64 / 1e6,
            rate / 1e6
        ),
    );
}

/// Says what the reference ran (paths, time, whether its time limit stopped it) and pairs
/// each solved object with its reference estimate.
///
/// # Errors
/// The note cannot be written (a closed stderr).
pub(crate) fn compare_objects(
    estimates: &radiosity_reference::Estimates,
    solved: &[radiosity_solver::ObjectRadiosity],
    interrupted: bool,
) -> Result<Vec<Comparison>> {
    let secs = estimates.elapsed.as_secs_f64();
    let stopped = match (interrupted, estimates.timed_out) {
        (true, _) => ", stopped by Ctrl-C",
        (false, true) => ", stopped by its time budget",
        (false, false) => "",
    };
    crate::output::note(format_args!(
        "reference: {:.1} M paths in {:.1} s ({:.2} M paths/s){stopped}; {}",
        estimates.paths as f64 / 1e6,
        secs,
        estimates.paths as f64 / secs.max(1e-9) / 1e6,
        precision(estimates)
    ))?;
    Ok(solved
        .iter()
        .zip(&estimates.objects)
        .map(|(s, r)| Comparison { solve: s.radiosity, reference: r.estimate })
        .collect())
}

/// How precise the reference got: the largest and the median standard error of the lit
/// objects' luminance, relative to it.
fn precision(estimates: &radiosity_reference::Estimates) -> String {
    let errors: Vec<(f64, &str)> = estimates
        .objects
        .iter()
        .filter(|o| o.estimate.luminance > 0.0)
        .map(|o| (o.estimate.luminance_stderr / o.estimate.luminance * 100.0, o.name.as_str()))
        .collect();
    let Some(&(worst, name)) = errors.iter().max_by(|a, b| a.0.total_cmp(&b.0)) else {
        return "no object has light to estimate".into();
    };
    let median = median(errors.iter().map(|e| e.0).collect()).unwrap_or(worst);
    let worst = if worst.is_finite() { format!("{worst:.2} %") } else { "unknown (too few paths)".into() };
    format!("standard error at most {worst} ({name}), median {median:.2} %")
}

/// One solve value against its reference estimate.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Comparison {
    /// The solver's value.
    pub(crate) solve: Rgb,
    /// The reference's estimate of it.
    pub(crate) reference: Estimate,
}

impl Comparison {
    /// (solve − reference) / reference per channel, in per cent (`None` where the reference
    /// is 0).
    fn percent(&self) -> [Option<f64>; 3] {
        let (s, r) = (self.solve.to_array(), self.reference.mean.to_array());
        [0, 1, 2].map(|i| (r[i] != 0.0).then(|| (s[i] - r[i]) / r[i] * 100.0))
    }

    /// (solve − reference) / standard error per channel.
    fn sigma(&self) -> [f64; 3] {
        let (s, r, e) =
            (self.solve.to_array(), self.reference.mean.to_array(), self.reference.stderr.to_array());
        [0, 1, 2].map(|i| z_score(s[i] - r[i], e[i], r[i]))
    }

    /// (solve − reference) / reference in luminance, in per cent (`None` where the
    /// reference is 0).
    pub(crate) fn luminance_percent(&self) -> Option<f64> {
        let r = self.reference.luminance;
        (r != 0.0).then(|| (self.solve.luminance() - r) / r * 100.0)
    }

    /// (solve − reference) / standard error in luminance.
    pub(crate) fn luminance_sigma(&self) -> f64 {
        let r = self.reference.luminance;
        z_score(self.solve.luminance() - r, self.reference.luminance_stderr, r)
    }
}

/// A difference in standard errors. An exact reference (a light that only emits: every path
/// gives its emission) has a standard error of round-off only; below 1e-9 of the value it
/// counts as 1e-9 of the value, so round-off never reads as a significant difference.
fn z_score(diff: f64, stderr: f64, reference: f64) -> f64 {
    let floor = 1e-9 * reference.abs();
    if stderr.max(floor) > 0.0 {
        diff / stderr.max(floor)
    } else if diff == 0.0 {
        0.0
    } else {
        diff.signum() * f64::INFINITY
    }
}

/// A number for JSON: non-finite values become null.
pub(crate) fn num(x: f64) -> Value {
    if x.is_finite() { json!(x) } else { Value::Null }
}

fn fmt_pct(p: Option<f64>) -> String {
    p.map_or_else(|| "—".into(), |p| format!("{p:+.2}"))
}

fn fmt_sigma(z: f64) -> String {
    if z.is_finite() { format!("{z:+.1}") } else { format!("{}∞", if z > 0.0 { "+" } else { "−" }) }
}

fn median(mut v: Vec<f64>) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) })
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
            .with_luminaires(prepared.scene.lighting.luminaires.clone());
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

/// `(index, difference %, difference σ)` of every row with light to compare: objects that
/// are dark in both (nothing to compare) are left out of the summary.
pub(crate) fn judged(rows: &[Comparison]) -> Vec<(usize, f64, f64)> {
    rows.iter()
        .enumerate()
        .filter_map(|(i, c)| c.luminance_percent().map(|p| (i, p, c.luminance_sigma())))
        .collect()
}

/// The verdict over some of the compared objects: how many differ by more than 3 σ, the
/// worst, the median |difference| and the area-weighted mean difference.
pub(crate) struct Summary {
    /// Objects judged.
    pub(crate) objects: usize,
    /// Of them, those more than 3 σ off.
    pub(crate) over: usize,
    /// `(name, difference %, difference σ)`.
    pub(crate) worst: Option<(String, f64, f64)>,
    /// Median |difference|, per cent.
    pub(crate) median_abs: Option<f64>,
    /// Area-weighted mean difference, per cent.
    pub(crate) area_weighted: Option<f64>,
    /// The one-line verdict.
    pub(crate) text: String,
}

impl Summary {
    /// The verdict over `judged` (`(index into solved, difference %, difference σ)`).
    pub(crate) fn of(judged: &[(usize, f64, f64)], solved: &[ObjectRadiosity]) -> Self {
        let over = judged.iter().filter(|(_, _, z)| z.abs() > 3.0).count();
        let worst = judged
            .iter()
            .max_by(|x, y| x.1.abs().total_cmp(&y.1.abs()))
            .map(|&(i, p, z)| (solved[i].name.clone(), p, z));
        let median_abs = median(judged.iter().map(|j| j.1.abs()).collect());
        let area_weighted = {
            let (mut sum, mut area) = (0.0, 0.0);
            for &(i, p, _) in judged {
                sum += p * solved[i].area;
                area += solved[i].area;
            }
            (area > 0.0).then(|| sum / area)
        };
        let text = match &worst {
            Some((name, p, z)) => format!(
                "{over} of {} objects differ by more than 3 σ; worst {name} {p:+.2} % ({} σ), median |difference| {:.2} %, area-weighted mean {:+.2} %",
                judged.len(),
                fmt_sigma(*z),
                median_abs.unwrap_or(0.0),
                area_weighted.unwrap_or(0.0)
            ),
            None => "no object has light to compare".into(),
        };
        Self { objects: judged.len(), over, worst, median_abs, area_weighted, text }
    }

    /// The report's form of it, with `text` as its text.
    pub(crate) fn json(&self, text: &str) -> Value {
        json!({
            "text": text,
            "objects": self.objects,
            "over_3_sigma": self.over,
            "worst": self.worst.as_ref().map(|(name, p, z)| json!({"name": name, "difference_percent": num(*p), "difference_sigma": num(*z)})),
            "median_abs_difference_percent": self.median_abs,
            "area_weighted_difference_percent": self.area_weighted,
        })
    }
}

/// What the element sample adds to the table and to the report.
struct ElementPart {
    text: String,
    json: Value,
}

/// Compares `count` elements drawn at random (seeded) with reference estimates over each.
fn compare_elements(
    reference: &Reference,
    mesh: &Mesh,
    element_radiosity: &[Rgb],
    count: usize,
    paths: u64,
    seed: u64,
    max_reflections: u32,
) -> Result<ElementPart> {
    // A partial Fisher–Yates shuffle: `count` distinct elements, the same for a seed.
    let n = mesh.elements.len();
    let mut order: Vec<usize> = (0..n).collect();
    let mut rng = Rng::for_task(seed, 0x656c_656d, 0); // "elem"
    let k = count.min(n);
    for i in 0..k {
        let j = i + (rng.next_u64() % (n - i) as u64) as usize;
        order.swap(i, j);
    }
    let mut sample = order[..k].to_vec();
    sample.sort_unstable();
    let regions: Vec<Region> = sample
        .iter()
        .map(|&e| {
            let object = mesh.element_object(e);
            let object = if mesh.element_is_back(e) {
                reference.back_object(object).unwrap_or(object)
            } else {
                object
            };
            Region { object, corners: mesh.element_corners(e).collect() }
        })
        .collect();
    let params = EstimateParams {
        budget: PathBudget::Fixed { paths },
        seed,
        max_reflections,
        ..EstimateParams::default()
    };
    let progress = reference_progress("elements");
    let estimates = reference.estimate_regions_until(
        &regions,
        &params,
        &|p| report_progress(&progress, p),
        &crate::interrupt::requested,
    )?;
    drop(progress);

    let rows: Vec<(usize, Comparison)> = sample
        .iter()
        .zip(&estimates)
        .map(|(&e, r)| (e, Comparison { solve: element_radiosity[e], reference: *r }))
        .collect();
    // Relative differences in luminance, over the elements the reference sees lit; the
    // noise part is what the reference's own standard errors alone would give.
    let lit: Vec<&(usize, Comparison)> = rows.iter().filter(|(_, c)| c.reference.luminance > 0.0).collect();
    let m = lit.len().max(1) as f64;
    let rms =
        (lit.iter().map(|(_, c)| (c.luminance_percent().unwrap_or(0.0)).powi(2)).sum::<f64>() / m).sqrt();
    let noise = (lit
        .iter()
        .map(|(_, c)| (c.reference.luminance_stderr / c.reference.luminance * 100.0).powi(2))
        .sum::<f64>()
        / m)
        .sqrt();
    let beyond = (rms * rms - noise * noise).max(0.0).sqrt();
    let mean = lit.iter().map(|(_, c)| c.luminance_percent().unwrap_or(0.0)).sum::<f64>() / m;

    let mut text = format!(
        "\n{} elements sampled, {} paths each: RMS difference {:.2} % (reference noise alone {:.2} %, beyond noise {:.2} %), mean {:+.2} %\n",
        rows.len(),
        paths,
        rms,
        noise,
        beyond,
        mean
    );
    let mut worst: Vec<&(usize, Comparison)> = lit.clone();
    worst.sort_by(|x, y| y.1.luminance_sigma().abs().total_cmp(&x.1.luminance_sigma().abs()));
    let shown = worst.len().min(20);
    text += &format!(
        "the {shown} largest in σ:\n{:>9} {:<20} {:>11} {:>11} {:>9} {:>8} {:>8}\n",
        "element", "object", "solve Y", "reference Y", "± σ %", "diff %", "diff σ"
    );
    for (e, c) in &worst[..shown] {
        text += &format!(
            "{:>9} {:<20} {:>11.5e} {:>11.5e} {:>9.3} {:>8} {:>8}\n",
            e,
            mesh.object_names[mesh.element_object(*e)],
            c.solve.luminance(),
            c.reference.luminance,
            c.reference.luminance_stderr / c.reference.luminance * 100.0,
            fmt_pct(c.luminance_percent()),
            fmt_sigma(c.luminance_sigma())
        );
    }
    let json = json!({
        "count": rows.len(),
        "paths_per_element": paths,
        "rms_difference_percent": rms,
        "rms_noise_percent": noise,
        "rms_beyond_noise_percent": beyond,
        "mean_difference_percent": mean,
        "elements": rows.iter().map(|(e, c)| json!({
            "element": e,
            "object": mesh.object_names[mesh.element_object(*e)],
            "area": mesh.elements[*e].area,
            "centre": mesh.elements[*e].centre.to_array(),
            "radiosity": c.solve.to_array(),
            "reference": c.reference.mean.to_array(),
            "stderr": c.reference.stderr.to_array(),
        })).collect::<Vec<_>>(),
    });
    Ok(ElementPart { text, json })
}

/// Renders `camera`'s view of the prepared scene with the reference estimator, printing how
/// long it took and how noisy it is: the picture behind `render --reference`.
///
/// # Errors
/// Picture settings out of range (exit code 2).
pub fn reference_picture(
    prepared: &Prepared,
    camera: &Camera,
    width: u32,
    height: u32,
    samples_per_pixel: u32,
    seed: u64,
) -> Result<HdrImage> {
    let reference = Reference::new(&prepared.scene);
    let params = PictureParams { width, height, samples_per_pixel, seed };
    let start = std::time::Instant::now();
    let progress = Progress::bar("reference", u64::from(height), "rows");
    let picture = reference.render(camera, &params, &|| progress.inc()).map_err(|e| input(e.to_string()))?;
    drop(progress);
    // The noise floor of any comparison with this picture: the pixels' relative standard
    // error in luminance (bounded by the channels' own).
    let (mut sum, mut count) = (0.0, 0usize);
    for (l, s) in picture.radiance.iter().zip(&picture.stderr) {
        let y = l.luminance();
        if y > 0.0 && s.is_finite() {
            sum += s.luminance() / y;
            count += 1;
        }
    }
    crate::output::note(format_args!(
        "{}: reference picture {}×{} at {} paths per pixel in {:.1} s; mean relative standard error per pixel {}",
        prepared.scene.name,
        width,
        height,
        samples_per_pixel,
        start.elapsed().as_secs_f64(),
        if count > 0 { format!("{:.2} %", sum / count as f64 * 100.0) } else { "—".into() }
    ))?;
    Ok(HdrImage::from_pixels(width, height, picture.radiance))
}
