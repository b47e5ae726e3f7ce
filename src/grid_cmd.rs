//! `radiosity grid`: solve a photometric scene and write its calculation grids: the lux at
//! every point as CSV, a false-colour sheet of every grid (PNG), and a one-page HTML report.

use std::path::{Path, PathBuf};

use anyhow::Result;
use clap::Args;
use radiosity_image::{GridIlluminance, PictureFormat, encode_png, grid_picture, picture_sheet};

use crate::errors::InputError;
use crate::lighting_cmd::{compute_grids, grid_table, sky_lux, write_grid_csv};
use crate::output::{self, Targets, note};
use crate::prepare::{Prepared, prepare, run_solver};
use crate::solve_opts::SolveOpts;

/// Arguments of `radiosity grid`.
#[derive(Args)]
pub struct GridArgs {
    /// The scene to load: see [`SCENE_HELP`](crate::solve_opts::SCENE_HELP).
    #[arg(help = crate::solve_opts::SCENE_HELP)]
    pub scene: String,
    /// The lux at every grid point as CSV: `grid,x,y,z,lux`, one row per point, positions in
    /// the file's coordinates.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// A false-colour picture of every grid, stacked on one PNG sheet: colour bands and
    /// iso-lux lines at the legend's levels, Em, Emin, Emax and U0 printed under each.
    #[arg(long, value_name = "FILE")]
    pub png: Option<PathBuf>,
    /// A one-page, self-contained HTML report: the scene, its luminaires with their flux,
    /// each grid's picture and a table of Em, Emin, Emax and U0.
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub solve: SolveOpts,
}

fn input(msg: String) -> anyhow::Error {
    InputError(msg).into()
}

/// Runs `grid`.
pub fn run(a: GridArgs) -> Result<()> {
    if a.output.is_none() && a.png.is_none() && a.report.is_none() {
        return Err(input(
            "nothing to write: give -o grid.csv, --png grid.png and/or --report report.html".into(),
        ));
    }
    if let Some(path) = &a.png
        && PictureFormat::of(path).ok() != Some(PictureFormat::Png)
    {
        return Err(input(format!("--png {}: the sheet is a PNG; name a .png file", path.display())));
    }
    let mut targets = Targets::new(a.force);
    for (path, option) in [(&a.output, "-o"), (&a.png, "--png"), (&a.report, "--report")] {
        if let Some(path) = path {
            targets.file(path, option)?;
        }
    }
    let prepared = prepare(&a.scene, &a.solve)?;
    if prepared.scene.lighting.grids.is_empty() {
        return Err(input(format!(
            "{}: the scene has no calculation grid; add a [[grid]] (origin, u, v) to its file",
            a.scene
        )));
    }
    let (solver, report) = run_solver(&prepared)?;
    let grids = compute_grids(&prepared, &solver.solution())?;
    drop(solver);
    note(format_args!(
        "{}: {} elements, {} shots, solved in {:.2} s",
        prepared.scene.name,
        prepared.problem.mesh().elements.len(),
        report.total_shots,
        report.elapsed.as_secs_f64()
    ))?;
    output::stdout(&grid_table(&grids, sky_lux(&prepared.scene)))?;
    if let Some(path) = &a.output {
        write_grid_csv(path, a.force, &prepared, &grids)?;
    }
    let pictures =
        if a.png.is_some() || a.report.is_some() { grid_pngs(&prepared, &grids)? } else { Vec::new() };
    if let Some(path) = &a.png {
        let images: Vec<_> = pictures.iter().map(|(image, _)| image.clone()).collect();
        output::write_file(path, a.force, &encode_png(&picture_sheet(&images), path)?)?;
        note(format_args!("wrote {}", path.display()))?;
    }
    if let Some(path) = &a.report {
        let pngs: Vec<&[u8]> = pictures.iter().map(|(_, png)| png.as_slice()).collect();
        let html = crate::report_html::grid_report(&prepared, &grids, &pngs);
        output::write_file(path, a.force, html.as_bytes())?;
        note(format_args!("wrote {}", path.display()))?;
    }
    Ok(())
}

/// Each grid's false-colour picture, and the same as PNG bytes.
fn grid_pngs(
    prepared: &Prepared,
    grids: &[GridIlluminance],
) -> Result<Vec<(radiosity_image::SrgbImage, Vec<u8>)>> {
    let unit = prepared.scene.lighting.unit().as_str();
    let luminaires: Vec<_> = prepared.scene.lighting.luminaires.iter().map(|l| l.position).collect();
    prepared
        .scene
        .lighting
        .grids
        .iter()
        .zip(grids)
        .map(|(grid, result)| {
            let image = grid_picture(grid, result, unit, None, &luminaires);
            let png = encode_png(&image, Path::new("grid.png"))?;
            Ok((image, png))
        })
        .collect()
}
