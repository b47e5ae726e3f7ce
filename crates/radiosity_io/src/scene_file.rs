//! Second stage of loading: [`SceneDesc`] → validated core [`Scene`].
//!
//! Validation itself lives in the core's constructors (`Material::try_new`,
//! `Polygon::try_new`, `box_faces`, `Sphere::try_new`, `Camera::try_new`,
//! `MeshParams::try_new`, `Scene::try_new`), so a scene built in code and one read from a file
//! obey the same rules; this module only decides *where* in the file each error points: the
//! offending value's span, down to the vertex for a non-finite or non-convex corner.

use std::ops::Range;
use std::path::Path;

use radiosity_core::glam::DVec3;
use radiosity_core::{
    Camera, Facing, Material, MeshParams, Object, Polygon, Rgb, Scene, SceneError, Shape, SolverSettings,
    Sphere, box_faces,
};
use toml::Spanned;

use crate::LoadError;
use crate::desc::{CameraDesc, Face, MaterialDesc, MeshDesc, ObjectDesc, SceneDesc, SolverDesc};
use crate::locate::Locator;

/// Camera `up` when the file gives none.
const DEFAULT_UP: [f64; 3] = [0.0, 1.0, 0.0];
/// Camera vertical field of view in degrees when the file gives none.
const DEFAULT_FOV_Y_DEG: f64 = 45.0;

fn v3(a: [f64; 3]) -> DVec3 {
    DVec3::from_array(a)
}

fn all_finite(a: &[f64; 3]) -> bool {
    a.iter().all(|c| c.is_finite())
}

/// Loads and validates a scene file.
///
/// # Errors
/// [`LoadError::Unreadable`] naming the file when it cannot be read as UTF-8 text; otherwise
/// as [`parse_scene`], with the path as origin.
pub fn load_scene(path: &Path) -> Result<Scene, LoadError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| LoadError::Unreadable { path: path.to_owned(), reason: e.to_string() })?;
    parse_scene(&text, &path.display().to_string())
}

/// Parses and validates the text of a scene file; `origin` (usually the path) starts every
/// error message.
///
/// The scene's name defaults to the file stem of `origin`; `[mesh]` sets [`Scene::mesh`] and
/// `[solver]` sets [`Scene::solver`].
///
/// # Errors
/// [`LoadError::At`], naming line, column, key path and what was expected, for TOML syntax
/// errors, unknown keys, wrong types, and every validation rule: reflectance in [0, 1),
/// emission finite and ≥ 0, unique materials, known material references, finite coordinates,
/// planar convex non-degenerate polygons of 3+ vertices, radius > 0, box min < max, a usable
/// camera, sizes > 0, `unshot_threshold` in (0, 1), `max_shots` ≥ 1, `time_limit` > 0, at
/// least one object and at least one light. TOML's `nan` and `inf` are rejected wherever a
/// number is validated.
pub fn parse_scene(text: &str, origin: &str) -> Result<Scene, LoadError> {
    let loc = Locator { origin, text };
    let desc: SceneDesc = toml::from_str(text).map_err(|e| loc.toml_error(&e))?;

    let materials = materials(&loc, &desc.material)?;
    let objects = desc
        .object
        .iter()
        .enumerate()
        .map(|(i, o)| object(&loc, i, o, &desc.material, &materials))
        .collect::<Result<Vec<_>, _>>()?;
    let camera = desc.camera.as_ref().map(|c| camera(&loc, c)).transpose()?;
    let mesh = desc.mesh.as_ref().map(|m| mesh_params(&loc, m)).transpose()?;
    let solver = desc.solver.as_ref().map(|s| solver_settings(&loc, s)).transpose()?.unwrap_or_default();
    let name = desc.name.clone().unwrap_or_else(|| {
        Path::new(origin).file_stem().map_or_else(|| "scene".to_owned(), |s| s.to_string_lossy().into_owned())
    });

    // Whole-scene rules come last, once every local error has had its say. The unused light
    // is found before `materials` and `objects` move into the scene, to explain a dark scene.
    let unused_light = materials
        .iter()
        .enumerate()
        .find(|(i, m)| m.is_emitter() && !objects.iter().any(|o| o.material == *i))
        .map(|(i, _)| i);
    let mut scene = Scene::try_new(&name, camera, materials, objects).map_err(|e| match e {
        SceneError::NoObjects => loc.at(
            0..0,
            "object",
            format!("{e}; add at least one [[object]] (polygon, polygons, box or sphere)"),
        ),
        SceneError::NoEmitter => match unused_light {
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
    })?;
    scene.mesh = mesh;
    scene.solver = solver;
    Ok(scene)
}

fn materials(loc: &Locator, descs: &[Spanned<MaterialDesc>]) -> Result<Vec<Material>, LoadError> {
    let mut materials: Vec<Material> = Vec::with_capacity(descs.len());
    for (i, m) in descs.iter().enumerate() {
        let m = m.get_ref();
        let key = format!("material[{i}]");
        let name = m.name.get_ref();
        if let Some(first) = materials.iter().position(|o| o.name == *name) {
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
    }
    Ok(materials)
}

fn camera(loc: &Locator, c: &Spanned<CameraDesc>) -> Result<Camera, LoadError> {
    let d = c.get_ref();
    let position = *d.position.get_ref();
    let look_at = *d.look_at.get_ref();
    let up = d.up.as_ref().map_or(DEFAULT_UP, |u| *u.get_ref());
    let fov = d.fov_y_deg.as_ref().map_or(DEFAULT_FOV_Y_DEG, |f| *f.get_ref());
    Camera::try_new(v3(position), v3(look_at), v3(up), fov).map_err(|e| {
        // The core says what is wrong; name the field it is about, checking in the core's
        // order (finite, distinct points, up, field of view). Whether `up` is at fault is
        // asked of the core itself, with a field of view known to be good.
        let field = if !all_finite(&position) {
            "position"
        } else if !all_finite(&look_at) || position == look_at {
            "look_at"
        } else if !all_finite(&up)
            || Camera::try_new(v3(position), v3(look_at), v3(up), DEFAULT_FOV_Y_DEG).is_err()
        {
            "up"
        } else {
            "fov_y_deg"
        };
        let (span, note) = match field {
            "position" => (d.position.span(), ""),
            "look_at" => (d.look_at.span(), ""),
            "up" => d.up.as_ref().map_or_else(
                || (c.span(), "; `up` defaults to [0, 1, 0]: give another when looking straight up or down"),
                |u| (u.span(), ""),
            ),
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
            SceneError::NonFiniteCoordinate { .. } => points.iter().position(|p| !all_finite(p.get_ref())),
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
    material_descs: &[Spanned<MaterialDesc>],
    materials: &[Material],
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
    if kind == "mesh" {
        return Err(loc.at(
            d.kind.span(),
            format!("{key}.type"),
            format!(
                "object '{name}': object type 'mesh' (OBJ/glTF import) is not supported yet; \
                 use polygon, polygons, box or sphere"
            ),
        ));
    }
    // A field of another type (a `radius` on a box) is an error, not silently ignored.
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
                format!("'{field}' does not apply to type '{kind}' (it takes: {})", allowed.join(", ")),
            ));
        }
    }
    let material = materials.iter().position(|m| m.name == *d.material.get_ref()).ok_or_else(|| {
        let known = material_descs.iter().map(|m| m.get_ref().name.get_ref().as_str()).collect::<Vec<_>>();
        let known = if known.is_empty() { "none".to_owned() } else { known.join(", ") };
        loc.at(
            d.material.span(),
            format!("{key}.material"),
            format!(
                "object '{name}' uses material '{}', which is not defined (defined: {known})",
                d.material.get_ref()
            ),
        )
    })?;
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
                    // A non-finite corner is named; otherwise (min ≥ max) both are in the message.
                    let (field, span) = if all_finite(min.get_ref()) && !all_finite(max.get_ref()) {
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
                let (field, span) = if matches!(e, SceneError::BadRadius { .. }) {
                    ("radius", r.span())
                } else {
                    ("center", c.span())
                };
                loc.at(span, format!("{key}.{field}"), e.to_string())
            })?;
            Shape::Sphere(s)
        }
        _ => unreachable!("allowed_fields accepts only the types matched here"),
    };
    Ok(Object { name, material, shape })
}

fn mesh_params(loc: &Locator, d: &MeshDesc) -> Result<MeshParams, LoadError> {
    MeshParams::try_new(*d.patch_size.get_ref(), *d.element_size.get_ref()).map_err(|e| {
        let (field, span) = match e {
            SceneError::BadMeshSize { key: "patch_size", .. } => ("patch_size", d.patch_size.span()),
            _ => ("element_size", d.element_size.span()),
        };
        loc.at(span, format!("mesh.{field}"), e.to_string())
    })
}

fn solver_settings(loc: &Locator, d: &SolverDesc) -> Result<SolverSettings, LoadError> {
    let mut settings = SolverSettings::default();
    if let Some(t) = &d.unshot_threshold {
        let v = *t.get_ref();
        // Written so that NaN fails too.
        if !(v > 0.0 && v < 1.0) {
            return Err(loc.at(
                t.span(),
                "solver.unshot_threshold",
                format!("expected a fraction of the emitted power in (0, 1), e.g. 0.001, got {v}"),
            ));
        }
        settings.unshot_threshold = Some(v);
    }
    if let Some(n) = &d.max_shots {
        let v = *n.get_ref();
        let Ok(shots) = u64::try_from(v) else {
            return Err(loc.at(
                n.span(),
                "solver.max_shots",
                format!("expected a whole number ≥ 1, got {v}"),
            ));
        };
        if shots == 0 {
            return Err(loc.at(n.span(), "solver.max_shots", "expected a whole number ≥ 1, got 0"));
        }
        settings.max_shots = Some(shots);
    }
    if let Some(t) = &d.time_limit {
        let v = *t.get_ref();
        if !(v.is_finite() && v > 0.0) {
            return Err(loc.at(
                t.span(),
                "solver.time_limit",
                format!("expected a finite number of seconds > 0, got {v}"),
            ));
        }
        settings.time_limit = Some(v);
    }
    Ok(settings)
}
