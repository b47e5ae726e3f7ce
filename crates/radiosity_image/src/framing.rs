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

use radiosity_accel::{Bvh, RayQuery};
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
    // shown as a whole from its open side whenever half the probe rays of some side meet
    // sides that see a light (the outsides of a room's walls are not such sides: nothing
    // lights them, whichever way they are wound). A quarter let the Modern Hall be shown
    // from outside, a little of its lit inside through its glass front in a black picture.
    let lights = Lights::of(scene);
    let best_outside = best_of(scene, &lights, candidates, false);
    if best_outside.2 >= PROBE.0 * PROBE.1 / 2 {
        return best_outside.0;
    }
    // A closed room shows only the unlit outsides of its walls: look from inside, at
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
    let best_inside = best_of(scene, &lights, inside.collect(), true);
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
    /// A side that takes part in the solve (the front of anything, either face of a
    /// two-sided object) and sees a light directly; any such side when the scene's lights
    /// give no point to look for (see [`Lights`]).
    Lit,
    /// A side that takes part in the solve but sees no light directly: lit, if at all, by
    /// what the lights light. The outside of a room modelled with its normals out (as many
    /// exported rooms are) is such a side, and nothing lights it.
    Shaded,
    /// The back of a one-sided face: black.
    Back,
}

/// The candidate with the best score (a lit side 2, a shaded one 1), its score and its lit
/// sides; ties keep the earlier one (the classic framing first). With `by_objects`, the
/// number of objects whose solved sides the probe rays meet comes first. `candidates` must
/// not be empty.
fn best_of(
    scene: &Scene,
    lights: &Lights,
    candidates: Vec<Camera>,
    by_objects: bool,
) -> (Camera, usize, usize) {
    let mut best = (candidates[0], 0usize, 0usize);
    let mut best_key = (0, 0);
    for camera in candidates {
        let seen = probe_objects(scene, lights, &camera);
        let lit = seen.iter().filter(|(s, _)| *s == Seen::Lit).count();
        let score = 2 * lit + seen.iter().filter(|(s, _)| *s == Seen::Shaded).count();
        let mut objects: Vec<usize> =
            seen.iter().filter(|(s, _)| *s != Seen::Back).map(|&(_, o)| o).collect();
        objects.sort_unstable();
        objects.dedup();
        let key = (if by_objects { objects.len() } else { 0 }, score);
        if key > best_key {
            (best, best_key) = ((camera, score, lit), key);
        }
    }
    best
}

/// The share of the probe rays through `camera` that first meet a side that takes part in
/// the solve: a front face, or either face of a two-sided object.
fn lit_share(scene: &Scene, camera: &Camera) -> f64 {
    let solved = probe(scene, &Lights::none(), camera).into_iter().filter(|&s| s != Seen::Back).count();
    solved as f64 / (PROBE.0 * PROBE.1) as f64
}

/// What each probe ray through `camera` meets first (rays that meet nothing are left out).
fn probe(scene: &Scene, lights: &Lights, camera: &Camera) -> Vec<Seen> {
    probe_objects(scene, lights, camera).into_iter().map(|(seen, _)| seen).collect()
}

/// [`probe`], with the object each ray meets.
fn probe_objects(scene: &Scene, lights: &Lights, camera: &Camera) -> Vec<(Seen, usize)> {
    let rays = CameraRays::new(camera, PROBE.0 as u32, PROBE.1 as u32);
    (0..PROBE.1)
        .flat_map(|j| (0..PROBE.0).map(move |i| (i, j)))
        .filter_map(|(i, j)| {
            let dir = rays.direction(i as f64 + 0.5, j as f64 + 0.5);
            let (t, side, object) = first_hit(scene, camera.position, dir)?;
            let seen = match side {
                Side::Dark => Seen::Back,
                Side::Solved(facing) if lights.light(camera.position + dir * t, facing) => Seen::Lit,
                Side::Solved(_) => Seen::Shaded,
            };
            Some((seen, object))
        })
        .collect()
}

/// How many of the probe rays through `camera` first meet a side that takes part in the
/// solve: a front face, or either face of a two-sided object.
#[cfg(test)]
pub(crate) fn front_faces_seen(scene: &Scene, camera: &Camera) -> usize {
    probe(scene, &Lights::none(), camera).into_iter().filter(|&s| s != Seen::Back).count()
}

/// Which face of a surface a ray meets.
#[derive(Clone, Copy, PartialEq, Debug)]
enum Side {
    /// A face that takes part in the solve, with its unit normal (towards the ray's origin).
    Solved(DVec3),
    /// The back of a one-sided face.
    Dark,
}

/// Emitter points (on the lit side of the emitting polygons and spheres, luminaires' light
/// points) kept for the view probes, at most this many, spread over the emitters.
const MAX_LIGHT_POINTS: usize = 16;

/// Where the light comes from, to tell a side that sees a light from one that sees none.
///
/// Probing views by which face the rays meet alone was fooled by rooms modelled with their
/// normals out and read two-sided (an OBJ's default): from outside, every side showed the
/// room's front faces, lit by nothing, and Bitterli's *Veach Bidir* room was rendered
/// black from behind a wall. A side counts as lit when a light point is in view of it
/// (unblocked, in front of both), or the sun, or the sky straight above it.
struct Lights {
    /// Points just off the emitters' lit sides, each with that side's normal (`None`: a
    /// luminaire, which may light every way).
    points: Vec<(DVec3, Option<DVec3>)>,
    /// Unit directions towards light at infinity: the sun, the zenith of a sky.
    towards: Vec<DVec3>,
    /// The scene's polygons, for the shadow rays; `None` when there is no light to find.
    blockers: Option<Bvh>,
    /// The scene's spheres, which the BVH of polygons leaves out.
    spheres: Vec<radiosity_core::Sphere>,
    /// How far off a surface a probe point stands, and light points off their emitter.
    step: f64,
    /// Past the scene: the length of a shadow ray towards light at infinity.
    reach: f64,
}

impl Lights {
    /// No light to look for: every side that takes part in the solve counts as lit.
    fn none() -> Self {
        Self {
            points: Vec::new(),
            towards: Vec::new(),
            blockers: None,
            spheres: Vec::new(),
            step: 0.0,
            reach: 0.0,
        }
    }

    /// The lights of `scene`.
    fn of(scene: &Scene) -> Self {
        let (lo, hi) = scene.bounds();
        let diagonal = (hi - lo).length().max(f64::MIN_POSITIVE);
        let step = 1e-3 * diagonal;
        let mut points = Vec::new();
        for object in &scene.objects {
            if !scene.materials[object.material].is_emitter() {
                continue;
            }
            let back = matches!(object.sides, Sides::Two { emits_back: true });
            let mut polygon = |p: &Polygon| {
                let v = p.vertices();
                let centre = v.iter().copied().sum::<DVec3>() / v.len() as f64;
                let n = p.normal();
                points.push((centre + n * step, Some(n)));
                if back {
                    points.push((centre - n * step, Some(-n)));
                }
            };
            match &object.shape {
                Shape::Polygons(ps) => ps.iter().for_each(&mut polygon),
                Shape::Mesh(m) => m.polygons().iter().for_each(&mut polygon),
                Shape::Sphere(s) => {
                    let out = if s.facing == Facing::Outward { 1.0 } else { -1.0 };
                    for axis in [DVec3::X, -DVec3::X, DVec3::Y, -DVec3::Y, DVec3::Z, -DVec3::Z] {
                        points.push((s.center + axis * (s.radius + out * step), Some(axis * out)));
                    }
                }
            }
        }
        points.extend(scene.lighting.luminaires.iter().map(|l| (l.light_point(step), None)));
        if points.len() > MAX_LIGHT_POINTS {
            let stride = points.len() as f64 / MAX_LIGHT_POINTS as f64;
            points = (0..MAX_LIGHT_POINTS).map(|k| points[(k as f64 * stride) as usize]).collect();
        }
        let mut towards: Vec<DVec3> = scene.lighting.sun.iter().map(|s| s.towards.normalize()).collect();
        if scene.lighting.sky.is_some() {
            towards.push(DVec3::Y);
        }
        if points.is_empty() && towards.is_empty() {
            return Self::none();
        }
        let mut triangles = Vec::new();
        let mut spheres = Vec::new();
        for object in &scene.objects {
            let mut fan = |p: &Polygon| {
                let v = p.vertices();
                for k in 1..v.len() - 1 {
                    triangles.push([v[0].as_vec3(), v[k].as_vec3(), v[k + 1].as_vec3()]);
                }
            };
            match &object.shape {
                Shape::Polygons(ps) => ps.iter().for_each(&mut fan),
                Shape::Mesh(m) => m.polygons().iter().for_each(&mut fan),
                Shape::Sphere(s) => spheres.push(*s),
            }
        }
        Self { points, towards, blockers: Some(Bvh::new(&triangles)), spheres, step, reach: 4.0 * diagonal }
    }

    /// Whether the point `q` of a surface whose face towards the viewer has unit normal
    /// `facing` sees a light directly (always, when there is no light to look for).
    fn light(&self, q: DVec3, facing: DVec3) -> bool {
        let Some(bvh) = &self.blockers else { return true };
        let from = q + facing * self.step;
        let sphere_between = |a: DVec3, b: DVec3| self.spheres.iter().any(|s| segment_meets_sphere(a, b, s));
        let point_seen = self.points.iter().any(|&(l, n)| {
            let to = l - from;
            facing.dot(to) > 0.0
                && n.is_none_or(|n| n.dot(to) < 0.0)
                && !bvh.occluded(from.as_vec3(), l.as_vec3())
                && !sphere_between(from, l)
        });
        point_seen
            || self.towards.iter().any(|&d| {
                facing.dot(d) > 0.0
                    && !bvh.occluded_towards(from.as_vec3(), d.as_vec3(), self.reach as f32)
                    && !sphere_between(from, from + d * self.reach)
            })
    }
}

/// Whether the segment from `a` to `b` crosses the surface of sphere `s`.
fn segment_meets_sphere(a: DVec3, b: DVec3, s: &radiosity_core::Sphere) -> bool {
    let len = (b - a).length();
    len > 0.0 && sphere_roots(a, (b - a) / len, s).is_some_and(|ts| ts.iter().any(|&t| t > 0.0 && t < len))
}

/// Where the line `origin + t·dir` (`dir` unit) meets the surface of sphere `s`: both roots
/// of |o + t d − c|² = r², i.e. t² + 2 b t + c = 0, nearer first; `None` when it misses.
fn sphere_roots(origin: DVec3, dir: DVec3, s: &radiosity_core::Sphere) -> Option<[f64; 2]> {
    let oc = origin - s.center;
    let (b, c) = (oc.dot(dir), oc.length_squared() - s.radius * s.radius);
    let disc = b * b - c;
    (disc >= 0.0).then(|| [-b - disc.sqrt(), -b + disc.sqrt()])
}

/// The nearest surface along `origin + t·dir` (t > 0): its distance, which of its faces the
/// ray meets, and its object.
fn first_hit(scene: &Scene, origin: DVec3, dir: DVec3) -> Option<(f64, Side, usize)> {
    let mut best: Option<(f64, Side, usize)> = None;
    for (index, object) in scene.objects.iter().enumerate() {
        let two_sided = object.sides != Sides::One;
        // `normal` is the face's outward (front) normal.
        let mut take = |t: f64, normal: DVec3| {
            let front = normal.dot(dir) < 0.0;
            let side = match (front, two_sided) {
                (true, _) => Side::Solved(normal),
                (false, true) => Side::Solved(-normal),
                (false, false) => Side::Dark,
            };
            if best.is_none_or(|(b, _, _)| t < b) {
                best = Some((t, side, index));
            }
        };
        match &object.shape {
            Shape::Polygons(ps) => {
                ps.iter().filter_map(|p| hit_polygon(p, origin, dir)).for_each(|(t, n)| take(t, n))
            }
            Shape::Mesh(m) => {
                m.polygons().iter().filter_map(|p| hit_polygon(p, origin, dir)).for_each(|(t, n)| take(t, n))
            }
            Shape::Sphere(s) => {
                let Some([near, far]) = sphere_roots(origin, dir, s) else { continue };
                let t = if near > 0.0 { near } else { far };
                if t > 0.0 {
                    let outward = (origin + dir * t - s.center) / s.radius;
                    take(t, if s.facing == Facing::Outward { outward } else { -outward });
                }
            }
        }
    }
    best
}

/// Where the ray meets the convex polygon `p` (t > 0), and the polygon's normal.
fn hit_polygon(p: &Polygon, origin: DVec3, dir: DVec3) -> Option<(f64, DVec3)> {
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
    inside.then_some((t, n))
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
        let seen = probe(&scene, &Lights::of(&scene), &camera);
        assert!(seen.iter().filter(|&&s| s == Seen::Lit).count() >= PROBE.0 * PROBE.1 / 4, "{seen:?}");
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

    /// A room modelled with its normals out and read two-sided (as an OBJ is), lit by a
    /// ceiling lamp inside: from outside, every side shows the walls' front faces, which
    /// nothing lights. Closed, it is seen from inside; without its −x wall, through that
    /// opening.
    #[test]
    fn a_room_wound_outwards_is_seen_where_its_lamp_lights_it() {
        use radiosity_core::{Material, Object, Rgb, box_faces};
        let room = |open: bool| {
            let (lo, hi) = (DVec3::ZERO, DVec3::new(4.0, 3.0, 5.0));
            let mut walls = box_faces(lo, hi, Facing::Outward, 0.0).unwrap();
            if open {
                walls.retain(|p| p.normal().dot(-DVec3::X) < 0.5);
            }
            let lamp = Polygon::try_new(vec![
                DVec3::new(1.5, 2.99, 2.0),
                DVec3::new(2.5, 2.99, 2.0),
                DVec3::new(2.5, 2.99, 3.0),
                DVec3::new(1.5, 2.99, 3.0),
            ])
            .unwrap();
            assert!(lamp.normal().y < -0.99, "the lamp faces down");
            let materials = vec![
                Material::try_new("wall", Rgb::splat(0.7), Rgb::ZERO).unwrap(),
                Material::try_new("lamp", Rgb::ZERO, Rgb::splat(10.0)).unwrap(),
            ];
            let objects = vec![
                Object {
                    name: "room".into(),
                    material: 0,
                    shape: Shape::Polygons(walls),
                    sides: Sides::Two { emits_back: false },
                },
                Object::new("lamp", 1, Shape::Polygons(vec![lamp])),
            ];
            (Scene::try_new("room", None, materials, objects).unwrap(), lo, hi)
        };
        let (closed, lo, hi) = room(false);
        let camera = camera_or_framing(&closed);
        assert!(camera.position.cmpgt(lo).all() && camera.position.cmplt(hi).all(), "inside: {camera:?}");
        let (open, _, _) = room(true);
        let camera = camera_or_framing(&open);
        assert!(
            camera.position.x < 0.0 && camera.look_at.x > camera.position.x,
            "through the opening: {camera:?}"
        );
        let seen = probe(&open, &Lights::of(&open), &camera);
        assert!(seen.iter().filter(|&&s| s == Seen::Lit).count() >= PROBE.0 * PROBE.1 / 4, "{seen:?}");
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
