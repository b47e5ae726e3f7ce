//! The lightmap atlas as files an engine loads: `lightmapped.gltf` (the model's own faces with
//! their materials and colour textures, `TEXCOORD_0` where the model has texture coordinates
//! and the lightmap's `TEXCOORD_1`), `lightmap.exr` (the linear texels) and `lightmap.png`
//! (tone-mapped, embedded in the glTF as a texture).
//!
//! glTF 2.0 has no lightmap slot, so the lightmap is referenced in `extras`, as engines'
//! importers read it: every material's `extras.lightmap` is `{ "index": texture, "texCoord":
//! 1 }`, and the asset's `extras.radiosity_lightmap` says what the texels hold (quantity,
//! unit, the HDR file, the PNG's exposure and tone curve). In three.js:
//! `material.lightMap = texture; texture.channel = 1` (the PNG is sRGB). A face without
//! texture coordinates of its own has the lightmap's as `TEXCOORD_0` as well (glTF numbers
//! the sets without gaps).

use std::path::{Path, PathBuf};

use radiosity_core::{Scene, Wrap};
use radiosity_image::{HdrImage, ToneParams, encode_png, tone_map_image};
use serde_json::{Value, json};

use crate::atlas::{Atlas, AtlasOptions};
use crate::base64;
use crate::textured::{TextureTable, push_view};

/// The file names written into the lightmap folder.
pub const ATLAS_FILES: [&str; 3] = ["lightmapped.gltf", "lightmap.exr", "lightmap.png"];

/// The atlas's texels as radiance a white surface would show, for the PNG: E/π for
/// irradiance, B/π for radiosity.
pub fn atlas_radiance(atlas: &Atlas) -> HdrImage {
    let (w, h) = (atlas.image.width(), atlas.image.height());
    let pixels = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| atlas.image.pixel(x, y) * std::f64::consts::FRAC_1_PI)
        .collect();
    HdrImage::from_pixels(w, h, pixels)
}

/// Writes the atlas's three files into `dir` (see the module's documentation), the PNG
/// tone-mapped by `tone`. Returns the paths written.
///
/// # Errors
/// A file that cannot be written.
pub fn write_atlas(
    dir: &Path,
    scene: &Scene,
    atlas: &Atlas,
    options: &AtlasOptions,
    tone: ToneParams,
) -> Result<Vec<PathBuf>, String> {
    let (mut written, png) = write_pictures(dir, atlas, tone)?;
    let text = atlas_gltf(scene, atlas, options, &png, tone);
    let gltf = dir.join(ATLAS_FILES[0]);
    std::fs::write(&gltf, text).map_err(|e| format!("{}: {e}", gltf.display()))?;
    written.insert(0, gltf);
    Ok(written)
}

/// Writes `lightmap.exr` and `lightmap.png` (tone-mapped by `tone`) into `dir`, made if
/// missing: their paths and the PNG's bytes.
pub(crate) fn write_pictures(
    dir: &Path,
    atlas: &Atlas,
    tone: ToneParams,
) -> Result<(Vec<PathBuf>, Vec<u8>), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: cannot create the folder: {e}", dir.display()))?;
    let exr = dir.join(ATLAS_FILES[1]);
    radiosity_image::write_exr(&exr, &atlas.image).map_err(|e| e.to_string())?;
    let picture = tone_map_image(&atlas_radiance(atlas), &tone);
    let png_path = dir.join(ATLAS_FILES[2]);
    let png = encode_png(&picture, &png_path).map_err(|e| e.to_string())?;
    std::fs::write(&png_path, &png).map_err(|e| format!("{}: {e}", png_path.display()))?;
    Ok((vec![exr, png_path], png))
}

/// The asset's `extras.radiosity_lightmap`: what the texels hold, where the lightmap is
/// (`texture`, on `TEXCOORD_<set>`), the HDR file and the PNG's tone curve.
pub(crate) fn lightmap_extras(
    atlas: &Atlas,
    options: &AtlasOptions,
    tone: ToneParams,
    texture: usize,
    set: usize,
) -> Value {
    json!({
        "texture": texture, "texCoord": set, "quantity": options.quantity.as_str(),
        "unit": "W per scene unit squared", "hdr": ATLAS_FILES[1], "png_exposure_ev": tone.exposure_ev,
        "png": format!("{}/pi tone-mapped ({}, {:+.3} EV), sRGB", options.quantity.as_str(), tone.operator,
            tone.exposure_ev),
        "texels_per_unit": atlas.texels_per_unit })
}

/// The `.gltf` text of the lightmapped model (buffer embedded as a data URI), `png` the
/// lightmap's picture as the PNG written beside it.
pub fn atlas_gltf(
    scene: &Scene,
    atlas: &Atlas,
    options: &AtlasOptions,
    png: &[u8],
    tone: ToneParams,
) -> String {
    const ARRAY_BUFFER: u32 = 34962;
    const ELEMENT_ARRAY_BUFFER: u32 = 34963;
    const FLOAT: u32 = 5126;
    const UNSIGNED_INT: u32 = 5125;
    let mut blob = Vec::new();
    let (mut views, mut accessors, mut meshes, mut nodes) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    // Texture 0: the lightmap, its PNG first in the buffer; the model's textures after it.
    let mut table = TextureTable::default();
    table.png("lightmap", png, [Wrap::ClampToEdge; 2], &mut blob, &mut views);
    // One glTF material per scene material used.
    let mut materials: Vec<Value> = Vec::new();
    let mut material_of = std::collections::HashMap::new();
    let mut emissive = false;
    for m in &atlas.meshes {
        let object = &scene.objects[m.object];
        let material = &scene.materials[object.material];
        // A side that does not emit (the back of a lamp) takes the material without its
        // emission.
        let index = *material_of.entry((object.material, m.emits)).or_insert_with(|| {
            let rho = material.reflectance.to_array().map(|c| c.clamp(0.0, 1.0));
            let mut pbr = json!({ "baseColorFactor": [rho[0], rho[1], rho[2], 1.0],
                "metallicFactor": 0.0, "roughnessFactor": 1.0 });
            if let (Some(texture), true) = (&material.texture, m.uv0.is_some()) {
                let index = table.texture(texture, &material.name, &mut blob, &mut views);
                let f = texture.factor.map(|c| c.clamp(0.0, 1.0));
                pbr["baseColorFactor"] = json!([f[0], f[1], f[2], 1.0]);
                pbr["baseColorTexture"] = json!({ "index": index, "texCoord": 0 });
            }
            let name =
                if m.emits { material.name.clone() } else { format!("{} (not emitting)", material.name) };
            let mut entry = json!({ "name": name, "pbrMetallicRoughness": pbr,
                "extras": { "lightmap": { "index": 0, "texCoord": 1 } } });
            // An emitter's emission M (W per unit², as this program reads glTF back), the
            // colour at most 1 and the rest in the strength: it shows M/π beside the
            // lightmap's E/π.
            let emission = if m.emits { material.emission.to_array() } else { [0.0; 3] };
            let peak = emission.iter().copied().fold(0.0, f64::max);
            if peak > 0.0 {
                entry["emissiveFactor"] = json!(emission.map(|c| c / peak));
                entry["extensions"] = json!({ "KHR_materials_emissive_strength": {
                    "emissiveStrength": peak } });
                emissive = true;
            }
            materials.push(entry);
            materials.len() - 1
        });
        let count = m.positions.len();
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        let mut pos = Vec::with_capacity(count * 12);
        for p in &m.positions {
            let p = p.as_vec3().to_array();
            for c in 0..3 {
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
                pos.extend_from_slice(&p[c].to_le_bytes());
            }
        }
        let base = accessors.len();
        views.push(push_view(&mut blob, &pos, Some(ARRAY_BUFFER)));
        accessors.push(json!({ "bufferView": views.len() - 1, "componentType": FLOAT, "count": count,
            "type": "VEC3", "min": lo, "max": hi }));
        let uv1: Vec<u8> = m.uv1.iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
        views.push(push_view(&mut blob, &uv1, Some(ARRAY_BUFFER)));
        accessors.push(json!({ "bufferView": views.len() - 1, "componentType": FLOAT, "count": count,
            "type": "VEC2" }));
        let idx: Vec<u8> = m.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        views.push(push_view(&mut blob, &idx, Some(ELEMENT_ARRAY_BUFFER)));
        accessors.push(json!({ "bufferView": views.len() - 1, "componentType": UNSIGNED_INT,
            "count": m.indices.len(), "type": "SCALAR" }));
        // glTF numbers texture coordinate sets from 0 without gaps: a face without the
        // model's own coordinates takes the lightmap's as TEXCOORD_0 too (one accessor).
        let mut attributes = json!({ "POSITION": base, "TEXCOORD_0": base + 1, "TEXCOORD_1": base + 1 });
        if let Some(uv0) = &m.uv0 {
            let bytes: Vec<u8> = uv0.iter().flatten().flat_map(|&c| (c as f32).to_le_bytes()).collect();
            views.push(push_view(&mut blob, &bytes, Some(ARRAY_BUFFER)));
            accessors.push(json!({ "bufferView": views.len() - 1, "componentType": FLOAT, "count": count,
                "type": "VEC2" }));
            attributes["TEXCOORD_0"] = (accessors.len() - 1).into();
        }
        let name = if m.back { format!("{} (back)", object.name) } else { object.name.clone() };
        meshes.push(json!({ "name": name, "primitives": [{
            "attributes": attributes, "indices": base + 2, "material": index }] }));
        nodes.push(json!({ "name": name, "mesh": meshes.len() - 1 }));
    }
    let mut doc = json!({
        "asset": { "version": "2.0", "generator": concat!("radiosity ", env!("CARGO_PKG_VERSION")),
            "extras": { "radiosity_lightmap": lightmap_extras(atlas, options, tone, 0, 1) } },
        "scene": 0,
        "scenes": [{ "nodes": (0..nodes.len()).collect::<Vec<_>>() }],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "textures": table.textures,
        "samplers": table.samplers,
        "images": table.images,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{ "byteLength": blob.len(),
            "uri": format!("data:application/octet-stream;base64,{}", base64(&blob)) }],
    });
    if emissive {
        doc["extensionsUsed"] = json!(["KHR_materials_emissive_strength"]);
    }
    serde_json::to_string(&doc).expect("a JSON value serialises")
}
