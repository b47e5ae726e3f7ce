//! Automatic exposure for the view: the elements the camera sees, metered as `render` meters
//! its pixels.

use glam::{DMat4, DVec3};
use radiosity_mesh::Mesh;
use radiosity_solver::Solution;

/// Most elements [`auto_exposure_ev`] looks at per call; bigger meshes are sampled evenly so
/// the estimate stays a fraction of a millisecond.
pub const AUTO_EXPOSURE_SAMPLES: usize = 50_000;

/// Automatic exposure for what the camera sees, in stops: the same meter as
/// `render --exposure auto` over its pixels ([`radiosity_image::metered_exposure_ev`]: the
/// log-average luminance of the lit, non-highlight radiance B/π goes to middle grey, held down
/// so the brightest lit surfaces stay under display white). Each element in front of the
/// camera, inside the view and facing it counts with its solid angle, area·cosθ/d² — the
/// share of pixels it would cover, occlusion aside — and is flagged as an emitter when its
/// material emits, so a lamp in view is left out of the meter. `None` when nothing lit is in
/// view.
pub fn auto_exposure_ev(mesh: &Mesh, solution: &Solution, clip_from_world: DMat4, eye: DVec3) -> Option<f64> {
    if solution.element_radiosity.len() != mesh.elements.len() {
        return None;
    }
    let step = mesh.elements.len().div_ceil(AUTO_EXPOSURE_SAMPLES).max(1);
    let samples = mesh.elements.iter().zip(&solution.element_radiosity).enumerate().step_by(step).filter_map(
        |(e, (el, b))| {
            let to_eye = eye - el.centre;
            let d2 = to_eye.length_squared();
            let cos = el.normal.dot(to_eye) / d2.sqrt();
            // Back faces are culled, so only the lit side is ever seen (NaN: a degenerate
            // element).
            if cos.is_nan() || cos <= 0.0 {
                return None;
            }
            let c = clip_from_world * el.centre.extend(1.0);
            if c.w <= 0.0 || c.x.abs() > c.w || c.y.abs() > c.w {
                return None;
            }
            Some(radiosity_image::MeterSample {
                luminance: b.luminance() / std::f64::consts::PI,
                weight: el.area * cos / d2,
                emitter: mesh.element_material(e).emission.max_channel() > 0.0,
            })
        },
    );
    radiosity_image::metered_exposure_ev(samples)
}
