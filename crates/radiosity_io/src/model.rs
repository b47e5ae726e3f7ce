//! Model files in: OBJ + MTL (through `tobj`) and glTF 2.0 / GLB (through `gltf`), turned into
//! named parts of validated [`PolygonMesh`]es with diffuse [`Material`]s.
//!
//! What is taken from the files:
//! * OBJ/MTL: `Kd` (× the mean of the `map_Kd` texture, decoded from sRGB) → reflectance,
//!   `Ke` → emission (emitted radiosity, W per unit², the same quantity as `emission` in a
//!   scene file). A missing MTL file, an unknown `usemtl` or an unreadable texture gives the
//!   default grey (ρ = 0.5) or `Kd` alone, and a warning. Vertex normals are ignored:
//!   facets are flat for the solve. Every part is two-sided ([`ModelPart::sides`]).
//! * Textures: the decoded image is kept on the material (`Material::texture`, for pictures)
//!   and the texture coordinates per face corner on the mesh (`PolygonMesh::uvs`), mapped by
//!   `map_Kd`'s options or `KHR_texture_transform` (`texture_map.rs`) and with v running
//!   down the image.
//! * glTF: `baseColorFactor` (times the mean of the base colour texture, decoded from sRGB,
//!   when the texture's pixels can be read) → reflectance; `emissiveFactor` ×
//!   `KHR_materials_emissive_strength` → emission; node transforms; the first perspective
//!   camera; `doubleSided` → two-sided parts emitting from both faces. A primitive without a
//!   material gets the default grey and a warning (the glTF default, white ρ = 1, would never
//!   converge).
//! * Both: reflectance ≥ 1 in a channel is clamped to [`CLAMPED_REFLECTANCE`], and a mirror
//!   or glass material is read as diffuse, each with a warning: real files are full of both,
//!   and refusing them would refuse the file.
//!
//! Faces are kept as polygons when planar and convex (so an OBJ of quads meshes exactly like
//! the same quads in a scene file), fan-split when convex but not planar, ear-clipped when
//! concave. Positions equal to the bit after the transform are welded, so faces that an
//! exporter split at texture seams still share edges (and so surfaces, see
//! `radiosity_mesh::Mesh::build`). Degenerate faces are dropped with a warning count; an
//! object left with no face is an error.

use rustc_hash::FxHashMap as HashMap;
use std::path::Path;

use radiosity_core::glam::{DMat4, DQuat, DVec3};
use radiosity_core::{
    Camera, Material, Polygon, PolygonMesh, Rgb, SceneError, Sides, Texture, Wrap, srgb_decode,
};
use std::sync::Arc;

use crate::LoadError;
use radiosity_core::escape_controls;

/// Reflectance given to faces whose material is missing or unknown.
pub const DEFAULT_GREY: f64 = 0.5;

/// Placement of a model in a scene: scale, then rotations about x, y, z (degrees, right-
/// handed), then translation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Offset added last, scene units.
    pub translate: [f64; 3],
    /// Scale per axis (a uniform scale repeats one number); a negative product mirrors the
    /// model, and its faces are turned round so they still face the same way.
    pub scale: [f64; 3],
    /// Rotation about the x axis, degrees.
    pub rotate_x_deg: f64,
    /// Rotation about the y (vertical) axis, degrees.
    pub rotate_y_deg: f64,
    /// Rotation about the z axis, degrees.
    pub rotate_z_deg: f64,
}

impl Default for Transform {
    fn default() -> Self {
        Self { translate: [0.0; 3], scale: [1.0; 3], rotate_x_deg: 0.0, rotate_y_deg: 0.0, rotate_z_deg: 0.0 }
    }
}

impl Transform {
    /// The matrix `world_from_model`.
    pub fn matrix(&self) -> DMat4 {
        let rotation = DQuat::from_rotation_z(self.rotate_z_deg.to_radians())
            * DQuat::from_rotation_y(self.rotate_y_deg.to_radians())
            * DQuat::from_rotation_x(self.rotate_x_deg.to_radians());
        DMat4::from_scale_rotation_translation(
            DVec3::from_array(self.scale),
            rotation,
            DVec3::from_array(self.translate),
        )
    }
}

/// One named part of a model with one material.
#[derive(Clone, Debug)]
pub struct ModelPart {
    /// OBJ `o`/`g` name or glTF node/mesh name (with the material's name appended when a
    /// part uses several materials).
    pub name: String,
    /// Index into [`Model::materials`].
    pub material: usize,
    /// The geometry, in world units (transform applied).
    pub mesh: PolygonMesh,
    /// Faces that exchange light, as the format says: OBJ says nothing, and modellers show
    /// its faces from both sides, so two-sided with a front-only emission; glTF's
    /// `doubleSided` material flag, whose emission viewers show on both faces.
    pub sides: Sides,
}

/// A model file read and validated.
#[derive(Clone, Debug)]
pub struct Model {
    /// Parts in file order.
    pub parts: Vec<ModelPart>,
    /// Materials used by the parts, names unique.
    pub materials: Vec<Material>,
    /// The file's camera (glTF only), transformed.
    pub camera: Option<Camera>,
    /// Things dropped or defaulted, one line each, for the user.
    pub warnings: Vec<String>,
}

/// Which importer a file name asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModelFormat {
    /// Wavefront OBJ (materials from the MTL files it names).
    Obj,
    /// glTF 2.0, JSON (`.gltf`) or binary (`.glb`).
    Gltf,
}

impl ModelFormat {
    /// The format for a path's extension (case-insensitive), or `None` for another file.
    pub fn from_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(Self::Obj),
            "gltf" | "glb" => Some(Self::Gltf),
            _ => None,
        }
    }
}

/// Largest model file read (OBJ, glTF, GLB, and each external glTF buffer): 1 GiB.
pub(crate) const MAX_MODEL_BYTES: u64 = 1 << 30;

/// Largest scene or MTL text read: 64 MiB, far past any hand-written file.
pub(crate) const MAX_TEXT_BYTES: u64 = 64 << 20;

/// Reads a whole input file: only a regular file (a FIFO would block, `/dev/zero` never
/// ends), of at most `limit` bytes, both checked before reading.
///
/// # Errors
/// A one-line reason, without the path (callers name the file).
pub(crate) fn read_input_file(path: &Path, limit: u64) -> Result<Vec<u8>, String> {
    use std::io::Read;
    let meta = std::fs::metadata(path).map_err(|e| e.to_string())?;
    if !meta.is_file() {
        return Err("not a regular file".into());
    }
    if meta.len() > limit {
        return Err(format!("{} bytes is more than the {limit} read", meta.len()));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    // `take`: the file may have grown since it was measured.
    std::fs::File::open(path)
        .and_then(|f| f.take(limit + 1).read_to_end(&mut bytes))
        .map_err(|e| e.to_string())?;
    if bytes.len() as u64 > limit {
        return Err(format!("more than the {limit} bytes read"));
    }
    Ok(bytes)
}

/// A model error at `origin` (and `line`, when known).
pub(crate) fn model_error(origin: &str, line: Option<usize>, message: impl Into<String>) -> LoadError {
    LoadError::Model { origin: escape_controls(origin), line, message: escape_controls(&message.into()) }
}

/// A validated material from a model file, with the file named in the error.
pub(crate) fn model_material(
    origin: &str,
    line: Option<usize>,
    name: &str,
    reflectance: [f64; 3],
    emission: [f64; 3],
) -> Result<Material, LoadError> {
    Material::try_new(name, Rgb::from_array(reflectance), Rgb::from_array(emission))
        .map_err(|e| model_error(origin, line, e.to_string()))
}

/// Reflectance given to a model material that reflects 1 or more in a channel: a white
/// (`Kd 1 1 1`, glTF's default factor) is common in real files, and ρ ≥ 1 never converges.
pub const CLAMPED_REFLECTANCE: f64 = 0.95;

/// `reflectance` with every channel ≥ 1 lowered to [`CLAMPED_REFLECTANCE`], and a warning
/// naming the file, the material and the value when one was. Non-finite and negative values
/// are left for the material's own check to refuse.
pub(crate) fn clamp_reflectance(
    origin: &str,
    name: &str,
    reflectance: [f64; 3],
    warnings: &mut Vec<String>,
) -> [f64; 3] {
    if !reflectance.iter().any(|&v| v >= 1.0 && v.is_finite()) {
        return reflectance;
    }
    warnings.push(format!(
        "{origin}: material '{name}': reflectance {reflectance:?} has a channel ≥ 1 (light would never stop bouncing); clamped to {CLAMPED_REFLECTANCE}"
    ));
    reflectance.map(|v| if v >= 1.0 && v.is_finite() { CLAMPED_REFLECTANCE } else { v })
}

/// The warning for a material that the format describes as mirror-like or see-through, which
/// the solver (diffuse only) cannot show; `why` names what in the file says so.
pub(crate) fn specular_warning(origin: &str, name: &str, why: &str) -> String {
    format!("material '{name}' ({origin}) is specular/transmissive ({why}); treated as diffuse")
}

/// The warning for a glTF material blended by its alpha (`alphaMode BLEND`): diffuse transfer
/// has no partial transparency, so it is cut as a mask at one half.
pub(crate) fn blend_warning(origin: &str, name: &str) -> String {
    format!(
        "material '{name}' ({origin}) is alpha-blended (alphaMode BLEND): treated as a mask (MASK) with alphaCutoff 0.5"
    )
}

/// A colour texture read from a file: its 8-bit sRGB texels, its alpha if it has one, and
/// their mean linear colour.
pub(crate) struct DecodedImage {
    width: u32,
    height: u32,
    texels: Vec<[u8; 3]>,
    /// Alpha per texel (0–255) of an image with an alpha channel.
    alpha: Option<Vec<u8>>,
    /// Mean linear colour: what the texture contributes to a flat element's reflectance, as
    /// the mean of what it reflects.
    pub(crate) mean: [f64; 3],
}

impl DecodedImage {
    /// 8-bit sRGB pixels of `channels` bytes each, red, green and blue first (RGB, RGBA; the
    /// fourth is alpha), `width` per row, top row first; `None` without a pixel, with fewer
    /// than three channels, or when the sizes disagree.
    pub(crate) fn from_srgb8(pixels: &[u8], channels: usize, width: u32, height: u32) -> Option<Self> {
        let count = width as usize * height as usize;
        if channels < 3 || count == 0 || pixels.len() != count * channels {
            return None;
        }
        let texels: Vec<[u8; 3]> = pixels.chunks_exact(channels).map(|px| [px[0], px[1], px[2]]).collect();
        let alpha = (channels >= 4).then(|| pixels.chunks_exact(channels).map(|px| px[3]).collect());
        let mut image = Self { width, height, texels, alpha, mean: [0.0; 3] };
        image.mean = image.mean_where(None);
        Some(image)
    }

    /// The mean linear colour of the texels where `mask` is set (all when `None`; the whole
    /// image's mean when the mask is empty everywhere).
    fn mean_where(&self, mask: Option<&[bool]>) -> [f64; 3] {
        let lut: Vec<f64> = (0..256).map(|v| srgb_decode(v as f64 / 255.0)).collect();
        let (mut sum, mut count) = ([0.0; 3], 0usize);
        for (i, px) in self.texels.iter().enumerate() {
            if mask.is_none_or(|m| m[i]) {
                (0..3).for_each(|c| sum[c] += lut[px[c] as usize]);
                count += 1;
            }
        }
        if count == 0 {
            return self.mean_where(None);
        }
        sum.map(|s| s / count as f64)
    }

    /// Where the surface is: alpha × `scale` at or above `cutoff` (glTF's `alphaCutoff`), or,
    /// for an image without alpha, the texel's brightness (a grey MTL `map_d`) when `grey`.
    /// `None` for an image without alpha when not `grey`.
    pub(crate) fn mask(&self, scale: f64, cutoff: f64, grey: bool) -> Option<Vec<bool>> {
        let at = |a: u8| f64::from(a) / 255.0 * scale >= cutoff;
        match &self.alpha {
            Some(alpha) => Some(alpha.iter().map(|&a| at(a)).collect()),
            // A scalar map is read as its first channel, as MTL's `-imfchan` defaults to
            // luminance of a grey image.
            None if grey => Some(self.texels.iter().map(|px| at(px[0])).collect()),
            None => None,
        }
    }

    /// `mask` (of an image `width` × `height`) sampled at this image's texel centres, nearest
    /// texel, so that a `map_d` of another size than its `map_Kd` lines up with it.
    pub(crate) fn resampled(&self, mask: &[bool], width: u32, height: u32) -> Vec<bool> {
        nearest(width, height, self.width, self.height).map(|i| mask[i]).collect()
    }

    /// This image sampled at the texel centres of one `width` × `height`, nearest texel: a
    /// colour texture brought to a finer mask's size, which a coarser one would alias.
    pub(crate) fn scaled(&self, width: u32, height: u32) -> Self {
        let texels = nearest(self.width, self.height, width, height).map(|i| self.texels[i]).collect();
        let alpha = self
            .alpha
            .as_ref()
            .map(|a| nearest(self.width, self.height, width, height).map(|i| a[i]).collect());
        Self { width, height, texels, alpha, mean: self.mean }
    }

    /// Texels per row and rows.
    pub(crate) fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// The mean linear colour over the texels `mask` keeps: the reflectance of what is there.
    pub(crate) fn masked_mean(&self, mask: &[bool]) -> [f64; 3] {
        self.mean_where(Some(mask))
    }

    /// The texture the renderer samples: these texels times `factor`, wrapped by `wrap`,
    /// there where `mask` says (everywhere when `None`).
    pub(crate) fn texture(&self, factor: [f64; 3], wrap: [Wrap; 2], mask: Option<Vec<bool>>) -> Arc<Texture> {
        Arc::new(Texture {
            width: self.width,
            height: self.height,
            texels: self.texels.clone(),
            factor,
            wrap,
            mask,
        })
    }

    /// A white image of `width` × `height`: what carries a mask for a material with no colour
    /// texture (its factor is its colour).
    pub(crate) fn white(width: u32, height: u32) -> Self {
        let count = width as usize * height as usize;
        Self { width, height, texels: vec![[255; 3]; count], alpha: None, mean: [1.0; 3] }
    }
}

/// For each texel centre of a `to_w` × `to_h` image, row after row, the index of the texel of
/// a `from_w` × `from_h` image under it.
fn nearest(from_w: u32, from_h: u32, to_w: u32, to_h: u32) -> impl Iterator<Item = usize> {
    let (fw, fh, tw, th) = (u64::from(from_w), u64::from(from_h), u64::from(to_w), u64::from(to_h));
    (0..th).flat_map(move |y| {
        let sy = (2 * y + 1) * fh / (2 * th);
        (0..tw).map(move |x| (sy * fw + (2 * x + 1) * fw / (2 * tw)) as usize)
    })
}

/// The image file at `path` (PNG or JPEG, 8-bit sRGB after decoding; an alpha channel kept).
///
/// # Errors
/// Why it cannot be read or decoded, one line without the path.
pub(crate) fn read_texture(path: &Path) -> Result<DecodedImage, String> {
    let bytes = read_input_file(path, MAX_MODEL_BYTES)?;
    let image = image::load_from_memory(&bytes).map_err(|e| e.to_string())?;
    let decoded = if image.color().has_alpha() {
        let rgba = image.to_rgba8();
        DecodedImage::from_srgb8(rgba.as_raw(), 4, rgba.width(), rgba.height())
    } else {
        let rgb = image.to_rgb8();
        DecodedImage::from_srgb8(rgb.as_raw(), 3, rgb.width(), rgb.height())
    };
    decoded.ok_or_else(|| "the image has no pixels".to_owned())
}

/// A face corner: its welded index and texture coordinates.
type Corner = (u32, [f64; 2]);

/// Collects the faces of one part: welds positions, drops degenerate faces (counted), and
/// splits faces that are not planar convex polygons.
pub(crate) struct PartBuilder {
    world_from_model: DMat4,
    mirrored: bool,
    positions: Vec<DVec3>,
    index_of: HashMap<[u64; 3], u32>,
    faces: Vec<Vec<u32>>,
    /// Texture coordinates per corner of each face in `faces`, where the file gave them.
    uvs: Vec<Option<Vec<[f64; 2]>>>,
    /// Faces dropped because they had no area.
    pub(crate) dropped: usize,
}

impl PartBuilder {
    /// A builder placing points with `world_from_model`.
    pub(crate) fn new(world_from_model: DMat4) -> Self {
        Self {
            world_from_model,
            mirrored: world_from_model.determinant() < 0.0,
            positions: Vec::new(),
            index_of: HashMap::default(),
            faces: Vec::new(),
            uvs: Vec::new(),
            dropped: 0,
        }
    }

    /// The welded index of model-space point `p`.
    ///
    /// # Errors
    /// The message for a non-finite point (before or after the transform), or one placed
    /// beyond ±[`radiosity_core::MAX_COORDINATE`].
    pub(crate) fn vertex(&mut self, p: DVec3) -> Result<u32, String> {
        let w = self.world_from_model.transform_point3(p);
        if !p.is_finite() || !w.is_finite() {
            return Err(format!("coordinates must be finite numbers, got {:?}", p.to_array()));
        }
        if let Err(e) = radiosity_core::check_coordinate(w) {
            return Err(format!("{e} (placed from {:?})", p.to_array()));
        }
        // -0.0 and 0.0 are one point.
        let w = w + DVec3::ZERO;
        let key = [w.x.to_bits(), w.y.to_bits(), w.z.to_bits()];
        let next = self.positions.len() as u32;
        Ok(*self.index_of.entry(key).or_insert_with(|| {
            self.positions.push(w);
            next
        }))
    }

    /// Adds a face of welded indices, counter-clockwise in model space.
    ///
    /// # Errors
    /// As [`PartBuilder::face_with_uvs`].
    #[cfg(test)]
    pub(crate) fn face(&mut self, f: Vec<u32>) -> Result<(), String> {
        self.face_with_uvs(f, None)
    }

    /// Adds a face of welded indices, counter-clockwise in model space, with texture
    /// coordinates per corner (ignored unless one per corner); they follow the corners
    /// through the splits below.
    ///
    /// # Errors
    /// The message for a face of more than [`radiosity_core::MAX_POLYGON_VERTICES`] corners
    /// (before anything is triangulated: ear clipping is quadratic in the corners).
    pub(crate) fn face_with_uvs(&mut self, f: Vec<u32>, uvs: Option<Vec<[f64; 2]>>) -> Result<(), String> {
        if f.len() > radiosity_core::MAX_POLYGON_VERTICES {
            let e =
                SceneError::TooManyVertices { count: f.len(), limit: radiosity_core::MAX_POLYGON_VERTICES };
            return Err(e.to_string());
        }
        let uvs = uvs.filter(|u| u.len() == f.len());
        let textured = uvs.is_some();
        let mut corners: Vec<Corner> =
            f.iter().enumerate().map(|(k, &v)| (v, uvs.as_ref().map_or([0.0; 2], |u| u[k]))).collect();
        if self.mirrored {
            corners.reverse();
        }
        // Consecutive repeats (welded points) carry no area.
        corners.dedup_by_key(|c| c.0);
        while corners.len() > 1 && corners.first().map(|c| c.0) == corners.last().map(|c| c.0) {
            corners.pop();
        }
        if corners.len() < 3 {
            self.dropped += 1;
            return Ok(());
        }
        let pts: Vec<DVec3> = corners.iter().map(|c| self.positions[c.0 as usize]).collect();
        match Polygon::try_new(pts.clone()) {
            Ok(_) => self.push(&corners, textured),
            Err(SceneError::NonPlanarPolygon { .. }) => {
                // Convex but bent: a fan keeps every triangle inside the outline.
                for k in 1..corners.len() - 1 {
                    self.triangle([corners[0], corners[k], corners[k + 1]], textured);
                }
            }
            Err(SceneError::NonConvexPolygon { .. }) => {
                let ears = ear_clip(&pts);
                // A polygon that is not simple leaves part of itself unclipped: counted as
                // dropped, so the user hears of the missing area.
                if ears.len() < pts.len() - 2 {
                    self.dropped += 1;
                }
                for t in ears {
                    self.triangle(t.map(|k| corners[k]), textured);
                }
            }
            Err(_) => self.dropped += 1,
        }
        Ok(())
    }

    fn push(&mut self, corners: &[Corner], textured: bool) {
        self.faces.push(corners.iter().map(|c| c.0).collect());
        self.uvs.push(textured.then(|| corners.iter().map(|c| c.1).collect()));
    }

    fn triangle(&mut self, t: [Corner; 3], textured: bool) {
        let pts = t.map(|c| self.positions[c.0 as usize]).to_vec();
        if Polygon::try_new(pts).is_ok() {
            self.push(&t, textured);
        } else {
            self.dropped += 1;
        }
    }

    /// True when no face was kept.
    pub(crate) fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// The validated mesh.
    ///
    /// # Errors
    /// The core's message (cannot happen for faces that passed [`PartBuilder::face`], kept
    /// as an error rather than a panic).
    pub(crate) fn build(self) -> Result<PolygonMesh, String> {
        // Texture coordinates are kept only when every face has them: a picture shows a
        // texture on all of a part or on none of it.
        let uvs: Option<Vec<Vec<[f64; 2]>>> = self.uvs.into_iter().collect();
        let mesh = PolygonMesh::try_new(self.positions, self.faces).map_err(|e| e.to_string())?;
        Ok(match uvs {
            Some(uvs) => mesh.with_uvs(uvs),
            None => mesh,
        })
    }
}

/// Triangles (as indices into `pts`) of a simple planar polygon, by ear clipping in the plane
/// of its Newell normal. A polygon that is not simple gives what ears it can (fewer than
/// `pts.len() - 2`); the rest is left out.
fn ear_clip(pts: &[DVec3]) -> Vec<[usize; 3]> {
    let mut n = DVec3::ZERO;
    for (i, &a) in pts.iter().enumerate() {
        n += a.cross(pts[(i + 1) % pts.len()]);
    }
    let n = n.normalize_or_zero();
    let mut idx: Vec<usize> = (0..pts.len()).collect();
    let mut out = Vec::new();
    let convex = |a: DVec3, b: DVec3, c: DVec3| (b - a).cross(c - b).dot(n) > 0.0;
    let inside = |p: DVec3, a: DVec3, b: DVec3, c: DVec3| {
        (b - a).cross(p - a).dot(n) >= 0.0
            && (c - b).cross(p - b).dot(n) >= 0.0
            && (a - c).cross(p - c).dot(n) >= 0.0
    };
    let mut guard = 0;
    // The search for the next ear starts where the last was clipped, where the next one
    // usually is: from the start of the list every time, each clip could rescan it all.
    let mut from = 0;
    while idx.len() > 3 && guard < pts.len() * pts.len() {
        guard += 1;
        let k = idx.len();
        let ear = (from.min(k)..k).chain(0..from.min(k)).find(|&i| {
            let (a, b, c) = (idx[(i + k - 1) % k], idx[i], idx[(i + 1) % k]);
            convex(pts[a], pts[b], pts[c])
                && idx.iter().all(|&j| j == a || j == b || j == c || !inside(pts[j], pts[a], pts[b], pts[c]))
        });
        let Some(i) = ear else { break };
        out.push([idx[(i + k - 1) % k], idx[i], idx[(i + 1) % k]]);
        idx.remove(i);
        from = i.saturating_sub(1);
    }
    if idx.len() == 3 {
        out.push([idx[0], idx[1], idx[2]]);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ear_clipping_splits_an_l_shape_into_four_triangles_of_its_area() {
        let l = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 1.0), (1.0, 2.0), (0.0, 2.0)]
            .map(|(x, y)| DVec3::new(x, y, 0.0));
        let tris = ear_clip(&l);
        assert_eq!(tris.len(), 4);
        let area: f64 = tris.iter().map(|t| 0.5 * (l[t[1]] - l[t[0]]).cross(l[t[2]] - l[t[0]]).z).sum();
        assert!((area - 3.0).abs() < 1e-12, "{area}");
    }

    #[test]
    fn a_concave_obj_face_becomes_triangles_of_its_area() {
        let mut b = PartBuilder::new(DMat4::IDENTITY);
        let l = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 1.0), (1.0, 2.0), (0.0, 2.0)];
        let f = l.map(|(x, y)| b.vertex(DVec3::new(x, y, 0.0)).unwrap()).to_vec();
        b.face(f).unwrap();
        assert_eq!(b.dropped, 0);
        let m = b.build().unwrap();
        assert_eq!(m.faces().len(), 4);
        assert!((m.area() - 3.0).abs() < 1e-12);
    }

    #[test]
    fn a_mirroring_transform_keeps_faces_facing_out() {
        let t = Transform { scale: [-1.0, 1.0, 1.0], ..Transform::default() };
        let mut b = PartBuilder::new(t.matrix());
        let f = [DVec3::ZERO, DVec3::X, DVec3::Y].map(|p| b.vertex(p).unwrap()).to_vec();
        b.face(f).unwrap();
        let m = b.build().unwrap();
        assert!((m.polygons()[0].normal() - DVec3::Z).length() < 1e-12);
    }

    #[test]
    fn rotations_apply_x_then_y_then_z() {
        let t = Transform { rotate_x_deg: 90.0, rotate_z_deg: 90.0, ..Transform::default() };
        // y → z under x, z stays under z.
        let p = t.matrix().transform_point3(DVec3::Y);
        assert!((p - DVec3::Z).length() < 1e-12, "{p}");
    }
}
