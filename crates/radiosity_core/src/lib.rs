//! Vocabulary of the `radiosity` renderer: linear colour ([`Rgb`]), validated scenes
//! ([`Scene`], [`Material`], [`Object`]), and meshing into shooting patches and receiving
//! elements ([`Mesh`], [`MeshParams`]).
//!
//! Units: positions in scene units (any length unit, used consistently), radiosity and
//! emission in W per unit², power in W.
#![warn(missing_docs)]
#![forbid(unsafe_code)]

mod auto_camera;
mod canonical;
mod color;
mod contacts;
mod film;
mod grading;
mod mesh;
mod one_line;
mod photometry;
mod planar;
pub mod random;
mod scene;
mod sealed;
mod shadows;
mod srgb;
mod up;

pub use canonical::{
    cornell_box, furnace_box, furnace_sphere, two_plates, two_sided_plate, unit_cube_floor_light,
    uv_sphere_mesh,
};
pub use color::Rgb;
pub use film::CameraRays;
pub use mesh::{
    DEFAULT_ADAPTIVE_LEVELS, DEFAULT_CORNER_REFINEMENT, DEFAULT_CREASE_ANGLE_DEG,
    DEFAULT_PROXIMITY_REFINEMENT, Element, MAX_ADAPTIVE_LEVELS, MAX_CORNER_REFINEMENT, MAX_ELEMENTS,
    MAX_PROXIMITY_REFINEMENT, Mesh, MeshError, MeshParams, Patch, Refinement, Smoothing, Surface,
    estimate_elements, first_object_over_limit,
};
pub use one_line::{MAX_PART_CHARS, escape_controls, one_line};
pub use photometry::{
    Grid, IntensityError, IntensityTable, LUMENS_PER_WATT, LengthUnit, Lighting, Luminaire, colour_of_cct,
    photometric_y, unit_luminance,
};
pub use planar::distance_to_polygon;
pub use scene::{
    Camera, Facing, MAX_COORDINATE, MAX_POLYGON_VERTICES, MAX_TIME_LIMIT_SECONDS, Material, Object, Polygon,
    PolygonMesh, Scene, SceneError, Shape, Sides, SolverSettings, Sphere, box_faces, check_coordinate,
    coordinate_in_range, unique_names,
};
pub use sealed::{MAX_HOLE_SHARE, Sealed, seal_closed_objects};
pub use srgb::{encode_srgb, srgb_decode, srgb_encode};
pub use up::{UpAxis, UpGuess};

/// Re-export of the vector maths used in the public API.
pub use glam;
