//! Pictures out of the window: P screenshots, G stills rendered in the background, and the
//! scripted `--screenshot` of a headless run.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use eframe::egui::{self};
use radiosity_core::Camera;
use radiosity_image::{Exposure, Gather, ToneParams, tone_map_image};

use crate::render::{RenderTarget, SceneRenderer};
use crate::still::{StillJob, StillPoll};
use crate::worker::WorkerState;

use super::ViewerApp;
use super::state::{Capture, FPS_MEASURE};

impl ViewerApp {
    /// P: draws the 3D view (without the panel) offscreen at its on-screen size and writes
    /// it as a PNG.
    pub(super) fn save_view_png(&mut self) {
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
    pub(super) fn start_still(&mut self, ctx: &egui::Context) {
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
            // The still shows textures when the view does.
            self.view.textures.then(|| snap.job.scene.clone()),
            snap.solution.clone(),
            camera,
            self.view_size,
            Gather::Direct,
            move || ctx.request_repaint(),
        ));
    }

    /// Takes a finished still onto a texture, tone mapped as the view is.
    pub(super) fn poll_still(&mut self, ctx: &egui::Context) {
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

    /// `--screenshot`: once the solve reached its mark, asks for the window's pixels, writes
    /// them, and closes the window.
    pub(super) fn scripted_capture(&mut self, ctx: &egui::Context) {
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

    pub(super) fn finish(&mut self, ctx: &egui::Context, result: anyhow::Result<()>) {
        *self.outcome.lock().unwrap_or_else(|e| e.into_inner()) = Some(result);
        self.scripted = None;
        ctx.send_viewport_cmd(egui::ViewportCommand::Close);
    }
}

/// Writes an egui screenshot as an RGB PNG.
pub(super) fn save_color_image(img: &egui::ColorImage, path: &std::path::Path) -> anyhow::Result<()> {
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
pub(super) fn write_rgb_png(
    path: &std::path::Path,
    width: u32,
    height: u32,
    rgb: Vec<u8>,
) -> anyhow::Result<()> {
    let pixels = rgb.chunks_exact(3).map(|p| [p[0], p[1], p[2]]).collect();
    let image = radiosity_image::SrgbImage { width, height, pixels };
    Ok(radiosity_image::write_png(path, &image)?)
}

/// `name.png`, or `name-2.png`, … if it exists: a screenshot never overwrites a file.
pub(super) fn unique_path(dir: &std::path::Path, name: &str) -> PathBuf {
    let first = dir.join(format!("{name}.png"));
    if !first.exists() {
        return first;
    }
    (2..).map(|k| dir.join(format!("{name}-{k}.png"))).find(|p| !p.exists()).unwrap_or(first)
}
