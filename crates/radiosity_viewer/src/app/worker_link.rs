//! The window's side of the solve: jobs sent to the worker (a new scene, other mesh sizes, the
//! up axis turned), files opened in the background, and the newest snapshot taken up.

use std::sync::Arc;
use std::sync::mpsc::TryRecvError;
use std::time::{Duration, Instant};

use eframe::egui::{self};
use radiosity_core::{MeshParams, Scene, UpAxis};

use crate::camera::{FlyCamera, SceneExtent};
use crate::render::{Detail, SceneRenderer, Wireframe, false_colour_range};
use crate::worker::{SolveJob, WorkerState};

use super::ViewerApp;
use super::state::{REST, Subdivision, has_textures};

impl ViewerApp {
    /// Starts a new job, keeping the paused/running state.
    pub(super) fn restart_with(&mut self, job: SolveJob) {
        self.job = job.clone();
        self.worker.restart(Some(job));
    }

    pub(super) fn apply_subdivision(&mut self) {
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
    pub(super) fn set_up(&mut self, up: UpAxis) {
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
    pub(super) fn open(&mut self, ctx: &egui::Context, arg: String) {
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

    pub(super) fn poll_loading(&mut self) {
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
    pub(super) fn sync_snapshot(&mut self) {
        self.status = self.worker.status();
        let Some(snap) = self.worker.latest() else { return };
        let is_new = self.shown.as_ref().is_none_or(|s| !Arc::ptr_eq(s, &snap));
        if !is_new && self.shown_mode == self.view.mode {
            return;
        }
        {
            let mut egui_renderer = self.render_state.renderer.write();
            if let Some(renderer) = egui_renderer.callback_resources.get_mut::<SceneRenderer>() {
                let (device, queue) = (&self.render_state.device, &self.render_state.queue);
                renderer.set_textured_mesh(device, queue, &snap.mesh, &snap.element_uvs);
                renderer.set_solution(&self.render_state.queue, &snap.solution, self.view.mode);
            }
        }
        self.shown_mode = self.view.mode;
        let lighting = &snap.job.scene.lighting;
        self.lux_per_irradiance = lighting.is_photometric().then(|| lighting.unit().lux_per_irradiance());
        if self.view.mode.is_false_colour() {
            self.log_range = false_colour_range(&snap.solution, &snap.mesh, self.view.mode);
        }
        // A new scene (not a re-mesh of the same one) gets its own camera.
        if self.camera_scene.as_ref().is_none_or(|s| !Arc::ptr_eq(s, &snap.job.scene)) {
            let (lo, hi) = snap.mesh.bounds();
            self.extent = SceneExtent::new(lo, hi);
            self.view.camera = FlyCamera::from_scene_camera(
                &radiosity_image::camera_or_framing(&snap.job.scene),
                &self.extent,
            );
            self.view.textures = has_textures(&snap.job.scene);
            self.camera_scene = Some(snap.job.scene.clone());
        }
        self.shown = Some(snap);
    }

    /// Whether this frame draws the big mesh's coarse copy: see [`Detail`]. A screenshot being
    /// taken and subdivision lines (which the coarse copy has not) always get every element.
    pub(super) fn wants_coarse(&self, now: Instant) -> bool {
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
    pub(super) fn sync_detail(&mut self, coarse: bool) {
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
}
