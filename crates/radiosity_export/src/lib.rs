//! Lit meshes out: the solved element mesh with per-vertex colours as glTF 2.0 (`.gltf` with
//! the buffer embedded, or `.glb`) and PLY, and per-object lightmaps (OpenEXR) with an OBJ
//! that maps them.
//!
//! * glTF: one node and mesh per object (named as in the scene), triangles of the elements
//!   (a quad element gives two), `POSITION` (float), `COLOR_0` (float RGB in [0, 1], linear
//!   as glTF requires), `_RADIOSITY` (float RGB: the radiosity B, W per unit², of
//!   [`radiosity_solver::Solution::vertex_radiosity`], unclamped — glTF's colours may not
//!   exceed 1, and a light's radiosity does) and a `KHR_materials_unlit` material with a white
//!   base colour, so every viewer shows the baked colour itself whatever its lights. See
//!   [`VertexColours`] for what `COLOR_0` holds. An object with a colour texture (and texture
//!   coordinates, [`radiosity_image::element_uvs`]) also gets `TEXCOORD_0` per element corner
//!   and an unlit material showing the texture, its PNG embedded in the file's buffer; its
//!   `COLOR_0` is then the colour over the material's mean reflectance (clamped to 1), so
//!   texel × colour is what `render` shows (see the `textured` module).
//! * PLY: binary little endian; per vertex `float x y z`, `uchar red green blue` (sRGB-encoded
//!   display colour, what PLY viewers show) and `float radiosity_r radiosity_g radiosity_b`
//!   (linear B); faces are the elements' triangles (a quad element gives two, as in glTF) as
//!   `list uchar uint`: triangles only, because common readers (trimesh among them) refuse a
//!   face list that mixes triangles and quads.
//! * Lightmaps: see [`write_lightmaps`] (one cell per element, an OBJ over the elements)
//!   and [`bake_atlas`] with [`write_atlas`] (the model's own faces unwrapped into one atlas,
//!   a glTF with `TEXCOORD_1` for engines).
//!
//! Frames: the mesh is in the renderer's +y-up frame. glTF is +y up by its specification and
//! is written as the mesh is; PLY and the lightmaps' OBJ have no convention, and are written
//! back in the frame of the model file ([`UpAxis::from_y_up`]), so a lit z-up building model
//! lies over its original in the tool it came from.
//!
//! Scene files come in through `radiosity_io`; lit meshes go out here, so the scene loader
//! needs neither the solver nor the picture-file formats.
#![warn(missing_docs)]
#![forbid(unsafe_code)]

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use radiosity_core::glam::DVec3;
use radiosity_core::{Rgb, UpAxis, encode_srgb, unique_names};
use radiosity_image::{
    ElementUvs, HdrImage, RenderError, RenderParams, Renderer, ToneOperator, ToneParams, tone_map,
};
use radiosity_mesh::Mesh;
use radiosity_solver::Solution;
use rayon::prelude::*;
use serde_json::{Value, json};
use textured::{TexturedMaterials, push_view};

mod atlas;
mod atlas_gltf;
mod atlas_source;
mod textured;

pub use atlas::{
    Atlas, AtlasError, AtlasMesh, AtlasOptions, AtlasTexels, DIM, DIM_DENSITY, LightmapQuantity, bake_atlas,
};
pub use atlas_gltf::{ATLAS_FILES, atlas_gltf, atlas_radiance, write_atlas};
pub use atlas_source::{SourceGltf, bake_source_atlas, write_source_atlas};

/// What the exported vertex colours (`COLOR_0`) hold. glTF requires colours in [0, 1], so
/// radiosity itself (lights reach 65 W per unit² in the Cornell box) goes unclamped into the
/// `_RADIOSITY` attribute, and `COLOR_0` holds a displayable colour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum VertexColours {
    /// Linear radiance B/π times 2^`exposure_ev`, clamped to [0, 1]: proportional to
    /// radiosity up to white (the `linear` tone operator).
    Linear {
        /// Exposure in stops.
        exposure_ev: f64,
    },
    /// The display colour of the radiance B/π under these tone-mapping settings.
    Display(ToneParams),
}

/// Lit-mesh file formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExportFormat {
    /// glTF 2.0 JSON with the buffer embedded as a base64 data URI.
    Gltf,
    /// Binary glTF.
    Glb,
    /// Stanford PLY, binary little endian.
    Ply,
}

impl ExportFormat {
    /// The format for an output path's extension (case-insensitive), or `None`.
    pub fn from_path(path: &Path) -> Option<Self> {
        match path.extension()?.to_str()?.to_ascii_lowercase().as_str() {
            "gltf" => Some(Self::Gltf),
            "glb" => Some(Self::Glb),
            "ply" => Some(Self::Ply),
            _ => None,
        }
    }
}

/// The colour of every mesh vertex for `mode`, each channel in [0, 1].
pub fn vertex_colours(solution: &Solution, mode: VertexColours) -> Vec<Rgb> {
    let tone = match mode {
        VertexColours::Linear { exposure_ev } => ToneParams::new(exposure_ev, ToneOperator::Linear),
        VertexColours::Display(tone) => tone,
    };
    solution.vertex_radiosity.iter().map(|&b| tone_map(b / std::f64::consts::PI, &tone)).collect()
}

/// One object's glTF vertices and triangles.
struct ObjectMesh {
    object: usize,
    /// Per glTF vertex: the mesh vertex and, on a textured object, its texture coordinates.
    verts: Vec<(u32, [f32; 2])>,
    /// Triangles in indices into `verts`.
    tris: Vec<[u32; 3]>,
    /// The mesh material index when the object is exported textured.
    textured: Option<usize>,
}

/// The vertices and triangles of each object. Vertices are never shared across surfaces, so
/// never across objects; on a textured object (see [`textured::is_textured`]) a mesh vertex
/// is one glTF vertex per distinct texture coordinate of the element corners at it.
fn objects_of(mesh: &Mesh, uvs: &[Option<ElementUvs>]) -> Vec<ObjectMesh> {
    let mut local = vec![u32::MAX; mesh.positions.len()];
    let mut split: HashMap<(u32, [u32; 2]), u32> = HashMap::new();
    let mut out: Vec<ObjectMesh> = (0..mesh.object_names.len())
        .map(|object| ObjectMesh { object, verts: Vec::new(), tris: Vec::new(), textured: None })
        .collect();
    // An object is one material: textured when its elements are.
    for e in 0..mesh.elements.len() {
        if textured::is_textured(mesh, uvs, e) {
            out[mesh.element_object(e)].textured = Some(textured::material_index(mesh, e));
        }
    }
    for (e, tri) in mesh.element_triangles() {
        let e = e as usize;
        let o = &mut out[mesh.element_object(e)];
        let corners = mesh.elements[e].vertex_indices();
        let t = tri.map(|v| match (o.textured, uvs.get(e).copied().flatten()) {
            (Some(_), Some(element_uvs)) => {
                let k = corners.iter().position(|&c| c == v).expect("a triangle's vertex is its element's");
                let uv = element_uvs[k].map(|c| c as f32);
                *split.entry((v, uv.map(f32::to_bits))).or_insert_with(|| {
                    o.verts.push((v, uv));
                    o.verts.len() as u32 - 1
                })
            }
            _ => {
                if local[v as usize] == u32::MAX {
                    local[v as usize] = o.verts.len() as u32;
                    o.verts.push((v, [0.0; 2]));
                }
                local[v as usize]
            }
        });
        o.tris.push(t);
    }
    out.retain(|o| !o.verts.is_empty());
    out
}

/// The number of vertices [`gltf_text`] and [`glb_bytes`] write: the mesh's, plus the copies
/// of vertices where textured elements meet with different texture coordinates.
pub fn gltf_vertex_count(mesh: &Mesh, uvs: &[Option<ElementUvs>]) -> usize {
    objects_of(mesh, uvs).iter().map(|o| o.verts.len()).sum()
}

/// The glTF document (JSON) and its binary buffer for `mesh` with `colours` per vertex.
/// With `uri`, the buffer is referenced by it (a data URI for `.gltf`); without, it is the
/// GLB's own chunk.
fn gltf_document(
    mesh: &Mesh,
    colours: &[Rgb],
    radiosity: &[Rgb],
    mode: VertexColours,
    uvs: &[Option<ElementUvs>],
) -> (Value, Vec<u8>) {
    const ARRAY_BUFFER: u32 = 34962;
    const ELEMENT_ARRAY_BUFFER: u32 = 34963;
    const FLOAT: u32 = 5126;
    const UNSIGNED_INT: u32 = 5125;
    let mut blob = Vec::new();
    let (mut views, mut accessors, mut meshes, mut nodes) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut textured = TexturedMaterials::default();
    for ObjectMesh { object, verts, tris, textured: material } in objects_of(mesh, uvs) {
        let mut pos = Vec::with_capacity(verts.len() * 12);
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for &(v, _) in &verts {
            let p = mesh.positions[v as usize].as_vec3().to_array();
            for c in 0..3 {
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
                pos.extend_from_slice(&p[c].to_le_bytes());
            }
        }
        let scale = material.map_or([1.0; 3], |m| textured::colour_scale(&mesh.materials[m]));
        let mut col = Vec::with_capacity(verts.len() * 12);
        for &(v, _) in &verts {
            for (c, s) in colours[v as usize].to_array().into_iter().zip(scale) {
                // glTF colours are linear and in [0, 1] (the validator's ACCESSOR_NON_CLAMPED):
                // a tiny negative from round-off is 0, and a textured object's colour over its
                // mean reflectance is clamped to 1 where the light is that bright.
                col.extend_from_slice(&((c * s).clamp(0.0, 1.0) as f32).to_le_bytes());
            }
        }
        let mut rad = Vec::with_capacity(verts.len() * 12);
        for &(v, _) in &verts {
            for c in radiosity[v as usize].to_array() {
                rad.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
        let idx: Vec<u8> = tris.iter().flatten().flat_map(|i| i.to_le_bytes()).collect();
        let base = accessors.len();
        views.push(push_view(&mut blob, &pos, Some(ARRAY_BUFFER)));
        accessors.push(json!({ "bufferView": views.len() - 1, "componentType": FLOAT, "count": verts.len(),
            "type": "VEC3", "min": lo, "max": hi }));
        views.push(push_view(&mut blob, &col, Some(ARRAY_BUFFER)));
        accessors.push(json!({ "bufferView": views.len() - 1, "componentType": FLOAT, "count": verts.len(),
            "type": "VEC3" }));
        views.push(push_view(&mut blob, &rad, Some(ARRAY_BUFFER)));
        accessors.push(json!({ "bufferView": views.len() - 1, "componentType": FLOAT, "count": verts.len(),
            "type": "VEC3" }));
        views.push(push_view(&mut blob, &idx, Some(ELEMENT_ARRAY_BUFFER)));
        accessors.push(json!({ "bufferView": views.len() - 1, "componentType": UNSIGNED_INT,
            "count": tris.len() * 3, "type": "SCALAR" }));
        let mut attributes = json!({ "POSITION": base, "COLOR_0": base + 1, "_RADIOSITY": base + 2 });
        let mut material_index = 0;
        if let Some(m) = material {
            let uv: Vec<u8> =
                verts.iter().flat_map(|(_, uv)| uv.iter().flat_map(|c| c.to_le_bytes())).collect();
            views.push(push_view(&mut blob, &uv, Some(ARRAY_BUFFER)));
            accessors
                .push(json!({ "bufferView": views.len() - 1, "componentType": FLOAT, "count": verts.len(),
                "type": "VEC2" }));
            attributes["TEXCOORD_0"] = (accessors.len() - 1).into();
            material_index = textured.material(mesh, m, &mut blob, &mut views);
        }
        let name = &mesh.object_names[object];
        meshes.push(json!({ "name": name, "primitives": [{
            "attributes": attributes, "indices": base + 3, "material": material_index }] }));
        nodes.push(json!({ "name": name, "mesh": meshes.len() - 1 }));
    }
    let colours_are = match mode {
        VertexColours::Linear { exposure_ev } => {
            format!("linear radiance B/pi x 2^EV clamped to [0, 1], exposure {exposure_ev:+.3} EV")
        }
        VertexColours::Display(t) => {
            format!("display colour (tone mapped {}, exposure {:+.3} EV)", t.operator, t.exposure_ev)
        }
    };
    let mut materials = vec![json!({ "name": "baked", "pbrMetallicRoughness": {
        "baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0 },
        "extensions": { "KHR_materials_unlit": {} } })];
    materials.append(&mut textured.materials);
    let mut doc = json!({
        "asset": { "version": "2.0", "generator": concat!("radiosity ", env!("CARGO_PKG_VERSION")),
            "extras": { "COLOR_0": colours_are, "_RADIOSITY": "radiosity B, W/unit^2, linear, unclamped",
                "TEXCOORD_0": "textured objects: COLOR_0 is the colour over the material's mean reflectance \
                    per channel (clamped to 1), so baseColorTexture x COLOR_0 is the light times the texel's albedo" } },
        "extensionsUsed": ["KHR_materials_unlit"],
        "scene": 0,
        "scenes": [{ "nodes": (0..nodes.len()).collect::<Vec<_>>() }],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{ "byteLength": blob.len() }],
    });
    // glTF forbids empty arrays: these appear only when something is textured.
    for (key, list) in [
        ("textures", textured.table.textures),
        ("samplers", textured.table.samplers),
        ("images", textured.table.images),
    ] {
        if !list.is_empty() {
            doc[key] = Value::Array(list);
        }
    }
    (doc, blob)
}

/// Standard base64 with padding (RFC 4648), for the `.gltf` data URI.
fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let n = (chunk[0] as u32) << 16
            | (*chunk.get(1).unwrap_or(&0) as u32) << 8
            | *chunk.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= chunk.len() {
                s.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// A `.gltf` file (JSON, buffer embedded as a base64 data URI, texture images in it as PNG) of
/// the lit mesh. `uvs`: per element, its corners' texture coordinates
/// ([`radiosity_image::element_uvs`] of the scene the mesh was built from); empty, or `None`
/// for an element, exports it with its material's mean colour.
pub fn gltf_text(
    mesh: &Mesh,
    solution: &Solution,
    mode: VertexColours,
    uvs: &[Option<ElementUvs>],
) -> String {
    let colours = vertex_colours(solution, mode);
    let (mut doc, blob) = gltf_document(mesh, &colours, &solution.vertex_radiosity, mode, uvs);
    doc["buffers"][0]["uri"] =
        Value::String(format!("data:application/octet-stream;base64,{}", base64(&blob)));
    let mut text = serde_json::to_string(&doc).expect("a JSON value always serialises");
    text.push('\n');
    text
}

/// A `.glb` file (binary glTF: JSON chunk and BIN chunk, texture images in the latter as PNG)
/// of the lit mesh; `uvs` as for [`gltf_text`].
pub fn glb_bytes(
    mesh: &Mesh,
    solution: &Solution,
    mode: VertexColours,
    uvs: &[Option<ElementUvs>],
) -> Vec<u8> {
    let colours = vertex_colours(solution, mode);
    let (doc, blob) = gltf_document(mesh, &colours, &solution.vertex_radiosity, mode, uvs);
    let mut json = serde_json::to_vec(&doc).expect("a JSON value always serialises");
    // Chunks are 4-byte aligned: JSON padded with spaces, BIN (already padded) with zeros.
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let total = 12 + 8 + json.len() + 8 + blob.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(blob.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&blob);
    out
}

/// A binary little-endian PLY of the element mesh: display colour as `uchar` and linear
/// radiosity as `float` per vertex; `display` sets the tone mapping of the former. Faces are
/// triangles only ([`Mesh::element_triangles`], the split the glTF output uses).
///
/// Positions are written in the frame of a file whose up axis is `up` ([`UpAxis::from_y_up`]):
/// PLY has no up convention, so the lit mesh lies over the model it came from in the tool the
/// model came from.
pub fn ply_bytes(mesh: &Mesh, solution: &Solution, display: ToneParams, up: UpAxis) -> Vec<u8> {
    let shown = vertex_colours(solution, VertexColours::Display(display));
    let mut header = String::new();
    let _ = write!(
        header,
        "ply\nformat binary_little_endian 1.0\ncomment radiosity {}: red green blue = display colour \
         (sRGB, tone mapped {}, exposure {:+.3} EV), radiosity_* = linear radiosity W/unit^2\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         property uchar red\nproperty uchar green\nproperty uchar blue\n\
         property float radiosity_r\nproperty float radiosity_g\nproperty float radiosity_b\n\
         element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        env!("CARGO_PKG_VERSION"),
        display.operator,
        display.exposure_ev,
        mesh.positions.len(),
        mesh.element_triangles().count()
    );
    let mut out = header.into_bytes();
    for (v, p) in mesh.positions.iter().enumerate() {
        for c in up.from_y_up(*p).as_vec3().to_array() {
            out.extend_from_slice(&c.to_le_bytes());
        }
        out.extend_from_slice(&encode_srgb(shown[v]));
        for c in solution.vertex_radiosity[v].to_array() {
            out.extend_from_slice(&(c as f32).to_le_bytes());
        }
    }
    for (_, triangle) in mesh.element_triangles() {
        out.push(3);
        for i in triangle {
            out.extend_from_slice(&i.to_le_bytes());
        }
    }
    out
}

/// Texels along each side of one element's cell in a lightmap.
pub const LIGHTMAP_CELL_TEXELS: u32 = 8;

/// One object's lightmap: its image and, per element of the object, the texture coordinates of
/// its corners (in the element's vertex order).
#[derive(Clone, Debug)]
pub struct Lightmap {
    /// Object index in the mesh.
    pub object: usize,
    /// Linear radiosity B per texel, W per unit².
    pub image: HdrImage,
    /// `(element, uv of each corner)`; `v` counts down from the top row (glTF's convention;
    /// OBJ's `vt` is 1 − v).
    pub charts: Vec<(usize, Vec<[f64; 2]>)>,
}

/// How the texels of a lightmap get their radiosity.
#[derive(Clone, Copy)]
pub enum Texels<'a> {
    /// Interpolated from the element's vertex radiosity, as the vertex colours shade.
    Interpolated,
    /// Gathered at the texel's point ([`Renderer::gathered_radiosity`]: direct light by
    /// shadow rays, so a coarse solve bakes sharp shadows), `params.samples_per_pixel`
    /// samples per texel.
    Gathered {
        /// The renderer over the same mesh.
        renderer: &'a Renderer,
        /// Gather mode, samples and rays per texel, seed.
        params: &'a RenderParams,
    },
}

/// Per-object lightmaps: each element of an object gets its own square cell of
/// [`LIGHTMAP_CELL_TEXELS`]² texels in the object's atlas, cells in rows in element order (the
/// simplest chart packing: no texel is shared, so no seam bleeds from one element into
/// another; a triangle uses half its cell). Corners map to the centres of the cell's corner
/// texels, and each texel holds the radiosity interpolated from the element's vertex
/// radiosity at its centre (bilinear over a quad, barycentric over a triangle), so the map
/// shades as smoothly as the vertex colours.
pub fn lightmaps(mesh: &Mesh, solution: &Solution) -> Vec<Lightmap> {
    lightmaps_with(mesh, solution, Texels::Interpolated).expect("interpolated texels cannot fail")
}

/// [`lightmaps`] with the texels' radiosity taken as `texels` says.
///
/// # Errors
/// A gather's [`RenderError`] (bad parameters, a solution of another mesh, no direct part).
pub fn lightmaps_with(
    mesh: &Mesh,
    solution: &Solution,
    texels: Texels<'_>,
) -> Result<Vec<Lightmap>, RenderError> {
    let k = LIGHTMAP_CELL_TEXELS;
    let mut by_object: Vec<Vec<usize>> = vec![Vec::new(); mesh.object_names.len()];
    for e in 0..mesh.elements.len() {
        by_object[mesh.element_object(e)].push(e);
    }
    let mut out = Vec::new();
    for (object, elements) in by_object.into_iter().enumerate() {
        if elements.is_empty() {
            continue;
        }
        let columns = (elements.len() as f64).sqrt().ceil() as u32;
        let rows = (elements.len() as u32).div_ceil(columns);
        let (w, h) = (columns * k, rows * k);
        let mut image = HdrImage::new(w, h);
        // Each element's cell on its own (in parallel: a gather traces rays per texel).
        let cells: Vec<Vec<Rgb>> = elements
            .par_iter()
            .map(|&e| element_cell(mesh, solution, e, texels))
            .collect::<Result<_, _>>()?;
        let mut charts = Vec::with_capacity(elements.len());
        for (n, (&e, cell)) in elements.iter().zip(cells).enumerate() {
            let (cx, cy) = ((n as u32 % columns) * k, (n as u32 / columns) * k);
            for (i, value) in cell.into_iter().enumerate() {
                image.set_pixel(cx + i as u32 % k, cy + i as u32 / k, value);
            }
            let uv = |s: f64, t: f64| {
                [
                    (cx as f64 + 0.5 + s * (k - 1) as f64) / w as f64,
                    (cy as f64 + 0.5 + t * (k - 1) as f64) / h as f64,
                ]
            };
            let corners = if mesh.elements[e].vertex_count == 4 {
                vec![uv(0.0, 0.0), uv(1.0, 0.0), uv(1.0, 1.0), uv(0.0, 1.0)]
            } else {
                vec![uv(0.0, 0.0), uv(1.0, 0.0), uv(0.0, 1.0)]
            };
            charts.push((e, corners));
        }
        out.push(Lightmap { object, image, charts });
    }
    Ok(out)
}

/// The [`LIGHTMAP_CELL_TEXELS`]² texels of element `e`'s cell, row by row.
fn element_cell(
    mesh: &Mesh,
    solution: &Solution,
    e: usize,
    texels: Texels<'_>,
) -> Result<Vec<Rgb>, RenderError> {
    let k = LIGHTMAP_CELL_TEXELS;
    let idx = mesh.elements[e].vertex_indices();
    // Cell parameters (s, t) in [0, 1] at texel centres 0 and k−1.
    let param = |i: u32| i as f64 / (k - 1) as f64;
    let mut cell = Vec::with_capacity((k * k) as usize);
    for ty in 0..k {
        for tx in 0..k {
            let (s, t) = (param(tx), param(ty));
            let weights: Vec<f64> = if idx.len() == 4 {
                vec![(1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t]
            } else {
                // Outside the triangle (s + t > 1) the texel is never sampled inside the
                // chart; it takes the nearest edge value so filtering there is harmless.
                let sum = (s + t).max(1.0);
                let (s, t) = (s / sum, t / sum);
                vec![1.0 - s - t, s, t]
            };
            let value = match texels {
                Texels::Interpolated => {
                    idx.iter().zip(&weights).map(|(&v, &w)| solution.vertex_radiosity[v as usize] * w).sum()
                }
                Texels::Gathered { renderer, params } => {
                    let p: DVec3 =
                        idx.iter().zip(&weights).map(|(&v, &w)| mesh.positions[v as usize] * w).sum();
                    // Corner texels sit on the element's edge, which may be a room's edge where
                    // rays graze the next wall: gather a thousandth of the way in instead.
                    let p = p + (mesh.elements[e].centre - p) * 1e-3;
                    let key = (e as u64) << 12 | u64::from(ty * k + tx);
                    renderer.gathered_radiosity(solution, e, p, params, key)?
                }
            };
            cell.push(value);
        }
    }
    Ok(cell)
}

/// A file-name-safe version of an object name (`/` and other separators become `_`).
pub fn file_stem_for(name: &str) -> String {
    let s: String =
        name.chars().map(|c| if c.is_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect();
    if s.is_empty() { "object".into() } else { s }
}

/// Writes lightmaps ([`lightmaps_with`] `texels`) into `dir` as `<object>.exr` (linear radiosity), with `lightmapped.obj`
/// and `lightmapped.mtl` mapping them (`map_Kd`, texture coordinates per element corner) so a
/// modelling tool shows the baked light, its positions in the frame of a file whose up axis is
/// `up` (as [`ply_bytes`]). Returns the paths written.
///
/// # Errors
/// The folder or a file cannot be written.
pub fn write_lightmaps(
    dir: &Path,
    mesh: &Mesh,
    solution: &Solution,
    texels: Texels<'_>,
    up: UpAxis,
) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: cannot create the folder: {e}", dir.display()))?;
    let maps = lightmaps_with(mesh, solution, texels).map_err(|e| e.to_string())?;
    let mut stems: Vec<String> = maps.iter().map(|m| file_stem_for(&mesh.object_names[m.object])).collect();
    unique_names(&mut stems);
    let mut written = Vec::new();
    let mut obj = String::from(
        "# radiosity lightmaps: one material and one EXR (linear radiosity) per object\nmtllib lightmapped.mtl\n",
    );
    let mut mtl = String::new();
    let (mut nv, mut nt) = (0usize, 0usize);
    for (map, stem) in maps.iter().zip(&stems) {
        let path = dir.join(format!("{stem}.exr"));
        radiosity_image::write_exr(&path, &map.image).map_err(|e| e.to_string())?;
        written.push(path);
        let _ = writeln!(mtl, "newmtl {stem}\nKd 1 1 1\nmap_Kd {stem}.exr\n");
        let _ = writeln!(obj, "o {stem}\nusemtl {stem}");
        for (e, uvs) in &map.charts {
            let el = &mesh.elements[*e];
            for (&v, uv) in el.vertex_indices().iter().zip(uvs) {
                let p = up.from_y_up(mesh.positions[v as usize]);
                let _ = writeln!(obj, "v {} {} {}\nvt {} {}", p.x, p.y, p.z, uv[0], 1.0 - uv[1]);
            }
            let corners: Vec<String> =
                (0..uvs.len()).map(|k| format!("{}/{}", nv + k + 1, nt + k + 1)).collect();
            let _ = writeln!(obj, "f {}", corners.join(" "));
            nv += uvs.len();
            nt += uvs.len();
        }
    }
    for (name, text) in [("lightmapped.obj", obj), ("lightmapped.mtl", mtl)] {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| format!("{}: {e}", path.display()))?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc_4648_vectors() {
        for (raw, enc) in [("", ""), ("f", "Zg=="), ("fo", "Zm8="), ("foo", "Zm9v"), ("foobar", "Zm9vYmFy")] {
            assert_eq!(base64(raw.as_bytes()), enc);
        }
    }

    #[test]
    fn file_stems_are_safe() {
        assert_eq!(file_stem_for("statue/head 2"), "statue_head_2");
        assert_eq!(file_stem_for(""), "object");
    }
}
