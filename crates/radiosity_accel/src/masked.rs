//! Ray queries over triangles some of which are alpha-masked (leaves, chains, fences): a ray
//! that meets a masked triangle where its mask is clear goes on through it.
//!
//! The solid triangles keep their own tree and its any-hit shadow test untouched; the masked
//! ones are a second tree walked hit after hit, nearest first, until a hit the caller's test
//! calls opaque. A shadow ray is blocked when either tree stops it; a closest hit is the
//! nearer of the solid tree's hit and the first opaque masked hit before it.

use glam::{Vec3, Vec3A};

use crate::wide::WideBvh;
use crate::{BEST_BUILD_LIMIT, Hit, RayQuery, SEGMENT_MARGIN, barycentric, nudge, to_triangles};
use obvhs::BvhBuildParams;
use obvhs::triangle::Triangle;

/// Whether a ray passes masked triangle `k` (its place among the masked triangles given to
/// [`MaskedBvh::new`]) at barycentric weights `(u, v)` of its second and third corners.
pub type ClearTest = Box<dyn Fn(usize, f32, f32) -> bool + Send + Sync>;

/// One tree of triangles with the caller's indices of them.
struct Part {
    tree: WideBvh,
    triangles: Vec<Triangle>,
    ids: Vec<u32>,
}

impl Part {
    fn new(all: &[[Vec3; 3]], ids: Vec<u32>) -> Self {
        let tris: Vec<[Vec3; 3]> = ids.iter().map(|&i| all[i as usize]).collect();
        let triangles = to_triangles(&tris);
        let params = if triangles.len() <= BEST_BUILD_LIMIT {
            BvhBuildParams::very_slow_build()
        } else {
            BvhBuildParams::medium_build()
        };
        Self { tree: WideBvh::new(&triangles, params), triangles, ids }
    }

    fn hit(&self, origin: Vec3A, direction: Vec3A, (t, k): (f32, u32)) -> Hit {
        let (u, v) = barycentric(&self.triangles[k as usize], origin + direction * t);
        Hit { t, triangle: self.ids[k as usize], u, v }
    }
}

/// A [`RayQuery`] over solid and alpha-masked triangles.
pub struct MaskedBvh {
    solid: Part,
    masked: Part,
    clear: ClearTest,
}

impl MaskedBvh {
    /// The structure over `triangles`, of which those at the increasing indices `masked` are
    /// masked, with `clear` telling where a ray passes one of them.
    pub fn new(triangles: &[[Vec3; 3]], masked: &[u32], clear: ClearTest) -> Self {
        let mut is_masked = vec![false; triangles.len()];
        for &i in masked {
            is_masked[i as usize] = true;
        }
        let solid = (0..triangles.len() as u32).filter(|&i| !is_masked[i as usize]).collect();
        Self { solid: Part::new(triangles, solid), masked: Part::new(triangles, masked.to_vec()), clear }
    }

    /// The first masked hit in `(tmin, tmax]` that is opaque where the ray meets it.
    fn first_opaque(&self, origin: Vec3A, direction: Vec3A, mut tmin: f32, tmax: f32) -> Option<Hit> {
        // Each step starts at the float after the last hit (the tree's interval is closed
        // at tmin), so the walk ends: the distances only grow.
        while let Some(found) = self.masked.tree.closest(origin, direction, tmin, tmax) {
            let hit = self.masked.hit(origin, direction, found);
            if !(self.clear)(found.1 as usize, hit.u, hit.v) {
                return Some(hit);
            }
            if found.0 >= tmax {
                return None;
            }
            tmin = f32::from_bits(found.0.max(0.0).to_bits() + 1);
        }
        None
    }
}

impl RayQuery for MaskedBvh {
    fn occluded(&self, from: Vec3, to: Vec3) -> bool {
        let (from, d) = (Vec3A::from(from), nudge(Vec3A::from(to - from)));
        self.solid.tree.occluded(from, d, SEGMENT_MARGIN, 1.0 - SEGMENT_MARGIN)
            || self.first_opaque(from, d, SEGMENT_MARGIN, 1.0 - SEGMENT_MARGIN).is_some()
    }

    fn closest_hit(&self, origin: Vec3, direction: Vec3, t_max: f32) -> Option<Hit> {
        let (origin, direction) = (Vec3A::from(origin), nudge(Vec3A::from(direction)));
        let solid = self
            .solid
            .tree
            .closest(origin, direction, f32::MIN_POSITIVE, t_max)
            .map(|found| self.solid.hit(origin, direction, found));
        let reach = solid.map_or(t_max, |h| h.t);
        self.first_opaque(origin, direction, f32::MIN_POSITIVE, reach).or(solid)
    }

    fn triangle_count(&self) -> usize {
        self.solid.ids.len() + self.masked.ids.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Bvh;

    /// A unit square in the plane z = `z` as two triangles.
    fn square(z: f32) -> [[Vec3; 3]; 2] {
        let p = |x: f32, y: f32| Vec3::new(x, y, z);
        [[p(0.0, 0.0), p(1.0, 0.0), p(1.0, 1.0)], [p(0.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)]]
    }

    /// Two sheets at z = 1 (masked: clear where x < ½) and z = 2 (solid), and the same
    /// without the mask.
    fn scenes() -> (MaskedBvh, Bvh) {
        let tris: Vec<[Vec3; 3]> = square(1.0).into_iter().chain(square(2.0)).collect();
        // Triangle 0's corners (0,0), (1,0), (1,1): x = u + v; triangle 1's (0,0), (1,1),
        // (0,1): x = u.
        let clear: ClearTest = Box::new(|k, u, v| if k == 0 { u + v < 0.5 } else { u < 0.5 });
        (MaskedBvh::new(&tris, &[0, 1], clear), Bvh::new(&tris))
    }

    #[test]
    fn rays_pass_the_clear_half_and_stop_on_the_opaque_one() {
        let (masked, plain) = scenes();
        let up = Vec3::Z;
        for (x, y) in [(0.2, 0.1), (0.3, 0.8), (0.7, 0.2), (0.9, 0.6)] {
            let from = Vec3::new(x, y, 0.0);
            let hit = masked.closest_hit(from, up, 10.0).unwrap();
            let expected = if x < 0.5 { 2.0 } else { 1.0 };
            assert!((hit.t - expected).abs() < 1e-5, "({x}, {y}): {hit:?}");
            assert_eq!(hit.triangle >= 2, x < 0.5, "({x}, {y}): the caller's index of the sheet hit");
            // Up to the first sheet's far side: blocked only where it is opaque.
            assert_eq!(masked.occluded(from, Vec3::new(x, y, 1.5)), x >= 0.5, "({x}, {y})");
            assert!(plain.occluded(from, Vec3::new(x, y, 1.5)));
            assert!(masked.occluded(from, Vec3::new(x, y, 3.0)), "the solid sheet stops every ray");
        }
        assert_eq!(masked.triangle_count(), 4);
    }
}
