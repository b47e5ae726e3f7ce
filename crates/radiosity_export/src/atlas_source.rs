//! The lightmap atlas of a glTF model kept as it is: its nodes, meshes, materials, textures,
//! normals and every other attribute stay, each lightmapped primitive gets a second set of
//! texture coordinates for the lightmap, and the lightmap's texture is added beside the
//! model's own. Only what the lightmap needs changes: a primitive's vertices are split along
//! the charts' seams (every attribute follows, gathered vertex by vertex), strips and fans
//! become triangle lists, a mesh drawn by several nodes is copied for each (each place has
//! its own light), and the file's buffers and images are embedded, so that it stands alone in
//! the lightmap's folder.

use std::path::{Path, PathBuf};

use glam::{DMat4, DVec3};
use radiosity_core::{Scene, UpAxis};
use radiosity_image::ToneParams;
use radiosity_mesh::{Mesh, fan_triangles, strip_triangles};
use radiosity_solver::Solution;
use serde_json::{Value, json};

use crate::atlas::{
    ANY_OBJECT, Atlas, AtlasError, AtlasMesh, AtlasOptions, AtlasTexels, Locator, Unwrapping, unwrap_and_bake,
};
use crate::atlas_gltf::{ATLAS_FILES, lightmap_extras, write_pictures};
use crate::base64;
use crate::textured::push_view;

/// A glTF model as read for its lightmap: its JSON, its buffers' bytes, its folder, and the
/// primitives lightmapped, in the atlas's mesh order.
pub struct SourceGltf {
    json: Value,
    buffers: Vec<Vec<u8>>,
    base: PathBuf,
    /// Per atlas mesh: the node and the index of the primitive in the node's mesh.
    primitives: Vec<(usize, usize)>,
}

/// Reads the glTF (or GLB) model at `path` (the file `scene` was loaded from, turned up by
/// `up`), unwraps every triangle primitive of its default scene, each placed by its node,
/// into one atlas, and bakes `solution` on `mesh` into it. A texel takes the element under
/// its point, of whichever object, facing the face's way when one does.
///
/// # Errors
/// The file cannot be read again, an accessor the atlas cannot gather (sparse, or a matrix),
/// or the unwrap's and the bake's errors.
pub fn bake_source_atlas(
    path: &Path,
    up: UpAxis,
    scene: &Scene,
    mesh: &Mesh,
    solution: &Solution,
    options: &AtlasOptions,
    texels: AtlasTexels<'_>,
) -> Result<(Atlas, SourceGltf), AtlasError> {
    let bad = |m: String| AtlasError::Source(format!("{}: {m}", path.display()));
    let gltf = gltf::Gltf::open(path).map_err(|e| bad(e.to_string()))?;
    let base = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let buffers = gltf::import_buffers(&gltf.document, Some(&base), gltf.blob.clone())
        .map_err(|e| bad(e.to_string()))?
        .into_iter()
        .map(|d| d.0)
        .collect::<Vec<_>>();
    let document = &gltf.document;
    let mut work = Unwrapping { meshes: Vec::new(), inputs: Vec::new(), scales: Vec::new() };
    let mut primitives = Vec::new();
    let Some(root) = document.default_scene().or_else(|| document.scenes().next()) else {
        return Err(AtlasError::Empty);
    };
    let mut stack: Vec<(gltf::Node, DMat4)> = root.nodes().map(|n| (n, DMat4::IDENTITY)).collect();
    while let Some((node, parent)) = stack.pop() {
        let local = DMat4::from_cols_array_2d(&node.transform().matrix().map(|c| c.map(f64::from)));
        let world = parent * local;
        stack.extend(node.children().map(|c| (c, world)));
        let Some(node_mesh) = node.mesh() else { continue };
        for (p, prim) in node_mesh.primitives().enumerate() {
            let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d[..]));
            let Some(points) = reader.read_positions() else { continue };
            let positions: Vec<DVec3> = points
                .map(|q| {
                    up.to_y_up(world.transform_point3(DVec3::new(q[0].into(), q[1].into(), q[2].into())))
                })
                .collect();
            let indices: Vec<u32> = match reader.read_indices() {
                Some(i) => i.into_u32().collect(),
                None => (0..positions.len() as u32).collect(),
            };
            let Some(triangles) = triangle_list(prim.mode(), &indices) else { continue };
            if triangles.iter().any(|&i| i as usize >= positions.len()) || triangles.is_empty() {
                continue;
            }
            work.inputs.push((positions.iter().map(|q| q.as_vec3().to_array()).collect(), triangles.clone()));
            work.scales.push(1.0);
            work.meshes.push(AtlasMesh {
                object: ANY_OBJECT,
                back: false,
                two_sided: false,
                emits: true,
                positions,
                uv0: None,
                uv1: Vec::new(),
                chart: Vec::new(),
                xref: Vec::new(),
                indices: triangles,
            });
            primitives.push((node.index(), p));
        }
    }
    let locator = Locator::new(scene, mesh, true);
    let atlas = unwrap_and_bake(mesh, solution, options, texels, &locator, work)?;
    let json = serde_json::to_value(document.clone().into_json()).map_err(|e| bad(e.to_string()))?;
    Ok((atlas, SourceGltf { json, buffers, base, primitives }))
}

/// A primitive's triangles as a list, strips and fans unrolled; `None` for points and lines.
fn triangle_list(mode: gltf::mesh::Mode, indices: &[u32]) -> Option<Vec<u32>> {
    use gltf::mesh::Mode;
    Some(match mode {
        Mode::Triangles => indices[..indices.len() / 3 * 3].to_vec(),
        Mode::TriangleStrip => strip_triangles(indices).concat(),
        Mode::TriangleFan => fan_triangles(indices).concat(),
        _ => return None,
    })
}

/// Writes `lightmapped.gltf` (the model of `source` with the atlas's coordinates), the EXR
/// and the PNG into `dir`. Returns the paths written.
///
/// # Errors
/// A file that cannot be written, an image file of the model that cannot be read, an
/// accessor that cannot be gathered.
pub fn write_source_atlas(
    dir: &Path,
    source: &SourceGltf,
    atlas: &Atlas,
    options: &AtlasOptions,
    tone: ToneParams,
) -> Result<Vec<PathBuf>, String> {
    let (mut written, png) = write_pictures(dir, atlas, tone)?;
    let text = source_gltf(source, atlas, options, &png, tone)?;
    let gltf = dir.join(ATLAS_FILES[0]);
    std::fs::write(&gltf, text).map_err(|e| format!("{}: {e}", gltf.display()))?;
    written.insert(0, gltf);
    Ok(written)
}

/// Bytes of one component of glTF type `component_type`.
fn component_bytes(component_type: u64) -> Option<usize> {
    match component_type {
        5120 | 5121 => Some(1),
        5122 | 5123 => Some(2),
        5125 | 5126 => Some(4),
        _ => None,
    }
}

/// The new document's one buffer, being filled.
struct Blob {
    bytes: Vec<u8>,
    views: Vec<Value>,
}

impl Blob {
    /// Appends `data` as a buffer view (with `stride` when given); its index.
    fn view(&mut self, data: &[u8], stride: Option<usize>) -> usize {
        let mut view = push_view(&mut self.bytes, data, None);
        if let Some(stride) = stride {
            view["byteStride"] = stride.into();
        }
        self.views.push(view);
        self.views.len() - 1
    }
}

/// The `.gltf` text: `source`'s JSON with the lightmapped primitives rewritten (see the
/// module's documentation) and `png` as the lightmap's texture.
fn source_gltf(
    source: &SourceGltf,
    atlas: &Atlas,
    options: &AtlasOptions,
    png: &[u8],
    tone: ToneParams,
) -> Result<String, String> {
    let mut doc = source.json.clone();
    // One buffer: the model's buffers one after another, then what is added.
    let mut starts = Vec::new();
    let mut blob = Blob { bytes: Vec::new(), views: Vec::new() };
    for b in &source.buffers {
        while !blob.bytes.len().is_multiple_of(4) {
            blob.bytes.push(0);
        }
        starts.push(blob.bytes.len());
        blob.bytes.extend_from_slice(b);
    }
    // What is added after them starts 4-byte aligned, as every view `push_view` adds ends so.
    while !blob.bytes.len().is_multiple_of(4) {
        blob.bytes.push(0);
    }
    let old_views = doc["bufferViews"].as_array().cloned().unwrap_or_default();
    for v in &old_views {
        let mut v = v.clone();
        let b = v["buffer"].as_u64().unwrap_or(0) as usize;
        let offset = v["byteOffset"].as_u64().unwrap_or(0) as usize + starts.get(b).copied().unwrap_or(0);
        v["buffer"] = 0.into();
        v["byteOffset"] = offset.into();
        blob.views.push(v);
    }
    // Images given by file embed their bytes.
    if let Some(images) = doc["images"].as_array_mut() {
        for image in images {
            let Some(uri) = image["uri"].as_str().map(str::to_owned) else { continue };
            if uri.starts_with("data:") {
                continue;
            }
            let file = source.base.join(percent_decoded(&uri));
            let bytes = std::fs::read(&file).map_err(|e| format!("{}: {e}", file.display()))?;
            let lower = uri.to_ascii_lowercase();
            let mime = if lower.ends_with(".png") { "image/png" } else { "image/jpeg" };
            let view = blob.view(&bytes, None);
            let map = image.as_object_mut().expect("an image is an object");
            map.remove("uri");
            map.insert("bufferView".into(), view.into());
            map.entry("mimeType").or_insert(mime.into());
        }
    }
    // The lightmap's set: after the most sets any lightmapped primitive has.
    let sets = |prim: &Value| {
        prim["attributes"].as_object().map_or(0, |a| a.keys().filter(|k| k.starts_with("TEXCOORD_")).count())
    };
    let mesh_of = |doc: &Value, node: usize| doc["nodes"][node]["mesh"].as_u64().map(|m| m as usize);
    let set = source
        .primitives
        .iter()
        .filter_map(|&(n, p)| mesh_of(&doc, n).map(|m| sets(&doc["meshes"][m]["primitives"][p])))
        .max()
        .unwrap_or(0);
    // The lightmap texture.
    let png_view = blob.view(png, None);
    push(&mut doc, "images", json!({ "name": "lightmap", "bufferView": png_view, "mimeType": "image/png" }));
    let sampler = push(
        &mut doc,
        "samplers",
        json!({ "magFilter": 9729, "minFilter": 9987, "wrapS": 33071, "wrapT": 33071 }),
    );
    let image = doc["images"].as_array().map_or(0, |a| a.len() - 1);
    let texture =
        push(&mut doc, "textures", json!({ "name": "lightmap", "sampler": sampler, "source": image }));
    // Each node with lightmapped primitives gets its own copy of its mesh.
    let mut copies: std::collections::HashMap<usize, usize> = std::collections::HashMap::new();
    let mut default_material = None;
    for (m, &(node, p)) in atlas.meshes.iter().zip(&source.primitives) {
        let Some(original) = mesh_of(&doc, node) else { continue };
        let copy = match copies.get(&node) {
            Some(&c) => c,
            None => {
                let mesh = doc["meshes"][original].clone();
                let c = push(&mut doc, "meshes", mesh);
                doc["nodes"][node]["mesh"] = c.into();
                copies.insert(node, c);
                c
            }
        };
        let mut prim = doc["meshes"][copy]["primitives"][p].clone();
        let gather = |doc: &mut Value, blob: &mut Blob, accessor: u64| {
            gathered(doc, blob, &source.buffers, accessor as usize, &m.xref)
        };
        let names: Vec<String> =
            prim["attributes"].as_object().map(|a| a.keys().cloned().collect()).unwrap_or_default();
        for name in names {
            let a = prim["attributes"][&name].as_u64().ok_or("an attribute without an accessor")?;
            prim["attributes"][&name] = gather(&mut doc, &mut blob, a)?.into();
        }
        if let Some(targets) = prim["targets"].as_array().cloned() {
            let mut new_targets = Vec::new();
            for t in targets {
                let mut t = t.clone();
                let names: Vec<String> =
                    t.as_object().map(|a| a.keys().cloned().collect()).unwrap_or_default();
                for name in names {
                    let a = t[&name].as_u64().ok_or("a morph target without an accessor")?;
                    t[&name] = gather(&mut doc, &mut blob, a)?.into();
                }
                new_targets.push(t);
            }
            prim["targets"] = Value::Array(new_targets);
        }
        let uv: Vec<u8> = m.uv1.iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
        let view = blob.view(&uv, None);
        let uv_accessor = push(
            &mut doc,
            "accessors",
            json!({ "bufferView": view, "componentType": 5126, "count": m.uv1.len(), "type": "VEC2" }),
        );
        // Sets below the lightmap's that this primitive lacks take the lightmap's too (glTF
        // numbers them without gaps).
        for k in 0..=set {
            let key = format!("TEXCOORD_{k}");
            if k == set || prim["attributes"].get(&key).is_none() {
                prim["attributes"][&key] = uv_accessor.into();
            }
        }
        let idx: Vec<u8> = m.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
        let view = blob.view(&idx, None);
        prim["indices"] = push(
            &mut doc,
            "accessors",
            json!({ "bufferView": view, "componentType": 5125, "count": m.indices.len(), "type": "SCALAR" }),
        )
        .into();
        prim["mode"] = 4.into();
        if prim.get("material").is_none_or(Value::is_null) {
            let d = *default_material.get_or_insert_with(|| {
                push(&mut doc, "materials", json!({ "name": "default", "pbrMetallicRoughness": {
                    "baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0 } }))
            });
            prim["material"] = d.into();
        }
        doc["meshes"][copy]["primitives"][p] = prim;
    }
    // Every material points at the lightmap.
    if let Some(materials) = doc["materials"].as_array_mut() {
        for material in materials {
            let extras = material
                .as_object_mut()
                .expect("a material is an object")
                .entry("extras")
                .or_insert(json!({}));
            if !extras.is_object() {
                *extras = json!({ "value": extras.clone() });
            }
            extras["lightmap"] = json!({ "index": texture, "texCoord": set });
        }
    }
    let asset = doc["asset"].as_object_mut().ok_or("no asset")?;
    let extras = asset.entry("extras").or_insert(json!({}));
    if !extras.is_object() {
        *extras = json!({ "value": extras.clone() });
    }
    extras["radiosity_lightmap"] = lightmap_extras(atlas, options, tone, texture, set);
    doc["bufferViews"] = Value::Array(blob.views);
    doc["buffers"] = json!([{ "byteLength": blob.bytes.len(),
        "uri": format!("data:application/octet-stream;base64,{}", base64(&blob.bytes)) }]);
    Ok(serde_json::to_string(&doc).expect("a JSON value serialises"))
}

/// Appends `value` to the array `key` of `doc` (made if missing); its index.
fn push(doc: &mut Value, key: &str, value: Value) -> usize {
    if !doc[key].is_array() {
        doc[key] = json!([]);
    }
    let list = doc[key].as_array_mut().expect("made an array above");
    list.push(value);
    list.len() - 1
}

/// A copy of accessor `a` of `doc` holding, for each new vertex, the element of the old
/// vertex `xref` names (raw bytes, whatever the type); its index. `POSITION`-like float
/// `VEC3` accessors get their bounds again, since glTF requires them for positions.
fn gathered(
    doc: &mut Value,
    blob: &mut Blob,
    buffers: &[Vec<u8>],
    a: usize,
    xref: &[u32],
) -> Result<usize, String> {
    let accessor = doc["accessors"][a].clone();
    if accessor.get("sparse").is_some() {
        return Err(format!("accessor {a} is sparse: the lightmap atlas cannot split its vertices"));
    }
    let components = match accessor["type"].as_str() {
        Some("SCALAR") => 1,
        Some("VEC2") => 2,
        Some("VEC3") => 3,
        Some("VEC4") => 4,
        other => {
            return Err(format!("accessor {a} is a {other:?}: not a vertex attribute the atlas can gather"));
        }
    };
    let component_type = accessor["componentType"].as_u64().unwrap_or(0);
    let size =
        components * component_bytes(component_type).ok_or(format!("accessor {a}: bad componentType"))?;
    let stride = size.next_multiple_of(4);
    let count = accessor["count"].as_u64().unwrap_or(0) as usize;
    let mut out = vec![0u8; stride * xref.len()];
    if let Some(v) = accessor["bufferView"].as_u64() {
        let view = &doc["bufferViews"][v as usize];
        let buffer = &buffers[view["buffer"].as_u64().unwrap_or(0) as usize];
        let start = view["byteOffset"].as_u64().unwrap_or(0) as usize
            + accessor["byteOffset"].as_u64().unwrap_or(0) as usize;
        let step = view["byteStride"].as_u64().map_or(size, |s| s as usize);
        for (k, &old) in xref.iter().enumerate() {
            let from = start + old as usize * step;
            if old as usize >= count || from + size > buffer.len() {
                return Err(format!("accessor {a}: vertex {old} out of its range"));
            }
            out[k * stride..k * stride + size].copy_from_slice(&buffer[from..from + size]);
        }
    }
    // Vertex attributes are strided in multiples of 4 bytes (glTF 2.0, 3.6.2.4).
    let view = blob.view(&out, Some(stride));
    let mut new = json!({ "bufferView": view, "componentType": component_type, "count": xref.len(),
        "type": accessor["type"].clone() });
    if accessor["normalized"].as_bool() == Some(true) {
        new["normalized"] = true.into();
    }
    if components == 3 && component_type == 5126 && accessor.get("min").is_some() {
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for chunk in out.chunks_exact(stride) {
            for c in 0..3 {
                let x = f32::from_le_bytes(chunk[4 * c..4 * c + 4].try_into().expect("4 bytes"));
                lo[c] = lo[c].min(x);
                hi[c] = hi[c].max(x);
            }
        }
        new["min"] = json!(lo);
        new["max"] = json!(hi);
    }
    Ok(push(doc, "accessors", new))
}

/// A URI's `%xx` escapes decoded (file names with spaces).
fn percent_decoded(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = bytes.get(i + 1..i + 3).and_then(|h| std::str::from_utf8(h).ok());
        if bytes[i] == b'%'
            && let Some(b) = hex.and_then(|h| u8::from_str_radix(h, 16).ok())
        {
            out.push(b);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}
