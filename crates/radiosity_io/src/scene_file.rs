//! Second stage of loading: [`SceneDesc`] → validated core [`Scene`].
//!
//! Validation itself lives in the core's constructors (`Material::try_new`,
//! `Polygon::try_new`, `box_faces`, `Sphere::try_new`, `Camera::try_new`,
//! `MeshParams::try_new`, `Scene::try_new`), so a scene built in code and one read from a file
//! obey the same rules; this module only decides *where* in the file each error points: the
//! offending value's span, down to the vertex for a non-finite or non-convex corner.

use rustc_hash::FxHashMap as HashMap;
use std::ops::Range;
use std::path::Path;

use radiosity_core::glam::DVec3;
use radiosity_core::{
    Camera, Facing, LengthUnit, Material, Object, Polygon, Rgb, Scene, SceneError, Shape, Sides, Sphere,
    UpAxis, box_faces,
};
use toml::Spanned;

use crate::LoadError;
use crate::desc::{CameraDesc, Face, MaterialDesc, ObjectDesc, Scale, SceneDesc, TransformDesc};
use crate::load_model::load_model;
use crate::locate::Locator;
use crate::model::{ModelFormat, Transform, model_error};
use crate::scene_settings::{mesh_params, solver_settings};

/// Camera vertical field of view in degrees when the file gives none.
const DEFAULT_FOV_Y_DEG: f64 = 45.0;

fn v3(a: [f64; 3]) -> DVec3 {
    DVec3::from_array(a)
}

fn all_finite(a: &[f64; 3]) -> bool {
    a.iter().all(|c| c.is_finite())
}

/// Finite and within ±[`radiosity_core::MAX_COORDINATE`]: a point the core accepts.
fn in_range(a: &[f64; 3]) -> bool {
    radiosity_core::coordinate_in_range(*a)
}

/// A scene and what the loader dropped or defaulted on the way (degenerate faces of a model,
/// a missing MTL file), one line each, for the user to read. What every scene loader returns:
/// a caller that shows nothing to a user may take `.scene` alone.
#[derive(Clone, Debug)]
pub struct LoadedScene {
    /// The validated scene.
    pub scene: Scene,
    /// Warnings, each one line naming its file.
    pub warnings: Vec<String>,
    /// Only when loaded with [`LoadOptions::allow_no_light`] and nothing emits: the error a
    /// strict load gives, for a caller that describes the scene to report, or one that
    /// solves it to return once the warnings (which may explain it) are out.
    pub no_light: Option<LoadError>,
    /// The up axis the scene was declared with ([`LoadOptions::up`], else a scene file's
    /// `up` key), already applied: the scene is in the renderer's +y-up frame, and
    /// [`UpAxis::from_y_up`] takes its coordinates back to the file's. `None` when nothing
    /// declared one and the file was taken as +y up (OBJ has no convention; glTF's is +y),
    /// which is when [`likely_up`](crate::likely_up) is worth asking.
    pub up: Option<UpAxis>,
}

/// How a scene is loaded. The default is what a solve needs: every rule, and the sides that
/// the files say.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LoadOptions {
    /// Sides of every object read from a model file (a model given as the scene, the parts
    /// of `mesh` objects), over what the file and the scene file's `sides` keys say:
    /// [`Sides::One`] turns an OBJ's two-sidedness off; with [`Sides::Two`] the back emits
    /// when `emits_back` is set or the file already made it emit.
    pub model_sides: Option<Sides>,
    /// Accept a scene in which nothing emits (a solve of it would be black), setting
    /// [`LoadedScene::no_light`] instead of failing; every other rule still applies.
    pub allow_no_light: bool,
    /// The up axis of the file, over a scene file's `up` key; `None`: the key, else +y. The
    /// loaded scene is turned so that this axis is +y ([`Scene::rotate_to_y_up`]).
    pub up: Option<UpAxis>,
    /// The length unit of the file's coordinates (`--units`), over a scene file's `units`
    /// key; `None`: the key, else none declared (metres for photometric figures).
    pub units: Option<LengthUnit>,
}

/// Whether the back face of `sides` emits.
fn emits_back(sides: Sides) -> bool {
    matches!(sides, Sides::Two { emits_back: true })
}

/// `sides` with the count set by a `sides = 1 | 2` key; a back face keeps `base`'s emission.
fn with_count(count: u8, base: Sides) -> Sides {
    if count == 1 { Sides::One } else { Sides::Two { emits_back: emits_back(base) } }
}

/// The sides of an object from a model file, after [`LoadOptions::model_sides`].
fn model_sides(sides: Sides, opts: &LoadOptions) -> Sides {
    match opts.model_sides {
        None => sides,
        Some(Sides::One) => Sides::One,
        Some(Sides::Two { emits_back: back }) => Sides::Two { emits_back: back || emits_back(sides) },
    }
}

/// Loads and validates a TOML scene file or a model file (`.obj`, `.gltf`, `.glb`, chosen by
/// extension), with the loader's warnings.
///
/// A model file becomes a scene of its parts: named as in the file, the file's camera or none
/// (the renderer frames the bounds), mesh sizes from the extent.
///
/// # Errors
/// [`LoadError::Unreadable`] naming the file when it cannot be read as UTF-8 text; otherwise
/// as [`parse_scene`], with the path as origin; [`LoadError::Model`] for model files, and for a
/// model without any emitting material.
pub fn load_scene(path: &Path) -> Result<LoadedScene, LoadError> {
    load_scene_with(path, &LoadOptions::default())
}

/// [`load_scene`] with [`LoadOptions`].
///
/// # Errors
/// As [`load_scene`] (without the light rule when `opts` allows no light).
pub fn load_scene_with(path: &Path, opts: &LoadOptions) -> Result<LoadedScene, LoadError> {
    if ModelFormat::from_path(path).is_some() {
        return scene_from_model(path, opts);
    }
    let bytes = crate::model::read_input_file(path, crate::model::MAX_TEXT_BYTES)
        .map_err(|reason| LoadError::Unreadable { path: path.to_owned(), reason })?;
    let text = String::from_utf8(bytes).map_err(|e| LoadError::Unreadable {
        path: path.to_owned(),
        reason: format!("not a text file (invalid UTF-8 at byte {})", e.utf8_error().valid_up_to()),
    })?;
    parse_scene_with(&text, &path.display().to_string(), opts)
}

fn scene_from_model(path: &Path, opts: &LoadOptions) -> Result<LoadedScene, LoadError> {
    let origin = path.display().to_string();
    let model = load_model(path, &Transform::default())?;
    let objects: Vec<Object> = model
        .parts
        .into_iter()
        .map(|p| Object {
            name: p.name,
            material: p.material,
            shape: Shape::Mesh(p.mesh),
            sides: model_sides(p.sides, opts),
        })
        .collect();
    let name = path.file_stem().map_or_else(|| "model".to_owned(), |s| s.to_string_lossy().into_owned());
    let error = |e: SceneError, notes: &str| {
        let hint = match e {
            SceneError::NoEmitter => {
                "; give a material an emission (OBJ/MTL: `Ke r g b`; glTF: emissiveFactor) or place the model in a scene file with a light"
            }
            _ => "",
        };
        model_error(&origin, None, format!("{e}{hint}{notes}"))
    };
    let lit = objects.iter().any(|o| model.materials.get(o.material).is_some_and(Material::is_emitter));
    if opts.allow_no_light {
        // The caller shows the warnings before it reports or returns the missing light.
        let mut scene =
            Scene::try_new_unlit(&name, model.camera, model.materials, objects).map_err(|e| error(e, ""))?;
        scene.lighting.units = opts.units;
        scene.rotate_to_y_up(opts.up.unwrap_or_default());
        let no_light = (!lit).then(|| error(SceneError::NoEmitter, ""));
        return Ok(LoadedScene { scene, warnings: model.warnings, no_light, up: opts.up });
    }
    // What the loader noticed (a missing MTL, an unknown material) often explains the error,
    // and would otherwise be lost with the scene.
    let notes: String = model.warnings.iter().map(|w| format!(" (warning: {w})")).collect();
    let mut scene =
        Scene::try_new(&name, model.camera, model.materials, objects).map_err(|e| error(e, &notes))?;
    scene.lighting.units = opts.units;
    scene.rotate_to_y_up(opts.up.unwrap_or_default());
    Ok(LoadedScene { scene, warnings: model.warnings, no_light: None, up: opts.up })
}

/// Parses and validates the text of a scene file, with the loader's warnings (from the model
/// files of `mesh` objects, which are read relative to the folder of `origin`); `origin`
/// (usually the path) starts every error message.
///
/// The scene's name defaults to the file stem of `origin`; `[mesh]` sets [`Scene::mesh`] and
/// `[solver]` sets [`Scene::solver`]. An object's sides are its `sides` key, else its
/// material's, else one; a `mesh` object's parts keep their file's unless the object or an
/// overriding material that gives `sides` says otherwise.
///
/// # Errors
/// [`LoadError::At`], naming line, column, key path and what was expected, for TOML syntax
/// errors, unknown keys, wrong types, and every validation rule: reflectance in [0, 1),
/// emission finite and ≥ 0, unique materials, known material references, finite coordinates,
/// planar convex non-degenerate polygons of 3+ vertices, radius > 0, box min < max, a usable
/// camera, sizes > 0, `sides` and `emission_sides` 1 or 2 (`emission_sides = 2` only with
/// `sides = 2`), `unshot_threshold` in (0, 1), `max_shots` ≥ 1, `time_limit` > 0, at
/// least one object and at least one light. TOML's `nan` and `inf` are rejected wherever a
/// number is validated. [`LoadError::Model`] for a broken model file.
pub fn parse_scene(text: &str, origin: &str) -> Result<LoadedScene, LoadError> {
    parse_scene_with(text, origin, &LoadOptions::default())
}

/// [`parse_scene`] with [`LoadOptions`].
///
/// # Errors
/// As [`parse_scene`] (without the light rule when `opts` allows no light).
pub fn parse_scene_with(text: &str, origin: &str, opts: &LoadOptions) -> Result<LoadedScene, LoadError> {
    let loc = Locator { origin, text };
    let desc: SceneDesc = toml::from_str(text).map_err(|e| loc.toml_error(&e))?;

    let (mut materials, material_sides) = materials(&loc, &desc.material)?;
    let declared = materials.len();
    // Names are unique by now; objects look theirs up here (a search of the list per object
    // was quadratic: 50 000 objects using the last of 50 000 materials ran for minutes).
    let by_name: HashMap<&str, usize> =
        desc.material.iter().enumerate().map(|(i, m)| (m.get_ref().name.get_ref().as_str(), i)).collect();
    let mut objects = Vec::new();
    // For each object, the `[[object]]` it came from (a `mesh` object gives several).
    let mut origins = Vec::new();
    let mut warnings = Vec::new();
    for (i, o) in desc.object.iter().enumerate() {
        if o.get_ref().kind.get_ref() == "mesh" {
            let declared =
                Declared { descs: &desc.material[..declared], sides: &material_sides, by_name: &by_name };
            let parts = mesh_object(&loc, i, o, &declared, opts, &mut materials, &mut warnings)?;
            objects.extend(parts);
        } else {
            let declared = Declared { descs: &desc.material, sides: &material_sides, by_name: &by_name };
            objects.push(object(&loc, i, o, &declared)?);
        }
        origins.resize(objects.len(), i);
    }
    let up = match opts.up {
        Some(up) => Some(up),
        None => desc.up.as_ref().map(|u| up_axis(&loc, u)).transpose()?,
    };
    let units = crate::lighting_file::units(&loc, &desc, opts.units)?;
    crate::lighting_file::photometric_emission(
        &loc,
        &desc.material,
        &mut materials,
        &mut objects,
        units.unwrap_or_default(),
    )?;
    let lighting = crate::lighting_file::lighting(&loc, &desc, units, up.unwrap_or_default())?;
    let camera = desc.camera.as_ref().map(|c| camera(&loc, c, up.unwrap_or_default())).transpose()?;
    let mesh = desc.mesh.as_ref().map(|m| mesh_params(&loc, m)).transpose()?;
    let solver = desc.solver.as_ref().map(|s| solver_settings(&loc, s)).transpose()?.unwrap_or_default();
    let name = desc.name.clone().unwrap_or_else(|| {
        Path::new(origin).file_stem().map_or_else(|| "scene".to_owned(), |s| s.to_string_lossy().into_owned())
    });

    // Whole-scene rules come last, once every local error has had its say. The unused light
    // is found before `materials` and `objects` move into the scene, to explain a dark scene.
    let mut used = vec![false; materials.len()];
    for o in &objects {
        if let Some(u) = used.get_mut(o.material) {
            *u = true;
        }
    }
    let unused_light = materials.iter().enumerate().position(|(i, m)| m.is_emitter() && !used[i]);
    let lit = !lighting.luminaires.is_empty()
        || lighting.sun.is_some()
        || lighting.sky.is_some()
        || objects.iter().any(|o| materials.get(o.material).is_some_and(Material::is_emitter));
    let build = if opts.allow_no_light || lit { Scene::try_new_unlit } else { Scene::try_new };
    let scene_error = |e: SceneError| match e {
        SceneError::NoObjects => loc.at(
            0..0,
            "object",
            format!("{e}; add at least one [[object]] (polygon, polygons, box or sphere)"),
        ),
        SceneError::NoEmitter => match unused_light.filter(|&i| i < declared) {
            Some(i) => {
                let m = desc.material[i].get_ref();
                let span = m.emission.as_ref().map_or_else(|| m.name.span(), Spanned::span);
                let message = format!("{e}; material '{}' emits but no object uses it", m.name.get_ref());
                loc.at(span, format!("material[{i}].emission"), message)
            }
            None => loc.at(
                0..0,
                "material",
                format!("{e}; give a material `emission = [r, g, b]` above 0 and use it on an object"),
            ),
        },
        // Duplicates and unknown references were reported above with their spans.
        other => loc.at(0..0, "scene", other.to_string()),
    };
    let mut scene = build(&name, camera, materials, objects).map_err(scene_error)?;
    scene.mesh = mesh;
    scene.solver = solver;
    scene.lighting = lighting;
    check_element_count(&loc, &desc, &scene, &origins)?;
    // Last, once every error has pointed at the file's own coordinates.
    scene.rotate_to_y_up(up.unwrap_or_default());
    let no_light = (!lit).then(|| scene_error(SceneError::NoEmitter));
    Ok(LoadedScene { scene, warnings, no_light, up })
}

/// The `[[material]]` entries of a file with the sides each one gives (`None`: it says
/// nothing, so a `mesh` object keeps its file's sides and other objects are one-sided).
struct Declared<'a> {
    descs: &'a [Spanned<MaterialDesc>],
    sides: &'a [Option<Sides>],
    /// Index of each name in `descs`.
    by_name: &'a HashMap<&'a str, usize>,
}

/// `1` or `2` from a `sides` or `emission_sides` key, or an error at its value.
fn side_count(loc: &Locator, key: String, v: &Spanned<i64>) -> Result<u8, LoadError> {
    match *v.get_ref() {
        1 => Ok(1),
        2 => Ok(2),
        other => Err(loc.at(
            v.span(),
            key,
            format!("expected 1 (the front face only) or 2 (both faces), got {other}"),
        )),
    }
}

/// What a material's `sides` and `emission_sides` keys say, `None` when neither is given.
fn material_sides(loc: &Locator, key: &str, m: &MaterialDesc) -> Result<Option<Sides>, LoadError> {
    let sides = m.sides.as_ref().map(|v| side_count(loc, format!("{key}.sides"), v)).transpose()?;
    let emission_sides = m
        .emission_sides
        .as_ref()
        .map(|v| Ok::<_, LoadError>((side_count(loc, format!("{key}.emission_sides"), v)?, v.span())))
        .transpose()?;
    let back = matches!(emission_sides, Some((2, _)));
    if let Some((2, span)) = emission_sides
        && sides != Some(2)
    {
        return Err(loc.at(
            span,
            format!("{key}.emission_sides"),
            "emission_sides = 2 needs sides = 2: a one-sided material has no back face to emit from",
        ));
    }
    Ok(sides.map(|n| match n {
        1 => Sides::One,
        _ => Sides::Two { emits_back: back },
    }))
}

/// Refuses, with a line, a scene whose mesh would pass [`radiosity_mesh::MAX_ELEMENTS`]: at
/// `[mesh] element_size` when the file sets it, else at the object that passes the limit
/// (a huge sphere, say, against the default sizes).
fn check_element_count(
    loc: &Locator,
    desc: &SceneDesc,
    scene: &Scene,
    origins: &[usize],
) -> Result<(), LoadError> {
    let params = scene.mesh_params();
    let Some(i) = radiosity_mesh::first_object_over_limit(scene, &params) else { return Ok(()) };
    let object = &desc.object[origins[i]];
    let e = radiosity_mesh::MeshError::TooManyElements {
        object: scene.objects[i].name.chars().take(80).collect(),
        limit: radiosity_mesh::MAX_ELEMENTS,
        patch_size: params.patch_size,
        element_size: params.element_size,
    };
    Err(match &desc.mesh {
        Some(m) => {
            let (line, _) = crate::locate::line_col(loc.text, object.span().start);
            loc.at(m.element_size.span(), "mesh.element_size", format!("{e} (the object at line {line})"))
        }
        None => loc.at(object.span(), format!("object[{}]", origins[i]), e.to_string()),
    })
}

fn materials(
    loc: &Locator,
    descs: &[Spanned<MaterialDesc>],
) -> Result<(Vec<Material>, Vec<Option<Sides>>), LoadError> {
    let mut materials: Vec<Material> = Vec::with_capacity(descs.len());
    let mut sides = Vec::with_capacity(descs.len());
    // First index of each name: a search of the list per material was quadratic (100 000
    // materials took 36 s).
    let mut first_of: HashMap<&str, usize> = HashMap::default();
    for (i, m) in descs.iter().enumerate() {
        let m = m.get_ref();
        let key = format!("material[{i}]");
        let name = m.name.get_ref();
        if let Some(&first) = first_of.get(name.as_str()) {
            return Err(loc.at(
                m.name.span(),
                format!("{key}.name"),
                format!(
                    "material '{name}' is defined twice (first as material[{first}]); names must be unique"
                ),
            ));
        }
        let emission = m.emission.as_ref().map_or([0.0; 3], |e| *e.get_ref());
        let material =
            Material::try_new(name, Rgb::from_array(*m.reflectance.get_ref()), Rgb::from_array(emission))
                .map_err(|e| match (&e, &m.emission) {
                    (SceneError::EmissionOutOfRange { .. }, Some(em)) => {
                        loc.at(em.span(), format!("{key}.emission"), e.to_string())
                    }
                    _ => loc.at(m.reflectance.span(), format!("{key}.reflectance"), e.to_string()),
                })?;
        materials.push(material);
        first_of.insert(name, i);
        sides.push(material_sides(loc, &key, m)?);
    }
    Ok((materials, sides))
}

/// The file's `up` key, or an error at its value listing the accepted names.
fn up_axis(loc: &Locator, u: &Spanned<String>) -> Result<UpAxis, LoadError> {
    UpAxis::parse(u.get_ref()).ok_or_else(|| {
        let names: Vec<String> = UpAxis::NAMES.iter().map(|n| format!("\"{n}\"")).collect();
        loc.at(u.span(), "up", format!("expected one of {}, got {:?}", names.join(", "), u.get_ref()))
    })
}

/// The `[camera]` of a file whose up axis is `file_up` (the default of its `up`).
fn camera(loc: &Locator, c: &Spanned<CameraDesc>, file_up: UpAxis) -> Result<Camera, LoadError> {
    let d = c.get_ref();
    let position = *d.position.get_ref();
    let look_at = *d.look_at.get_ref();
    let up = d.up.as_ref().map_or(file_up.direction().to_array(), |u| *u.get_ref());
    let fov = d.fov_y_deg.as_ref().map_or(DEFAULT_FOV_Y_DEG, |f| *f.get_ref());
    Camera::try_new(v3(position), v3(look_at), v3(up), fov).map_err(|e| {
        // The core says what is wrong; name the field it is about, checking in the core's
        // order (finite, distinct points, up, field of view). Whether `up` is at fault is
        // asked of the core itself, with a field of view known to be good.
        let field = if !in_range(&position) {
            "position"
        } else if !in_range(&look_at) || position == look_at {
            "look_at"
        } else if !all_finite(&up)
            || Camera::try_new(v3(position), v3(look_at), v3(up), DEFAULT_FOV_Y_DEG).is_err()
        {
            "up"
        } else {
            "fov_y_deg"
        };
        let default_up = format!(
            "; `up` defaults to {:?} (the file's up axis): give another when looking straight up or down",
            file_up.direction().to_array().map(|c| c as i32)
        );
        let (span, note) = match field {
            "position" => (d.position.span(), ""),
            "look_at" => (d.look_at.span(), ""),
            "up" => d.up.as_ref().map_or_else(|| (c.span(), default_up.as_str()), |u| (u.span(), "")),
            _ => d.fov_y_deg.as_ref().map_or_else(|| (c.span(), ""), |f| (f.span(), "")),
        };
        loc.at(span, format!("camera.{field}"), format!("{e}{note}"))
    })
}

/// The fields each object type takes besides `name`, `type` and `material`.
fn allowed_fields(kind: &str) -> Option<&'static [&'static str]> {
    Some(match kind {
        "polygon" => &["vertices"],
        "polygons" => &["faces"],
        "box" => &["min", "max", "normals", "rotate_y_deg"],
        "sphere" => &["center", "radius", "normals"],
        "mesh" => &["file", "transform"],
        _ => return None,
    })
}

/// A polygon from its vertex list; a non-finite or non-convex vertex is pointed at itself.
fn polygon(loc: &Locator, face: &Face, key: &str) -> Result<Polygon, LoadError> {
    let points = face.get_ref();
    Polygon::try_new(points.iter().map(|p| v3(*p.get_ref())).collect()).map_err(|e| {
        let vertex = match &e {
            SceneError::NonFiniteCoordinate { .. } | SceneError::CoordinateOutOfRange { .. } => {
                points.iter().position(|p| !in_range(p.get_ref()))
            }
            SceneError::NonConvexPolygon { vertex } => Some(*vertex),
            _ => None,
        };
        match vertex.and_then(|k| points.get(k).map(|p| (k, p))) {
            Some((k, p)) => loc.at(p.span(), format!("{key}[{k}]"), e.to_string()),
            None => loc.at(face.span(), key, e.to_string()),
        }
    })
}

fn facing(loc: &Locator, key: &str, normals: Option<&Spanned<String>>) -> Result<Facing, LoadError> {
    match normals.map(|s| (s.get_ref().as_str(), s)) {
        None | Some(("outward", _)) => Ok(Facing::Outward),
        Some(("inward", _)) => Ok(Facing::Inward),
        Some((other, s)) => Err(loc.at(
            s.span(),
            format!("{key}.normals"),
            format!("expected \"inward\" or \"outward\", got \"{other}\""),
        )),
    }
}

fn object(
    loc: &Locator,
    i: usize,
    o: &Spanned<ObjectDesc>,
    declared: &Declared,
) -> Result<Object, LoadError> {
    let d = o.get_ref();
    let name = d.name.get_ref().clone();
    let key = format!("object[{i}]");
    let kind = d.kind.get_ref().as_str();
    let Some(allowed) = allowed_fields(kind) else {
        return Err(loc.at(
            d.kind.span(),
            format!("{key}.type"),
            format!(
                "object '{name}': unknown type '{kind}'; expected one of polygon, polygons, box, sphere, mesh"
            ),
        ));
    };
    check_fields(loc, &key, kind, allowed, d)?;
    let Some(material_name) = d.material.as_ref() else {
        return Err(loc.at(o.span(), format!("{key}.material"), format!("object '{name}' needs 'material'")));
    };
    let material = material_index(loc, &key, &name, material_name, declared)?;
    let missing = |field: &str| {
        loc.at(
            o.span(),
            format!("{key}.{field}"),
            format!("object '{name}' of type '{kind}' needs '{field}'"),
        )
    };

    let shape = match kind {
        "polygon" => {
            let v = d.vertices.as_ref().ok_or_else(|| missing("vertices"))?;
            Shape::Polygons(vec![polygon(loc, v, &format!("{key}.vertices"))?])
        }
        "polygons" => {
            let f = d.faces.as_ref().ok_or_else(|| missing("faces"))?;
            if f.get_ref().is_empty() {
                return Err(loc.at(f.span(), format!("{key}.faces"), "expected at least one face, got []"));
            }
            let faces = f
                .get_ref()
                .iter()
                .enumerate()
                .map(|(k, face)| polygon(loc, face, &format!("{key}.faces[{k}]")))
                .collect::<Result<_, _>>()?;
            Shape::Polygons(faces)
        }
        "box" => {
            let min = d.min.as_ref().ok_or_else(|| missing("min"))?;
            let max = d.max.as_ref().ok_or_else(|| missing("max"))?;
            let rotate_y_deg = match &d.rotate_y_deg {
                None => 0.0,
                Some(r) if r.get_ref().is_finite() => *r.get_ref(),
                Some(r) => {
                    return Err(loc.at(
                        r.span(),
                        format!("{key}.rotate_y_deg"),
                        format!("expected a finite angle in degrees, got {}", r.get_ref()),
                    ));
                }
            };
            let facing = facing(loc, &key, d.normals.as_ref())?;
            let faces =
                box_faces(v3(*min.get_ref()), v3(*max.get_ref()), facing, rotate_y_deg).map_err(|e| {
                    // A corner out of range is named; otherwise (min ≥ max) both are in the message.
                    let (field, span) = if in_range(min.get_ref()) && !in_range(max.get_ref()) {
                        ("max", max.span())
                    } else {
                        ("min", min.span())
                    };
                    loc.at(span, format!("{key}.{field}"), e.to_string())
                })?;
            Shape::Polygons(faces)
        }
        "sphere" => {
            let c = d.center.as_ref().ok_or_else(|| missing("center"))?;
            let r = d.radius.as_ref().ok_or_else(|| missing("radius"))?;
            let facing = facing(loc, &key, d.normals.as_ref())?;
            let s = Sphere::try_new(v3(*c.get_ref()), *r.get_ref(), facing).map_err(|e| {
                // A sphere reaching past the coordinate limit from a centre within it: its
                // radius takes it there.
                let (field, span) = if matches!(e, SceneError::BadRadius { .. })
                    || (matches!(e, SceneError::CoordinateOutOfRange { .. }) && in_range(c.get_ref()))
                {
                    ("radius", r.span())
                } else {
                    ("center", c.span())
                };
                loc.at(span, format!("{key}.{field}"), e.to_string())
            })?;
            Shape::Sphere(s)
        }
        _ => unreachable!("mesh objects go through mesh_object; allowed_fields accepts only these types"),
    };
    let sides = declared.sides.get(material).copied().flatten().unwrap_or(Sides::One);
    let sides = match &d.sides {
        Some(v) => with_count(side_count(loc, format!("{key}.sides"), v)?, sides),
        None => sides,
    };
    Ok(Object { name, material, shape, sides })
}

/// A field of another type (a `radius` on a box) is an error, not silently ignored.
fn check_fields(
    loc: &Locator,
    key: &str,
    kind: &str,
    allowed: &[&str],
    d: &ObjectDesc,
) -> Result<(), LoadError> {
    let present: [(&str, Option<Range<usize>>); 10] = [
        ("vertices", d.vertices.as_ref().map(Spanned::span)),
        ("faces", d.faces.as_ref().map(Spanned::span)),
        ("min", d.min.as_ref().map(Spanned::span)),
        ("max", d.max.as_ref().map(Spanned::span)),
        ("normals", d.normals.as_ref().map(Spanned::span)),
        ("rotate_y_deg", d.rotate_y_deg.as_ref().map(Spanned::span)),
        ("center", d.center.as_ref().map(Spanned::span)),
        ("radius", d.radius.as_ref().map(Spanned::span)),
        ("file", d.file.as_ref().map(Spanned::span)),
        ("transform", d.transform.as_ref().map(Spanned::span)),
    ];
    for (field, span) in present {
        if let Some(span) = span
            && !allowed.contains(&field)
        {
            return Err(loc.at(
                span,
                format!("{key}.{field}"),
                format!(
                    "'{field}' does not apply to type '{kind}' (it takes: {}; every type takes name, type, material, sides)",
                    allowed.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// The index of the declared material an object names, or an error at the name.
fn material_index(
    loc: &Locator,
    key: &str,
    name: &str,
    material: &Spanned<String>,
    declared: &Declared,
) -> Result<usize, LoadError> {
    declared.by_name.get(material.get_ref().as_str()).copied().ok_or_else(|| {
        let known = declared.descs.iter().map(|m| m.get_ref().name.get_ref().as_str()).collect::<Vec<_>>();
        let known = if known.is_empty() { "none".to_owned() } else { known.join(", ") };
        loc.at(
            material.span(),
            format!("{key}.material"),
            format!(
                "object '{name}' uses material '{}', which is not defined (defined: {known})",
                material.get_ref()
            ),
        )
    })
}

/// A finite number from a transform, or an error at its span.
fn finite(loc: &Locator, key: &str, v: &Spanned<f64>) -> Result<f64, LoadError> {
    let x = *v.get_ref();
    if x.is_finite() {
        Ok(x)
    } else {
        Err(loc.at(v.span(), key, format!("expected a finite number, got {x}")))
    }
}

fn transform(loc: &Locator, key: &str, t: &Spanned<TransformDesc>) -> Result<Transform, LoadError> {
    let d = t.get_ref();
    let mut out = Transform::default();
    if let Some(tr) = &d.translate {
        if !all_finite(tr.get_ref()) {
            return Err(loc.at(
                tr.span(),
                format!("{key}.translate"),
                format!("expected finite numbers, got {:?}", tr.get_ref()),
            ));
        }
        out.translate = *tr.get_ref();
    }
    if let Some(sc) = &d.scale {
        let scale = match sc.get_ref() {
            Scale::Uniform(s) => [*s; 3],
            Scale::PerAxis(a) => a.0,
        };
        if !scale.iter().all(|s| s.is_finite() && *s != 0.0) {
            return Err(loc.at(
                sc.span(),
                format!("{key}.scale"),
                format!("expected a finite number ≠ 0 or three of them, got {scale:?}"),
            ));
        }
        out.scale = scale;
    }
    for (field, value, slot) in [
        ("rotate_x_deg", &d.rotate_x_deg, &mut out.rotate_x_deg),
        ("rotate_y_deg", &d.rotate_y_deg, &mut out.rotate_y_deg),
        ("rotate_z_deg", &d.rotate_z_deg, &mut out.rotate_z_deg),
    ] {
        if let Some(v) = value {
            *slot = finite(loc, &format!("{key}.{field}"), v)?;
        }
    }
    Ok(out)
}

/// A `mesh` object: the model file's parts as objects named `object/part`, with the file's
/// materials added as `object/material` (or every part in the object's `material`).
fn mesh_object(
    loc: &Locator,
    i: usize,
    o: &Spanned<ObjectDesc>,
    declared: &Declared,
    opts: &LoadOptions,
    materials: &mut Vec<Material>,
    warnings: &mut Vec<String>,
) -> Result<Vec<Object>, LoadError> {
    let d = o.get_ref();
    let name = d.name.get_ref().clone();
    let key = format!("object[{i}]");
    check_fields(loc, &key, "mesh", allowed_fields("mesh").unwrap_or(&[]), d)?;
    let Some(file) = d.file.as_ref() else {
        return Err(loc.at(
            o.span(),
            format!("{key}.file"),
            format!("object '{name}' of type 'mesh' needs 'file'"),
        ));
    };
    let override_material =
        d.material.as_ref().map(|m| material_index(loc, &key, &name, m, declared)).transpose()?;
    let object_sides = d.sides.as_ref().map(|v| side_count(loc, format!("{key}.sides"), v)).transpose()?;
    let transform = d
        .transform
        .as_ref()
        .map(|t| transform(loc, &format!("{key}.transform"), t))
        .transpose()?
        .unwrap_or_default();
    let folder = Path::new(loc.origin).parent().unwrap_or(Path::new(""));
    let path = folder.join(file.get_ref());
    if ModelFormat::from_path(&path).is_none() {
        return Err(loc.at(
            file.span(),
            format!("{key}.file"),
            format!("'{}' is not a model file; expected a .obj, .gltf or .glb file", file.get_ref()),
        ));
    }
    if !path.is_file() {
        return Err(loc.at(
            file.span(),
            format!("{key}.file"),
            format!(
                "cannot read '{}' ({}): no such file (paths are relative to the scene file's folder)",
                file.get_ref(),
                path.display()
            ),
        ));
    }
    let model = load_model(&path, &transform)?;
    warnings.extend(model.warnings);
    let first = materials.len();
    if override_material.is_none() {
        for m in &model.materials {
            let mut m = m.clone();
            m.name = format!("{name}/{}", m.name);
            materials.push(m);
        }
    }
    // The file's sides, then the overriding material's when it says, then the object's key,
    // then the command line's.
    let material_sides = override_material.and_then(|m| declared.sides.get(m).copied().flatten());
    Ok(model
        .parts
        .into_iter()
        .map(|p| {
            let sides = material_sides.unwrap_or(p.sides);
            let sides = object_sides.map_or(sides, |n| with_count(n, sides));
            Object {
                name: format!("{name}/{}", p.name),
                material: override_material.unwrap_or(first + p.material),
                shape: Shape::Mesh(p.mesh),
                sides: model_sides(sides, opts),
            }
        })
        .collect())
}
