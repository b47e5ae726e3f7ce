//! Running the independent Monte Carlo reference with progress on stderr: per element for
//! `verify --elements`, and the picture behind `render --reference`.

use anyhow::Result;
use radiosity_core::random::Rng;
use radiosity_core::{Camera, Rgb};
use radiosity_image::HdrImage;
use radiosity_mesh::Mesh;
use radiosity_reference::{EstimateParams, PathBudget, PictureParams, Reference, Region};
use serde_json::{Value, json};

use crate::comparison::{Comparison, fmt_pct, fmt_sigma};
use crate::errors::InputError;
use crate::prepare::Prepared;
use crate::progress::Progress;

fn input(msg: String) -> anyhow::Error {
    InputError(msg).into()
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

/// What the element sample adds to the table and to the report.
pub(crate) struct ElementPart {
    pub(crate) text: String,
    pub(crate) json: Value,
}

/// Compares `count` elements drawn at random (seeded) with reference estimates over each.
pub(crate) fn compare_elements(
    reference: &Reference,
    mesh: &Mesh,
    element_radiosity: &[Rgb],
    count: usize,
    paths: u64,
    seed: u64,
    max_reflections: u32,
) -> Result<ElementPart> {
    // A partial Fisher–Yates shuffle: `count` distinct elements, the same for a seed. Only
    // elements of some area: a model's slivers (a public cathedral's, 3 764 zero-area faces
    // dropped, still left a few) carry no light and are no region to estimate over.
    let mut order: Vec<usize> = (0..mesh.elements.len()).filter(|&e| mesh.elements[e].area > 0.0).collect();
    let n = order.len();
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
            "normal": mesh.elements[*e].normal.to_array(),
            "back": mesh.element_is_back(*e),
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
