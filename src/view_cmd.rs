//! `radiosity view`: the interactive window, solving while you walk through the scene.

use std::path::PathBuf;

use anyhow::Result;
use clap::{Args, ValueEnum};
use radiosity_image::Exposure;
use radiosity_viewer::{Detail, DisplayMode, Wireframe};

use crate::errors::InputError;
use crate::load_scene::{Settings, settings};
use crate::output::Targets;
use crate::picture_opts::ToneOpts;
use crate::solve_opts::SolveOpts;

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
    /// False colour of the light arriving: lux in a photometric scene.
    Illuminance,
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

/// How much of a big mesh the window draws, on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum DetailArg {
    /// On a CPU rasteriser, a coarse copy of a big mesh (over 400 k triangles) while the camera
    /// moves or the solve runs, every element once the view rests; on a GPU, every element.
    Auto,
    /// Every element, always.
    Full,
    /// The coarse copy, always (for a big mesh).
    Coarse,
}

/// Arguments of `radiosity view`.
#[derive(Args)]
pub struct ViewArgs {
    /// The scene to load: see [`SCENE_HELP`](crate::solve_opts::SCENE_HELP).
    #[arg(help = crate::solve_opts::SCENE_HELP, default_value = "cornell")]
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
    /// How much of a big mesh is drawn, at start (the panel changes it).
    #[arg(long, value_enum, default_value_t = DetailArg::Auto)]
    pub detail: DetailArg,
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
    // The same option rules as every solving command, without meshing here: the viewer
    // meshes on its worker so the window opens at once.
    let Settings { scene, mesh_params, solver_params, up } = settings(&a.scene, o)?;
    if let Some(path) = &a.screenshot {
        Targets::new(a.force).file(path, "--screenshot")?;
    }
    if !(a.width >= 200.0 && a.height >= 150.0) {
        return Err(input(format!("the window must be at least 200×150, got {}×{}", a.width, a.height)));
    }
    let mut options = radiosity_viewer::ViewerOptions::new(scene, &a.scene);
    options.up = up;
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
        DisplayArg::Illuminance => DisplayMode::Illuminance,
    };
    options.wireframe = match a.wireframe {
        WireframeArg::Off => Wireframe::Off,
        WireframeArg::Patches => Wireframe::Patches,
        WireframeArg::Elements => Wireframe::Elements,
    };
    options.detail = match a.detail {
        DetailArg::Auto => Detail::Auto,
        DetailArg::Full => Detail::Full,
        DetailArg::Coarse => Detail::Coarse,
    };
    options.exposure_ev = match a.tone.exposure {
        Exposure::Ev(ev) => Some(ev),
        Exposure::Auto => None,
        Exposure::AutoPlus(_) => {
            return Err(crate::errors::InputError(
                "--exposure auto±EV is for pictures; in the viewer, start from auto and use its exposure slider".into(),
            )
            .into());
        }
    };
    options.operator = a.tone.tonemap.into();
    options.command = command_line();
    radiosity_viewer::run(options)
}

/// This process's command line as the user would type it again (`radiosity view …`, with
/// its options), for the error that says to run it under a virtual display.
fn command_line() -> String {
    let quote = |arg: String| {
        if !arg.is_empty() && arg.chars().all(|c| c.is_ascii_alphanumeric() || "-_./=:,+@%".contains(c)) {
            arg
        } else {
            format!("'{}'", arg.replace('\'', r"'\''"))
        }
    };
    std::iter::once("radiosity".to_owned())
        .chain(std::env::args().skip(1).map(quote))
        .collect::<Vec<_>>()
        .join(" ")
}
