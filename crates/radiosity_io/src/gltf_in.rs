//! glTF 2.0 (`.gltf` JSON or `.glb` binary) through the `gltf` crate.
//!
//! The crate's accessor readers trust the file (a float index accessor reaches an
//! `unreachable!`, a zero count underflows, a short buffer view is sliced past its end), so
//! every accessor is checked here against its buffer before it is read: a broken file is an
//! error naming the mesh, primitive and accessor, never a panic.

use std::collections::HashMap;
use std::path::Path;

use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;
use radiosity_core::glam::{DMat4, DVec3};
use radiosity_core::{Camera, Material, Rgb, Sides, Wrap, unique_names};
use radiosity_mesh::{fan_triangles, strip_triangles};

use crate::LoadError;
use crate::model::{
    DEFAULT_GREY, DecodedImage, Model, ModelPart, PartBuilder, Transform, blend_warning, clamp_reflectance,
    model_error, model_material, specular_warning,
};
use crate::texture_map::UvTransform;

/// Checks that `accessor` can be read as `dims` of one of `types` without leaving its buffer.
fn check_accessor(
    accessor: &gltf::Accessor,
    dims: Dimensions,
    types: &[DataType],
    buffers: &[gltf::buffer::Data],
) -> Result<(), String> {
    let index = accessor.index();
    if accessor.dimensions() != dims || !types.contains(&accessor.data_type()) {
        return Err(format!(
            "accessor {index}: expected {dims:?} of {types:?}, got {:?} of {:?}",
            accessor.dimensions(),
            accessor.data_type()
        ));
    }
    if accessor.count() == 0 {
        return Err(format!("accessor {index}: count is 0"));
    }
    if accessor.sparse().is_some() {
        return Err(format!("accessor {index}: sparse accessors are not supported"));
    }
    let Some(view) = accessor.view() else {
        return Err(format!("accessor {index}: has no buffer view"));
    };
    let size = accessor.size();
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(format!(
            "accessor {index}: byte stride {stride} is smaller than an element ({size} bytes)"
        ));
    }
    let end = (accessor.count() - 1)
        .checked_mul(stride)
        .and_then(|v| v.checked_add(size))
        .and_then(|v| v.checked_add(accessor.offset()));
    if end.is_none_or(|end| end > view.length()) {
        return Err(format!(
            "accessor {index}: {} elements from byte {} run past its buffer view ({} bytes)",
            accessor.count(),
            accessor.offset(),
            view.length()
        ));
    }
    let data_len = buffers.get(view.buffer().index()).map_or(0, |d| d.len());
    if view.offset().checked_add(view.length()).is_none_or(|end| end > data_len) {
        return Err(format!(
            "buffer view {}: bytes {}..{} run past buffer {} ({data_len} bytes)",
            view.index(),
            view.offset(),
            view.offset().saturating_add(view.length()),
            view.buffer().index()
        ));
    }
    Ok(())
}

/// An 8-bit sRGB image decoded, or `None` for other pixel formats.
fn decoded(image: &gltf::image::Data) -> Option<DecodedImage> {
    use gltf::image::Format;
    let channels = match image.format {
        Format::R8G8B8 => 3,
        Format::R8G8B8A8 => 4,
        _ => return None,
    };
    DecodedImage::from_srgb8(&image.pixels, channels, image.width, image.height)
}

/// A sampler's wrap mode as the renderer's.
fn wrap(mode: gltf::texture::WrappingMode) -> Wrap {
    use gltf::texture::WrappingMode;
    match mode {
        WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
        WrappingMode::Repeat => Wrap::Repeat,
    }
}

/// Where a base colour texture lies: its texture coordinate set and the
/// `KHR_texture_transform` that maps them.
fn placement(info: &gltf::texture::Info) -> (u32, UvTransform) {
    match info.texture_transform() {
        Some(t) => {
            let transform = UvTransform {
                offset: t.offset().map(f64::from),
                scale: t.scale().map(f64::from),
                rotation: f64::from(t.rotation()),
            };
            (t.tex_coord().unwrap_or(info.tex_coord()), transform)
        }
        None => (info.tex_coord(), UvTransform::default()),
    }
}

/// Texture coordinates of the welded triangle corners `triangles` (indices into the
/// primitive's vertices) from set `set`, mapped by `transform`; `None` when the primitive has
/// no such set or it cannot be read (the part then shows its mean colour).
fn triangle_uvs(
    prim: &gltf::Primitive,
    buffers: &[gltf::buffer::Data],
    set: u32,
    transform: &UvTransform,
    triangles: &[[u32; 3]],
) -> Option<Vec<[[f64; 2]; 3]>> {
    let accessor = prim.get(&gltf::Semantic::TexCoords(set))?;
    check_accessor(&accessor, Dimensions::Vec2, &[DataType::F32, DataType::U8, DataType::U16], buffers)
        .ok()?;
    let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
    let uvs: Vec<[f32; 2]> = reader.read_tex_coords(set)?.into_f32().collect();
    let uv = |i: u32| uvs.get(i as usize).map(|uv| transform.apply(uv.map(f64::from)));
    triangles.iter().map(|t| Some([uv(t[0])?, uv(t[1])?, uv(t[2])?])).collect()
}

/// Splits a GLB container into its JSON chunk and optional BIN chunk. Done here rather than by
/// `gltf::Glb`, whose header check underflows on a declared length below 12.
fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<Vec<u8>>), String> {
    let word =
        |at: usize| -> Option<u32> { Some(u32::from_le_bytes(bytes.get(at..at + 4)?.try_into().ok()?)) };
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        return Err("GLB: the file ends inside its 12-byte header".into());
    };
    if version != 2 {
        return Err(format!("GLB: version {version}, expected 2"));
    }
    let length = length as usize;
    if length > bytes.len() || length < 12 {
        return Err(format!("GLB: the header declares {length} bytes, the file has {}", bytes.len()));
    }
    let mut at = 12;
    let mut json = None;
    let mut bin = None;
    while at + 8 <= length {
        let (Some(size), Some(kind)) = (word(at), word(at + 4)) else { break };
        let start = at + 8;
        let Some(end) = start.checked_add(size as usize).filter(|&e| e <= length) else {
            return Err(format!("GLB: chunk at byte {at} declares {size} bytes past the end of the file"));
        };
        match &kind.to_le_bytes() {
            b"JSON" if json.is_none() => json = Some(&bytes[start..end]),
            b"BIN\0" if bin.is_none() => bin = Some(bytes[start..end].to_vec()),
            _ => {}
        }
        at = end;
    }
    let json = json.ok_or_else(|| "GLB: no JSON chunk".to_owned())?;
    Ok((json, bin))
}

/// The validated document and the GLB's binary chunk.
///
/// The JSON is parsed and its mesh attribute indices checked before `gltf` validates it: its
/// validation indexes the accessor list with the `POSITION` index unchecked (a panic on a bad
/// index in gltf-json 1.4.1).
fn read_document(bytes: &[u8]) -> Result<(gltf::Document, Option<Vec<u8>>), String> {
    let (json, blob) = if bytes.starts_with(b"glTF") { split_glb(bytes)? } else { (bytes, None) };
    let root = gltf::json::Root::from_slice(json).map_err(|e| e.to_string())?;
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            for index in prim.attributes.values().chain(prim.indices.iter()) {
                if index.value() >= root.accessors.len() {
                    return Err(format!(
                        "meshes[{m}].primitives[{p}]: accessor {} does not exist (the file has {})",
                        index.value(),
                        root.accessors.len()
                    ));
                }
            }
        }
    }
    let document = gltf::Document::from_json(root).map_err(|e| match e {
        // The crate lists every problem; the first few make one readable line.
        gltf::Error::Validation(list) => {
            let shown: Vec<String> = list.iter().take(3).map(|(path, e)| format!("{path}: {e}")).collect();
            let more = if list.len() > 3 { format!(" (and {} more)", list.len() - 3) } else { String::new() };
            format!("invalid glTF: {}{more}", shown.join("; "))
        }
        other => other.to_string(),
    })?;
    Ok((document, blob))
}

/// Parses glTF or GLB bytes; external buffers and images are read from `base`.
///
/// # Errors
/// See [`crate::load_model`].
pub(crate) fn parse_gltf(
    bytes: &[u8],
    origin: &str,
    base: Option<&Path>,
    transform: &Transform,
) -> Result<Model, LoadError> {
    let err = |message: String| model_error(origin, None, message);
    let (document, blob) = read_document(bytes).map_err(|m| err(format!("glTF: {m}")))?;
    // The crate reads external buffers itself, unbounded: a FIFO or `/dev/zero` named as a
    // buffer would block or exhaust memory, so each is checked first.
    for buffer in document.buffers() {
        if let (gltf::buffer::Source::Uri(uri), Some(base)) = (buffer.source(), base)
            && !uri.starts_with("data:")
            && !uri.contains('%')
        {
            let path = base.join(uri);
            if let Ok(meta) = std::fs::metadata(&path) {
                if !meta.is_file() {
                    return Err(err(format!(
                        "glTF buffer {}: '{uri}' is not a regular file",
                        buffer.index()
                    )));
                }
                if meta.len() > crate::model::MAX_MODEL_BYTES {
                    return Err(err(format!(
                        "glTF buffer {}: '{uri}' is {} bytes, more than the {} read",
                        buffer.index(),
                        meta.len(),
                        crate::model::MAX_MODEL_BYTES
                    )));
                }
            }
        }
    }
    let buffers =
        gltf::import_buffers(&document, base, blob).map_err(|e| err(format!("glTF buffers: {e}")))?;
    let mut warnings = Vec::new();

    // Base colour textures are averaged when their pixels can be read; otherwise the factor
    // alone is used, with a warning.
    let needs_images =
        document.materials().any(|m| m.pbr_metallic_roughness().base_color_texture().is_some());
    let images = if needs_images {
        // The crate wants a folder even for embedded images; without one, only embedded
        // images (data URIs, buffer views) can be read, and any folder will do for those.
        let embedded = document.images().all(|i| match i.source() {
            gltf::image::Source::View { .. } => true,
            gltf::image::Source::Uri { uri, .. } => uri.starts_with("data:"),
        });
        let image_base = base.or_else(|| embedded.then_some(Path::new(".")));
        match gltf::import_images(&document, image_base, &buffers) {
            Ok(images) => images,
            Err(e) => {
                warnings.push(format!("{origin}: textures not read ({e}); base colour factors used alone"));
                Vec::new()
            }
        }
    } else {
        Vec::new()
    };

    let mut materials: Vec<Material> = Vec::new();
    // Each material's index in `materials` and, when it keeps a texture, where it lies.
    type Placed = (usize, Option<(u32, UvTransform)>);
    let mut material_of: HashMap<Option<usize>, Placed> = HashMap::new();
    let mut material_index = |m: gltf::Material, warnings: &mut Vec<String>| -> Result<Placed, LoadError> {
        if let Some(&i) = material_of.get(&m.index()) {
            return Ok(i);
        }
        let mut kept = None;
        let mut placed = None;
        let material = match m.index() {
            None => {
                warnings.push(format!(
                    "{origin}: primitives without a material are default grey ({DEFAULT_GREY}), not glTF's white (ρ = 1 never converges)"
                ));
                model_material(origin, None, "default", [DEFAULT_GREY; 3], [0.0; 3])?
            }
            Some(i) if m.unlit() => {
                // An unlit material (as `radiosity export` writes) shows a baked colour; it says
                // nothing about how the surface reflects.
                let name = m.name().map_or_else(|| format!("material{i}"), str::to_owned);
                warnings.push(format!(
                    "{origin}: material '{name}' is unlit (KHR_materials_unlit), not a reflectance; default grey ({DEFAULT_GREY}) used"
                ));
                model_material(origin, None, &name, [DEFAULT_GREY; 3], [0.0; 3])?
            }
            Some(i) => {
                let name = m.name().map_or_else(|| format!("material{i}"), str::to_owned);
                let pbr = m.pbr_metallic_roughness();
                let f = pbr.base_color_factor();
                let mut reflectance = [f[0] as f64, f[1] as f64, f[2] as f64];
                // An alpha mask: texels whose alpha × the factor's is at least the cutoff are
                // there; BLEND has no diffuse meaning and is cut at one half.
                let cutoff = match m.alpha_mode() {
                    gltf::material::AlphaMode::Opaque => None,
                    gltf::material::AlphaMode::Mask => Some(f64::from(m.alpha_cutoff().unwrap_or(0.5))),
                    gltf::material::AlphaMode::Blend => {
                        warnings.push(blend_warning(origin, &name));
                        Some(0.5)
                    }
                };
                let alpha = f64::from(f[3]);
                let base = pbr.base_color_texture();
                let image = base
                    .as_ref()
                    .and_then(|tex| images.get(tex.texture().source().index()).and_then(decoded));
                match (&base, image) {
                    (Some(tex), Some(image)) => {
                        let sampler = tex.texture().sampler();
                        let mask = cutoff.and_then(|c| image.mask(alpha, c, false));
                        let mean = mask.as_deref().map_or(image.mean, |m| image.masked_mean(m));
                        kept = Some(image.texture(
                            reflectance,
                            [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())],
                            mask,
                        ));
                        placed = Some(placement(tex));
                        reflectance = [0, 1, 2].map(|c| reflectance[c] * mean[c]);
                    }
                    (Some(_), None) if !images.is_empty() => warnings.push(format!(
                        "{origin}: material '{name}': base colour texture format not averaged; factor used alone"
                    )),
                    // The factor's alpha alone: the whole material is there or not.
                    _ if cutoff.is_some_and(|c| alpha < c) => {
                        kept = Some(DecodedImage::white(1, 1).texture(reflectance, [Wrap::Repeat; 2], Some(vec![false])));
                    }
                    _ => {}
                }
                let reflectance = clamp_reflectance(origin, &name, reflectance, warnings);
                // Metal reflects like a mirror, a transmissive material lets light through:
                // neither is a diffuse reflectance, but its base colour is the best guess.
                let metallic = pbr.metallic_factor();
                let transmission = m.transmission().map_or(0.0, |t| t.transmission_factor());
                if metallic > 0.5 {
                    warnings.push(specular_warning(origin, &name, &format!("metallicFactor {metallic}")));
                } else if transmission > 0.0 {
                    warnings.push(specular_warning(
                        origin,
                        &name,
                        &format!("KHR_materials_transmission {transmission}"),
                    ));
                }
                let strength = m.emissive_strength().unwrap_or(1.0) as f64;
                let emission = m.emissive_factor().map(|v| v as f64 * strength);
                let mut material =
                    Material::try_new(&name, Rgb::from_array(reflectance), Rgb::from_array(emission))
                        .map_err(|e| err(format!("material {i}: {e}")))?;
                material.texture = kept;
                material
            }
        };
        let mut names: Vec<String> = materials.iter().map(|m| m.name.clone()).collect();
        names.push(material.name.clone());
        unique_names(&mut names);
        let mut material = material;
        material.name = names.pop().unwrap_or_default();
        materials.push(material);
        material_of.insert(m.index(), (materials.len() - 1, placed));
        Ok((materials.len() - 1, placed))
    };

    let scene = document.default_scene().or_else(|| document.scenes().next());
    let roots: Vec<gltf::Node> = match &scene {
        Some(s) => s.nodes().collect(),
        // No scene: every node that is no one's child is a root.
        None => {
            let children: Vec<usize> =
                document.nodes().flat_map(|n| n.children().map(|c| c.index())).collect();
            document.nodes().filter(|n| !children.contains(&n.index())).collect()
        }
    };
    let world_from_file = transform.matrix();
    // A stack pops last first: roots (and children, below) go on reversed, so parts come in
    // file order.
    let mut stack: Vec<(gltf::Node, DMat4, usize)> =
        roots.into_iter().rev().map(|n| (n, world_from_file, 0)).collect();
    let mut parts = Vec::new();
    let mut camera = None;
    let mut dropped = 0usize;
    let mut skipped_modes = 0usize;
    let mut visits = 0usize;
    let mut by_material = Vec::new();
    while let Some((node, parent, depth)) = stack.pop() {
        // A cycle in a malformed file would loop forever; glTF trees are finite and shallow.
        visits += 1;
        if depth > 256 || visits > 1_000_000 {
            return Err(err(format!("node {}: the node hierarchy is cyclic or too deep", node.index())));
        }
        let local = node.transform().matrix().map(|c| c.map(|v| v as f64));
        let world = parent * DMat4::from_cols_array_2d(&local);
        if !world.is_finite() {
            return Err(err(format!("node {}: transform is not finite", node.index())));
        }
        for child in node.children().collect::<Vec<_>>().into_iter().rev() {
            stack.push((child, world, depth + 1));
        }
        if camera.is_none()
            && let Some(cam) = node.camera()
        {
            match cam.projection() {
                gltf::camera::Projection::Perspective(p) => {
                    let position = world.transform_point3(DVec3::ZERO);
                    let forward = world.transform_vector3(-DVec3::Z).normalize_or_zero();
                    let up = world.transform_vector3(DVec3::Y);
                    let fov = (p.yfov() as f64).to_degrees();
                    match Camera::try_new(position, position + forward, up, fov) {
                        Ok(c) => camera = Some(c),
                        Err(e) => {
                            warnings.push(format!("{origin}: camera of node {}: {e}; ignored", node.index()))
                        }
                    }
                }
                gltf::camera::Projection::Orthographic(_) => {
                    warnings.push(format!("{origin}: orthographic camera of node {} ignored", node.index()));
                }
            }
        }
        let Some(mesh) = node.mesh() else { continue };
        let node_name =
            node.name().or(mesh.name()).map_or_else(|| format!("node{}", node.index()), str::to_owned);
        let primitives: Vec<gltf::Primitive> = mesh.primitives().collect();
        for prim in &primitives {
            let what = format!("mesh {} ('{node_name}') primitive {}", mesh.index(), prim.index());
            if !matches!(prim.mode(), Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
                skipped_modes += 1;
                continue;
            }
            let Some(positions) = prim.get(&gltf::Semantic::Positions) else {
                return Err(err(format!("{what}: no POSITION attribute")));
            };
            check_accessor(&positions, Dimensions::Vec3, &[DataType::F32], &buffers)
                .map_err(|m| err(format!("{what}: POSITION {m}")))?;
            if let Some(ind) = prim.indices() {
                check_accessor(
                    &ind,
                    Dimensions::Scalar,
                    &[DataType::U8, DataType::U16, DataType::U32],
                    &buffers,
                )
                .map_err(|m| err(format!("{what}: indices {m}")))?;
            }
            let reader = prim.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
            let Some(points) = reader.read_positions() else {
                return Err(err(format!("{what}: POSITION cannot be read")));
            };
            let mut b = PartBuilder::new(world);
            let mut welded = Vec::new();
            for (k, p) in points.enumerate() {
                let v = b
                    .vertex(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64))
                    .map_err(|m| err(format!("{what}: vertex {k}: {m}")))?;
                welded.push(v);
            }
            let indices: Vec<u32> = match reader.read_indices() {
                Some(ind) => ind.into_u32().collect(),
                None => (0..welded.len() as u32).collect(),
            };
            let triangles: Vec<[u32; 3]> = match prim.mode() {
                Mode::TriangleStrip => strip_triangles(&indices),
                Mode::TriangleFan => fan_triangles(&indices),
                _ => {
                    if !indices.len().is_multiple_of(3) {
                        return Err(err(format!(
                            "{what}: {} indices is not a whole number of triangles",
                            indices.len()
                        )));
                    }
                    indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect()
                }
            };
            let (material, placed) = material_index(prim.material(), &mut warnings)?;
            let uvs =
                placed.and_then(|(set, transform)| triangle_uvs(prim, &buffers, set, &transform, &triangles));
            for (t, tri) in triangles.iter().enumerate() {
                let mut face = Vec::with_capacity(3);
                for &i in tri {
                    let Some(&v) = welded.get(i as usize) else {
                        return Err(err(format!(
                            "{what}: triangle {t}: vertex index {i} out of range (POSITION has {} vertices)",
                            welded.len()
                        )));
                    };
                    face.push(v);
                }
                let uv = uvs.as_ref().map(|uvs| uvs[t].to_vec());
                b.face_with_uvs(face, uv).map_err(|m| err(format!("{what}: triangle {t}: {m}")))?;
            }
            dropped += b.dropped;
            let sides =
                if prim.material().double_sided() { Sides::Two { emits_back: true } } else { Sides::One };
            // Several primitives of one node are told apart by material (named below, once
            // the material list is complete).
            let name = node_name.clone();
            if b.is_empty() {
                warnings.push(format!("{origin}: {what} has no triangle with an area; left out"));
                continue;
            }
            let mesh = b.build().map_err(|m| err(format!("{what}: {m}")))?;
            by_material.push(primitives.len() > 1);
            parts.push(ModelPart { name, material, mesh, sides });
        }
    }
    if skipped_modes > 0 {
        warnings.push(format!("{origin}: {skipped_modes} primitive(s) of points or lines left out"));
    }
    if dropped > 0 {
        warnings.push(format!("{origin}: {dropped} degenerate triangle(s) (zero area) dropped"));
    }
    if parts.is_empty() {
        return Err(err("no triangle with an area in the default scene".into()));
    }
    let mut names: Vec<String> = parts
        .iter()
        .zip(&by_material)
        .map(
            |(p, &by)| if by { format!("{}/{}", p.name, materials[p.material].name) } else { p.name.clone() },
        )
        .collect();
    unique_names(&mut names);
    for (p, n) in parts.iter_mut().zip(names) {
        p.name = n;
    }
    Ok(Model { parts, materials, camera, warnings })
}
