//! `radiosity export`: solve a scene (or a model file) and write the lit mesh as glTF, GLB or
//! PLY with baked vertex colours, and optionally per-object lightmaps.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use radiosity_export::{ExportFormat, Texels, VertexColours};
use radiosity_image::{Gather, HdrImage, RenderParams, Renderer, ToneOperator, ToneParams};

use crate::errors::InputError;
use crate::output::{self, Targets, note};
use crate::picture_opts::{GatherArg, ToneOpts};
use crate::prepare::{prepare, run_solver};
use crate::progress::spinning;
use crate::solve_opts::SolveOpts;

/// Arguments of `radiosity export`.
#[derive(Args)]
pub struct ExportArgs {
    /// The scene to load: see [`SCENE_HELP`](crate::solve_opts::SCENE_HELP).
    #[arg(help = crate::solve_opts::SCENE_HELP)]
    pub scene: String,
    /// Lit mesh to write: .glb, .gltf (buffer embedded) or .ply (binary little endian).
    #[arg(short = 'o', long = "output")]
    pub output: PathBuf,
    /// glTF COLOR_0: the tone-mapped display colour (see --exposure, --tonemap) instead of
    /// exposed linear radiance clamped to 1. Exact radiosity is always in _RADIOSITY (glTF) or
    /// radiosity_r/g/b (PLY).
    #[arg(long)]
    pub tonemapped: bool,
    /// Also write per-object lightmaps (linear EXR) and an OBJ mapping them into this folder
    /// (made if missing, with the folders above it).
    #[arg(long)]
    pub lightmap: Option<PathBuf>,
    /// Lightmap texels: `none` interpolated from the solution, `direct` with direct light by
    /// shadow rays per texel (sharp shadows from a coarse solve), `full` also one bounce of
    /// gathering rays. Needs --lightmap.
    #[arg(long, value_enum, default_value_t = GatherArg::None)]
    pub gather: GatherArg,
    #[command(flatten)]
    pub tone: ToneOpts,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub solve: SolveOpts,
}

/// Runs `export`.
///
/// # Errors
/// Bad scene or options, an unknown output extension, an existing output without --force
/// (exit code 2), or a file that cannot be written.
pub fn run(a: ExportArgs) -> Result<()> {
    let format = ExportFormat::from_path(&a.output).ok_or_else(|| {
        InputError(format!("{}: unknown output format; expected .glb, .gltf or .ply", a.output.display()))
    })?;
    // Refuse before solving, so a long solve is not lost to an existing file.
    let mut targets = Targets::new(a.force);
    targets.file(&a.output, "-o")?;
    if let Some(dir) = &a.lightmap {
        targets.folder(dir, "lightmapped.obj", "--lightmap")?;
    }
    if a.lightmap.is_none() && !matches!(a.gather, GatherArg::None) {
        return Err(InputError("--gather bakes lightmaps: give --lightmap DIR too".into()).into());
    }
    let prepared = prepare(&a.scene, &a.solve)?;
    let (solver, report) = run_solver(&prepared)?;
    let solution = solver.solution();
    // The solver's tables and kept rows are not needed past here: on a big model they are
    // as large as the picture's inputs.
    drop(solver);
    let mesh = prepared.problem.mesh();

    // The exposure for display colours: fixed, or the elements metered as a picture's pixels
    // are (lit part to middle grey, capped under white; there is no picture to measure, so
    // the scene itself is used).
    let radiance = HdrImage::from_pixels(
        solution.element_radiosity.len() as u32,
        1,
        solution.element_radiosity.iter().map(|&b| b / std::f64::consts::PI).collect(),
    );
    let ev = a.tone.exposure.ev_for(&radiance);
    let tone = ToneParams::new(ev, a.tone.tonemap.into());
    let mode =
        if a.tonemapped { VertexColours::Display(tone) } else { VertexColours::Linear { exposure_ev: ev } };
    // Texture coordinates per element corner, for glTF's textured materials (PLY has none).
    let uvs = match format {
        ExportFormat::Ply => Vec::new(),
        ExportFormat::Glb | ExportFormat::Gltf => radiosity_image::element_uvs(&prepared.scene, mesh),
    };
    spinning(&format!("writing {}", a.output.display()), || {
        let bytes = match format {
            ExportFormat::Glb => radiosity_export::glb_bytes(mesh, &solution, mode, &uvs),
            ExportFormat::Gltf => radiosity_export::gltf_text(mesh, &solution, mode, &uvs).into_bytes(),
            ExportFormat::Ply => radiosity_export::ply_bytes(mesh, &solution, tone, prepared.up),
        };
        output::write_file(&a.output, a.force, &bytes)
    })?;
    note(format_args!(
        "{}: {} patches, {} elements, {} shots, unshot {:.4} %",
        prepared.scene.name,
        mesh.patches.len(),
        mesh.elements.len(),
        report.total_shots,
        report.unshot_fraction * 100.0
    ))?;
    let colours = match (format, a.tonemapped) {
        (ExportFormat::Ply, _) => format!(
            "display colours ({}, {ev:+.2} EV) and linear radiosity",
            ToneOperator::from(a.tone.tonemap)
        ),
        (_, true) => format!("display colours ({}, {ev:+.2} EV)", ToneOperator::from(a.tone.tonemap)),
        (_, false) => format!("linear colours ({ev:+.2} EV) and radiosity"),
    };
    let vertices = match format {
        ExportFormat::Ply => mesh.positions.len(),
        ExportFormat::Glb | ExportFormat::Gltf => radiosity_export::gltf_vertex_count(mesh, &uvs),
    };
    note(format_args!("wrote {} ({vertices} vertices, {colours})", a.output.display()))?;
    if let Some(dir) = &a.lightmap {
        let gather = Gather::from(a.gather);
        let renderer = (gather != Gather::None).then(|| Renderer::new(mesh.clone()));
        let params = RenderParams { gather, seed: a.solve.seed, ..RenderParams::default() };
        let texels = match &renderer {
            Some(renderer) => Texels::Gathered { renderer, params: &params },
            None => Texels::Interpolated,
        };
        let what = format!(
            "baking lightmaps ({} texels a cell, gather {})",
            radiosity_export::LIGHTMAP_CELL_TEXELS.pow(2),
            gather.as_str()
        );
        let count = spinning(&what, || {
            output::write_folder(dir, a.force, |staging| {
                radiosity_export::write_lightmaps(staging, mesh, &solution, texels, prepared.up)
            })
        })?;
        note(format_args!("wrote {count} lightmap files into {}", dir.display()))?;
    }
    Ok(())
}
