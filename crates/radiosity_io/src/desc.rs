//! First stage of loading: the scene file as plain serde data, exactly as written.
//!
//! Every struct denies unknown keys, so a typo is an error that lists the expected keys
//! rather than a silently ignored setting. Values that the second stage validates are
//! wrapped in [`Spanned`], so that stage can say on which line the bad value sits.

use serde::de::Error as _;
use serde::{Deserialize, Deserializer};
use toml::Spanned;

/// A point `[x, y, z]` and where it was written.
pub(crate) type Point = Spanned<[f64; 3]>;

/// A polygon's vertex list and where it was written.
pub(crate) type Face = Spanned<Vec<Point>>;

/// Exactly three numbers: serde reads a `[f64; 3]` from the first three values of a longer
/// array and drops the rest, so `[x, y, z, w]` would pass silently.
pub(crate) struct Exactly3(pub(crate) [f64; 3]);

impl<'de> Deserialize<'de> for Exactly3 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let values = Vec::<f64>::deserialize(d)?;
        <[f64; 3]>::try_from(values.as_slice()).map(Exactly3).map_err(|_| {
            D::Error::custom(format!("invalid length {}, expected 3 numbers [x, y, z]", values.len()))
        })
    }
}

fn point_of(p: Spanned<Exactly3>) -> Point {
    let span = p.span();
    Spanned::new(span, p.into_inner().0)
}

fn face_of(f: Spanned<Vec<Spanned<Exactly3>>>) -> Face {
    let span = f.span();
    Spanned::new(span, f.into_inner().into_iter().map(point_of).collect())
}

/// A [`Point`] of exactly three numbers.
pub(crate) fn point<'de, D: Deserializer<'de>>(d: D) -> Result<Point, D::Error> {
    Spanned::<Exactly3>::deserialize(d).map(point_of)
}

/// An optional [`Point`] of exactly three numbers.
pub(crate) fn point_opt<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Point>, D::Error> {
    Ok(Option::<Spanned<Exactly3>>::deserialize(d)?.map(point_of))
}

/// An optional [`Face`] whose points are exactly three numbers.
fn face_opt<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Face>, D::Error> {
    Ok(Option::<Spanned<Vec<Spanned<Exactly3>>>>::deserialize(d)?.map(face_of))
}

/// Optional faces whose points are exactly three numbers.
fn faces_opt<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Spanned<Vec<Face>>>, D::Error> {
    Ok(Option::<Spanned<Vec<Spanned<Vec<Spanned<Exactly3>>>>>>::deserialize(d)?.map(|f| {
        let span = f.span();
        Spanned::new(span, f.into_inner().into_iter().map(face_of).collect())
    }))
}

/// The whole file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SceneDesc {
    /// Display name; defaults to the file stem.
    pub(crate) name: Option<String>,
    /// The file's up axis: `"x"`, `"y"` (default), `"z"`, `"-x"`, `"-y"` or `"-z"`; every
    /// coordinate of the file is in that frame.
    pub(crate) up: Option<Spanned<String>>,
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
    /// Length unit of every coordinate: `"m"`, `"cm"`, `"mm"`, `"in"` or `"ft"`.
    pub(crate) units: Option<Spanned<String>>,
    /// `[[luminaire]]` entries (photometric files placed in the scene).
    #[serde(default)]
    pub(crate) luminaire: Vec<Spanned<LuminaireDesc>>,
    /// `[[grid]]` entries (calculation grids).
    #[serde(default)]
    pub(crate) grid: Vec<Spanned<GridDesc>>,
    /// `[sun]`: parallel light from a direction at infinity.
    pub(crate) sun: Option<Spanned<SunDesc>>,
    /// `[sky]`: diffuse light from a dome at infinity.
    pub(crate) sky: Option<Spanned<SkyDesc>>,
}

/// `[sky]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SkyDesc {
    /// `"cie-overcast"` (default) or `"uniform"`.
    pub(crate) model: Option<Spanned<String>>,
    /// Illuminance on an unobstructed horizontal plane, lx (overcast: about 10 000).
    pub(crate) illuminance: Option<Spanned<f64>>,
    /// Irradiance on an unobstructed horizontal plane, W/unit² per channel.
    #[serde(deserialize_with = "point_opt", default)]
    pub(crate) irradiance: Option<Spanned<[f64; 3]>>,
    /// Linear RGB colour of `illuminance`'s light, scaled to luminance 1; default white.
    #[serde(deserialize_with = "point_opt", default)]
    pub(crate) colour: Option<Spanned<[f64; 3]>>,
    /// Colour as a correlated colour temperature, K.
    pub(crate) cct: Option<Spanned<f64>>,
    /// Shadow rays per element towards the sky.
    pub(crate) rays: Option<Spanned<i64>>,
    /// An equirectangular environment map (Radiance `.hdr`, linear radiance) as the sky,
    /// relative to the scene file.
    pub(crate) map: Option<Spanned<String>>,
    /// What the map's texels are multiplied by (default 1).
    pub(crate) scale: Option<Spanned<f64>>,
    /// Degrees the map is turned about the zenith, its middle column from north towards east.
    pub(crate) rotation: Option<Spanned<f64>>,
}

/// `[sun]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct SunDesc {
    /// Direction from the scene towards the sun, in the file's frame.
    #[serde(deserialize_with = "point_opt", default)]
    pub(crate) direction: Option<Spanned<[f64; 3]>>,
    /// Instead of `direction`: the site's latitude, degrees north...
    pub(crate) latitude: Option<Spanned<f64>>,
    /// ... its longitude, degrees east ...
    pub(crate) longitude: Option<Spanned<f64>>,
    /// ... and the date and time with its offset from UTC (a TOML offset date-time).
    pub(crate) time: Option<Spanned<toml::value::Datetime>>,
    /// Which way north is, in the file's frame: default −z (y-up files), the file's up
    /// axis turned to y otherwise.
    #[serde(deserialize_with = "point_opt", default)]
    pub(crate) north: Option<Spanned<[f64; 3]>>,
    /// Illuminance on a plane facing the sun, lx (clear noon: about 100 000).
    pub(crate) illuminance: Option<Spanned<f64>>,
    /// Irradiance on a plane facing the sun, W/unit² per channel, as `emission` is given.
    #[serde(deserialize_with = "point_opt", default)]
    pub(crate) irradiance: Option<Spanned<[f64; 3]>>,
    /// Linear RGB colour of `illuminance`'s light, scaled to luminance 1; default white.
    #[serde(deserialize_with = "point_opt", default)]
    pub(crate) colour: Option<Spanned<[f64; 3]>>,
    /// Colour as a correlated colour temperature, K.
    pub(crate) cct: Option<Spanned<f64>>,
}

/// `[camera]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct CameraDesc {
    /// Eye position.
    #[serde(deserialize_with = "point")]
    pub(crate) position: Point,
    /// Point looked at.
    #[serde(deserialize_with = "point")]
    pub(crate) look_at: Point,
    /// Up direction; default the file's up axis (`[0, 1, 0]` without one).
    #[serde(default, deserialize_with = "point_opt")]
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
    #[serde(deserialize_with = "point")]
    pub(crate) reflectance: Spanned<[f64; 3]>,
    /// Emitted radiosity W/m² per channel, each ≥ 0; default 0.
    #[serde(default, deserialize_with = "point_opt")]
    pub(crate) emission: Option<Spanned<[f64; 3]>>,
    /// Luminous flux of each whole object using the material, lm (instead of `emission`).
    pub(crate) lumens: Option<Spanned<f64>>,
    /// Luminance of the emitting faces, cd/m² (instead of `emission`).
    pub(crate) luminance: Option<Spanned<f64>>,
    /// Colour of `lumens` or `luminance` light, linear RGB (scaled to luminance 1).
    #[serde(default, deserialize_with = "point_opt")]
    pub(crate) colour: Option<Spanned<[f64; 3]>>,
    /// Colour of `lumens` or `luminance` light as a correlated colour temperature, K.
    pub(crate) cct: Option<Spanned<f64>>,
    /// Faces that exchange light, `1` (default) or `2` (signed so any other number gets our
    /// message, at its span).
    pub(crate) sides: Option<Spanned<i64>>,
    /// Faces that emit, `1` (default: the front) or `2` (the back too; needs `sides = 2`).
    pub(crate) emission_sides: Option<Spanned<i64>>,
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
    #[serde(default, deserialize_with = "face_opt")]
    pub(crate) vertices: Option<Face>,
    /// `polygons`: several vertex lists.
    #[serde(default, deserialize_with = "faces_opt")]
    pub(crate) faces: Option<Spanned<Vec<Face>>>,
    /// `box`: minimum corner.
    #[serde(default, deserialize_with = "point_opt")]
    pub(crate) min: Option<Point>,
    /// `box`: maximum corner.
    #[serde(default, deserialize_with = "point_opt")]
    pub(crate) max: Option<Point>,
    /// `box`, `sphere`: `"inward"` or `"outward"` (default).
    pub(crate) normals: Option<Spanned<String>>,
    /// `box`: rotation about the vertical axis through its centre, degrees; default 0.
    pub(crate) rotate_y_deg: Option<Spanned<f64>>,
    /// `sphere`: centre.
    #[serde(default, deserialize_with = "point_opt")]
    pub(crate) center: Option<Point>,
    /// `sphere`: radius > 0.
    pub(crate) radius: Option<Spanned<f64>>,
    /// `mesh`: OBJ or glTF file, relative to the scene file's folder.
    pub(crate) file: Option<Spanned<String>>,
    /// `mesh`: placement of the model.
    pub(crate) transform: Option<Spanned<TransformDesc>>,
    /// Any type: `1` or `2`, overriding the material's sides (for `mesh`, the model file's).
    pub(crate) sides: Option<Spanned<i64>>,
}

/// `transform = { … }` of a `mesh` object: scale, rotate about x, y, z, then translate.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct TransformDesc {
    /// Offset, scene units; default 0.
    #[serde(default, deserialize_with = "point_opt")]
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
    PerAxis(Exactly3),
}

/// `[mesh]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct MeshDesc {
    /// Longest patch edge, scene units, > 0.
    pub(crate) patch_size: Spanned<f64>,
    /// Longest element edge, scene units, > 0.
    pub(crate) element_size: Spanned<f64>,
    /// Smooth shading joins facets of one object bent by less than this, degrees in [0, 180).
    pub(crate) crease_angle: Option<Spanned<f64>>,
    /// Cut surfaces along the footprints of solids standing on them (default true).
    pub(crate) contacts: Option<bool>,
    /// Cut surfaces along the shadow outlines of convex solids (default true).
    pub(crate) shadow_outlines: Option<bool>,
    /// Halve elements along inside corners this many times, 0 to 6 (default 2).
    pub(crate) corner_refinement: Option<Spanned<u32>>,
    /// Quarter elements that other geometry comes nearer to than half their size this many
    /// times, 0 to 4 (default 1).
    pub(crate) proximity_refinement: Option<Spanned<u32>>,
    /// Levels of adaptive subdivision, 0 to 4 (default 2).
    pub(crate) adaptive_levels: Option<Spanned<u32>>,
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

/// One `[[luminaire]]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct LuminaireDesc {
    /// Name in reports; default the file stem.
    pub(crate) name: Option<String>,
    /// IES (`.ies`) or EULUMDAT (`.ldt`) file, relative to the scene file's folder.
    pub(crate) file: Spanned<String>,
    /// Photometric centre of one luminaire.
    #[serde(default, deserialize_with = "point_opt")]
    pub(crate) position: Option<Spanned<[f64; 3]>>,
    /// Photometric centres of a row of the same luminaire.
    pub(crate) positions: Option<Spanned<Vec<[f64; 3]>>>,
    /// Direction of the photometric nadir (γ = 0); default straight down.
    #[serde(default, deserialize_with = "point_opt")]
    pub(crate) aim: Option<Spanned<[f64; 3]>>,
    /// Turn of the C0 plane about the nadir towards C90 (counter-clockwise seen from above a
    /// downlight), degrees; default 0 (C0 towards +x).
    pub(crate) rotation_deg: Option<Spanned<f64>>,
    /// Luminous flux to scale each luminaire to, lm; default the file's.
    pub(crate) lumens: Option<Spanned<f64>>,
    /// Factor on the intensities (maintenance factor, dimming); default 1.
    pub(crate) multiplier: Option<Spanned<f64>>,
    /// Linear RGB colour of the light, scaled to luminance 1; default white.
    #[serde(default, deserialize_with = "point_opt")]
    pub(crate) colour: Option<Spanned<[f64; 3]>>,
    /// Colour as a correlated colour temperature, K.
    pub(crate) cct: Option<Spanned<f64>>,
    /// Whether receivers near the luminaire see its luminous opening (default) or a point.
    pub(crate) near_field: Option<bool>,
}

/// One `[[grid]]`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct GridDesc {
    /// Name in reports; default `grid N`.
    pub(crate) name: Option<String>,
    /// A corner of the rectangle.
    #[serde(default, deserialize_with = "point_opt")]
    pub(crate) origin: Option<Spanned<[f64; 3]>>,
    /// First edge.
    #[serde(default, deserialize_with = "point_opt")]
    pub(crate) u: Option<Spanned<[f64; 3]>>,
    /// Second edge.
    #[serde(default, deserialize_with = "point_opt")]
    pub(crate) v: Option<Spanned<[f64; 3]>>,
    /// Instead of `origin`, `u` and `v`: the name of a four-cornered `polygon` object whose
    /// front the grid covers.
    pub(crate) surface: Option<Spanned<String>>,
    /// Largest distance between points, scene units; default EN 12464-1's for the longer
    /// side.
    pub(crate) spacing: Option<Spanned<f64>>,
    /// Cells along u and v.
    pub(crate) divisions: Option<Spanned<[i64; 2]>>,
    /// Direction the illuminance is measured facing; default up.
    #[serde(default, deserialize_with = "point_opt")]
    pub(crate) normal: Option<Spanned<[f64; 3]>>,
    /// Offset of the points along the normal, scene units; default 0.
    pub(crate) height: Option<Spanned<f64>>,
}
