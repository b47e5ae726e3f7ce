//! First stage of loading: the scene file as plain serde data, exactly as written.
//!
//! Every struct denies unknown keys, so a typo is an error that lists the expected keys
//! rather than a silently ignored setting. Values that the second stage validates are
//! wrapped in [`Spanned`], so that stage can say on which line the bad value sits.

use serde::Deserialize;
use toml::Spanned;

/// A point `[x, y, z]` and where it was written.
pub(crate) type Point = Spanned<[f64; 3]>;

/// A polygon's vertex list and where it was written.
pub(crate) type Face = Spanned<Vec<Point>>;

/// The whole file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SceneDesc {
    /// Display name; defaults to the file stem.
    pub(crate) name: Option<String>,
    /// `[camera]`; without it the renderer frames the scene.
    pub(crate) camera: Option<Spanned<CameraDesc>>,
    /// `[[material]]` entries.
    #[serde(default)]
    pub(crate) material: Vec<Spanned<MaterialDesc>>,
    /// `[[object]]` entries.
    #[serde(default)]
    pub(crate) object: Vec<Spanned<ObjectDesc>>,
    /// `[mesh]`; without it the sizes follow from the scene's extent.
    pub(crate) mesh: Option<MeshDesc>,
    /// `[solver]`; every key optional.
    pub(crate) solver: Option<SolverDesc>,
}

/// `[camera]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct CameraDesc {
    /// Eye position.
    pub(crate) position: Point,
    /// Point looked at.
    pub(crate) look_at: Point,
    /// Up direction; default `[0, 1, 0]`.
    pub(crate) up: Option<Point>,
    /// Vertical field of view in degrees, in (0, 180); default 45.
    pub(crate) fov_y_deg: Option<Spanned<f64>>,
}

/// One `[[material]]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct MaterialDesc {
    /// Unique name, referenced by objects.
    pub(crate) name: Spanned<String>,
    /// ρ per channel, each in [0, 1).
    pub(crate) reflectance: Spanned<[f64; 3]>,
    /// Emitted radiosity W/m² per channel, each ≥ 0; default 0.
    pub(crate) emission: Option<Spanned<[f64; 3]>>,
}

/// One `[[object]]`: a flat struct rather than an enum tagged by `type`, because serde's
/// internally tagged enums buffer their content and lose the spans that errors need. Which
/// fields a type takes is checked in the second stage.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ObjectDesc {
    /// Name, as reported per object in results.
    pub(crate) name: Spanned<String>,
    /// `polygon`, `polygons`, `box`, `sphere` or `mesh`.
    #[serde(rename = "type")]
    pub(crate) kind: Spanned<String>,
    /// Name of a `[[material]]`; required except for `mesh`, where it overrides the file's
    /// materials.
    pub(crate) material: Option<Spanned<String>>,
    /// `polygon`: the vertices, counter-clockwise seen from the lit side.
    pub(crate) vertices: Option<Face>,
    /// `polygons`: several vertex lists.
    pub(crate) faces: Option<Spanned<Vec<Face>>>,
    /// `box`: minimum corner.
    pub(crate) min: Option<Point>,
    /// `box`: maximum corner.
    pub(crate) max: Option<Point>,
    /// `box`, `sphere`: `"inward"` or `"outward"` (default).
    pub(crate) normals: Option<Spanned<String>>,
    /// `box`: rotation about the vertical axis through its centre, degrees; default 0.
    pub(crate) rotate_y_deg: Option<Spanned<f64>>,
    /// `sphere`: centre.
    pub(crate) center: Option<Point>,
    /// `sphere`: radius > 0.
    pub(crate) radius: Option<Spanned<f64>>,
    /// `mesh`: OBJ or glTF file, relative to the scene file's folder.
    pub(crate) file: Option<Spanned<String>>,
    /// `mesh`: placement of the model.
    pub(crate) transform: Option<Spanned<TransformDesc>>,
}

/// `transform = { … }` of a `mesh` object: scale, rotate about x, y, z, then translate.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct TransformDesc {
    /// Offset, scene units; default 0.
    pub(crate) translate: Option<Spanned<[f64; 3]>>,
    /// One number or one per axis, each finite and ≠ 0; default 1.
    pub(crate) scale: Option<Spanned<Scale>>,
    /// Degrees about x; default 0.
    pub(crate) rotate_x_deg: Option<Spanned<f64>>,
    /// Degrees about y; default 0.
    pub(crate) rotate_y_deg: Option<Spanned<f64>>,
    /// Degrees about z; default 0.
    pub(crate) rotate_z_deg: Option<Spanned<f64>>,
}

/// A uniform or per-axis scale.
#[derive(Deserialize)]
#[serde(untagged, expecting = "a number or [x, y, z]")]
pub(crate) enum Scale {
    /// The same factor on every axis.
    Uniform(f64),
    /// One factor per axis.
    PerAxis([f64; 3]),
}

/// `[mesh]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct MeshDesc {
    /// Longest patch edge, scene units, > 0.
    pub(crate) patch_size: Spanned<f64>,
    /// Longest element edge, scene units, > 0.
    pub(crate) element_size: Spanned<f64>,
}

/// `[solver]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SolverDesc {
    /// Stop when unshot / emitted power falls to this, in (0, 1).
    pub(crate) unshot_threshold: Option<Spanned<f64>>,
    /// Stop after this many shots, ≥ 1 (signed so a negative value gets our message).
    pub(crate) max_shots: Option<Spanned<i64>>,
    /// Stop after this many seconds, > 0.
    pub(crate) time_limit: Option<Spanned<f64>>,
}
