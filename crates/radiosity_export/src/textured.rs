//! Colour textures in glTF: a textured object's material shows its texture image
//! (`baseColorTexture`, the PNG embedded in the file's own buffer so the file stands alone,
//! as the mesh data already does), sampled with the wrap modes it was loaded with, and its
//! `COLOR_0` holds the light over the material's mean reflectance, so that an unlit viewer's
//! texel × vertex colour is the light times the texel's albedo, as `render` shows it:
//! L = B·ρ(uv)/ρ̄ / π. glTF colours may not exceed 1, so where the light over the mean
//! reflectance does (a bright colour on a dark texture), `COLOR_0` is clamped to 1 and the
//! texture shows darker than in a picture; the texture image is kept as it is, not brightened
//! to make room, so it stays the model's own.
//! With `--tonemapped` colours the quotient is taken after the tone curve, so texel × colour
//! is the picture's tone-mapped colour only where the curve is near linear (its toe).
//!
//! Emitting textured materials keep their mean colour (no texture): a picture adds the
//! emitted part unscaled and scales only the reflected part, which one vertex colour
//! multiplying the texel cannot express.

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use radiosity_core::{Material, Rgb, Texture, Wrap};
use radiosity_image::{ElementUvs, SrgbImage, encode_png};
use radiosity_mesh::Mesh;
use serde_json::{Value, json};

/// The index into [`Mesh::materials`] of element `e`'s material.
pub(crate) fn material_index(mesh: &Mesh, e: usize) -> usize {
    let patch = &mesh.patches[mesh.elements[e].patch as usize];
    mesh.surfaces[patch.surface as usize].material as usize
}

/// Whether element `e` is exported textured: its material has a texture, emits nothing, and
/// the element has texture coordinates in `uvs`.
pub(crate) fn is_textured(mesh: &Mesh, uvs: &[Option<ElementUvs>], e: usize) -> bool {
    let m = mesh.element_material(e);
    m.texture.is_some() && m.emission == Rgb::ZERO && matches!(uvs.get(e), Some(Some(_)))
}

/// What a textured object's display colour is multiplied by for `COLOR_0`, per channel:
/// 1 / the material's mean reflectance (1 where the mean is 0, as pictures do), and the part
/// of the texture's factor above 1, which `baseColorFactor` (at most 1) cannot hold.
pub(crate) fn colour_scale(material: &Material) -> [f64; 3] {
    let mean = material.reflectance.to_array();
    let factor = material.texture.as_ref().map_or([1.0; 3], |t| t.factor);
    [0, 1, 2].map(|c| {
        let over_mean = if mean[c] > 0.0 { 1.0 / mean[c] } else { 1.0 };
        over_mean * factor[c].max(1.0)
    })
}

/// Appends `bytes` to `blob`, padded to 4 bytes, and returns the buffer view's JSON (an
/// image's view has no target).
pub(crate) fn push_view(blob: &mut Vec<u8>, bytes: &[u8], target: Option<u32>) -> Value {
    let offset = blob.len();
    blob.extend_from_slice(bytes);
    while !blob.len().is_multiple_of(4) {
        blob.push(0);
    }
    let mut view = json!({ "buffer": 0, "byteOffset": offset, "byteLength": bytes.len() });
    if let Some(target) = target {
        view["target"] = target.into();
    }
    view
}

/// glTF's sampler wrap code.
pub(crate) fn wrap_code(wrap: Wrap) -> u32 {
    match wrap {
        Wrap::Repeat => 10497,
        Wrap::ClampToEdge => 33071,
        Wrap::MirroredRepeat => 33648,
    }
}

/// The textures of a glTF document with their samplers and images, each written once however
/// many materials use it.
#[derive(Default)]
pub(crate) struct TextureTable {
    /// glTF textures: one per (image, sampler) pair.
    pub(crate) textures: Vec<Value>,
    /// glTF samplers: one per pair of wrap modes.
    pub(crate) samplers: Vec<Value>,
    /// glTF images: one per texture image, its PNG in a buffer view.
    pub(crate) images: Vec<Value>,
    /// Texture (by address: loaders share one `Arc` among materials) → glTF texture index.
    by_texture: Vec<(Arc<Texture>, usize)>,
    /// Wrap modes → glTF sampler index.
    by_wrap: Vec<([Wrap; 2], usize)>,
}

impl TextureTable {
    /// The glTF texture of `texture` (named `name`), adding its image (a PNG appended to
    /// `blob` as a buffer view) and sampler when new.
    pub(crate) fn texture(
        &mut self,
        texture: &Arc<Texture>,
        name: &str,
        blob: &mut Vec<u8>,
        views: &mut Vec<Value>,
    ) -> usize {
        if let Some(&(_, i)) = self.by_texture.iter().find(|(t, _)| Arc::ptr_eq(t, texture)) {
            return i;
        }
        let picture =
            SrgbImage { width: texture.width, height: texture.height, pixels: texture.texels.clone() };
        // A texture has at least one texel, and the encoder writes into memory: it cannot fail.
        let png = encode_png(&picture, Path::new("texture.png")).expect("a texture encodes as PNG");
        let i = self.png(name, &png, texture.wrap, blob, views);
        self.by_texture.push((texture.clone(), i));
        i
    }

    /// A glTF texture of the PNG `bytes` (named `name`, appended to `blob` as a buffer view),
    /// sampled with `wrap` and linear filtering (pictures filter texels bilinearly).
    pub(crate) fn png(
        &mut self,
        name: &str,
        bytes: &[u8],
        wrap: [Wrap; 2],
        blob: &mut Vec<u8>,
        views: &mut Vec<Value>,
    ) -> usize {
        views.push(push_view(blob, bytes, None));
        self.images.push(json!({ "name": name, "bufferView": views.len() - 1, "mimeType": "image/png" }));
        let sampler = match self.by_wrap.iter().find(|(w, _)| *w == wrap) {
            Some(&(_, i)) => i,
            None => {
                self.samplers.push(json!({ "magFilter": 9729, "minFilter": 9987,
                    "wrapS": wrap_code(wrap[0]), "wrapT": wrap_code(wrap[1]) }));
                self.by_wrap.push((wrap, self.samplers.len() - 1));
                self.samplers.len() - 1
            }
        };
        self.textures.push(json!({ "sampler": sampler, "source": self.images.len() - 1 }));
        self.textures.len() - 1
    }
}

/// The textured materials of a glTF document, with their textures ([`TextureTable`]).
#[derive(Default)]
pub(crate) struct TexturedMaterials {
    /// glTF materials after the untextured `baked` one (index 0).
    pub(crate) materials: Vec<Value>,
    /// Their textures, samplers and images.
    pub(crate) table: TextureTable,
    /// Mesh material index → glTF material index.
    by_material: HashMap<usize, usize>,
}

impl TexturedMaterials {
    /// The glTF material index for mesh material `m` (which has a texture), adding it, its
    /// texture, sampler and image (a PNG appended to `blob` as a buffer view) when new.
    pub(crate) fn material(
        &mut self,
        mesh: &Mesh,
        m: usize,
        blob: &mut Vec<u8>,
        views: &mut Vec<Value>,
    ) -> usize {
        if let Some(&i) = self.by_material.get(&m) {
            return i;
        }
        let material = &mesh.materials[m];
        let texture = material.texture.as_ref().expect("only textured materials come here");
        let index = self.table.texture(texture, &material.name, blob, views);
        let f = texture.factor.map(|c| c.clamp(0.0, 1.0));
        self.materials.push(json!({ "name": material.name, "pbrMetallicRoughness": {
            "baseColorTexture": { "index": index },
            "baseColorFactor": [f[0], f[1], f[2], 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0 },
            "extensions": { "KHR_materials_unlit": {} } }));
        let index = self.materials.len(); // after `baked`
        self.by_material.insert(m, index);
        index
    }
}
