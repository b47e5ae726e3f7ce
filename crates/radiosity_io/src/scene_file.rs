//! The TOML scene format: plain serde data with every validated value `Spanned`, then
//! validation through the core's constructors with the span turned into file:line:column.

use std::ops::Range;
use std::path::Path;

use radiosity_core::glam::DVec3;
use radiosity_core::{
    Camera, Facing, Material, MeshParams, Object, Polygon, Rgb, Scene, SceneError, Shape, Sphere, box_faces,
};
use serde::Deserialize;
use toml::Spanned;

use crate::LoadError;
use crate::error::line_col;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneDesc {
    name: Option<String>,
    camera: Option<Spanned<CameraDesc>>,
    #[serde(default)]
    material: Vec<Spanned<MaterialDesc>>,
    #[serde(default)]
    object: Vec<Spanned<ObjectDesc>>,
    mesh: Option<Spanned<MeshDesc>>,
    solver: Option<Spanned<SolverDesc>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraDesc {
    position: [f64; 3],
    look_at: [f64; 3],
    #[serde(default = "default_up")]
    up: [f64; 3],
    #[serde(default = "default_fov")]
    fov_y_deg: f64,
}

fn default_up() -> [f64; 3] {
    [0.0, 1.0, 0.0]
}

fn default_fov() -> f64 {
    45.0
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialDesc {
    name: Spanned<String>,
    reflectance: Spanned<[f64; 3]>,
    emission: Option<Spanned<[f64; 3]>>,
}

/// One `[[object]]`: a flat struct rather than a tagged enum, because serde's tagged enums
/// buffer their content and lose the spans that errors need.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectDesc {
    name: Spanned<String>,
    #[serde(rename = "type")]
    kind: Spanned<String>,
    material: Spanned<String>,
    vertices: Option<Spanned<Vec<[f64; 3]>>>,
    faces: Option<Spanned<Vec<Vec<[f64; 3]>>>>,
    min: Option<Spanned<[f64; 3]>>,
    max: Option<Spanned<[f64; 3]>>,
    normals: Option<Spanned<String>>,
    rotate_y_deg: Option<Spanned<f64>>,
    center: Option<Spanned<[f64; 3]>>,
    radius: Option<Spanned<f64>>,
    file: Option<Spanned<String>>,
    transform: Option<Spanned<toml::Value>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MeshDesc {
    patch_size: Spanned<f64>,
    element_size: Spanned<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SolverDesc {
    unshot_threshold: Option<Spanned<f64>>,
    max_shots: Option<Spanned<i64>>,
    time_limit: Option<Spanned<f64>>,
}

/// Turns spans into located errors for one text.
struct Locator<'a> {
    origin: &'a str,
    text: &'a str,
}

impl Locator<'_> {
    fn at(&self, span: Range<usize>, key: impl Into<String>, message: impl Into<String>) -> LoadError {
        let (line, column) = line_col(self.text, span.start);
        LoadError::At {
            origin: self.origin.to_owned(),
            line,
            column,
            key: key.into(),
            message: message.into(),
        }
    }
}

fn v3(a: [f64; 3]) -> DVec3 {
    DVec3::from_array(a)
}

/// Loads and validates a scene file.
///
/// # Errors
/// [`LoadError::Unreadable`] when the file cannot be read; otherwise as [`parse_scene`].
pub fn load_scene(path: &Path) -> Result<Scene, LoadError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| LoadError::Unreadable { path: path.to_owned(), reason: e.to_string() })?;
    parse_scene(&text, &path.display().to_string())
}

/// Parses and validates scene text; `origin` names it in errors (usually the file path).
///
/// # Errors
/// [`LoadError::At`] naming line, column, key and what was expected, for TOML syntax,
/// unknown keys, wrong types, and every validation rule of the core (reflectance in [0, 1),
/// finite coordinates, planar convex non-degenerate polygons, radius > 0, a light, …).
pub fn parse_scene(text: &str, origin: &str) -> Result<Scene, LoadError> {
    let loc = Locator { origin, text };
    let desc: SceneDesc = toml::from_str(text).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        // toml's message can span several lines (it quotes the source); keep the first.
        let message = e.message().lines().next().unwrap_or("invalid TOML").to_owned();
        loc.at(span.clone(), key_at(text, span.start), message)
    })?;

    let mut materials = Vec::new();
    for (i, m) in desc.material.iter().enumerate() {
        let m = m.get_ref();
        let key = format!("material[{i}]");
        let emission = m.emission.as_ref().map_or([0.0; 3], |e| *e.get_ref());
        let material = Material::try_new(
            m.name.get_ref(),
            Rgb::from_array(*m.reflectance.get_ref()),
            Rgb::from_array(emission),
        );
        materials.push(material.map_err(|e| match e {
            SceneError::EmissionOutOfRange { .. } => {
                let span = m.emission.as_ref().map_or(m.name.span(), Spanned::span);
                loc.at(span, format!("{key}.emission"), e.to_string())
            }
            _ => loc.at(m.reflectance.span(), format!("{key}.reflectance"), e.to_string()),
        })?);
        if materials[..i].iter().any(|o: &Material| o.name == *m.name.get_ref()) {
            return Err(loc.at(
                m.name.span(),
                format!("{key}.name"),
                format!("material '{}' is defined twice", m.name.get_ref()),
            ));
        }
    }

    let mut objects = Vec::new();
    for (i, o) in desc.object.iter().enumerate() {
        objects.push(object(&loc, i, o, &materials)?);
    }

    let camera = match &desc.camera {
        Some(c) => {
            let d = c.get_ref();
            Some(
                Camera::try_new(v3(d.position), v3(d.look_at), v3(d.up), d.fov_y_deg)
                    .map_err(|e| loc.at(c.span(), "camera", e.to_string()))?,
            )
        }
        None => None,
    };
    let name = desc.name.clone().unwrap_or_else(|| {
        Path::new(origin).file_stem().map_or("scene".into(), |s| s.to_string_lossy().into_owned())
    });
    let mut scene = Scene::try_new(&name, camera, materials, objects).map_err(|e| {
        let span = desc.object.first().map_or(0..0, |o| o.span());
        loc.at(span, "object", e.to_string())
    })?;

    if let Some(m) = &desc.mesh {
        let d = m.get_ref();
        scene.mesh =
            Some(MeshParams::try_new(*d.patch_size.get_ref(), *d.element_size.get_ref()).map_err(|e| {
                let span = if matches!(e, SceneError::BadMeshSize { key: "patch_size", .. }) {
                    d.patch_size.span()
                } else {
                    d.element_size.span()
                };
                loc.at(span, "mesh", e.to_string())
            })?);
    }
    if let Some(s) = &desc.solver {
        let d = s.get_ref();
        if let Some(t) = &d.unshot_threshold {
            let v = *t.get_ref();
            if !(v > 0.0 && v < 1.0) {
                return Err(loc.at(
                    t.span(),
                    "solver.unshot_threshold",
                    format!("expected a number in (0, 1), got {v}"),
                ));
            }
            scene.solver.unshot_threshold = Some(v);
        }
        if let Some(n) = &d.max_shots {
            let v = *n.get_ref();
            if v <= 0 {
                return Err(loc.at(
                    n.span(),
                    "solver.max_shots",
                    format!("expected a whole number ≥ 1, got {v}"),
                ));
            }
            scene.solver.max_shots = Some(v as u64);
        }
        if let Some(t) = &d.time_limit {
            let v = *t.get_ref();
            if !(v.is_finite() && v > 0.0) {
                return Err(loc.at(t.span(), "solver.time_limit", format!("expected seconds > 0, got {v}")));
            }
            scene.solver.time_limit = Some(v);
        }
    }
    Ok(scene)
}

/// The key assigned on the line holding byte `offset` (`reflectance` in
/// `reflectance = [1, 2]`), or `toml` when the line assigns nothing.
fn key_at(text: &str, offset: usize) -> String {
    let offset = offset.min(text.len());
    let start = text[..offset].rfind('\n').map_or(0, |p| p + 1);
    let line = text[start..].lines().next().unwrap_or("");
    match line.split_once('=') {
        Some((k, _))
            if !k.trim().is_empty()
                && k.trim().chars().all(|c| c.is_alphanumeric() || "_-.\"".contains(c)) =>
        {
            k.trim().to_owned()
        }
        _ => "toml".to_owned(),
    }
}

/// The fields each object type takes; any other geometry field is an error, so a typo'd
/// type or a stray key never goes unnoticed.
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

fn object(
    loc: &Locator,
    i: usize,
    o: &Spanned<ObjectDesc>,
    materials: &[Material],
) -> Result<Object, LoadError> {
    let d = o.get_ref();
    let name = d.name.get_ref().clone();
    let key = format!("object[{i}] ('{name}')");
    let kind = d.kind.get_ref().as_str();
    let Some(allowed) = allowed_fields(kind) else {
        return Err(loc.at(
            d.kind.span(),
            format!("{key}.type"),
            format!("unknown object type '{kind}'; expected one of polygon, polygons, box, sphere, mesh"),
        ));
    };
    if kind == "mesh" {
        return Err(loc.at(
            d.kind.span(),
            format!("{key}.type"),
            "object type 'mesh' (OBJ/glTF import) is not supported yet; use polygon, polygons, box or sphere",
        ));
    }
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
    for (field, span) in &present {
        if let Some(span) = span
            && !allowed.contains(field)
        {
            return Err(loc.at(
                span.clone(),
                format!("{key}.{field}"),
                format!("'{field}' does not apply to type '{kind}' (it takes: {})", allowed.join(", ")),
            ));
        }
    }
    let material = materials.iter().position(|m| m.name == *d.material.get_ref()).ok_or_else(|| {
        let known = materials.iter().map(|m| m.name.as_str()).collect::<Vec<_>>().join(", ");
        loc.at(
            d.material.span(),
            format!("{key}.material"),
            format!("material '{}' is not defined (defined: {known})", d.material.get_ref()),
        )
    })?;
    let missing =
        |field: &str| loc.at(o.span(), format!("{key}.{field}"), format!("type '{kind}' needs '{field}'"));
    let facing = |n: &Option<Spanned<String>>| -> Result<Facing, LoadError> {
        match n.as_ref().map(|s| (s.get_ref().as_str(), s.span())) {
            None | Some(("outward", _)) => Ok(Facing::Outward),
            Some(("inward", _)) => Ok(Facing::Inward),
            Some((other, span)) => Err(loc.at(
                span,
                format!("{key}.normals"),
                format!("expected \"inward\" or \"outward\", got \"{other}\""),
            )),
        }
    };
    let poly = |pts: &[[f64; 3]], span: Range<usize>, field: String| {
        Polygon::try_new(pts.iter().map(|p| v3(*p)).collect()).map_err(|e| loc.at(span, field, e.to_string()))
    };
    let shape = match kind {
        "polygon" => {
            let v = d.vertices.as_ref().ok_or_else(|| missing("vertices"))?;
            Shape::Polygons(vec![poly(v.get_ref(), v.span(), format!("{key}.vertices"))?])
        }
        "polygons" => {
            let f = d.faces.as_ref().ok_or_else(|| missing("faces"))?;
            if f.get_ref().is_empty() {
                return Err(loc.at(f.span(), format!("{key}.faces"), "expected at least one face"));
            }
            let faces = f
                .get_ref()
                .iter()
                .enumerate()
                .map(|(k, face)| poly(face, f.span(), format!("{key}.faces[{k}]")))
                .collect::<Result<_, _>>()?;
            Shape::Polygons(faces)
        }
        "box" => {
            let (min, max) = (
                d.min.as_ref().ok_or_else(|| missing("min"))?,
                d.max.as_ref().ok_or_else(|| missing("max"))?,
            );
            let rot = d.rotate_y_deg.as_ref().map_or(0.0, |r| *r.get_ref());
            let faces = box_faces(v3(*min.get_ref()), v3(*max.get_ref()), facing(&d.normals)?, rot)
                .map_err(|e| loc.at(min.span(), format!("{key}.min"), e.to_string()))?;
            Shape::Polygons(faces)
        }
        "sphere" => {
            let c = d.center.as_ref().ok_or_else(|| missing("center"))?;
            let r = d.radius.as_ref().ok_or_else(|| missing("radius"))?;
            let s = Sphere::try_new(v3(*c.get_ref()), *r.get_ref(), facing(&d.normals)?).map_err(|e| {
                let (span, field) = if matches!(e, SceneError::BadRadius { .. }) {
                    (r.span(), "radius")
                } else {
                    (c.span(), "center")
                };
                loc.at(span, format!("{key}.{field}"), e.to_string())
            })?;
            Shape::Sphere(s)
        }
        _ => unreachable!("object types are checked above"),
    };
    Ok(Object { name, material, shape })
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
name = "t"
[[material]]
name = "w"
reflectance = [0.5, 0.5, 0.5]
[[material]]
name = "light"
reflectance = [0, 0, 0]
emission = [1, 1, 1]
[[object]]
name = "room"
type = "box"
min = [0, 0, 0]
max = [1, 1, 1]
normals = "inward"
material = "w"
[[object]]
name = "lamp"
type = "polygon"
vertices = [[0.4, 0.99, 0.4], [0.4, 0.99, 0.6], [0.6, 0.99, 0.6], [0.6, 0.99, 0.4]]
material = "light"
"#;

    /// Replaces the first `from` in GOOD by `to`, parses, and returns the error line.
    fn error_of(from: &str, to: &str) -> String {
        assert!(GOOD.contains(from), "{from}");
        let text = GOOD.replacen(from, to, 1);
        let e = parse_scene(&text, "bad.toml").expect_err("must fail");
        let s = e.to_string();
        assert_eq!(s.lines().count(), 1, "{s}");
        assert!(s.starts_with("bad.toml:"), "{s}");
        s
    }

    fn line_of(s: &str) -> usize {
        s.split(':').nth(1).unwrap().parse().unwrap()
    }

    #[test]
    fn good_scene_loads() {
        let s = parse_scene(GOOD, "good.toml").unwrap();
        assert_eq!(s.objects.len(), 2);
        assert_eq!(s.name, "t");
    }

    #[test]
    fn each_malformed_case_names_its_line_and_key() {
        // (replace, with, expected line, text the message must hold)
        let cases: &[(&str, &str, usize, &str)] = &[
            ("reflectance = [0.5, 0.5, 0.5]", "reflectance = [1.0, 0.5, 0.5]", 5, "material[0].reflectance"),
            ("reflectance = [0.5, 0.5, 0.5]", "reflectance = [nan, 0.5, 0.5]", 5, "[0, 1)"),
            ("emission = [1, 1, 1]", "emission = [1, -1, 1]", 9, "material[1].emission"),
            ("emission = [1, 1, 1]", "emission = [inf, 1, 1]", 9, "finite"),
            ("material = \"light\"", "material = \"lite\"", 21, "defined: w, light"),
            ("name = \"light\"", "name = \"w\"", 7, "defined twice"),
            ("max = [1, 1, 1]", "max = [1, 0, 1]", 13, "min must be below max"),
            ("[0.6, 0.99, 0.6]", "[0.4, 0.99, 0.4]", 20, "degenerate"),
            ("[0.6, 0.99, 0.6]", "[0.6, 0.5, 0.6]", 20, "not planar"),
            ("[0.6, 0.99, 0.6]", "[0.45, 0.99, 0.45]", 20, "not convex"),
            ("[0.6, 0.99, 0.6], [0.6, 0.99, 0.4]", "", 20, "at least 3 vertices"),
            ("[0.4, 0.99, 0.6]", "[0.4, nan, 0.6]", 20, "finite"),
            ("normals = \"inward\"", "normals = \"in\"", 15, "\"inward\" or \"outward\""),
            ("type = \"box\"", "type = \"cube\"", 12, "unknown object type"),
            ("type = \"box\"", "type = \"mesh\"", 12, "not supported yet"),
            ("min = [0, 0, 0]", "mins = [0, 0, 0]", 13, "mins"),
            ("name = \"t\"", "name = \"t\"\ncolour = 1", 3, "colour"),
            ("reflectance = [0.5, 0.5, 0.5]", "reflectance = [0.5, 0.5]", 5, "reflectance: invalid length 2"),
            ("reflectance = [0.5, 0.5, 0.5]", "reflectance = \"grey\"", 5, "reflectance"),
            ("[[material]]\nname = \"w\"", "[[material]\nname = \"w\"", 3, "toml"),
            ("vertices =", "center = [0, 0, 0]\nvertices =", 20, "does not apply"),
        ];
        for (from, to, line, needle) in cases {
            let s = error_of(from, to);
            assert_eq!(line_of(&s), *line, "{from} -> {to}: {s}");
            assert!(s.contains(needle), "{from} -> {to}: {s}");
        }
    }

    #[test]
    fn sphere_radius_and_light_and_mesh_errors() {
        let sphere = GOOD.replace(
            "type = \"box\"\nmin = [0, 0, 0]\nmax = [1, 1, 1]",
            "type = \"sphere\"\ncenter = [0, 0, 0]\nradius = -1",
        );
        let e = parse_scene(&sphere, "s.toml").unwrap_err().to_string();
        assert!(e.contains("radius") && e.contains(":14:"), "{e}");
        let dark = GOOD.replace("emission = [1, 1, 1]", "emission = [0, 0, 0]");
        let e = parse_scene(&dark, "d.toml").unwrap_err().to_string();
        assert!(e.contains("no light"), "{e}");
        let mesh = format!("{GOOD}[mesh]\npatch_size = 0.5\nelement_size = 0\n");
        let e = parse_scene(&mesh, "m.toml").unwrap_err().to_string();
        assert!(e.contains("element_size") && e.contains(":24:"), "{e}");
        let solver = format!("{GOOD}[solver]\nunshot_threshold = 1.5\n");
        let e = parse_scene(&solver, "m.toml").unwrap_err().to_string();
        assert!(e.contains("(0, 1)") && e.contains(":23:"), "{e}");
        let e = load_scene(Path::new("/no/such/file.toml")).unwrap_err().to_string();
        assert!(e.contains("/no/such/file.toml"), "{e}");
    }

    #[test]
    fn mutated_files_never_panic() {
        // Deterministic mutations of the Cornell file: truncations, deletions, insertions,
        // replacements. Every one must give Ok or a one-line Err, never a panic.
        let base = include_str!("../../../scenes/cornell.toml").as_bytes().to_vec();
        let alphabet = b"[]{}=\",.-0123456789 \nabcxyz#nanif";
        let mut state = 0x1234_5678_9abc_def0u64;
        let mut next = |n: usize| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % n as u64) as usize
        };
        for i in 0..3000 {
            let mut b = base.clone();
            match i % 4 {
                0 => b.truncate(next(b.len())),
                1 => {
                    let at = next(b.len());
                    b.remove(at);
                }
                2 => b.insert(next(b.len()), alphabet[next(alphabet.len())]),
                _ => {
                    let at = next(b.len());
                    b[at] = alphabet[next(alphabet.len())];
                }
            }
            let text = String::from_utf8_lossy(&b).into_owned();
            let r = std::panic::catch_unwind(|| parse_scene(&text, "m.toml"));
            match r {
                Ok(Ok(_)) => {}
                Ok(Err(e)) => assert_eq!(e.to_string().lines().count(), 1, "mutation {i}: {e}"),
                Err(_) => panic!("mutation {i} panicked"),
            }
        }
    }
}
