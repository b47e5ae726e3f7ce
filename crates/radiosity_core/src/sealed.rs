//! Closed models lit from outside.
//!
//! A model's faces that close up into one consistently wound surface (every edge shared by
//! exactly two faces, which run along it in opposite directions) enclose a space that no
//! light from outside reaches: every face blocks light from either side. When no emitter
//! lies in that space, the back faces of such a two-sided object face darkness only, so
//! meshing them doubles the object's elements to solve for nothing but the light that ray
//! offsets let through. Such objects are made one-sided: half the elements of a watertight
//! scan or CAD part, and an inside that is exactly dark.
//!
//! Which side of the surface an emitter lies on is found by rays from points just in front
//! of it: the first face a ray meets shows it its front or its back; a ray that meets none
//! is outside, which is the front for a surface wound outwards (positive enclosed volume)
//! and the back for one wound inwards (a room).

use std::collections::HashMap;

use glam::DVec3;

use crate::planar::{bounds, key};
use crate::scene::{Polygon, Scene, Shape, Sides};

/// Emitter points tested against each closed object, spread over the emitters.
const MAX_EMITTER_POINTS: usize = 32;

/// Directions of the rays cast from each emitter point (normalised where used), off the axes
/// and diagonals a model is built along; a majority decides, so that one ray that slips along
/// an edge cannot.
const DIRECTIONS: [DVec3; 3] = [
    DVec3::new(0.5377, 0.7093, 0.4597),
    DVec3::new(-0.6123, 0.2211, -0.7591),
    DVec3::new(0.1489, -0.9311, 0.3331),
];

/// Makes one-sided every two-sided, non-emitting object of `scene` whose faces close up into
/// one consistently wound surface with no emitter on its back side; returns their indices.
pub fn seal_closed_objects(scene: &mut Scene) -> Vec<usize> {
    let points = emitter_points(scene);
    let mut sealed = Vec::new();
    for (i, o) in scene.objects.iter_mut().enumerate() {
        let polygons = match &o.shape {
            Shape::Polygons(ps) => &ps[..],
            Shape::Mesh(m) => m.polygons(),
            Shape::Sphere(_) => continue,
        };
        let two_sided = matches!(o.sides, Sides::Two { .. });
        if two_sided && !scene.materials[o.material].is_emitter() && is_closed(polygons) {
            let surface = Closed::new(polygons);
            if points.iter().all(|&p| !surface.behind(p)) {
                o.sides = Sides::One;
                sealed.push(i);
            }
        }
    }
    sealed
}

/// Whether every edge of `polygons` is run along once in each direction (by exact corner
/// positions, as a model's faces share its vertices).
fn is_closed(polygons: &[Polygon]) -> bool {
    let mut runs: HashMap<([u64; 3], [u64; 3]), u32> = HashMap::new();
    for p in polygons {
        let v = p.vertices();
        for k in 0..v.len() {
            *runs.entry((key(v[k]), key(v[(k + 1) % v.len()]))).or_insert(0) += 1;
        }
    }
    !runs.is_empty() && runs.iter().all(|(&(a, b), &n)| n == 1 && runs.get(&(b, a)) == Some(&1))
}

/// Points just in front of the scene's emitters (and behind those that emit from both
/// sides), at most [`MAX_EMITTER_POINTS`], spread over every emitting polygon in turn.
fn emitter_points(scene: &Scene) -> Vec<DVec3> {
    let (lo, hi) = scene.bounds();
    let step = 1e-6 * lo.distance(hi).max(f64::MIN_POSITIVE);
    let mut points = Vec::new();
    for o in scene.objects.iter().filter(|o| scene.materials[o.material].is_emitter()) {
        let both = matches!(o.sides, Sides::Two { emits_back: true });
        match &o.shape {
            Shape::Sphere(s) => {
                // Light leaves the outside of a ball and the inside of a dome.
                let out = if s.facing == crate::scene::Facing::Outward { 1.0 + 1e-6 } else { 0.0 };
                points.push(s.center + DVec3::Y * (s.radius * out));
            }
            Shape::Polygons(ps) => push_fronts(&mut points, ps, both, step),
            Shape::Mesh(m) => push_fronts(&mut points, m.polygons(), both, step),
        }
    }
    if points.len() > MAX_EMITTER_POINTS {
        let stride = points.len().div_ceil(MAX_EMITTER_POINTS);
        points = points.into_iter().step_by(stride).collect();
    }
    points
}

fn push_fronts(points: &mut Vec<DVec3>, polygons: &[Polygon], both: bool, step: f64) {
    // A mesh lamp of thousands of facets: a spread of them is enough to place it.
    let stride = polygons.len().div_ceil(MAX_EMITTER_POINTS).max(1);
    for p in polygons.iter().step_by(stride) {
        let v = p.vertices();
        let centre = v.iter().sum::<DVec3>() / v.len() as f64;
        points.push(centre + p.normal() * step);
        if both {
            points.push(centre - p.normal() * step);
        }
    }
}

/// A closed surface as triangles with their lit-side normals.
struct Closed {
    triangles: Vec<([DVec3; 3], DVec3)>,
    lo: DVec3,
    hi: DVec3,
    /// Wound outwards: the unbounded outside is its front.
    outward: bool,
}

impl Closed {
    fn new(polygons: &[Polygon]) -> Self {
        let mut triangles = Vec::new();
        let mut volume = 0.0;
        for p in polygons {
            let v = p.vertices();
            for i in 1..v.len() - 1 {
                triangles.push(([v[0], v[i], v[i + 1]], p.normal()));
                // Divergence theorem: Σ v0 · (v1 × v2) / 6 over a closed surface's triangles.
                volume += v[0].dot(v[i].cross(v[i + 1])) / 6.0;
            }
        }
        let (lo, hi) =
            bounds(&polygons.iter().flat_map(|p| p.vertices().iter().copied()).collect::<Vec<_>>());
        Self { triangles, lo, hi, outward: volume > 0.0 }
    }

    /// Whether `p` lies on the back side of the surface, by a majority of [`DIRECTIONS`].
    fn behind(&self, p: DVec3) -> bool {
        DIRECTIONS.iter().filter(|&&d| self.first_side_met(p, d)).count() >= 2
    }

    /// Whether a ray from `p` along `d` first meets a face from behind (or, meeting none,
    /// leaves through the side the outside is).
    fn first_side_met(&self, p: DVec3, d: DVec3) -> bool {
        let d = d.normalize();
        if !self.ray_meets_box(p, d) {
            return !self.outward;
        }
        let mut nearest = (f64::INFINITY, false);
        for (t, n) in &self.triangles {
            if let Some(s) = ray_triangle(p, d, t)
                && s < nearest.0
            {
                nearest = (s, n.dot(d) > 0.0);
            }
        }
        if nearest.0.is_finite() { nearest.1 } else { !self.outward }
    }

    fn ray_meets_box(&self, p: DVec3, d: DVec3) -> bool {
        let inv = d.recip();
        let (a, b) = ((self.lo - p) * inv, (self.hi - p) * inv);
        let (near, far) = (a.min(b).max_element(), a.max(b).min_element());
        far >= near.max(0.0)
    }
}

/// The distance along unit `d` from `p` to triangle `t`, if the ray meets it ahead
/// (Möller & Trumbore 1997).
fn ray_triangle(p: DVec3, d: DVec3, t: &[DVec3; 3]) -> Option<f64> {
    let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
    let h = d.cross(e2);
    let det = e1.dot(h);
    if det.abs() < 1e-300 {
        return None;
    }
    let s = p - t[0];
    let u = s.dot(h) / det;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = d.dot(q) / det;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let dist = e2.dot(q) / det;
    (dist > 0.0).then_some(dist)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Facing, Material, Object, PolygonMesh, Sphere};
    use crate::{Rgb, box_faces};

    fn lamp(at: DVec3, down: bool) -> Object {
        let mut v: Vec<DVec3> = [(-0.1, -0.1), (0.1, -0.1), (0.1, 0.1), (-0.1, 0.1)]
            .iter()
            .map(|&(x, z)| at + DVec3::new(x, 0.0, z))
            .collect();
        // This order faces down: (+x) × (+x +z) = −y.
        if !down {
            v.reverse();
        }
        Object {
            name: "lamp".into(),
            material: 0,
            shape: Shape::Polygons(vec![Polygon::try_new(v).unwrap()]),
            sides: Sides::One,
        }
    }

    fn boxed(normals: Facing, faces_as_mesh: bool) -> Object {
        let faces = box_faces(DVec3::ZERO, DVec3::ONE, normals, 0.0).unwrap();
        let shape = if faces_as_mesh {
            // Shared vertices, as a model file gives them.
            let mut positions: Vec<DVec3> = Vec::new();
            let mut index = |q: DVec3| match positions.iter().position(|&p| p == q) {
                Some(i) => i as u32,
                None => {
                    positions.push(q);
                    (positions.len() - 1) as u32
                }
            };
            let faces: Vec<Vec<u32>> =
                faces.iter().map(|f| f.vertices().iter().map(|&q| index(q)).collect()).collect();
            Shape::Mesh(PolygonMesh::try_new(positions, faces).unwrap())
        } else {
            Shape::Polygons(faces)
        };
        Object { name: "box".into(), material: 1, shape, sides: Sides::Two { emits_back: false } }
    }

    fn scene(objects: Vec<Object>) -> Scene {
        let materials = vec![
            Material::try_new("light", Rgb::ZERO, Rgb::splat(1.0)).unwrap(),
            Material::try_new("white", Rgb::splat(0.5), Rgb::ZERO).unwrap(),
        ];
        Scene::try_new("sealed", None, materials, objects).unwrap()
    }

    #[test]
    fn a_closed_box_lit_from_outside_is_sealed() {
        for as_mesh in [false, true] {
            let mut s = scene(vec![lamp(DVec3::new(0.5, 3.0, 0.5), true), boxed(Facing::Outward, as_mesh)]);
            assert_eq!(seal_closed_objects(&mut s), vec![1], "mesh: {as_mesh}");
            assert_eq!(s.objects[1].sides, Sides::One);
        }
    }

    /// A lamp inside a box wound outwards lights its back faces: they stay.
    #[test]
    fn a_box_with_its_lamp_inside_keeps_both_sides() {
        let mut s = scene(vec![lamp(DVec3::new(0.5, 0.9, 0.5), true), boxed(Facing::Outward, true)]);
        assert!(seal_closed_objects(&mut s).is_empty());
        assert_eq!(s.objects[1].sides, Sides::Two { emits_back: false });
    }

    /// A room wound inwards with its lamp inside: its outside is its back, which no light
    /// reaches. With a lamp outside it instead, the back stays.
    #[test]
    fn a_room_wound_inwards_is_sealed_with_its_lamp_inside_only() {
        let mut s = scene(vec![lamp(DVec3::new(0.5, 0.9, 0.5), true), boxed(Facing::Inward, true)]);
        assert_eq!(seal_closed_objects(&mut s), vec![1]);
        let mut s = scene(vec![lamp(DVec3::new(0.5, 3.0, 0.5), true), boxed(Facing::Inward, true)]);
        assert!(seal_closed_objects(&mut s).is_empty());
    }

    /// A box without its top, or with one face turned over, is not closed.
    #[test]
    fn an_open_or_inconsistent_box_keeps_both_sides() {
        let open = |drop: usize, flip: bool| {
            let mut faces = box_faces(DVec3::ZERO, DVec3::ONE, Facing::Outward, 0.0).unwrap();
            if flip {
                let v: Vec<DVec3> = faces[drop].vertices().iter().rev().copied().collect();
                faces[drop] = Polygon::try_new(v).unwrap();
            } else {
                faces.remove(drop);
            }
            let mut o = boxed(Facing::Outward, false);
            o.shape = Shape::Polygons(faces);
            scene(vec![lamp(DVec3::new(0.5, 3.0, 0.5), true), o])
        };
        for flip in [false, true] {
            assert!(seal_closed_objects(&mut open(2, flip)).is_empty(), "flipped: {flip}");
        }
    }

    /// Emitters, one-sided objects and balls are left as they are.
    #[test]
    fn only_two_sided_reflecting_models_are_sealed() {
        let mut glowing = boxed(Facing::Outward, true);
        glowing.material = 0;
        let mut one = boxed(Facing::Outward, true);
        one.sides = Sides::One;
        let ball = Object {
            name: "ball".into(),
            material: 1,
            shape: Shape::Sphere(Sphere::try_new(DVec3::splat(5.0), 1.0, Facing::Outward).unwrap()),
            sides: Sides::Two { emits_back: false },
        };
        let mut s = scene(vec![lamp(DVec3::new(0.5, 3.0, 0.5), true), glowing, one, ball]);
        assert!(seal_closed_objects(&mut s).is_empty());
    }
}
