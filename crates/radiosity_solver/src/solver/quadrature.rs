//! How finely a receiving element is integrated against a shooter: one midpoint when it is
//! small against its gap to the shooter, else Gauss cells sized to the gap (the "5× rule" of
//! VRAD, Wallace et al. 1989, turned into a cell count).

use glam::DVec3;
use radiosity_mesh::Patch;

use crate::form_factor::{Rule, distance_to_polygon};

/// An element takes one midpoint when its gap to the shooter exceeds this many of its radii.
pub(super) const MIDPOINT_RATIO: f64 = 16.0;

/// Receiver quadrature: one midpoint when the element is small against its gap to the
/// shooter (radius < gap/16, midpoint error ~4e-3 of the curvature term; the closed-form
/// tests also pass at gap/8, so this keeps a factor of two in hand), else Gauss cells of radius < gap/4
/// (error ~ (1/4)⁴ ≈ 4e-3 of the point form's curvature term, ~1e-5 in practice).
///
/// What matters most is that a receiver's row of form factors sums to 1 in a closed scene —
/// the midpoint rule overestimates (the integrand is convex), and an all-midpoint scheme
/// needed radius < gap/32 everywhere (16× the evaluations) to bring the ρ = 0.9 furnace
/// inside 0.5 %.
pub(super) fn quadrature(el_radius: f64, gap: f64, max: u32) -> (u32, Rule) {
    let gap = gap.max(1e-12 * el_radius);
    if MIDPOINT_RATIO * el_radius < gap {
        return (1, Rule::Midpoint);
    }
    (((4.0 * el_radius / gap).ceil() as u32).clamp(1, max), Rule::Gauss)
}

/// [`quadrature`] for an element at `centre` with circumradius `radius`, and the shooter
/// (circumradius `shooter_radius` about its centre). The exact distance to the shooter lies
/// between the larger of the distance to its plane and the distance to its centre less its
/// radius, and the distance to its centre; the rule only grows as the gap shrinks, so when
/// both bounds (widened by a millionth, more than the exact distance's rounding) give the
/// same rule, so does the exact distance, which is then not computed (it costs far more
/// than the bounds for elements beside the shooter).
pub(super) fn element_quadrature(
    centre: DVec3,
    radius: f64,
    shooter: &Patch,
    shooter_radius: f64,
    max: u32,
) -> (u32, Rule) {
    let corners = shooter.corners();
    let to_centre = centre.distance(shooter.centre);
    let height = shooter.normal.dot(centre - corners[0]).abs();
    let (low, high) = (height.max(to_centre - shooter_radius), to_centre);
    let near = quadrature(radius, low * (1.0 - 1e-6) - radius, max);
    if near == quadrature(radius, high * (1.0 + 1e-6) - radius, max) {
        return near;
    }
    quadrature(radius, distance_to_polygon(centre, shooter.normal, corners) - radius, max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiosity_mesh::Mesh;
    use radiosity_scenes::furnace_box;

    /// Far: one midpoint; near: Gauss cells of radius below a quarter of the gap, capped at
    /// `max`; the count never falls as the gap shrinks.
    #[test]
    fn the_rule_tightens_as_the_gap_shrinks() {
        assert_eq!(quadrature(1.0, 16.5, 8), (1, Rule::Midpoint));
        assert_eq!(quadrature(1.0, 16.0, 8), (1, Rule::Gauss));
        assert_eq!(quadrature(1.0, 4.0, 8), (1, Rule::Gauss));
        assert_eq!(quadrature(1.0, 3.9, 8), (2, Rule::Gauss));
        assert_eq!(quadrature(1.0, 1.0, 8), (4, Rule::Gauss));
        assert_eq!(quadrature(1.0, 0.1, 8), (8, Rule::Gauss));
        // Touching (gap 0 or below, an element on the shooter's edge): the finest allowed.
        assert_eq!(quadrature(1.0, 0.0, 8), (8, Rule::Gauss));
        assert_eq!(quadrature(1.0, -1.0, 256), (256, Rule::Gauss));
        let mut last = 0;
        for k in (1..400).rev() {
            let (n, rule) = quadrature(1.0, k as f64 * 0.05, 256);
            let n = if rule == Rule::Midpoint { 0 } else { n };
            assert!(n >= last, "gap {}: {n} cells after {last}", k as f64 * 0.05);
            last = n;
        }
    }

    /// The bounds shortcut picks the rule the exact distance picks, for every element of a
    /// box against every patch of it (near, far, beside and across).
    #[test]
    fn bounds_give_the_exact_distances_rule() {
        let scene = furnace_box(0.5, 1.0);
        let mesh = Mesh::build(&scene, &scene.mesh_params()).unwrap();
        let mut settled_by_bounds = 0;
        for shooter in &mesh.patches {
            let corners = shooter.corners();
            let shooter_radius = corners.iter().map(|c| c.distance(shooter.centre)).fold(0.0, f64::max);
            for (e, el) in mesh.elements.iter().enumerate() {
                let radius = mesh.element_corners(e).map(|p| p.distance(el.centre)).fold(0.0, f64::max);
                let exact =
                    quadrature(radius, distance_to_polygon(el.centre, shooter.normal, corners) - radius, 4);
                assert_eq!(
                    element_quadrature(el.centre, radius, shooter, shooter_radius, 4),
                    exact,
                    "element {e}"
                );
                let to_centre = el.centre.distance(shooter.centre);
                let low = shooter.normal.dot(el.centre - corners[0]).abs().max(to_centre - shooter_radius);
                settled_by_bounds += usize::from(
                    quadrature(radius, low * (1.0 - 1e-6) - radius, 4)
                        == quadrature(radius, to_centre * (1.0 + 1e-6) - radius, 4),
                );
            }
        }
        assert!(settled_by_bounds > 0, "the shortcut never applied");
    }
}
