//! Primary rays of a pinhole camera: the one mapping from a picture's pixels to directions,
//! shared by the radiosity renderer, the reference path tracer and the default camera's probe,
//! so their pictures compare pixel by pixel.

use glam::DVec3;

use crate::Camera;
use crate::random::Rng;

/// Directions through the film of `camera` for a picture of `width × height` pixels.
#[derive(Clone, Copy, Debug)]
pub struct CameraRays {
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    /// tan(fov_y / 2): half the image plane's height at distance 1.
    half_height: f64,
    aspect: f64,
    width: f64,
    height: f64,
}

impl CameraRays {
    /// The film of `camera` for `width × height` pixels (each at least 1).
    pub fn new(camera: &Camera, width: u32, height: u32) -> Self {
        let forward = (camera.look_at - camera.position).normalize();
        // Right-handed: right = forward × up, so a camera looking down +z with +y up sees +x on
        // its left (the Cornell box's red wall, at x ≈ 556, is on the left of its picture).
        let right = forward.cross(camera.up).normalize();
        let up = right.cross(forward);
        let (width, height) = (f64::from(width.max(1)), f64::from(height.max(1)));
        Self {
            forward,
            right,
            up,
            half_height: (camera.fov_y_deg.to_radians() * 0.5).tan(),
            aspect: width / height,
            width,
            height,
        }
    }

    /// Unit direction through the film point `(px, py)` in pixels, y down from the top edge
    /// (`(x + 0.5, y + 0.5)` is the centre of pixel `(x, y)`).
    pub fn direction(&self, px: f64, py: f64) -> DVec3 {
        let sx = (2.0 * px / self.width - 1.0) * self.aspect * self.half_height;
        let sy = (1.0 - 2.0 * py / self.height) * self.half_height;
        (self.forward + self.right * sx + self.up * sy).normalize()
    }

    /// Direction of sample `sample` of `samples` in pixel `(x, y)`: jittered in its cell of a
    /// stratified ⌊√samples⌋² grid over the pixel, the samples beyond the grid anywhere in it
    /// (two draws from `rng` each, so every picture taken this way jitters alike).
    pub fn jittered_direction(&self, x: u32, y: u32, sample: u32, samples: u32, rng: &mut Rng) -> DVec3 {
        let m = f64::from(samples).sqrt().floor() as u32; // strata per side
        let (jx, jy) = (rng.next_f64(), rng.next_f64());
        let (sx, sy) = if sample < m * m {
            ((f64::from(sample % m) + jx) / f64::from(m), (f64::from(sample / m) + jy) / f64::from(m))
        } else {
            (jx, jy)
        };
        self.direction(f64::from(x) + sx, f64::from(y) + sy)
    }
}
