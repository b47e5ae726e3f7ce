//! Textures in pictures. The solve spreads each material's mean reflectance, which is what
//! diffuse transfer needs; a picture shows the texture by scaling the light a point reflects
//! by the texel's albedo over that mean, per channel: L = (E + (B − E)·ρ(uv)/ρ̄) / π.
//!
//! The mesh the solver meshed no longer follows the model's faces (coplanar faces are meshed
//! afresh as one surface), so a hit's texture coordinates come from the model's own faces:
//! the same ray is traced against a BVH of the textured faces, and the face it meets at the
//! same distance on the same object gives them, interpolated by its barycentric weights.
//! Texels are filtered bilinearly, in linear light, after wrapping (glTF's three modes).

use std::sync::Arc;

use glam::DVec3;
use radiosity_accel::{Bvh, RayQuery};
use radiosity_core::{Material, Rgb, Scene, Shape, Texture, srgb_decode};
use radiosity_mesh::{Mesh, wrapped};

/// The textured faces of a scene, as triangles a ray can meet.
pub(super) struct Textures {
    bvh: Bvh,
    /// Per BVH triangle: its object and the texture coordinates of its corners.
    faces: Vec<(u32, [[f64; 2]; 3])>,
    /// Per BVH triangle: its corners in double precision, for its affine texture map.
    corners: Vec<[DVec3; 3]>,
    /// How far along the ray the face may lie from the element's hit and still be its face:
    /// the two are the same plane up to the BVH's single precision.
    tolerance: f64,
}

impl Textures {
    /// The faces of `scene`'s mesh objects whose material has a texture and which have
    /// texture coordinates (fanned into triangles: faces are convex), or `None` when none.
    pub(super) fn new(scene: &Scene) -> Option<Self> {
        let mut triangles = Vec::new();
        let mut faces = Vec::new();
        let mut corners = Vec::new();
        for (o, object) in scene.objects.iter().enumerate() {
            let Shape::Mesh(mesh) = &object.shape else { continue };
            if scene.materials[object.material].texture.is_none() || mesh.uvs().is_empty() {
                continue;
            }
            for (face, uvs) in mesh.faces().iter().zip(mesh.uvs()) {
                for k in 1..face.len() - 1 {
                    let corner = |i: usize| mesh.positions()[face[i] as usize];
                    let triangle = [corner(0), corner(k), corner(k + 1)];
                    triangles.push(triangle.map(DVec3::as_vec3));
                    corners.push(triangle);
                    faces.push((o as u32, [uvs[0], uvs[k], uvs[k + 1]]));
                }
            }
        }
        if faces.is_empty() {
            return None;
        }
        let (lo, hi) = scene.bounds();
        Some(Self { bvh: Bvh::new(&triangles), faces, corners, tolerance: 1e-4 * (hi - lo).length() })
    }

    /// The textured face of `object` that the ray from `origin` along unit `dir` meets at
    /// `distance` (its BVH triangle), or `None`.
    fn face(&self, object: u32, origin: DVec3, dir: DVec3, distance: f64) -> Option<usize> {
        let reach = (distance + self.tolerance) as f32;
        let hit = self.bvh.closest_hit(origin.as_vec3(), dir.as_vec3(), reach)?;
        let (owner, _) = self.faces[hit.triangle as usize];
        (owner == object && (f64::from(hit.t) - distance).abs() <= self.tolerance)
            .then_some(hit.triangle as usize)
    }

    /// The textured face of `object` under `point` of a surface with unit normal `normal`:
    /// met by a ray along the normal from either side, so a face of the same object a little
    /// above the point (a thin slab's far side) does not hide it.
    fn face_under(&self, object: u32, point: DVec3, normal: DVec3) -> Option<usize> {
        // Far enough off the plane for the BVH's single precision, near enough that little
        // else of the object lies between.
        let h = 4.0 * self.tolerance;
        self.face(object, point + normal * h, -normal, h)
            .or_else(|| self.face(object, point - normal * h, normal, h))
    }

    /// Texture coordinates of `point` by face `f`'s affine map: its barycentric weights in the
    /// face's plane, extrapolated outside the face. `None` for a degenerate face.
    fn affine_uv(&self, f: usize, point: DVec3) -> Option<[f64; 2]> {
        let [a, b, c] = self.corners[f];
        let (e0, e1, d) = (b - a, c - a, point - a);
        let (d00, d01, d11) = (e0.dot(e0), e0.dot(e1), e1.dot(e1));
        let det = d00 * d11 - d01 * d01;
        if det <= 1e-12 * d00 * d11 || !det.is_finite() {
            return None;
        }
        let (d20, d21) = (d.dot(e0), d.dot(e1));
        let v = (d11 * d20 - d01 * d21) / det;
        let w = (d00 * d21 - d01 * d20) / det;
        let uvs = self.faces[f].1;
        Some([0, 1].map(|k| uvs[0][k] * (1.0 - v - w) + uvs[1][k] * v + uvs[2][k] * w))
    }

    /// The textured face of `object` nearest `point` (by the distance to its centroid), for an
    /// element no ray finds a face under: a last resort, searched face by face.
    fn nearest_face(&self, object: u32, point: DVec3) -> Option<usize> {
        (0..self.faces.len()).filter(|&f| self.faces[f].0 == object).min_by(|&f, &g| {
            let d = |f: usize| (self.corners[f].iter().sum::<DVec3>() / 3.0 - point).length_squared();
            d(f).total_cmp(&d(g))
        })
    }

    /// Texture coordinates where the ray from `origin` along unit `dir` meets `object` at
    /// `distance`, or `None` when no textured face of it lies there.
    pub(super) fn uv(&self, object: u32, origin: DVec3, dir: DVec3, distance: f64) -> Option<[f64; 2]> {
        let f = self.face(object, origin, dir, distance)?;
        self.affine_uv(f, origin + dir * distance)
    }
}

/// The albedo of `texture` at `uv`: the four nearest texels decoded from sRGB, weighted
/// bilinearly, times the texture's factor.
pub(super) fn albedo(texture: &Texture, uv: [f64; 2]) -> Rgb {
    let decode = |v: u8| srgb_decode(f64::from(v) / 255.0);
    // Texel centres lie at half-integers: (u·w − ½) is the texel coordinate.
    let x = uv[0] * f64::from(texture.width) - 0.5;
    let y = uv[1] * f64::from(texture.height) - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let (x0, y0) = (x0 as i64, y0 as i64);
    let mut sum = [0.0; 3];
    for (dy, wy) in [(0, 1.0 - fy), (1, fy)] {
        let row = wrapped(y0 + dy, texture.height, texture.wrap[1]);
        for (dx, wx) in [(0, 1.0 - fx), (1, fx)] {
            let column = wrapped(x0 + dx, texture.width, texture.wrap[0]);
            let texel = texture.texels[row * texture.width as usize + column];
            for c in 0..3 {
                sum[c] += wx * wy * decode(texel[c]);
            }
        }
    }
    Rgb::from_array([0, 1, 2].map(|c| sum[c] * texture.factor[c]))
}

/// Per channel, the albedo at `uv` over `material`'s mean reflectance (1 where the mean is
/// 0: nothing is reflected there to scale).
pub(super) fn ratio(material: &Material, texture: &Arc<Texture>, uv: [f64; 2]) -> Rgb {
    let texel = albedo(texture, uv).to_array();
    let mean = material.reflectance.to_array();
    Rgb::from_array([0, 1, 2].map(|c| if mean[c] > 0.0 { texel[c] / mean[c] } else { 1.0 }))
}

/// Light `b` leaving a point (radiosity, or radiance) as its texture shows it: the emitted
/// part `emitted` (in the same quantity) as it is, the reflected part scaled by `ratio`.
pub(super) fn shown(b: Rgb, emitted: Rgb, ratio: Rgb) -> Rgb {
    emitted + (b - emitted) * ratio
}

/// Texture coordinates of an element's corners, in its vertex order; only the first
/// `vertex_count` are meaningful (a triangle's fourth is `[0, 0]`).
pub type ElementUvs = [[f64; 2]; 4];

/// Per element of `mesh` (built from `scene`), the texture coordinates of its corners where its
/// object's material has a texture and its model mesh has texture coordinates; `None`
/// elsewhere. Empty when no object is textured.
///
/// The mesher remeshes coplanar faces as one surface, so elements do not follow the model's
/// faces: each element takes the affine texture map of the model face under its centre (found
/// by a ray along its normal, as pictures find a hit's face), extrapolated to its corners.
/// Where the map is continuous across faces this is exact for every corner; an element
/// straddling a seam of the map takes the map of the face under its centre. When no face lies
/// under the centre (it sits on an edge a single-precision ray slips through), points halfway
/// to each corner are tried, and then the face nearest the centre.
pub fn element_uvs(scene: &Scene, mesh: &Mesh) -> Vec<Option<ElementUvs>> {
    let Some(textures) = Textures::new(scene) else { return Vec::new() };
    let mut textured = vec![false; scene.objects.len()];
    for &(o, _) in &textures.faces {
        textured[o as usize] = true;
    }
    (0..mesh.elements.len())
        .map(|e| {
            let object = mesh.element_object(e);
            if !textured.get(object).copied().unwrap_or(false) {
                return None;
            }
            let corners: Vec<DVec3> = mesh.element_corners(e).collect();
            let centre = corners.iter().sum::<DVec3>() / corners.len() as f64;
            let normal = (corners[1] - corners[0]).cross(corners[2] - corners[0]).normalize_or_zero();
            let object = object as u32;
            let face = std::iter::once(centre)
                .chain(corners.iter().map(|&c| centre + (c - centre) * 0.5))
                .find_map(|p| textures.face_under(object, p, normal))
                .or_else(|| textures.nearest_face(object, centre))?;
            let mut uvs = [[0.0; 2]; 4];
            for (uv, &c) in uvs.iter_mut().zip(&corners) {
                *uv = textures.affine_uv(face, c)?;
            }
            Some(uvs)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiosity_core::Wrap;

    #[test]
    fn wrap_modes_bring_texels_back_into_the_image() {
        // A row of 4 texels: −1 is the last (repeat), the first (clamp), the first again
        // (mirrored: … 1 0 | 0 1 2 3 | 3 2 …).
        let row = |wrap| [-5, -1, 0, 3, 4, 7, 9].map(|i| wrapped(i, 4, wrap));
        assert_eq!(row(Wrap::Repeat), [3, 3, 0, 3, 0, 3, 1]);
        assert_eq!(row(Wrap::ClampToEdge), [0, 0, 0, 3, 3, 3, 3]);
        assert_eq!(row(Wrap::MirroredRepeat), [3, 0, 0, 3, 3, 0, 1]);
    }

    #[test]
    fn bilinear_albedo_is_exact_at_texel_centres_and_blends_between() {
        // Black | white, two texels in a row, white's factor halving green.
        let t = Texture {
            width: 2,
            height: 1,
            texels: vec![[0; 3], [255; 3]],
            factor: [1.0, 0.5, 1.0],
            wrap: [Wrap::ClampToEdge; 2],
            mask: None,
        };
        let at = |u: f64| albedo(&t, [u, 0.5]).to_array();
        assert_eq!(at(0.25), [0.0; 3]);
        assert_eq!(at(0.75), [1.0, 0.5, 1.0]);
        // Halfway between the centres: half of each, in linear light.
        assert!((at(0.5)[0] - 0.5).abs() < 1e-12, "{:?}", at(0.5));
        // Clamped past the edge; repeated, the far side of u = 0 is white again.
        assert_eq!(at(-3.0), [0.0; 3]);
        let repeat = Texture { wrap: [Wrap::Repeat; 2], ..t };
        assert!((albedo(&repeat, [0.0, 0.5]).to_array()[0] - 0.5).abs() < 1e-12);
    }

    #[test]
    fn the_ratio_keeps_emission_and_guards_a_black_mean() {
        let mut m = Material::try_new("m", Rgb::new(0.5, 0.0, 0.25), Rgb::new(1.0, 0.0, 0.0)).unwrap();
        let t = Arc::new(Texture {
            width: 1,
            height: 1,
            texels: vec![[255; 3]],
            factor: [0.9, 0.9, 0.5],
            wrap: [Wrap::Repeat; 2],
            mask: None,
        });
        m.texture = Some(t.clone());
        let r = ratio(&m, &t, [0.5, 0.5]).to_array();
        assert!((r[0] - 1.8).abs() < 1e-12 && r[1] == 1.0 && (r[2] - 2.0).abs() < 1e-12, "{r:?}");
        // B = E + reflected: only the reflected 2 doubles.
        let b = shown(Rgb::new(3.0, 0.0, 0.0), m.emission, Rgb::new(2.0, 1.0, 1.0));
        assert_eq!(b.to_array(), [5.0, 0.0, 0.0]);
    }

    /// Two coplanar model faces under one continuous, affine map (u = x/2 + ¼, v = z) are
    /// meshed as one surface: every element corner, on either face or across their shared
    /// edge, gets the map's own coordinates; the untextured lamp gets none.
    #[test]
    fn element_corners_take_the_affine_map_of_the_face_under_them() {
        use radiosity_core::{MeshParams, Object, PolygonMesh, Sides};
        let positions = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.0, 1.0], [1.0, 1.0], [2.0, 1.0]]
            .map(|[x, z]| DVec3::new(x, 0.0, z))
            .to_vec();
        // Counter-clockwise seen from above: both faces face up, towards the lamp.
        let faces = vec![vec![0, 3, 4, 1], vec![1, 4, 5, 2]];
        let map = |p: DVec3| [p.x / 2.0 + 0.25, p.z];
        let uvs = faces.iter().map(|f| f.iter().map(|&i| map(positions[i as usize])).collect()).collect();
        let floor_mesh = PolygonMesh::try_new(positions, faces).unwrap().with_uvs(uvs);
        let mut floor = Material::try_new("floor", Rgb::splat(0.5), Rgb::ZERO).unwrap();
        floor.texture = Some(Arc::new(Texture {
            width: 1,
            height: 1,
            texels: vec![[188; 3]],
            factor: [1.0; 3],
            wrap: [Wrap::Repeat; 2],
            mask: None,
        }));
        let light = Material::try_new("light", Rgb::ZERO, Rgb::splat(1.0)).unwrap();
        let lamp = radiosity_core::Polygon::try_new(vec![
            DVec3::new(0.5, 1.0, 0.25),
            DVec3::new(1.5, 1.0, 0.25),
            DVec3::new(1.5, 1.0, 0.75),
            DVec3::new(0.5, 1.0, 0.75),
        ])
        .unwrap();
        let objects = vec![
            Object { name: "floor".into(), material: 0, shape: Shape::Mesh(floor_mesh), sides: Sides::One },
            Object {
                name: "lamp".into(),
                material: 1,
                shape: Shape::Polygons(vec![lamp]),
                sides: Sides::One,
            },
        ];
        let scene = Scene::try_new("two faces", None, vec![floor, light], objects).unwrap();
        let params = MeshParams::try_new(0.3, 0.3).unwrap();
        let mesh = radiosity_solver::Problem::new(&scene, &params).unwrap().mesh().clone();
        let uvs = element_uvs(&scene, &mesh);
        assert_eq!(uvs.len(), mesh.elements.len());
        let mut textured = 0;
        for (e, uv) in uvs.iter().enumerate() {
            let is_floor = mesh.element_object(e) == 0;
            assert_eq!(uv.is_some(), is_floor, "element {e}");
            let Some(corners) = uv else { continue };
            textured += 1;
            for (uv, p) in corners.iter().zip(mesh.element_corners(e)) {
                let want = map(p);
                assert!((uv[0] - want[0]).abs() < 1e-9 && (uv[1] - want[1]).abs() < 1e-9, "{p}: {uv:?}");
            }
        }
        assert!(textured > 2, "{textured} floor elements");
    }
}
