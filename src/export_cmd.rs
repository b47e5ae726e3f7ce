//! `radiosity export`: solve a scene (or a model file) and write the lit mesh as glTF, GLB or
//! PLY with baked vertex colours, and optionally per-object lightmaps.

use std::path::{Path, PathBuf};

use anyhow::Result;
use clap::Args;
use radiosity_export::{
    ATLAS_FILES, AtlasOptions, AtlasTexels, ExportFormat, LightmapQuantity, Texels, VertexColours,
    atlas_radiance, bake_atlas, bake_source_atlas, write_atlas, write_source_atlas,
};
use radiosity_image::{Gather, HdrImage, RenderParams, Renderer, ToneOperator, ToneParams};
use radiosity_solver::Solution;

use crate::errors::InputError;
use crate::output::{self, Targets, note};
use crate::picture_opts::{GatherArg, ToneOpts};
use crate::prepare::{Prepared, prepare, run_solver};
use crate::progress::spinning;
use crate::solve_opts::SolveOpts;

/// Arguments of `radiosity export`.
#[derive(Args)]
pub struct ExportArgs {
    /// The scene to load: see [`SCENE_HELP`](crate::solve_opts::SCENE_HELP).
    #[arg(help = crate::solve_opts::SCENE_HELP)]
    pub scene: String,
    /// Lit mesh to write: .glb, .gltf (buffer embedded) or .ply (binary little endian).
    /// Needed unless --lightmap or --lightmap-atlas is given.
    #[arg(short = 'o', long = "output")]
    pub output: Option<PathBuf>,
    /// glTF COLOR_0: the tone-mapped display colour (see --exposure, --tonemap) instead of
    /// exposed linear radiance clamped to 1. Exact radiosity is always in _RADIOSITY (glTF) or
    /// radiosity_r/g/b (PLY).
    #[arg(long)]
    pub tonemapped: bool,
    /// Also write per-object lightmaps (linear EXR) and an OBJ mapping them into this folder
    /// (made if missing, with the folders above it).
    #[arg(long)]
    pub lightmap: Option<PathBuf>,
    /// Also write, into this folder, the scene's own faces for a game engine:
    /// `lightmapped.gltf` (the model's meshes, materials and colour textures, with lightmap
    /// coordinates in TEXCOORD_1 from a chart-and-pack unwrap), `lightmap.exr` (linear) and
    /// `lightmap.png` (tone-mapped, also in the glTF). See docs/FORMAT.md.
    #[arg(long, value_name = "DIR")]
    pub lightmap_atlas: Option<PathBuf>,
    /// Lightmap texels per scene unit (default: the most that fits one --atlas-size page).
    /// Needs --lightmap-atlas.
    #[arg(long, value_name = "TEXELS", value_parser = positive_density)]
    pub texels_per_unit: Option<f64>,
    /// Lightmap atlas width in texels (its height is what the charts take), 64 to 16384.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(64..=16384))]
    pub atlas_size: u32,
    /// What lightmap atlas texels hold: `irradiance` E (W per unit², what an engine multiplies
    /// by the albedo and its texture) or `radiosity` B (the albedo applied).
    #[arg(long, value_enum, default_value_t = QuantityArg::Irradiance)]
    pub lightmap_quantity: QuantityArg,
    /// Lightmap texels: `none` interpolated from the solution, `direct` with direct light by
    /// shadow rays per texel (sharp shadows from a coarse solve), `full` also one bounce of
    /// gathering rays. Needs --lightmap or --lightmap-atlas.
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

/// What lightmap atlas texels hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum QuantityArg {
    /// Irradiance E arriving at the surface.
    Irradiance,
    /// Radiosity B leaving it.
    Radiosity,
}

impl From<QuantityArg> for LightmapQuantity {
    fn from(q: QuantityArg) -> Self {
        match q {
            QuantityArg::Irradiance => LightmapQuantity::Irradiance,
            QuantityArg::Radiosity => LightmapQuantity::Radiosity,
        }
    }
}

/// `--texels-per-unit`: finite and positive.
fn positive_density(text: &str) -> Result<f64, String> {
    let value: f64 = text.parse().map_err(|_| format!("'{text}' is not a number"))?;
    if value.is_finite() && value > 0.0 && value <= 1e6 {
        Ok(value)
    } else {
        Err(format!("{value}: must be in (0, 1e6]"))
    }
}

/// Runs `export`.
///
/// # Errors
/// Bad scene or options, an unknown output extension, an existing output without --force
/// (exit code 2), or a file that cannot be written.
pub fn run(a: ExportArgs) -> Result<()> {
    let format = match &a.output {
        Some(path) => Some(ExportFormat::from_path(path).ok_or_else(|| {
            InputError(format!("{}: unknown output format; expected .glb, .gltf or .ply", path.display()))
        })?),
        None if a.lightmap.is_none() && a.lightmap_atlas.is_none() => {
            return Err(InputError(
                "nothing to write: give -o FILE (a lit mesh), --lightmap DIR or --lightmap-atlas DIR".into(),
            )
            .into());
        }
        None => None,
    };
    // Refuse before solving, so a long solve is not lost to an existing file.
    let mut targets = Targets::new(a.force);
    if let Some(path) = &a.output {
        targets.file(path, "-o")?;
    }
    if let Some(dir) = &a.lightmap {
        targets.folder(dir, "lightmapped.obj", "--lightmap")?;
    }
    if let Some(dir) = &a.lightmap_atlas {
        targets.folder(dir, ATLAS_FILES[0], "--lightmap-atlas")?;
    }
    if a.lightmap.is_none() && a.lightmap_atlas.is_none() && !matches!(a.gather, GatherArg::None) {
        return Err(InputError(
            "--gather bakes lightmaps: give --lightmap DIR or --lightmap-atlas DIR too".into(),
        )
        .into());
    }
    if a.lightmap_atlas.is_none() && a.texels_per_unit.is_some() {
        return Err(
            InputError("--texels-per-unit sizes the atlas: give --lightmap-atlas DIR too".into()).into()
        );
    }
    let prepared = prepare(&a.scene, &a.solve)?;
    let (solver, report) = run_solver(&prepared)?;
    let solution = solver.solution();
    // The solver's tables and kept rows are not needed past here: on a big model they are
    // as large as the picture's inputs.
    drop(solver);
    let mesh = prepared.problem.mesh();
    note(format_args!(
        "{}: {} patches, {} elements, {} shots, unshot {:.4} %",
        prepared.scene.name,
        mesh.patches.len(),
        mesh.elements.len(),
        report.total_shots,
        report.unshot_fraction * 100.0
    ))?;
    if let (Some(path), Some(format)) = (&a.output, format) {
        write_lit_mesh(&a, path, format, &prepared, &solution)?;
    }
    if let Some(dir) = &a.lightmap {
        write_cells(&a, dir, &prepared, &solution)?;
    }
    if let Some(dir) = &a.lightmap_atlas {
        write_atlas_folder(&a, dir, &prepared, &solution)?;
    }
    Ok(())
}

/// The renderer and its settings when `--gather` asks for texels gathered per point.
fn gatherer(
    a: &ExportArgs,
    mesh: &std::sync::Arc<radiosity_mesh::Mesh>,
) -> (Gather, Option<Renderer>, RenderParams) {
    let gather = Gather::from(a.gather);
    let renderer = (gather != Gather::None).then(|| Renderer::new(mesh.clone()));
    (gather, renderer, RenderParams { gather, seed: a.solve.seed, ..RenderParams::default() })
}

/// Writes the lit element mesh to `path` in `format`.
fn write_lit_mesh(
    a: &ExportArgs,
    path: &Path,
    format: ExportFormat,
    prepared: &Prepared,
    solution: &Solution,
) -> Result<()> {
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
    spinning(&format!("writing {}", path.display()), || {
        let bytes = match format {
            ExportFormat::Glb => radiosity_export::glb_bytes(mesh, solution, mode, &uvs),
            ExportFormat::Gltf => radiosity_export::gltf_text(mesh, solution, mode, &uvs).into_bytes(),
            ExportFormat::Ply => radiosity_export::ply_bytes(mesh, solution, tone, prepared.up),
        };
        output::write_file(path, a.force, &bytes)
    })?;
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
    note(format_args!("wrote {} ({vertices} vertices, {colours})", path.display()))
}

/// Writes the per-element lightmap cells and their OBJ into `dir` (`--lightmap`).
fn write_cells(a: &ExportArgs, dir: &Path, prepared: &Prepared, solution: &Solution) -> Result<()> {
    let mesh = prepared.problem.mesh();
    let (gather, renderer, params) = gatherer(a, mesh);
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
            radiosity_export::write_lightmaps(staging, mesh, solution, texels, prepared.up)
        })
    })?;
    note(format_args!("wrote {count} lightmap files into {}", dir.display()))
}

/// Unwraps the scene's faces into one atlas, bakes it and writes its files into `dir`
/// (`--lightmap-atlas`).
fn write_atlas_folder(a: &ExportArgs, dir: &Path, prepared: &Prepared, solution: &Solution) -> Result<()> {
    let mesh = prepared.problem.mesh();
    let (gather, renderer, params) = gatherer(a, mesh);
    let texels = match &renderer {
        Some(renderer) => AtlasTexels::Gathered { renderer, params: &params },
        None => AtlasTexels::Interpolated,
    };
    let options = AtlasOptions {
        texels_per_unit: a.texels_per_unit,
        size: a.atlas_size,
        quantity: a.lightmap_quantity.into(),
        ..AtlasOptions::default()
    };
    let what = format!("unwrapping and baking the lightmap atlas (gather {})", gather.as_str());
    // A glTF model is kept as it is (its nodes, materials, normals), its primitives given
    // the lightmap's coordinates; any other input is written as the scene's faces.
    let path = Path::new(&a.scene);
    let is_gltf = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"));
    let (atlas, source) = if is_gltf && path.is_file() {
        let (atlas, source) = spinning(&what, || {
            bake_source_atlas(path, prepared.up, &prepared.scene, mesh, solution, &options, texels)
        })
        .map_err(|e| InputError(format!("--lightmap-atlas: {e}")))?;
        (atlas, Some(source))
    } else {
        let atlas = spinning(&what, || bake_atlas(&prepared.scene, mesh, solution, &options, texels))
            .map_err(|e| InputError(format!("--lightmap-atlas: {e}")))?;
        (atlas, None)
    };
    let ev = a.tone.exposure.ev_for(&atlas_radiance(&atlas));
    let tone = ToneParams::new(ev, a.tone.tonemap.into());
    spinning(&format!("writing {}", dir.display()), || {
        output::write_folder(dir, a.force, |staging| match &source {
            Some(source) => write_source_atlas(staging, source, &atlas, &options, tone),
            None => write_atlas(staging, &prepared.scene, &atlas, &options, tone),
        })
    })?;
    note(format_args!(
        "wrote {} into {}: {}x{} texels, {:.2} texels per unit, {} charts, {} of {} face texels \
         without an element under them (filled from their neighbours){}",
        ATLAS_FILES.join(", "),
        dir.display(),
        atlas.image.width(),
        atlas.image.height(),
        atlas.texels_per_unit,
        atlas.charts,
        atlas.missed,
        atlas.covered,
        match atlas.dim_sides {
            0 => String::new(),
            n => format!("; {n} dim sides (the outside of a room) at an eighth of the density"),
        }
    ))
}
