//! `radiosity tonemap`: tone map a linear picture again without solving.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use radiosity_image::{PictureFormat, ToneOperator, read_hdr};

use crate::errors::InputError;
use crate::output::{Targets, note};
use crate::picture_opts::{ToneOpts, write_tonemapped};

fn input(msg: String) -> anyhow::Error {
    InputError(msg).into()
}

/// Arguments of `radiosity tonemap`.
#[derive(Args)]
pub struct TonemapArgs {
    /// Linear picture to read (.exr or .pfm), e.g. from `render --exr`.
    pub input: PathBuf,
    /// Tone-mapped 8-bit sRGB picture to write: PNG (.png) or JPEG (.jpg, .jpeg).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    #[command(flatten)]
    pub tone: ToneOpts,
    /// Overwrite an existing output file.
    #[arg(long)]
    pub force: bool,
}

/// Runs `tonemap`.
pub fn run(a: TonemapArgs) -> Result<()> {
    Targets::new(a.force).file(&a.output, "-o")?;
    PictureFormat::of(&a.output).map_err(|e| input(format!("-o: {e}")))?;
    // A missing or malformed input is the user's to fix: exit code 2.
    let radiance = read_hdr(&a.input).map_err(|e| input(e.to_string()))?;
    let ev = write_tonemapped(&a.output, a.force, &radiance, &a.tone)?;
    note(format_args!(
        "wrote {} (exposure {ev:+.2} EV, {})",
        a.output.display(),
        ToneOperator::from(a.tone.tonemap)
    ))
}
