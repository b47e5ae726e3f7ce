//! `radiosity compare A B`: how far picture A is from picture B (e.g. a radiosity render from
//! `render --reference`), per channel, and where — as a false-colour difference picture.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use radiosity_core::Rgb;
use radiosity_image::{HdrImage, SrgbImage, encode_png, read_hdr};
use serde_json::json;

use crate::output::{self, Targets, write_report};
use crate::prepare::InputError;

/// Arguments of `radiosity compare`.
#[derive(Args)]
pub struct CompareArgs {
    /// Picture to judge (.exr or .pfm, linear radiance), e.g. from `render --exr`.
    pub picture: PathBuf,
    /// Picture taken as the truth (.exr or .pfm), e.g. from `render --reference --exr`.
    pub reference: PathBuf,
    /// Write a false-colour picture of the relative luminance difference (PNG): blue where the
    /// first picture is darker, red where it is brighter, white where they agree, black where
    /// the reference is dark.
    #[arg(short = 'o', long = "output")]
    pub output: Option<PathBuf>,
    /// Relative difference shown at full colour in the difference picture.
    #[arg(long, default_value_t = 0.1, value_name = "FRACTION")]
    pub range: f64,
    /// Write the figures as JSON here (`-` for stdout).
    #[arg(long)]
    pub json: Option<String>,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
}

fn input(msg: String) -> anyhow::Error {
    InputError(msg).into()
}

/// Pixels whose reference value is below this share of the reference's mean are left out of
/// relative errors: the background and unlit backs carry no light to be relative to.
const DARK_SHARE: f64 = 0.01;

/// Figures of one channel (or of luminance).
#[derive(Clone, Copy, Debug, Default)]
struct ChannelFigures {
    /// Mean over the counted pixels of |a − b| / b.
    mean_relative_error: f64,
    /// Mean over the counted pixels of (a − b) / b: the sign says darker or brighter.
    mean_relative_difference: f64,
    /// √mean (a − b)² over every pixel, radiance units.
    rmse: f64,
    /// `rmse` over the reference's mean.
    relative_rmse: f64,
    /// Pixels counted in the relative figures.
    pixels: usize,
}

fn figures(a: &[f64], b: &[f64]) -> ChannelFigures {
    let n = b.len().max(1) as f64;
    let mean_b = b.iter().sum::<f64>() / n;
    let floor = DARK_SHARE * mean_b;
    let (mut abs_rel, mut rel, mut count) = (0.0, 0.0, 0usize);
    for (&x, &y) in a.iter().zip(b) {
        if y > floor && y > 0.0 {
            abs_rel += ((x - y) / y).abs();
            rel += (x - y) / y;
            count += 1;
        }
    }
    let rmse = (a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>() / n).sqrt();
    let c = count.max(1) as f64;
    ChannelFigures {
        mean_relative_error: abs_rel / c,
        mean_relative_difference: rel / c,
        rmse,
        relative_rmse: if mean_b > 0.0 { rmse / mean_b } else { 0.0 },
        pixels: count,
    }
}

/// One value of a pixel: a channel or the luminance.
type Channel = fn(&Rgb) -> f64;

/// Blue (−range) through white (0) to red (+range).
fn diverging(d: f64, range: f64) -> [u8; 3] {
    let t = (d / range).clamp(-1.0, 1.0);
    let (r, g, b) = if t < 0.0 { (1.0 + t, 1.0 + t, 1.0) } else { (1.0, 1.0 - t, 1.0 - t) };
    [r, g, b].map(|c: f64| (c * 255.0).round() as u8)
}

/// The false-colour picture of (Y_a − Y_b) / Y_b.
fn difference_picture(a: &HdrImage, b: &HdrImage, range: f64) -> SrgbImage {
    let mean_b = b.pixels().iter().map(|p| p.luminance()).sum::<f64>() / b.pixels().len().max(1) as f64;
    let pixels = a
        .pixels()
        .iter()
        .zip(b.pixels())
        .map(|(p, q)| {
            let (ya, yb) = (p.luminance(), q.luminance());
            if yb > DARK_SHARE * mean_b && yb > 0.0 { diverging((ya - yb) / yb, range) } else { [0, 0, 0] }
        })
        .collect();
    SrgbImage { width: a.width(), height: a.height(), pixels }
}

/// Runs `compare`.
pub fn run(a: CompareArgs) -> Result<()> {
    if !(a.range.is_finite() && a.range > 0.0) {
        return Err(input(format!("--range must be a number > 0, got {}", a.range)));
    }
    let mut targets = Targets::new(a.force);
    if let Some(path) = &a.output {
        targets.file(path, "-o")?;
    }
    if let Some(path) = &a.json
        && path != "-"
    {
        targets.file(std::path::Path::new(path), "--json")?;
    }
    let pa = read_hdr(&a.picture).map_err(|e| input(e.to_string()))?;
    let pb = read_hdr(&a.reference).map_err(|e| input(e.to_string()))?;
    if (pa.width(), pa.height()) != (pb.width(), pb.height()) {
        return Err(input(format!(
            "the pictures differ in size: {}×{} and {}×{}",
            pa.width(),
            pa.height(),
            pb.width(),
            pb.height()
        )));
    }
    let channel = |img: &HdrImage, f: Channel| img.pixels().iter().map(f).collect::<Vec<f64>>();
    let getters: [(&str, Channel); 4] =
        [("r", |p| p.r), ("g", |p| p.g), ("b", |p| p.b), ("Y", |p| p.luminance())];
    let all: Vec<(&str, ChannelFigures)> =
        getters.iter().map(|&(name, f)| (name, figures(&channel(&pa, f), &channel(&pb, f)))).collect();

    let mut text = format!(
        "{} vs {} ({}×{}; relative figures over the pixels where the reference is above {} % of its mean)\n{:<8} {:>16} {:>18} {:>12} {:>11} {:>8}\n",
        a.picture.display(),
        a.reference.display(),
        pa.width(),
        pa.height(),
        DARK_SHARE * 100.0,
        "channel",
        "mean |rel. err|",
        "mean rel. diff.",
        "RMSE",
        "RMSE/mean",
        "pixels"
    );
    for (name, f) in &all {
        text += &format!(
            "{:<8} {:>15.2} % {:>+16.2} % {:>12.4e} {:>9.2} % {:>8}\n",
            name,
            f.mean_relative_error * 100.0,
            f.mean_relative_difference * 100.0,
            f.rmse,
            f.relative_rmse * 100.0,
            f.pixels
        );
    }
    if a.json.as_deref() != Some("-") {
        output::stdout(&text)?;
    }
    if let Some(path) = &a.output {
        let png = encode_png(&difference_picture(&pa, &pb, a.range), path)
            .context("cannot encode the difference picture")?;
        output::write_file(path, a.force, &png)?;
        output::note(format_args!(
            "wrote {} (relative luminance difference, ±{:.0} % at full colour)",
            path.display(),
            a.range * 100.0
        ))?;
    }
    if let Some(path) = &a.json {
        let doc = json!({
            "picture": a.picture.display().to_string(),
            "reference": a.reference.display().to_string(),
            "width": pa.width(),
            "height": pa.height(),
            "channels": all.iter().map(|(name, f)| json!({
                "channel": name,
                "mean_relative_error": f.mean_relative_error,
                "mean_relative_difference": f.mean_relative_difference,
                "rmse": f.rmse,
                "relative_rmse": f.relative_rmse,
                "pixels": f.pixels,
            })).collect::<Vec<_>>(),
        });
        write_report(path, a.force, &serde_json::to_string_pretty(&doc)?)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_of_a_uniformly_brighter_picture() {
        let b = vec![1.0, 2.0, 0.0, 4.0];
        let a: Vec<f64> = b.iter().map(|x| x * 1.1).collect();
        let f = figures(&a, &b);
        assert_eq!(f.pixels, 3);
        assert!((f.mean_relative_error - 0.1).abs() < 1e-12);
        assert!((f.mean_relative_difference - 0.1).abs() < 1e-12);
        let expected_rmse = ((0.01 + 0.04 + 0.16) / 4.0_f64).sqrt();
        assert!((f.rmse - expected_rmse).abs() < 1e-12);
    }

    #[test]
    fn diverging_colours() {
        assert_eq!(diverging(0.0, 0.1), [255, 255, 255]);
        assert_eq!(diverging(-0.2, 0.1), [0, 0, 255]);
        assert_eq!(diverging(0.1, 0.1), [255, 0, 0]);
    }
}
