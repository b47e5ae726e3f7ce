//! Wavefront OBJ + MTL through `tobj`, after a line scan of our own: `tobj` reports *what* is
//! wrong but not *where*, and a user with a 100k-line file needs the line. The scan checks
//! what `tobj` would reject or accept badly (vertex lines that are not finite numbers, face
//! indices out of range, faces of fewer than 3 vertices) and records each face's line.
//!
//! Each MTL library is checked line by line before `tobj` sees it ([`check_mtl`]): `tobj`
//! panics on a colour of fewer than three numbers, and its other MTL errors name no line.

use rustc_hash::FxHashMap as HashMap;
use std::cell::RefCell;
use std::io::Cursor;
use std::path::Path;

use radiosity_core::glam::DVec3;
use radiosity_core::{Sides, Wrap, unique_names};

use crate::LoadError;
use crate::model::{
    DEFAULT_GREY, DecodedImage, MAX_TEXT_BYTES, Model, ModelPart, PartBuilder, Transform, clamp_reflectance,
    model_error, model_material, read_input_file, read_texture, specular_warning,
};
use crate::texture_map::{UvTransform, parse_map_kd};

/// Sides of every OBJ part: the format says nothing, and modellers and Blender show its faces
/// from both sides (the normals of many files face every which way). The emission stays on the
/// front face, the side the file's winding points to.
const OBJ_SIDES: Sides = Sides::Two { emits_back: false };

/// What in an MTL material says it is mirror-like or see-through, or `None` for a diffuse
/// one: an illumination model with reflection or refraction (3 to 7), a strong sharp
/// highlight (`Ks` above 0.5 with `Ns` ≥ 100: a weak or broad one is the gloss of a diffuse
/// paint), or transmission (`d` < 1, `Tr` > 0, `Tf` below 1).
fn specular_reason(m: &tobj::Material) -> Option<String> {
    if let Some(illum @ 3..=7) = m.illumination_model {
        return Some(format!("illum {illum}"));
    }
    let ks = m.specular.map_or(0.0, |k| k.iter().copied().fold(0.0, f64::max));
    let ns = m.shininess.unwrap_or(0.0);
    if ks > 0.5 && ns >= 100.0 {
        return Some(format!("Ks {ks} with Ns {ns}"));
    }
    if let Some(d) = m.dissolve.filter(|&d| d < 1.0) {
        return Some(format!("d {d}"));
    }
    let numbers = |key: &str| -> Vec<f64> {
        m.unknown_param
            .get(key)
            .map(|v| v.split_whitespace().filter_map(|w| w.parse().ok()).collect())
            .unwrap_or_default()
    };
    if let Some(tr) = numbers("Tr").first().filter(|&&t| t > 0.0) {
        return Some(format!("Tr {tr}"));
    }
    let tf = numbers("Tf");
    if tf.len() == 3 && tf.iter().any(|&t| t < 1.0) {
        return Some(format!("Tf {} {} {}", tf[0], tf[1], tf[2]));
    }
    None
}

/// What the line scan learns: the line of every face, in file order, and every `usemtl`.
struct Scan {
    face_lines: Vec<usize>,
    /// Material name and line of each `usemtl`, to warn about names no library defines.
    usemtl: Vec<(String, usize)>,
}

/// Checks an MTL text line by line and returns it as `tobj` can read it without panicking:
/// a colour given as one number (the MTL spec's grey, `Kd 0.5`) is written out as three.
///
/// # Errors
/// The first malformed line, named by file and line: a colour (`Ka`, `Kd`, `Ks`, `Ke`)
/// that is not one or three finite numbers, a number key (`Ns`, `Ni`, `d`, `illum`) that is
/// not a number, a `newmtl` without a name, a texture key without a file.
pub(crate) fn check_mtl(text: &str, origin: &str) -> Result<String, LoadError> {
    let mut out = String::with_capacity(text.len() + 64);
    for (l, raw) in text.lines().enumerate() {
        let err = |m: String| model_error(origin, Some(l + 1), m);
        let line = raw.trim();
        let mut words = line.split_whitespace();
        let key = words.next().unwrap_or("");
        // A comment after a number key's values ends them (`Ka 0.63 0.065 0.05 # Red`, as in
        // McGuire's Cornell box); a name or file name may hold a '#', so only number keys.
        let numeric = matches!(key, "Ka" | "Kd" | "Ks" | "Ke" | "Ns" | "Ni" | "d" | "illum" | "Tr" | "Tf");
        let values: Vec<&str> =
            if numeric { words.take_while(|w| !w.starts_with('#')).collect() } else { words.collect() };
        let number = |w: &str| w.parse::<f64>().ok().filter(|v| v.is_finite());
        match key {
            "Ka" | "Kd" | "Ks" | "Ke" => {
                if values.iter().any(|w| number(w).is_none()) || !(values.len() == 1 || values.len() == 3) {
                    let shown: String = values.join(" ").chars().take(60).collect();
                    return Err(err(format!(
                        "{key}: expected three finite numbers r g b (or one, a grey), got '{shown}'"
                    )));
                }
                if values.len() == 1 {
                    out.push_str(&format!("{key} {0} {0} {0}\n", values[0]));
                    continue;
                }
            }
            "Ns" | "Ni" | "d" if values.first().and_then(|w| number(w)).is_none() => {
                return Err(err(format!("{key}: expected a finite number")));
            }
            "illum" if values.first().and_then(|w| w.parse::<u8>().ok()).is_none() => {
                return Err(err("illum: expected an illumination model number 0 to 10".into()));
            }
            "newmtl" if values.is_empty() => return Err(err("newmtl: the material needs a name".into())),
            k if (k.starts_with("map_") || k == "bump") && values.is_empty() => {
                return Err(err(format!("{k}: expected a texture file name")));
            }
            _ => {}
        }
        if numeric {
            out.push_str(&format!("{key} {}\n", values.join(" ")));
        } else {
            out.push_str(raw);
            out.push('\n');
        }
    }
    Ok(out)
}

/// Checks `v` and `f` lines; the first problem is an error naming its line and element.
fn scan(text: &str, origin: &str) -> Result<Scan, LoadError> {
    let mut vertices = 0usize;
    let mut face_lines = Vec::new();
    let mut usemtl = Vec::new();
    for (l, line) in text.lines().enumerate() {
        let line_no = l + 1;
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                vertices += 1;
                let numbers: Vec<&str> = words.take(3).collect();
                let values: Vec<Option<f64>> = numbers.iter().map(|w| w.parse::<f64>().ok()).collect();
                if values.len() < 3 || values.iter().any(Option::is_none) {
                    return Err(model_error(
                        origin,
                        Some(line_no),
                        format!("vertex {vertices}: expected 3 numbers x y z, got '{}'", line.trim()),
                    ));
                }
                let p: Vec<f64> = values.into_iter().flatten().collect();
                if p.iter().any(|v| !v.is_finite()) {
                    return Err(model_error(
                        origin,
                        Some(line_no),
                        format!("vertex {vertices}: coordinates must be finite numbers, got {p:?}"),
                    ));
                }
                if p.iter().any(|v| v.abs() > radiosity_core::MAX_COORDINATE) {
                    return Err(model_error(
                        origin,
                        Some(line_no),
                        format!(
                            "vertex {vertices}: coordinates must be within ±{:e} of the origin, got {p:?}",
                            radiosity_core::MAX_COORDINATE
                        ),
                    ));
                }
            }
            Some("f") => {
                let face = face_lines.len() + 1;
                let corners: Vec<&str> = words.collect();
                if corners.len() < 3 {
                    return Err(model_error(
                        origin,
                        Some(line_no),
                        format!("face {face}: a face needs at least 3 vertices, got {}", corners.len()),
                    ));
                }
                for c in corners {
                    let first = c.split('/').next().unwrap_or("");
                    let Ok(i) = first.parse::<i64>() else {
                        return Err(model_error(
                            origin,
                            Some(line_no),
                            format!("face {face}: expected a vertex index, got '{c}'"),
                        ));
                    };
                    // OBJ indices count from 1; negative ones count back from the last vertex.
                    let resolved = if i < 0 { vertices as i64 + 1 + i } else { i };
                    if resolved < 1 || resolved > vertices as i64 {
                        return Err(model_error(
                            origin,
                            Some(line_no),
                            format!(
                                "face {face}: vertex index {i} out of range (file has {vertices} vertices)"
                            ),
                        ));
                    }
                }
                face_lines.push(line_no);
            }
            Some("usemtl") => usemtl.push((words.collect::<Vec<_>>().join(" "), line_no)),
            _ => {}
        }
    }
    Ok(Scan { face_lines, usemtl })
}

/// Line of `key` within material `name` of an MTL text, for errors.
fn mtl_line(text: &str, name: &str, key: &str) -> Option<usize> {
    let mut in_material = false;
    for (l, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("newmtl") => {
                in_material = words.collect::<Vec<_>>().join(" ") == name;
                if in_material && key == "newmtl" {
                    return Some(l + 1);
                }
            }
            Some(k) if in_material && k == key => return Some(l + 1),
            _ => {}
        }
    }
    None
}

/// Parses an OBJ file's bytes; MTL libraries are read from `base` (none: every face grey).
///
/// # Errors
/// See [`crate::load_model`].
pub(crate) fn parse_obj(
    bytes: &[u8],
    origin: &str,
    base: Option<&Path>,
    transform: &Transform,
) -> Result<Model, LoadError> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        model_error(origin, None, format!("not a text file (invalid UTF-8 at byte {})", e.valid_up_to()))
    })?;
    let scan = scan(text, origin)?;
    if scan.face_lines.is_empty() {
        return Err(model_error(origin, None, "the file has no faces (`f` lines)"));
    }
    // MTL texts read by the loader, kept for error lines; and why a library could not be read.
    let mtl_texts: RefCell<Vec<(String, String)>> = RefCell::new(Vec::new());
    let mtl_problems: RefCell<Vec<String>> = RefCell::new(Vec::new());
    // A malformed library is an error, not a warning: its materials would all be lost.
    let mtl_error: RefCell<Option<LoadError>> = RefCell::new(None);
    let options = tobj::LoadOptions {
        triangulate: false,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let loaded = tobj::load_obj_buf(&mut Cursor::new(bytes), &options, |p| {
        let Some(base) = base else {
            mtl_problems.borrow_mut().push(format!("'{}': no folder to read it from", p.display()));
            return Err(tobj::LoadError::OpenFileFailed);
        };
        let path = base.join(p);
        let mtl_origin = path.display().to_string();
        match read_input_file(&path, MAX_TEXT_BYTES) {
            Ok(mtl) => {
                let checked = std::str::from_utf8(&mtl)
                    .map_err(|e| {
                        model_error(
                            &mtl_origin,
                            None,
                            format!("not a text file (invalid UTF-8 at byte {})", e.valid_up_to()),
                        )
                    })
                    .and_then(|text| check_mtl(text, &mtl_origin));
                let text = match checked {
                    Ok(text) => text,
                    Err(e) => {
                        mtl_error.borrow_mut().get_or_insert(e);
                        return Err(tobj::LoadError::MaterialParseError);
                    }
                };
                let result = tobj::load_mtl_buf(&mut Cursor::new(text.as_bytes()));
                if let Err(e) = &result {
                    mtl_problems.borrow_mut().push(format!("{mtl_origin}: {e}"));
                }
                mtl_texts.borrow_mut().push((mtl_origin, text));
                result
            }
            Err(e) => {
                mtl_problems.borrow_mut().push(format!("{mtl_origin}: {e}"));
                Err(tobj::LoadError::OpenFileFailed)
            }
        }
    });
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    let (models, materials) = loaded.map_err(|e| model_error(origin, None, format!("OBJ: {e}")))?;
    let mut warnings = Vec::new();
    let materials = materials.unwrap_or_else(|_| Vec::new());
    // tobj maps an unknown `usemtl` name to no material at all; say which line did it.
    for (name, line) in &scan.usemtl {
        if !materials.iter().any(|m| &m.name == name) {
            warnings.push(format!(
                "{origin}:{line}: usemtl '{}': no material library defines it; its faces are default grey ({DEFAULT_GREY})",
                name.chars().take(60).collect::<String>()
            ));
        }
    }
    for p in mtl_problems.into_inner() {
        warnings.push(format!(
            "{origin}: cannot read material library {p}; its faces are default grey ({DEFAULT_GREY})"
        ));
    }
    let mtl_texts = mtl_texts.into_inner();

    // Our materials: those the parts use, in order of first use, plus the grey default.
    let mut out_materials: Vec<radiosity_core::Material> = Vec::new();
    let mut material_of: HashMap<Option<usize>, (usize, UvTransform)> = HashMap::default();
    let mut resolve = |id: Option<usize>,
                       warnings: &mut Vec<String>|
     -> Result<(usize, UvTransform), LoadError> {
        if let Some(&m) = material_of.get(&id) {
            return Ok(m);
        }
        let mut uv_transform = UvTransform::default();
        let mut kept = None;
        let material = match id.and_then(|i| materials.get(i)) {
            Some(m) => {
                let found =
                    mtl_texts.iter().find_map(|(f, t)| mtl_line(t, &m.name, "newmtl").map(|_| (f, t)));
                let (mtl_origin, line_of) = match found {
                    Some((f, t)) => (f.as_str(), Some(t.as_str())),
                    None => (origin, None),
                };
                let line = |key: &str| line_of.and_then(|t| mtl_line(t, &m.name, key));
                // A texture is read from the MTL's folder; its mean colour scales Kd, as glTF's
                // base colour texture scales its factor.
                // The image is kept for pictures, placed by the `map_Kd` options.
                let folder = Path::new(mtl_origin).parent().filter(|_| line_of.is_some());
                let mut read = |kind: &str, file: &str| match folder.map(|f| read_texture(&f.join(file))) {
                    Some(Ok(image)) => Some(image),
                    Some(Err(e)) => {
                        warnings.push(format!(
                            "{mtl_origin}: material '{}': {kind} '{file}' not read ({e}); {}",
                            m.name,
                            if kind == "map_d" { "its faces are solid" } else { "Kd alone used" }
                        ));
                        None
                    }
                    None => None,
                };
                let map = m.diffuse_texture.as_deref().map(parse_map_kd);
                let mut colour = map.as_ref().and_then(|map| read("texture", &map.file));
                // `map_d`: a scalar map (its alpha, or a grey image's value) cut at one half,
                // placed as `map_Kd` is (its own options are not read). Of two sizes, the
                // colour and the mask meet at the finer: the coarser would alias the other.
                let mask_map = m.dissolve_texture.as_deref().map(parse_map_kd);
                let mask = mask_map.as_ref().and_then(|d| read("map_d", &d.file)).and_then(|d| {
                    let (w, h) = d.size();
                    let mask = d.mask(1.0, 0.5, true)?;
                    let texels = |(a, b): (u32, u32)| u64::from(a) * u64::from(b);
                    Some(match &mut colour {
                        Some(c) if c.size() != (w, h) && texels(c.size()) >= texels((w, h)) => {
                            (c.resampled(&mask, w, h), c.size())
                        }
                        Some(c) if c.size() != (w, h) => {
                            *c = c.scaled(w, h);
                            (mask, (w, h))
                        }
                        _ => (mask, (w, h)),
                    })
                });
                let wrap = map.as_ref().or(mask_map.as_ref()).map_or(Wrap::Repeat, |m| m.wrap);
                uv_transform = map.as_ref().or(mask_map.as_ref()).map_or(uv_transform, |m| m.transform);
                let factor = m.diffuse.unwrap_or([1.0; 3]);
                // With a mask, the reflectance is the mean of what is there.
                let image = match (colour, &mask) {
                    (Some(image), _) => Some(image),
                    (None, Some((_, (w, h)))) => Some(DecodedImage::white(*w, *h)),
                    (None, None) => None,
                };
                let texture = image.map(|image| {
                    let mask = mask.map(|(k, _)| k);
                    let mean = mask.as_deref().map_or(image.mean, |k| image.masked_mean(k));
                    kept = Some(image.texture(factor, [wrap; 2], mask));
                    mean
                });
                let reflectance = match (m.diffuse, texture) {
                    (Some(kd), Some(mean)) => [kd[0] * mean[0], kd[1] * mean[1], kd[2] * mean[2]],
                    (Some(kd), None) => kd,
                    // The texture alone is what a viewer shows.
                    (None, Some(mean)) => mean,
                    (None, None) => {
                        warnings.push(format!(
                            "{mtl_origin}: material '{}' has no Kd; it is default grey ({DEFAULT_GREY})",
                            m.name
                        ));
                        [DEFAULT_GREY; 3]
                    }
                };
                let reflectance = clamp_reflectance(mtl_origin, &m.name, reflectance, warnings);
                if let Some(why) = specular_reason(m) {
                    warnings.push(specular_warning(mtl_origin, &m.name, &why));
                }
                let emission = m.emissive.unwrap_or([0.0; 3]);
                // Name the line of the value at fault: Kd unless only the emission is wrong.
                let bad_kd = !reflectance.iter().all(|v| v.is_finite() && (0.0..1.0).contains(v));
                let key_line = if bad_kd { line("Kd") } else { line("Ke") };
                let key_line = if key_line.is_some() { key_line } else { line("newmtl") };
                let mut material = model_material(mtl_origin, key_line, &m.name, reflectance, emission)?;
                material.texture = kept;
                material
            }
            None => {
                if let Some(i) = id {
                    warnings.push(format!(
                        "{origin}: material #{i} is not in any material library; its faces are default grey"
                    ));
                }
                model_material(origin, None, "default", [DEFAULT_GREY; 3], [0.0; 3])?
            }
        };
        let name = material.name.clone();
        // Two MTL files may define the same name; the second one becomes `name#2`.
        let mut names: Vec<String> = out_materials.iter().map(|m| m.name.clone()).collect();
        names.push(name);
        unique_names(&mut names);
        let mut material = material;
        material.name = names.pop().unwrap_or_default();
        out_materials.push(material);
        material_of.insert(id, (out_materials.len() - 1, uv_transform));
        Ok((out_materials.len() - 1, uv_transform))
    };

    let total_faces: usize = models
        .iter()
        .map(|m| {
            if m.mesh.face_arities.is_empty() { m.mesh.indices.len() / 3 } else { m.mesh.face_arities.len() }
        })
        .sum();
    // tobj keeps faces in file order; when the counts agree, face k of the file is line k.
    let face_line =
        |k: usize| (total_faces == scan.face_lines.len()).then(|| scan.face_lines.get(k).copied()).flatten();
    let mut parts = Vec::new();
    let mut dropped = 0usize;
    let mut face_number = 0usize;
    let stem =
        Path::new(origin).file_stem().map_or_else(|| "model".into(), |s| s.to_string_lossy().into_owned());
    for model in &models {
        let mesh = &model.mesh;
        let (material, uv_transform) = resolve(mesh.material_id, &mut warnings)?;
        // Texture coordinates per corner, where every corner of the object has one: mapped
        // by the `map_Kd` options, and v turned to run down the image as the renderer's does.
        let textured = !mesh.texcoord_indices.is_empty() && mesh.texcoord_indices.len() == mesh.indices.len();
        let uv_of = |k: usize| -> Option<[f64; 2]> {
            let t = *mesh.texcoord_indices.get(k)? as usize;
            let uv = [*mesh.texcoords.get(2 * t)?, *mesh.texcoords.get(2 * t + 1)?];
            let [u, v] = uv_transform.apply(uv);
            Some([u, 1.0 - v])
        };
        let mut b = PartBuilder::new(transform.matrix());
        let mut welded = Vec::with_capacity(mesh.positions.len() / 3);
        for (k, p) in mesh.positions.chunks_exact(3).enumerate() {
            let v = b.vertex(DVec3::new(p[0], p[1], p[2])).map_err(|m| {
                model_error(origin, None, format!("object '{}': vertex {}: {m}", model.name, k + 1))
            })?;
            welded.push(v);
        }
        let arities: Vec<usize> = if mesh.face_arities.is_empty() {
            vec![3; mesh.indices.len() / 3]
        } else {
            mesh.face_arities.iter().map(|&a| a as usize).collect()
        };
        let mut start = 0;
        for arity in arities {
            face_number += 1;
            let uvs: Option<Vec<[f64; 2]>> =
                textured.then(|| (start..start + arity).map(uv_of).collect()).flatten();
            let Some(ids) = mesh.indices.get(start..start + arity) else {
                return Err(model_error(
                    origin,
                    face_line(face_number - 1),
                    format!("face {face_number}: indices missing"),
                ));
            };
            start += arity;
            let mut face = Vec::with_capacity(arity);
            for &i in ids {
                let Some(&v) = welded.get(i as usize) else {
                    return Err(model_error(
                        origin,
                        face_line(face_number - 1),
                        format!(
                            "face {face_number}: vertex index {} out of range (object has {} vertices)",
                            i + 1,
                            welded.len()
                        ),
                    ));
                };
                face.push(v);
            }
            b.face_with_uvs(face, uvs).map_err(|m| {
                model_error(origin, face_line(face_number - 1), format!("face {face_number}: {m}"))
            })?;
        }
        dropped += b.dropped;
        let name = if model.name.is_empty() || model.name == "unnamed_object" {
            stem.clone()
        } else {
            model.name.clone()
        };
        if b.is_empty() {
            warnings.push(format!("{origin}: object '{name}' has no face with an area; left out"));
            continue;
        }
        let mesh = b.build().map_err(|m| model_error(origin, None, format!("object '{name}': {m}")))?;
        parts.push(ModelPart { name, material, mesh, sides: OBJ_SIDES });
    }
    if dropped > 0 {
        warnings.push(format!("{origin}: {dropped} degenerate face(s) (zero area) dropped"));
    }
    if parts.is_empty() {
        return Err(model_error(origin, None, "no face with an area: every face is degenerate"));
    }
    // tobj starts a new model at each `usemtl`: parts named alike are told apart by material.
    let mut counts: HashMap<&str, usize> = HashMap::default();
    for p in &parts {
        *counts.entry(p.name.as_str()).or_insert(0) += 1;
    }
    let mut names: Vec<String> = parts
        .iter()
        .map(|p| {
            if counts[p.name.as_str()] > 1 {
                format!("{}/{}", p.name, out_materials[p.material].name)
            } else {
                p.name.clone()
            }
        })
        .collect();
    unique_names(&mut names);
    for (p, n) in parts.iter_mut().zip(names) {
        p.name = n;
    }
    Ok(Model { parts, materials: out_materials, camera: None, warnings })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        parse_obj(text.as_bytes(), "m.obj", None, &Transform::default()).unwrap_err().to_string()
    }

    /// Every colour line `tobj` would panic on or misread is caught with its line; a single
    /// number is the MTL spec's grey and is written out as three for `tobj`.
    #[test]
    fn mtl_lines_are_checked_before_tobj_sees_them() {
        let ok = check_mtl("newmtl a\n  Kd 0.5\nKe 1 2 3\nNs 10\nillum 2\n# Kd\n", "m.mtl").unwrap();
        assert_eq!(ok, "newmtl a\nKd 0.5 0.5 0.5\nKe 1 2 3\nNs 10\nillum 2\n# Kd\n");
        let (materials, _) = tobj::load_mtl_buf(&mut Cursor::new(ok.as_bytes())).unwrap();
        assert_eq!(materials[0].diffuse, Some([0.5; 3]));
        // A comment after the numbers is dropped before tobj reads them.
        let commented = "newmtl a\r\n  Ka 0.63 0.065 0.05 # Red\r\nKd 0.5 #grey\r\nNs 10.0 # soft\r\n";
        let ok = check_mtl(commented, "m.mtl").unwrap();
        assert_eq!(ok, "newmtl a\nKa 0.63 0.065 0.05\nKd 0.5 0.5 0.5\nNs 10.0\n");
        for (text, expected) in [
            ("newmtl a\nKd # 0.5 0.5 0.5\n", "m.mtl:2: Kd: expected three finite numbers"),
            ("newmtl a\nKd\n", "m.mtl:2: Kd: expected three finite numbers"),
            ("newmtl a\nKd 1 2\n", "m.mtl:2: Kd"),
            ("newmtl a\nKa 1 2 3 4\n", "m.mtl:2: Ka"),
            ("newmtl a\nKs 1 inf 1\n", "m.mtl:2: Ks"),
            ("newmtl a\n\nKe xyz 1 1 1\n", "m.mtl:3: Ke"),
            ("newmtl a\nd\n", "m.mtl:2: d: expected a finite number"),
            ("newmtl a\nillum -1\n", "m.mtl:2: illum"),
            ("newmtl\n", "m.mtl:1: newmtl"),
            ("newmtl a\nmap_Kd   \n", "m.mtl:2: map_Kd"),
        ] {
            let e = check_mtl(text, "m.mtl").unwrap_err().to_string();
            assert!(e.starts_with(expected), "{text:?}: {e}");
        }
    }

    #[test]
    fn the_scan_names_line_face_and_index() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 40\n";
        assert_eq!(err(text), "m.obj:5: face 2: vertex index 40 out of range (file has 3 vertices)");
        assert_eq!(
            err("v 0 0 nan\n"),
            "m.obj:1: vertex 1: coordinates must be finite numbers, got [0.0, 0.0, NaN]"
        );
        assert_eq!(err("v 0 0\n"), "m.obj:1: vertex 1: expected 3 numbers x y z, got 'v 0 0'");
        assert_eq!(err("v 0 0 0\nf 1 1\n"), "m.obj:2: face 1: a face needs at least 3 vertices, got 2");
        assert_eq!(err("v 0 0 0\nf 1 x 1\n"), "m.obj:2: face 1: expected a vertex index, got 'x'");
        assert_eq!(err("v 0 0 0\n"), "m.obj: the file has no faces (`f` lines)");
    }

    #[test]
    fn negative_indices_and_ngons_load_without_an_mtl() {
        let text = "o quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf -4 -3 -2 -1\n";
        let m = parse_obj(text.as_bytes(), "m.obj", None, &Transform::default()).unwrap();
        assert_eq!(m.parts.len(), 1);
        assert_eq!(m.parts[0].name, "quad");
        assert_eq!(m.parts[0].mesh.faces()[0].len(), 4);
        assert_eq!(m.materials[0].reflectance, radiosity_core::Rgb::splat(DEFAULT_GREY));
    }

    #[test]
    fn degenerate_faces_are_dropped_and_counted() {
        let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n";
        let m = parse_obj(text.as_bytes(), "m.obj", None, &Transform::default()).unwrap();
        assert_eq!(m.parts[0].mesh.faces().len(), 1);
        assert!(m.warnings.iter().any(|w| w.contains("1 degenerate face(s)")), "{:?}", m.warnings);
        assert_eq!(
            err("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"),
            "m.obj: no face with an area: every face is degenerate"
        );
    }
}
