//! Vocabulary of the `radiosity` renderer: linear colour ([`Rgb`]), validated scenes ([`Scene`],
//! [`Material`], [`Object`], [`Texture`]), how finely to mesh them ([`MeshParams`]; the mesher is
//! `radiosity_mesh`), camera rays, seeded random streams. The test scenes are `radiosity_scenes`.
//!
//! Units: positions in scene units (any length unit, used consistently), radiosity and
//! emission in W per unit², power in W.
#![warn(missing_docs)]
#![forbid(unsafe_code)]

mod color;
mod film;
mod limits;
mod mesh_params;
mod one_line;
mod photometry;
pub mod random;
mod scene;
mod scene_error;
mod sky_map;
mod srgb;
mod texture;
mod up;

pub use color::Rgb;
pub use film::CameraRays;
pub use limits::{MAX_COORDINATE, MAX_POLYGON_VERTICES, MAX_TIME_LIMIT_SECONDS};
pub use mesh_params::{
    DEFAULT_ADAPTIVE_LEVELS, DEFAULT_CORNER_REFINEMENT, DEFAULT_CREASE_ANGLE_DEG,
    DEFAULT_PROXIMITY_REFINEMENT, MAX_ADAPTIVE_LEVELS, MAX_CORNER_REFINEMENT, MAX_PROXIMITY_REFINEMENT,
    MeshParams,
};
pub use one_line::{MAX_PART_CHARS, escape_controls, one_line};
pub use photometry::{
    Daylight, Grid, IntensityError, IntensityTable, LUMENS_PER_WATT, LengthUnit, Lighting, Luminaire,
    NEAR_FIELD_RATIO, Opening, Sky, SkyModel, Sun, colour_of_cct, photometric_y, unit_luminance,
};
pub use scene::{
    Camera, Facing, Material, Object, Polygon, PolygonMesh, Scene, Shape, Sides, SolverSettings, Sphere,
    box_faces, check_coordinate, coordinate_in_range, unique_names,
};
pub use scene_error::SceneError;
pub use sky_map::SkyMap;
pub use srgb::{encode_srgb, srgb_decode, srgb_encode};
pub use texture::{Texture, Wrap};
pub use up::UpAxis;

/// Re-export of the vector maths used in the public API.
pub use glam;
