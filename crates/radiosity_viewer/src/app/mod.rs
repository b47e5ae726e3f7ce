//! The window: an egui panel beside the 3D view, camera input, scene loading, screenshots.
//!
//! Every frame reads the newest snapshot the worker published (never waiting for it), uploads
//! its colours when it is new, and adds the 3D view as a paint callback that draws the mesh
//! straight into egui's render pass. Slow work — loading a file, meshing, solving — happens on
//! other threads, so the window stays responsive whatever the scene.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::mpsc::Receiver;
use std::time::{Duration, Instant};

use eframe::egui::{self, Color32, Pos2, Rect, Sense, Vec2};
use eframe::{egui_wgpu, wgpu};
use radiosity_core::{Scene, UpAxis};
use radiosity_image::SrgbImage;

use crate::ViewerOptions;
use crate::camera::{FlyCamera, SceneExtent};
use crate::render::{DisplayMode, SceneRenderer};
use crate::still::{Still, StillJob};
use crate::worker::{SolveJob, SolveWorker, Status, WorkerOptions, WorkerState};

mod capture;
mod input;
mod panels;
mod state;
#[cfg(test)]
mod tests;
mod view;
mod worker_link;

pub(crate) use state::Outcome;
pub use state::ViewState;
use state::{Capture, FpsCounter, REST, Subdivision, has_textures};

/// The key hint shown under the 3D view.
pub const KEY_HINT: &str = "WASD/arrows move · Q/E or Ctrl/Space down/up · drag to look · wheel: speed · \
                            Shift: run · R reset · F frame all · P screenshot · G render still";

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
    /// Lux per W/unit² of the shown scene, when it is photometric (the illuminance legend).
    lux_per_irradiance: Option<f64>,
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
        let ctx = cc.egui_ctx.clone();
        Ok(Self::with_render_state(
            render_state,
            Some(Arc::new(move || ctx.request_repaint())),
            options,
            outcome,
        ))
    }

    /// Sets up GPU resources on `render_state` (egui's renderer, whose render pass the scene
    /// draws in) and starts the solve worker, which calls `repaint` after each publication.
    /// Apart from eframe so that tests can drive the app on a renderer of their own.
    pub(crate) fn with_render_state(
        render_state: egui_wgpu::RenderState,
        repaint: Option<Arc<dyn Fn() + Send + Sync>>,
        options: ViewerOptions,
        outcome: Outcome,
    ) -> Self {
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
        let worker = SolveWorker::spawn(
            job.clone(),
            WorkerOptions {
                threads: options.threads,
                start_paused: false,
                pause_at_shots: options.after_shots.filter(|_| options.screenshot.is_some()),
                notify: repaint,
            },
        );
        let (lo, hi) = scene.bounds();
        let extent = SceneExtent::new(lo, hi);
        let camera = FlyCamera::from_scene_camera(&radiosity_image::camera_or_framing(&scene), &extent);
        Self {
            view: ViewState {
                camera,
                auto_exposure: options.exposure_ev.is_none(),
                exposure_ev: options.exposure_ev.unwrap_or(0.0),
                operator: options.operator,
                mode: options.display,
                wireframe: options.wireframe,
                detail: options.detail,
                textures: has_textures(&scene),
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
            lux_per_irradiance: None,
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
        }
    }

    /// One frame of the window: input, the worker's news, the panel and the view.
    pub(crate) fn frame(&mut self, ui: &mut egui::Ui) {
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

impl eframe::App for ViewerApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.frame(ui);
    }
}
