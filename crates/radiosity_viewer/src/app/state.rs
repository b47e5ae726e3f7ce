//! What the window keeps between frames apart from the app itself: the persisted view
//! settings, the frame counter, a pending screenshot, the subdivision sliders' sizes, and the
//! constants that the window's files share.

use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use eframe::egui::{self};
use radiosity_image::ToneOperator;

use crate::camera::FlyCamera;
use crate::render::{Detail, DisplayMode, Wireframe};

/// Mouse-look sensitivity, radians per point dragged.
pub(super) const LOOK_RADIANS_PER_POINT: f64 = 0.004;

/// Wheel scroll (points) per speed notch.
pub(super) const POINTS_PER_NOTCH: f32 = 50.0;

/// Longest frame time used for movement, so a frame after an idle pause does not jump.
pub(super) const MAX_MOVE_DT: f64 = 1.0 / 20.0;

/// Clear colour of the 3D view (display values): a dark grey that neither red nor green
/// walls nor black unlit surfaces can be confused with.
pub(super) const BACKGROUND: [f32; 4] = [0.11, 0.11, 0.12, 1.0];

/// With continuous redraw, how long a scripted run keeps drawing after its mark before the
/// screenshot, to measure the frame rate with the solver idle.
pub(super) const FPS_MEASURE: Duration = Duration::from_secs(3);

/// How long the view must rest before [`Detail::Auto`] draws every element again: long enough
/// that the pauses between key presses or drags do not flicker to full detail and back.
pub(super) const REST: Duration = Duration::from_millis(300);

/// Time constant of the automatic exposure's adaptation, seconds.
pub(super) const ADAPTATION: f64 = 0.3;

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
    /// Whether textured materials show their textures (on when a scene that has any is
    /// opened); off, every surface shows its mean colour, as the solve sees it.
    pub textures: bool,
}

/// Whether any material of `scene` has a colour texture: the textures checkbox starts on.
pub(super) fn has_textures(scene: &radiosity_core::Scene) -> bool {
    scene.materials.iter().any(|m| m.texture.is_some())
}

/// Frames per second over the last second of drawn frames.
#[derive(Default)]
pub(super) struct FpsCounter {
    pub(super) frames: VecDeque<Instant>,
}

impl FpsCounter {
    pub(super) fn tick(&mut self, now: Instant) {
        self.frames.push_back(now);
        while self.frames.front().is_some_and(|t| now.duration_since(*t) > Duration::from_secs(1)) {
            self.frames.pop_front();
        }
    }

    pub(super) fn fps(&self) -> f64 {
        match (self.frames.front(), self.frames.back()) {
            (Some(a), Some(b)) if self.frames.len() > 1 => {
                (self.frames.len() - 1) as f64 / b.duration_since(*a).as_secs_f64().max(1e-9)
            }
            _ => 0.0,
        }
    }
}

/// A `--screenshot` asked for and not yet written.
pub(super) struct Capture {
    pub(super) path: PathBuf,
    pub(super) image: Arc<Mutex<Option<Arc<egui::ColorImage>>>>,
    pub(super) requested: bool,
    /// The frame rate just before the capture, with the solver idle: the capture's own frames
    /// draw every element (and upload their colours), which is not what was being measured.
    pub(super) idle_fps: f64,
}

/// Scene sizes the subdivision sliders work in.
#[derive(Clone, Copy)]
pub(super) struct Subdivision {
    pub(super) light_scale: f64,
    pub(super) patch_size: f64,
    pub(super) element_size: f64,
    /// Levels of adaptive subdivision (see `MeshParams::adaptive_levels`).
    pub(super) adaptive_levels: u32,
}

/// Outcome of a scripted run, read by [`crate::run`] after the window closes.
pub(crate) type Outcome = Arc<Mutex<Option<anyhow::Result<()>>>>;
