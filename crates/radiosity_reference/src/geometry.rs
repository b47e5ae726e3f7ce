//! The scene's input geometry as the estimator sees it: every input polygon (fan-triangulated
//! for the BVH, sampled by area), every sphere (exact, intersected analytically), one list of
//! primitives per object, and the emitters with their powers.
//!
//! Nothing here comes from the mesh: the reference must not share the solver's subdivision
//! (only the mesher's texel lookup of an alpha mask, which is the scene's definition).

use radiosity_accel::{Bvh, ClearTest, MaskedBvh, RayQuery};
use radiosity_core::glam::{DVec3, Vec3};
use radiosity_core::{Facing, Polygon, Rgb, Scene, Shape, Sides};
use radiosity_mesh::MaskedOccluder;

/// One piece of an object's surface.
#[derive(Clone, Debug)]
pub(crate) enum Primitive {
    /// A planar convex polygon: its fan triangles are `triangles` in [`Geometry::triangles`].
    Polygon {
        /// Unit normal of the lit side.
        normal: DVec3,
        /// First fan triangle and count.
        first_triangle: usize,
        /// Number of fan triangles.
        triangle_count: usize,
    },
    /// A sphere, lit from outside (`inward` false) or from inside.
    Sphere {
        /// Centre.
        center: DVec3,
        /// Radius, > 0.
        radius: f64,
        /// Lit from inside.
        inward: bool,
    },
}

/// A primitive with its object and area.
#[derive(Clone, Debug)]
pub(crate) struct Piece {
    pub object: u32,
    pub area: f64,
    pub shape: Primitive,
    /// The piece on the other face of a two-sided object: the same place with the normal
    /// reversed, in the back face's object. Back pieces are not in the BVH nor in `spheres`:
    /// a ray that meets a front piece from behind is handed to its twin.
    pub twin: Option<u32>,
}

/// A surface point reached by a ray or drawn on an object.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SurfacePoint {
    /// Position, world space.
    pub p: DVec3,
    /// Unit normal of the lit side.
    pub n: DVec3,
    /// The object.
    pub object: u32,
}

/// What a ray meets first.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RayHit {
    /// The point and its lit-side normal.
    pub point: SurfacePoint,
    /// True when the ray meets the lit side (radiosity surfaces are one-sided).
    pub front: bool,
}

/// Per object: name, material, area, and its pieces with a cumulative area table.
#[derive(Clone, Debug)]
pub(crate) struct ObjectGeometry {
    pub name: String,
    pub reflectance: Rgb,
    pub emission: Rgb,
    pub area: f64,
    /// Indices into [`Geometry::pieces`].
    pub pieces: Vec<u32>,
    /// Cumulative areas of `pieces`, last = `area`.
    pub cdf: Vec<f64>,
}

/// The whole scene for the estimator.
pub(crate) struct Geometry {
    pub pieces: Vec<Piece>,
    /// Fan triangles of every polygon, in f64.
    pub triangles: Vec<[DVec3; 3]>,
    /// The piece of each triangle.
    pub triangle_piece: Vec<u32>,
    /// Cumulative areas of each polygon's fan triangles (indexed like `triangles`), relative
    /// to the polygon's first triangle.
    pub triangle_cdf: Vec<f64>,
    pub bvh: Box<dyn RayQuery>,
    /// The fan triangles of alpha-masked faces: rays pass where the mask is clear, and a
    /// point drawn there is no surface.
    pub masked: Vec<MaskedOccluder>,
    /// Pieces that are spheres (tested analytically on every ray).
    pub spheres: Vec<u32>,
    pub objects: Vec<ObjectGeometry>,
    /// Per scene object, the index in `objects` of its back face (two-sided objects).
    pub back_objects: Vec<Option<u32>>,
    /// Emitting pieces and cumulative emitted power (channel sum) to choose them by.
    pub emitters: Vec<u32>,
    pub emitter_cdf: Vec<f64>,
    /// Distance rays start off their surface (and end off a lamp): 1e-6 of the scene's
    /// diagonal, as the solver's rays (above the BVH's single-precision error: about 18 of
    /// its steps at the scene's far corner). At 1e-5 it passed features: a 34 m hall's
    /// ceiling lights hang 0.25 mm under a lamp panel added there, and shadow rays to the
    /// panel, ending 0.34 mm below it, went past them where the solver's were stopped; the
    /// hall's high walls then read 2–3 % brighter than the solve.
    pub offset: f64,
    /// The scene's point luminaires (next-event estimation towards each, every vertex).
    pub luminaires: Vec<radiosity_core::Luminaire>,
    /// The scene's sun (next-event estimation towards it, every vertex) and how far a shadow
    /// ray towards it reaches: past the scene.
    pub sun: Option<(radiosity_core::Sun, f64)>,
    /// The scene's sky: what a path that leaves the scene meets.
    pub sky: Option<radiosity_core::Sky>,
}

/// Index of the first entry of the non-decreasing `cdf` that exceeds `u · total`.
pub(crate) fn pick(cdf: &[f64], u: f64) -> usize {
    let total = *cdf.last().expect("non-empty table");
    let x = u * total;
    cdf.partition_point(|&c| c <= x).min(cdf.len() - 1)
}

fn triangle_area(t: &[DVec3; 3]) -> f64 {
    0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length()
}

impl Geometry {
    pub fn new(scene: &Scene) -> Self {
        let mut g = Geometry {
            pieces: Vec::new(),
            triangles: Vec::new(),
            triangle_piece: Vec::new(),
            triangle_cdf: Vec::new(),
            bvh: Box::new(Bvh::new(&[])),
            masked: Vec::new(),
            spheres: Vec::new(),
            objects: Vec::new(),
            back_objects: vec![None; scene.objects.len()],
            emitters: Vec::new(),
            emitter_cdf: Vec::new(),
            offset: 0.0,
            luminaires: scene.lighting.luminaires.clone(),
            sun: None,
            sky: None,
        };
        for (oi, o) in scene.objects.iter().enumerate() {
            let material = &scene.materials[o.material];
            let mut object = ObjectGeometry {
                name: o.name.clone(),
                reflectance: material.reflectance,
                emission: material.emission,
                area: 0.0,
                pieces: Vec::new(),
                cdf: Vec::new(),
            };
            let mut add = |g: &mut Geometry, piece: Piece| {
                object.area += piece.area;
                object.pieces.push(g.pieces.len() as u32);
                object.cdf.push(object.area);
                g.pieces.push(piece);
            };
            match &o.shape {
                Shape::Polygons(ps) => {
                    for p in ps {
                        let piece = g.polygon(oi, p);
                        add(&mut g, piece);
                    }
                }
                Shape::Mesh(m) => {
                    // Masks of emitting materials are not applied (as in the mesh).
                    let mask =
                        material.texture.as_ref().filter(|t| t.mask.is_some() && !material.is_emitter());
                    for (f, p) in m.polygons().iter().enumerate() {
                        if let (Some(texture), Some(uv)) = (mask, m.uvs().get(f)) {
                            let first = g.triangles.len() as u32;
                            g.masked.extend((1..p.vertices().len() - 1).map(|i| MaskedOccluder {
                                occluder: first + i as u32 - 1,
                                uv: [uv[0], uv[i], uv[i + 1]],
                                texture: texture.clone(),
                            }));
                        }
                        let piece = g.polygon(oi, p);
                        add(&mut g, piece);
                    }
                }
                Shape::Sphere(s) => {
                    g.spheres.push(g.pieces.len() as u32);
                    let piece = Piece {
                        object: oi as u32,
                        area: 4.0 * std::f64::consts::PI * s.radius * s.radius,
                        shape: Primitive::Sphere {
                            center: s.center,
                            radius: s.radius,
                            inward: s.facing == Facing::Inward,
                        },
                        twin: None,
                    };
                    add(&mut g, piece);
                }
            }
            g.objects.push(object);
        }
        // Back faces of two-sided objects come after every scene object, in scene order, so
        // object i is still scene object i.
        for (oi, o) in scene.objects.iter().enumerate() {
            let Sides::Two { emits_back } = o.sides else { continue };
            let front = g.objects[oi].clone();
            let back_index = g.objects.len() as u32;
            g.back_objects[oi] = Some(back_index);
            let mut back = ObjectGeometry {
                name: format!("{} (back)", front.name),
                emission: if emits_back { front.emission } else { Rgb::ZERO },
                pieces: Vec::with_capacity(front.pieces.len()),
                ..front.clone()
            };
            for &p in &front.pieces {
                let mut piece = g.pieces[p as usize].clone();
                piece.object = back_index;
                piece.twin = Some(p);
                piece.shape = match piece.shape {
                    Primitive::Polygon { normal, first_triangle, triangle_count } => {
                        Primitive::Polygon { normal: -normal, first_triangle, triangle_count }
                    }
                    Primitive::Sphere { center, radius, inward } => {
                        Primitive::Sphere { center, radius, inward: !inward }
                    }
                };
                g.pieces[p as usize].twin = Some(g.pieces.len() as u32);
                back.pieces.push(g.pieces.len() as u32);
                g.pieces.push(piece);
            }
            g.objects.push(back);
        }
        let mut power = 0.0;
        for (i, piece) in g.pieces.iter().enumerate() {
            let e = g.objects[piece.object as usize].emission.sum();
            if e > 0.0 {
                power += e * piece.area;
                g.emitters.push(i as u32);
                g.emitter_cdf.push(power);
            }
        }
        let f32_triangles: Vec<[Vec3; 3]> = g.triangles.iter().map(|t| t.map(|v| v.as_vec3())).collect();
        g.bvh = if g.masked.is_empty() {
            Box::new(Bvh::new(&f32_triangles))
        } else {
            let masks = g.masked.clone();
            let clear: ClearTest = Box::new(move |k, u, v| masks[k].clear_at(f64::from(u), f64::from(v)));
            let positions: Vec<u32> = g.masked.iter().map(|m| m.occluder).collect();
            Box::new(MaskedBvh::new(&f32_triangles, &positions, clear))
        };
        let (lo, hi) = scene.bounds();
        g.offset = 1e-6 * (hi - lo).length().max(f64::MIN_POSITIVE);
        g.sun = scene.lighting.sun.map(|s| (s, 2.0 * (hi - lo).length().max(f64::MIN_POSITIVE)));
        g.sky = scene.lighting.sky.clone();
        g
    }

    fn polygon(&mut self, object: usize, p: &Polygon) -> Piece {
        let v = p.vertices();
        let first_triangle = self.triangles.len();
        let piece = self.pieces.len() as u32;
        let mut acc = 0.0;
        for i in 1..v.len() - 1 {
            let t = [v[0], v[i], v[i + 1]];
            acc += triangle_area(&t);
            self.triangles.push(t);
            self.triangle_piece.push(piece);
            self.triangle_cdf.push(acc);
        }
        Piece {
            object: object as u32,
            area: p.area(),
            shape: Primitive::Polygon { normal: p.normal(), first_triangle, triangle_count: v.len() - 2 },
            twin: None,
        }
    }

    /// A point drawn uniformly by area on `piece` from three uniform numbers.
    pub fn sample_piece(&self, piece: u32, u: [f64; 3]) -> SurfacePoint {
        let pc = &self.pieces[piece as usize];
        match pc.shape {
            Primitive::Polygon { normal, first_triangle, triangle_count } => {
                let cdf = &self.triangle_cdf[first_triangle..first_triangle + triangle_count];
                let t = &self.triangles[first_triangle + pick(cdf, u[0])];
                SurfacePoint { p: uniform_in_triangle(t, u[1], u[2]), n: normal, object: pc.object }
            }
            Primitive::Sphere { center, radius, inward } => {
                // Uniform on the sphere: z uniform in [−1, 1] (Archimedes' hat-box theorem).
                let z = 1.0 - 2.0 * u[1];
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = 2.0 * std::f64::consts::PI * u[2];
                let d = DVec3::new(r * phi.cos(), r * phi.sin(), z);
                SurfacePoint { p: center + d * radius, n: if inward { -d } else { d }, object: pc.object }
            }
        }
    }

    /// A point drawn uniformly by area on object `object`.
    pub fn sample_object(&self, object: u32, u: [f64; 4]) -> SurfacePoint {
        let o = &self.objects[object as usize];
        let piece = o.pieces[pick(&o.cdf, u[0])];
        self.sample_piece(piece, [u[1], u[2], u[3]])
    }

    /// Whether the point that [`Geometry::sample_object`] draws from `u` on `object` falls
    /// on a clear texel of an alpha-masked face: no surface there, so it has no radiosity.
    pub fn sample_is_clear(&self, object: u32, u: [f64; 4]) -> bool {
        if self.masked.is_empty() {
            return false;
        }
        let o = &self.objects[object as usize];
        let piece = &self.pieces[o.pieces[pick(&o.cdf, u[0])] as usize];
        // A back piece draws its twin's points.
        let Primitive::Polygon { first_triangle, triangle_count, .. } = piece.shape else { return false };
        let cdf = &self.triangle_cdf[first_triangle..first_triangle + triangle_count];
        let t = (first_triangle + pick(cdf, u[1])) as u32;
        let Ok(k) = self.masked.binary_search_by_key(&t, |m| m.occluder) else { return false };
        // `uniform_in_triangle`'s weights of the second and third corners.
        let s = u[2].sqrt();
        self.masked[k].clear_at(s * (1.0 - u[3]), s * u[3])
    }

    /// The point `p` on piece `piece` (lit-side normal `n`) as a ray along `dir` sees it: on
    /// the piece's back face, when it has one and the ray comes from behind.
    fn facing(&self, piece: u32, p: DVec3, n: DVec3, dir: DVec3) -> SurfacePoint {
        match self.pieces[piece as usize].twin {
            Some(twin) if n.dot(dir) > 0.0 => {
                SurfacePoint { p, n: -n, object: self.pieces[twin as usize].object }
            }
            _ => SurfacePoint { p, n, object: self.pieces[piece as usize].object },
        }
    }

    /// The first surface along `origin + t·dir` (`dir` unit), t > 0.
    pub fn intersect(&self, origin: DVec3, dir: DVec3) -> Option<RayHit> {
        let mut best: Option<(f64, SurfacePoint)> = None;
        if let Some(hit) = self.bvh.closest_hit(origin.as_vec3(), dir.as_vec3(), f32::MAX) {
            let piece_index = self.triangle_piece[hit.triangle as usize];
            let piece = &self.pieces[piece_index as usize];
            let Primitive::Polygon { normal, .. } = piece.shape else {
                unreachable!("triangles are polygons")
            };
            // The hit again in double precision, on the polygon's plane.
            let t0 = self.triangles[hit.triangle as usize][0];
            let denom = normal.dot(dir);
            let t = if denom.abs() > 1e-12 { normal.dot(t0 - origin) / denom } else { f64::from(hit.t) };
            best = Some((t, self.facing(piece_index, origin + dir * t, normal, dir)));
        }
        for &s in &self.spheres {
            let piece = &self.pieces[s as usize];
            let Primitive::Sphere { center, radius, inward } = piece.shape else { continue };
            let limit = best.map_or(f64::INFINITY, |b| b.0);
            if let Some(t) = sphere_hit(center, radius, origin, dir, 1e-3 * self.offset, limit) {
                let p = origin + dir * t;
                let out = (p - center) / radius;
                best = Some((t, self.facing(s, p, if inward { -out } else { out }, dir)));
            }
        }
        best.map(|(_, point)| RayHit { point, front: point.n.dot(dir) < 0.0 })
    }

    /// True when something lies along the ray from `from` along unit `dir` before `reach`
    /// (towards light at infinity), its start excluded by 1e-8 of `reach`, not 1e-4: see
    /// `RayQuery::occluded_towards`, which the triangles take; a sphere's test takes the
    /// same margin.
    pub fn occluded_towards(&self, from: DVec3, dir: DVec3, reach: f64) -> bool {
        if self.bvh.occluded_towards(from.as_vec3(), dir.as_vec3(), reach as f32) {
            return true;
        }
        self.spheres.iter().any(|&s| {
            let Primitive::Sphere { center, radius, .. } = self.pieces[s as usize].shape else {
                return false;
            };
            sphere_hit(center, radius, from, dir, 1e-8 * reach, reach).is_some()
        })
    }

    /// True when something lies strictly between `from` and `to` (both ends excluded by
    /// 1e-4 of the segment, as the BVH does).
    pub fn occluded(&self, from: DVec3, to: DVec3) -> bool {
        if self.bvh.occluded(from.as_vec3(), to.as_vec3()) {
            return true;
        }
        let d = to - from;
        let len = d.length();
        self.spheres.iter().any(|&s| {
            let Primitive::Sphere { center, radius, .. } = self.pieces[s as usize].shape else {
                return false;
            };
            sphere_hit(center, radius, from, d / len, 1e-4 * len, (1.0 - 1e-4) * len).is_some()
        })
    }
}

/// Uniform point in a triangle from two uniform numbers (Osada et al. 2002, eq. 1).
fn uniform_in_triangle(t: &[DVec3; 3], u: f64, v: f64) -> DVec3 {
    let s = u.sqrt();
    t[0] * (1.0 - s) + t[1] * (s * (1.0 - v)) + t[2] * (s * v)
}

/// Smallest root t of |o + t·d − c| = r in (t_min, t_max) (`d` unit).
fn sphere_hit(center: DVec3, radius: f64, o: DVec3, d: DVec3, t_min: f64, t_max: f64) -> Option<f64> {
    let oc = o - center;
    let b = oc.dot(d);
    // c computed as (|oc| − r)(|oc| + r) keeps precision for points near the surface.
    let l = oc.length();
    let c = (l - radius) * (l + radius);
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    let sq = disc.sqrt();
    // Numerically stable pair of roots (Press et al., Numerical Recipes §5.6).
    let q = -(b + sq.copysign(b));
    let (t1, t2) = if q != 0.0 { (q, c / q) } else { (-b, -b) };
    let (t1, t2) = (t1.min(t2), t1.max(t2));
    [t1, t2].into_iter().find(|&t| t > t_min && t < t_max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_roots_are_found_from_outside_and_inside() {
        let t = sphere_hit(DVec3::ZERO, 1.0, DVec3::new(0.0, 0.0, -3.0), DVec3::Z, 0.0, f64::INFINITY);
        assert!((t.unwrap() - 2.0).abs() < 1e-12);
        let t = sphere_hit(DVec3::ZERO, 1.0, DVec3::ZERO, DVec3::Z, 0.0, f64::INFINITY);
        assert!((t.unwrap() - 1.0).abs() < 1e-12);
        assert!(sphere_hit(DVec3::ZERO, 1.0, DVec3::new(0.0, 2.0, -3.0), DVec3::Z, 0.0, 9.0).is_none());
    }

    #[test]
    fn pick_follows_the_table() {
        let cdf = [1.0, 1.0, 3.0];
        assert_eq!(pick(&cdf, 0.0), 0);
        assert_eq!(pick(&cdf, 0.5), 2);
        assert_eq!(pick(&cdf, 0.9999), 2);
    }
}
