//! Interactive viewer of the radiosity renderer: the solver runs on a worker thread while the
//! window shows the newest solution, tone mapped on the GPU, and a fly-through camera walks
//! through the scene as it converges.
//!
//! The parts that need no window are plain Rust and tested as such: [`camera`] (view and
//! projection maths, movement, framing) and [`worker`] (the solve thread and its protocol).
//! [`render`] draws into any [`RenderTarget`] it is given (the window's view, a screenshot, a
//! headless test texture), and the eframe application ties them together.
#![warn(missing_docs)]
#![forbid(unsafe_code)]

mod app;
pub mod camera;
pub mod coarse;
pub mod render;
mod still;
pub mod worker;

use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use radiosity_core::{MeshParams, Scene, UpAxis};
use radiosity_solver::SolverParams;

pub use app::{KEY_HINT, ViewState};
pub use camera::{FlyCamera, MoveInput, SceneExtent};
pub use render::{
    COLOR_FORMAT, Detail, DisplayMode, FrameParams, RenderTarget, SCENE_WGSL, SceneRenderer, TONEMAP_WGSL,
    Wireframe, headless_gpu,
};
pub use worker::{Progress, Snapshot, SolveJob, SolveWorker, Status, WorkerOptions, WorkerState};

/// What `radiosity view` opens, and how.
#[derive(Clone, Debug)]
pub struct ViewerOptions {
    /// The scene, before the light scale, turned +y up.
    pub scene: Scene,
    /// The up axis of the file `scene` was read from (it has been turned by it, see
    /// [`Scene::rotate_to_y_up`]); the panel's up setting starts here and turns the scene live.
    pub up: UpAxis,
    /// What the user typed to open it (path or built-in name), shown in the panel.
    pub scene_label: String,
    /// Factor on every emission, > 0.
    pub light_scale: f64,
    /// Subdivision; `None`: the scene's own ([`Scene::mesh_params`]).
    pub mesh_params: Option<MeshParams>,
    /// Solver settings.
    pub solver_params: SolverParams,
    /// Solver threads; `None`: all cores but one.
    pub threads: Option<usize>,
    /// Write the window's content to this PNG once the solve reaches `after_shots` (or stops,
    /// without it), then exit.
    pub screenshot: Option<PathBuf>,
    /// Shots before the screenshot; the solve pauses there.
    pub after_shots: Option<u64>,
    /// Folder where P writes pictures of the view.
    pub screenshot_dir: PathBuf,
    /// Redraw every frame rather than only on change (shows the highest frame rate).
    pub continuous: bool,
    /// Initial window size, points.
    pub window_size: [f32; 2],
    /// Samples per pixel of the window (1 or 4); see [`default_samples`].
    pub samples: u32,
    /// What the surfaces show at start.
    pub display: DisplayMode,
    /// Subdivision lines at start.
    pub wireframe: Wireframe,
    /// How much of a big mesh is drawn, at start.
    pub detail: Detail,
    /// Exposure in stops at start; `None`: automatic (the log-average luminance of the lit
    /// surfaces in view to middle grey, see `render::auto_exposure_ev`).
    pub exposure_ev: Option<f64>,
    /// Tone-map operator at start.
    pub operator: radiosity_image::ToneOperator,
    /// The command line that opened the viewer, as the user would type it again: the error
    /// when no window can be opened shows it under `scripts/xvfb-run.sh`.
    pub command: String,
}

impl ViewerOptions {
    /// Options to view `scene` with its own settings.
    pub fn new(scene: Scene, scene_label: &str) -> Self {
        Self {
            scene,
            up: UpAxis::Y,
            scene_label: scene_label.to_owned(),
            light_scale: 1.0,
            mesh_params: None,
            solver_params: SolverParams::default(),
            threads: None,
            screenshot: None,
            after_shots: None,
            screenshot_dir: PathBuf::from("."),
            continuous: false,
            window_size: [1200.0, 760.0],
            samples: default_samples(),
            display: DisplayMode::Smooth,
            wireframe: Wireframe::Off,
            detail: Detail::Auto,
            exposure_ev: None,
            operator: radiosity_image::ToneOperator::Aces,
            command: format!("radiosity view {scene_label}"),
        }
    }
}

/// Opens the viewer window and runs until it is closed (or, with a screenshot asked for,
/// until the screenshot is written).
///
/// # Errors
/// When no window or GPU adapter can be had (the message says to use Xvfb on a headless
/// machine), or a scripted screenshot could not be taken or written.
pub fn run(options: ViewerOptions) -> anyhow::Result<()> {
    let title = format!("radiosity — {}", options.scene.name);
    let native = eframe::NativeOptions {
        viewport: eframe::egui::ViewportBuilder::default()
            .with_title(&title)
            .with_app_id("radiosity")
            .with_inner_size(options.window_size)
            .with_drag_and_drop(true),
        renderer: eframe::Renderer::Wgpu,
        // The 3D view is drawn inside egui's pass and needs its depth buffer (reversed z).
        depth_buffer: 32,
        multisampling: options.samples.clamp(1, 4) as u16,
        // Dithering adds noise to every pixel, the 3D view included, for nothing: the view is
        // already 8-bit sRGB.
        dithering: false,
        ..Default::default()
    };
    let command = options.command.clone();
    let outcome: app::Outcome = Arc::new(Mutex::new(None));
    let app_outcome = outcome.clone();
    eframe::run_native(
        "radiosity",
        native,
        Box::new(move |cc| {
            let app = app::ViewerApp::new(cc, options, app_outcome)?;
            Ok(Box::new(app))
        }),
    )
    .map_err(|e| window_error(&e, &command))?;
    let result = outcome.lock().unwrap_or_else(|e| e.into_inner()).take();
    result.unwrap_or(Ok(()))
}

/// The error for a window that could not be opened. Without a display (none set, or one
/// that cannot be reached) what to do comes first, then the cause as winit gives it, without
/// the location in winit's source that its message carries.
fn window_error(e: &eframe::Error, command: &str) -> anyhow::Error {
    let cause = without_source_locations(&e.to_string());
    match e {
        eframe::Error::Winit(_) | eframe::Error::WinitEventLoop(_) => anyhow::anyhow!(
            "no display to open a window on (DISPLAY/WAYLAND_DISPLAY unset or unusable); run it under a \
             virtual display: scripts/xvfb-run.sh {command} (cause: {cause})"
        ),
        _ => anyhow::anyhow!("cannot open the viewer window: {cause}"),
    }
}

/// `text` without the source locations that winit puts in its errors ("os error at
/// /…/.cargo/registry/…/winit-…/src/platform_impl/linux/mod.rs:765: neither … is set"): a path
/// into someone's crate cache tells the user nothing.
fn without_source_locations(text: &str) -> String {
    let mut words: Vec<&str> = Vec::new();
    for word in text.split(' ') {
        if word.contains(".rs:") && word.contains('/') {
            // The location's lead-in ("os error at") goes with it.
            if words.last() == Some(&"at") {
                words.pop();
            }
            if words.ends_with(&["os", "error"]) {
                words.truncate(words.len() - 2);
            }
            continue;
        }
        words.push(word);
    }
    words.join(" ")
}

/// Samples per pixel for the window: 4 (smooth edges) on a GPU, 1 on a CPU rasteriser
/// (lavapipe, llvmpipe) where each sample costs CPU time. Asks wgpu for the adapter the window
/// will most likely get; `RADIOSITY_MSAA=1` or `=4` overrides.
pub fn default_samples() -> u32 {
    if let Some(n) = std::env::var("RADIOSITY_MSAA").ok().and_then(|v| v.parse::<u32>().ok()) {
        return if n >= 4 { 4 } else { 1 };
    }
    // Without a display there will be no window to draw in; spare the probe (and Mesa's
    // warnings) and let `run` say what to do.
    if cfg!(target_os = "linux")
        && ["DISPLAY", "WAYLAND_DISPLAY", "WAYLAND_SOCKET"].iter().all(|v| std::env::var_os(v).is_none())
    {
        return 1;
    }
    use eframe::wgpu;
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    match pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default())) {
        Ok(a) if a.get_info().device_type != wgpu::DeviceType::Cpu => 4,
        _ => 1,
    }
}

/// Loads a scene file or built-in name, the error on one line as the command prints it
/// ([`radiosity_core::one_line`]), with closed models lit from one side made one-sided as the
/// command does ([`radiosity_mesh::seal_closed_objects`]). The loader's warnings are
/// dropped: the window has no place for them yet.
fn load_scene(arg: &str) -> Result<Scene, String> {
    let mut scene = radiosity_io::resolve_scene(arg).map_err(|e| radiosity_core::one_line(&e))?.scene;
    radiosity_mesh::seal_closed_objects(&mut scene);
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The window shows the loader's error as the command prints it: one line, naming the
    /// file and line.
    #[test]
    fn a_bad_scene_file_gives_the_command_line_error() {
        let path = std::env::temp_dir().join(format!("radiosity-viewer-bad-{}.toml", std::process::id()));
        std::fs::write(&path, "name = \"x\"\n[[material]]\nname = \"m\"\nreflectance = [2, 0, 0]\n").unwrap();
        let arg = path.display().to_string();
        let shown = load_scene(&arg).unwrap_err();
        let command = radiosity_io::resolve_scene(&arg).unwrap_err().to_string();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(shown, command);
        assert_eq!(shown.lines().count(), 1);
        assert!(shown.starts_with(&format!("{arg}:")), "{shown}");
        let missing = load_scene("no-such-scene-anywhere").unwrap_err();
        assert!(missing.contains("no-such-scene-anywhere"), "{missing}");
        assert!(load_scene("cornell").is_ok());
    }

    /// A scene opened in the window has its closed models lit from one side made one-sided, as
    /// the command's: a cube (an OBJ, so two-sided) under a lamp.
    #[test]
    fn the_window_seals_closed_models_as_the_command_does() {
        let dir = std::env::temp_dir().join(format!("radiosity-viewer-sealed-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // The lamp's corners are vertices 1–4, the cube's 5–12; every face wound outwards.
        let obj = "mtllib m.mtl\no lamp\nusemtl lamp\nv 0 3 0\nv 1 3 0\nv 1 3 1\nv 0 3 1\nf 1 2 3 4\n\
                   o cube\nusemtl grey\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
                   f 5 8 7 6\nf 9 10 11 12\nf 5 6 10 9\nf 8 12 11 7\nf 5 9 12 8\nf 6 7 11 10\n";
        std::fs::write(dir.join("cube.obj"), obj).unwrap();
        std::fs::write(dir.join("m.mtl"), "newmtl grey\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0 0 0\nKe 5 5 5\n")
            .unwrap();
        let scene = load_scene(&dir.join("cube.obj").display().to_string()).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        let sides: Vec<_> = scene.objects.iter().map(|o| (o.name.as_str(), o.sides)).collect();
        assert!(sides.contains(&("cube", radiosity_core::Sides::One)), "{sides:?}");
    }

    /// winit's message loses the path into its source, keeps what went wrong.
    #[test]
    fn source_locations_are_left_out_of_window_errors() {
        let winit = "winit EventLoopError: os error at /root/.cargo/registry/src/index.crates.io-1949cf8c6b5b557f/\
                     winit-0.30.13/src/platform_impl/linux/mod.rs:765: neither WAYLAND_DISPLAY nor DISPLAY is set.";
        assert_eq!(
            without_source_locations(winit),
            "winit EventLoopError: neither WAYLAND_DISPLAY nor DISPLAY is set."
        );
        assert_eq!(without_source_locations("no adapter at all"), "no adapter at all");
    }
}
