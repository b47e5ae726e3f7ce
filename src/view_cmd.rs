//! `radiosity view`: the interactive window, solving while you walk through the scene.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::Result;
use clap::{Args, ValueEnum};
use radiosity_core::MeshParams;
use radiosity_image::Exposure;
use radiosity_solver::{Ambient, FormFactorMethod, Overshoot, SolverParams};
use radiosity_viewer::{DisplayMode, Wireframe};

use crate::prepare::{FormFactorArg, InputError, SolveOpts, check_writable};
use crate::render_cmd::ToneOpts;

/// What the surfaces show, on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum DisplayArg {
    /// Vertex radiosity interpolated across elements.
    Smooth,
    /// Each element's own radiosity.
    Flat,
    /// False colour of log luminance, with a legend.
    FalseColour,
    /// False colour of the unshot radiosity still waiting to be shot.
    Unshot,
}

/// Subdivision lines on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum WireframeArg {
    /// None.
    Off,
    /// Patch outlines.
    Patches,
    /// Element and patch outlines.
    Elements,
}

/// Arguments of `radiosity view`.
#[derive(Args)]
pub struct ViewArgs {
    /// Scene file (.toml) or built-in name.
    #[arg(default_value = "cornell")]
    pub scene: String,
    /// Write the window's content to this PNG once the solve has done --after-shots shots (or
    /// has stopped, without it), then exit. Runs headless under scripts/xvfb-run.sh.
    #[arg(long, value_name = "PNG")]
    pub screenshot: Option<PathBuf>,
    /// Shots before the screenshot; the solve pauses there.
    #[arg(long, value_name = "N", requires = "screenshot")]
    pub after_shots: Option<u64>,
    /// Overwrite the screenshot file if it exists.
    #[arg(long)]
    pub force: bool,
    /// Redraw every frame, not only when something changes (shows the highest frame rate; with
    /// --screenshot, also prints it).
    #[arg(long)]
    pub continuous: bool,
    /// Window width, points.
    #[arg(long, default_value_t = 1200.0)]
    pub width: f32,
    /// Window height, points.
    #[arg(long, default_value_t = 760.0)]
    pub height: f32,
    /// What the surfaces show at start (the panel changes it).
    #[arg(long, value_enum, default_value_t = DisplayArg::Smooth)]
    pub display: DisplayArg,
    /// Subdivision lines at start.
    #[arg(long, value_enum, default_value_t = WireframeArg::Off)]
    pub wireframe: WireframeArg,
    #[command(flatten)]
    pub tone: ToneOpts,
    #[command(flatten)]
    pub solve: SolveOpts,
}

fn input(msg: String) -> anyhow::Error {
    InputError(msg).into()
}

/// Runs `view`: loads the scene (errors exit with code 2 before any window opens), then hands
/// it to the viewer, which meshes and solves it on a worker thread.
pub fn run(a: ViewArgs) -> Result<()> {
    let o = &a.solve;
    let scene = radiosity_io::resolve_scene(&a.scene)?;
    // The same rules as every solving command (see prepare::prepare), without meshing here:
    // the viewer meshes on its worker so the window opens at once.
    if o.threads == Some(0) {
        return Err(input("--threads must be at least 1".into()));
    }
    if !(o.light_scale.is_finite() && o.light_scale > 0.0) {
        return Err(input(format!("--light-scale must be a finite number > 0, got {}", o.light_scale)));
    }
    let base = scene.mesh_params();
    let patch = o.patch_size.unwrap_or(base.patch_size);
    let element = o.element_size.unwrap_or(if o.patch_size.is_some() {
        patch.min(base.element_size)
    } else {
        base.element_size
    });
    let mesh_params = MeshParams::try_new(patch, element).map_err(|e| input(format!("mesh options: {e}")))?;
    let time_limit = match o.time_limit.or(scene.solver.time_limit) {
        Some(t) if t.is_finite() && t >= 0.0 => Some(Duration::from_secs_f64(t)),
        Some(t) => return Err(input(format!("--time-limit must be a number of seconds ≥ 0, got {t}"))),
        None => None,
    };
    let solver_params = SolverParams {
        form_factor: match o.form_factor {
            FormFactorArg::Exact => FormFactorMethod::Exact,
            FormFactorArg::Point => FormFactorMethod::PointToPoint,
        },
        visibility_rays: o.visibility_rays,
        unshot_threshold: o.unshot_threshold.or(scene.solver.unshot_threshold).unwrap_or(1e-3),
        max_shots: o.max_shots.or(scene.solver.max_shots),
        time_limit,
        seed: o.seed,
        ambient: if o.ambient { Ambient::On } else { Ambient::Off },
        overshoot: if o.overshoot == 1.0 { Overshoot::Off } else { Overshoot::Relaxation(o.overshoot) },
        ..SolverParams::default()
    };
    if let Some(path) = &a.screenshot {
        check_writable(path, a.force)?;
    }
    if !(a.width >= 200.0 && a.height >= 150.0) {
        return Err(input(format!("the window must be at least 200×150, got {}×{}", a.width, a.height)));
    }
    let mut options = radiosity_viewer::ViewerOptions::new(scene, &a.scene);
    options.light_scale = o.light_scale;
    options.mesh_params = Some(mesh_params);
    options.solver_params = solver_params;
    options.threads = o.threads;
    options.screenshot = a.screenshot;
    options.after_shots = a.after_shots;
    options.continuous = a.continuous;
    options.window_size = [a.width, a.height];
    options.display = match a.display {
        DisplayArg::Smooth => DisplayMode::Smooth,
        DisplayArg::Flat => DisplayMode::FlatElements,
        DisplayArg::FalseColour => DisplayMode::FalseColour,
        DisplayArg::Unshot => DisplayMode::Unshot,
    };
    options.wireframe = match a.wireframe {
        WireframeArg::Off => Wireframe::Off,
        WireframeArg::Patches => Wireframe::Patches,
        WireframeArg::Elements => Wireframe::Elements,
    };
    options.exposure_ev = match a.tone.exposure {
        Exposure::Ev(ev) => Some(ev),
        Exposure::Auto => None,
    };
    options.operator = a.tone.tonemap.into();
    radiosity_viewer::run(options)
}
