//! Ray queries for the radiosity renderer: segment occlusion (visibility between a receiver
//! point and a point on a shooting patch) and closest hit (the image renderer).
//!
//! One small trait, [`RayQuery`], with three implementations: [`MaskedBvh`] (two [`Bvh`] trees,
//! one of alpha-masked triangles whose clear texels rays pass), [`Bvh`], a sixteen-wide BVH of
//! our own traced one ray at a time with four-lane SIMD (`wide`: boxes and leaf triangles
//! stored axis by axis, collapsed by least surface-area cost from obvhs's binary BVH built
//! with PLOC and reinsertion), and [`BruteForce`], the obviously-correct reference the tests
//! compare against (every triangle, obvhs's own triangle test).
//!
//! Beside them, [`CandidateTriangles`] answers segments against short lists of triangle
//! indices, four segments at a time: the solver's production path for receiver–shooter pairs
//! that its shaft culling narrowed to a few triangles.
//!
//! All the fast paths share one four-lane segment–triangle test (`lanes`), which computes
//! what obvhs's `RtTriangle::intersect` computes, bit for bit; the BVH traces the solver's
//! incoherent segments faster than obvhs's compressed wide BVH8, which it replaced, and is
//! within reach of Embree on the same rays (`cargo run --release -p radiosity_accel
//! --example ray_bench -- rays.bin`, `scripts/embree_bench.py`; the figures are in
//! `docs/PERFORMANCE.md`).
#![warn(missing_docs)]
#![forbid(unsafe_code)]

use glam::{Vec3, Vec3A};
mod candidates;
mod lanes;
mod masked;
mod wide;

pub use candidates::{CandidateTriangles, Segments4};
pub use masked::{ClearTest, MaskedBvh};

use obvhs::{BvhBuildParams, ray::Ray, rt_triangle::RtTriangle, triangle::Triangle};
use wide::WideBvh;

/// A ray hit: distance and the hit triangle with barycentric coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit: the point is `origin + t * direction`.
    pub t: f32,
    /// Index of the triangle in the slice the structure was built from.
    pub triangle: u32,
    /// Barycentric weight of the triangle's second vertex.
    pub u: f32,
    /// Barycentric weight of the triangle's third vertex (the first has `1 - u - v`).
    pub v: f32,
}

/// Ray queries against a fixed set of triangles. Two-sided: back faces block and are hit.
pub trait RayQuery: Send + Sync {
    /// True when some triangle crosses the open segment from `from` to `to`, with both ends
    /// excluded by a relative margin of `1e-4` of the segment (so a ray aimed at a point of a
    /// surface is not stopped by that surface). Callers offset `from` off its own surface.
    fn occluded(&self, from: Vec3, to: Vec3) -> bool;

    /// True when some triangle crosses the ray from `from` along unit `dir` before `reach`: a
    /// shadow ray towards light at infinity (the sun, the sky), `reach` past the scene.
    ///
    /// One segment of that length would skip what lies within [`occluded`]'s margin, 1e-4 of
    /// `reach`, of its start: a millimetre in a 5 m room, where a floor point beside a wall
    /// saw the sky through the wall's foot. So the ray is tested as segments a hundred times
    /// longer each, from 1e-4 of `reach`, each starting halfway along the one before (inside
    /// it, past its margin): the margin at the start is 1e-8 of `reach`.
    ///
    /// [`occluded`]: RayQuery::occluded
    fn occluded_towards(&self, from: Vec3, dir: Vec3, reach: f32) -> bool {
        let (mut start, mut end) = (0.0f32, reach * 1e-4);
        loop {
            let stop = end.min(reach);
            if self.occluded(from + dir * start, from + dir * stop) {
                return true;
            }
            if stop >= reach {
                return false;
            }
            (start, end) = (stop * 0.5, stop * 100.0);
        }
    }

    /// The nearest triangle hit along `origin + t * direction` for `t` in `(0, t_max]`.
    fn closest_hit(&self, origin: Vec3, direction: Vec3, t_max: f32) -> Option<Hit>;

    /// Number of triangles.
    fn triangle_count(&self) -> usize;
}

/// Above this many triangles the BVH is built with obvhs's medium preset, below it with its
/// slowest, best one. On the bench's Cornell box the slowest build traces noticeably faster
/// for a fraction of a second more building, but its build time grows too fast for models of
/// a million triangles.
pub const BEST_BUILD_LIMIT: usize = 250_000;

/// Margin at both ends of an occlusion segment, as a fraction of its length.
const SEGMENT_MARGIN: f32 = 1e-4;

fn to_triangles(triangles: &[[Vec3; 3]]) -> Vec<Triangle> {
    triangles
        .iter()
        .map(|t| Triangle { v0: Vec3A::from(t[0]), v1: Vec3A::from(t[1]), v2: Vec3A::from(t[2]) })
        .collect()
}

/// Barycentric `(u, v)` of point `p` in `tri`, weights of its second and third vertices.
fn barycentric(tri: &Triangle, p: Vec3A) -> (f32, f32) {
    let (e1, e2, d) = (tri.v1 - tri.v0, tri.v2 - tri.v0, p - tri.v0);
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (d1, d2) = (d.dot(e1), d.dot(e2));
    let det = d11 * d22 - d12 * d12;
    let u = (d22 * d1 - d12 * d2) / det;
    let v = (d11 * d2 - d12 * d1) / det;
    // A degenerate triangle (det 0) or one so large that the products overflow gives NaN:
    // take its first vertex rather than let a clamp on NaN panic.
    if !(u.is_finite() && v.is_finite()) {
        return (0.0, 0.0);
    }
    let u = u.clamp(0.0, 1.0);
    (u, v.clamp(0.0, 1.0 - u))
}

/// Replaces direction components that are (almost) zero by a tiny value of the same sign.
///
/// A slab test with an exactly zero direction component computes 0 × ∞ = NaN for a ray
/// that starts on a box face, and flat (zero-thickness) boxes — every wall of an
/// axis-aligned room — are all face; tilting the ray by 1e-7 radian changes no result that
/// matters and keeps the slab arithmetic finite.
fn nudge(d: Vec3A) -> Vec3A {
    let eps = 1e-7 * d.abs().max_element();
    Vec3A::select(d.abs().cmplt(Vec3A::splat(eps)), Vec3A::splat(eps).copysign(d + Vec3A::splat(0.0)), d)
}

fn segment_ray(from: Vec3, to: Vec3) -> Ray {
    Ray::new(Vec3A::from(from), nudge(Vec3A::from(to - from)), SEGMENT_MARGIN, 1.0 - SEGMENT_MARGIN)
}

/// A sixteen-wide BVH over triangles, traced with four-lane SIMD (see the `wide` module).
pub struct Bvh {
    tree: WideBvh,
    triangles: Vec<Triangle>,
}

impl Bvh {
    /// Builds the BVH. An empty slice gives a structure that never hits.
    pub fn new(triangles: &[[Vec3; 3]]) -> Self {
        let triangles = to_triangles(triangles);
        let params = if triangles.len() <= BEST_BUILD_LIMIT {
            BvhBuildParams::very_slow_build()
        } else {
            BvhBuildParams::medium_build()
        };
        Self { tree: WideBvh::new(&triangles, params), triangles }
    }
}

impl RayQuery for Bvh {
    fn occluded(&self, from: Vec3, to: Vec3) -> bool {
        let d = nudge(Vec3A::from(to - from));
        self.tree.occluded(Vec3A::from(from), d, SEGMENT_MARGIN, 1.0 - SEGMENT_MARGIN)
    }

    fn closest_hit(&self, origin: Vec3, direction: Vec3, t_max: f32) -> Option<Hit> {
        let (origin, direction) = (Vec3A::from(origin), nudge(Vec3A::from(direction)));
        // Hits at t > 0 only: the smallest positive float is the first distance allowed.
        let (t, triangle) = self.tree.closest(origin, direction, f32::MIN_POSITIVE, t_max)?;
        let (u, v) = barycentric(&self.triangles[triangle as usize], origin + direction * t);
        Some(Hit { t, triangle, u, v })
    }

    fn triangle_count(&self) -> usize {
        self.triangles.len()
    }
}

/// Tests every triangle for every ray with obvhs's own triangle test: slow, obviously
/// correct; the reference for tests.
pub struct BruteForce {
    triangles: Vec<Triangle>,
    /// The same triangles with edges and normal precomputed (obvhs's `RtTriangle`).
    rt: Vec<RtTriangle>,
}

impl BruteForce {
    /// Stores the triangles.
    pub fn new(triangles: &[[Vec3; 3]]) -> Self {
        let triangles = to_triangles(triangles);
        let rt = triangles.iter().map(RtTriangle::from).collect();
        Self { triangles, rt }
    }
}

impl RayQuery for BruteForce {
    fn occluded(&self, from: Vec3, to: Vec3) -> bool {
        let ray = segment_ray(from, to);
        self.rt.iter().any(|t| t.intersect(&ray).is_finite())
    }

    fn closest_hit(&self, origin: Vec3, direction: Vec3, t_max: f32) -> Option<Hit> {
        let ray = Ray::new(Vec3A::from(origin), Vec3A::from(direction), 0.0, t_max);
        let (i, t) = self
            .triangles
            .iter()
            .enumerate()
            .map(|(i, tri)| (i, tri.intersect(&ray)))
            .filter(|(_, t)| t.is_finite() && *t > 0.0)
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        let (u, v) = barycentric(&self.triangles[i], ray.origin + ray.direction * t);
        Some(Hit { t, triangle: i as u32, u, v })
    }

    fn triangle_count(&self) -> usize {
        self.triangles.len()
    }
}

/// Uniform numbers in [0, 1) from a seeded xorshift64 stream (24 bits each): the tests'
/// random triangles and segments.
#[cfg(test)]
pub(crate) fn test_uniforms(seed: u64) -> impl FnMut() -> f32 {
    let mut rng = radiosity_core::random::XorShift64::new(seed);
    move || rng.next_f32()
}

#[cfg(test)]
mod tests {
    use super::*;

    use radiosity_core::random::XorShift64;

    fn random_point(rng: &mut XorShift64) -> Vec3 {
        Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 10.0
    }

    fn random_scene(rng: &mut XorShift64, n: usize) -> Vec<[Vec3; 3]> {
        (0..n)
            .map(|_| {
                let c = random_point(rng);
                [c, c + (random_point(rng) - 5.0) * 0.3, c + (random_point(rng) - 5.0) * 0.3]
            })
            .collect()
    }

    #[test]
    fn bvh_agrees_with_brute_force() {
        let mut rng = XorShift64::new(0x9e3779b97f4a7c15);
        let tris = random_scene(&mut rng, 500);
        let (bvh, brute, candidates) =
            (Bvh::new(&tris), BruteForce::new(&tris), CandidateTriangles::new(&tris));
        let all: Vec<u32> = (0..tris.len() as u32).collect();
        let mut blocked = 0;
        for _ in 0..4000 {
            let (a, b) = (random_point(&mut rng), random_point(&mut rng));
            let expected = brute.occluded(a, b);
            assert_eq!(bvh.occluded(a, b), expected, "segment {a} -> {b}");
            // The candidate-list path on every triangle gives the same answer.
            assert_eq!(candidates.occluded_by(a, b, &all), expected, "segment {a} -> {b}");
            blocked += usize::from(expected);
            let (h1, h2) = (bvh.closest_hit(a, b - a, 1.0), brute.closest_hit(a, b - a, 1.0));
            assert_eq!(h1.map(|h| h.triangle), h2.map(|h| h.triangle));
            if let (Some(h1), Some(h2)) = (h1, h2) {
                assert!((h1.t - h2.t).abs() < 1e-5);
            }
        }
        // Both outcomes must be exercised for the comparison to mean anything.
        assert!(blocked > 400 && blocked < 3600, "blocked {blocked}");
    }

    /// Above `BEST_BUILD_LIMIT` the other build preset answers the same.
    #[test]
    fn a_large_bvh_agrees_with_brute_force() {
        let mut rng = XorShift64::new(0x2545_f491_4f6c_dd1d);
        let tris: Vec<[Vec3; 3]> = random_scene(&mut rng, BEST_BUILD_LIMIT + 1000)
            .into_iter()
            .map(|t| [t[0], t[0] + (t[1] - t[0]) * 0.04, t[0] + (t[2] - t[0]) * 0.04])
            .collect();
        let (bvh, brute) = (Bvh::new(&tris), BruteForce::new(&tris));
        let mut blocked = 0;
        for _ in 0..400 {
            let (a, b) = (random_point(&mut rng), random_point(&mut rng));
            let expected = brute.occluded(a, b);
            assert_eq!(bvh.occluded(a, b), expected, "segment {a} -> {b}");
            blocked += usize::from(expected);
        }
        assert!(blocked > 40 && blocked < 360, "blocked {blocked}");
    }

    #[test]
    fn axis_aligned_rays_hit_axis_aligned_walls() {
        // A unit room: flat node boxes and rays with zero direction components.
        let mut tris = Vec::new();
        for axis in 0..3 {
            for side in [0.0, 1.0] {
                let p = |a: f32, b: f32| {
                    let mut v = [0.0; 3];
                    v[axis] = side;
                    v[(axis + 1) % 3] = a;
                    v[(axis + 2) % 3] = b;
                    Vec3::from(v)
                };
                tris.push([p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0)]);
                tris.push([p(0.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)]);
            }
        }
        let (bvh, brute) = (Bvh::new(&tris), BruteForce::new(&tris));
        let c = Vec3::new(0.3, 0.6, 0.45);
        for d in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z, Vec3::new(1.0, 1.0, 0.0)] {
            let (h, r) = (bvh.closest_hit(c, d, 10.0).unwrap(), brute.closest_hit(c, d, 10.0).unwrap());
            assert!((h.t - r.t).abs() < 1e-5, "{d}: {} vs {}", h.t, r.t);
            assert!(bvh.occluded(c, c + d * 3.0));
        }
    }

    #[test]
    fn barycentrics_locate_the_hit() {
        let tri = [[Vec3::ZERO, Vec3::X, Vec3::Y]];
        let bvh = Bvh::new(&tri);
        let h = bvh.closest_hit(Vec3::new(0.2, 0.3, 1.0), -Vec3::Z, 10.0).unwrap();
        assert!((h.t - 1.0).abs() < 1e-6);
        assert!((h.u - 0.2).abs() < 1e-6 && (h.v - 0.3).abs() < 1e-6);
    }

    /// A triangle too large for single-precision dot products still gives a hit with
    /// barycentrics in range, not a panic.
    #[test]
    fn a_huge_triangle_hits_without_panicking() {
        let tri = [[Vec3::new(-1e18, -1e18, 0.0), Vec3::new(1e18, -1e18, 0.0), Vec3::new(0.0, 1e18, 0.0)]];
        let h = Bvh::new(&tri).closest_hit(Vec3::new(1.0, 2.0, 5.0), -Vec3::Z, 10.0).unwrap();
        assert!((h.t - 5.0).abs() < 1e-5);
        assert!((0.0..=1.0).contains(&h.u) && (0.0..=1.0 - h.u).contains(&h.v), "{h:?}");
    }

    #[test]
    fn segment_ends_on_a_surface_are_not_blocked_by_it() {
        let quad = [[Vec3::ZERO, Vec3::X, Vec3::Y], [Vec3::X, Vec3::ONE.with_z(0.0), Vec3::Y]];
        let bvh = Bvh::new(&quad);
        assert!(!bvh.occluded(Vec3::new(0.5, 0.5, 1.0), Vec3::new(0.5, 0.5, 0.0)));
        assert!(bvh.occluded(Vec3::new(0.5, 0.5, 1.0), Vec3::new(0.5, 0.5, -1.0)));
        assert!(!Bvh::new(&[]).occluded(Vec3::ZERO, Vec3::ONE));
    }
}
