//! The 3D view: exposure as it adapts, the frame's parameters, and the paint callback that
//! draws the mesh into egui's render pass.

use eframe::egui::{self, Rect};
use eframe::{egui_wgpu, wgpu};

use crate::render::{FrameParams, SceneRenderer, auto_exposure_ev};

use super::ViewerApp;
use super::state::{ADAPTATION, BACKGROUND};

impl ViewerApp {
    pub(super) fn exposure_ev(&self) -> f64 {
        if self.view.auto_exposure { self.auto_ev.unwrap_or(0.0) } else { self.view.exposure_ev }
    }

    /// Follows the automatic exposure for the current view, easing towards it like an eye
    /// adapting (time constant [`ADAPTATION`]) so walking past a lamp does not flash; a
    /// scripted screenshot takes the exact value. Returns whether it is still adapting.
    pub(super) fn adapt_exposure(&mut self, size_px: [u32; 2], dt: f64) -> bool {
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

    /// The frame's settings for a view of `size_px` pixels.
    pub(super) fn frame_params(&self, size_px: [u32; 2]) -> FrameParams {
        let aspect = f64::from(size_px[0].max(1)) / f64::from(size_px[1].max(1));
        FrameParams {
            clip_from_world: self.view.camera.clip_from_view(aspect) * self.view.camera.view_from_world(),
            exposure_ev: self.exposure_ev(),
            operator: self.view.operator,
            mode: self.view.mode,
            wireframe: self.view.wireframe,
            log_range: self.log_range,
            background: BACKGROUND,
            textures: self.view.textures,
        }
    }

    /// Adds the 3D view to `ui` as a paint callback covering `rect`: the mesh is drawn
    /// straight into egui's render pass.
    pub(super) fn draw_view(&mut self, ui: &egui::Ui, rect: Rect) {
        let ppp = ui.ctx().pixels_per_point();
        self.view_size =
            [(rect.width() * ppp).round().max(1.0) as u32, (rect.height() * ppp).round().max(1.0) as u32];
        let callback = ViewCallback { frame: self.frame_params(self.view_size), width_px: self.view_size[0] };
        ui.painter().add(egui_wgpu::Callback::new_paint_callback(rect, callback));
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
