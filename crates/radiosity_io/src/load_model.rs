//! A model file read whole: its bytes (bounded), the parser its extension names (`obj`,
//! `gltf_in`), then faces an exporter repeated dropped.

use std::path::Path;

use radiosity_core::{PolygonMesh, escape_controls};

use crate::LoadError;
use crate::model::{MAX_MODEL_BYTES, Model, ModelFormat, ModelPart, Transform, read_input_file};

/// Reads the model at `path` with `transform` applied.
///
/// # Errors
/// [`LoadError::Model`], one line naming the file (and line, for OBJ/MTL) and the element:
/// unreadable or malformed files, indices out of range, non-finite coordinates, negative or
/// non-finite reflectance, negative emission, or no face left after dropping degenerate ones.
pub fn load_model(path: &Path, transform: &Transform) -> Result<Model, LoadError> {
    let origin = path.display().to_string();
    let bytes = read_input_file(path, MAX_MODEL_BYTES).map_err(|e| LoadError::Model {
        origin: origin.clone(),
        line: None,
        message: format!("cannot read the model file: {e}"),
    })?;
    let base = path.parent().unwrap_or(Path::new("."));
    match ModelFormat::from_path(path) {
        Some(format) => parse_model(&bytes, &origin, Some(base), format, transform),
        None => Err(LoadError::Model {
            origin,
            line: None,
            message: "unknown model format; expected a .obj, .gltf or .glb file".into(),
        }),
    }
}

/// Parses a model file's bytes in `format`; MTL libraries, glTF buffers and images that the
/// file names are read from `base` (without one, an OBJ's faces are grey and a glTF may only
/// use embedded data). `origin` names the file in messages.
///
/// # Errors
/// As [`load_model`].
pub fn parse_model(
    bytes: &[u8],
    origin: &str,
    base: Option<&Path>,
    format: ModelFormat,
    transform: &Transform,
) -> Result<Model, LoadError> {
    let mut model = match format {
        ModelFormat::Obj => crate::obj::parse_obj(bytes, origin, base, transform),
        ModelFormat::Gltf => crate::gltf_in::parse_gltf(bytes, origin, base, transform),
    }?;
    let duplicates = drop_duplicate_faces(&mut model.parts);
    if duplicates > 0 {
        model.warnings.push(format!(
            "{}: {duplicates} duplicate face(s) dropped (the same corners, facing the same way, as an earlier face): their light would have been reflected twice",
            escape_controls(origin)
        ));
    }
    Ok(model)
}

/// Removes every face whose corners (the same points, in the same cyclic order, so facing
/// the same way) repeat a face met earlier in `parts`, in this part or another: exporters
/// repeat faces (McGuire's Cornell boxes give each block a "bottom face" that is one of its
/// sides again), and two coincident faces would each receive and reflect the same light.
/// A part left with no face is removed. Returns the number of faces dropped. Faces back to
/// back (the same corners facing opposite ways) are kept: they are how a one-sided format
/// models a thin two-sided sheet.
fn drop_duplicate_faces(parts: &mut Vec<ModelPart>) -> usize {
    let mut seen: std::collections::HashSet<Vec<[u64; 3]>> = std::collections::HashSet::new();
    let mut dropped = 0;
    let mut emptied = vec![false; parts.len()];
    for (part, emptied) in parts.iter_mut().zip(&mut emptied) {
        let positions = part.mesh.positions();
        let key = |face: &[u32]| {
            let mut corners: Vec<[u64; 3]> =
                face.iter().map(|&i| positions[i as usize].to_array().map(f64::to_bits)).collect();
            // The same cycle from any start: start at the smallest corner.
            let first = (0..corners.len()).min_by_key(|&k| corners[k]).unwrap_or(0);
            corners.rotate_left(first);
            corners
        };
        let keep: Vec<bool> = part.mesh.faces().iter().map(|f| seen.insert(key(f))).collect();
        let removed = keep.iter().filter(|k| !**k).count();
        if removed == 0 {
            continue;
        }
        dropped += removed;
        let faces: Vec<Vec<u32>> =
            part.mesh.faces().iter().zip(&keep).filter(|(_, k)| **k).map(|(f, _)| f.clone()).collect();
        if faces.is_empty() {
            *emptied = true;
            continue;
        }
        // A subset of valid faces over the same points is valid.
        if let Ok(mesh) = PolygonMesh::try_new(positions.to_vec(), faces) {
            part.mesh = mesh;
        }
    }
    let mut flags = emptied.into_iter();
    parts.retain(|_| !flags.next().unwrap_or(false));
    dropped
}
