//! Meshes that follow shadow outlines: discontinuity meshing of direct light (Heckbert 1992,
//! "Discontinuity meshing for radiosity"; Lischinski, Tampieri & Greenberg 1992). Where a
//! solid stands between a bright emitter and a surface, the surface is cut along the outer
//! outline of the solid's penumbra and along the outline of its umbra before it is meshed, so
//! the shadow's edges fall on element edges instead of across elements (an element across
//! one averages light and shade, and its smooth shading then draws the edge as a ramp as wide
//! as the element).
//!
//! For a convex emitter and a convex solid over a plane, both outlines follow from the
//! emitter's corners alone (the standard construction of soft-shadow volumes): the shadow
//! cast from one corner is the hull of the solid's corners projected from it onto the plane;
//! the umbra (no point of the emitter seen) is the intersection of those shadows, and the
//! penumbra (some point hidden) lies within their hull, which is its outline whenever the
//! emitter is parallel to the plane (a lamp in a ceiling over a floor). The lines inside the
//! penumbra where the visible part of the emitter changes shape (the remaining vertex–edge
//! events) are not cut: the radiosity is smooth across them to first order, and cutting
//! them all costs more elements than it buys.
//!
//! A point luminaire (`[[luminaire]]`) is an emitter with one corner, its photometric
//! centre (the point the solver's shadow rays start from): its shadow has no penumbra, and
//! its one outline is the umbra's, the hull of the solid's corners projected from that point
//! onto the plane (the silhouette of a convex solid from a point, Heckbert 1992 §3).
//!
//! Emitters are the polygon lights and luminaires carrying at least [`LIGHT_SHARE`] of the
//! scene's emitted power, polygons' and luminaires' together (a luminaire's flux Φ counts
//! as Φ / 683 W, the solver's rule), at most [`MAX_LIGHTS`] of them, the brightest first; a
//! light object whose coplanar faces make one convex polygon (a quad given as two
//! triangles) is one emitter. Solids are sets of polygons joined
//! at shared corners that make a convex solid (a box given face by face, as the Cornell box's
//! blocks are): all their corners lie on or behind each face. Concave objects and tessellated
//! models cast no outlines; they are left to adaptive subdivision.

use rustc_hash::FxHashMap as HashMap;

use glam::{DVec2, DVec3};

use crate::planar::{area, bounds, clean, clip, key, lexicographic, plane, split, tolerance};
use crate::union_find::UnionFind;
use radiosity_core::{LUMENS_PER_WATT, Luminaire, Polygon, Scene, Shape};

/// Least share of the scene's emitted power an emitter needs to cast outlines: the dim ones'
/// shadows are faint, and every outline costs elements.
const LIGHT_SHARE: f64 = 0.1;

/// Most emitters casting outlines, the brightest first.
const MAX_LIGHTS: usize = 4;

/// Most corners of a solid that casts outlines (a box has 8, a hexagonal prism 12).
const MAX_SOLID_CORNERS: usize = 32;

/// Objects from model files with more faces than this are neither emitters nor solids here:
/// a tessellated model is neither convex nor one polygon, and looking costs linear time.
const MAX_MODEL_FACES: usize = 64;

/// Most magnification of a solid's shadow: a solid reaching almost as high above the surface
/// as the emitter casts a shadow reaching almost to infinity; outlines stop there.
const MAX_MAGNIFICATION: f64 = 20.0;

/// The pieces of a cut surface may cost at most this many times the elements of the whole
/// surface (the same bound as for contacts): past it, an outline does not cut.
const PIECE_COST: usize = 4;

/// A convex emitter: a polygon light, or a point luminaire (one corner).
struct Light {
    corners: Vec<DVec3>,
    /// Which way it shines.
    shine: Shine,
}

/// Where an emitter's light goes.
enum Shine {
    /// A polygon's front side: its normal and a point of it.
    Front { normal: DVec3, centre: DVec3 },
    /// A point luminaire's goniometric distribution.
    Distribution(Box<Luminaire>),
}

impl Light {
    /// Whether some light can reach the plane of `target` (a polygon light: some corner of
    /// it lies in front). A luminaire may light any plane on the far side of a solid it lights.
    fn reaches(&self, target: &Polygon) -> bool {
        match &self.shine {
            Shine::Front { normal, centre } => {
                target.vertices().iter().any(|&q| normal.dot(q - *centre) > 0.0)
            }
            Shine::Distribution(_) => true,
        }
    }

    /// Whether `solid` (its corners) is lit: some corner in front of a polygon light; for a
    /// luminaire, some intensity towards a corner or the centre (a narrow spot on the middle
    /// of a box misses its corners).
    fn lights(&self, solid: &[DVec3]) -> bool {
        match &self.shine {
            Shine::Front { normal, centre } => solid.iter().any(|&q| normal.dot(q - *centre) > 0.0),
            Shine::Distribution(l) => {
                let middle = solid.iter().copied().sum::<DVec3>() / solid.len() as f64;
                solid.iter().chain([&middle]).any(|&q| {
                    let dir = (q - l.position).normalize_or_zero();
                    dir != DVec3::ZERO && l.candela_towards(dir) > 0.0
                })
            }
        }
    }
}

/// The shadow outlines the scene's bright emitters cast through its convex solids.
pub(crate) struct ShadowOutlines {
    lights: Vec<Light>,
    /// Each convex solid's corners.
    solids: Vec<Vec<DVec3>>,
}

/// The polygons of `shape` looked at here: all of a polygon object's, a small model's.
fn polygons_of(shape: &Shape) -> &[Polygon] {
    match shape {
        Shape::Polygons(ps) => ps,
        Shape::Mesh(m) if m.polygons().len() <= MAX_MODEL_FACES => m.polygons(),
        _ => &[],
    }
}

impl ShadowOutlines {
    /// The emitters and convex solids of `scene`.
    pub(crate) fn new(scene: &Scene) -> Self {
        Self { lights: lights(scene), solids: solids(scene) }
    }

    /// Whether no outline can be cast (no bright emitter or luminaire, or no convex solid).
    pub(crate) fn is_empty(&self) -> bool {
        self.lights.is_empty() || self.solids.is_empty()
    }

    /// The outlines cast on the plane of `target`, each convex and counter-clockwise about its
    /// normal: per emitter and solid, the penumbra's outline, then the umbra's where there is
    /// one (a point luminaire's shadow is all umbra: one outline). Not clipped to `target`.
    pub(crate) fn outlines(&self, target: &Polygon) -> Vec<Vec<DVec3>> {
        let (n, d) = plane(target);
        let eps = tolerance(target);
        let height = |q: DVec3| n.dot(q) - d;
        let mut out = Vec::new();
        for light in &self.lights {
            let lit_heights: Vec<f64> = light.corners.iter().map(|&q| height(q)).collect();
            let lowest_light = lit_heights.iter().copied().fold(f64::INFINITY, f64::min);
            // The emitter wholly in front of the surface, and the surface partly in front of it.
            if lowest_light <= eps || !light.reaches(target) {
                continue;
            }
            for solid in &self.solids {
                let hs: Vec<f64> = solid.iter().map(|&q| height(q)).collect();
                let highest = hs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                // Standing on or above the surface, below the emitter, and lit by it.
                if hs.iter().any(|&h| h < -eps)
                    || highest <= eps
                    || highest >= lowest_light * (1.0 - 1.0 / MAX_MAGNIFICATION)
                    || !light.lights(solid)
                {
                    continue;
                }
                let shadows: Vec<Vec<DVec3>> = light
                    .corners
                    .iter()
                    .zip(&lit_heights)
                    .map(|(&l, &hl)| {
                        let cast: Vec<DVec3> = solid
                            .iter()
                            .zip(&hs)
                            .map(|(&o, &ho)| {
                                // Along the ray from the corner through o, to height 0.
                                let x = l + (o - l) * (hl / (hl - ho));
                                x - n * height(x)
                            })
                            .collect();
                        hull(&cast, n)
                    })
                    .collect();
                if let [point] = &shadows[..] {
                    // From a point: the umbra is the whole shadow.
                    if point.len() >= 3 {
                        out.push(point.clone());
                    }
                    continue;
                }
                let all: Vec<DVec3> = shadows.iter().flatten().copied().collect();
                let penumbra = hull(&all, n);
                // Clipping repeats a corner where the shadows share one; the hull drops it (a
                // zero-length edge would cut nothing off and keep everything twice).
                let umbra =
                    hull(&shadows[1..].iter().fold(shadows[0].clone(), |u, s| intersect(&u, s, n)), n);
                if penumbra.len() >= 3 {
                    let whole = area(&penumbra, n);
                    out.push(penumbra);
                    if area(&umbra, n) > 1e-6 * whole {
                        out.push(umbra);
                    }
                }
            }
        }
        out
    }

    /// `pieces` of `target` (the surface, or its pieces around footprints) cut along the
    /// outlines cast on it, one outline after another; an outline that misses every piece, or
    /// whose cut would leave a piece the polygon validation refuses or cost more than
    /// [`PIECE_COST`] times `estimate(target)` elements, does not cut.
    pub(crate) fn cut(
        &self,
        target: &Polygon,
        pieces: &[Polygon],
        estimate: impl Fn(&Polygon) -> usize,
    ) -> Option<Vec<Polygon>> {
        let outlines = self.outlines(target);
        if outlines.is_empty() {
            return None;
        }
        let whole = target.area();
        let tiny = 1e-9 * whole;
        let budget = PIECE_COST * estimate(target).max(1);
        let mut current: Vec<Polygon> = pieces.to_vec();
        let mut cut_any = false;
        for outline in &outlines {
            let Some(next) = split_all(&current, outline, target, tiny) else { continue };
            if next.len() > current.len() && next.iter().map(&estimate).sum::<usize>() <= budget {
                current = next;
                cut_any = true;
            }
        }
        cut_any.then_some(current)
    }
}

/// `pieces` (of `target`) split along convex `outline`, pieces of at most `tiny` area left
/// out; `None` when a piece the split makes is one the polygon validation refuses.
fn split_all(pieces: &[Polygon], outline: &[DVec3], target: &Polygon, tiny: f64) -> Option<Vec<Polygon>> {
    let n = target.normal();
    let mut out = Vec::with_capacity(pieces.len() + outline.len());
    for piece in pieces {
        let (outside, inside) = split(piece.vertices(), outline, n);
        let kept: Vec<Vec<DVec3>> = outside.into_iter().filter(|q| area(q, n) > tiny).collect();
        if area(&inside, n) <= tiny || kept.is_empty() {
            out.push(piece.clone());
            continue;
        }
        for q in kept.into_iter().chain([inside]) {
            out.push(Polygon::try_new(clean(q, target)).ok()?);
        }
    }
    Some(out)
}

/// Power of luminaire `l` in the solver's units (W; Φ / 683 · colour, colour at Y = 1), Y.
fn luminaire_power(l: &Luminaire) -> f64 {
    (l.colour * (l.flux() / LUMENS_PER_WATT)).luminance()
}

/// The bright convex emitters and point luminaires of `scene`, brightest first.
fn lights(scene: &Scene) -> Vec<Light> {
    let luminaires = &scene.lighting.luminaires;
    let mut total = scene.emitted_power().luminance();
    if !luminaires.is_empty() {
        total += luminaires.iter().map(luminaire_power).sum::<f64>();
    }
    if total.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Vec::new();
    }
    let mut found: Vec<(f64, Light)> = Vec::new();
    for o in &scene.objects {
        let emission = scene.materials[o.material].emission.luminance();
        let ps = polygons_of(&o.shape);
        if emission <= 0.0 || ps.is_empty() {
            continue;
        }
        let as_light = |corners: Vec<DVec3>, normal: DVec3| {
            let centre = corners.iter().copied().sum::<DVec3>() / corners.len() as f64;
            Light { corners, shine: Shine::Front { normal, centre } }
        };
        // Coplanar faces that tile one convex polygon (a quad as two triangles) are one light.
        let n = ps[0].normal();
        let (n0, d0) = plane(&ps[0]);
        let eps = tolerance(&ps[0]);
        let coplanar = ps.iter().all(|p| {
            p.normal().dot(n) > 1.0 - 1e-9 && p.vertices().iter().all(|&q| (n0.dot(q) - d0).abs() <= eps)
        });
        let faces_area: f64 = ps.iter().map(Polygon::area).sum();
        let corners: Vec<DVec3> = ps.iter().flat_map(|p| p.vertices().iter().copied()).collect();
        let joined = coplanar
            .then(|| hull(&corners, n))
            .filter(|h| (area(h, n) - faces_area).abs() <= 1e-9 * faces_area);
        match joined {
            Some(h) if h.len() >= 3 => found.push((emission * faces_area, as_light(h, n))),
            _ => found.extend(
                ps.iter().map(|p| (emission * p.area(), as_light(p.vertices().to_vec(), p.normal()))),
            ),
        }
    }
    // A luminaire casts from its photometric centre, where the solver's shadow rays start.
    found.extend(luminaires.iter().map(|l| {
        let light = Light { corners: vec![l.position], shine: Shine::Distribution(Box::new(l.clone())) };
        (luminaire_power(l), light)
    }));
    found.retain(|(power, _)| *power >= LIGHT_SHARE * total);
    // Brightest first; equal ones in a fixed order whatever the input's.
    found.sort_by(|a, b| b.0.total_cmp(&a.0).then_with(|| lexicographic(a.1.corners[0], b.1.corners[0])));
    found.into_iter().take(MAX_LIGHTS).map(|(_, l)| l).collect()
}

/// The convex solids of `scene`'s non-emitting polygons: sets of at least three faces joined
/// at exactly shared corners, every corner on or behind every face.
fn solids(scene: &Scene) -> Vec<Vec<DVec3>> {
    let faces: Vec<&Polygon> = scene
        .objects
        .iter()
        .filter(|o| !scene.materials[o.material].is_emitter())
        .flat_map(|o| polygons_of(&o.shape))
        .collect();
    // Union–find over faces: a face joins the first face met at each of its corners.
    let mut sets = UnionFind::new(faces.len());
    let mut first_at: HashMap<[u64; 3], u32> = HashMap::default();
    for (f, p) in (0u32..).zip(&faces) {
        for &q in p.vertices() {
            let other = *first_at.entry(key(q)).or_insert(f);
            sets.union(f, other);
        }
    }
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); faces.len()];
    for f in 0..faces.len() {
        members[sets.find(f as u32) as usize].push(f);
    }
    let mut out = Vec::new();
    for group in members.into_iter().filter(|g| g.len() >= 3) {
        let mut corners: Vec<DVec3> =
            group.iter().flat_map(|&f| faces[f].vertices().iter().copied()).collect();
        corners.sort_by(|a, b| lexicographic(*a, *b));
        corners.dedup_by_key(|q| key(*q));
        if corners.len() > MAX_SOLID_CORNERS {
            continue;
        }
        let (lo, hi) = bounds(&corners);
        let eps = 1e-6 * lo.distance(hi);
        let depth = |f: usize, q: DVec3| faces[f].normal().dot(q - faces[f].vertices()[0]);
        let convex = group.iter().all(|&f| corners.iter().all(|&q| depth(f, q) <= eps));
        // A solid, not faces of one plane: something lies behind some face.
        let thick = group.iter().any(|&f| corners.iter().any(|&q| depth(f, q) < -1e3 * eps));
        if convex && thick {
            out.push(corners);
        }
    }
    out
}

/// The convex hull of `pts` (on a plane with unit normal `n`), counter-clockwise about `n`,
/// without collinear corners (Andrew 1979, monotone chain).
pub(crate) fn hull(pts: &[DVec3], n: DVec3) -> Vec<DVec3> {
    if pts.len() < 3 {
        return Vec::new();
    }
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    let mut flat: Vec<(DVec2, DVec3)> = pts.iter().map(|&p| (DVec2::new(p.dot(u), p.dot(v)), p)).collect();
    flat.sort_by(|a, b| a.0.x.total_cmp(&b.0.x).then(a.0.y.total_cmp(&b.0.y)));
    let (lo, hi) = bounds(pts);
    let tiny = 1e-12 * lo.distance_squared(hi);
    let turn = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let mut chain: Vec<(DVec2, DVec3)> = Vec::with_capacity(2 * flat.len());
    for pass in [flat.clone(), flat.into_iter().rev().collect()] {
        let start = chain.len();
        for p in pass {
            while chain.len() >= start + 2
                && turn(chain[chain.len() - 2].0, chain[chain.len() - 1].0, p.0) <= tiny
            {
                chain.pop();
            }
            chain.push(p);
        }
        chain.pop(); // the next pass starts where this one ends
    }
    if chain.len() < 3 {
        return Vec::new();
    }
    chain.into_iter().map(|(_, p)| p).collect()
}

/// The intersection of convex polygons `a` and `b` (counter-clockwise about `n`).
fn intersect(a: &[DVec3], b: &[DVec3], n: DVec3) -> Vec<DVec3> {
    let mut rest = a.to_vec();
    for i in 0..b.len() {
        if rest.len() < 3 {
            return Vec::new();
        }
        let (p, q) = (b[i], b[(i + 1) % b.len()]);
        let inward = n.cross(q - p);
        rest = clip(&rest, |x| inward.dot(x - p));
    }
    rest
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Mesh;
    use crate::planar::contains_within;
    use radiosity_core::{Facing, box_faces};
    use radiosity_core::{Material, Object, Rgb};

    /// A 4 × 4 floor, a unit box turned 30° about the vertical standing on it, and a unit
    /// lamp 3 above the floor facing down.
    fn lamp_box_floor() -> (Scene, impl Fn(DVec3) -> DVec3) {
        let (sin, cos) = 30f64.to_radians().sin_cos();
        let turn = move |p: DVec3| DVec3::new(2.0 + cos * p.x - sin * p.z, p.y, 2.0 + sin * p.x + cos * p.z);
        let back = move |p: DVec3| {
            let q = p - DVec3::new(2.0, 0.0, 2.0);
            DVec3::new(cos * q.x + sin * q.z, q.y, -sin * q.x + cos * q.z)
        };
        let block: Vec<Polygon> =
            box_faces(DVec3::new(-0.5, 0.0, -0.5), DVec3::new(0.5, 1.0, 0.5), Facing::Outward, 0.0)
                .unwrap()
                .iter()
                .map(|p| p.try_map(turn).unwrap())
                .collect();
        let at = |y: f64, lo: f64, hi: f64| {
            vec![DVec3::new(lo, y, lo), DVec3::new(lo, y, hi), DVec3::new(hi, y, hi), DVec3::new(hi, y, lo)]
        };
        let floor = Polygon::try_new(at(0.0, 0.0, 4.0)).unwrap();
        let mut lamp_corners = at(3.0, 1.2, 2.2);
        lamp_corners.reverse();
        let lamp = Polygon::try_new(lamp_corners).unwrap();
        let grey = Material::try_new("grey", Rgb::splat(0.5), Rgb::ZERO).unwrap();
        let light = Material::try_new("lamp", Rgb::ZERO, Rgb::ONE).unwrap();
        let scene = Scene::try_new(
            "lamp over a box",
            None,
            vec![grey, light],
            vec![
                Object::new("floor", 0, Shape::Polygons(vec![floor])),
                Object::new("block", 0, Shape::Polygons(block)),
                Object::new("lamp", 1, Shape::Polygons(vec![lamp])),
            ],
        )
        .unwrap();
        (scene, back)
    }

    /// How many of a 64 × 64 grid of points on the lamp (y = 3, x and z in [1.2, 2.2]) the box
    /// hides from floor point `x`: the segment to each, taken into the box's own frame by
    /// `back`, against its slabs. Independent of the projections the outlines are made by.
    fn hidden_samples(x: DVec3, back: &impl Fn(DVec3) -> DVec3) -> usize {
        let k = 64;
        let mut hidden = 0;
        for i in 0..k {
            for j in 0..k {
                let p = DVec3::new(1.2 + (i as f64 + 0.5) / k as f64, 3.0, 1.2 + (j as f64 + 0.5) / k as f64);
                let (a, b) = (back(x), back(p));
                let d = b - a;
                let (mut t0, mut t1) = (0.0f64, 1.0f64);
                for (lo, hi, o, v) in [(-0.5, 0.5, a.x, d.x), (0.0, 1.0, a.y, d.y), (-0.5, 0.5, a.z, d.z)] {
                    let (s0, s1) = ((lo - o) / v, (hi - o) / v);
                    t0 = t0.max(s0.min(s1));
                    t1 = t1.min(s0.max(s1));
                }
                hidden += usize::from(t0 < t1);
            }
        }
        hidden
    }

    /// Just outside the penumbra's outline the whole lamp is seen, just inside it part is
    /// hidden; just inside the umbra's outline all of it is hidden, just outside some is seen.
    /// Checked at the middle of every outline edge on the open floor.
    #[test]
    fn outlines_bound_the_penumbra_and_the_umbra() {
        let (scene, back) = lamp_box_floor();
        let outlines = ShadowOutlines::new(&scene);
        assert_eq!((outlines.lights.len(), outlines.solids.len()), (1, 1));
        let Shape::Polygons(floor) = &scene.objects[0].shape else { unreachable!() };
        let found = outlines.outlines(&floor[0]);
        assert_eq!(found.len(), 2, "a penumbra and an umbra");
        let under_box = |x: DVec3| {
            let q = back(x);
            q.x.abs() < 0.5 && q.z.abs() < 0.5
        };
        let on_floor = |x: DVec3| (0.0..4.0).contains(&x.x) && (0.0..4.0).contains(&x.z);
        let delta = 0.02;
        let mut checked = [0, 0];
        for (which, outline) in found.iter().enumerate() {
            for i in 0..outline.len() {
                let (a, b) = (outline[i], outline[(i + 1) % outline.len()]);
                let out = (b - a).cross(DVec3::Y).normalize();
                let m = (a + b) / 2.0;
                let (outside, inside) = (m + out * delta, m - out * delta);
                if [outside, inside].iter().any(|&x| under_box(x) || !on_floor(x)) {
                    continue;
                }
                let (h_out, h_in) = (hidden_samples(outside, &back), hidden_samples(inside, &back));
                if which == 0 {
                    assert_eq!(h_out, 0, "outside the penumbra at {m}");
                    assert!(h_in > 0, "inside the penumbra at {m}");
                } else {
                    assert_eq!(h_in, 64 * 64, "inside the umbra at {m}");
                    assert!(h_out < 64 * 64, "outside the umbra at {m}");
                }
                checked[which] += 1;
            }
        }
        assert!(checked[0] >= 4 && checked[1] >= 2, "{checked:?} edges checked");
    }

    /// The Cornell box's floor is cut along the outlines its blocks cast from the lamp: no
    /// floor element lies across one (its corners, pulled a hair towards its centre, all on
    /// one side of each), while the floor meshed without outlines has elements across them.
    #[test]
    fn no_cornell_floor_element_lies_across_a_shadow_outline() {
        let scene = radiosity_scenes::cornell_box();
        let params = scene.mesh_params();
        let Shape::Polygons(floor) = &scene.objects[0].shape else { unreachable!() };
        let outlines = ShadowOutlines::new(&scene).outlines(&floor[0]);
        assert_eq!(outlines.len(), 4, "two blocks, each a penumbra and an umbra");
        let across = |mesh: &Mesh| {
            (0..mesh.elements.len())
                .filter(|&e| mesh.element_object(e) == 0)
                .filter(|&e| {
                    let c = mesh.elements[e].centre;
                    let corners: Vec<DVec3> = mesh.element_corners(e).map(|p| p + (c - p) * 1e-3).collect();
                    outlines.iter().any(|o| {
                        let inside: Vec<bool> =
                            corners.iter().map(|&p| contains_within(o, DVec3::Y, p, 0.0)).collect();
                        inside.iter().any(|&b| b) && !inside.iter().all(|&b| b)
                    })
                })
                .count()
        };
        let cut = Mesh::build(&scene, &params).unwrap();
        assert_eq!(across(&cut), 0);
        let uncut = Mesh::build(&scene, &params.with_shadow_outlines(false)).unwrap();
        assert!(across(&uncut) > 50, "{} elements across without outlines", across(&uncut));
    }

    /// A 4 × 4 floor, an axis-aligned unit box on it over x, z ∈ [1.5, 2.5], and an isotropic
    /// point luminaire at `LAMP` (no emitting polygon: `try_new_unlit`).
    fn luminaire_box_floor() -> Scene {
        let block =
            box_faces(DVec3::new(1.5, 0.0, 1.5), DVec3::new(2.5, 1.0, 2.5), Facing::Outward, 0.0).unwrap();
        let floor = Polygon::try_new(vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 0.0, 4.0),
            DVec3::new(4.0, 0.0, 4.0),
            DVec3::new(4.0, 0.0, 0.0),
        ])
        .unwrap();
        let grey = Material::try_new("grey", Rgb::splat(0.5), Rgb::ZERO).unwrap();
        let mut scene = Scene::try_new_unlit(
            "a downlight over a box",
            None,
            vec![grey],
            vec![
                Object::new("floor", 0, Shape::Polygons(vec![floor])),
                Object::new("block", 0, Shape::Polygons(block)),
            ],
        )
        .unwrap();
        let table = std::sync::Arc::new(radiosity_core::IntensityTable::isotropic(100.0));
        scene.lighting.luminaires.push(Luminaire::aimed("lamp", LAMP, -DVec3::Y, 0.0, table, 1.0, Rgb::ONE));
        scene
    }

    /// The luminaire's photometric centre in [`luminaire_box_floor`]: off the box's axis and at
    /// a height that puts no shadow line on a round coordinate.
    const LAMP: DVec3 = DVec3::new(1.05, 3.1, 1.3);

    /// How much of the segment from `a` to `b` on the floor the edges of the floor's elements
    /// cover (edges within 1e-6 of the segment's line, overlapping it), as a share of its
    /// length.
    fn covered(mesh: &Mesh, a: DVec3, b: DVec3) -> f64 {
        let along = (b - a).normalize();
        let length = a.distance(b);
        let off = |p: DVec3| (p - a - along * along.dot(p - a)).length();
        let mut spans: Vec<(f64, f64)> = Vec::new();
        for e in (0..mesh.elements.len()).filter(|&e| mesh.element_object(e) == 0) {
            let corners: Vec<DVec3> = mesh.element_corners(e).collect();
            for k in 0..corners.len() {
                let (p, q) = (corners[k], corners[(k + 1) % corners.len()]);
                if off(p) <= 1e-6 && off(q) <= 1e-6 {
                    let (s, t) = (along.dot(p - a), along.dot(q - a));
                    spans.push((s.min(t).max(0.0), s.max(t).min(length)));
                }
            }
        }
        spans.sort_by(|x, y| x.0.total_cmp(&y.0));
        let (mut total, mut reach) = (0.0, 0.0_f64);
        for (s, t) in spans {
            let s = s.max(reach);
            if t > s {
                total += t - s;
                reach = t;
            }
        }
        total / length
    }

    /// A point luminaire casts the box's hard shadow outline: the top's far corners projected
    /// from the lamp onto the floor, x' = L + (x − L)·h_L / (h_L − h_x) (similar triangles),
    /// bound the shadow by two straight lines, z = z' of the far top edge and x = x' of the
    /// right one, and element edges run along both of them for their whole length. Meshed
    /// without outlines, element edges cover less than half of either.
    #[test]
    fn a_point_luminaire_puts_element_edges_on_the_shadow_of_a_box() {
        let scene = luminaire_box_floor();
        let outlines = ShadowOutlines::new(&scene);
        assert_eq!((outlines.lights.len(), outlines.solids.len()), (1, 1));
        let Shape::Polygons(floor) = &scene.objects[0].shape else { unreachable!() };
        assert_eq!(outlines.outlines(&floor[0]).len(), 1, "one umbra, no penumbra");
        let cast = |x: f64, z: f64| {
            let top = DVec3::new(x, 1.0, z);
            let p = LAMP + (top - LAMP) * (LAMP.y / (LAMP.y - 1.0));
            DVec3::new(p.x, 0.0, p.z)
        };
        // The far top edge's shadow (z = z' from x'(1.5) to x'(2.5)), and the right top
        // edge's (x = x' from z'(1.5) to z'(2.5)).
        let far = (cast(1.5, 2.5), cast(2.5, 2.5));
        let right = (cast(2.5, 1.5), cast(2.5, 2.5));
        let params = scene.mesh_params();
        let cut = Mesh::build(&scene, &params).unwrap();
        for (a, b) in [far, right] {
            let share = covered(&cut, a, b);
            assert!(share > 0.999, "{share} of the shadow line {a} – {b} on element edges");
        }
        let uncut = Mesh::build(&scene, &params.with_shadow_outlines(false)).unwrap();
        for (a, b) in [far, right] {
            let share = covered(&uncut, a, b);
            assert!(share < 0.5, "{share} of {a} – {b} on element edges without outlines");
        }
    }

    /// Luminaires share the emitters' budget: one whose flux is under [`LIGHT_SHARE`] of the
    /// scene's light casts no outline, and no more than [`MAX_LIGHTS`] cast, the brightest first.
    #[test]
    fn dim_luminaires_cast_no_outlines_and_at_most_four_do() {
        let mut scene = luminaire_box_floor();
        let bright = scene.lighting.luminaires[0].clone();
        let mut dim = bright.clone();
        dim.scale = 0.05;
        dim.position = DVec3::new(3.0, 3.0, 3.0);
        scene.lighting.luminaires.push(dim);
        assert_eq!(ShadowOutlines::new(&scene).lights.len(), 1, "the dim one left out");
        for k in 0..6 {
            let mut l = bright.clone();
            l.position = DVec3::new(0.5 + 0.5 * f64::from(k), 3.0, 0.5);
            scene.lighting.luminaires.push(l);
        }
        let lights = ShadowOutlines::new(&scene).lights;
        assert_eq!(lights.len(), MAX_LIGHTS);
        assert!(lights.iter().all(|l| l.corners.len() == 1));
    }
}
