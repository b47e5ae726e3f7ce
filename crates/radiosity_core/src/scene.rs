//! Validated scene description: materials, objects (polygons, boxes, spheres), camera.
//!
//! Constructors here validate one piece at a time (`Material::try_new`, `Polygon::try_new`,
//! `Sphere::try_new`, `Scene::try_new`) so that a file loader can attach a file/line location
//! to each error it gets back.

use crate::limits::{MAX_COORDINATE, MAX_POLYGON_VERTICES};
use crate::{MeshParams, Rgb, SceneError};
use glam::DVec3;

/// A diffuse (Lambertian) material.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Unique name.
    pub name: String,
    /// Diffuse reflectance ρ per channel, each in [0, 1).
    pub reflectance: Rgb,
    /// Emitted radiosity (exitance) E per channel, W/m² (scene units² for area), each ≥ 0.
    pub emission: Rgb,
    /// Albedo per texel (a model's colour texture), for pictures only: `reflectance` is its
    /// mean, which is what diffuse transfer needs.
    pub texture: Option<std::sync::Arc<crate::Texture>>,
}

impl Material {
    /// A validated material.
    ///
    /// # Errors
    /// [`SceneError::ReflectanceOutOfRange`] when a channel of ρ is not in [0, 1) (ρ = 1 is the
    /// source document's "never stops" case), [`SceneError::EmissionOutOfRange`] when emission is
    /// negative or not finite.
    pub fn try_new(name: &str, reflectance: Rgb, emission: Rgb) -> Result<Self, SceneError> {
        let rho = reflectance.to_array();
        if !rho.iter().all(|&v| v.is_finite() && (0.0..1.0).contains(&v)) {
            return Err(SceneError::ReflectanceOutOfRange { material: name.to_owned(), value: rho });
        }
        let e = emission.to_array();
        if !e.iter().all(|&v| v.is_finite() && v >= 0.0) {
            return Err(SceneError::EmissionOutOfRange { material: name.to_owned(), value: e });
        }
        Ok(Self { name: name.to_owned(), reflectance, emission, texture: None })
    }

    /// True when the material emits in some channel.
    pub fn is_emitter(&self) -> bool {
        self.emission.max_channel() > 0.0
    }
}

/// Whether every coordinate of `p` is finite and within ±[`MAX_COORDINATE`].
pub fn coordinate_in_range(p: [f64; 3]) -> bool {
    p.iter().all(|c| c.is_finite() && c.abs() <= MAX_COORDINATE)
}

/// `p` as a point of a scene: finite, within ±[`MAX_COORDINATE`].
///
/// # Errors
/// [`SceneError::NonFiniteCoordinate`] or [`SceneError::CoordinateOutOfRange`].
pub fn check_coordinate(p: DVec3) -> Result<(), SceneError> {
    if !p.is_finite() {
        Err(SceneError::NonFiniteCoordinate { value: p.to_array() })
    } else if !coordinate_in_range(p.to_array()) {
        Err(SceneError::CoordinateOutOfRange { value: p.to_array(), limit: MAX_COORDINATE })
    } else {
        Ok(())
    }
}

/// A planar convex polygon, counter-clockwise seen from its lit (front) side.
#[derive(Clone, Debug, PartialEq)]
pub struct Polygon {
    vertices: Vec<DVec3>,
    normal: DVec3,
    area: f64,
}

impl Polygon {
    /// A validated polygon.
    ///
    /// Planarity tolerance is 1e-4 of the bounding box diagonal; that keeps measured data such as
    /// the Cornell box (whose non-planar red wall is given as two triangles) exact.
    ///
    /// Linear in the vertex count.
    ///
    /// # Errors
    /// Too few or too many vertices, non-finite coordinates or beyond [`MAX_COORDINATE`], zero
    /// area, non-planar or non-convex.
    pub fn try_new(vertices: Vec<DVec3>) -> Result<Self, SceneError> {
        if vertices.len() < 3 {
            return Err(SceneError::TooFewVertices { count: vertices.len() });
        }
        if vertices.len() > MAX_POLYGON_VERTICES {
            return Err(SceneError::TooManyVertices { count: vertices.len(), limit: MAX_POLYGON_VERTICES });
        }
        for &v in &vertices {
            check_coordinate(v)?;
        }
        // Newell's method: robust normal and area for any planar polygon.
        let mut n = DVec3::ZERO;
        for (i, &a) in vertices.iter().enumerate() {
            let b = vertices[(i + 1) % vertices.len()];
            n += a.cross(b);
        }
        let area = 0.5 * n.length();
        // The bounding box's diagonal stands for the diameter in the tolerances below: it is
        // within a factor √3 of it and linear to compute (the pairwise maximum took 80 s at
        // 10⁵ corners).
        let (lo, hi) =
            vertices.iter().fold((vertices[0], vertices[0]), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
        let diameter = lo.distance(hi);
        // NaN-safe: a NaN area must also be rejected, hence the explicit `is_nan`.
        if area.is_nan() || area <= 1e-12 * diameter * diameter || diameter == 0.0 {
            return Err(SceneError::DegeneratePolygon { area });
        }
        let normal = n / n.length();
        let centre = vertices.iter().copied().sum::<DVec3>() / vertices.len() as f64;
        let tolerance = 1e-4 * diameter;
        let distance = vertices.iter().map(|v| (*v - centre).dot(normal).abs()).fold(0.0, f64::max);
        if distance > tolerance {
            return Err(SceneError::NonPlanarPolygon { distance, tolerance });
        }
        let k = vertices.len();
        for i in 0..k {
            let a = vertices[(i + k - 1) % k];
            let b = vertices[i];
            let c = vertices[(i + 1) % k];
            // A slightly negative turn is allowed for collinear points given with round-off.
            if (b - a).cross(c - b).dot(normal) < -1e-9 * diameter * diameter {
                return Err(SceneError::NonConvexPolygon { vertex: i });
            }
        }
        Ok(Self { vertices, normal, area })
    }

    /// The vertices, counter-clockwise around [`Polygon::normal`].
    pub fn vertices(&self) -> &[DVec3] {
        &self.vertices
    }

    /// Unit normal of the lit side.
    pub fn normal(&self) -> DVec3 {
        self.normal
    }

    /// Area in scene units².
    pub fn area(&self) -> f64 {
        self.area
    }

    /// The same polygon lit from its other side: the first vertex kept, the rest in reverse
    /// order, the normal negated.
    pub fn flipped(&self) -> Self {
        let mut vertices = self.vertices.clone();
        vertices[1..].reverse();
        Self { vertices, normal: -self.normal, area: self.area }
    }

    /// The same polygon with its vertices transformed by `f` (must keep it planar and convex,
    /// e.g. a rigid motion or a uniform scale).
    ///
    /// # Errors
    /// As [`Polygon::try_new`] for the transformed vertices.
    pub fn try_map(&self, f: impl Fn(DVec3) -> DVec3) -> Result<Self, SceneError> {
        Self::try_new(self.vertices.iter().map(|&v| f(v)).collect())
    }

    /// The polygon with its vertices and normal mapped by `f`, a rotation that only swaps
    /// and negates coordinates ([`crate::UpAxis::to_y_up`]): exact, so the area and the
    /// validity need no new check (and a big model no second validation).
    pub(crate) fn mapped_exactly(&self, f: &impl Fn(DVec3) -> DVec3) -> Self {
        Self {
            vertices: self.vertices.iter().map(|&v| f(v)).collect(),
            normal: f(self.normal),
            area: self.area,
        }
    }
}

/// An indexed mesh of planar convex faces (triangles or larger polygons), as read from a model
/// file: vertices are shared by index, so faces that share an edge can be meshed into one
/// surface (see `Mesh::build`) and shade smoothly across it.
#[derive(Clone, Debug, PartialEq)]
pub struct PolygonMesh {
    positions: Vec<DVec3>,
    faces: Vec<Vec<u32>>,
    polygons: Vec<Polygon>,
    /// Texture coordinates per face corner, or empty.
    uvs: Vec<Vec<[f64; 2]>>,
}

impl PolygonMesh {
    /// A validated mesh: every index in range, every face a valid polygon
    /// ([`Polygon::try_new`]: 3+ vertices, finite, non-degenerate, planar, convex), counter-
    /// clockwise seen from its lit side. Positions are kept as given (no welding): faces are
    /// connected only where they use the same index.
    ///
    /// # Errors
    /// [`SceneError::EmptyMesh`], [`SceneError::VertexIndexOutOfRange`], or
    /// [`SceneError::BadMeshFace`] with the face number and the polygon's error.
    pub fn try_new(positions: Vec<DVec3>, faces: Vec<Vec<u32>>) -> Result<Self, SceneError> {
        if faces.is_empty() {
            return Err(SceneError::EmptyMesh);
        }
        let mut polygons = Vec::with_capacity(faces.len());
        for (face, f) in faces.iter().enumerate() {
            let mut vertices = Vec::with_capacity(f.len());
            for &i in f {
                let p = positions.get(i as usize).ok_or(SceneError::VertexIndexOutOfRange {
                    face,
                    index: i as usize,
                    count: positions.len(),
                })?;
                vertices.push(*p);
            }
            let polygon = Polygon::try_new(vertices)
                .map_err(|e| SceneError::BadMeshFace { face, source: Box::new(e) })?;
            polygons.push(polygon);
        }
        Ok(Self { positions, faces, polygons, uvs: Vec::new() })
    }

    /// The mesh with texture coordinates `uvs` per face corner (as [`PolygonMesh::uvs`]);
    /// left without them when `uvs` does not match the faces corner for corner.
    pub fn with_uvs(mut self, uvs: Vec<Vec<[f64; 2]>>) -> Self {
        let matches =
            uvs.len() == self.faces.len() && uvs.iter().zip(&self.faces).all(|(u, f)| u.len() == f.len());
        self.uvs =
            if matches && uvs.iter().flatten().flatten().all(|v| v.is_finite()) { uvs } else { Vec::new() };
        self
    }

    /// The same mesh with every face lit from its other side ([`Polygon::flipped`]).
    pub fn flipped(&self) -> Self {
        fn reversed<T: Clone>(f: &[T]) -> Vec<T> {
            let mut f = f.to_vec();
            f[1..].reverse();
            f
        }
        Self {
            positions: self.positions.clone(),
            faces: self.faces.iter().map(|f| reversed(f)).collect(),
            polygons: self.polygons.iter().map(Polygon::flipped).collect(),
            uvs: self.uvs.iter().map(|f| reversed(f)).collect(),
        }
    }

    /// The mesh with its positions and faces mapped by `f` ([`Polygon::mapped_exactly`]).
    pub(crate) fn mapped_exactly(&self, f: &impl Fn(DVec3) -> DVec3) -> Self {
        Self {
            positions: self.positions.iter().map(|&p| f(p)).collect(),
            faces: self.faces.clone(),
            polygons: self.polygons.iter().map(|p| p.mapped_exactly(f)).collect(),
            uvs: self.uvs.clone(),
        }
    }

    /// Vertex positions, scene units.
    pub fn positions(&self) -> &[DVec3] {
        &self.positions
    }

    /// Faces as vertex indices into [`PolygonMesh::positions`], counter-clockwise.
    pub fn faces(&self) -> &[Vec<u32>] {
        &self.faces
    }

    /// Faces as validated polygons (normal, area), in the order of [`PolygonMesh::faces`].
    pub fn polygons(&self) -> &[Polygon] {
        &self.polygons
    }

    /// Texture coordinates (u, v) per corner of each face, in the order of
    /// [`PolygonMesh::faces`] (v down from the image's top, as [`crate::Texture`]); empty
    /// when the model gives none.
    pub fn uvs(&self) -> &[Vec<[f64; 2]>] {
        &self.uvs
    }

    /// Total area, scene units².
    pub fn area(&self) -> f64 {
        self.polygons.iter().map(Polygon::area).sum()
    }
}

/// Which way the surface normals of a closed shape point.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Facing {
    /// Lit from outside (a block, a ball).
    #[default]
    Outward,
    /// Lit from inside (a room, a dome).
    Inward,
}

/// A sphere, tessellated when the scene is meshed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Centre, scene units.
    pub center: DVec3,
    /// Radius, scene units, > 0.
    pub radius: f64,
    /// Normals outward (a ball) or inward (a dome).
    pub facing: Facing,
}

impl Sphere {
    /// A validated sphere.
    ///
    /// # Errors
    /// [`SceneError::BadRadius`] when radius ≤ 0, not finite or over [`MAX_COORDINATE`]; a
    /// centre not finite or beyond ±[`MAX_COORDINATE`], or a sphere reaching beyond it
    /// ([`SceneError::CoordinateOutOfRange`] with its farthest point).
    pub fn try_new(center: DVec3, radius: f64, facing: Facing) -> Result<Self, SceneError> {
        check_coordinate(center)?;
        if !(radius.is_finite() && radius > 0.0 && radius <= MAX_COORDINATE) {
            return Err(SceneError::BadRadius { radius });
        }
        // Its bounds, not only its centre, are points of the scene.
        let farthest = center + center.signum() * radius;
        check_coordinate(farthest)?;
        Ok(Self { center, radius, facing })
    }
}

/// The six faces of an axis-aligned box, optionally rotated about the vertical (y) axis
/// through its centre.
///
/// # Errors
/// [`SceneError::EmptyBox`] when `min` is not below `max` on every axis; a corner not finite
/// or beyond ±[`MAX_COORDINATE`].
pub fn box_faces(
    min: DVec3,
    max: DVec3,
    facing: Facing,
    rotate_y_deg: f64,
) -> Result<Vec<Polygon>, SceneError> {
    check_coordinate(min)?;
    check_coordinate(max)?;
    if !(min.x < max.x && min.y < max.y && min.z < max.z && rotate_y_deg.is_finite()) {
        return Err(SceneError::EmptyBox { min: min.to_array(), max: max.to_array() });
    }
    let c =
        |x: usize, y: usize, z: usize| DVec3::new([min.x, max.x][x], [min.y, max.y][y], [min.z, max.z][z]);
    // Outward-facing faces, counter-clockwise seen from outside.
    let faces = [
        [c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1)], // bottom (-y)
        [c(0, 1, 0), c(0, 1, 1), c(1, 1, 1), c(1, 1, 0)], // top (+y)
        [c(0, 0, 0), c(0, 1, 0), c(1, 1, 0), c(1, 0, 0)], // -z
        [c(0, 0, 1), c(1, 0, 1), c(1, 1, 1), c(0, 1, 1)], // +z
        [c(0, 0, 0), c(0, 0, 1), c(0, 1, 1), c(0, 1, 0)], // -x
        [c(1, 0, 0), c(1, 1, 0), c(1, 1, 1), c(1, 0, 1)], // +x
    ];
    let centre = (min + max) * 0.5;
    let rot = glam::DQuat::from_rotation_y(rotate_y_deg.to_radians());
    faces
        .iter()
        .map(|f| {
            let mut v: Vec<DVec3> = f.iter().map(|&p| centre + rot * (p - centre)).collect();
            if facing == Facing::Inward {
                v.reverse();
            }
            Polygon::try_new(v)
        })
        .collect()
}

/// The geometry of one object.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// One or more planar convex polygons (`polygon`, `polygons`, `box`, meshes).
    Polygons(Vec<Polygon>),
    /// A sphere.
    Sphere(Sphere),
    /// An indexed mesh from a model file; coplanar faces that share edges become one surface.
    Mesh(PolygonMesh),
}

/// Which faces of an object take part in the exchange of light.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Sides {
    /// The face its normals point to only; the back is black and blocks light. Right for
    /// closed shapes and the walls of a room, and half the work of [`Sides::Two`].
    #[default]
    One,
    /// Both faces receive and reflect, each with its own radiosity (a sheet of paper, a wall
    /// modelled as one polygon seen from both rooms, a model whose normals are inconsistent).
    /// Emission leaves the front face only unless `emits_back`.
    Two {
        /// The back face emits the material's emission too.
        emits_back: bool,
    },
}

impl Sides {
    /// `1` or `2`, as written in scene files and reports.
    pub fn count(self) -> u8 {
        match self {
            Sides::One => 1,
            Sides::Two { .. } => 2,
        }
    }
}

/// A named object with one material.
#[derive(Clone, Debug, PartialEq)]
pub struct Object {
    /// Name, as reported per object in results.
    pub name: String,
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// Geometry.
    pub shape: Shape,
    /// Faces that exchange light.
    pub sides: Sides,
}

impl Object {
    /// Axis-aligned bounds of its geometry (lowest corner, highest corner).
    pub fn bounds(&self) -> (DVec3, DVec3) {
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        let mut take = |v: DVec3| {
            lo = lo.min(v);
            hi = hi.max(v);
        };
        match &self.shape {
            Shape::Polygons(ps) => ps.iter().flat_map(|p| p.vertices()).for_each(|v| take(*v)),
            Shape::Sphere(s) => {
                take(s.center - DVec3::splat(s.radius));
                take(s.center + DVec3::splat(s.radius));
            }
            Shape::Mesh(m) => m.positions().iter().for_each(|v| take(*v)),
        }
        (lo, hi)
    }

    /// A one-sided object.
    pub fn new(name: impl Into<String>, material: usize, shape: Shape) -> Self {
        Self { name: name.into(), material, shape, sides: Sides::One }
    }
}

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub position: DVec3,
    /// Point looked at.
    pub look_at: DVec3,
    /// Up direction (need not be orthogonal to the view direction).
    pub up: DVec3,
    /// Vertical field of view in degrees, in (0, 180).
    pub fov_y_deg: f64,
}

impl Camera {
    /// A validated camera.
    ///
    /// # Errors
    /// [`SceneError::BadCamera`] when position equals look_at, up is parallel to the view
    /// direction, the field of view is outside (0, 180), a value is not finite, or position or
    /// look_at lies beyond ±[`MAX_COORDINATE`].
    pub fn try_new(position: DVec3, look_at: DVec3, up: DVec3, fov_y_deg: f64) -> Result<Self, SceneError> {
        let bad = |reason: &str| Err(SceneError::BadCamera { reason: reason.to_owned() });
        if !(position.is_finite() && look_at.is_finite() && up.is_finite() && fov_y_deg.is_finite()) {
            return bad("a value is not finite");
        }
        if !(coordinate_in_range(position.to_array()) && coordinate_in_range(look_at.to_array())) {
            return Err(SceneError::BadCamera {
                reason: format!(
                    "position and look_at must be within ±{MAX_COORDINATE:e} of the origin, got position {:?}, look_at {:?}",
                    position.to_array(),
                    look_at.to_array()
                ),
            });
        }
        let dir = look_at - position;
        if dir.length() == 0.0 {
            return bad("position and look_at are the same point");
        }
        if dir.normalize().cross(up).length() < 1e-6 * up.length() || up.length() == 0.0 {
            return bad("up is zero or parallel to the viewing direction");
        }
        if !(fov_y_deg > 0.0 && fov_y_deg < 180.0) {
            return bad("fov_y_deg must be in (0, 180)");
        }
        Ok(Self { position, look_at, up, fov_y_deg })
    }

    /// A camera that frames the box `[min, max]` from the -z side, looking at its centre.
    pub fn framing(min: DVec3, max: DVec3) -> Self {
        Self::fitting(min, max, DVec3::Z, DVec3::Y)
    }

    /// A camera looking along `direction` at the centre of the box `[min, max]`, just far
    /// enough back that all eight corners fit a 4:3 picture with a 45° vertical field of view
    /// (a 5 % margin): the box fills the frame instead of its bounding sphere, which from a
    /// face leaves a third of the picture empty. `up` must not be parallel to `direction`.
    pub fn fitting(min: DVec3, max: DVec3, direction: DVec3, up: DVec3) -> Self {
        const ASPECT: f64 = 4.0 / 3.0;
        let fov_y_deg = 45.0_f64;
        let tan_y = (fov_y_deg.to_radians() * 0.5).tan();
        let forward = direction.normalize();
        let right = forward.cross(up).normalize();
        let true_up = right.cross(forward);
        let centre = (min + max) * 0.5;
        let half = (max - min) * 0.5;
        let mut distance: f64 = 1e-9;
        for i in 0..8 {
            let sign = |bit: usize| if i & bit == 0 { -1.0 } else { 1.0 };
            let c = DVec3::new(half.x * sign(1), half.y * sign(2), half.z * sign(4));
            // The corner's depth D + c·f must be at least |y| / tan and |x| / (tan · aspect).
            let needed = (c.dot(true_up).abs() / tan_y).max(c.dot(right).abs() / (tan_y * ASPECT));
            distance = distance.max(needed - c.dot(forward));
        }
        let distance = distance * 1.05;
        Self { position: centre - forward * distance, look_at: centre, up, fov_y_deg }
    }
}

/// Stop settings a scene file may carry for the solver (all optional; the solver has defaults).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolverSettings {
    /// Stop when unshot power / emitted power falls to this.
    pub unshot_threshold: Option<f64>,
    /// Stop after this many shots.
    pub max_shots: Option<u64>,
    /// Stop after this many seconds, in (0, [`MAX_TIME_LIMIT_SECONDS`]].
    pub time_limit: Option<f64>,
}

/// A validated scene: every material is in range, every object's material exists, and
/// something emits.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Display name.
    pub name: String,
    /// Camera given by the scene, if any.
    pub camera: Option<Camera>,
    /// Materials, referenced by index from objects.
    pub materials: Vec<Material>,
    /// Objects.
    pub objects: Vec<Object>,
    /// Subdivision given by the scene, if any (`None`: derived from the scene size).
    pub mesh: Option<MeshParams>,
    /// Stop settings given by the scene.
    pub solver: SolverSettings,
    /// Units, luminaires and calculation grids (photometry); empty by default.
    pub lighting: crate::Lighting,
}

impl Scene {
    /// A validated scene.
    ///
    /// # Errors
    /// [`SceneError::NoObjects`], [`SceneError::NoEmitter`], [`SceneError::DuplicateMaterial`],
    /// or an object whose material index is out of range (reported as
    /// [`SceneError::UnknownMaterial`]).
    pub fn try_new(
        name: &str,
        camera: Option<Camera>,
        materials: Vec<Material>,
        objects: Vec<Object>,
    ) -> Result<Self, SceneError> {
        Self::build(name, camera, materials, objects, true)
    }

    /// [`Scene::try_new`] without the light rule: for describing a scene (`info` on a model
    /// that has no light yet) rather than solving it, where a solve would only be black.
    ///
    /// # Errors
    /// As [`Scene::try_new`], except [`SceneError::NoEmitter`].
    pub fn try_new_unlit(
        name: &str,
        camera: Option<Camera>,
        materials: Vec<Material>,
        objects: Vec<Object>,
    ) -> Result<Self, SceneError> {
        Self::build(name, camera, materials, objects, false)
    }

    fn build(
        name: &str,
        camera: Option<Camera>,
        materials: Vec<Material>,
        objects: Vec<Object>,
        needs_light: bool,
    ) -> Result<Self, SceneError> {
        // A set, not a search of the list per material: that was quadratic (100 000
        // materials took 36 s).
        let mut names = std::collections::HashSet::with_capacity(materials.len());
        for m in &materials {
            if !names.insert(m.name.as_str()) {
                return Err(SceneError::DuplicateMaterial { name: m.name.clone() });
            }
        }
        if objects.is_empty() {
            return Err(SceneError::NoObjects);
        }
        for o in &objects {
            if o.material >= materials.len() {
                return Err(SceneError::UnknownMaterial {
                    object: o.name.clone(),
                    material: format!("#{}", o.material),
                    known: materials.iter().map(|m| m.name.as_str()).collect::<Vec<_>>().join(", "),
                });
            }
        }
        if needs_light && !objects.iter().any(|o| materials[o.material].is_emitter()) {
            return Err(SceneError::NoEmitter);
        }
        Ok(Self {
            name: name.to_owned(),
            camera,
            materials,
            objects,
            mesh: None,
            solver: SolverSettings::default(),
            lighting: crate::Lighting::default(),
        })
    }

    /// Axis-aligned bounds `(min, max)` of all geometry.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        self.objects
            .iter()
            .map(Object::bounds)
            .fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(lo, hi), (a, b)| {
                (lo.min(a), hi.max(b))
            })
    }

    /// Mesh parameters of the scene, or [`MeshParams::for_extent`] of its bounds.
    pub fn mesh_params(&self) -> MeshParams {
        self.mesh.unwrap_or_else(|| {
            let (lo, hi) = self.bounds();
            MeshParams::for_extent((hi - lo).length())
        })
    }

    /// Multiplies every light by `scale` (the seed document's light intensity, S11): every
    /// material's emission and every luminaire's intensity ([`crate::Luminaire::scale`]), the sun's and the sky's, so
    /// that `--light-scale` brightens a scene lit by photometric files as it does one lit by
    /// emissive surfaces.
    pub fn scale_emission(&mut self, scale: f64) {
        for m in &mut self.materials {
            m.emission *= scale;
        }
        for l in &mut self.lighting.luminaires {
            l.scale *= scale;
        }
        if let Some(sun) = &mut self.lighting.sun {
            sun.irradiance *= scale;
        }
        if let Some(sky) = &mut self.lighting.sky {
            sky.zenith_radiosity *= scale;
        }
    }

    /// Total emitted power per channel, Σ E·A over emitting objects (spheres use their exact
    /// area 4πR²).
    pub fn emitted_power(&self) -> Rgb {
        self.objects
            .iter()
            .map(|o| {
                let area = match &o.shape {
                    Shape::Polygons(ps) => ps.iter().map(Polygon::area).sum(),
                    Shape::Sphere(s) => 4.0 * std::f64::consts::PI * s.radius * s.radius,
                    Shape::Mesh(m) => m.area(),
                };
                self.materials[o.material].emission * area
            })
            .sum()
    }
}

/// Makes names unique in place by appending `#2`, `#3`, … to repeats, in order (the first
/// keeps its name): object names from model files, file names derived from object names.
pub fn unique_names(names: &mut [String]) {
    let mut seen: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
    for name in names.iter_mut() {
        let count = seen.entry(name.clone()).or_insert(0);
        *count += 1;
        if *count > 1 {
            *name = format!("{name}#{count}");
        }
    }
}
