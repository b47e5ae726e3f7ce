//! The geometry of one interaction, shared by every layer above: a shooter element's
//! corners and form factor from a point ([`ShooterElement`]), an element's corners in a fixed
//! array, and whether an element and the shooter see each other whole.

use glam::DVec3;
use radiosity_mesh::{Mesh, Patch};

use super::plans::PatchPlan;
use crate::form_factor::{point_to_point, point_to_polygon_x4};

/// Corners of one element of the shooter, copied once per shot so ray ends need no lookups.
#[derive(Clone, Copy, Debug)]
pub(super) struct ShooterElement {
    /// Its corners; the first `count` are its own.
    pub(super) corners: [DVec3; 4],
    /// Its number of corners, 3 or 4.
    pub(super) count: u8,
    /// Its centroid.
    pub(super) centre: DVec3,
    /// Circumradius about `centre`.
    pub(super) radius: f64,
    /// Its area, unit².
    pub(super) area: f64,
}

impl ShooterElement {
    /// Element `e` of `mesh`, whose circumradius is `radius`.
    pub(super) fn new(mesh: &Mesh, e: usize, radius: f64) -> Self {
        let mut corners = [DVec3::ZERO; 4];
        for (slot, p) in corners.iter_mut().zip(mesh.element_corners(e)) {
            *slot = p;
        }
        let el = &mesh.elements[e];
        Self { corners, count: el.vertex_count, centre: el.centre, radius, area: el.area }
    }

    /// Its own corners.
    pub(super) fn corners(&self) -> &[DVec3] {
        &self.corners[..self.count as usize]
    }

    /// Form factor from a differential area at `p` (normal `n`) to this element of a shooter
    /// with normal `ns`: the exact polygon formula up close, else the point-to-point one,
    /// cos θ cos θ' A / (π r²), which is within ~2 % beyond four radii (Cohen & Wallace
    /// §4.9's "five times rule" is the same trade). An element wholly in front of the
    /// receiver's tangent plane takes the formula in four f32 lanes (within 3e-7 absolute,
    /// see `point_to_polygon_in_front_x4`; the near field keeps shares in f32, and this was
    /// a tenth of the Cornell box's solve in f64); one the plane cuts is clipped in f64.
    pub(super) fn factor_from(&self, p: DVec3, n: DVec3, ns: DVec3) -> f64 {
        if self.centre.distance_squared(p) < 16.0 * self.radius * self.radius {
            point_to_polygon_x4(p, n, self.corners())
        } else {
            point_to_point(p, n, self.centre, ns, self.area)
        }
    }
}

/// A `k × k` grid of unit squares in the plane z = 0, facing +z, row after row: a shooter's
/// elements for the tests.
#[cfg(test)]
pub(super) fn unit_squares(k: usize) -> Vec<ShooterElement> {
    let mut out = Vec::with_capacity(k * k);
    for j in 0..k {
        for i in 0..k {
            let (x, y) = (i as f64, j as f64);
            let corners = [
                DVec3::new(x, y, 0.0),
                DVec3::new(x + 1.0, y, 0.0),
                DVec3::new(x + 1.0, y + 1.0, 0.0),
                DVec3::new(x, y + 1.0, 0.0),
            ];
            let centre = DVec3::new(x + 0.5, y + 0.5, 0.0);
            out.push(ShooterElement { corners, count: 4, centre, radius: 0.5f64.sqrt(), area: 1.0 });
        }
    }
    out
}

/// Element `e`'s corners in a fixed array (the first `vertex_count` are its own).
pub(super) fn corners_of(mesh: &Mesh, e: usize) -> [DVec3; 4] {
    let mut pts = [DVec3::ZERO; 4];
    for (k, p) in mesh.element_corners(e).enumerate() {
        pts[k] = p;
    }
    pts
}

/// The element (corners `receiver`) and the shooter see each other whole: no clipping, no
/// redrawn rays. A patch that meets the shooter's plane (a wall standing on the floor) has
/// most of its elements off that plane: those, when no part of the shooter is behind them
/// either, are such elements too. Same test as the patch's, same tolerance.
pub(super) fn element_facing(shooter: &Patch, plan: &PatchPlan, receiver: &[DVec3]) -> bool {
    let corner = shooter.corners()[0];
    plan.facing
        || (plan.shooter_ahead
            && receiver.iter().all(|p| shooter.normal.dot(*p - corner) > 1e-9 * shooter.area.sqrt()))
}
