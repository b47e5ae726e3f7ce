//! Colour textures on the GPU. The solve spreads each material's mean reflectance ρ̄; a
//! textured surface shows its radiosity B with the reflected part scaled by the texel's
//! albedo over that mean, per channel, emission E as it is: E + (B − E)·ρ(uv)/ρ̄, the rule
//! `render` follows (`radiosity_image`'s textures), here evaluated per pixel by the shader.
//!
//! Each distinct texture (by `Arc` identity: materials sharing one share its upload) becomes
//! one `Rgba8UnormSrgb` texture with a full mip chain, so the hardware decodes sRGB before it
//! filters, as the CPU filters in linear light. The mip levels are box-filtered here, in
//! linear light too. Elements take their corners' texture coordinates from
//! [`radiosity_image::element_uvs`].

use std::ops::Range;
use std::sync::Arc;

use eframe::wgpu;
use radiosity_core::{Material, Texture, Wrap, srgb_decode, srgb_encode};
use radiosity_image::ElementUvs;
use radiosity_mesh::Mesh;

/// What the shader needs of a textured material (`Material` in `scene.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct MaterialUniforms {
    /// Emitted radiosity E, W/m² per channel (w unused).
    emission: [f32; 4],
    /// Per channel, the texture's factor over the mean reflectance, or −1 where the mean is
    /// 0 (nothing reflected there to scale: the ratio is 1). The shader multiplies the
    /// decoded texel by it.
    factor_over_mean: [f32; 4],
}

impl MaterialUniforms {
    fn new(material: &Material, texture: &Texture) -> Self {
        let mean = material.reflectance.to_array();
        let emission = material.emission.to_array();
        let k = |c: usize| if mean[c] > 0.0 { (texture.factor[c] / mean[c]) as f32 } else { -1.0 };
        Self {
            emission: [emission[0] as f32, emission[1] as f32, emission[2] as f32, 0.0],
            factor_over_mean: [k(0), k(1), k(2), 0.0],
        }
    }
}

/// The material's texture when it has one and the element has texture coordinates: what
/// decides whether a triangle is drawn textured.
pub(super) fn texture_of<'a>(mesh: &'a Mesh, uvs: &[Option<ElementUvs>], e: u32) -> Option<&'a Arc<Texture>> {
    uvs.get(e as usize)?.as_ref()?;
    mesh.element_material(e as usize).texture.as_ref()
}

/// The textures uploaded so far, kept across meshes: a restart or a new light scale re-meshes
/// the same scene, whose materials hold the same `Arc`s.
pub(super) struct TextureCache {
    /// Layout of a textured material's bind group (group 1 of the textured pipeline).
    layout: wgpu::BindGroupLayout,
    /// Each texture (held, so its address is not reused) and its view with every mip level.
    textures: Vec<(Arc<Texture>, wgpu::TextureView)>,
    /// One sampler per wrap mode pair (u, v) met so far.
    samplers: Vec<([Wrap; 2], wgpu::Sampler)>,
}

impl TextureCache {
    /// An empty cache.
    pub(super) fn new(device: &wgpu::Device) -> Self {
        Self { layout: bind_group_layout(device), textures: Vec::new(), samplers: Vec::new() }
    }

    /// Layout of a textured material's bind group.
    pub(super) fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// The view of `texture`, uploaded on first use.
    fn view(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        texture: &Arc<Texture>,
    ) -> wgpu::TextureView {
        if let Some((_, view)) = self.textures.iter().find(|(t, _)| Arc::ptr_eq(t, texture)) {
            return view.clone();
        }
        let view = upload(device, queue, texture);
        self.textures.push((texture.clone(), view.clone()));
        view
    }

    /// The sampler for `wrap`: trilinear, so a far wall's texture averages rather than
    /// shimmers. Not anisotropic: a CPU rasteriser's anisotropic filter blends neighbouring
    /// texels even where the texture is magnified, which the CPU picture does not.
    fn sampler(&mut self, device: &wgpu::Device, wrap: [Wrap; 2]) -> wgpu::Sampler {
        if let Some((_, s)) = self.samplers.iter().find(|(w, _)| *w == wrap) {
            return s.clone();
        }
        let mode = |w: Wrap| match w {
            Wrap::Repeat => wgpu::AddressMode::Repeat,
            Wrap::ClampToEdge => wgpu::AddressMode::ClampToEdge,
            Wrap::MirroredRepeat => wgpu::AddressMode::MirrorRepeat,
        };
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("radiosity texture sampler"),
            address_mode_u: mode(wrap[0]),
            address_mode_v: mode(wrap[1]),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        self.samplers.push((wrap, sampler.clone()));
        sampler
    }

    /// Forgets the textures no material of `mesh` uses any more.
    fn keep_only(&mut self, mesh: &Mesh) {
        self.textures.retain(|(t, _)| {
            mesh.materials.iter().any(|m| m.texture.as_ref().is_some_and(|u| Arc::ptr_eq(t, u)))
        });
    }
}

/// The textured triangles of a mesh on the GPU: they follow the untextured ones in the mesh's
/// buffers, grouped by material, one draw each.
pub(super) struct TexturedDraw {
    /// Index of the first textured triangle in the mesh's buffers.
    pub(super) first_triangle: u32,
    /// Texture coordinates of every corner of the textured triangles, in buffer order.
    pub(super) uvs: wgpu::Buffer,
    /// Per material: its triangles (counted from `first_triangle`) and what it samples.
    pub(super) batches: Vec<(Range<u32>, wgpu::BindGroup)>,
}

impl TexturedDraw {
    /// The draw of `triangles[first..]` (each `(element, corners)`, grouped by material),
    /// textures uploaded through `cache`; `None` when there are none.
    pub(super) fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        cache: &mut TextureCache,
        mesh: &Mesh,
        uvs: &[Option<ElementUvs>],
        triangles: &[(u32, [u32; 3])],
        first: usize,
    ) -> Option<Self> {
        cache.keep_only(mesh);
        let textured = &triangles[first..];
        if textured.is_empty() {
            return None;
        }
        let mut corner_uvs = Vec::with_capacity(textured.len() * 3);
        for &(e, tri) in textured {
            let element_uvs = uvs[e as usize].as_ref().expect("textured triangles have texture coordinates");
            let order = mesh.elements[e as usize].vertex_indices();
            for v in tri {
                let k = order.iter().position(|&w| w == v).expect("a triangle's corners are its element's");
                corner_uvs.push(element_uvs[k].map(|c| c as f32));
            }
        }
        use wgpu::util::DeviceExt;
        let uv_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("radiosity texture coordinates"),
            contents: bytemuck::cast_slice(&corner_uvs),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let mut batches = Vec::new();
        let mut start = 0;
        while start < textured.len() {
            let material = mesh.element_material(textured[start].0 as usize);
            let end = start
                + textured[start..]
                    .iter()
                    .take_while(|(e, _)| std::ptr::eq(mesh.element_material(*e as usize), material))
                    .count();
            let texture = material.texture.as_ref().expect("textured triangles have a texture");
            let uniforms = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("radiosity textured material"),
                contents: bytemuck::bytes_of(&MaterialUniforms::new(material, texture)),
                usage: wgpu::BufferUsages::UNIFORM,
            });
            let view = cache.view(device, queue, texture);
            let sampler = cache.sampler(device, texture.wrap);
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("radiosity textured material"),
                layout: &cache.layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&view) },
                    wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::Sampler(&sampler) },
                    wgpu::BindGroupEntry { binding: 2, resource: uniforms.as_entire_binding() },
                ],
            });
            batches.push((start as u32..end as u32, bind_group));
            start = end;
        }
        Some(Self { first_triangle: first as u32, uvs: uv_buffer, batches })
    }
}

/// The layout of a textured material's bind group: texture, sampler, [`MaterialUniforms`].
fn bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("radiosity textured material layout"),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: true },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 2,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
        ],
    })
}

/// One mip level: its size and its texels as the GPU takes them, sRGB-encoded RGBA.
struct Level {
    width: u32,
    height: u32,
    rgba: Vec<u8>,
}

/// The texture's mip chain down to 1 × 1, level 0 the file's own codes: each level a box
/// filter of the one above in linear light (an sRGB average would darken a fine pattern as it
/// recedes). Odd sizes round down, each texel averaging the whole run of texels it covers.
/// Only one level is held in linear light at a time, and level 0 never is: a 4096² texture
/// would take 200 MB as floats. Alpha is the mask (255 where the surface is, 0 where an alpha
/// mask is clear), averaged down the chain as the share that is there: the fragment shader
/// discards below one half.
fn mip_chain(texture: &Texture) -> Vec<Level> {
    let decode: Vec<f32> = (0..=255u8).map(|v| srgb_decode(f64::from(v) / 255.0) as f32).collect();
    let encode = |v: f32| (srgb_encode(f64::from(v)) * 255.0).round().clamp(0.0, 255.0) as u8;
    let there = |i: usize| texture.mask.as_ref().is_none_or(|m| m.get(i).copied().unwrap_or(true));
    let (mut w, mut h) = (texture.width.max(1), texture.height.max(1));
    let rgba = (texture.texels.iter().enumerate())
        .flat_map(|(i, t)| [t[0], t[1], t[2], if there(i) { 255 } else { 0 }])
        .collect();
    let mut levels = vec![Level { width: w, height: h, rgba }];
    let mut above: Option<Vec<[f32; 4]>> = None;
    while w > 1 || h > 1 {
        let (w2, h2) = ((w / 2).max(1), (h / 2).max(1));
        let texel = |x: u32, y: u32| {
            let i = (y * w + x) as usize;
            match &above {
                Some(linear) => linear[i],
                None => {
                    let [r, g, b] = texture.texels[i].map(|v| decode[v as usize]);
                    [r, g, b, if there(i) { 1.0 } else { 0.0 }]
                }
            }
        };
        let span = |i: u32, n: u32, from: u32| (i * from / n)..((i + 1) * from / n);
        let mut linear = Vec::with_capacity((w2 * h2) as usize);
        for y in 0..h2 {
            for x in 0..w2 {
                let mut sum = [0.0f32; 4];
                let mut count = 0.0f32;
                for sy in span(y, h2, h) {
                    for sx in span(x, w2, w) {
                        let t = texel(sx, sy);
                        for c in 0..4 {
                            sum[c] += t[c];
                        }
                        count += 1.0;
                    }
                }
                linear.push(sum.map(|s| s / count));
            }
        }
        let rgba = (linear.iter())
            .flat_map(|t| [encode(t[0]), encode(t[1]), encode(t[2]), (t[3] * 255.0).round() as u8])
            .collect();
        levels.push(Level { width: w2, height: h2, rgba });
        (w, h, above) = (w2, h2, Some(linear));
    }
    levels
}

/// Uploads `texture` with its mip chain; a texture larger than the device allows starts at
/// the first level that fits.
fn upload(device: &wgpu::Device, queue: &wgpu::Queue, texture: &Texture) -> wgpu::TextureView {
    let most = device.limits().max_texture_dimension_2d;
    let levels: Vec<Level> =
        mip_chain(texture).into_iter().skip_while(|l| l.width > most || l.height > most).collect();
    let (w, h) = (levels[0].width, levels[0].height);
    let gpu = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("radiosity albedo texture"),
        size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
        mip_level_count: levels.len() as u32,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8UnormSrgb,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    for (mip, level) in levels.iter().enumerate() {
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &gpu,
                mip_level: mip as u32,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            &level.rgba,
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * level.width),
                rows_per_image: Some(level.height),
            },
            wgpu::Extent3d { width: level.width, height: level.height, depth_or_array_layers: 1 },
        );
    }
    gpu.create_view(&Default::default())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texture(width: u32, height: u32, texels: Vec<[u8; 3]>) -> Texture {
        Texture { width, height, texels, factor: [1.0; 3], wrap: [Wrap::Repeat; 2], mask: None }
    }

    /// The 8-bit code of linear value `v`, as the chain encodes it.
    fn code(v: f64) -> u8 {
        (srgb_encode(v) * 255.0).round() as u8
    }

    /// A 4 × 2 black and white pattern: level 1 is 2 × 1, level 2 is 1 × 1, every level
    /// half white in linear light (code 188, not sRGB 50 % grey, 128, which is 21 % in linear
    /// light); level 0 is the texels as they are.
    #[test]
    fn mips_average_in_linear_light_down_to_one_texel() {
        let t = texture(4, 2, (0..8).map(|i| if i % 2 == 0 { [255; 3] } else { [0; 3] }).collect());
        let levels = mip_chain(&t);
        let sizes: Vec<(u32, u32)> = levels.iter().map(|l| (l.width, l.height)).collect();
        assert_eq!(sizes, [(4, 2), (2, 1), (1, 1)]);
        assert_eq!(&levels[0].rgba[..8], [255, 255, 255, 255, 0, 0, 0, 255]);
        for level in &levels[1..] {
            for texel in level.rgba.chunks(4) {
                assert_eq!(texel, [code(0.5), code(0.5), code(0.5), 255]);
            }
        }
    }

    /// An odd size: 3 × 1 → 1 × 1 averages all three texels, none dropped.
    #[test]
    fn odd_sizes_average_every_texel() {
        let t = texture(3, 1, vec![[255; 3], [0; 3], [0; 3]]);
        let levels = mip_chain(&t);
        assert_eq!(levels.len(), 2);
        assert_eq!(levels[1].rgba[0], code(1.0 / 3.0), "{:?}", levels[1].rgba);
    }

    /// The scale per channel is the factor over the mean, and −1 (ratio 1) where the mean is
    /// 0; emission goes through as it is.
    #[test]
    fn material_uniforms_carry_factor_over_mean() {
        let mut m = Material::try_new(
            "m",
            radiosity_core::Rgb::new(0.5, 0.0, 0.25),
            radiosity_core::Rgb::new(1.0, 2.0, 3.0),
        )
        .unwrap();
        let t = Texture { factor: [0.9, 0.9, 0.5], ..texture(1, 1, vec![[255; 3]]) };
        m.texture = Some(Arc::new(t.clone()));
        let u = MaterialUniforms::new(&m, &t);
        assert_eq!(u.emission, [1.0, 2.0, 3.0, 0.0]);
        assert!((u.factor_over_mean[0] - 1.8).abs() < 1e-6 && u.factor_over_mean[1] == -1.0);
        assert!((u.factor_over_mean[2] - 2.0).abs() < 1e-6);
    }
}
