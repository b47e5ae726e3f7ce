//! Convex polygons on a plane, as the mesher cuts them: clipping by a line, splitting one
//! polygon by another, areas and containment. Corners are 3D points on the plane; "counter-
//! clockwise" is about the plane's normal.

use glam::DVec3;

use radiosity_core::Polygon;

/// A point's exact position as a hashable key: faces of one solid share corners bit for bit.
/// Adding 0 makes −0 and +0 (a pole of a model's sphere written as `-0` and `0`) one key.
pub(crate) fn key(p: DVec3) -> [u64; 3] {
    let p = p + DVec3::ZERO;
    [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]
}

/// The bounding box of `v` (not empty).
pub(crate) fn bounds(v: &[DVec3]) -> (DVec3, DVec3) {
    v.iter().fold((v[0], v[0]), |(lo, hi), &q| (lo.min(q), hi.max(q)))
}

/// The tolerance for "on the plane": the planarity a [`Polygon`] is allowed (1e-4 of its
/// bounding box's diagonal).
pub(crate) fn tolerance(p: &Polygon) -> f64 {
    let v = p.vertices();
    let (lo, hi) = bounds(v);
    1e-4 * lo.distance(hi)
}

/// Unit normal n and offset d of a polygon's plane n·x = d, through its vertex mean.
pub(crate) fn plane(p: &Polygon) -> (DVec3, f64) {
    let v = p.vertices();
    let centre = v.iter().copied().sum::<DVec3>() / v.len() as f64;
    (p.normal(), p.normal().dot(centre))
}

/// Distance from `p` to a convex planar polygon, counter-clockwise about its unit normal `n`:
/// to its plane when `p` projects inside it, else to its nearest edge.
pub fn distance_to_polygon(p: DVec3, n: DVec3, poly: &[DVec3]) -> f64 {
    let k = poly.len();
    let height = n.dot(p - poly[0]);
    let q = p - n * height;
    let inside = (0..k).all(|i| (poly[(i + 1) % k] - poly[i]).cross(q - poly[i]).dot(n) >= 0.0);
    if inside {
        return height.abs();
    }
    (0..k)
        .map(|i| {
            let (a, b) = (poly[i], poly[(i + 1) % k]);
            let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            p.distance(a + (b - a) * t)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Orders points by x, then y, then z: a fixed order for corners whatever the input's.
pub(crate) fn lexicographic(a: DVec3, b: DVec3) -> std::cmp::Ordering {
    a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)).then(a.z.total_cmp(&b.z))
}

/// The area of `pts`, positive when they run counter-clockwise about `n`.
pub(crate) fn area_signed(pts: &[DVec3], n: DVec3) -> f64 {
    let mut s = DVec3::ZERO;
    for (i, &a) in pts.iter().enumerate() {
        s += a.cross(pts[(i + 1) % pts.len()]);
    }
    0.5 * s.dot(n)
}

/// The unsigned area of `pts` (0 for fewer than three corners).
pub(crate) fn area(pts: &[DVec3], n: DVec3) -> f64 {
    if pts.len() < 3 { 0.0 } else { area_signed(pts, n).abs() }
}

/// Whether `p` (on the plane) lies inside the convex polygon `poly` whose normal is `n`, or
/// within `eps` of its outline.
pub(crate) fn contains_within(poly: &[DVec3], n: DVec3, p: DVec3, eps: f64) -> bool {
    let k = poly.len();
    (0..k).all(|i| {
        let edge = poly[(i + 1) % k] - poly[i];
        edge.cross(p - poly[i]).dot(n) >= -eps * edge.length()
    })
}

/// The part of convex `poly` where `f(x) ≥ 0` for the affine `f` (Sutherland & Hodgman 1974,
/// one clipping plane).
pub(crate) fn clip(poly: &[DVec3], f: impl Fn(DVec3) -> f64) -> Vec<DVec3> {
    let mut out = Vec::with_capacity(poly.len() + 1);
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        let (fa, fb) = (f(a), f(b));
        if fa >= 0.0 {
            out.push(a);
        }
        if (fa >= 0.0) != (fb >= 0.0) {
            out.push(a + (b - a) * (fa / (fa - fb)));
        }
    }
    out
}

/// Convex `piece` minus convex footprint `f` (both on the plane with normal `n`) as convex
/// pieces, and `piece ∩ f`.
pub(crate) fn split(piece: &[DVec3], f: &[DVec3], n: DVec3) -> (Vec<Vec<DVec3>>, Vec<DVec3>) {
    let mut outside = Vec::new();
    let mut rest = piece.to_vec();
    for i in 0..f.len() {
        let (a, b) = (f[i], f[(i + 1) % f.len()]);
        // Inward normal of the edge within the plane (the footprint is counter-clockwise).
        let m = n.cross(b - a);
        if m == DVec3::ZERO {
            continue; // a repeated corner: no edge, nothing to cut off
        }
        let inside = |x: DVec3| m.dot(x - a);
        let out = clip(&rest, |x| -inside(x));
        if area(&out, n) > 0.0 {
            outside.push(out);
        }
        rest = clip(&rest, inside);
        if rest.len() < 3 {
            return (outside, Vec::new());
        }
    }
    (outside, rest)
}

/// A piece's corners without repeats (a cut through a corner gives it twice), within
/// round-off of the target's size (1e-9 of its bounding box's diagonal).
pub(crate) fn clean(piece: Vec<DVec3>, target: &Polygon) -> Vec<DVec3> {
    let eps = 1e-5 * tolerance(target);
    let mut out: Vec<DVec3> = Vec::with_capacity(piece.len());
    for p in piece {
        if out.last().is_none_or(|q: &DVec3| q.distance(p) > eps) {
            out.push(p);
        }
    }
    while out.len() > 1 && out[0].distance(out[out.len() - 1]) <= eps {
        out.pop();
    }
    out
}
