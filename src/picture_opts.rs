//! Picture options shared by `render`, `tonemap` and `export`: tone mapping, shading and the
//! final gather as the command line spells them.

use std::path::Path;

use anyhow::Result;
use clap::{Args, ValueEnum};
use radiosity_image::{Exposure, Gather, HdrImage, ToneOperator, ToneParams, encode_picture, tone_map_image};

use crate::output;

/// Tone-mapping operator on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum TonemapArg {
    /// Exposure, then clamp to [0, 1].
    Linear,
    /// Reinhard et al. 2002, L / (1 + L) on luminance.
    Reinhard,
    /// ACES filmic curve (Narkowicz 2015 fit).
    Aces,
}

impl From<TonemapArg> for ToneOperator {
    fn from(a: TonemapArg) -> Self {
        match a {
            TonemapArg::Linear => ToneOperator::Linear,
            TonemapArg::Reinhard => ToneOperator::Reinhard,
            TonemapArg::Aces => ToneOperator::Aces,
        }
    }
}

/// Shading on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum ShadingArg {
    /// Radiosity interpolated from the vertices (within each surface only).
    Smooth,
    /// Each element's own radiosity: shows the mesh.
    Flat,
}

/// Final gather on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum GatherArg {
    /// The radiosity solution only, interpolated over the mesh.
    None,
    /// Direct light by shadow rays per pixel; indirect light from the solution.
    Direct,
    /// Direct light by shadow rays; indirect by one bounce of gathering rays at the records
    /// of an irradiance cache, interpolated between them.
    Full,
}

impl From<GatherArg> for Gather {
    fn from(a: GatherArg) -> Self {
        match a {
            GatherArg::None => Gather::None,
            GatherArg::Direct => Gather::Direct,
            GatherArg::Full => Gather::Full,
        }
    }
}

/// Exposure and operator, shared by `render` and `tonemap`.
#[derive(Args, Clone, Debug)]
pub struct ToneOpts {
    /// Exposure: `auto` maps the log-average luminance of the picture's lit pixels (near-black
    /// pixels and the brightest 2 %, where lamps are, left out) to middle grey, held down so
    /// the brightest lit surfaces stay under display white; `auto+1` or
    /// `auto-0.5` is that many stops brighter or darker than auto; a plain number is a fixed
    /// exposure in stops (EV, radiance × 2^EV: `1` is brighter than `0`, not than auto).
    /// One exposure for the whole picture.
    #[arg(long, default_value = "auto", allow_hyphen_values = true)]
    pub exposure: Exposure,
    /// Tone-mapping operator.
    #[arg(long, value_enum, default_value_t = TonemapArg::Aces)]
    pub tonemap: TonemapArg,
}

/// Tone maps `radiance` with `tone` and writes it as the picture format `path` names; returns
/// the exposure used (EV).
pub fn write_tonemapped(path: &Path, force: bool, radiance: &HdrImage, tone: &ToneOpts) -> Result<f64> {
    let ev = tone.exposure.ev_for(radiance);
    let png = tone_map_image(radiance, &ToneParams::new(ev, tone.tonemap.into()));
    output::write_file(path, force, &encode_picture(&png, path)?)?;
    Ok(ev)
}
