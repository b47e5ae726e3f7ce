//! Why a material, a piece of geometry or a whole scene is refused: one variant per rule, with
//! the offending values.

use thiserror::Error;

use crate::limits::MAX_COORDINATE;

/// Why a material, a piece of geometry or a whole scene is not acceptable.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum SceneError {
    /// A reflectance channel is outside [0, 1) or not finite.
    #[error(
        "reflectance of material '{material}' must be in [0, 1) in every channel, got {value:?} (ρ ≥ 1 never converges: energy is never lost)"
    )]
    ReflectanceOutOfRange {
        /// Material name.
        material: String,
        /// The offending `[r, g, b]`.
        value: [f64; 3],
    },
    /// An emission channel is negative or not finite.
    #[error("emission of material '{material}' must be finite and ≥ 0 in every channel, got {value:?}")]
    EmissionOutOfRange {
        /// Material name.
        material: String,
        /// The offending `[r, g, b]`.
        value: [f64; 3],
    },
    /// A coordinate is NaN or infinite.
    #[error("coordinates must be finite numbers, got {value:?}")]
    NonFiniteCoordinate {
        /// The offending point.
        value: [f64; 3],
    },
    /// A coordinate lies farther from the origin than [`MAX_COORDINATE`] on some axis.
    #[error(
        "coordinates must be within ±{limit:e} scene units of the origin, got {value:?}; move the scene nearer the origin or use larger units"
    )]
    CoordinateOutOfRange {
        /// The offending point.
        value: [f64; 3],
        /// [`MAX_COORDINATE`].
        limit: f64,
    },
    /// A polygon has fewer than three vertices.
    #[error("a polygon needs at least 3 vertices, got {count}")]
    TooFewVertices {
        /// Number of vertices given.
        count: usize,
    },
    /// A polygon has more vertices than [`MAX_POLYGON_VERTICES`].
    #[error(
        "polygon has {count} vertices, more than the {limit} accepted; give the curve fewer corners or as a model's triangles"
    )]
    TooManyVertices {
        /// Number of vertices given.
        count: usize,
        /// [`MAX_POLYGON_VERTICES`].
        limit: usize,
    },
    /// A polygon's area is zero (collinear or repeated vertices).
    #[error("polygon is degenerate: its area is {area:e}, its vertices are collinear or repeated")]
    DegeneratePolygon {
        /// Area found.
        area: f64,
    },
    /// A polygon's vertices do not lie in one plane.
    #[error(
        "polygon is not planar: a vertex is {distance:e} off the polygon's plane (tolerance {tolerance:e}); split it into triangles"
    )]
    NonPlanarPolygon {
        /// Largest distance of a vertex from the best-fit plane.
        distance: f64,
        /// Tolerance used.
        tolerance: f64,
    },
    /// A polygon is not convex.
    #[error("polygon is not convex at vertex {vertex}; split it into convex polygons")]
    NonConvexPolygon {
        /// Index of the offending vertex.
        vertex: usize,
    },
    /// A sphere radius is not a positive finite number, or is over [`MAX_COORDINATE`].
    #[error(
        "sphere radius must be a finite number > 0, got {radius}; the largest accepted is {MAX_COORDINATE:e}"
    )]
    BadRadius {
        /// Radius given.
        radius: f64,
    },
    /// A box has min ≥ max on some axis.
    #[error("box min must be below max on every axis, got min {min:?} max {max:?}")]
    EmptyBox {
        /// Minimum corner.
        min: [f64; 3],
        /// Maximum corner.
        max: [f64; 3],
    },
    /// An object names a material that does not exist.
    #[error("object '{object}' uses material '{material}', which is not defined (defined: {known})")]
    UnknownMaterial {
        /// Object name.
        object: String,
        /// Material name asked for.
        material: String,
        /// Comma-separated list of the defined materials.
        known: String,
    },
    /// Two materials share a name.
    #[error("material '{name}' is defined twice")]
    DuplicateMaterial {
        /// The repeated name.
        name: String,
    },
    /// Nothing in the scene emits light.
    #[error("the scene has no light: no object uses a material with emission > 0")]
    NoEmitter,
    /// The scene has no objects at all.
    #[error("the scene has no objects")]
    NoObjects,
    /// A mesh size parameter is not a positive finite number.
    #[error("{key} must be a finite number > 0, got {value}")]
    BadMeshSize {
        /// `patch_size` or `element_size`.
        key: &'static str,
        /// Value given.
        value: f64,
    },
    /// A crease angle outside [0, 180) degrees.
    #[error("crease_angle must be a number of degrees in [0, 180), got {value}")]
    BadCreaseAngle {
        /// Value given.
        value: f64,
    },
    /// A corner refinement beyond the largest allowed.
    #[error("corner_refinement must be a whole number in [0, 6], got {value}")]
    BadCornerRefinement {
        /// Value given.
        value: u32,
    },
    /// A proximity refinement beyond the largest allowed.
    #[error("proximity_refinement must be a whole number in [0, 4], got {value}")]
    BadProximityRefinement {
        /// Value given.
        value: u32,
    },
    /// Adaptive subdivision levels beyond the largest allowed.
    #[error("adaptive_levels must be a whole number in [0, 4], got {value}")]
    BadAdaptiveLevels {
        /// Value given.
        value: u32,
    },
    /// A camera is degenerate.
    #[error("camera is degenerate: {reason}")]
    BadCamera {
        /// What is wrong.
        reason: String,
    },
    /// A face of a polygon mesh refers to a vertex that does not exist.
    #[error("face {face}: vertex index {index} out of range (the mesh has {count} vertices)")]
    VertexIndexOutOfRange {
        /// 0-based face number.
        face: usize,
        /// The offending 0-based vertex index.
        index: usize,
        /// Number of vertices in the mesh.
        count: usize,
    },
    /// A face of a polygon mesh is not a valid polygon.
    #[error("face {face}: {source}")]
    BadMeshFace {
        /// 0-based face number.
        face: usize,
        /// Why the face's polygon was rejected.
        source: Box<SceneError>,
    },
    /// A polygon mesh has no faces.
    #[error("the mesh has no faces")]
    EmptyMesh,
}
