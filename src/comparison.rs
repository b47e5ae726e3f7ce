//! A solve against the reference, object by object: differences in per cent and in standard
//! errors, the verdict over them, and the table and JSON that `verify` and `bench --real` print.

use anyhow::Result;
use radiosity_core::Rgb;
use radiosity_reference::Estimate;
use radiosity_solver::ObjectRadiosity;
use serde_json::{Value, json};

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
    pub(crate) fn percent(&self) -> [Option<f64>; 3] {
        let (s, r) = (self.solve.to_array(), self.reference.mean.to_array());
        [0, 1, 2].map(|i| (r[i] != 0.0).then(|| (s[i] - r[i]) / r[i] * 100.0))
    }

    /// (solve − reference) / standard error per channel.
    pub(crate) fn sigma(&self) -> [f64; 3] {
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

pub(crate) fn fmt_pct(p: Option<f64>) -> String {
    p.map_or_else(|| "—".into(), |p| format!("{p:+.2}"))
}

pub(crate) fn fmt_sigma(z: f64) -> String {
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
