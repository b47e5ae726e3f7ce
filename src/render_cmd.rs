//! `radiosity render`: solve, ray cast from a camera, tone map, write PNG (and linear EXR /
//! PFM).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Result;
use clap::Args;
use glam::DVec3;
use radiosity_core::Camera;
use radiosity_image::{
    Gather, HdrImage, PictureFormat, RenderParams, Renderer, Shading, ToneOperator, encode_exr, encode_pfm,
};

use crate::errors::InputError;
use crate::false_colour_cmd::{FalseColourArg, check_photometric, write_false_colour};
use crate::output::{self, Targets, note};
use crate::picture_opts::{GatherArg, ShadingArg, ToneOpts, write_tonemapped};
use crate::prepare::{prepare, run_solver};
use crate::progress::{Progress, spinning};
use crate::solve_opts::SolveOpts;

/// Arguments of `radiosity render`.
#[derive(Args)]
pub struct RenderArgs {
    /// The scene to load: see [`SCENE_HELP`](crate::solve_opts::SCENE_HELP).
    #[arg(help = crate::solve_opts::SCENE_HELP)]
    pub scene: String,
    /// Tone-mapped 8-bit sRGB picture to write: PNG (.png) or JPEG (.jpg, .jpeg).
    #[arg(short = 'o', long = "output")]
    pub output: Option<PathBuf>,
    /// Linear radiance as 32-bit float OpenEXR.
    #[arg(long)]
    pub exr: Option<PathBuf>,
    /// Linear radiance as PFM (bottom row first, little-endian).
    #[arg(long)]
    pub pfm: Option<PathBuf>,
    /// Picture width in pixels.
    #[arg(long, default_value_t = RenderParams::default().width)]
    pub width: u32,
    /// Picture height in pixels.
    #[arg(long, default_value_t = RenderParams::default().height)]
    pub height: u32,
    /// Jittered samples per pixel (seeded by --seed) [default: 16; 64 with `--gather full`].
    #[arg(long)]
    pub spp: Option<u32>,
    /// Radiosity at a hit point: interpolated from vertices, or per element.
    #[arg(long, value_enum, default_value_t = ShadingArg::Smooth)]
    pub shading: ShadingArg,
    /// Final gather: `direct` (direct light by shadow rays per pixel: shadows as sharp as the
    /// lamp makes them whatever the mesh; the default: on the Cornell box 1.8 % RMS error per
    /// pixel against the path-traced reference, rendered in about 2.9 s), `none` (the radiosity
    /// mesh as the viewer shows it: 2.6 %), `full` (the indirect light too gathered by rays,
    /// at an irradiance cache's records, instead of taken from the mesh, and 64 samples per
    /// pixel: 0.9 %, about 35 s).
    #[arg(long, value_enum, default_value_t = GatherArg::Direct)]
    pub gather: GatherArg,
    /// Shadow rays per sample towards the emitters, with a gather.
    #[arg(long, default_value_t = RenderParams::default().shadow_rays)]
    pub shadow_rays: u32,
    /// Gathering rays with `--gather full`: a picture's irradiance-cache records take 128 times
    /// this many each (more where a record spans many pixels); a lightmap's texels this many
    /// per sample.
    #[arg(long, default_value_t = RenderParams::default().gather_rays)]
    pub gather_rays: u32,
    /// Pixels on an outline (their corners and centre do not all see the same object) take
    /// this many times --spp samples, 1 to 64; 1: as many as any pixel. On a lamp's outline,
    /// where the lamp far outshines what lies beside it, its square (at most 64).
    #[arg(long, default_value_t = RenderParams::default().edge_factor, value_name = "N")]
    pub edge_factor: u32,
    /// With a gather, pixels whose point sees part of the lamps and not all (a penumbra, or a
    /// lamp cut by the surface's horizon, found by probe rays apart from the pixel's) take this
    /// many times --shadow-rays, 1 to 64; 1: as many as any pixel.
    #[arg(long, default_value_t = RenderParams::default().penumbra_factor, value_name = "N")]
    pub penumbra_factor: u32,
    /// Eye position `x,y,z`, in the file's coordinates (default: the scene's `[camera]`, or
    /// one framing the scene).
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    pub camera_position: Option<DVec3>,
    /// Point looked at, `x,y,z`, in the file's coordinates.
    #[arg(long, value_parser = parse_point, allow_hyphen_values = true)]
    pub look_at: Option<DVec3>,
    /// Vertical field of view, degrees, in (0, 180).
    #[arg(long, allow_negative_numbers = true)]
    pub fov: Option<f64>,
    #[command(flatten)]
    pub tone: ToneOpts,
    /// Colour `-o`'s pixels by the illuminance (lx) of the surface each one sees, with a
    /// legend, instead of tone mapping them (photometric scenes only: `units` or luminaires).
    #[arg(long, value_enum, value_name = "QUANTITY")]
    pub false_colour: Option<FalseColourArg>,
    /// Render with the independent Monte Carlo reference (a diffuse path tracer of the input
    /// geometry) instead of the radiosity solution, for `radiosity compare`.
    #[arg(long)]
    pub reference: bool,
    /// Paths per pixel of `--reference`.
    #[arg(long, default_value_t = 256, value_name = "N")]
    pub reference_spp: u32,
    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
    #[command(flatten)]
    pub solve: SolveOpts,
}

fn parse_point(s: &str) -> Result<DVec3, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let numbers: Vec<f64> =
        parts.iter().filter_map(|p| p.parse().ok()).filter(|v: &f64| v.is_finite()).collect();
    if parts.len() != 3 || numbers.len() != 3 {
        return Err(format!("expected three numbers x,y,z, got '{s}'"));
    }
    Ok(DVec3::new(numbers[0], numbers[1], numbers[2]))
}

fn input(msg: String) -> anyhow::Error {
    InputError(msg).into()
}

/// Runs `render`.
pub fn run(a: RenderArgs) -> Result<()> {
    if a.output.is_none() && a.exr.is_none() && a.pfm.is_none() {
        return Err(input("nothing to write: give -o out.png, --exr out.exr and/or --pfm out.pfm".into()));
    }
    let params = RenderParams {
        width: a.width,
        height: a.height,
        samples_per_pixel: a.spp.unwrap_or_else(|| Gather::from(a.gather).default_samples()),
        shading: match a.shading {
            ShadingArg::Smooth => Shading::Smooth,
            ShadingArg::Flat => Shading::Flat,
        },
        seed: a.solve.seed,
        gather: a.gather.into(),
        shadow_rays: a.shadow_rays,
        gather_rays: a.gather_rays,
        edge_factor: a.edge_factor,
        penumbra_factor: a.penumbra_factor,
    };
    params
        .validate()
        .map_err(|e| input(format!("--width, --height, --spp, --edge-factor, --penumbra-factor: {e}")))?;
    // Every target checked before the solve: folders, --force, and no file named twice.
    let mut targets = Targets::new(a.force);
    for (path, option) in [(&a.output, "-o"), (&a.exr, "--exr"), (&a.pfm, "--pfm")] {
        if let Some(path) = path {
            targets.file(path, option)?;
        }
    }
    if let Some(path) = &a.output {
        PictureFormat::of(path).map_err(|e| input(format!("-o: {e}")))?;
    }
    if a.false_colour.is_some() && (a.output.is_none() || a.reference) {
        return Err(input("--false-colour: give -o out.png for the picture (and no --reference)".into()));
    }
    let prepared = prepare(&a.scene, &a.solve)?;
    if a.false_colour.is_some() {
        check_photometric(&prepared, &a.scene)?;
    }
    let base = radiosity_image::camera_or_framing(&prepared.scene);
    // The points given are in the file's frame; the scene has been turned +y up.
    let turned = |p: DVec3| prepared.up.to_y_up(p);
    let (position, look_at) =
        (a.camera_position.map_or(base.position, turned), a.look_at.map_or(base.look_at, turned));
    // A camera placed by hand stands upright: the automatic framing of an open scene may look
    // straight down with +z up, which turned a level view on its side or upside down.
    let placed = prepared.scene.camera.is_none() && (a.camera_position.is_some() || a.look_at.is_some());
    let level = (look_at - position).normalize_or_zero().cross(DVec3::Y).length() > 1e-3;
    let up = if placed && level { DVec3::Y } else { base.up };
    let camera = Camera::try_new(position, look_at, up, a.fov.unwrap_or(base.fov_y_deg))
        .map_err(|e| input(format!("camera options (--camera-position, --look-at, --fov): {e}")))?;
    let lit = radiosity_image::lit_share_seen_by(&prepared.scene, &camera);
    if lit < 0.05 {
        note(format_args!(
            "warning: the camera sees almost no lit face ({:.0} % of a coarse probe): it looks at nothing or at the backs of one-sided surfaces, so the picture will be nearly black; move it (--camera-position, --look-at), or make the surfaces two-sided (--sides 2 for model files, sides = 2 in a scene file)",
            lit * 100.0
        ))?;
    }
    if a.reference {
        let radiance = crate::reference_run::reference_picture(
            &prepared,
            &camera,
            a.width,
            a.height,
            a.reference_spp,
            a.solve.seed,
        )?;
        return write_pictures(&a, &radiance);
    }

    let (solver, report) = run_solver(&prepared)?;
    let solution = solver.solution();
    // The solver's tables and kept rows are not needed past here: on a big model they are
    // as large as the picture's inputs.
    drop(solver);
    let start = Instant::now();
    // The solve used each material's mean reflectance; the picture shows its texture.
    let renderer = spinning("preparing the renderer", || {
        Renderer::new(prepared.problem.mesh().clone())
            .with_textures(&prepared.scene)
            .with_sky(prepared.scene.lighting.sky.clone())
    });
    // The irradiance cache is gathered before the first row: say so, and keep the line
    // ticking meanwhile, so a long gather does not look like a hang.
    let what = if params.gather == Gather::Full { "rendering (irradiance cache first)" } else { "rendering" };
    let progress = Progress::bar(what, u64::from(params.height), "rows");
    let rendering = renderer.render_with_progress(&solution, &camera, &params, &|| progress.inc())?;
    drop(progress);
    let render_secs = start.elapsed().as_secs_f64();

    note(format_args!(
        "{}: {} elements, {} shots, unshot {:.4} % ({}), solved in {:.2} s; rendered {}×{} at {} spp (gather {}) in {:.2} s",
        prepared.scene.name,
        prepared.problem.mesh().elements.len(),
        report.total_shots,
        report.unshot_fraction * 100.0,
        report.stop_reason.map_or("running", |s| s.as_str()),
        report.elapsed.as_secs_f64(),
        params.width,
        params.height,
        params.samples_per_pixel,
        params.gather.as_str(),
        render_secs
    ))?;
    if a.false_colour.is_some()
        && let Some(path) = &a.output
    {
        write_false_colour(&prepared, &rendering, path, a.force)?;
        return write_pictures(&RenderArgs { output: None, ..a }, &rendering.radiance);
    }
    write_pictures(&a, &rendering.radiance)
}

/// Writes the picture to every output asked for.
fn write_pictures(a: &RenderArgs, radiance: &HdrImage) -> Result<()> {
    if let Some(path) = &a.output {
        let ev = write_tonemapped(path, a.force, radiance, &a.tone)?;
        note(format_args!(
            "wrote {} (exposure {ev:+.2} EV, {})",
            path.display(),
            ToneOperator::from(a.tone.tonemap)
        ))?;
    }
    if let Some(path) = &a.exr {
        output::write_file(path, a.force, &encode_exr(radiance, path)?)?;
        note(format_args!("wrote {} (linear radiance)", path.display()))?;
    }
    if let Some(path) = &a.pfm {
        output::write_file(path, a.force, &encode_pfm(radiance))?;
        note(format_args!("wrote {} (linear radiance)", path.display()))?;
    }
    Ok(())
}
