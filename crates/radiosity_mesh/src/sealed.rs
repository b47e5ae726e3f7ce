//! Closed models lit from one side.
//!
//! A model's faces that close up into one consistently wound surface (every edge run along
//! as often in each direction: shared by two faces, or by two pairs where solids meet along
//! it) enclose a space that no
//! light from outside reaches: every face blocks light from either side. When no emitter
//! lies in that space, the back faces of such a two-sided object face darkness only, so
//! meshing them doubles the object's elements to solve for nothing but the light that ray
//! offsets let through. Such objects are made one-sided: half the elements of a watertight
//! scan or CAD part, and an inside that is exactly dark.
//!
//! A scan is rarely watertight: the Stanford bunny has five holes in its base, 1.8 % of its
//! area. Light that enters a hole spreads over the whole inside, which therefore receives
//! about that share of what the outside does and returns less of it through the same holes.
//! An object whose holes (the area their rims span) are at most [`MAX_HOLE_SHARE`] of its
//! surface is sealed too; meshed two-sided, the insides of a room of four such scans were
//! half its elements and a fifth of its solve time, for back faces at 0.2 % of the front's
//! radiosity. The holes are capped (a fan about each rim's centroid) for the inside test.
//!
//! Which side of the surface an emitter lies on is found by rays from points just in front
//! of it: the first face a ray meets shows it its front or its back; a ray that meets none
//! is outside, which is the front for a surface wound outwards (positive enclosed volume)
//! and the back for one wound inwards (a room). A point luminaire is a light like any
//! emitter here, placed at the point it lights from
//! ([`radiosity_core::Luminaire::light_point`]: a recessed downlight's centre lies in its
//! ceiling, the point just below it in the room), so a scene lit by luminaires alone is
//! sealed, and turned, as one lit by emissive polygons.

use rustc_hash::FxHashMap as HashMap;

use glam::DVec3;

use crate::planar::{bounds, key};
use radiosity_core::{Polygon, Scene, Shape, Sides};

/// Emitting polygon sides tested against each closed object, spread over the emitters.
const MAX_EMITTER_SIDES: usize = 32;

/// Directions of the rays cast from each emitter point (normalised where used), off the axes
/// and diagonals a model is built along; a majority decides, so that one ray that slips along
/// an edge cannot.
const DIRECTIONS: [DVec3; 3] = [
    DVec3::new(0.5377, 0.7093, 0.4597),
    DVec3::new(-0.6123, 0.2211, -0.7591),
    DVec3::new(0.1489, -0.9311, 0.3331),
];

/// Largest share of an object's area that its holes may span for it to be sealed: the
/// inside of such an object gets about that share of the light its outside does (see the
/// module's notes). A cup's or a bowl's opening is a fifth to a half of its area, a box
/// without its lid a fifth: those keep both sides.
pub const MAX_HOLE_SHARE: f64 = 0.05;

/// An object [`seal_closed_objects`] made one-sided.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sealed {
    /// Its index in the scene's objects.
    pub object: usize,
    /// The area its holes span over its surface's area: 0 for a watertight surface, at most
    /// [`MAX_HOLE_SHARE`].
    pub hole_share: f64,
    /// Its faces were turned: every emitter lay on their back side, so their fronts enclosed
    /// a space no light reaches (a model whose normals point inwards, a room whose normals
    /// point out).
    pub turned: bool,
}

/// Makes one-sided every two-sided, non-emitting object of `scene` whose faces close up into
/// one consistently wound surface, but for holes spanning at most [`MAX_HOLE_SHARE`] of its
/// area, with no light (emitter or luminaire) on its back side, or with every light on it
/// (then its faces are turned, so that the side the light is on is their front); returns
/// them in scene order.
pub fn seal_closed_objects(scene: &mut Scene) -> Vec<Sealed> {
    let sides = emitter_points(scene);
    let mut sealed = Vec::new();
    for (i, o) in scene.objects.iter_mut().enumerate() {
        let polygons = match &o.shape {
            Shape::Polygons(ps) => &ps[..],
            Shape::Mesh(m) => m.polygons(),
            Shape::Sphere(_) => continue,
        };
        let two_sided = matches!(o.sides, Sides::Two { .. });
        if !two_sided || scene.materials[o.material].is_emitter() {
            continue;
        }
        let Some(holes) = Holes::of(polygons) else { continue };
        let surface = Closed::new(polygons, &holes.caps);
        // Each lamp side by the majority of its points: a closed object touching the lamp
        // (a pendant's rod, a housing around the panel) may hold one of them.
        let mut verdicts = sides.iter().map(|points| {
            let behind = points.iter().filter(|&&p| surface.behind(p)).count();
            match 2 * behind {
                b if b < points.len() => Some(false),
                b if b > points.len() => Some(true),
                _ => None,
            }
        });
        let Some(Some(turned)) = verdicts.next() else { continue };
        if !verdicts.all(|v| v == Some(turned)) {
            continue;
        }
        if turned {
            o.shape = match &o.shape {
                Shape::Polygons(ps) => Shape::Polygons(ps.iter().map(Polygon::flipped).collect()),
                Shape::Mesh(m) => Shape::Mesh(m.flipped()),
                Shape::Sphere(_) => continue,
            };
        }
        o.sides = Sides::One;
        sealed.push(Sealed { object: i, hole_share: holes.share, turned });
    }
    sealed
}

/// The holes of a surface that is closed but for them.
pub(crate) struct Holes {
    /// Triangles that close them, wound as the surface around them.
    pub(crate) caps: Vec<[DVec3; 3]>,
    /// The area their rims span over the surface's area.
    share: f64,
}

impl Holes {
    /// The holes of `polygons` when every edge is run along as often in each direction (by
    /// exact corner positions, as a model's faces share its vertices) except the rims of
    /// holes, run once one way: rims that close up, touch no other rim at a corner, and span
    /// at most [`MAX_HOLE_SHARE`] of the area in all. `None` for any other surface.
    pub(crate) fn of(polygons: &[Polygon]) -> Option<Self> {
        let mut runs: HashMap<([u64; 3], [u64; 3]), (u32, DVec3)> = HashMap::default();
        for p in polygons {
            let v = p.vertices();
            for k in 0..v.len() {
                let (a, b) = (v[k], v[(k + 1) % v.len()]);
                runs.entry((key(a), key(b))).or_insert((0, a)).0 += 1;
            }
        }
        if runs.is_empty() {
            return None;
        }
        // Each rim edge, by the corner it starts from: one per corner, or rims touch. An edge
        // run as often each way is inside the surface: once each way between two faces, or
        // twice where two pairs of faces meet along it (a scan's seam, a model's mirror
        // plane: the `beast` of the common 3D test models has four such edges among 193 k).
        let mut rim: HashMap<[u64; 3], ([u64; 3], DVec3)> = HashMap::default();
        for (&(a, b), &(n, pa)) in &runs {
            match (n, runs.get(&(b, a)).map_or(0, |r| r.0)) {
                (n, m) if n == m => {}
                (1, 0) => {
                    if rim.insert(a, (b, pa)).is_some() {
                        return None;
                    }
                }
                _ => return None,
            }
        }
        let area: f64 = polygons.iter().map(Polygon::area).sum();
        let mut caps = Vec::new();
        let mut spanned = 0.0;
        // Rims walked from their lowest corner, so the caps do not depend on map order.
        let mut starts: Vec<[u64; 3]> = rim.keys().copied().collect();
        starts.sort_unstable();
        let mut walked = rustc_hash::FxHashSet::default();
        for start in starts {
            if walked.contains(&start) {
                continue;
            }
            let mut corners = Vec::new();
            let mut at = start;
            loop {
                let &(next, p) = rim.get(&at)?;
                walked.insert(at);
                corners.push(p);
                at = next;
                if at == start {
                    break;
                }
                if walked.contains(&at) {
                    return None;
                }
            }
            let n = corners.len();
            let span = (0..n).map(|i| corners[i].cross(corners[(i + 1) % n])).sum::<DVec3>() / 2.0;
            spanned += span.length();
            // The faces run each rim edge a → b, so a cap that closes the surface runs b → a.
            let centre = corners.iter().sum::<DVec3>() / n as f64;
            caps.extend((0..n).map(|i| [centre, corners[(i + 1) % n], corners[i]]));
        }
        let share = spanned / area.max(f64::MIN_POSITIVE);
        (share <= MAX_HOLE_SHARE).then_some(Self { caps, share })
    }
}

/// Points just in front of the scene's emitters (and behind those that emit from both
/// sides), one group per emitting side of a polygon (at most [`MAX_EMITTER_SIDES`], spread
/// over every emitting polygon and luminaire in turn): its centre and the points halfway
/// from it to each corner; a luminaire's group is its
/// [`radiosity_core::Luminaire::light_point`]. One point per side was not enough: a
/// pendant's rod standing on the middle of a ceiling panel held it, so the fixture seemed to
/// enclose the lamp and was turned inside out, and its faces read 0 against the path
/// tracer's 0.25.
fn emitter_points(scene: &Scene) -> Vec<Vec<DVec3>> {
    let (lo, hi) = scene.bounds();
    let step = 1e-6 * lo.distance(hi).max(f64::MIN_POSITIVE);
    let mut sides = Vec::new();
    for o in scene.objects.iter().filter(|o| scene.materials[o.material].is_emitter()) {
        let both = matches!(o.sides, Sides::Two { emits_back: true });
        match &o.shape {
            Shape::Sphere(s) => {
                // Light leaves the outside of a ball and the inside of a dome.
                let out = if s.facing == radiosity_core::Facing::Outward { 1.0 + 1e-6 } else { 0.0 };
                sides.push(vec![s.center + DVec3::Y * (s.radius * out)]);
            }
            Shape::Polygons(ps) => push_fronts(&mut sides, ps, both, step),
            Shape::Mesh(m) => push_fronts(&mut sides, m.polygons(), both, step),
        }
    }
    sides.extend(scene.lighting.luminaires.iter().map(|l| vec![l.light_point(step)]));
    if sides.len() > MAX_EMITTER_SIDES {
        let stride = sides.len().div_ceil(MAX_EMITTER_SIDES);
        sides = sides.into_iter().step_by(stride).collect();
    }
    sides
}

fn push_fronts(sides: &mut Vec<Vec<DVec3>>, polygons: &[Polygon], both: bool, step: f64) {
    // A mesh lamp of thousands of facets: a spread of them is enough to place it.
    let stride = polygons.len().div_ceil(MAX_EMITTER_SIDES).max(1);
    for p in polygons.iter().step_by(stride) {
        let v = p.vertices();
        let centre = v.iter().sum::<DVec3>() / v.len() as f64;
        let on_face: Vec<DVec3> =
            std::iter::once(centre).chain(v.iter().map(|c| centre + (*c - centre) * 0.5)).collect();
        sides.push(on_face.iter().map(|q| *q + p.normal() * step).collect());
        if both {
            sides.push(on_face.iter().map(|q| *q - p.normal() * step).collect());
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
    /// `polygons` closed by the triangles `caps` (wound as the surface around them).
    fn new(polygons: &[Polygon], caps: &[[DVec3; 3]]) -> Self {
        let fans = polygons.iter().flat_map(|p| {
            let v = p.vertices();
            (1..v.len() - 1).map(move |i| ([v[0], v[i], v[i + 1]], p.normal()))
        });
        let caps = caps.iter().map(|&t| (t, (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero()));
        let triangles: Vec<([DVec3; 3], DVec3)> = fans.chain(caps).collect();
        // Divergence theorem: Σ v0 · (v1 × v2) / 6 over a closed surface's triangles.
        let volume: f64 = triangles.iter().map(|(v, _)| v[0].dot(v[1].cross(v[2])) / 6.0).sum();
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
pub(crate) mod tests {
    use super::*;
    use radiosity_core::{Facing, Luminaire, Material, Object, PolygonMesh, Sphere};
    use radiosity_core::{Rgb, box_faces};

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

    /// `faces` (corner lists) as one mesh whose corners in the same place share a vertex,
    /// as a model file gives them.
    fn shared_mesh(faces: impl IntoIterator<Item = Vec<DVec3>>) -> PolygonMesh {
        let mut positions: Vec<DVec3> = Vec::new();
        let mut index = |q: DVec3| match positions.iter().position(|&p| p == q) {
            Some(i) => i as u32,
            None => {
                positions.push(q);
                (positions.len() - 1) as u32
            }
        };
        let faces: Vec<Vec<u32>> =
            faces.into_iter().map(|f| f.into_iter().map(&mut index).collect()).collect();
        PolygonMesh::try_new(positions, faces).unwrap()
    }

    pub(crate) fn boxed(normals: Facing, faces_as_mesh: bool) -> Object {
        let faces = box_faces(DVec3::ZERO, DVec3::ONE, normals, 0.0).unwrap();
        let shape = if faces_as_mesh {
            Shape::Mesh(shared_mesh(faces.iter().map(|f| f.vertices().to_vec())))
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

    /// The indices of the objects `seal_closed_objects` seals.
    fn sealed(s: &mut Scene) -> Vec<usize> {
        seal_closed_objects(s).iter().map(|x| x.object).collect()
    }

    /// The unit cube wound outwards as one mesh of shared vertices, each face a 4 × 4 grid
    /// of quads (quarters: every shared corner is the same double from either face), with
    /// the quads `missing` (face, cell) left out.
    pub(crate) fn gridded_box(missing: &[(usize, usize)]) -> Object {
        let faces = box_faces(DVec3::ZERO, DVec3::ONE, Facing::Outward, 0.0).unwrap();
        let mut quads: Vec<Vec<DVec3>> = Vec::new();
        for (f, face) in faces.iter().enumerate() {
            let v = face.vertices();
            let at = |a: usize, b: usize| {
                v[0] + (v[1] - v[0]) * (a as f64 / 4.0) + (v[3] - v[0]) * (b as f64 / 4.0)
            };
            for cell in (0..16).filter(|c| !missing.contains(&(f, *c))) {
                let (a, b) = (cell % 4, cell / 4);
                quads.push(vec![at(a, b), at(a + 1, b), at(a + 1, b + 1), at(a, b + 1)]);
            }
        }
        let shape = Shape::Mesh(shared_mesh(quads));
        Object { name: "scan".into(), material: 1, shape, sides: Sides::Two { emits_back: false } }
    }

    /// A pendant's rod standing on the middle of a ceiling lamp holds the point just below
    /// the lamp's centre: decided by that point alone, the closed rod seemed to enclose the
    /// lamp and was turned inside out. The lamp's other points see its outside.
    #[test]
    fn a_rod_touching_the_middle_of_a_lamp_is_sealed_not_turned() {
        let faces = box_faces(DVec3::new(0.48, 0.2, 0.48), DVec3::new(0.52, 1.0, 0.52), Facing::Outward, 0.0);
        let rod = Object {
            name: "rod".into(),
            material: 1,
            shape: Shape::Mesh(shared_mesh(faces.unwrap().iter().map(|f| f.vertices().to_vec()))),
            sides: Sides::Two { emits_back: false },
        };
        let mut s = scene(vec![lamp(DVec3::new(0.5, 1.0, 0.5), true), rod]);
        let got = seal_closed_objects(&mut s);
        assert_eq!(got.len(), 1, "{got:?}");
        assert!(!got[0].turned, "the rod's outside faces the lamp: {got:?}");
    }

    /// A scan with small holes (two cells of one face, 2/96 of the area) is sealed, its
    /// holes' share reported, and turned when its lamp is inside; with holes that touch or
    /// reach past `MAX_HOLE_SHARE` (a whole face: a fifth), it keeps both sides.
    #[test]
    fn a_box_with_small_holes_is_sealed_a_wide_open_one_is_not() {
        let mut s = scene(vec![lamp(DVec3::new(0.5, 3.0, 0.5), true), gridded_box(&[(0, 5), (0, 7)])]);
        let got = seal_closed_objects(&mut s);
        assert_eq!(got.len(), 1);
        assert_eq!(got[0].object, 1);
        let expected = 2.0 / 16.0 / (6.0 - 2.0 / 16.0);
        assert!((got[0].hole_share - expected).abs() < 1e-12, "{} vs {expected}", got[0].hole_share);
        assert_eq!(s.objects[1].sides, Sides::One);

        // Its lamp inside: its outside gets only what leaks through the holes.
        let mut inside = scene(vec![lamp(DVec3::new(0.5, 0.5, 0.5), true), gridded_box(&[(0, 5), (0, 7)])]);
        let got = seal_closed_objects(&mut inside);
        assert!(got.len() == 1 && got[0].turned, "lamp inside a box with small holes: {got:?}");

        // Two holes that meet at a corner: the rims cannot be told apart there.
        let mut touching =
            scene(vec![lamp(DVec3::new(0.5, 3.0, 0.5), true), gridded_box(&[(0, 5), (0, 10)])]);
        assert!(sealed(&mut touching).is_empty(), "holes touching at a corner");

        let whole_face: Vec<(usize, usize)> = (0..16).map(|c| (2, c)).collect();
        let mut open = scene(vec![lamp(DVec3::new(0.5, 3.0, 0.5), true), gridded_box(&whole_face)]);
        assert!(sealed(&mut open).is_empty(), "a box without a face");
        const { assert!(1.0 / 5.0 > MAX_HOLE_SHARE) };
    }

    /// Two cubes that meet along an edge, as one mesh: that edge is run twice each way, and
    /// the surface still encloses what no light reaches.
    #[test]
    fn solids_meeting_along_an_edge_are_sealed() {
        let faces = [DVec3::ZERO, DVec3::new(1.0, 1.0, 0.0)]
            .into_iter()
            .flat_map(|lo| box_faces(lo, lo + DVec3::ONE, Facing::Outward, 0.0).unwrap())
            .map(|f| f.vertices().to_vec());
        let shape = Shape::Mesh(shared_mesh(faces));
        let cubes =
            Object { name: "cubes".into(), material: 1, shape, sides: Sides::Two { emits_back: false } };
        let mut s = scene(vec![lamp(DVec3::new(0.5, 3.0, 0.5), true), cubes]);
        assert_eq!(sealed(&mut s), vec![1]);
    }

    #[test]
    fn a_closed_box_lit_from_outside_is_sealed() {
        for as_mesh in [false, true] {
            let mut s = scene(vec![lamp(DVec3::new(0.5, 3.0, 0.5), true), boxed(Facing::Outward, as_mesh)]);
            assert_eq!(sealed(&mut s), vec![1], "mesh: {as_mesh}");
            assert_eq!(s.objects[1].sides, Sides::One);
        }
    }

    /// A lamp inside a box wound outwards lights its back faces only: it is turned inside
    /// out (a room modelled as a box with its normals out) and sealed so.
    #[test]
    fn a_box_with_its_lamp_inside_is_turned_inside_out() {
        for as_mesh in [false, true] {
            let mut s = scene(vec![lamp(DVec3::new(0.5, 0.9, 0.5), true), boxed(Facing::Outward, as_mesh)]);
            assert_eq!(
                seal_closed_objects(&mut s),
                vec![Sealed { object: 1, hole_share: 0.0, turned: true }]
            );
            assert_eq!(s.objects[1].sides, Sides::One);
            let polygons = match &s.objects[1].shape {
                Shape::Polygons(ps) => ps.clone(),
                Shape::Mesh(m) => m.polygons().to_vec(),
                Shape::Sphere(_) => unreachable!(),
            };
            for p in &polygons {
                let centre = p.vertices().iter().sum::<DVec3>() / p.vertices().len() as f64;
                assert!(p.normal().dot(centre - DVec3::splat(0.5)) < 0.0, "mesh {as_mesh}: faces the inside");
            }
        }
    }

    /// A room wound inwards with its lamp inside: its outside is its back, which no light
    /// reaches. With its lamp outside instead (a model whose normals point inwards), its
    /// faces are turned outwards and it is sealed so; with lamps on both sides it keeps both.
    #[test]
    fn a_closed_surface_is_sealed_on_the_side_its_lamps_are() {
        let mut s = scene(vec![lamp(DVec3::new(0.5, 0.9, 0.5), true), boxed(Facing::Inward, true)]);
        let got = seal_closed_objects(&mut s);
        assert_eq!(got, vec![Sealed { object: 1, hole_share: 0.0, turned: false }]);

        let facing_out = |o: &Object| match &o.shape {
            Shape::Mesh(m) => m.polygons().iter().all(|p| {
                let centre = p.vertices().iter().sum::<DVec3>() / p.vertices().len() as f64;
                p.normal().dot(centre - DVec3::splat(0.5)) > 0.0
            }),
            _ => panic!("a mesh was given"),
        };
        let mut s = scene(vec![lamp(DVec3::new(0.5, 3.0, 0.5), true), boxed(Facing::Inward, true)]);
        assert!(!facing_out(&s.objects[1]));
        let got = seal_closed_objects(&mut s);
        assert_eq!(got, vec![Sealed { object: 1, hole_share: 0.0, turned: true }]);
        assert_eq!(s.objects[1].sides, Sides::One);
        assert!(facing_out(&s.objects[1]), "turned outwards");

        let both = vec![
            lamp(DVec3::new(0.5, 0.9, 0.5), true),
            lamp(DVec3::new(0.5, 3.0, 0.5), true),
            boxed(Facing::Inward, true),
        ];
        let mut s = scene(both);
        assert!(seal_closed_objects(&mut s).is_empty());
        assert_eq!(s.objects[2].sides, Sides::Two { emits_back: false });
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

    /// A downlight: a cosine distribution over the lower hemisphere, aimed down.
    pub(crate) fn downlight(at: DVec3) -> Luminaire {
        let gammas: Vec<f64> = (0..=90).step_by(5).map(f64::from).collect();
        let cd: Vec<f64> = gammas.iter().map(|g| 100.0 * g.to_radians().cos()).collect();
        let table = std::sync::Arc::new(radiosity_core::IntensityTable::symmetric(gammas, cd).unwrap());
        Luminaire::aimed("downlight", at, DVec3::NEG_Y, 0.0, table, 1.0, Rgb::ONE)
    }

    /// `objects` lit by `luminaires` alone: no material emits.
    pub(crate) fn lit_by(objects: Vec<Object>, luminaires: Vec<Luminaire>) -> Scene {
        let materials = vec![
            Material::try_new("unused", Rgb::ZERO, Rgb::ZERO).unwrap(),
            Material::try_new("white", Rgb::splat(0.5), Rgb::ZERO).unwrap(),
        ];
        let mut s = Scene::try_new_unlit("luminaires", None, materials, objects).unwrap();
        s.lighting.luminaires = luminaires;
        s
    }

    /// Luminaires count as lights: a scene lit by them alone seals a closed box they are
    /// outside of, and turns one wound outwards around them (a room with its normals out),
    /// even when the downlight's centre lies in the box's ceiling (recessed): it lights from
    /// just below.
    #[test]
    fn luminaires_alone_decide_the_lit_side() {
        for as_mesh in [false, true] {
            let mut s =
                lit_by(vec![boxed(Facing::Outward, as_mesh)], vec![downlight(DVec3::new(0.5, 3.0, 0.5))]);
            assert_eq!(
                seal_closed_objects(&mut s),
                vec![Sealed { object: 0, hole_share: 0.0, turned: false }]
            );
            for y in [0.9, 1.0] {
                let mut s =
                    lit_by(vec![boxed(Facing::Outward, as_mesh)], vec![downlight(DVec3::new(0.5, y, 0.5))]);
                let got = seal_closed_objects(&mut s);
                assert_eq!(got, vec![Sealed { object: 0, hole_share: 0.0, turned: true }], "y {y}");
            }
        }
        // One luminaire outside, one inside: light on both sides, both kept.
        let both = vec![downlight(DVec3::new(0.5, 3.0, 0.5)), downlight(DVec3::new(0.5, 0.9, 0.5))];
        let mut s = lit_by(vec![boxed(Facing::Inward, true)], both);
        assert!(seal_closed_objects(&mut s).is_empty());
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
