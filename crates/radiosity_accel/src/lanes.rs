//! The one segment–triangle test, four lanes at a time.
//!
//! Möller & Trumbore's test (1997, "Fast, minimum storage ray-triangle intersection") in the
//! form of obvhs's `RtTriangle::intersect`: edges `e1 = v0 − v1`, `e2 = v2 − v0` and normal
//! `ng = e1 × e2` precomputed; `c = v0 − o`, `r = d × c`, `1/det = 1/(ng·d)`,
//! `u = (r·e2)/det`, `v = (r·e1)/det`, `w = 1 − u − v`, hit when `u`, `v`, `w` have clear
//! sign bits, `det ≠ 0` and the plane distance `t = (ng·c)/det` lies in `[tmin, tmax]`.
//!
//! Every lane computes exactly what `RtTriangle::intersect` computes for its ray and
//! triangle, operation for operation (products commute and every dot product sums x, y,
//! then z, as glam's do), so all callers answer a segment bit for bit alike, whatever they
//! put in the lanes: four rays against one triangle (candidate lists, [`crate::CandidateTriangles`]),
//! one ray against four triangles (the BVH's leaves), or one ray against one triangle.

use glam::Vec4;

/// x, y and z of four points or vectors, one per lane.
pub(crate) type Lanes3 = [Vec4; 3];

/// Four triangles (or one, splatted) in the test's precomputed form, axis by axis.
#[derive(Clone, Copy, Debug)]
pub(crate) struct TriangleLanes {
    pub(crate) v0: Lanes3,
    pub(crate) ng: Lanes3,
    pub(crate) e1: Lanes3,
    pub(crate) e2: Lanes3,
}

/// Four segments (or one, splatted): origins and directions, axis by axis.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RayLanes {
    pub(crate) origin: Lanes3,
    pub(crate) direction: Lanes3,
}

/// Each lane's ray against its triangle: the plane distance `t` of every lane, and a bit per
/// lane, among the lanes of `mask`, whose ray meets its triangle within `[tmin, tmax]`.
///
/// The plane distance comes first: most candidates lie where the segments do not reach their
/// plane, and when no lane of `mask` does, the edge tests are skipped.
#[inline(always)]
pub(crate) fn hit_x4(ray: &RayLanes, tri: &TriangleLanes, tmin: Vec4, tmax: Vec4, mask: u32) -> (Vec4, u32) {
    let [ox, oy, oz] = ray.origin;
    let [dx, dy, dz] = ray.direction;
    let [v0x, v0y, v0z] = tri.v0;
    let [e1x, e1y, e1z] = tri.e1;
    let [e2x, e2y, e2z] = tri.e2;
    let [nx, ny, nz] = tri.ng;
    let (cx, cy, cz) = (v0x - ox, v0y - oy, v0z - oz);
    let inv_det = Vec4::ONE / (nx * dx + ny * dy + nz * dz);
    let t = (nx * cx + ny * cy + nz * cz) * inv_det;
    let reach = t.cmpge(tmin).bitmask() & t.cmple(tmax).bitmask() & mask;
    if reach == 0 {
        return (t, 0);
    }
    // r = d × c and the edge coordinates.
    let (rx, ry, rz) = (dy * cz - dz * cy, dz * cx - dx * cz, dx * cy - dy * cx);
    let u = (rx * e2x + ry * e2y + rz * e2z) * inv_det;
    let v = (rx * e1x + ry * e1y + rz * e1z) * inv_det;
    let w = Vec4::ONE - u - v;
    // u, v, w all non-negative (sign bits clear, as `RtTriangle::intersect` reads them).
    let inside = !(u.is_negative_bitmask() | v.is_negative_bitmask() | w.is_negative_bitmask());
    (t, inside & inv_det.cmpne(Vec4::ZERO).bitmask() & reach)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec3, Vec3A};
    use obvhs::{ray::Ray, rt_triangle::RtTriangle};

    fn splat(v: Vec3A) -> Lanes3 {
        [Vec4::splat(v.x), Vec4::splat(v.y), Vec4::splat(v.z)]
    }

    /// One ray against one triangle in every lane answers as obvhs's `RtTriangle::intersect`
    /// (the reference [`crate::BruteForce`] uses), on random segments and triangles.
    #[test]
    fn lanes_answer_as_the_reference_test() {
        let mut next = crate::test_uniforms(0x51_7cc1_b727_220a);
        let mut point = || Vec3::new(next(), next(), next()) * 4.0;
        let (mut hits, mut misses) = (0, 0);
        for _ in 0..20_000 {
            let (a, b, c) = (point(), point(), point());
            let (from, to) = (point(), point());
            let rt = RtTriangle::new(a.into(), b.into(), c.into());
            let d = crate::nudge(Vec3A::from(to - from));
            let ray = Ray::new(Vec3A::from(from), d, 1e-4, 1.0 - 1e-4);
            let expected = rt.intersect(&ray).is_finite();
            let tri =
                TriangleLanes { v0: splat(rt.v0), ng: splat(rt.ng), e1: splat(rt.e1), e2: splat(rt.e2) };
            let lanes = RayLanes { origin: splat(from.into()), direction: splat(d) };
            let (_, hit) = hit_x4(&lanes, &tri, Vec4::splat(1e-4), Vec4::splat(1.0 - 1e-4), 0b1111);
            assert_eq!(hit, if expected { 0b1111 } else { 0 }, "{from} -> {to}");
            if expected {
                hits += 1;
            } else {
                misses += 1;
            }
        }
        assert!(hits > 1000 && misses > 1000, "{hits} hits, {misses} misses");
    }
}
