//! `radiosity compare A B`: how far picture A is from picture B (e.g. a radiosity render from
//! `render --reference`), per channel, and where — as a false-colour difference picture.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use radiosity_core::Rgb;
use radiosity_image::{HdrImage, SrgbImage, encode_png, read_hdr};
use serde_json::json;

use crate::errors::InputError;
use crate::output::{self, Targets, write_report};

/// Arguments of `radiosity compare`.
#[derive(Args)]
pub struct CompareArgs {
    /// Picture to judge (.exr or .pfm, linear radiance), e.g. from `render --exr`.
    pub picture: PathBuf,
    /// Picture taken as the truth (.exr or .pfm), e.g. from `render --reference --exr`.
    pub reference: PathBuf,
    /// A second reference of the same view, rendered with another `--seed`. With it the
    /// figures are taken against the mean of the two references, and `compare` adds the
    /// picture's RMS relative error with the references' own noise taken out, so a picture
    /// can be judged against a path-traced truth far noisier than its own error.
    #[arg(long, value_name = "PICTURE")]
    pub second_reference: Option<PathBuf>,
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
    /// With two references: the RMS over the counted pixels of (a − t) / t against the
    /// noiseless picture t, and the RMS relative noise of the references' mean.
    noise_free: Option<NoiseFree>,
}

/// Figures against the noiseless truth, from two independent references.
#[derive(Clone, Copy, Debug, Default)]
struct NoiseFree {
    /// √(mean of (a − r₁)(a − r₂) / ℓ²), ℓ the references' level ([`reference_level`]): the
    /// picture's RMS relative error.
    relative_rms_error: f64,
    /// √(mean of ((r₁ − r₂) / 2)² / ℓ²): the RMS relative noise left in r̄ (whose variance is
    /// that of (r₁ − r₂) / 2).
    reference_noise: f64,
}

/// Half the side of the window [`reference_level`] averages over.
const LEVEL_RADIUS: usize = 2;

/// Pixels whose picture values differ by less than this share count as showing the same
/// light in [`reference_level`].
const LEVEL_SIMILAR: f64 = 0.1;

/// The references' level at each pixel without most of their noise: the mean of
/// r̄ = (r₁ + r₂)/2 over the pixels q of a 5 × 5 window such that the picture `a` shows both
/// q and its mirror image through the pixel within 10 % of the pixel's own value. The
/// picture, far less noisy than the references, tells which neighbours lie on the same side
/// of an edge; the window is point-symmetric, so across a gradient the mean is the pixel's
/// own value. With a window of n pixels the level keeps 1/√n of r̄'s noise.
///
/// Relative errors need a denominator, and r̄ itself will not do where the references are
/// noisy: 1/r̄² overshoots 1/t² on average (Jensen), and the pixels counted are chosen by
/// the same noise. Against references whose relative noise grows in the shadows as a path
/// tracer's does (3.6 % in the Cornell box's lit parts, 12–17 % at its blocks' feet), the
/// noiseless picture itself read 0.9 % RMS error and a picture 2 % off read 2.6 %
/// (`a_noiseless_picture_reads_no_error_against_references_noisy_in_the_dark`).
fn reference_level(a: &[f64], r1: &[f64], r2: &[f64], width: usize) -> Vec<f64> {
    let height = a.len() / width.max(1);
    let r = LEVEL_RADIUS as isize;
    let at = |x: isize, y: isize| {
        (x >= 0 && y >= 0 && (x as usize) < width && (y as usize) < height)
            .then(|| y as usize * width + x as usize)
    };
    (0..a.len())
        .map(|i| {
            let (x, y) = ((i % width) as isize, (i / width) as isize);
            let close = |j: usize| (a[j] - a[i]).abs() <= LEVEL_SIMILAR * a[i].abs();
            let (mut sum, mut n) = (0.0, 0usize);
            for dy in -r..=r {
                for dx in -r..=r {
                    let pair = at(x + dx, y + dy).zip(at(x - dx, y - dy));
                    if let Some((j, _)) = pair.filter(|&(j, k)| (dx, dy) == (0, 0) || (close(j) && close(k)))
                    {
                        sum += 0.5 * (r1[j] + r2[j]);
                        n += 1;
                    }
                }
            }
            sum / n as f64
        })
        .collect()
}

/// The picture's error with the references' noise taken out. With r₁ = t + e₁ and
/// r₂ = t + e₂, e₁ and e₂ independent, zero-mean and independent of a,
/// E[(a − r₁)(a − r₂)] = E[(a − t)²]: the product is an unbiased estimate of the squared error
/// against the truth, however noisy each reference is. It is made relative by the
/// references' `level` ([`reference_level`]), which also chooses the pixels counted.
/// Dividing by the picture's own value instead would be unbiased, but one dark pixel under a
/// lit reference would outweigh the rest of the picture.
fn noise_free(a: &[f64], r1: &[f64], r2: &[f64], level: &[f64], counted: impl Fn(f64) -> bool) -> NoiseFree {
    let (mut err, mut noise, mut n) = (0.0, 0.0, 0usize);
    for (((&x, &y1), &y2), &l) in a.iter().zip(r1).zip(r2).zip(level) {
        if counted(l) {
            err += (x - y1) * (x - y2) / (l * l);
            noise += (0.5 * (y1 - y2) / l).powi(2);
            n += 1;
        }
    }
    let n = n.max(1) as f64;
    // The mean can come out negative when the picture is closer to the truth than the
    // references can tell: that reads as no error.
    NoiseFree { relative_rms_error: (err / n).max(0.0).sqrt(), reference_noise: (noise / n).sqrt() }
}

/// Figures of `a` against the reference `r1`, or against the mean of `r1` and `r2` when there
/// are two; the pictures are `width` pixels wide.
fn figures(a: &[f64], r1: &[f64], r2: Option<&[f64]>, width: usize) -> ChannelFigures {
    let mean_of_two: Option<Vec<f64>> = r2.map(|r2| r1.iter().zip(r2).map(|(x, y)| 0.5 * (x + y)).collect());
    let b = mean_of_two.as_deref().unwrap_or(r1);
    let n = b.len().max(1) as f64;
    let mean_b = b.iter().sum::<f64>() / n;
    let floor = DARK_SHARE * mean_b;
    let counted = |y: f64| y > floor && y > 0.0;
    let (mut abs_rel, mut rel, mut count) = (0.0, 0.0, 0usize);
    for (&x, &y) in a.iter().zip(b) {
        if counted(y) {
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
        noise_free: r2.map(|r2| noise_free(a, r1, r2, &reference_level(a, r1, r2, width), counted)),
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
    let pb2 =
        a.second_reference.as_ref().map(|p| read_hdr(p).map_err(|e| input(e.to_string()))).transpose()?;
    for (path, other) in std::iter::once((&a.reference, &pb)).chain(a.second_reference.iter().zip(&pb2)) {
        if (pa.width(), pa.height()) != (other.width(), other.height()) {
            return Err(input(format!(
                "the pictures differ in size: {} is {}×{}, {} is {}×{}",
                a.picture.display(),
                pa.width(),
                pa.height(),
                path.display(),
                other.width(),
                other.height()
            )));
        }
    }
    let channel = |img: &HdrImage, f: Channel| img.pixels().iter().map(f).collect::<Vec<f64>>();
    let getters: [(&str, Channel); 4] =
        [("r", |p| p.r), ("g", |p| p.g), ("b", |p| p.b), ("Y", |p| p.luminance())];
    let all: Vec<(&str, ChannelFigures)> = getters
        .iter()
        .map(|&(name, f)| {
            let second = pb2.as_ref().map(|p| channel(p, f));
            (name, figures(&channel(&pa, f), &channel(&pb, f), second.as_deref(), pa.width() as usize))
        })
        .collect();

    let against = match &a.second_reference {
        Some(second) => format!("the mean of {} and {}", a.reference.display(), second.display()),
        None => a.reference.display().to_string(),
    };
    let mut text = format!(
        "{} vs {} ({}×{}; relative figures over the pixels where the reference is above {} % of its mean)\n{:<8} {:>16} {:>18} {:>12} {:>11} {:>8}",
        a.picture.display(),
        against,
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
    if pb2.is_some() {
        text += &format!(" {:>22} {:>11}", "RMS rel. err, noise out", "ref. noise");
    }
    text.push('\n');
    for (name, f) in &all {
        text += &format!(
            "{:<8} {:>15.2} % {:>+16.2} % {:>12.4e} {:>9.2} % {:>8}",
            name,
            f.mean_relative_error * 100.0,
            f.mean_relative_difference * 100.0,
            f.rmse,
            f.relative_rmse * 100.0,
            f.pixels
        );
        if let Some(nf) = f.noise_free {
            text +=
                &format!(" {:>21.2} % {:>9.2} %", nf.relative_rms_error * 100.0, nf.reference_noise * 100.0);
        }
        text.push('\n');
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
            "second_reference": a.second_reference.as_ref().map(|p| p.display().to_string()),
            "width": pa.width(),
            "height": pa.height(),
            "channels": all.iter().map(|(name, f)| json!({
                "channel": name,
                "mean_relative_error": f.mean_relative_error,
                "mean_relative_difference": f.mean_relative_difference,
                "rmse": f.rmse,
                "relative_rmse": f.relative_rmse,
                "pixels": f.pixels,
                "noise_free_relative_rms_error": f.noise_free.map(|n| n.relative_rms_error),
                "reference_noise": f.noise_free.map(|n| n.reference_noise),
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
        let f = figures(&a, &b, None, 2);
        assert_eq!(f.pixels, 3);
        assert!((f.mean_relative_error - 0.1).abs() < 1e-12);
        assert!((f.mean_relative_difference - 0.1).abs() < 1e-12);
        let expected_rmse = ((0.01 + 0.04 + 0.16) / 4.0_f64).sqrt();
        assert!((f.rmse - expected_rmse).abs() < 1e-12);
    }

    /// A picture 2 % off everywhere, judged against two references with 6 % noise each (as
    /// much as 1024-path references of the Cornell box have): against one of them the error
    /// reads about 5 %, with the noise taken out 2 %.
    #[test]
    fn noise_free_error_sees_through_noisy_references() {
        let mut rng = radiosity_core::random::Rng::from_state(7);
        let n = 400_000;
        let truth: Vec<f64> = (0..n).map(|i| 1.0 + (i % 7) as f64).collect();
        // Alternating signs: 2 % off in magnitude, no mean offset.
        let a: Vec<f64> =
            truth.iter().enumerate().map(|(i, t)| t * if i % 2 == 0 { 1.02 } else { 0.98 }).collect();
        // Uniform noise of ±√3·σ: standard deviation σ of the truth.
        let sigma = 0.06;
        let mut noisy = || {
            truth
                .iter()
                .map(|t| t * (1.0 + sigma * 3f64.sqrt() * (2.0 * rng.next_f64() - 1.0)))
                .collect::<Vec<f64>>()
        };
        let (r1, r2) = (noisy(), noisy());
        let one = figures(&a, &r1, None, 800);
        assert!(one.mean_relative_error > 0.04, "{one:?}");
        let two = figures(&a, &r1, Some(&r2), 800);
        let nf = two.noise_free.unwrap();
        assert!((nf.relative_rms_error - 0.02).abs() < 0.001, "{nf:?}");
        // The mean of two references has σ/√2 of noise.
        assert!((nf.reference_noise - sigma / 2f64.sqrt()).abs() < 0.002, "{nf:?}");
        // A picture equal to the truth reads close to no error: the mean of e₁e₂ over n pixels
        // spreads by σ²/√n, whose root is 0.002.
        let exact = figures(&truth, &r1, Some(&r2), 800).noise_free.unwrap();
        assert!(exact.relative_rms_error < 0.004, "{exact:?}");
    }

    /// References noisy as a path tracer's are: skewed (a few bright paths), and the darker
    /// the pixel the noisier (5 % at half the mean, 16 % at a twentieth). Judged relative to
    /// the references' own mean value, the noiseless picture read 0.9 % and a picture 2 % off
    /// 2.6 %; relative to their level under the picture's guidance, 0–0.33 % and 1.96–2.04 %
    /// (six seeds: the square root of a mean that spreads about zero).
    #[test]
    fn a_noiseless_picture_reads_no_error_against_references_noisy_in_the_dark() {
        let (w, h) = (320usize, 240usize);
        // A lit wall beside a shadow that deepens to 2 % of the mean, with a sharp edge.
        let truth: Vec<f64> = (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f64 / w as f64, (i / w) as f64 / h as f64);
                if x < 0.4 { 1.5 - y } else { 0.02 + 0.3 * (x - 0.4) * (1.0 - 0.5 * y) }
            })
            .collect();
        let mean = truth.iter().sum::<f64>() / truth.len() as f64;
        let mut rng = radiosity_core::random::Rng::from_state(11);
        let mut noisy = || {
            truth
                .iter()
                .map(|t| {
                    let sigma = (0.05 * (0.5 * mean / t).sqrt()).min(0.6);
                    // −ln U − 1: mean 0, variance 1, a long bright tail.
                    t * (1.0 + sigma * (-(1.0 - rng.next_f64()).ln() - 1.0))
                })
                .collect::<Vec<f64>>()
        };
        let (r1, r2) = (noisy(), noisy());
        let exact = figures(&truth, &r1, Some(&r2), w).noise_free.unwrap();
        // The old reading, 0.9 %, would fail this.
        assert!(exact.relative_rms_error < 0.005, "{exact:?}");
        let off: Vec<f64> = truth
            .iter()
            .enumerate()
            .map(|(i, t)| t * if (i / w + i) % 2 == 0 { 1.02 } else { 0.98 })
            .collect();
        let nf = figures(&off, &r1, Some(&r2), w).noise_free.unwrap();
        assert!((nf.relative_rms_error - 0.02).abs() < 0.001, "{nf:?}");
    }

    #[test]
    fn diverging_colours() {
        assert_eq!(diverging(0.0, 0.1), [255, 255, 255]);
        assert_eq!(diverging(-0.2, 0.1), [0, 0, 255]);
        assert_eq!(diverging(0.1, 0.1), [255, 0, 0]);
    }
}
