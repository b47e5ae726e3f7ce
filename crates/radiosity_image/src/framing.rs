//! A camera for a scene that gives none: one that sees lit (front) faces.
//!
//! Framing the scene from a fixed side shows a closed room, or a model that opens towards
//! another side, from behind its walls: a black picture. Instead a few candidate views are
//! probed with a coarse grid of rays against the scene's own polygons and spheres, and the
//! view whose rays meet the most front faces wins: from outside on each side (the open side
//! of an open box), or from the middle looking along each horizontal axis (inside a closed
//! room), turned towards what stands in the room when it lies ahead. `render` and `view`
//! both take their default camera from here, so they agree.
//!
//! The back face of a two-sided object (every OBJ face, by default) counts, but less than a
//! front face: it is lit only where something lights it, and the outside of a room or of an
//! open box's walls is lit by nothing, so a view of it would be black.

use glam::DVec3;

use radiosity_core::{Camera, CameraRays, Facing, Polygon, Scene, Shape, Sides};

/// Probe rays per candidate view, across and down (a 4:3 picture).
const PROBE: (usize, usize) = (8, 6);

/// Field of view of a camera placed inside the scene, degrees: wide, as a room is seen.
const INSIDE_FOV_DEG: f64 = 75.0;

/// The scene's camera or, without one, a view that sees its lit faces: from outside on the
/// side that shows the most front faces (the open side of an open box), or from inside a
/// closed room (probed with a few dozen rays per candidate view).
pub fn camera_or_framing(scene: &Scene) -> Camera {
    scene.camera.unwrap_or_else(|| choose(scene))
}

/// The share of a coarse grid of rays through `camera` (48 of them) that first meet a lit
/// face: near 0 when the view looks at the backs of one-sided surfaces (a closed room from
/// outside) or at nothing, so that a black picture can be explained before it is made.
pub fn lit_share_seen_by(scene: &Scene, camera: &Camera) -> f64 {
    lit_share(scene, camera)
}

/// The camera [`camera_or_framing`] gives a scene without one.
fn choose(scene: &Scene) -> Camera {
    let (lo, hi) = scene.bounds();
    let framing = Camera::framing(lo, hi);
    let centre = (lo + hi) * 0.5;
    let mut candidates = vec![framing];
    for d in [-DVec3::Z, DVec3::X, -DVec3::X, -DVec3::Y, DVec3::Y] {
        // The framing view already looks along +z.
        let up = if d.y.abs() > 0.5 { DVec3::Z } else { DVec3::Y };
        candidates.push(Camera::fitting(lo, hi, d, up));
    }
    // From outside first: an open scene (a box without a front wall, a model on a plane) is
    // shown as a whole from its open side whenever some side shows enough front faces (the
    // backs of two-sided walls, seen from outside, are not enough: nothing lights them).
    let best_outside = best_of(scene, candidates, false);
    if best_outside.2 >= PROBE.0 * PROBE.1 / 4 {
        return best_outside.0;
    }
    // A closed room shows only the backs of its walls from outside: look from inside, at
    // mid-height, standing back from the middle towards one wall (as a photographer stands
    // to show a room), along each horizontal axis; the view that shows the most objects
    // wins (from the middle along +z, the generated furnished room showed a bare wall and
    // the sofa, and none of the models on the table).
    // Each view looks level, or at the room's contents when they stand ahead of it: a model
    // on the floor of a tall room is then in the middle of the picture, not cut off by its
    // bottom edge.
    let contents = contents_centre(scene, lo, hi);
    let inside = [DVec3::Z, -DVec3::Z, DVec3::X, -DVec3::X].into_iter().filter_map(|d| {
        let from = centre - d * (INSIDE_STEP_BACK * (hi - lo).dot(d.abs()));
        let view = contents.and_then(|c| aim(c - from, d)).unwrap_or(d);
        Camera::try_new(from, from + view, DVec3::Y, INSIDE_FOV_DEG).ok()
    });
    let best_inside = best_of(scene, inside.collect(), true);
    if best_inside.1 > best_outside.1 { best_inside.0 } else { best_outside.0 }
}

/// How far back from the middle an inside camera stands, as a share of the room's depth
/// along its view (0.5 would be against the wall behind it; furniture stands there).
const INSIDE_STEP_BACK: f64 = 0.3;

/// An inside view along `d` (horizontal) turned towards `to` (from the camera): when `to`
/// lies within 45° of `d` seen from above, the direction towards it, tilted at most 45° up
/// or down; `None` otherwise (the view then looks level along `d`).
fn aim(to: DVec3, d: DVec3) -> Option<DVec3> {
    let level = DVec3::new(to.x, 0.0, to.z);
    let across = level.length();
    if across <= 0.0 || level.dot(d) < across * std::f64::consts::FRAC_1_SQRT_2 {
        return None;
    }
    let tilt = to.y.atan2(across).clamp(-std::f64::consts::FRAC_PI_4, std::f64::consts::FRAC_PI_4);
    Some(level / across * tilt.cos() + DVec3::Y * tilt.sin())
}

/// Share of the scene's extent along an axis from which an object spans that axis.
const SPANS: f64 = 0.9;

/// The centre of the bounds of what stands in a room: the objects that neither emit nor
/// span two of the scene's axes (walls, floor, ceiling, the room's own box do). `None` when
/// there are none.
fn contents_centre(scene: &Scene, lo: DVec3, hi: DVec3) -> Option<DVec3> {
    let extent = hi - lo;
    let (mut a, mut b) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for object in &scene.objects {
        if scene.materials[object.material].is_emitter() {
            continue;
        }
        let (olo, ohi) = object.bounds();
        let spans = (ohi - olo).cmpge(extent * SPANS).bitmask().count_ones();
        if spans < 2 {
            (a, b) = (a.min(olo), b.max(ohi));
        }
    }
    a.cmple(b).all().then(|| (a + b) * 0.5)
}

/// What a probe ray meets first.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Seen {
    /// The front face of anything.
    Front,
    /// The back face of a two-sided object: lit if something lights it.
    TwoSidedBack,
    /// The back of a one-sided face: black.
    Back,
}

/// The candidate with the best score (a front face 2, a two-sided back face 1), its score
/// and its front faces; ties keep the earlier one (the classic framing first). With
/// `by_objects`, the number of objects whose lit sides the probe rays meet comes first.
/// `candidates` must not be empty.
fn best_of(scene: &Scene, candidates: Vec<Camera>, by_objects: bool) -> (Camera, usize, usize) {
    let mut best = (candidates[0], 0usize, 0usize);
    let mut best_key = (0, 0);
    for camera in candidates {
        let seen = probe_objects(scene, &camera);
        let fronts = seen.iter().filter(|(s, _)| *s == Seen::Front).count();
        let score = 2 * fronts + seen.iter().filter(|(s, _)| *s == Seen::TwoSidedBack).count();
        let mut objects: Vec<usize> =
            seen.iter().filter(|(s, _)| *s != Seen::Back).map(|&(_, o)| o).collect();
        objects.sort_unstable();
        objects.dedup();
        let key = (if by_objects { objects.len() } else { 0 }, score);
        if key > best_key {
            (best, best_key) = ((camera, score, fronts), key);
        }
    }
    best
}

/// The share of the probe rays through `camera` that first meet a lit side: a front face, or
/// either face of a two-sided object.
fn lit_share(scene: &Scene, camera: &Camera) -> f64 {
    probe(scene, camera).into_iter().filter(|&s| s != Seen::Back).count() as f64 / (PROBE.0 * PROBE.1) as f64
}

/// What each probe ray through `camera` meets first (rays that meet nothing are left out).
fn probe(scene: &Scene, camera: &Camera) -> Vec<Seen> {
    probe_objects(scene, camera).into_iter().map(|(seen, _)| seen).collect()
}

/// [`probe`], with the object each ray meets.
fn probe_objects(scene: &Scene, camera: &Camera) -> Vec<(Seen, usize)> {
    let rays = CameraRays::new(camera, PROBE.0 as u32, PROBE.1 as u32);
    (0..PROBE.1)
        .flat_map(|j| (0..PROBE.0).map(move |i| (i, j)))
        .filter_map(|(i, j)| {
            let dir = rays.direction(i as f64 + 0.5, j as f64 + 0.5);
            first_hit(scene, camera.position, dir).map(|(_, seen, object)| (seen, object))
        })
        .collect()
}

/// How many of the probe rays through `camera` first meet a lit side: a front face, or either
/// face of a two-sided object.
#[cfg(test)]
pub(crate) fn front_faces_seen(scene: &Scene, camera: &Camera) -> usize {
    probe(scene, camera).into_iter().filter(|&s| s != Seen::Back).count()
}

/// The nearest surface along `origin + t·dir` (t > 0): its distance, which of its faces the
/// ray meets, and its object.
fn first_hit(scene: &Scene, origin: DVec3, dir: DVec3) -> Option<(f64, Seen, usize)> {
    let mut best: Option<(f64, Seen, usize)> = None;
    for (index, object) in scene.objects.iter().enumerate() {
        let two_sided = object.sides != Sides::One;
        let mut take = |t: f64, front: bool| {
            let seen = match (front, two_sided) {
                (true, _) => Seen::Front,
                (false, true) => Seen::TwoSidedBack,
                (false, false) => Seen::Back,
            };
            if best.is_none_or(|(b, _, _)| t < b) {
                best = Some((t, seen, index));
            }
        };
        match &object.shape {
            Shape::Polygons(ps) => {
                ps.iter().filter_map(|p| hit_polygon(p, origin, dir)).for_each(|h| take(h.0, h.1))
            }
            Shape::Mesh(m) => {
                m.polygons().iter().filter_map(|p| hit_polygon(p, origin, dir)).for_each(|h| take(h.0, h.1))
            }
            Shape::Sphere(s) => {
                // |o + t d − c|² = r², d unit: t² + 2 b t + c = 0.
                let oc = origin - s.center;
                let b = oc.dot(dir);
                let c = oc.length_squared() - s.radius * s.radius;
                let disc = b * b - c;
                if disc < 0.0 {
                    continue;
                }
                let root = disc.sqrt();
                let t = if -b - root > 0.0 { -b - root } else { -b + root };
                if t > 0.0 {
                    let outward = (origin + dir * t - s.center).dot(dir) < 0.0;
                    take(t, outward == (s.facing == Facing::Outward));
                }
            }
        }
    }
    best
}

/// Where the ray meets the convex polygon `p` (t > 0), and whether on its lit side.
fn hit_polygon(p: &Polygon, origin: DVec3, dir: DVec3) -> Option<(f64, bool)> {
    let n = p.normal();
    let v = p.vertices();
    let denom = n.dot(dir);
    if denom.abs() < 1e-12 {
        return None;
    }
    let t = n.dot(v[0] - origin) / denom;
    if t <= 0.0 || !t.is_finite() {
        return None;
    }
    let q = origin + dir * t;
    let k = v.len();
    let inside = (0..k).all(|i| (v[(i + 1) % k] - v[i]).cross(q - v[i]).dot(n) >= 0.0);
    inside.then_some((t, denom < 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiosity_scenes::{cornell_box, furnace_box, two_plates};

    /// A closed box lit from inside is seen from inside: every probe ray meets a lit face
    /// (the framing view from outside would see only the backs of its walls).
    #[test]
    fn a_closed_room_is_seen_from_inside() {
        let scene = furnace_box(0.5, 1.0);
        let framing = {
            let (lo, hi) = scene.bounds();
            Camera::framing(lo, hi)
        };
        assert_eq!(front_faces_seen(&scene, &framing), 0, "the old default saw only back faces");
        let camera = camera_or_framing(&scene);
        assert_eq!(front_faces_seen(&scene, &camera), PROBE.0 * PROBE.1);
    }

    /// The Cornell box opens towards −z: without its camera, the chosen view looks in
    /// through the open side (as the scene's own camera does).
    #[test]
    fn an_open_box_is_seen_through_its_open_side() {
        let mut scene = cornell_box();
        scene.camera = None;
        let camera = camera_or_framing(&scene);
        assert!(camera.position.z < 0.0 && camera.look_at.z > camera.position.z, "{camera:?}");
        assert!(front_faces_seen(&scene, &camera) >= PROBE.0 * PROBE.1 / 4);
    }

    /// The same box with two-sided walls (an OBJ's default): the backs of its walls count as
    /// lit, so every side sees "lit" faces, but only the open side shows faces that are lit by
    /// anything; the view from behind the back wall would be black.
    #[test]
    fn a_two_sided_open_box_is_seen_through_its_open_side() {
        let mut scene = cornell_box();
        scene.camera = None;
        for o in &mut scene.objects {
            o.sides = Sides::Two { emits_back: false };
        }
        let camera = camera_or_framing(&scene);
        assert!(camera.position.z < 0.0 && camera.look_at.z > camera.position.z, "{camera:?}");
        let seen = probe(&scene, &camera);
        assert!(seen.iter().filter(|&&s| s == Seen::Front).count() >= PROBE.0 * PROBE.1 / 4, "{seen:?}");
        // Turned round, so that it opens towards +z as McGuire's OBJ does: still seen from the
        // open side.
        for o in &mut scene.objects {
            let Shape::Polygons(ps) = &mut o.shape else { continue };
            for p in ps.iter_mut() {
                let turned: Vec<DVec3> =
                    p.vertices().iter().map(|v| DVec3::new(556.0 - v.x, v.y, 559.2 - v.z)).collect();
                *p = Polygon::try_new(turned).unwrap();
            }
        }
        let camera = camera_or_framing(&scene);
        assert!(camera.position.z > 559.2 && camera.look_at.z < camera.position.z, "{camera:?}");
    }

    /// A closed room of two-sided walls is seen from inside, not from behind a wall.
    #[test]
    fn a_closed_two_sided_room_is_seen_from_inside() {
        let mut scene = furnace_box(0.5, 1.0);
        for o in &mut scene.objects {
            o.sides = Sides::Two { emits_back: false };
        }
        let camera = camera_or_framing(&scene);
        let (lo, hi) = scene.bounds();
        assert!(camera.position.cmpgt(lo).all() && camera.position.cmplt(hi).all(), "{camera:?}");
    }

    /// In a closed room holding a block by one wall, the inside view looks towards the
    /// block (it shows two objects, the other views one), from behind the room's middle.
    #[test]
    fn inside_a_room_the_view_shows_the_most_objects() {
        use radiosity_core::box_faces;
        for (side, min, max) in [
            (DVec3::X, DVec3::new(0.7, 0.2, 0.3), DVec3::new(0.95, 0.7, 0.7)),
            (-DVec3::Z, DVec3::new(0.3, 0.2, 0.05), DVec3::new(0.7, 0.7, 0.3)),
        ] {
            let mut scene = furnace_box(0.5, 1.0);
            let block = box_faces(min, max, Facing::Outward, 0.0).unwrap();
            scene.objects.push(radiosity_core::Object {
                name: "block".into(),
                material: 0,
                shape: Shape::Polygons(block),
                sides: Sides::One,
            });
            let camera = camera_or_framing(&scene);
            let (lo, hi) = scene.bounds();
            assert!(camera.position.cmpgt(lo).all() && camera.position.cmplt(hi).all(), "{camera:?}");
            let view = (camera.look_at - camera.position).normalize();
            assert!(view.dot(side) > 0.99, "{side}: {camera:?}");
            assert!((camera.position - (lo + hi) * 0.5).dot(side) < -0.2, "stands back: {camera:?}");
        }
    }

    /// A block standing in the middle of a closed room's floor is looked at, not over: the
    /// view from inside aims down at it.
    #[test]
    fn inside_a_room_the_view_aims_at_what_stands_in_it() {
        use radiosity_core::box_faces;
        let mut scene = furnace_box(0.5, 1.0);
        for o in &mut scene.objects {
            let Shape::Polygons(ps) = &mut o.shape else { continue };
            for p in ps.iter_mut() {
                let room: Vec<DVec3> = p.vertices().iter().map(|v| *v * DVec3::new(4.0, 2.0, 4.0)).collect();
                *p = Polygon::try_new(room).unwrap();
            }
        }
        let grey = radiosity_core::Material::try_new(
            "grey",
            radiosity_core::Rgb::splat(0.5),
            radiosity_core::Rgb::ZERO,
        )
        .unwrap();
        scene.materials.push(grey);
        let (min, max) = (DVec3::new(1.7, 0.0, 1.7), DVec3::new(2.3, 0.3, 2.3));
        let block = box_faces(min, max, Facing::Outward, 0.0).unwrap();
        scene.objects.push(radiosity_core::Object::new("block", 1, Shape::Polygons(block)));
        let camera = camera_or_framing(&scene);
        let view = (camera.look_at - camera.position).normalize();
        let to_block = ((min + max) * 0.5 - camera.position).normalize();
        assert!(view.dot(to_block) > 0.999, "aims at the block: {camera:?}");
        assert!(view.y < -0.3, "looks down: {camera:?}");
    }

    /// Two facing plates show their lit sides.
    #[test]
    fn facing_plates_show_a_lit_side() {
        let scene = two_plates(1.0, 1.0, 0.5, 1.0);
        let camera = camera_or_framing(&scene);
        assert!(front_faces_seen(&scene, &camera) > 0, "{camera:?}");
    }

    /// A two-sided wall is lit on both sides: the framing view of a closed box, which sees
    /// no lit face of one-sided walls, sees lit faces of two-sided ones.
    #[test]
    fn both_faces_of_a_two_sided_object_count_as_lit() {
        let mut scene = furnace_box(0.5, 1.0);
        let framing = {
            let (lo, hi) = scene.bounds();
            Camera::framing(lo, hi)
        };
        assert_eq!(front_faces_seen(&scene, &framing), 0);
        scene.objects[0].sides = Sides::Two { emits_back: false };
        assert!(front_faces_seen(&scene, &framing) > 0);
    }
}
