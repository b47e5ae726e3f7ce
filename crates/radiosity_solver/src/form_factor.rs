//! Form factors between a receiving element and a shooting patch.
//!
//! * Point to polygon, exact (Lambert's formula as used by Baum, Rushmeier & Winget 1989,
//!   "Improving radiosity solutions through the use of analytically determined
//!   form-factors"): `F(dA→A) = 1/(2π) Σ_k γ_k · n · (R_k × R_{k+1}) / |R_k × R_{k+1}|`,
//!   where `R_k` runs from the point to the polygon's vertices and `γ_k` is the angle between
//!   consecutive `R_k`. The polygon is first clipped to the receiver's hemisphere.
//! * Area to polygon: the point form integrated over the receiver by midpoint quadrature on
//!   `n × n` sub-cells; `n` grows as the receiver gets close to the shooter, where the
//!   integrand varies fastest (the "5× rule" of VRAD, Wallace et al. 1989, turned into a
//!   sample count).
//! * Point to point (the source document's formula): `cosθi cosθj A / (π r²)`, good only far
//!   away; kept for comparison.

use glam::DVec3;
use std::f64::consts::PI;

/// Clips a convex polygon to the half-space `n · (x − p) ≥ 0`; at most 5 vertices come out of
/// a quad.
fn clip_to_hemisphere(p: DVec3, n: DVec3, poly: &[DVec3], out: &mut [DVec3; 8]) -> usize {
    let mut count = 0;
    let k = poly.len();
    for i in 0..k {
        let (a, b) = (poly[i], poly[(i + 1) % k]);
        let (da, db) = (n.dot(a - p), n.dot(b - p));
        if da >= 0.0 {
            out[count] = a;
            count += 1;
        }
        if (da >= 0.0) != (db >= 0.0) {
            let t = da / (da - db);
            out[count] = a + (b - a) * t;
            count += 1;
        }
    }
    count
}

/// Exact form factor from a differential area at `p` with unit normal `n` to a convex planar
/// polygon (any winding), ignoring occlusion. Parts of the polygon behind the receiver's
/// tangent plane are clipped away, so the result is in [0, 1].
pub fn point_to_polygon(p: DVec3, n: DVec3, polygon: &[DVec3]) -> f64 {
    let mut clipped = [DVec3::ZERO; 8];
    let k = clip_to_hemisphere(p, n, polygon, &mut clipped);
    if k < 3 {
        return 0.0;
    }
    let mut sum = 0.0;
    for i in 0..k {
        let (ra, rb) = (clipped[i] - p, clipped[(i + 1) % k] - p);
        let c = ra.cross(rb);
        let len = c.length();
        if len <= 1e-300 {
            continue;
        }
        let gamma = len.atan2(ra.dot(rb));
        sum += gamma * n.dot(c) / len;
    }
    (sum / (2.0 * PI)).abs().min(1.0)
}

/// The source document's point-to-point form factor from a differential receiver at `p`
/// (normal `n`) to a shooter of area `area` at `c` (normal `nc`): `cosθi cosθj A / (π r²)`,
/// clamped to [0, 1] because it diverges at short range.
pub fn point_to_point(p: DVec3, n: DVec3, c: DVec3, nc: DVec3, area: f64) -> f64 {
    let d = c - p;
    let r2 = d.length_squared();
    if r2 == 0.0 {
        return 0.0;
    }
    let r = r2.sqrt();
    let (cos_r, cos_s) = (n.dot(d) / r, -nc.dot(d) / r);
    if cos_r <= 0.0 || cos_s <= 0.0 {
        return 0.0;
    }
    (cos_r * cos_s * area / (PI * r2)).min(1.0)
}

/// Calls `f(point, weight)` for the centroids of an `n × n` subdivision of a triangle or a
/// convex quad, with weights (sub-area / area) summing to 1.
pub fn for_each_subcell(poly: &[DVec3], n: u32, mut f: impl FnMut(DVec3, f64)) {
    let nf = n as f64;
    if poly.len() == 4 {
        let at = |u: f64, v: f64| {
            poly[0] * ((1.0 - u) * (1.0 - v))
                + poly[1] * (u * (1.0 - v))
                + poly[2] * (u * v)
                + poly[3] * ((1.0 - u) * v)
        };
        let area = |a: DVec3, b: DVec3, c: DVec3, d: DVec3| 0.5 * (c - a).cross(d - b).length();
        let total = area(poly[0], poly[1], poly[2], poly[3]);
        for j in 0..n {
            for i in 0..n {
                let (u0, v0, u1, v1) =
                    (i as f64 / nf, j as f64 / nf, (i + 1) as f64 / nf, (j + 1) as f64 / nf);
                let (a, b, c, d) = (at(u0, v0), at(u1, v0), at(u1, v1), at(u0, v1));
                // Midpoint of a bilinear cell; exact centroid for parallelograms.
                f(at((u0 + u1) * 0.5, (v0 + v1) * 0.5), area(a, b, c, d) / total);
            }
        }
    } else {
        let (a, e1, e2) = (poly[0], (poly[1] - poly[0]) / nf, (poly[2] - poly[0]) / nf);
        let w = 1.0 / (nf * nf);
        for j in 0..n {
            for i in 0..n - j {
                let (x, y) = (i as f64, j as f64);
                f(a + e1 * (x + 1.0 / 3.0) + e2 * (y + 1.0 / 3.0), w);
                if i + j + 2 <= n {
                    f(a + e1 * (x + 2.0 / 3.0) + e2 * (y + 2.0 / 3.0), w);
                }
            }
        }
    }
}

/// Unoccluded area-to-area form factor `F(receiver → shooter)` by `n × n` midpoint quadrature
/// over the receiver with the exact point-to-polygon form at each point. Points behind the
/// shooter's plane (`shooter_normal`) receive nothing.
pub fn polygon_to_polygon(
    receiver: &[DVec3],
    receiver_normal: DVec3,
    shooter: &[DVec3],
    shooter_normal: DVec3,
    n: u32,
) -> f64 {
    let mut f = 0.0;
    for_each_subcell(receiver, n, |p, w| {
        if shooter_normal.dot(p - shooter[0]) > 0.0 {
            f += w * point_to_polygon(p, receiver_normal, shooter);
        }
    });
    f
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(z: f64, size: f64, flip: bool) -> Vec<DVec3> {
        let mut v = vec![
            DVec3::new(0.0, 0.0, z),
            DVec3::new(size, 0.0, z),
            DVec3::new(size, size, z),
            DVec3::new(0.0, size, z),
        ];
        if flip {
            v.reverse();
        }
        v
    }

    /// Howell C-11, opposed parallel rectangles a×b at distance c.
    fn c11(a: f64, b: f64, c: f64) -> f64 {
        let (x, y) = (a / c, b / c);
        let (x2, y2) = (x * x, y * y);
        2.0 / (PI * x * y)
            * (((1.0 + x2) * (1.0 + y2) / (1.0 + x2 + y2)).sqrt().ln()
                + x * (1.0 + y2).sqrt() * (x / (1.0 + y2).sqrt()).atan()
                + y * (1.0 + x2).sqrt() * (y / (1.0 + x2).sqrt()).atan()
                - x * x.atan()
                - y * y.atan())
    }

    /// Howell C-14, perpendicular rectangles l×w and l×h sharing the edge l.
    fn c14(l: f64, w: f64, h: f64) -> f64 {
        let (w, h) = (w / l, h / l);
        let (w2, h2) = (w * w, h * h);
        let a = (1.0 + w2) * (1.0 + h2) / (1.0 + w2 + h2);
        let b = (w2 * (1.0 + w2 + h2) / ((1.0 + w2) * (w2 + h2))).powf(w2);
        let c = (h2 * (1.0 + h2 + w2) / ((1.0 + h2) * (h2 + w2))).powf(h2);
        1.0 / (PI * w)
            * (w * (1.0 / w).atan() + h * (1.0 / h).atan()
                - (h2 + w2).sqrt() * (1.0 / (h2 + w2).sqrt()).atan()
                + 0.25 * (a * b * c).ln())
    }

    /// Howell B-3, differential element parallel to an a×b rectangle, normal through a corner.
    fn b3(a: f64, b: f64, c: f64) -> f64 {
        let (x, y) = (a / c, b / c);
        1.0 / (2.0 * PI)
            * (x / (1.0 + x * x).sqrt() * (y / (1.0 + x * x).sqrt()).atan()
                + y / (1.0 + y * y).sqrt() * (x / (1.0 + y * y).sqrt()).atan())
    }

    #[test]
    fn closed_forms_reproduce_the_reference_values() {
        assert!((c11(1.0, 1.0, 1.0) - 0.199825).abs() < 1e-6);
        assert!((c14(1.0, 1.0, 1.0) - 0.200044).abs() < 1e-6);
    }

    #[test]
    fn b3_point_to_rectangle_is_exact() {
        // The point form is exact: tolerance is round-off.
        for (a, b, c) in [(1.0, 1.0, 1.0), (2.0, 0.5, 1.0), (0.3, 3.0, 0.7), (10.0, 10.0, 0.1)] {
            let rect = [DVec3::ZERO, DVec3::new(a, 0.0, 0.0), DVec3::new(a, b, 0.0), DVec3::new(0.0, b, 0.0)];
            let f = point_to_polygon(DVec3::new(0.0, 0.0, c), -DVec3::Z, &rect);
            let expected = b3(a, b, c);
            assert!((f - expected).abs() < 1e-3 * expected * 1e-3, "B-3 {a} {b} {c}: {f} vs {expected}");
        }
    }

    #[test]
    fn c11_parallel_plates_within_a_thousandth() {
        // The integrand is smooth over the receiver (no shared edge); the midpoint rule's
        // error falls as 1/n² (measured 0.24 % at 8×8, 0.1 % at 16×16 for X = 2), so 32×32.
        for (a, c) in [(1.0, 1.0), (2.0, 1.0), (0.5, 1.0), (1.0, 0.25), (3.0, 0.5)] {
            let lower = square(0.0, a, false);
            let upper = square(c, a, true);
            let f = polygon_to_polygon(&lower, DVec3::Z, &upper, -DVec3::Z, 32);
            let expected = c11(a, a, c);
            assert!((f - expected).abs() < 1e-3 * expected, "C-11 a={a} c={c}: {f} vs {expected}");
        }
    }

    #[test]
    fn c14_perpendicular_plates_within_a_thousandth() {
        // A shared edge makes the integrand's derivative singular along it; 32×32 cells
        // bring the midpoint error below 0.1 % (measured: 8×8 gives ~0.3 %).
        for (w, h) in [(1.0, 1.0), (2.0, 1.0), (0.5, 2.0)] {
            // Surface 1: l×w in the floor (y = 0) facing +y; surface 2: l×h wall (z = 0) facing +z.
            let floor = vec![
                DVec3::ZERO,
                DVec3::new(0.0, 0.0, w),
                DVec3::new(1.0, 0.0, w),
                DVec3::new(1.0, 0.0, 0.0),
            ];
            let wall = vec![
                DVec3::ZERO,
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, h, 0.0),
                DVec3::new(0.0, h, 0.0),
            ];
            let f = polygon_to_polygon(&floor, DVec3::Y, &wall, DVec3::Z, 32);
            let expected = c14(1.0, w, h);
            assert!((f - expected).abs() < 1e-3 * expected, "C-14 w={w} h={h}: {f} vs {expected}");
        }
    }

    #[test]
    fn reciprocity_holds() {
        let floor = vec![
            DVec3::ZERO,
            DVec3::new(0.0, 0.0, 2.0),
            DVec3::new(1.0, 0.0, 2.0),
            DVec3::new(1.0, 0.0, 0.0),
        ];
        let wall = vec![
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 0.5, 0.0),
            DVec3::new(0.0, 0.5, 0.0),
        ];
        // Both directions integrate with 64×64 cells; the shared edge limits agreement to the
        // quadrature error, ~0.05 % here.
        let f12 = polygon_to_polygon(&floor, DVec3::Y, &wall, DVec3::Z, 64);
        let f21 = polygon_to_polygon(&wall, DVec3::Z, &floor, DVec3::Y, 64);
        assert!((2.0 * f12 - 0.5 * f21).abs() < 1e-3 * 2.0 * f12, "A1F12 {} A2F21 {}", 2.0 * f12, 0.5 * f21);
    }

    #[test]
    fn point_sees_a_closed_box_whole() {
        // From a point on the floor of a unit box the other five faces cover the hemisphere.
        let faces =
            radiosity_core::box_faces(DVec3::ZERO, DVec3::ONE, radiosity_core::Facing::Inward, 0.0).unwrap();
        let p = DVec3::new(0.3, 0.0, 0.7);
        let total: f64 = faces.iter().skip(1).map(|f| point_to_polygon(p, DVec3::Y, f.vertices())).sum();
        assert!((total - 1.0).abs() < 1e-12, "{total}");
    }

    #[test]
    fn point_to_point_matches_exact_far_away() {
        let tiny = square(0.0, 0.01, false);
        let p = DVec3::new(0.005, 0.005, 1.0);
        let exact = point_to_polygon(p, -DVec3::Z, &tiny);
        let approx = point_to_point(p, -DVec3::Z, DVec3::new(0.005, 0.005, 0.0), DVec3::Z, 1e-4);
        assert!((exact - approx).abs() < 1e-4 * exact);
    }
}
