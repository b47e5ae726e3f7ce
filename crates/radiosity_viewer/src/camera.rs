//! Fly-through camera: position plus yaw and pitch about the scene's up axis, with the view and
//! projection matrices for wgpu (right-handed world, NDC z in [0, 1], y up).
//!
//! Depth uses reversed z with an infinite far plane (near → 1, infinity → 0) and a 32-bit float
//! depth buffer: the float exponent cancels the 1/z compression, so precision is nearly uniform
//! in log-distance and one near plane, a small fraction of the scene size, suits a millimetre
//! Cornell box and a metre room alike (Reed 2015, "Depth precision visualized"; Lapidous &
//! Jiao 1999).
//!
//! Plain Rust without a window, so every formula here is unit-tested.

use glam::{DMat4, DVec3, Mat4};
use radiosity_core::Camera;

/// Near plane distance as a fraction of the scene's bounding-box diagonal. With reversed
/// float depth this costs no precision far away, and lets the camera come within 1/10000 of
/// the scene size of a wall before the wall is clipped.
pub const NEAR_FRACTION: f64 = 1e-4;

/// Default flying speed, scene diagonals per second (crossing the scene takes a few seconds).
pub const SPEED_FRACTION: f64 = 0.25;

/// Speed factor while Shift is held.
pub const RUN_FACTOR: f64 = 4.0;

/// Speed change per mouse-wheel notch.
pub const WHEEL_FACTOR: f64 = 1.2;

/// Largest pitch, radians: just short of straight up or down, where yaw would be undefined.
pub const MAX_PITCH: f64 = 89.0 * std::f64::consts::PI / 180.0;

/// Movement asked for by the keys held this frame, each axis in [-1, 1].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MoveInput {
    /// +1 forward (W, ↑), -1 backward (S, ↓).
    pub forward: f64,
    /// +1 right (D, →), -1 left (A, ←).
    pub right: f64,
    /// +1 up along the scene's up axis (E, Space), -1 down (Q, Ctrl).
    pub up: f64,
    /// Shift: move [`RUN_FACTOR`] times faster.
    pub run: bool,
}

impl MoveInput {
    /// Whether any movement is asked for.
    pub fn is_moving(&self) -> bool {
        self.forward != 0.0 || self.right != 0.0 || self.up != 0.0
    }
}

/// A fly-through camera. This is persisted view state (the panel and a screenshot restore it),
/// kept apart from runtime state such as keys held or GPU buffers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlyCamera {
    /// Eye position, scene units.
    pub position: DVec3,
    /// Rotation about `up`, radians, from `reference_forward` towards its right.
    pub yaw: f64,
    /// Elevation above the plane normal to `up`, radians, in [-MAX_PITCH, MAX_PITCH].
    pub pitch: f64,
    /// Vertical field of view, degrees, in (0, 180).
    pub fov_y_deg: f64,
    /// The scene's up axis (unit): the axis of yaw and of Q/E movement.
    pub up: DVec3,
    /// Unit vector normal to `up`: the forward direction at yaw 0, pitch 0.
    pub reference_forward: DVec3,
    /// Flying speed, scene units per second, > 0.
    pub speed: f64,
    /// Near plane distance, scene units, > 0.
    pub near: f64,
}

/// Size of the scene, which sets speed, near plane and how far the speed may be changed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneExtent {
    /// Bounding box minimum corner.
    pub min: DVec3,
    /// Bounding box maximum corner.
    pub max: DVec3,
}

impl SceneExtent {
    /// The extent of a bounding box; an empty or non-finite box becomes the unit cube so the
    /// camera always has a usable scale.
    pub fn new(min: DVec3, max: DVec3) -> Self {
        if min.is_finite() && max.is_finite() && (max - min).max_element() > 0.0 {
            Self { min, max }
        } else {
            Self { min: DVec3::ZERO, max: DVec3::ONE }
        }
    }

    /// Length of the box diagonal, scene units (> 0).
    pub fn diagonal(&self) -> f64 {
        (self.max - self.min).length()
    }

    /// Centre of the box.
    pub fn centre(&self) -> DVec3 {
        (self.min + self.max) * 0.5
    }

    /// The eight corners of the box.
    pub fn corners(&self) -> [DVec3; 8] {
        let (a, b) = (self.min, self.max);
        [
            DVec3::new(a.x, a.y, a.z),
            DVec3::new(b.x, a.y, a.z),
            DVec3::new(a.x, b.y, a.z),
            DVec3::new(b.x, b.y, a.z),
            DVec3::new(a.x, a.y, b.z),
            DVec3::new(b.x, a.y, b.z),
            DVec3::new(a.x, b.y, b.z),
            DVec3::new(b.x, b.y, b.z),
        ]
    }

    /// Slowest and fastest speeds the wheel may set, scene units per second.
    pub fn speed_range(&self) -> (f64, f64) {
        let d = self.diagonal();
        (d * 1e-4, d * 10.0)
    }
}

impl FlyCamera {
    /// The camera of a scene, scaled to its extent.
    pub fn from_scene_camera(camera: &Camera, extent: &SceneExtent) -> Self {
        let up = camera.up.try_normalize().unwrap_or(DVec3::Y);
        let dir = (camera.look_at - camera.position).try_normalize().unwrap_or(-DVec3::Z);
        // Scene cameras are validated to have `up` not parallel to the view direction, but
        // guard anyway: any horizontal reference will do when looking straight along up.
        let horizontal =
            (dir - up * dir.dot(up)).try_normalize().unwrap_or_else(|| up.any_orthonormal_vector());
        let pitch = dir.dot(up).clamp(-1.0, 1.0).asin().clamp(-MAX_PITCH, MAX_PITCH);
        Self {
            position: camera.position,
            yaw: 0.0,
            pitch,
            fov_y_deg: camera.fov_y_deg.clamp(1.0, 170.0),
            up,
            reference_forward: horizontal,
            speed: extent.diagonal() * SPEED_FRACTION,
            near: extent.diagonal() * NEAR_FRACTION,
        }
    }

    /// Unit vector the camera looks along.
    pub fn forward(&self) -> DVec3 {
        let horizontal = self.reference_forward * self.yaw.cos() + self.reference_right() * self.yaw.sin();
        horizontal * self.pitch.cos() + self.up * self.pitch.sin()
    }

    /// Unit vector to the right of the view, normal to `up` (so strafing never climbs).
    pub fn right(&self) -> DVec3 {
        let r = self.reference_right();
        r * self.yaw.cos() - self.reference_forward * self.yaw.sin()
    }

    fn reference_right(&self) -> DVec3 {
        // Right-handed: forward × up points right.
        self.reference_forward.cross(self.up)
    }

    /// Moves by `input` for `dt_seconds`: forward along the view (a fly-through, not a walk),
    /// sideways along [`Self::right`], vertically along the scene's up.
    pub fn advance(&mut self, input: MoveInput, dt_seconds: f64) {
        // Also rejects a NaN time step.
        if !input.is_moving() || dt_seconds.is_nan() || dt_seconds <= 0.0 {
            return;
        }
        let speed = self.speed * if input.run { RUN_FACTOR } else { 1.0 };
        let dir = self.forward() * input.forward + self.right() * input.right + self.up * input.up;
        // Diagonal movement is not faster than straight movement.
        let dir = if dir.length() > 1.0 { dir.normalize() } else { dir };
        self.position += dir * speed * dt_seconds;
    }

    /// Turns by a mouse drag: `dx` right and `dy` down, in radians (the caller multiplies
    /// pixels by its sensitivity). Dragging right looks right; dragging down looks down.
    pub fn look(&mut self, dx: f64, dy: f64) {
        self.yaw = (self.yaw + dx).rem_euclid(std::f64::consts::TAU);
        self.pitch = (self.pitch - dy).clamp(-MAX_PITCH, MAX_PITCH);
    }

    /// Changes the speed by `notches` wheel notches (positive: faster), kept in `range`.
    pub fn scale_speed(&mut self, notches: f64, range: (f64, f64)) {
        self.speed = (self.speed * WHEEL_FACTOR.powf(notches)).clamp(range.0, range.1);
    }

    /// Moves back along the current view direction until the whole box is in view at aspect
    /// ratio `aspect` (width / height), looking at its centre.
    pub fn frame(&mut self, extent: &SceneExtent, aspect: f64) {
        let half_y = (self.fov_y_deg.to_radians() * 0.5).min(1.5);
        let half_x = (half_y.tan() * aspect.max(1e-3)).atan();
        // The bounding sphere fits the narrower half-angle; 5 % margin.
        let radius = extent.diagonal() * 0.5;
        let distance = radius / half_y.min(half_x).sin() * 1.05;
        self.position = extent.centre() - self.forward() * distance;
    }

    /// World → view transform: right-handed, x right, y up, looking down -z.
    pub fn view_from_world(&self) -> DMat4 {
        glam::dcamera::rh::view::look_to_mat4(self.position, self.forward(), self.up)
    }

    /// View → clip transform for aspect ratio `aspect` (width / height): reversed z, infinite
    /// far plane, wgpu's NDC (z in [0, 1], y up).
    pub fn clip_from_view(&self, aspect: f64) -> DMat4 {
        glam::dcamera::rh::proj::directx::perspective_infinite_reverse(
            self.fov_y_deg.to_radians(),
            aspect.max(1e-6),
            self.near,
        )
    }

    /// World → clip transform in single precision for the shader.
    pub fn clip_from_world(&self, aspect: f64) -> Mat4 {
        (self.clip_from_view(aspect) * self.view_from_world()).as_mat4()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec4;

    fn cornell_camera() -> (FlyCamera, SceneExtent) {
        let extent = SceneExtent::new(DVec3::ZERO, DVec3::new(556.0, 548.8, 559.2));
        let cam = Camera::try_new(
            DVec3::new(278.0, 273.0, -800.0),
            DVec3::new(278.0, 273.0, 0.0),
            DVec3::Y,
            39.3076,
        )
        .unwrap();
        (FlyCamera::from_scene_camera(&cam, &extent), extent)
    }

    fn project(m: DMat4, p: DVec3) -> DVec3 {
        let c = m * DVec4::new(p.x, p.y, p.z, 1.0);
        assert!(c.w > 0.0, "point {p} is behind the camera");
        c.truncate() / c.w
    }

    fn close(a: DVec3, b: DVec3, tol: f64) -> bool {
        (a - b).length() <= tol
    }

    #[test]
    fn scene_camera_round_trips_to_the_same_view() {
        let (cam, _) = cornell_camera();
        assert!(close(cam.forward(), DVec3::Z, 1e-12));
        // Looking along +z with y up in a right-handed world, right is -x: the red wall (x = 556)
        // is on the left of the picture and the green one (x = 0) on the right.
        assert!(close(cam.right(), -DVec3::X, 1e-12));
        let m = cam.clip_from_view(1.0) * cam.view_from_world();
        let centre = project(m, DVec3::new(278.0, 273.0, 0.0));
        assert!(centre.x.abs() < 1e-9 && centre.y.abs() < 1e-9, "{centre}");
        let red = project(m, DVec3::new(556.0, 273.0, 280.0));
        let green = project(m, DVec3::new(0.0, 273.0, 280.0));
        assert!(red.x < -0.3 && green.x > 0.3, "red {red}, green {green}");
        let ceiling = project(m, DVec3::new(278.0, 548.8, 280.0));
        assert!(ceiling.y > 0.3, "ceiling must be at the top: {ceiling}");
    }

    #[test]
    fn tilted_scene_camera_keeps_its_direction() {
        let extent = SceneExtent::new(DVec3::ZERO, DVec3::splat(10.0));
        let cam =
            Camera::try_new(DVec3::new(1.0, 2.0, 3.0), DVec3::new(4.0, -1.0, 7.0), DVec3::Z, 60.0).unwrap();
        let fly = FlyCamera::from_scene_camera(&cam, &extent);
        let dir = (cam.look_at - cam.position).normalize();
        assert!(close(fly.forward(), dir, 1e-12), "{} vs {dir}", fly.forward());
        assert!(fly.right().dot(DVec3::Z).abs() < 1e-12, "right stays horizontal");
        assert!(fly.right().dot(fly.forward()).abs() < 1e-12);
        let m = fly.clip_from_view(1.5) * fly.view_from_world();
        let p = project(m, cam.look_at);
        assert!(p.x.abs() < 1e-9 && p.y.abs() < 1e-9);
    }

    #[test]
    fn reversed_depth_maps_near_to_one_and_far_towards_zero() {
        let (cam, _) = cornell_camera();
        let m = cam.clip_from_view(1.0) * cam.view_from_world();
        let at = |d: f64| project(m, cam.position + cam.forward() * d).z;
        assert!((at(cam.near) - 1.0).abs() < 1e-9);
        let (mut prev, mut d) = (at(cam.near), cam.near);
        while d < 1e7 {
            d *= 3.0;
            let z = at(d);
            assert!(z < prev && z > 0.0, "depth must fall monotonically and stay > 0: {z} at {d}");
            prev = z;
        }
    }

    /// Millimetre boxes and metre rooms: the near plane is far below any detail of the scene,
    /// and f32 reversed depth separates two surfaces 1/1000 of the scene size apart anywhere in
    /// the scene, seen from up to 10 scene sizes away.
    #[test]
    fn near_plane_and_depth_precision_suit_small_and_large_scenes() {
        for size in [1e-3, 1.0, 559.2, 5.0e4] {
            let extent = SceneExtent::new(DVec3::ZERO, DVec3::splat(size));
            let cam = FlyCamera::from_scene_camera(&Camera::framing(extent.min, extent.max), &extent);
            assert!(cam.near > 0.0 && cam.near <= 1e-3 * extent.diagonal());
            let m = cam.clip_from_view(1.0) * cam.view_from_world();
            for k in [0.01, 0.1, 1.0, 10.0] {
                let d = extent.diagonal() * k;
                let z1 = project(m, cam.position + cam.forward() * d).z as f32;
                let z2 = project(m, cam.position + cam.forward() * (d + 1e-3 * extent.diagonal())).z as f32;
                assert!(z1 > z2, "size {size}: surfaces at {d} and 1/1000 behind share a depth {z1}");
            }
        }
    }

    #[test]
    fn movement_follows_view_right_and_up_at_the_set_speed() {
        let (mut cam, _) = cornell_camera();
        cam.speed = 100.0;
        let start = cam.position;
        cam.advance(MoveInput { forward: 1.0, ..Default::default() }, 0.5);
        assert!(close(cam.position - start, DVec3::Z * 50.0, 1e-9));
        cam.position = start;
        cam.advance(MoveInput { right: 1.0, run: true, ..Default::default() }, 0.5);
        assert!(close(cam.position - start, -DVec3::X * 50.0 * RUN_FACTOR, 1e-9));
        cam.position = start;
        cam.advance(MoveInput { up: -1.0, ..Default::default() }, 1.0);
        assert!(close(cam.position - start, -DVec3::Y * 100.0, 1e-9));
        cam.position = start;
        cam.advance(MoveInput { forward: 1.0, right: 1.0, ..Default::default() }, 1.0);
        assert!(((cam.position - start).length() - 100.0).abs() < 1e-9, "diagonal moves are not faster");
        cam.position = start;
        cam.advance(MoveInput::default(), 1.0);
        assert_eq!(cam.position, start);
    }

    #[test]
    fn look_turns_towards_the_drag_and_clamps_pitch() {
        let (mut cam, _) = cornell_camera();
        let right = cam.right();
        cam.look(0.1, 0.0);
        assert!(cam.forward().dot(right) > 0.09, "dragging right turns right");
        cam.look(0.0, 0.1);
        assert!(cam.forward().y < -0.09, "dragging down looks down");
        cam.look(0.0, -100.0);
        assert!((cam.pitch - MAX_PITCH).abs() < 1e-12);
        assert!(cam.forward().is_normalized() && cam.right().is_normalized());
        assert!(cam.right().dot(cam.up).abs() < 1e-12);
    }

    #[test]
    fn wheel_scales_speed_within_the_scene_range() {
        let (mut cam, extent) = cornell_camera();
        let s = cam.speed;
        cam.scale_speed(1.0, extent.speed_range());
        assert!((cam.speed / s - WHEEL_FACTOR).abs() < 1e-12);
        cam.scale_speed(-1000.0, extent.speed_range());
        assert_eq!(cam.speed, extent.speed_range().0);
        cam.scale_speed(1000.0, extent.speed_range());
        assert_eq!(cam.speed, extent.speed_range().1);
    }

    #[test]
    fn framing_puts_every_corner_in_view() {
        for aspect in [0.5, 1.0, 2.5] {
            let (mut cam, extent) = cornell_camera();
            cam.position = DVec3::new(1e4, -3e3, 77.0);
            cam.look(0.7, -0.3);
            cam.frame(&extent, aspect);
            let m = cam.clip_from_view(aspect) * cam.view_from_world();
            let c = project(m, extent.centre());
            assert!(c.x.abs() < 1e-9 && c.y.abs() < 1e-9, "looks at the centre");
            for p in extent.corners() {
                let q = project(m, p);
                assert!(
                    q.x.abs() <= 1.0 && q.y.abs() <= 1.0 && q.z > 0.0 && q.z < 1.0,
                    "aspect {aspect}: {p} at {q}"
                );
            }
        }
    }

    #[test]
    fn degenerate_extent_falls_back_to_unit_cube() {
        let e = SceneExtent::new(DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        assert_eq!(e.diagonal(), 3f64.sqrt());
    }
}
