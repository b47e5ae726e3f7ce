//! What the window shows beside and over the 3D view: the side panel, the false-colour
//! legend, and the still's own window.

use eframe::egui::{self, Color32, Key, Pos2, Rect, Vec2};
use radiosity_core::UpAxis;
use radiosity_image::ToneOperator;

use crate::render::{Detail, DisplayMode, SceneRenderer, Wireframe, false_colour};
use crate::worker::WorkerState;

use super::ViewerApp;
use super::capture::unique_path;

impl ViewerApp {
    pub(super) fn panel(&mut self, ui: &mut egui::Ui) {
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
        let (counts, textured) = {
            let egui_renderer = self.render_state.renderer.read();
            let renderer = egui_renderer.callback_resources.get::<SceneRenderer>();
            (renderer.map(SceneRenderer::triangle_counts), renderer.is_some_and(SceneRenderer::has_textures))
        };
        // False colour shows the radiosity itself, never a texture.
        ui.add_enabled_ui(textured && !self.view.mode.is_false_colour(), |ui| {
            ui.checkbox(&mut self.view.textures, "textures").on_hover_text(if textured {
                "the models' colour textures over the radiosity, as `render` shows them; off: each \
                 surface in the mean colour the solve uses"
            } else {
                "the scene has no colour textures"
            });
        });
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
    pub(super) fn legend(&self, painter: &egui::Painter, rect: Rect) {
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
        // The shader shows log10 Y of what was uploaded; in lux, the labels are scaled.
        let (title, scale) = match (self.view.mode, self.lux_per_irradiance) {
            (DisplayMode::Unshot, _) => ("unshot ΔB, W/unit²", 1.0),
            (DisplayMode::Illuminance, Some(lux)) => ("illuminance, lx", lux),
            (DisplayMode::Illuminance, None) => ("irradiance (Y), W/unit²", 1.0),
            _ => ("radiosity (Y), W/unit²", 1.0),
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
            let value = 10f64.powf(lo + t * (hi - lo)) * scale;
            let y = bar.bottom() - t as f32 * bar.height();
            painter.text(
                Pos2::new(bar.right() + 6.0, y),
                egui::Align2::LEFT_CENTER,
                match value {
                    _ if scale == 1.0 => format!("{value:.3e}"),
                    v if v >= 100.0 => format!("{v:.0} lx"),
                    v if v >= 1.0 => format!("{v:.1} lx"),
                    v => format!("{v:.3} lx"),
                },
                font.clone(),
                Color32::WHITE,
            );
        }
    }

    /// The last still in its own window, with Save and Close.
    pub(super) fn still_window(&mut self, ctx: &egui::Context) {
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
}
