//! Segments against short candidate lists: the solver's production visibility path.
//!
//! The solver's shaft culling (Haines & Wallace 1991) finds, once per shooter and receiving
//! patch, the few triangles that can block any segment between the two; each of the pair's
//! rays then tests only those, four rays at once against each triangle in the four
//! single-precision lanes of an SSE register (glam's `Vec4`), instead of walking a tree.
//! The lane arithmetic is the crate's one triangle test ([`crate::lanes`]), so on a list
//! that holds every triangle a segment could meet, the answer is [`crate::BruteForce`]'s and
//! [`crate::Bvh`]'s, bit for bit.

use glam::{Vec3, Vec3A, Vec4};
use obvhs::rt_triangle::RtTriangle;

use crate::lanes::{Lanes3, RayLanes, TriangleLanes, hit_x4};
use crate::{SEGMENT_MARGIN, nudge, to_triangles};

/// Up to four segments in structure-of-arrays form: lane `i` is segment `i`.
#[derive(Clone, Copy, Debug)]
pub struct Segments4 {
    lanes: RayLanes,
    /// Lanes that hold a segment.
    live: u32,
}

impl Segments4 {
    /// The segments `from[i] → to[i]` for `i < count` (at most four); other lanes are empty.
    pub fn new(from: &[Vec3; 4], to: &[Vec3; 4], count: usize) -> Self {
        let count = count.min(4);
        let (mut o, mut e) = ([[0.0f32; 4]; 3], [[0.0f32; 4]; 3]);
        for i in 0..count {
            for axis in 0..3 {
                o[axis][i] = from[i][axis];
                e[axis][i] = to[i][axis];
            }
        }
        let origin = o.map(Vec4::from_array);
        let d = [0, 1, 2].map(|a| Vec4::from_array(e[a]) - origin[a]);
        // The one-ray test's direction, nudged the same way (see `nudge`), in the lanes:
        // components below 1e-7 of the largest take that size with their own sign.
        let eps = d[0].abs().max(d[1].abs()).max(d[2].abs()) * 1e-7;
        let direction = d.map(|c| Vec4::select(c.abs().cmplt(eps), eps.copysign(c + Vec4::ZERO), c));
        Self { lanes: RayLanes { origin, direction }, live: (1u32 << count) - 1 }
    }

    /// Bit `i` set for each lane that holds a segment.
    pub fn live(&self) -> u32 {
        self.live
    }
}

/// A fixed set of triangles whose segment tests go through short lists of their indices
/// (candidate lists), not a tree: the solver's production path for receiver–shooter pairs
/// that shaft culling narrowed to a few triangles. Two-sided, with [`crate::RayQuery`]'s
/// segment margins.
pub struct CandidateTriangles {
    /// Each triangle in the test's precomputed form (`RtTriangle`'s edges and normal).
    rt: Vec<RtTriangle>,
}

/// x, y, z of `v`, each in all four lanes.
fn splat(v: Vec3A) -> Lanes3 {
    [Vec4::splat(v.x), Vec4::splat(v.y), Vec4::splat(v.z)]
}

impl CandidateTriangles {
    /// Stores the triangles; candidate lists index into this slice.
    pub fn new(triangles: &[[Vec3; 3]]) -> Self {
        Self { rt: to_triangles(triangles).iter().map(RtTriangle::from).collect() }
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.rt.len()
    }

    /// Triangle `i` in every lane.
    fn lanes(&self, i: u32) -> TriangleLanes {
        let tri = &self.rt[i as usize];
        TriangleLanes { v0: splat(tri.v0), ng: splat(tri.ng), e1: splat(tri.e1), e2: splat(tri.e2) }
    }

    /// [`crate::RayQuery::occluded`] against only the triangles at `indices`: the same ray
    /// and the same triangle test, so on a list that holds every triangle the segment could
    /// meet the answer is the full query's answer.
    pub fn occluded_by(&self, from: Vec3, to: Vec3, indices: &[u32]) -> bool {
        self.first_blocker(from, to, indices).is_some()
    }

    /// Like [`CandidateTriangles::occluded_by`], and says which entry of `indices` blocked:
    /// callers test that triangle first for the next, nearby segment (the last-occluder
    /// cache).
    pub fn first_blocker(&self, from: Vec3, to: Vec3, indices: &[u32]) -> Option<usize> {
        // The one ray in every lane, without the inverse direction (three divisions only the
        // tree's box tests need); lane 0's answer.
        let ray =
            RayLanes { origin: splat(Vec3A::from(from)), direction: splat(nudge(Vec3A::from(to - from))) };
        let (tmin, tmax) = (Vec4::splat(SEGMENT_MARGIN), Vec4::splat(1.0 - SEGMENT_MARGIN));
        indices.iter().position(|&i| hit_x4(&ray, &self.lanes(i), tmin, tmax, 1).1 != 0)
    }

    /// Which of `segments` some triangle at `indices` crosses (bit `i` for segment `i`):
    /// [`CandidateTriangles::occluded_by`] for four segments at once, with the same answers.
    ///
    /// The first triangle that blocks is moved to the front of `indices`: the next rays of
    /// the same receiver most likely meet it too, and a packet stops as soon as every live
    /// lane is blocked. The answer does not depend on the order.
    pub fn occluded_x4(&self, segments: &Segments4, indices: &mut [u32]) -> u32 {
        let (tmin, tmax) = (Vec4::splat(SEGMENT_MARGIN), Vec4::splat(1.0 - SEGMENT_MARGIN));
        let mut blocked = 0u32;
        let mut first = None;
        for (k, &i) in indices.iter().enumerate() {
            let (_, hit) = hit_x4(&segments.lanes, &self.lanes(i), tmin, tmax, segments.live & !blocked);
            if hit != 0 {
                first.get_or_insert(k);
                blocked |= hit;
                if blocked == segments.live {
                    break;
                }
            }
        }
        if let Some(k) = first {
            indices.swap(0, k);
        }
        blocked
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{BruteForce, RayQuery};

    /// A fan of small triangles and segments through and past them, some grazing edges, some
    /// axis-aligned (zero direction components go through `nudge`).
    fn fan(next: &mut impl FnMut() -> f32) -> Vec<[Vec3; 3]> {
        let mut tris = Vec::new();
        for _ in 0..40 {
            let c = Vec3::new(next(), next(), next()) * 4.0;
            let mut d = || Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5);
            tris.push([c, c + d(), c + d()]);
        }
        tris.push([Vec3::new(0.0, 0.0, 2.0), Vec3::new(4.0, 0.0, 2.0), Vec3::new(0.0, 4.0, 2.0)]);
        tris
    }

    #[test]
    fn four_lanes_answer_as_four_single_rays_and_as_the_reference() {
        let mut next = crate::test_uniforms(0x2545_f491_4f6c_dd1du64);
        let tris = fan(&mut next);
        let (candidates, brute) = (CandidateTriangles::new(&tris), BruteForce::new(&tris));
        let mut all: Vec<u32> = (0..tris.len() as u32).collect();
        let (mut blocked, mut clear) = (0, 0);
        for round in 0..500 {
            let count = 1 + round % 4;
            let mut from = [Vec3::ZERO; 4];
            let mut to = [Vec3::ZERO; 4];
            for i in 0..count {
                from[i] = Vec3::new(next(), next(), next()) * 4.0;
                to[i] = Vec3::new(next(), next(), next()) * 4.0;
                if round % 7 == 0 {
                    to[i] = from[i] + Vec3::Z * 3.0 * (next() - 0.5);
                }
            }
            let mask = candidates.occluded_x4(&Segments4::new(&from, &to, count), &mut all);
            assert_eq!(mask >> count, 0, "lanes past the count stay clear");
            for i in 0..count {
                let one = candidates.occluded_by(from[i], to[i], &all);
                assert_eq!(mask >> i & 1 == 1, one, "round {round}, lane {i}");
                assert_eq!(brute.occluded(from[i], to[i]), one, "round {round}, lane {i}");
                if one {
                    blocked += 1;
                } else {
                    clear += 1;
                }
            }
        }
        assert!(blocked > 100 && clear > 100, "blocked {blocked}, clear {clear}");
    }

    /// The first blocker is an entry of the list that blocks, and the blocker moved to the
    /// front of the list is one that blocks.
    #[test]
    fn the_first_blocker_blocks_and_moves_to_the_front() {
        let tris = [
            [Vec3::new(5.0, 5.0, 0.5), Vec3::new(6.0, 5.0, 0.5), Vec3::new(5.0, 6.0, 0.5)], // off the path
            [Vec3::new(-1.0, -1.0, 0.5), Vec3::new(2.0, -1.0, 0.5), Vec3::new(-1.0, 2.0, 0.5)],
        ];
        let candidates = CandidateTriangles::new(&tris);
        let (from, to) = (Vec3::new(0.2, 0.2, 1.0), Vec3::new(0.2, 0.2, 0.0));
        assert_eq!(candidates.first_blocker(from, to, &[0, 1]), Some(1));
        assert_eq!(candidates.first_blocker(from, to, &[0]), None);
        let mut list = [0, 1];
        assert_eq!(candidates.occluded_x4(&Segments4::new(&[from; 4], &[to; 4], 2), &mut list), 0b11);
        assert_eq!(list, [1, 0]);
    }

    #[test]
    fn an_empty_packet_or_list_blocks_nothing() {
        let candidates = CandidateTriangles::new(&[[Vec3::ZERO, Vec3::X, Vec3::Y]]);
        let through = Segments4::new(&[Vec3::new(0.2, 0.2, 1.0); 4], &[Vec3::new(0.2, 0.2, -1.0); 4], 4);
        assert_eq!(candidates.occluded_x4(&through, &mut [0]), 0b1111);
        assert_eq!(candidates.occluded_x4(&through, &mut []), 0);
        let none = Segments4::new(&[Vec3::new(0.2, 0.2, 1.0); 4], &[Vec3::new(0.2, 0.2, -1.0); 4], 0);
        assert_eq!(candidates.occluded_x4(&none, &mut [0]), 0);
        assert_eq!(candidates.triangle_count(), 1);
    }
}
