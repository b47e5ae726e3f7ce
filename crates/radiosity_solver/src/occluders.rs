//! Which triangles can block light between two surfaces, and a cheap test for segments that
//! none of them can block.
//!
//! A triangle whose plane has the whole scene on its front side (a wall, floor or ceiling of
//! a room, the faces of a furnace) can never cross a segment between two surface points: both
//! ends lie in the closed front half-space, so the segment does too. Dropping those leaves the
//! BVH with the furniture only (the Cornell box: 10 of 38 triangles), and a scene with nothing
//! else (furnace, two plates) needs no rays at all.

use std::sync::Arc;

use glam::{DVec3, Vec3};
use radiosity_accel::{Bvh, ClearTest, MaskedBvh, RayQuery};
use radiosity_mesh::Mesh;

/// Above this many (triangle × vertex) pairs the exact half-space scan is skipped for
/// triangles that the bounding-box test does not settle; they are kept (always correct).
const SCAN_BUDGET: usize = 50_000_000;

/// Most boxes in an [`OccluderBoxes`]; consecutive triangles are merged to stay under it.
const MAX_BOXES: usize = 64;

/// The occluder triangles of `mesh` that can block a ray between two points of its surfaces.
pub(crate) fn blocking_triangles(mesh: &Mesh) -> Vec<[DVec3; 3]> {
    split_triangles(mesh).0.iter().map(|&i| mesh.occluders[i]).collect()
}

/// The occluder triangles that [`occluder_triangles`] leaves out: those with every surface
/// point in front of them (a box room's walls). No ray between two surface points crosses
/// them, but a ray leaving the scene from inside a closed room (towards the sun) meets them.
pub fn hull_triangles(mesh: &Mesh) -> Vec<[Vec3; 3]> {
    split_triangles(mesh).1.iter().map(|&i| mesh.occluders[i].map(|p| p.as_vec3())).collect()
}

/// The indices of the occluder triangles that can block a ray between two surface points,
/// and of the rest. An alpha-masked triangle is always among the first: the hull's tree
/// knows no masks.
fn split_triangles(mesh: &Mesh) -> (Vec<usize>, Vec<usize>) {
    let (lo, hi) = mesh.bounds();
    let tolerance = 1e-7 * (hi - lo).length().max(f64::MIN_POSITIVE);
    let corners: Vec<DVec3> = (0..8)
        .map(|i| DVec3::new([lo.x, hi.x][i & 1], [lo.y, hi.y][(i >> 1) & 1], [lo.z, hi.z][i >> 2]))
        .collect();
    let points: Vec<DVec3> = mesh.occluders.iter().flatten().copied().collect();
    let scan = mesh.occluders.len().saturating_mul(points.len()) <= SCAN_BUDGET;
    let mut masked = vec![false; mesh.occluders.len()];
    for m in &mesh.masked_occluders {
        masked[m.occluder as usize] = true;
    }
    (0..mesh.occluders.len()).partition(|&i| {
        let t = &mesh.occluders[i];
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        if n.length_squared() == 0.0 || masked[i] {
            return true;
        }
        let n = n.normalize();
        let in_front = |p: &DVec3| n.dot(*p - t[0]) >= -tolerance;
        // Bounding-box corners in front settle axis-aligned walls at once; otherwise scan
        // every occluder vertex when that is affordable.
        let hull = corners.iter().all(in_front) || (scan && points.iter().all(in_front));
        !hull
    })
}

/// The blocking occluder triangles of a mesh in single precision, ready for a
/// [`radiosity_accel::RayQuery`] backend. Triangles that cannot block any ray between two
/// surface points (see the module notes) are left out.
pub fn occluder_triangles(mesh: &Mesh) -> Vec<[Vec3; 3]> {
    blocking_triangles(mesh).iter().map(|t| t.map(|p| p.as_vec3())).collect()
}

/// The ray structure over [`occluder_triangles`]: a [`Bvh`], or, when some are alpha-masked,
/// a [`MaskedBvh`] whose rays pass their clear texels.
pub fn occluder_queries(mesh: &Mesh) -> Arc<dyn RayQuery> {
    let (blocking, _) = split_triangles(mesh);
    let triangles: Vec<[Vec3; 3]> =
        blocking.iter().map(|&i| mesh.occluders[i].map(|p| p.as_vec3())).collect();
    if mesh.masked_occluders.is_empty() {
        return Arc::new(Bvh::new(&triangles));
    }
    // Masked occluders come in occluder order, as the blocking indices do.
    let mut masks = Vec::with_capacity(mesh.masked_occluders.len());
    let mut positions = Vec::with_capacity(mesh.masked_occluders.len());
    let mut next = mesh.masked_occluders.iter().peekable();
    for (k, &i) in blocking.iter().enumerate() {
        if let Some(m) = next.next_if(|m| m.occluder as usize == i) {
            masks.push(m.clone());
            positions.push(k as u32);
        }
    }
    let clear: ClearTest = Box::new(move |k, u, v| masks[k].clear_at(f64::from(u), f64::from(v)));
    Arc::new(MaskedBvh::new(&triangles, &positions, clear))
}

/// Bounding boxes around runs of blocking triangles: a segment whose bounding box meets none
/// of them cannot be blocked, so its ray need not be traced.
pub(crate) struct OccluderBoxes {
    boxes: Vec<(DVec3, DVec3)>,
}

impl OccluderBoxes {
    /// Boxes around runs of `tris` (the mesh's [`blocking_triangles`]).
    pub(crate) fn new(tris: &[[DVec3; 3]]) -> Self {
        let per_box = tris.len().div_ceil(MAX_BOXES).max(1);
        let boxes = tris
            .chunks(per_box)
            .map(|c| {
                c.iter()
                    .flatten()
                    .fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(a, b), p| {
                        (a.min(*p), b.max(*p))
                    })
            })
            .collect();
        Self { boxes }
    }

    /// True when some blocking triangle's box overlaps the box `[lo, hi]` (grown by `margin`).
    pub(crate) fn may_block(&self, lo: DVec3, hi: DVec3, margin: f64) -> bool {
        let (lo, hi) = (lo - DVec3::splat(margin), hi + DVec3::splat(margin));
        self.boxes.iter().any(|(a, b)| a.cmple(hi).all() && lo.cmple(*b).all())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiosity_scenes::{furnace_box, furnace_sphere, two_plates};

    #[test]
    fn enclosures_and_open_plates_have_no_blockers() {
        for scene in [furnace_box(0.5, 1.0), furnace_sphere(0.5, 1.0), two_plates(1.0, 1.0, 0.5, 1.0)] {
            let mesh = Mesh::build(&scene, &scene.mesh_params()).unwrap();
            assert!(occluder_triangles(&mesh).is_empty(), "{}", scene.name);
        }
    }

    #[test]
    fn a_block_inside_a_room_is_kept_and_the_walls_are_not() {
        let mut scene = furnace_box(0.5, 1.0);
        let block = radiosity_core::box_faces(
            DVec3::splat(0.4),
            DVec3::splat(0.6),
            radiosity_core::Facing::Outward,
            30.0,
        )
        .unwrap();
        scene.objects.push(radiosity_core::Object {
            name: "block".into(),
            material: 0,
            shape: radiosity_core::Shape::Polygons(block),
            sides: radiosity_core::Sides::One,
        });
        let mesh = Mesh::build(&scene, &scene.mesh_params()).unwrap();
        let kept = blocking_triangles(&mesh);
        assert_eq!(kept.len(), 12);
        assert!(kept.iter().flatten().all(|p| (p.y - 0.5).abs() <= 0.1 + 1e-9));
        let boxes = OccluderBoxes::new(&kept);
        assert!(boxes.may_block(DVec3::new(0.5, 0.0, 0.5), DVec3::new(0.5, 1.0, 0.5), 0.0));
        assert!(!boxes.may_block(DVec3::new(0.0, 0.0, 0.0), DVec3::new(0.1, 1.0, 0.1), 0.0));
    }
}
