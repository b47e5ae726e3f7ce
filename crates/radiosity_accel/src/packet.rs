//! Four segments at once against a short list of triangles.
//!
//! A receiver's visibility rays all go to the same shooter through the same few candidate
//! triangles (the solver's shaft culling), so each triangle is tested against the four rays
//! side by side in the four single-precision lanes of an SSE register (glam's `Vec4`). The
//! lane arithmetic is [`BruteForce::first_blocker`]'s, operation for operation (products
//! are commutative and every dot product sums x, y, then z), so each lane's answer is that
//! of the one-ray test bit for bit.

use glam::{Vec3, Vec3A, Vec4};

use crate::{BruteForce, SEGMENT_MARGIN};

/// Up to four segments in structure-of-arrays form: lane `i` is segment `i`.
#[derive(Clone, Copy, Debug)]
pub struct Segments4 {
    origin: [Vec4; 3],
    direction: [Vec4; 3],
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
        Self { origin, direction, live: (1u32 << count) - 1 }
    }

    /// Bit `i` set for each lane that holds a segment.
    pub fn live(&self) -> u32 {
        self.live
    }
}

impl BruteForce {
    /// Which of `segments` some triangle at `indices` crosses (bit `i` for segment `i`):
    /// [`BruteForce::occluded_by`] for four segments at once, with the same answers.
    ///
    /// The first triangle that blocks is moved to the front of `indices`: the next rays of
    /// the same receiver most likely meet it too, and a packet stops as soon as every live
    /// lane is blocked. The answer does not depend on the order.
    pub fn occluded_x4(&self, segments: &Segments4, indices: &mut [u32]) -> u32 {
        let [ox, oy, oz] = segments.origin;
        let [dx, dy, dz] = segments.direction;
        let (tmin, tmax) = (Vec4::splat(SEGMENT_MARGIN), Vec4::splat(1.0 - SEGMENT_MARGIN));
        let mut blocked = 0u32;
        let mut first = None;
        for (k, &i) in indices.iter().enumerate() {
            let tri = &self.rt[i as usize];
            let s = |v: Vec3A| (Vec4::splat(v.x), Vec4::splat(v.y), Vec4::splat(v.z));
            let ((v0x, v0y, v0z), (e1x, e1y, e1z)) = (s(tri.v0), s(tri.e1));
            let ((e2x, e2y, e2z), (nx, ny, nz)) = (s(tri.e2), s(tri.ng));
            // c = v0 − o, the distance to the triangle's plane first: most candidates lie
            // where the segments do not reach their plane, and those skip the edge tests.
            let (cx, cy, cz) = (v0x - ox, v0y - oy, v0z - oz);
            let inv_det = Vec4::ONE / (nx * dx + ny * dy + nz * dz);
            let t = (nx * cx + ny * cy + nz * cz) * inv_det;
            let reach = t.cmpge(tmin).bitmask() & t.cmple(tmax).bitmask() & segments.live & !blocked;
            if reach == 0 {
                continue;
            }
            // r = d × c and the edge coordinates, as in the one-ray test.
            let (rx, ry, rz) = (dy * cz - dz * cy, dz * cx - dx * cz, dx * cy - dy * cx);
            let u = (rx * e2x + ry * e2y + rz * e2z) * inv_det;
            let v = (rx * e1x + ry * e1y + rz * e1z) * inv_det;
            let w = Vec4::ONE - u - v;
            // u, v, w all non-negative (sign bits clear, as the one-ray test reads them).
            let inside = !(u.is_negative_bitmask() | v.is_negative_bitmask() | w.is_negative_bitmask());
            let hit = inside & inv_det.cmpne(Vec4::ZERO).bitmask() & reach;
            if hit & !blocked != 0 {
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

    #[test]
    fn four_lanes_answer_as_four_single_rays() {
        // A fan of small triangles and segments through and past them, some grazing edges.
        let mut next = crate::test_uniforms(0x2545_f491_4f6c_dd1du64);
        let mut tris = Vec::new();
        for _ in 0..40 {
            let c = Vec3::new(next(), next(), next()) * 4.0;
            let d = |n: &mut dyn FnMut() -> f32| Vec3::new(n() - 0.5, n() - 0.5, n() - 0.5);
            tris.push([c, c + d(&mut next), c + d(&mut next)]);
        }
        // Axis-aligned pieces too: zero direction components go through `nudge`.
        tris.push([Vec3::new(0.0, 0.0, 2.0), Vec3::new(4.0, 0.0, 2.0), Vec3::new(0.0, 4.0, 2.0)]);
        let brute = BruteForce::new(&tris);
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
            let mask = brute.occluded_x4(&Segments4::new(&from, &to, count), &mut all);
            assert_eq!(mask >> count, 0, "lanes past the count stay clear");
            for i in 0..count {
                let one = brute.occluded_by(from[i], to[i], &all);
                assert_eq!(mask >> i & 1 == 1, one, "round {round}, lane {i}");
                if one {
                    blocked += 1;
                } else {
                    clear += 1;
                }
            }
        }
        assert!(blocked > 100 && clear > 100, "blocked {blocked}, clear {clear}");
    }

    #[test]
    fn an_empty_packet_or_list_blocks_nothing() {
        let brute = BruteForce::new(&[[Vec3::ZERO, Vec3::X, Vec3::Y]]);
        let through = Segments4::new(&[Vec3::new(0.2, 0.2, 1.0); 4], &[Vec3::new(0.2, 0.2, -1.0); 4], 4);
        assert_eq!(brute.occluded_x4(&through, &mut [0]), 0b1111);
        assert_eq!(brute.occluded_x4(&through, &mut []), 0);
        let none = Segments4::new(&[Vec3::new(0.2, 0.2, 1.0); 4], &[Vec3::new(0.2, 0.2, -1.0); 4], 0);
        assert_eq!(brute.occluded_x4(&none, &mut [0]), 0);
    }
}
