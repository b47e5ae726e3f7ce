//! The window: an egui panel beside the 3D view, camera input, scene loading, screenshots.
//!
//! Every frame reads the newest snapshot the worker published (never waiting for it), uploads
//! its colours when it is new, and adds the 3D view as a paint callback that draws the mesh
//! straight into egui's render pass. Slow work — loading a file, meshing, solving — happens on
//! other threads, so the window stays responsive whatever the scene.

use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::mpsc::{Receiver, TryRecvError};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use eframe::egui::{self, Color32, Key, Pos2, Rect, Sense, Vec2};
use eframe::{egui_wgpu, wgpu};
use radiosity_core::Camera;
use radiosity_core::{MeshParams, Scene, UpAxis};
use radiosity_image::{Exposure, Gather, SrgbImage, ToneOperator, ToneParams, tone_map_image};

use crate::ViewerOptions;
use crate::camera::{FlyCamera, MoveInput, SceneExtent};
use crate::render::{
    Detail, DisplayMode, FrameParams, RenderTarget, SceneRenderer, Wireframe, auto_exposure_ev, false_colour,
    false_colour_range,
};
use crate::still::{Still, StillJob, StillPoll};
use crate::worker::{SolveJob, SolveWorker, Status, WorkerOptions, WorkerState};

/// Mouse-look sensitivity, radians per point dragged.
const LOOK_RADIANS_PER_POINT: f64 = 0.004;
/// Wheel scroll (points) per speed notch.
const POINTS_PER_NOTCH: f32 = 50.0;
/// Longest frame time used for movement, so a frame after an idle pause does not jump.
const MAX_MOVE_DT: f64 = 1.0 / 20.0;
/// Clear colour of the 3D view (display values): a dark grey that neither red nor green
/// walls nor black unlit surfaces can be confused with.
const BACKGROUND: [f32; 4] = [0.11, 0.11, 0.12, 1.0];

/// The key hint shown under the 3D view.
pub const KEY_HINT: &str = "WASD/arrows move · Q/E or Ctrl/Space down/up · drag to look · wheel: speed · \
                            Shift: run · R reset · F frame all · P screenshot · G render still";

/// What the user chose to see: camera and display settings. Kept apart from runtime state
/// (GPU buffers, keys held, the worker) so a restart or a re-mesh never loses it.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewState {
    /// The fly-through camera.
    pub camera: FlyCamera,
    /// Exposure follows what the camera sees (the log-average luminance of its lit surfaces,
    /// lamps left out, goes to middle grey, held down so the brightest stay under white), as
    /// `render`'s default `--exposure auto` does for its picture.
    pub auto_exposure: bool,
    /// Exposure in stops when not automatic.
    pub exposure_ev: f64,
    /// Tone-map operator.
    pub operator: ToneOperator,
    /// What the surfaces show.
    pub mode: DisplayMode,
    /// Subdivision lines.
    pub wireframe: Wireframe,
    /// How much of a big mesh is drawn.
    pub detail: Detail,
}

/// Frames per second over the last second of drawn frames.
#[derive(Default)]
struct FpsCounter {
    frames: VecDeque<Instant>,
}

impl FpsCounter {
    fn tick(&mut self, now: Instant) {
        self.frames.push_back(now);
        while self.frames.front().is_some_and(|t| now.duration_since(*t) > Duration::from_secs(1)) {
            self.frames.pop_front();
        }
    }

    fn fps(&self) -> f64 {
        match (self.frames.front(), self.frames.back()) {
            (Some(a), Some(b)) if self.frames.len() > 1 => {
                (self.frames.len() - 1) as f64 / b.duration_since(*a).as_secs_f64().max(1e-9)
            }
            _ => 0.0,
        }
    }
}

/// A `--screenshot` asked for and not yet written.
struct Capture {
    path: PathBuf,
    image: Arc<Mutex<Option<Arc<egui::ColorImage>>>>,
    requested: bool,
    /// The frame rate just before the capture, with the solver idle: the capture's own frames
    /// draw every element (and upload their colours), which is not what was being measured.
    idle_fps: f64,
}

/// Scene sizes the subdivision sliders work in.
#[derive(Clone, Copy)]
struct Subdivision {
    light_scale: f64,
    patch_size: f64,
    element_size: f64,
    /// Levels of adaptive subdivision (see `MeshParams::adaptive_levels`).
    adaptive_levels: u32,
}

/// Outcome of a scripted run, read by [`crate::run`] after the window closes.
pub(crate) type Outcome = Arc<Mutex<Option<anyhow::Result<()>>>>;

/// The eframe application.
pub struct ViewerApp {
    view: ViewState,
    render_state: egui_wgpu::RenderState,
    /// The view's size in pixels at the last frame (for P screenshots).
    view_size: [u32; 2],
    worker: SolveWorker,
    /// The job last asked for; panel edits build on it.
    job: SolveJob,
    status: Status,
    /// The snapshot whose colours are on the GPU.
    shown: Option<Arc<crate::worker::Snapshot>>,
    shown_mode: DisplayMode,
    /// The scene the camera was set up for.
    camera_scene: Option<Arc<Scene>>,
    extent: SceneExtent,
    log_range: (f64, f64),
    /// The automatic exposure as it adapts, stops.
    auto_ev: Option<f64>,
    subdivision: Subdivision,
    /// The up axis of the file the scene came from, as the scene is now turned (the panel
    /// changes it: the scene turns and the solve restarts).
    up: UpAxis,
    open_text: String,
    loading: Option<(String, Receiver<Result<Scene, String>>)>,
    load_error: Option<String>,
    message: Option<String>,
    fps: FpsCounter,
    continuous: bool,
    /// Where P writes its pictures.
    screenshot_dir: PathBuf,
    capture: Option<Capture>,
    /// `--screenshot` path, taken once the solve reaches `after_shots` (or stops).
    scripted: Option<(PathBuf, Option<u64>)>,
    outcome: Outcome,
    last_frame: Option<Instant>,
    /// Time since the previous frame, seconds (capped at [`MAX_MOVE_DT`]).
    last_dt: f64,
    /// When a scripted run reached its mark, and the frame rate while it was solving.
    mark: Option<(Instant, f64)>,
    /// A still being rendered with a final gather (G).
    still_job: Option<StillJob>,
    /// The last still, tone mapped onto a texture, shown in its own window until closed.
    still: Option<(Still, egui::TextureHandle, SrgbImage)>,
    /// Whether the view is drawn by a CPU rasteriser (lavapipe, llvmpipe), where
    /// [`Detail::Auto`] draws a big mesh's coarse copy while things change.
    software: bool,
    /// When the camera last moved.
    last_motion: Option<Instant>,
    /// Whether the last frame drew the coarse copy.
    coarse: bool,
}

/// With continuous redraw, how long a scripted run keeps drawing after its mark before the
/// screenshot, to measure the frame rate with the solver idle.
const FPS_MEASURE: Duration = Duration::from_secs(3);

/// How long the view must rest before [`Detail::Auto`] draws every element again: long enough
/// that the pauses between key presses or drags do not flicker to full detail and back.
const REST: Duration = Duration::from_millis(300);

/// Time constant of the automatic exposure's adaptation, seconds.
const ADAPTATION: f64 = 0.3;

impl ViewerApp {
    /// Sets up GPU resources and starts the solve worker.
    ///
    /// # Errors
    /// When eframe runs without wgpu.
    pub(crate) fn new(
        cc: &eframe::CreationContext<'_>,
        options: ViewerOptions,
        outcome: Outcome,
    ) -> anyhow::Result<Self> {
        let render_state = cc
            .wgpu_render_state
            .clone()
            .ok_or_else(|| anyhow::anyhow!("the viewer needs eframe's wgpu renderer"))?;
        let info = render_state.adapter.get_info();
        let software = info.device_type == wgpu::DeviceType::Cpu;
        log::info!("drawing with {} ({:?}, {:?})", info.name, info.backend, info.device_type);
        // The renderer draws inside egui's render pass, so it lives with egui's renderer and
        // is made for egui's target format and sample count.
        let renderer = SceneRenderer::new(&render_state.device, render_state.target_format, options.samples);
        render_state.renderer.write().callback_resources.insert(renderer);
        let up = options.up;
        let scene = Arc::new(options.scene);
        let mesh_params = options.mesh_params.unwrap_or_else(|| scene.mesh_params());
        let job = SolveJob {
            label: options.scene_label,
            scene: scene.clone(),
            light_scale: options.light_scale,
            mesh_params,
            solver_params: options.solver_params,
        };
        let ctx = cc.egui_ctx.clone();
        let worker = SolveWorker::spawn(
            job.clone(),
            WorkerOptions {
                threads: options.threads,
                start_paused: false,
                pause_at_shots: options.after_shots.filter(|_| options.screenshot.is_some()),
                notify: Some(Arc::new(move || ctx.request_repaint())),
            },
        );
        let (lo, hi) = scene.bounds();
        let extent = SceneExtent::new(lo, hi);
        let camera = FlyCamera::from_scene_camera(&radiosity_image::camera_or_framing(&scene), &extent);
        Ok(Self {
            view: ViewState {
                camera,
                auto_exposure: options.exposure_ev.is_none(),
                exposure_ev: options.exposure_ev.unwrap_or(0.0),
                operator: options.operator,
                mode: options.display,
                wireframe: options.wireframe,
                detail: options.detail,
            },
            render_state,
            view_size: [1, 1],
            status: worker.status(),
            worker,
            subdivision: Subdivision {
                light_scale: job.light_scale,
                patch_size: job.mesh_params.patch_size,
                element_size: job.mesh_params.element_size,
                adaptive_levels: job.mesh_params.adaptive_levels,
            },
            up,
            open_text: String::new(),
            job,
            shown: None,
            shown_mode: DisplayMode::Smooth,
            camera_scene: Some(scene),
            extent,
            log_range: (-1.0, 0.0),
            auto_ev: None,
            loading: None,
            load_error: None,
            message: None,
            fps: FpsCounter::default(),
            continuous: options.continuous,
            screenshot_dir: options.screenshot_dir,
            capture: None,
            scripted: options.screenshot.map(|p| (p, options.after_shots)),
            outcome,
            last_frame: None,
            last_dt: 0.0,
            mark: None,
            still_job: None,
            still: None,
            software,
            last_motion: None,
            coarse: false,
        })
    }

    /// Starts a new job, keeping the paused/running state.
    fn restart_with(&mut self, job: SolveJob) {
        self.job = job.clone();
        self.worker.restart(Some(job));
    }

    fn apply_subdivision(&mut self) {
        let s = self.subdivision;
        // The sliders' sizes and levels over the job's other mesh settings (contacts, crease
        // angle, corner grading), which the command line or the scene file chose.
        let sized = MeshParams::try_new(s.patch_size, s.element_size).map(|m| MeshParams {
            patch_size: m.patch_size,
            element_size: m.element_size,
            ..self.job.mesh_params
        });
        match sized.and_then(|m| m.with_adaptive_levels(s.adaptive_levels)) {
            Ok(mesh_params) => {
                // Elements are never larger than their patches: show what will be used.
                self.subdivision.element_size = mesh_params.element_size;
                let job = SolveJob { light_scale: s.light_scale, mesh_params, ..self.job.clone() };
                self.restart_with(job);
            }
            Err(e) => self.message = Some(format!("subdivision: {e}")),
        }
    }

    /// Turns the scene as read from a file whose up axis is `up` instead of the current one,
    /// and solves it again: a z-up building model read +y up lies on its side until then.
    fn set_up(&mut self, up: UpAxis) {
        if up == self.up {
            return;
        }
        let mut scene = Scene::clone(&self.job.scene);
        scene.rotate_from_y_up(self.up);
        scene.rotate_to_y_up(up);
        self.up = up;
        // A new scene: the camera frames it afresh once its first snapshot arrives.
        let job = SolveJob { scene: Arc::new(scene), ..self.job.clone() };
        self.restart_with(job);
    }

    /// Loads a scene file (or built-in name) on a helper thread; the old scene stays until it
    /// has loaded and meshed.
    fn open(&mut self, ctx: &egui::Context, arg: String) {
        let arg = arg.trim().to_owned();
        if arg.is_empty() {
            return;
        }
        let (tx, rx) = std::sync::mpsc::channel();
        let ctx = ctx.clone();
        let what = arg.clone();
        std::thread::spawn(move || {
            let result = crate::load_scene(&what);
            let _ = tx.send(result);
            ctx.request_repaint();
        });
        self.load_error = None;
        self.loading = Some((arg, rx));
    }

    fn poll_loading(&mut self) {
        let Some((arg, rx)) = &self.loading else { return };
        match rx.try_recv() {
            Ok(Ok(scene)) => {
                let arg = arg.clone();
                self.loading = None;
                let scene = Arc::new(scene);
                let mesh_params = scene.mesh_params();
                self.subdivision = Subdivision {
                    light_scale: 1.0,
                    patch_size: mesh_params.patch_size,
                    element_size: mesh_params.element_size,
                    adaptive_levels: mesh_params.adaptive_levels,
                };
                let mut solver_params = self.job.solver_params.clone();
                // The new scene's own stop settings replace the old scene's.
                solver_params.max_shots = scene.solver.max_shots;
                solver_params.time_limit = scene.solver.time_limit.map(Duration::from_secs_f64);
                if let Some(t) = scene.solver.unshot_threshold {
                    solver_params.unshot_threshold = t;
                }
                let job = SolveJob { label: arg, scene, light_scale: 1.0, mesh_params, solver_params };
                // Files opened here are read +y up; the panel turns them.
                self.up = UpAxis::Y;
                self.restart_with(job);
                // A scene just opened is there to be seen lit, whatever the old one was doing.
                self.worker.resume();
            }
            Ok(Err(e)) => {
                self.load_error = Some(e);
                self.loading = None;
            }
            Err(TryRecvError::Empty) => {}
            Err(TryRecvError::Disconnected) => {
                self.load_error = Some(format!("{arg}: the loader stopped unexpectedly"));
                self.loading = None;
            }
        }
    }

    /// Takes the newest snapshot to the GPU if it is new or the display mode changed.
    fn sync_snapshot(&mut self) {
        self.status = self.worker.status();
        let Some(snap) = self.worker.latest() else { return };
        let is_new = self.shown.as_ref().is_none_or(|s| !Arc::ptr_eq(s, &snap));
        if !is_new && self.shown_mode == self.view.mode {
            return;
        }
        {
            let mut egui_renderer = self.render_state.renderer.write();
            if let Some(renderer) = egui_renderer.callback_resources.get_mut::<SceneRenderer>() {
                renderer.set_mesh(&self.render_state.device, &snap.mesh);
                renderer.set_solution(&self.render_state.queue, &snap.solution, self.view.mode);
            }
        }
        self.shown_mode = self.view.mode;
        if self.view.mode.is_false_colour() {
            self.log_range = false_colour_range(&snap.solution, self.view.mode);
        }
        // A new scene (not a re-mesh of the same one) gets its own camera.
        if self.camera_scene.as_ref().is_none_or(|s| !Arc::ptr_eq(s, &snap.job.scene)) {
            let (lo, hi) = snap.mesh.bounds();
            self.extent = SceneExtent::new(lo, hi);
            self.view.camera = FlyCamera::from_scene_camera(
                &radiosity_image::camera_or_framing(&snap.job.scene),
                &self.extent,
            );
            self.camera_scene = Some(snap.job.scene.clone());
        }
        self.shown = Some(snap);
    }

    /// Whether this frame draws the big mesh's coarse copy: see [`Detail`]. A screenshot being
    /// taken and subdivision lines (which the coarse copy has not) always get every element.
    fn wants_coarse(&self, now: Instant) -> bool {
        match self.view.detail {
            Detail::Full => false,
            Detail::Coarse => true,
            Detail::Auto => {
                let changing = self.last_motion.is_some_and(|t| now.duration_since(t) < REST)
                    || self.status.state == WorkerState::Running
                    || self.continuous;
                self.software && changing && self.view.wireframe == Wireframe::Off && self.capture.is_none()
            }
        }
    }

    /// Tells the renderer which copy to draw; going back to every element uploads the shown
    /// solution's colours, which only the coarse copy got meanwhile.
    fn sync_detail(&mut self, coarse: bool) {
        self.coarse = coarse;
        let mut egui_renderer = self.render_state.renderer.write();
        let Some(renderer) = egui_renderer.callback_resources.get_mut::<SceneRenderer>() else { return };
        renderer.set_coarse(coarse);
        if !coarse
            && renderer.full_colours_stale()
            && let Some(snap) = &self.shown
        {
            renderer.set_solution(&self.render_state.queue, &snap.solution, self.view.mode);
        }
    }

    fn exposure_ev(&self) -> f64 {
        if self.view.auto_exposure { self.auto_ev.unwrap_or(0.0) } else { self.view.exposure_ev }
    }

    /// Follows the automatic exposure for the current view, easing towards it like an eye
    /// adapting (time constant [`ADAPTATION`]) so walking past a lamp does not flash; a
    /// scripted screenshot takes the exact value. Returns whether it is still adapting.
    fn adapt_exposure(&mut self, size_px: [u32; 2], dt: f64) -> bool {
        let Some(snap) = &self.shown else { return false };
        let aspect = f64::from(size_px[0].max(1)) / f64::from(size_px[1].max(1));
        let clip = self.view.camera.clip_from_view(aspect) * self.view.camera.view_from_world();
        let Some(target) = auto_exposure_ev(&snap.mesh, &snap.solution, clip, self.view.camera.position)
        else {
            return false;
        };
        let ev = match self.auto_ev {
            Some(ev) if self.scripted.is_none() => ev + (target - ev) * (1.0 - (-dt / ADAPTATION).exp()),
            _ => target,
        };
        self.auto_ev = Some(ev);
        (target - ev).abs() > 0.01
    }

    /// Camera keys, drag and wheel. Returns whether the camera is moving (so frames continue).
    fn handle_camera_input(&mut self, ctx: &egui::Context, response: &egui::Response, aspect: f64) -> bool {
        let now = Instant::now();
        let dt = self.last_frame.map_or(0.0, |t| now.duration_since(t).as_secs_f64()).min(MAX_MOVE_DT);
        self.last_frame = Some(now);
        self.last_dt = dt;
        let mut moving = false;
        if response.dragged() {
            let d = response.drag_delta();
            self.view
                .camera
                .look(f64::from(d.x) * LOOK_RADIANS_PER_POINT, f64::from(d.y) * LOOK_RADIANS_PER_POINT);
            moving = true;
        }
        if response.hovered() {
            let scroll = ctx.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                self.view.camera.scale_speed(f64::from(scroll / POINTS_PER_NOTCH), self.extent.speed_range());
                moving = true;
            }
        }
        if ctx.egui_wants_keyboard_input() {
            return moving;
        }
        let (input, reset, frame_all, shot, still) = ctx.input(|i| {
            let axis = |pos: &[Key], neg: &[Key]| {
                let p = pos.iter().any(|k| i.key_down(*k));
                let n = neg.iter().any(|k| i.key_down(*k));
                f64::from(i8::from(p) - i8::from(n))
            };
            let up = f64::from(i8::from(i.key_down(Key::E) || i.key_down(Key::Space)))
                - f64::from(i8::from(i.key_down(Key::Q) || i.modifiers.ctrl));
            (
                MoveInput {
                    forward: axis(&[Key::W, Key::ArrowUp], &[Key::S, Key::ArrowDown]),
                    right: axis(&[Key::D, Key::ArrowRight], &[Key::A, Key::ArrowLeft]),
                    up,
                    run: i.modifiers.shift,
                },
                i.key_pressed(Key::R),
                i.key_pressed(Key::F),
                i.key_pressed(Key::P),
                i.key_pressed(Key::G),
            )
        });
        if input.is_moving() {
            self.view.camera.advance(input, dt);
            moving = true;
        }
        if reset && let Some(scene) = &self.camera_scene {
            self.view.camera =
                FlyCamera::from_scene_camera(&radiosity_image::camera_or_framing(&scene), &self.extent);
        }
        if frame_all {
            self.view.camera.frame(&self.extent, aspect);
        }
        if shot {
            self.save_view_png();
        }
        if still {
            self.start_still(ctx);
        }
        moving
    }

    /// P: draws the 3D view (without the panel) offscreen at its on-screen size and writes
    /// it as a PNG.
    fn save_view_png(&mut self) {
        let name = self.shown.as_ref().map_or("scene".to_owned(), |s| {
            let safe: String =
                s.job.scene.name.chars().map(|c| if c.is_alphanumeric() { c } else { '-' }).collect();
            format!("{}-{}shots", safe.to_lowercase(), s.solution.shots)
        });
        let path = unique_path(&self.screenshot_dir, &name);
        let frame = self.frame_params(self.view_size);
        // The picture shows every element, whatever the window draws meanwhile.
        let coarse = self.coarse;
        self.sync_detail(false);
        let (device, queue) = (&self.render_state.device, &self.render_state.queue);
        let egui_renderer = self.render_state.renderer.read();
        let Some(renderer) = egui_renderer.callback_resources.get::<SceneRenderer>() else { return };
        let target = RenderTarget::new(device, self.view_size, renderer.format(), renderer.samples());
        renderer.draw(device, queue, &target, &frame);
        let result = target.read_rgba8(device, queue).and_then(|img| {
            let rgb = image::DynamicImage::ImageRgba8(img).to_rgb8();
            write_rgb_png(&path, rgb.width(), rgb.height(), rgb.into_raw())
        });
        drop(egui_renderer);
        self.sync_detail(coarse);
        self.message = Some(match result {
            Ok(()) => format!("wrote {}", path.display()),
            Err(e) => format!("cannot write {}: {e}", path.display()),
        });
    }

    /// G: renders the current view with a final gather in the background (see `still`).
    fn start_still(&mut self, ctx: &egui::Context) {
        if self.still_job.is_some() {
            return;
        }
        let Some(snap) = &self.shown else { return };
        let cam = &self.view.camera;
        let camera = match Camera::try_new(cam.position, cam.position + cam.forward(), cam.up, cam.fov_y_deg)
        {
            Ok(c) => c,
            Err(e) => {
                self.message = Some(format!("cannot render a still: {e}"));
                return;
            }
        };
        let ctx = ctx.clone();
        self.still_job = Some(StillJob::spawn(
            snap.mesh.clone(),
            snap.solution.clone(),
            camera,
            self.view_size,
            Gather::Direct,
            move || ctx.request_repaint(),
        ));
    }

    /// Takes a finished still onto a texture, tone mapped as the view is.
    fn poll_still(&mut self, ctx: &egui::Context) {
        let Some(job) = &self.still_job else { return };
        let StillPoll::Done(result) = job.poll() else { return };
        self.still_job = None;
        match result {
            Ok(still) => {
                let ev = if self.view.auto_exposure {
                    Exposure::Auto.ev_for(&still.radiance)
                } else {
                    self.view.exposure_ev
                };
                let srgb = tone_map_image(&still.radiance, &ToneParams::new(ev, self.view.operator));
                let image =
                    egui::ColorImage::from_rgb([srgb.width as usize, srgb.height as usize], &srgb.as_bytes());
                let texture = ctx.load_texture("still", image, egui::TextureOptions::LINEAR);
                self.message = Some(format!(
                    "still rendered in {:.1} s (gather {}, {} shots)",
                    still.seconds,
                    still.gather.as_str(),
                    still.shots
                ));
                self.still = Some((still, texture, srgb));
            }
            Err(e) => self.message = Some(format!("cannot render a still: {e}")),
        }
    }

    /// The last still in its own window, with Save and Close.
    fn still_window(&mut self, ctx: &egui::Context) {
        let Some((still, texture, srgb)) = &self.still else { return };
        let mut open = true;
        let mut save = false;
        let caption =
            format!("gather {}, {} shots, {:.1} s", still.gather.as_str(), still.shots, still.seconds);
        egui::Window::new("Still").open(&mut open).resizable(true).show(ctx, |ui| {
            ui.weak(caption);
            let size = texture.size_vec2();
            let fit = (ui.available_width() / size.x).min(1.0);
            ui.image((texture.id(), size * fit));
            save = ui.button("Save PNG").clicked();
        });
        if save {
            let path = unique_path(&self.screenshot_dir, "still");
            let written = image::RgbImage::from_raw(srgb.width, srgb.height, srgb.as_bytes())
                .ok_or_else(|| "the still's size does not match its pixels".to_owned())
                .and_then(|img| img.save(&path).map_err(|e| e.to_string()));
            self.message = Some(match written {
                Ok(()) => format!("wrote {}", path.display()),
                Err(e) => format!("cannot write {}: {e}", path.display()),
            });
        }
        if !open {
            self.still = None;
        }
    }

    /// The frame's settings for a view of `size_px` pixels.
    fn frame_params(&self, size_px: [u32; 2]) -> FrameParams {
        let aspect = f64::from(size_px[0].max(1)) / f64::from(size_px[1].max(1));
        FrameParams {
            clip_from_world: self.view.camera.clip_from_view(aspect) * self.view.camera.view_from_world(),
            exposure_ev: self.exposure_ev(),
            operator: self.view.operator,
            mode: self.view.mode,
            wireframe: self.view.wireframe,
            log_range: self.log_range,
            background: BACKGROUND,
        }
    }

    /// Adds the 3D view to `ui` as a paint callback covering `rect`: the mesh is drawn
    /// straight into egui's render pass.
    fn draw_view(&mut self, ui: &egui::Ui, rect: Rect) {
        let ppp = ui.ctx().pixels_per_point();
        self.view_size =
            [(rect.width() * ppp).round().max(1.0) as u32, (rect.height() * ppp).round().max(1.0) as u32];
        let callback = ViewCallback { frame: self.frame_params(self.view_size), width_px: self.view_size[0] };
        ui.painter().add(egui_wgpu::Callback::new_paint_callback(rect, callback));
    }

    fn panel(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        let p = self.status.progress.clone();
        let scene_name =
            self.shown.as_ref().map_or(self.job.scene.name.clone(), |s| s.job.scene.name.clone());
        let label = self.shown.as_ref().map_or(self.job.label.clone(), |s| s.job.label.clone());
        ui.heading(&scene_name);
        if label != scene_name {
            ui.weak(&label);
        }
        ui.add_space(4.0);

        // Opening scenes.
        ui.horizontal(|ui| {
            let edit = ui.add(
                egui::TextEdit::singleline(&mut self.open_text)
                    .hint_text("scene file or built-in name")
                    .desired_width(ui.available_width() - 60.0),
            );
            let enter = edit.lost_focus() && ui.input(|i| i.key_pressed(Key::Enter));
            if ui.add_enabled(self.loading.is_none(), egui::Button::new("Open")).clicked() || enter {
                let text = self.open_text.clone();
                self.open(&ctx, text);
            }
        });
        if let Some((arg, _)) = &self.loading {
            ui.horizontal(|ui| {
                ui.spinner();
                ui.label(format!("loading {arg}…"));
            });
        } else {
            ui.weak("or drop a scene file on the window");
        }
        if let Some(e) = self.load_error.as_ref().or(self.status.error.as_ref()) {
            ui.colored_label(Color32::from_rgb(255, 110, 100), format!("error: {e}"));
        }
        ui.separator();

        // Progress.
        let state = match &self.status.state {
            WorkerState::Meshing => "meshing…".to_owned(),
            WorkerState::Running => "solving".to_owned(),
            WorkerState::Paused => "paused".to_owned(),
            WorkerState::Stopped(r) => format!("stopped: {}", r.as_str().replace('_', " ")),
            WorkerState::Ended => "solver ended".to_owned(),
        };
        egui::Grid::new("stats").num_columns(2).spacing([12.0, 2.0]).show(ui, |ui| {
            let mut row = |k: &str, v: String| {
                ui.label(k);
                ui.monospace(v);
                ui.end_row();
            };
            row("state", state);
            row("patches", p.patches.to_string());
            row("elements", p.elements.to_string());
            row("shots", p.shots.to_string());
            row("unshot", format!("{:.4} %", p.unshot_fraction * 100.0));
            row("rays/s", format!("{:.3} M", p.rays_per_second() / 1e6));
            row("elapsed", format!("{:.1} s", p.elapsed.as_secs_f64()));
            let eta = match (&self.status.state, p.eta()) {
                (WorkerState::Stopped(_), _) => "done".to_owned(),
                (_, Some(t)) => format!("{:.1} s", t.as_secs_f64()),
                (_, None) => "–".to_owned(),
            };
            row("ETA", eta);
            row("fps", format!("{:.0}", self.fps.fps()));
        });
        ui.add(egui::ProgressBar::new(p.done_fraction() as f32).desired_height(6.0));
        ui.horizontal(|ui| {
            let running = self.status.state == WorkerState::Running;
            // A stopped solve has nothing left to shoot: only Restart makes sense.
            let can_shoot = !matches!(self.status.state, WorkerState::Stopped(_) | WorkerState::Ended);
            if running {
                if ui.button("Pause").clicked() {
                    self.worker.pause();
                }
            } else if ui.add_enabled(can_shoot, egui::Button::new("Resume")).clicked() {
                self.worker.resume();
            }
            let step = ui.add_enabled(can_shoot, egui::Button::new("Step"));
            if step.on_hover_text("shoot one more patch, then pause").clicked() {
                self.worker.step_one();
            }
            if ui.button("Restart").clicked() {
                self.worker.restart(None);
            }
        });
        ui.separator();

        // Display.
        ui.label("display");
        ui.horizontal_wrapped(|ui| {
            for m in DisplayMode::ALL {
                ui.selectable_value(&mut self.view.mode, m, m.label()).on_hover_text(m.description());
            }
        });
        ui.horizontal(|ui| {
            ui.label("wireframe");
            for w in Wireframe::ALL {
                ui.selectable_value(&mut self.view.wireframe, w, w.label())
                    .on_hover_text("outlines of the patches (which shoot) or the elements (which receive)");
            }
        });
        let counts = {
            let egui_renderer = self.render_state.renderer.read();
            egui_renderer.callback_resources.get::<SceneRenderer>().map(SceneRenderer::triangle_counts)
        };
        if let Some((full, Some(coarse))) = counts {
            ui.horizontal(|ui| {
                ui.label("detail");
                for d in Detail::ALL {
                    ui.selectable_value(&mut self.view.detail, d, d.label()).on_hover_text(format!(
                        "{full} triangles in full, {coarse} in the coarse copy; auto draws the coarse copy \
                         while the view changes on a CPU rasteriser (now: {})",
                        if self.coarse { "coarse" } else { "full" }
                    ));
                }
            });
        }
        ui.add_enabled_ui(!self.view.mode.is_false_colour(), |ui| {
            ui.horizontal(|ui| {
                ui.checkbox(&mut self.view.auto_exposure, "auto exposure");
                if self.view.auto_exposure {
                    self.view.exposure_ev = self.auto_ev.unwrap_or(0.0);
                }
            });
            ui.add_enabled(
                !self.view.auto_exposure,
                egui::Slider::new(&mut self.view.exposure_ev, -16.0..=16.0).step_by(0.1).text("EV"),
            );
            egui::ComboBox::from_label("tone map").selected_text(self.view.operator.as_str()).show_ui(
                ui,
                |ui| {
                    for op in ToneOperator::ALL {
                        ui.selectable_value(&mut self.view.operator, op, op.as_str());
                    }
                },
            );
        });
        ui.separator();

        // Scene parameters: light intensity (S11) and subdivision (S10) restart the solve.
        ui.label("light and subdivision (restart the solve)");
        let diagonal = self.extent.diagonal();
        let mut apply = false;
        let released = |r: &egui::Response| r.drag_stopped() || (r.changed() && !r.dragged());
        let r = ui
            .add(
                egui::Slider::new(&mut self.subdivision.light_scale, 0.01..=100.0)
                    .logarithmic(true)
                    .text("light ×"),
            )
            .on_hover_text("multiplies every emission (the light intensity); the solve restarts");
        apply |= released(&r);
        let size_range = diagonal / 1000.0..=diagonal / 2.0;
        let r = ui
            .add(
                egui::Slider::new(&mut self.subdivision.patch_size, size_range.clone())
                    .logarithmic(true)
                    .text("patch size"),
            )
            .on_hover_text(
                "longest patch edge, scene units: patches shoot; smaller is slower and more accurate",
            );
        apply |= released(&r);
        let r = ui
            .add(
                egui::Slider::new(&mut self.subdivision.element_size, size_range)
                    .logarithmic(true)
                    .text("element size"),
            )
            .on_hover_text(
                "longest element edge, scene units: elements receive; smaller gives sharper shadows",
            );
        apply |= released(&r);
        let r = ui
            .add(
                egui::Slider::new(&mut self.subdivision.adaptive_levels, 0..=radiosity_core::MAX_ADAPTIVE_LEVELS)
                    .text("adaptive levels"),
            )
            .on_hover_text(
                "how many times elements on shadow edges are quartered (found by quick probe solves); 0: none",
            );
        apply |= released(&r);
        if apply {
            self.apply_subdivision();
        }
        let mut up = self.up;
        ui.horizontal(|ui| {
            egui::ComboBox::from_label("up axis of the file").selected_text(up.as_str()).show_ui(ui, |ui| {
                for a in UpAxis::ALL {
                    ui.selectable_value(&mut up, a, a.as_str());
                }
            });
        })
        .response
        .on_hover_text("the axis that points up in the model file (z for most building models): the scene turns upright and the solve restarts");
        self.set_up(up);
        ui.separator();

        ui.horizontal(|ui| {
            if ui.button("Screenshot (P)").clicked() {
                self.save_view_png();
            }
            ui.checkbox(&mut self.continuous, "redraw continuously").on_hover_text(
                "draw every frame, not only when something changes (shows the highest frame rate)",
            );
        });
        ui.horizontal(|ui| {
            let idle = self.still_job.is_none() && self.shown.is_some();
            let button = ui.add_enabled(idle, egui::Button::new("Render still (G)")).on_hover_text(
                "render this view on the CPU with direct light by shadow rays (sharp shadows), in the background",
            );
            if button.clicked() {
                self.start_still(&ctx);
            }
            if let Some(job) = &self.still_job {
                ui.spinner();
                ui.label(format!("{:.0} s", job.started.elapsed().as_secs_f64()));
            }
        });
        if let Some(m) = &self.message {
            ui.label(m);
        }
        ui.add_space(6.0);
        ui.weak(format!("camera speed {:.3} units/s", self.view.camera.speed));
    }

    /// Draws the false-colour legend in the bottom-left corner of `rect`.
    fn legend(&self, painter: &egui::Painter, rect: Rect) {
        let (lo, hi) = self.log_range;
        let bar = Rect::from_min_size(rect.left_bottom() + Vec2::new(16.0, -236.0), Vec2::new(18.0, 180.0));
        let bg = bar.expand2(Vec2::new(10.0, 28.0)).with_max_x(bar.max.x + 104.0);
        painter.rect_filled(bg, 4.0, Color32::from_black_alpha(170));
        let steps = 48;
        let mut mesh = egui::Mesh::default();
        for k in 0..=steps {
            let t = k as f32 / steps as f32;
            let [r, g, b] = false_colour(f64::from(t)).map(|c| (c * 255.0).round() as u8);
            let y = bar.bottom() - t * bar.height();
            let c = Color32::from_rgb(r, g, b);
            mesh.colored_vertex(Pos2::new(bar.left(), y), c);
            mesh.colored_vertex(Pos2::new(bar.right(), y), c);
            if k > 0 {
                let i = (2 * k) as u32;
                mesh.add_triangle(i - 2, i - 1, i);
                mesh.add_triangle(i - 1, i + 1, i);
            }
        }
        painter.add(egui::Shape::mesh(mesh));
        let font = egui::FontId::proportional(11.0);
        let title = match self.view.mode {
            DisplayMode::Unshot => "unshot ΔB, W/unit²",
            _ => "radiosity (Y), W/unit²",
        };
        painter.text(
            bar.left_top() + Vec2::new(-2.0, -8.0),
            egui::Align2::LEFT_BOTTOM,
            title,
            font.clone(),
            Color32::WHITE,
        );
        for k in 0..=4 {
            let t = k as f64 / 4.0;
            let value = 10f64.powf(lo + t * (hi - lo));
            let y = bar.bottom() - t as f32 * bar.height();
            painter.text(
                Pos2::new(bar.right() + 6.0, y),
                egui::Align2::LEFT_CENTER,
                format!("{value:.3e}"),
                font.clone(),
                Color32::WHITE,
            );
        }
    }

    /// `--screenshot`: once the solve reached its mark, asks for the window's pixels, writes
    /// them, and closes the window.
    fn scripted_capture(&mut self, ctx: &egui::Context) {
        if let Some((path, after)) = &self.scripted
            && self.capture.is_none()
        {
            let shown_shots = self.shown.as_ref().map_or(0, |s| s.solution.shots);
            let done_status = match after {
                Some(n) => self.status.progress.shots >= *n,
                None => matches!(self.status.state, WorkerState::Stopped(_)),
            } || matches!(self.status.state, WorkerState::Stopped(_));
            let shown_current = self.shown.is_some() && shown_shots == self.status.progress.shots;
            if self.status.error.is_some() && self.shown.is_none() {
                let e = self.status.error.clone().unwrap_or_default();
                self.finish(ctx, Err(anyhow::anyhow!(e)));
                return;
            }
            let ready = done_status && shown_current && self.status.state != WorkerState::Meshing;
            if ready && self.mark.is_none() {
                self.mark = Some((Instant::now(), self.fps.fps()));
            }
            // With continuous redraw, keep drawing a while with the solver idle: the frame
            // rate printed then is the window's own.
            let measured = !self.continuous || self.mark.is_some_and(|(t, _)| t.elapsed() >= FPS_MEASURE);
            if ready && measured {
                self.capture = Some(Capture {
                    path: path.clone(),
                    image: Arc::default(),
                    requested: false,
                    idle_fps: self.fps.fps(),
                });
            }
        }
        let Some(capture) = &mut self.capture else { return };
        if !capture.requested {
            let slot = capture.image.clone();
            let ctx2 = ctx.clone();
            ctx.request_screenshot(move |img| {
                *slot.lock().unwrap_or_else(|e| e.into_inner()) = Some(img);
                ctx2.request_repaint();
            });
            capture.requested = true;
            return;
        }
        let taken = capture.image.lock().unwrap_or_else(|e| e.into_inner()).take();
        if let Some(img) = taken {
            let (path, measured_idle) = (capture.path.clone(), capture.idle_fps);
            self.capture = None;
            let result = save_color_image(&img, &path);
            if result.is_ok() {
                let solving_fps = self.mark.map_or(0.0, |m| m.1);
                let idle_fps =
                    if self.continuous { format!(", {measured_idle:.1} fps idle") } else { String::new() };
                eprintln!(
                    "wrote {} ({}×{} px, {} shots; {solving_fps:.1} fps while solving{idle_fps})",
                    path.display(),
                    img.size[0],
                    img.size[1],
                    self.status.progress.shots,
                );
            }
            self.finish(ctx, result);
        }
    }

    fn finish(&mut self, ctx: &egui::Context, result: anyhow::Result<()>) {
        *self.outcome.lock().unwrap_or_else(|e| e.into_inner()) = Some(result);
        self.scripted = None;
        ctx.send_viewport_cmd(egui::ViewportCommand::Close);
    }
}

impl eframe::App for ViewerApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.fps.tick(Instant::now());
        let dropped: Vec<PathBuf> =
            ctx.input(|i| i.raw.dropped_files.iter().map(|f| f.path().to_path_buf()).collect());
        if let Some(path) = dropped.into_iter().next() {
            let text = path.display().to_string();
            self.open_text = text.clone();
            self.open(&ctx, text);
        }
        self.poll_loading();
        self.sync_snapshot();
        self.poll_still(&ctx);
        // Before the view is drawn, so that the frame a screenshot takes has every element.
        self.scripted_capture(&ctx);

        egui::Panel::right("radiosity_panel").default_size(300.0).min_size(240.0).show(ui, |ui| {
            egui::ScrollArea::vertical().show(ui, |ui| self.panel(ui));
        });
        let mut moving = false;
        let mut adapting = false;
        egui::CentralPanel::no_frame().show(ui, |ui| {
            let rect = ui.max_rect();
            let response = ui.allocate_rect(rect, Sense::click_and_drag());
            let aspect = f64::from(rect.width().max(1.0)) / f64::from(rect.height().max(1.0));
            moving = self.handle_camera_input(&ctx, &response, aspect);
            let now = Instant::now();
            if moving {
                self.last_motion = Some(now);
            }
            let coarse = self.wants_coarse(now);
            self.sync_detail(coarse);
            let view_px = [
                (rect.width() * ctx.pixels_per_point()) as u32,
                (rect.height() * ctx.pixels_per_point()) as u32,
            ];
            adapting = self.adapt_exposure(view_px, self.last_dt);
            // The camera may have moved, so draw after the input.
            self.draw_view(ui, rect);
            if self.view.mode.is_false_colour() && self.shown.is_some() {
                self.legend(ui.painter(), rect);
            }
            if self.shown.is_none() {
                let text = match &self.status.error {
                    Some(e) => format!("cannot show the scene: {e}"),
                    None => "meshing…".to_owned(),
                };
                ui.painter().text(
                    rect.center(),
                    egui::Align2::CENTER_CENTER,
                    text,
                    egui::FontId::proportional(18.0),
                    Color32::LIGHT_GRAY,
                );
            }
            // The key hint along the bottom, wrapped onto two lines in a narrow window.
            let galley = ui.painter().layout(
                KEY_HINT.to_owned(),
                egui::FontId::proportional(12.0),
                Color32::from_gray(220),
                rect.width() - 16.0,
            );
            let hint_rect =
                Rect::from_min_max(Pos2::new(rect.left(), rect.bottom() - galley.size().y - 8.0), rect.max);
            ui.painter().rect_filled(hint_rect, 0.0, Color32::from_black_alpha(140));
            ui.painter().galley(hint_rect.min + Vec2::new(8.0, 4.0), galley, Color32::from_gray(220));
        });
        self.still_window(&ctx);
        let busy = matches!(self.status.state, WorkerState::Meshing) || self.loading.is_some();
        if moving || adapting || self.continuous || busy || self.capture.is_some() || self.scripted.is_some()
        {
            ctx.request_repaint();
        } else if self.coarse {
            // Back to every element once the view has rested.
            ctx.request_repaint_after(REST);
        } else if self.status.state == WorkerState::Running {
            // The worker's publications wake the window; this is a floor for the panel's
            // clocks in case a shot takes long.
            ctx.request_repaint_after(Duration::from_millis(250));
        }
    }
}

/// The 3D view's part of egui's frame.
struct ViewCallback {
    frame: FrameParams,
    width_px: u32,
}

impl egui_wgpu::CallbackTrait for ViewCallback {
    fn prepare(
        &self,
        _device: &wgpu::Device,
        queue: &wgpu::Queue,
        _screen: &egui_wgpu::ScreenDescriptor,
        _encoder: &mut wgpu::CommandEncoder,
        resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        if let Some(renderer) = resources.get::<SceneRenderer>() {
            renderer.prepare(queue, &self.frame, self.width_px);
        }
        Vec::new()
    }

    fn paint(
        &self,
        _info: egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &egui_wgpu::CallbackResources,
    ) {
        if let Some(renderer) = resources.get::<SceneRenderer>() {
            renderer.paint(pass);
        }
    }
}

/// Writes an egui screenshot as an RGB PNG.
fn save_color_image(img: &egui::ColorImage, path: &std::path::Path) -> anyhow::Result<()> {
    let [w, h] = img.size;
    let rgb: Vec<u8> = img.pixels.iter().flat_map(|c| [c.r(), c.g(), c.b()]).collect();
    if rgb.len() != w * h * 3 {
        anyhow::bail!("screenshot has the wrong size");
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("cannot create {}: {e}", dir.display()))?;
    }
    write_rgb_png(path, w as u32, h as u32, rgb)
}

/// Writes packed RGB bytes as a PNG through a temporary file and a rename, as every picture
/// the program writes: an interrupted write leaves no half file under the name.
fn write_rgb_png(path: &std::path::Path, width: u32, height: u32, rgb: Vec<u8>) -> anyhow::Result<()> {
    let pixels = rgb.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    let image = radiosity_image::SrgbImage { width, height, pixels };
    Ok(radiosity_image::write_png(path, &image)?)
}

/// `name.png`, or `name-2.png`, … if it exists: a screenshot never overwrites a file.
fn unique_path(dir: &std::path::Path, name: &str) -> PathBuf {
    let first = dir.join(format!("{name}.png"));
    if !first.exists() {
        return first;
    }
    (2..).map(|k| dir.join(format!("{name}-{k}.png"))).find(|p| !p.exists()).unwrap_or(first)
}

/// The window driven by egui_kittest: real egui frames, real wgpu (lavapipe on CI), input
/// injected as events. Rendering goes through the P screenshot path (an offscreen target),
/// since the harness's own pass has no depth buffer for the paint callback.
#[cfg(test)]
mod tests {
    use super::*;
    use egui_kittest::Harness;
    use egui_kittest::kittest::Queryable;
    use radiosity_solver::SolverParams;

    const LONG: Duration = Duration::from_secs(60);

    fn harness(scene: &str, shots: Option<u64>, dir: &std::path::Path) -> Harness<'static, ViewerApp> {
        let mut options = ViewerOptions::new(radiosity_io::resolve_scene(scene).unwrap().scene, scene);
        options.samples = 1;
        options.threads = Some(1);
        options.screenshot_dir = dir.to_owned();
        options.solver_params = SolverParams { max_shots: shots, ..SolverParams::preview() };
        Harness::builder()
            .with_size(Vec2::new(1000.0, 640.0))
            .wgpu()
            .build_eframe(|cc| ViewerApp::new(cc, options, Arc::default()).unwrap())
    }

    /// Steps frames (sleeping between them, since the worker and loader run in real time)
    /// until `done` holds.
    fn step_until(h: &mut Harness<'static, ViewerApp>, what: &str, done: impl Fn(&ViewerApp) -> bool) {
        let start = Instant::now();
        while !done(h.state()) {
            assert!(start.elapsed() < LONG, "timed out waiting for {what}");
            std::thread::sleep(Duration::from_millis(20));
            h.step();
        }
    }

    fn temp_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("radiosity-viewer-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn keys_drag_and_wheel_fly_the_camera() {
        let dir = temp_dir("keys");
        let mut h = harness("cornell", Some(5), &dir);
        step_until(&mut h, "the first solution", |a| a.shown.is_some());
        let start = h.state().view.camera;
        let centre = Pos2::new(350.0, 320.0);
        h.hover_at(centre);
        h.key_down(Key::W);
        for _ in 0..5 {
            std::thread::sleep(Duration::from_millis(10));
            h.step();
        }
        h.key_up(Key::W);
        h.step();
        let moved = h.state().view.camera.position - start.position;
        assert!(moved.dot(start.forward()) > 0.0 && moved.length() > 0.0, "W flies forward: {moved}");
        assert!(moved.cross(start.forward()).length() < 1e-6 * moved.length().max(1.0), "straight ahead");

        // Drag to the right: look right.
        h.drag_at(centre);
        h.step();
        for k in 1..=5 {
            h.hover_at(centre + Vec2::new(20.0 * k as f32, 0.0));
            h.step();
        }
        h.drop_at(centre + Vec2::new(100.0, 0.0));
        h.step();
        assert!(h.state().view.camera.forward().dot(start.right()) > 0.1, "dragging right looks right");

        // Wheel up: faster.
        h.hover_at(centre);
        h.event(egui::Event::MouseWheel {
            unit: egui::MouseWheelUnit::Point,
            delta: Vec2::new(0.0, 100.0),
            phase: egui::TouchPhase::Move,
            modifiers: egui::Modifiers::NONE,
            source: egui::MouseWheelSource::Wheel,
        });
        h.run_steps(10);
        assert!(h.state().view.camera.speed > start.speed, "the wheel speeds up");

        // R: back to the scene camera; F: frame it all.
        h.key_press(Key::R);
        h.step();
        assert_eq!(h.state().view.camera.position, start.position);
        assert_eq!(h.state().view.camera.forward(), start.forward());
        h.key_press(Key::F);
        h.step();
        assert_ne!(h.state().view.camera.position, start.position, "F frames the whole box");
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn panel_buttons_pause_step_and_restart_the_solve() {
        let dir = temp_dir("buttons");
        let mut h = harness("cornell", None, &dir);
        step_until(&mut h, "some shots", |a| a.status.progress.shots >= 3);
        h.get_by_label("Pause").click();
        step_until(&mut h, "the pause", |a| a.status.state == WorkerState::Paused);
        let shots = h.state().status.progress.shots;
        h.get_by_label("Step").click();
        step_until(&mut h, "one more shot", |a| a.status.progress.shots == shots + 1);
        h.get_by_label("Restart").click();
        step_until(&mut h, "the restart", |a| a.status.generation == 2);
        assert_eq!(h.state().status.progress.shots, 0);
        assert_eq!(h.state().status.state, WorkerState::Paused, "restart keeps the pause");
        h.get_by_label("Resume").click();
        step_until(&mut h, "shots again", |a| a.status.progress.shots > 0);
        let _ = std::fs::remove_dir_all(dir);
    }

    /// The subdivision sliders change sizes and adaptive levels only: the contacts and crease
    /// angle the command line chose stay.
    #[test]
    fn subdivision_sliders_keep_the_other_mesh_settings() {
        let dir = temp_dir("sliders");
        let mut options =
            ViewerOptions::new(radiosity_io::resolve_scene("cornell").unwrap().scene, "cornell");
        options.threads = Some(1);
        options.screenshot_dir = dir.clone();
        options.solver_params = SolverParams { max_shots: Some(2), ..SolverParams::preview() };
        let chosen = MeshParams::try_new(140.0, 70.0)
            .unwrap()
            .with_contacts(false)
            .with_crease_angle(10.0)
            .and_then(|m| m.with_adaptive_levels(1))
            .unwrap();
        options.mesh_params = Some(chosen);
        let mut h = Harness::builder()
            .with_size(Vec2::new(1000.0, 640.0))
            .wgpu()
            .build_eframe(|cc| ViewerApp::new(cc, options, Arc::default()).unwrap());
        assert_eq!(h.state().subdivision.adaptive_levels, 1);
        h.state_mut().subdivision.element_size = 35.0;
        h.state_mut().subdivision.adaptive_levels = 0;
        h.state_mut().apply_subdivision();
        let m = h.state().job.mesh_params;
        assert_eq!((m.patch_size, m.element_size, m.adaptive_levels), (140.0, 35.0, 0));
        assert!(!m.contacts && m.crease_angle_deg == 10.0, "{m:?}");
        let _ = std::fs::remove_dir_all(dir);
    }

    #[derive(Debug)]
    struct Dropped(PathBuf);

    impl egui::DroppedFile for Dropped {
        fn path(&self) -> &std::path::Path {
            &self.0
        }
        fn bytes(&self) -> Result<Vec<u8>, String> {
            std::fs::read(&self.0).map_err(|e| e.to_string())
        }
    }

    #[test]
    fn a_bad_file_shows_its_error_and_the_old_scene_stays_then_a_dropped_one_opens() {
        let dir = temp_dir("open");
        let mut h = harness("cornell", Some(20), &dir);
        step_until(&mut h, "the first solution", |a| a.shown.is_some());
        let bad = dir.join("bad.toml");
        std::fs::write(&bad, "name = \"x\"\n[[material]]\nname = \"m\"\nreflectance = [2, 0, 0]\n").unwrap();
        h.state_mut().open_text = bad.display().to_string();
        h.get_by_label("Open").click();
        step_until(&mut h, "the load error", |a| a.load_error.is_some());
        let expected = crate::load_scene(&bad.display().to_string()).unwrap_err();
        assert_eq!(h.state().load_error.as_deref(), Some(expected.as_str()));
        h.step();
        assert!(
            h.query_all_by_label_contains(&expected).next().is_some(),
            "the panel shows: error: {expected}"
        );
        assert_eq!(h.state().shown.as_ref().unwrap().job.scene.name, "Cornell box", "the old scene stays");

        // Dropping a good file opens it (and the camera moves to it).
        let good = dir.join("furnace.toml");
        std::fs::write(
            &good,
            "name = \"Dropped furnace\"\n[[material]]\nname = \"m\"\nreflectance = [0.5, 0.5, 0.5]\n\
             emission = [1, 1, 1]\n[[object]]\nname = \"box\"\ntype = \"box\"\nmin = [0, 0, 0]\n\
             max = [1, 1, 1]\nnormals = \"inward\"\nmaterial = \"m\"\n",
        )
        .unwrap();
        h.input_mut().dropped_files.push(Arc::new(Dropped(good.clone())));
        step_until(&mut h, "the dropped scene", |a| {
            a.shown.as_ref().is_some_and(|s| s.job.scene.name == "Dropped furnace")
        });
        assert!(h.state().load_error.is_none());
        assert!(h.state().extent.diagonal() < 2.0, "the camera works at the new scene's scale");
        let _ = std::fs::remove_dir_all(dir);
    }

    #[test]
    fn p_writes_the_view_with_red_left_and_green_right() {
        let dir = temp_dir("p");
        let mut h = harness("cornell", Some(100), &dir);
        step_until(&mut h, "100 shots on screen", |a| {
            a.shown.as_ref().is_some_and(|s| s.solution.shots == 100)
        });
        h.key_press(Key::P);
        h.step();
        let path = dir.join("cornell-box-100shots.png");
        let message = h.state().message.clone().unwrap_or_default();
        assert!(path.exists(), "{message}");
        let img = image::open(&path).unwrap().to_rgb8();
        let [w, h_px] = h.state().view_size;
        assert_eq!(img.dimensions(), (w, h_px), "the view's size, without the panel");
        let mean = |x0: f32, x1: f32| {
            let (mut sum, mut n) = ([0.0; 3], 0.0);
            for y in h_px / 3..2 * h_px / 3 {
                for x in (x0 * w as f32) as u32..(x1 * w as f32) as u32 {
                    let p = img.get_pixel(x, y);
                    for c in 0..3 {
                        sum[c] += f64::from(p[c]);
                    }
                    n += 1.0;
                }
            }
            sum.map(|s| s / n)
        };
        let (left, right) = (mean(0.12, 0.22), mean(0.78, 0.88));
        assert!(left[0] > 2.0 * left[1], "red on the left: {left:?}");
        assert!(right[1] > 1.5 * right[0], "green on the right: {right:?}");
        // A second P never overwrites the first.
        h.key_press(Key::P);
        h.step();
        assert!(dir.join("cornell-box-100shots-2.png").exists());
        let _ = std::fs::remove_dir_all(dir);
    }

    /// G renders the view with a gather in the background; the still arrives in its window
    /// with the view's aspect, red on the left and green on the right, and Save writes it.
    #[test]
    fn g_renders_a_still_in_the_background_and_save_writes_it() {
        let dir = temp_dir("still");
        let mut h = harness("cornell", Some(100), &dir);
        step_until(&mut h, "100 shots on screen", |a| {
            a.shown.as_ref().is_some_and(|s| s.solution.shots == 100)
        });
        h.key_press(Key::G);
        h.step();
        assert!(h.state().still_job.is_some(), "G starts a still");
        step_until(&mut h, "the still", |a| a.still.is_some());
        let message = h.state().message.clone().unwrap_or_default();
        assert!(message.starts_with("still rendered"), "{message}");
        let (still, _, srgb) = h.state().still.as_ref().unwrap();
        assert_eq!(still.gather, Gather::Direct);
        let [w, h_px] = h.state().view_size;
        let aspect = f64::from(srgb.width) / f64::from(srgb.height);
        assert!((aspect - f64::from(w) / f64::from(h_px)).abs() < 0.01, "aspect {aspect}");
        let px = |x: u32, y: u32| srgb.pixels[(y * srgb.width + x) as usize];
        let (left, right) =
            (px(srgb.width * 17 / 100, srgb.height / 2), px(srgb.width * 83 / 100, srgb.height / 2));
        assert!(left[0] > 2 * left[1], "red on the left: {left:?}");
        assert!(right[1] > right[0], "green on the right: {right:?}");
        // A new window lays itself out unseen on its first frame.
        h.step();
        h.step();
        h.get_by_label("Save PNG").click();
        h.step();
        assert!(dir.join("still.png").exists(), "{:?}", h.state().message);
        let _ = std::fs::remove_dir_all(dir);
    }
}
