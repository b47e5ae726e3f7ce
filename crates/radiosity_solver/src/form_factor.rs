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
pub use radiosity_mesh::distance_to_polygon;
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

/// `atan2(y, x)` for `y ≥ 0`, in [0, π]: the angle between two vectors from the length of
/// their cross product and their dot product.
///
/// The form factor's hot loop calls this four times per evaluation, and libm's `atan2` was a
/// large share of the solve time; this is the classic reduction (Cephes `atan`): fold into
/// t ∈ [0, 1], then by atan(t) = π/6 + atan((√3 t − 1)/(√3 + t)) into |t| ≤ tan(π/12), where
/// the odd Taylor series to t¹⁵ leaves about 1e-11 rad of error.
#[inline]
fn angle(y: f64, x: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_6};
    const TAN_PI_12: f64 = 0.267_949_192_431_122_7;
    const SQRT_3: f64 = 1.732_050_807_568_877_2;
    let ax = x.abs();
    let (num, den, swapped) = if y <= ax { (y, ax, false) } else { (ax, y, true) };
    let t = if den > 0.0 { num / den } else { 0.0 };
    let (t, offset) = if t > TAN_PI_12 { ((SQRT_3 * t - 1.0) / (SQRT_3 + t), FRAC_PI_6) } else { (t, 0.0) };
    let t2 = t * t;
    let series = t
        * (1.0
            - t2 * (1.0 / 3.0
                - t2 * (1.0 / 5.0
                    - t2 * (1.0 / 7.0
                        - t2 * (1.0 / 9.0 - t2 * (1.0 / 11.0 - t2 * (1.0 / 13.0 - t2 / 15.0)))))));
    let a = offset + series;
    let a = if swapped { FRAC_PI_2 - a } else { a };
    if x < 0.0 { PI - a } else { a }
}

/// Exact form factor from a differential area at `p` with unit normal `n` to a convex planar
/// polygon (any winding), ignoring occlusion. Parts of the polygon behind the receiver's
/// tangent plane are clipped away, so the result is in [0, 1].
pub fn point_to_polygon(p: DVec3, n: DVec3, polygon: &[DVec3]) -> f64 {
    // Most polygons lie wholly in front: check the heights first and skip the copy.
    if polygon.iter().all(|v| n.dot(*v - p) >= 0.0) {
        return point_to_polygon_in_front(p, n, polygon);
    }
    let mut clipped = [DVec3::ZERO; 8];
    let k = clip_to_hemisphere(p, n, polygon, &mut clipped);
    if k < 3 {
        return 0.0;
    }
    point_to_polygon_in_front(p, n, &clipped[..k])
}

/// [`point_to_polygon`] on the fast path: a polygon wholly in front of the receiver's tangent
/// plane in four f32 lanes ([`point_to_polygon_in_front_x4`], which keeps its precision
/// right beside the polygon too), one the plane cuts clipped in f64.
pub fn point_to_polygon_x4(p: DVec3, n: DVec3, polygon: &[DVec3]) -> f64 {
    if polygon.iter().all(|v| n.dot(*v - p) >= 0.0) {
        point_to_polygon_in_front_x4(p, n, polygon)
    } else {
        point_to_polygon(p, n, polygon)
    }
}

/// [`point_to_polygon`] for a polygon known to lie wholly in front of the receiver's tangent
/// plane, so the clipping can be skipped (clipping such a polygon returns it unchanged, so
/// both give the same bits).
pub fn point_to_polygon_in_front(p: DVec3, n: DVec3, polygon: &[DVec3]) -> f64 {
    let Some(last) = polygon.last() else { return 0.0 };
    let mut sum = 0.0;
    // Edges (k−1, 0), (0, 1), …: no index arithmetic in the hot loop.
    let mut ra = *last - p;
    for v in polygon {
        let rb = *v - p;
        let c = ra.cross(rb);
        let len = c.length();
        if len > 1e-300 {
            sum += angle(len, ra.dot(rb)) * n.dot(c) / len;
        }
        ra = rb;
    }
    (sum / (2.0 * PI)).abs().min(1.0)
}

/// [`point_to_polygon_in_front`] for a triangle or a quad, its edges side by side in the
/// four single-precision lanes of a SIMD register (SSE2, glam's `Vec4`).
///
/// The edge vectors are formed in double precision and only then rounded, so the lanes see
/// differences of nearby points (no cancellation); what is left is f32 round-off, under 3e-7
/// absolute and about 4e-7 of the total (checked against the double-precision form in the
/// tests, near and far). The solver's fast path uses it for every receiver point of a patch
/// that strictly faces the shooter (no clipping).
pub fn point_to_polygon_in_front_x4(p: DVec3, n: DVec3, polygon: &[DVec3]) -> f64 {
    use glam::Vec4;
    let k = polygon.len();
    if !(3..=4).contains(&k) {
        return point_to_polygon_in_front(p, n, polygon);
    }
    // Lane i holds edge (i, i+1); a triangle's fourth lane repeats its first vertex twice, a
    // zero-length edge whose cross product is zero and is masked out below.
    let r = |i: usize| (polygon[i.min(k - 1)] - p).as_vec3();
    let (r0, r1, r2, r3) = (r(0), r(1), r(2), if k == 4 { r(3) } else { r(0) });
    let a = [r0, r1, r2, r3];
    let b = [r1, r2, r3, r0];
    let lanes = |f: fn(glam::Vec3) -> f32, v: &[glam::Vec3; 4]| Vec4::new(f(v[0]), f(v[1]), f(v[2]), f(v[3]));
    let (ax, ay, az) = (lanes(|v| v.x, &a), lanes(|v| v.y, &a), lanes(|v| v.z, &a));
    let (bx, by, bz) = (lanes(|v| v.x, &b), lanes(|v| v.y, &b), lanes(|v| v.z, &b));
    let (cx, cy, cz) = (ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx);
    let len = (cx * cx + cy * cy + cz * cz).sqrt();
    let dot = ax * bx + ay * by + az * bz;
    let n = n.as_vec3();
    let along = cx * n.x + cy * n.y + cz * n.z;
    let live = len.cmpgt(Vec4::splat(1e-30));
    let safe_len = Vec4::select(live, len, Vec4::ONE);
    let terms = angle_x4(len, dot) * along / safe_len;
    let sum = Vec4::select(live, terms, Vec4::ZERO).element_sum();
    (f64::from(sum) / (2.0 * PI)).abs().min(1.0)
}

/// [`point_to_polygon_in_front`] from up to four receiver points at once (`points[i]` with
/// unit normal `normals[i]`, for `i < count`), one point per SIMD lane, to a polygon in front
/// of all of them.
///
/// [`point_to_polygon_in_front_x4`] puts a polygon's edges in the lanes and sums them across
/// at the end; with the receivers in the lanes the edge loop runs down each lane and nothing
/// is gathered across, which is what many elements of one patch facing one shooter need.
/// Same precision: each edge vector is formed in double precision, then rounded.
pub fn points_to_polygon_in_front_x4(
    points: &[DVec3; 4],
    normals: &[DVec3; 4],
    count: usize,
    polygon: &[DVec3],
) -> [f64; 4] {
    use glam::Vec4;
    let mut out = [0.0; 4];
    let Some(last) = polygon.last() else { return out };
    let count = count.min(4);
    // Lane i: the vector from points[i] to a polygon vertex, per axis.
    let to = |v: DVec3| {
        let mut r = [[0.0f32; 4]; 3];
        for i in 0..count {
            let d = (v - points[i]).as_vec3();
            (r[0][i], r[1][i], r[2][i]) = (d.x, d.y, d.z);
        }
        r.map(Vec4::from_array)
    };
    let mut n = [[0.0f32; 4]; 3];
    for i in 0..count {
        let m = normals[i].as_vec3();
        (n[0][i], n[1][i], n[2][i]) = (m.x, m.y, m.z);
    }
    let [nx, ny, nz] = n.map(Vec4::from_array);
    let mut sum = Vec4::ZERO;
    let [mut ax, mut ay, mut az] = to(*last);
    for v in polygon {
        let [bx, by, bz] = to(*v);
        let (cx, cy, cz) = (ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx);
        let len = (cx * cx + cy * cy + cz * cz).sqrt();
        let dot = ax * bx + ay * by + az * bz;
        let along = cx * nx + cy * ny + cz * nz;
        let live = len.cmpgt(Vec4::splat(1e-30));
        let safe_len = Vec4::select(live, len, Vec4::ONE);
        sum += Vec4::select(live, angle_x4(len, dot) * along / safe_len, Vec4::ZERO);
        (ax, ay, az) = (bx, by, bz);
    }
    for (o, s) in out.iter_mut().zip(sum.to_array()).take(count) {
        *o = (f64::from(s) / (2.0 * PI)).abs().min(1.0);
    }
    out
}

/// [`angle`] in four f32 lanes: the same reduction, and the series to t⁹, whose first dropped
/// term (t¹¹/11 at t = tan(π/12)) is 5e-9, below f32 round-off.
fn angle_x4(y: glam::Vec4, x: glam::Vec4) -> glam::Vec4 {
    use glam::Vec4;
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_6, PI};
    const TAN_PI_12: f32 = 0.267_949_2;
    const SQRT_3: f32 = 1.732_050_8;
    let ax = x.abs();
    let swapped = y.cmpgt(ax);
    let (num, den) = (y.min(ax), y.max(ax));
    let t = Vec4::select(
        den.cmpgt(Vec4::ZERO),
        num / Vec4::select(den.cmpgt(Vec4::ZERO), den, Vec4::ONE),
        Vec4::ZERO,
    );
    let big = t.cmpgt(Vec4::splat(TAN_PI_12));
    let reduced = (t * SQRT_3 - Vec4::ONE) / (t + Vec4::splat(SQRT_3));
    let t = Vec4::select(big, reduced, t);
    let offset = Vec4::select(big, Vec4::splat(FRAC_PI_6), Vec4::ZERO);
    let t2 = t * t;
    let series = t * (Vec4::ONE - t2 * (1.0 / 3.0 - t2 * (1.0 / 5.0 - t2 * (1.0 / 7.0 - t2 * (1.0 / 9.0)))));
    let a = offset + series;
    let a = Vec4::select(swapped, Vec4::splat(FRAC_PI_2) - a, a);
    Vec4::select(x.cmplt(Vec4::ZERO), Vec4::splat(PI) - a, a)
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
/// convex quad, with weights (sub-area / area) summing to 1 (the midpoint rule).
pub fn for_each_subcell(poly: &[DVec3], n: u32, f: impl FnMut(DVec3, f64)) {
    for_each_point(poly, n, Rule::Midpoint, f);
}

/// A quadrature rule applied on each of the `n × n` cells of a receiver.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rule {
    /// One point per cell (its centre); error ~ (cell size / distance)².
    Midpoint,
    /// 2 × 2 Gauss–Legendre points on quad cells, Dunavant's 6-point degree-4 rule on
    /// triangle cells (Dunavant 1985); error ~ (cell size / distance)⁴.
    Gauss,
}

/// Gauss–Legendre 2-point nodes on [0, 1]: (1 ∓ 1/√3) / 2.
const GL2: [f64; 2] = [0.211_324_865_405_187_1, 0.788_675_134_594_812_9];

/// Dunavant's degree-4 rule: (barycentric a, b, b) and its permutations, weight.
const DUNAVANT4: [(f64, f64, f64); 2] = [
    (0.108_103_018_168_070, 0.445_948_490_915_965, 0.223_381_589_678_011),
    (0.816_847_572_980_459, 0.091_576_213_509_771, 0.109_951_743_655_322),
];

/// Calls `f(point, weight)` for the quadrature points of `rule` on an `n × n` subdivision of
/// a triangle or a convex planar quad; the weights sum to 1.
pub fn for_each_point(poly: &[DVec3], n: u32, rule: Rule, mut f: impl FnMut(DVec3, f64)) {
    if n == 1 && rule == Rule::Midpoint {
        // The one-cell midpoint rule: the centre of the bilinear map (the vertex mean, for a
        // quad and a triangle alike) with the whole weight; the most common call by far.
        let centre = poly.iter().copied().sum::<DVec3>() / poly.len() as f64;
        f(centre, 1.0);
        return;
    }
    let nf = n as f64;
    if poly.len() == 4 {
        let at = |u: f64, v: f64| {
            poly[0] * ((1.0 - u) * (1.0 - v))
                + poly[1] * (u * (1.0 - v))
                + poly[2] * (u * v)
                + poly[3] * ((1.0 - u) * v)
        };
        // |∂P/∂u × ∂P/∂v| of the bilinear map, linear in (u, v) for a planar quad.
        let jacobian = |u: f64, v: f64| {
            let du = (poly[1] - poly[0]) * (1.0 - v) + (poly[2] - poly[3]) * v;
            let dv = (poly[3] - poly[0]) * (1.0 - u) + (poly[2] - poly[1]) * u;
            du.cross(dv).length()
        };
        let total = 0.5 * (poly[2] - poly[0]).cross(poly[3] - poly[1]).length();
        let cell = 1.0 / (nf * nf * total);
        for j in 0..n {
            for i in 0..n {
                let (u0, v0) = (i as f64 / nf, j as f64 / nf);
                match rule {
                    Rule::Midpoint => {
                        let (u, v) = (u0 + 0.5 / nf, v0 + 0.5 / nf);
                        f(at(u, v), jacobian(u, v) * cell);
                    }
                    Rule::Gauss => {
                        for gv in GL2 {
                            for gu in GL2 {
                                let (u, v) = (u0 + gu / nf, v0 + gv / nf);
                                f(at(u, v), 0.25 * jacobian(u, v) * cell);
                            }
                        }
                    }
                }
            }
        }
    } else {
        let (a, e1, e2) = (poly[0], (poly[1] - poly[0]) / nf, (poly[2] - poly[0]) / nf);
        let w = 1.0 / (nf * nf);
        // A sub-triangle with corners p, p + s, p + t (s, t possibly negated for the
        // inverted cells).
        let mut cell = |p: DVec3, s: DVec3, t: DVec3| match rule {
            Rule::Midpoint => f(p + (s + t) / 3.0, w),
            Rule::Gauss => {
                for (x, y, wk) in DUNAVANT4 {
                    for (b1, b2) in [(y, y), (x, y), (y, x)] {
                        f(p + s * b1 + t * b2, w * wk);
                    }
                }
            }
        };
        for j in 0..n {
            for i in 0..n - j {
                let p = a + e1 * i as f64 + e2 * j as f64;
                cell(p, e1, e2);
                if i + j + 2 <= n {
                    cell(p + e1 + e2, -e1, -e2);
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
    polygon_to_polygon_with(receiver, receiver_normal, shooter, shooter_normal, n, Rule::Midpoint)
}

/// As [`polygon_to_polygon`], with a choice of quadrature rule on each cell.
pub fn polygon_to_polygon_with(
    receiver: &[DVec3],
    receiver_normal: DVec3,
    shooter: &[DVec3],
    shooter_normal: DVec3,
    n: u32,
    rule: Rule,
) -> f64 {
    let mut f = 0.0;
    for_each_point(receiver, n, rule, |p, w| {
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

    /// A receiver beside the shooter, across the line where their planes meet (a wall's foot
    /// on a floor patch), down to a ten-thousandth of the shooter's size from that line:
    /// the four-lane kernel keeps the double-precision form's value to 4e-7 of it.
    #[test]
    fn simd_kernel_holds_beside_the_shooter() {
        let shooter = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        for h in [1e-4, 1e-3, 1e-2, 0.1, 0.3] {
            for i in 0..200 {
                let p = DVec3::new(-0.5 + 2.0 * (f64::from(i) + 0.5) / 200.0, 0.0, h);
                let exact = point_to_polygon_in_front(p, DVec3::Y, &shooter);
                let fast = point_to_polygon_in_front_x4(p, DVec3::Y, &shooter);
                assert!(
                    (fast - exact).abs() <= 4e-7 * exact.max(1e-6),
                    "h {h}, x {}: {fast} vs {exact}",
                    p.x
                );
            }
        }
    }

    #[test]
    fn simd_kernel_matches_double_precision() {
        let mut rng = radiosity_core::random::XorShift64::new(0x1234_5678_9abc_def0u64);
        let mut next = move || rng.next_f64();
        let (mut worst, mut total_error, mut total) = (0.0f64, 0.0, 0.0);
        for case in 0..20_000 {
            let size = 0.05 + next();
            let z = if case % 4 < 2 { 0.2 + 3.0 * next() } else { 0.002 + 0.1 * next() };
            let poly: Vec<DVec3> = if case % 2 == 0 {
                square(z, size, true)
            } else {
                vec![DVec3::new(0.0, 0.0, z), DVec3::new(0.0, size, z), DVec3::new(size, 0.0, z)]
            };
            let p = DVec3::new(4.0 * next() - 2.0, 4.0 * next() - 2.0, 0.0);
            let n = DVec3::new(next() - 0.5, next() - 0.5, 2.0).normalize();
            if poly.iter().any(|v| n.dot(*v - p) <= 0.0) {
                continue;
            }
            let (exact, fast) =
                (point_to_polygon_in_front(p, n, &poly), point_to_polygon_in_front_x4(p, n, &poly));
            worst = worst.max((fast - exact).abs());
            total_error += (fast - exact).abs();
            total += exact;
        }
        // The edge terms are first order in the polygon's angular size and their sum second
        // order, so f32 round-off is relative to the terms: measured 2.9e-7 absolute at worst
        // (points 0.002 above the polygon's plane) and 4.3e-7 of the total.
        assert!(worst < 5e-7, "worst absolute difference {worst:e}");
        assert!(total_error < 2e-6 * total, "total relative difference {:e}", total_error / total);
    }

    /// Four receivers in the lanes agree with the double-precision form point by point, as
    /// closely as the edges-in-lanes kernel does (same bound as its test).
    #[test]
    fn receivers_in_lanes_match_double_precision() {
        let mut rng = radiosity_core::random::XorShift64::new(0x0bad_cafe_f00d_d00du64);
        let mut next = move || rng.next_f64();
        let (mut worst, mut checked) = (0.0f64, 0);
        for case in 0..5_000 {
            let size = 0.05 + next();
            let z = if case % 4 < 2 { 0.2 + 3.0 * next() } else { 0.002 + 0.1 * next() };
            let poly: Vec<DVec3> = if case % 2 == 0 {
                square(z, size, true)
            } else {
                vec![DVec3::new(0.0, 0.0, z), DVec3::new(0.0, size, z), DVec3::new(size, 0.0, z)]
            };
            let count = 1 + case % 4;
            let mut points = [DVec3::ZERO; 4];
            let mut normals = [DVec3::Z; 4];
            for i in 0..count {
                points[i] = DVec3::new(4.0 * next() - 2.0, 4.0 * next() - 2.0, 0.0);
                normals[i] = DVec3::new(next() - 0.5, next() - 0.5, 2.0).normalize();
                if poly.iter().any(|v| normals[i].dot(*v - points[i]) <= 0.0) {
                    normals[i] = DVec3::Z;
                }
            }
            let fast = points_to_polygon_in_front_x4(&points, &normals, count, &poly);
            for i in 0..4 {
                if i < count {
                    let exact = point_to_polygon_in_front(points[i], normals[i], &poly);
                    worst = worst.max((fast[i] - exact).abs());
                    checked += 1;
                } else {
                    assert_eq!(fast[i], 0.0, "lanes past the count stay zero");
                }
            }
        }
        assert!(checked > 10_000);
        assert!(worst < 5e-7, "worst absolute difference {worst:e}");
    }

    #[test]
    fn fast_angle_matches_atan2() {
        let mut worst: f64 = 0.0;
        for i in 0..=400 {
            for j in -400..=400 {
                let (y, x) = (i as f64 * 0.013, j as f64 * 0.0071);
                worst = worst.max((angle(y, x) - y.atan2(x)).abs());
            }
        }
        // The series remainder at the reduced range edge: about 1e-11 rad.
        assert!(worst < 2e-11, "{worst}");
        assert_eq!(angle(0.0, 0.0), 0.0);
        assert!((angle(1.0, 0.0) - PI / 2.0).abs() < 1e-15);
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
    fn gauss_cells_beat_midpoint_cells() {
        // Same 2×2 cells (each as big as the gap): the Gauss rule's error (measured 4e-4) is
        // far below the midpoint rule's.
        let lower = square(0.0, 1.0, false);
        let upper = square(1.0, 1.0, true);
        let expected = c11(1.0, 1.0, 1.0);
        let mid = polygon_to_polygon_with(&lower, DVec3::Z, &upper, -DVec3::Z, 2, Rule::Midpoint);
        let gauss = polygon_to_polygon_with(&lower, DVec3::Z, &upper, -DVec3::Z, 2, Rule::Gauss);
        assert!((gauss - expected).abs() < 1e-3 * expected, "{gauss} vs {expected}");
        assert!((gauss - expected).abs() < 0.1 * (mid - expected).abs());
        // Triangles: split the lower square in two and integrate each half.
        let (t1, t2) = ([lower[0], lower[1], lower[2]], [lower[0], lower[2], lower[3]]);
        let f = 0.5 * polygon_to_polygon_with(&t1, DVec3::Z, &upper, -DVec3::Z, 2, Rule::Gauss)
            + 0.5 * polygon_to_polygon_with(&t2, DVec3::Z, &upper, -DVec3::Z, 2, Rule::Gauss);
        assert!((f - expected).abs() < 1e-3 * expected, "{f} vs {expected}");
    }

    #[test]
    fn quadrature_weights_sum_to_one() {
        let trapezoid =
            [DVec3::ZERO, DVec3::new(3.0, 0.0, 0.0), DVec3::new(2.0, 1.0, 0.0), DVec3::new(1.0, 1.0, 0.0)];
        let tri = [DVec3::ZERO, DVec3::X, DVec3::new(0.2, 2.0, 0.0)];
        for rule in [Rule::Midpoint, Rule::Gauss] {
            for n in [1, 3] {
                for poly in [&trapezoid[..], &tri[..]] {
                    let (mut w, mut c) = (0.0, DVec3::ZERO);
                    for_each_point(poly, n, rule, |p, wk| {
                        w += wk;
                        c += p * wk;
                    });
                    assert!((w - 1.0).abs() < 1e-12, "{rule:?} {n}: {w}");
                    if rule == Rule::Gauss {
                        // Degree ≥ 1 exact: the weighted mean point is the centroid.
                        let area: f64 = (1..poly.len() - 1)
                            .map(|i| 0.5 * (poly[i] - poly[0]).cross(poly[i + 1] - poly[0]).length())
                            .sum();
                        let centroid: DVec3 = (1..poly.len() - 1)
                            .map(|i| {
                                (poly[0] + poly[i] + poly[i + 1]) / 3.0
                                    * (0.5 * (poly[i] - poly[0]).cross(poly[i + 1] - poly[0]).length())
                            })
                            .sum::<DVec3>()
                            / area;
                        assert!((c - centroid).length() < 1e-12);
                    }
                }
            }
        }
    }

    #[test]
    fn distance_to_polygon_inside_and_outside() {
        let sq = square(0.0, 1.0, false);
        assert!((distance_to_polygon(DVec3::new(0.5, 0.5, 2.0), DVec3::Z, &sq) - 2.0).abs() < 1e-12);
        assert!((distance_to_polygon(DVec3::new(2.0, 0.5, 0.0), DVec3::Z, &sq) - 1.0).abs() < 1e-12);
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
