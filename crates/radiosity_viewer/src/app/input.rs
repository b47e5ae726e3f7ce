//! Keys, drags and the wheel: the fly-through camera moved by what the user does.

use std::time::Instant;

use eframe::egui::{self, Key};

use crate::camera::{FlyCamera, MoveInput};

use super::ViewerApp;
use super::state::{LOOK_RADIANS_PER_POINT, MAX_MOVE_DT, POINTS_PER_NOTCH};

impl ViewerApp {
    /// Camera keys, drag and wheel. Returns whether the camera is moving (so frames continue).
    pub(super) fn handle_camera_input(
        &mut self,
        ctx: &egui::Context,
        response: &egui::Response,
        aspect: f64,
    ) -> bool {
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
                FlyCamera::from_scene_camera(&radiosity_image::camera_or_framing(scene), &self.extent);
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
}
