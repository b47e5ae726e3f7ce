//! GPU drawing of the lit mesh with wgpu into whatever it is given: a render pass someone else
//! began (the window's, through an egui paint callback), or a [`RenderTarget`] of its own (a
//! screenshot of the view, a headless test). Both go through [`SceneRenderer::paint`].
//!
//! Drawing straight into the window's pass, rather than into a texture that egui then copies,
//! saves a full-screen textured pass per frame: on a CPU rasteriser (lavapipe, llvmpipe) that
//! copy cost as much as drawing the scene.
//!
//! The mesh is drawn as a non-indexed triangle list so every triangle corner can carry its
//! own colour: the vertex radiosity for smooth shading (the same values and the same
//! barycentric interpolation as the CPU renderer) or its element's value for flat shading.
//! Colours stay linear to the fragment shader, which tone maps them (`tonemap.wgsl`).
//!
//! A big mesh also gets a coarse copy ([`crate::coarse`]) with its own buffers; the viewer
//! draws it while the camera moves or the solve runs on a CPU rasteriser, and only its
//! colours are uploaded at each snapshot meanwhile.
//!
//! Textured elements (see [`SceneRenderer::set_textured_mesh`] and `render/textured.rs`) come
//! last in the buffers, grouped by material: the untextured ones are one draw with the plain
//! pipeline, as without textures, and each textured material one draw with the textured
//! pipeline, which scales the interpolated radiosity by the texel's albedo over the mean.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use eframe::wgpu;
use glam::{DMat4, DVec3};
use radiosity_core::Rgb;
use radiosity_image::{ElementUvs, ToneOperator};
use radiosity_mesh::Mesh;
use radiosity_solver::Solution;

use crate::coarse::{COARSE_TRIANGLES, CoarseTriangle};
use textured::{TextureCache, TexturedDraw};

/// WGSL source of the tone-map functions (shared with the CPU/GPU agreement test).
pub const TONEMAP_WGSL: &str = include_str!("shaders/tonemap.wgsl");
/// WGSL source of the mesh shader, to be appended to [`TONEMAP_WGSL`].
pub const SCENE_WGSL: &str = include_str!("shaders/scene.wgsl");

/// Colour format of headless render targets. The shader writes sRGB-encoded values itself,
/// exactly like the CPU path (on an sRGB format it writes linear values instead).
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// Depth format: 32-bit float for reversed z (see [`crate::camera`]).
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Everything a frame needs besides the mesh and its colours.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameParams {
    /// World → clip transform (reversed z), double precision; see [`crate::FlyCamera`].
    pub clip_from_world: DMat4,
    /// Exposure in stops: radiance is multiplied by 2^EV before the operator.
    pub exposure_ev: f64,
    /// Tone-map operator.
    pub operator: ToneOperator,
    /// What the surfaces show.
    pub mode: DisplayMode,
    /// Subdivision lines.
    pub wireframe: Wireframe,
    /// False colour range, log10 of luminance, `(min, max)`.
    pub log_range: (f64, f64),
    /// Clear colour, display (sRGB-encoded) values.
    pub background: [f32; 4],
    /// Whether textured materials show their textures (in the tone-mapped modes; false
    /// colour always shows the radiosity itself). Off: every surface its mean colour.
    pub textures: bool,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Uniforms {
    clip_from_local: [[f32; 4]; 4],
    background: [f32; 4],
    exposure_scale: f32,
    tone_op: u32,
    mode: u32,
    wire: u32,
    log_min: f32,
    log_max: f32,
    wire_half_width: f32,
    output_linear: u32,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct StaticVertex {
    position: [f32; 3],
    edges: u32,
}

/// Colour and depth textures to draw into, with a multisampled colour buffer that resolves
/// into the single-sampled one when more than one sample is asked for.
pub struct RenderTarget {
    size: [u32; 2],
    format: wgpu::TextureFormat,
    samples: u32,
    colour: wgpu::Texture,
    colour_view: wgpu::TextureView,
    msaa_view: Option<wgpu::TextureView>,
    depth_view: wgpu::TextureView,
}

impl RenderTarget {
    /// Textures of `size` pixels (each at least 1) in `format` (8-bit RGBA or BGRA, plain or
    /// sRGB) with `samples` samples per pixel (1 or 4).
    pub fn new(device: &wgpu::Device, size: [u32; 2], format: wgpu::TextureFormat, samples: u32) -> Self {
        let size = [size[0].max(1), size[1].max(1)];
        let extent = wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 };
        let texture = |label, format, samples, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: extent,
                mip_level_count: 1,
                sample_count: samples,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let colour = texture(
            "radiosity view colour",
            format,
            1,
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
        );
        let msaa_view = (samples > 1).then(|| {
            texture("radiosity view msaa", format, samples, wgpu::TextureUsages::RENDER_ATTACHMENT)
                .create_view(&Default::default())
        });
        let depth =
            texture("radiosity view depth", DEPTH_FORMAT, samples, wgpu::TextureUsages::RENDER_ATTACHMENT);
        Self {
            size,
            format,
            samples,
            colour_view: colour.create_view(&Default::default()),
            colour,
            msaa_view,
            depth_view: depth.create_view(&Default::default()),
        }
    }

    /// Size in pixels.
    pub fn size(&self) -> [u32; 2] {
        self.size
    }

    /// Samples per pixel.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// The resolved colour texture.
    pub fn colour_view(&self) -> &wgpu::TextureView {
        &self.colour_view
    }

    /// Copies the colour texture back to the CPU as RGBA with sRGB-encoded values; waits for
    /// the GPU.
    ///
    /// # Errors
    /// When the device is lost or the buffer cannot be mapped.
    pub fn read_rgba8(&self, device: &wgpu::Device, queue: &wgpu::Queue) -> anyhow::Result<image::RgbaImage> {
        let [w, h] = self.size;
        // Rows of a texture-to-buffer copy are padded to 256 bytes.
        let row = (w * 4).div_ceil(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT) * wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("radiosity view readback"),
            size: u64::from(row) * u64::from(h),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_texture_to_buffer(
            self.colour.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: Some(h),
                },
            },
            wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
        );
        queue.submit([encoder.finish()]);
        let slice = buffer.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        device.poll(wgpu::PollType::wait_indefinitely())?;
        rx.recv()??;
        let data =
            slice.get_mapped_range().map_err(|e| anyhow::anyhow!("cannot read the picture back: {e:?}"))?;
        let bgra =
            matches!(self.format, wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb);
        let mut pixels = Vec::with_capacity((w * h * 4) as usize);
        for y in 0..h as usize {
            let start = y * row as usize;
            for px in data[start..start + (w * 4) as usize].chunks_exact(4) {
                if bgra {
                    pixels.extend_from_slice(&[px[2], px[1], px[0], px[3]]);
                } else {
                    pixels.extend_from_slice(px);
                }
            }
        }
        drop(data);
        buffer.unmap();
        image::RgbaImage::from_raw(w, h, pixels).ok_or_else(|| anyhow::anyhow!("readback has the wrong size"))
    }
}

/// A GPU device without a window, for offscreen pictures and tests. Any adapter will do,
/// a CPU one (lavapipe, llvmpipe) included; `WGPU_BACKEND` and friends are honoured.
///
/// # Errors
/// When no adapter or device can be had; the message names the drivers to install.
pub fn headless_gpu() -> anyhow::Result<(wgpu::Device, wgpu::Queue, wgpu::AdapterInfo)> {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))
        .or_else(|_| {
            pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
                force_fallback_adapter: true,
                ..Default::default()
            }))
        })
        .map_err(|e| {
            anyhow::anyhow!(
                "no GPU adapter: {e}; install a Vulkan or GL driver (./setup.sh installs Mesa's lavapipe and llvmpipe)"
            )
        })?;
    let info = adapter.get_info();
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("radiosity headless"),
        required_limits: wgpu::Limits::downlevel_defaults().using_resolution(adapter.limits()),
        ..Default::default()
    }))
    .map_err(|e| anyhow::anyhow!("cannot open {} ({:?}): {e}", info.name, info.backend))?;
    Ok((device, queue, info))
}

/// The mesh on the GPU.
struct Geometry {
    mesh: Arc<Mesh>,
    /// `(element, [v0, v1, v2])` of every drawn triangle, in buffer order.
    triangles: Vec<(u32, [u32; 3])>,
    /// Mesh-local origin: positions are stored relative to it.
    origin: DVec3,
    vertices: wgpu::Buffer,
    colours: wgpu::Buffer,
    /// Scratch for the colour upload, kept to avoid reallocating at every snapshot.
    scratch: Vec<[f32; 3]>,
    /// A coarser copy for big meshes ([`crate::coarse`]).
    coarse: Option<CoarseGeometry>,
    /// Whether `colours` lags the last solution (only the coarse copy's were uploaded).
    full_stale: bool,
    /// Whether texture coordinates came with the mesh (they may still texture nothing).
    uvs_given: bool,
    /// The textured triangles, the last in the buffers; `None` when there are none.
    textured: Option<TexturedDraw>,
}

/// The coarse copy of a big mesh on the GPU. It is drawn untextured, each surface in its mean
/// colour: its triangles merge elements, so no element's texture coordinates fit them, and it
/// is shown only while the view moves.
struct CoarseGeometry {
    triangles: Vec<CoarseTriangle>,
    vertices: wgpu::Buffer,
    colours: wgpu::Buffer,
}

/// Draws a [`Mesh`] lit by a [`Solution`].
pub struct SceneRenderer {
    mesh_pipeline: wgpu::RenderPipeline,
    /// The mesh pipeline with texture coordinates and a textured material (group 1).
    textured_pipeline: wgpu::RenderPipeline,
    background_pipeline: wgpu::RenderPipeline,
    /// Textures and samplers uploaded so far, and the layout of a material's bind group.
    texture_cache: TextureCache,
    /// Whether the frame last prepared shows textures. [`Self::prepare`] and [`Self::paint`]
    /// both borrow the renderer shared (egui's paint callback hands it out so), and what is
    /// painted is the frame that was prepared.
    textures_shown: AtomicBool,
    uniforms: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    format: wgpu::TextureFormat,
    samples: u32,
    geometry: Option<Geometry>,
    /// Whether [`Self::paint`] draws the coarse copy (when there is one).
    coarse: bool,
    /// Most triangles of the coarse copy; meshes over twice as many get one.
    coarse_budget: usize,
}

impl SceneRenderer {
    /// Pipelines for colour targets in `format` (8-bit, plain or sRGB) with a
    /// [`DEPTH_FORMAT`] depth buffer and `samples` samples per pixel.
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat, samples: u32) -> Self {
        let samples = samples.max(1);
        let source = format!("{TONEMAP_WGSL}\n{SCENE_WGSL}");
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("radiosity scene shader"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("radiosity scene uniforms"),
            size: std::mem::size_of::<Uniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("radiosity scene bind group layout"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("radiosity scene bind group"),
            layout: &layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: uniforms.as_entire_binding() }],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("radiosity scene pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let texture_cache = TextureCache::new(device);
        let textured_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("radiosity textured pipeline layout"),
            bind_group_layouts: &[Some(&layout), Some(texture_cache.layout())],
            immediate_size: 0,
        });
        let pipeline = |label,
                        layout: &wgpu::PipelineLayout,
                        vs,
                        fs,
                        buffers: &[Option<wgpu::VertexBufferLayout<'_>>],
                        cull,
                        compare| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(vs),
                    compilation_options: Default::default(),
                    buffers,
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleList,
                    front_face: wgpu::FrontFace::Ccw,
                    cull_mode: cull,
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(compare),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: wgpu::MultisampleState { count: samples, ..Default::default() },
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(fs),
                    compilation_options: Default::default(),
                    targets: &[Some(format.into())],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let static_vertices = wgpu::VertexBufferLayout {
            array_stride: std::mem::size_of::<StaticVertex>() as u64,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Uint32],
        };
        let colours = wgpu::VertexBufferLayout {
            array_stride: 12,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![2 => Float32x3],
        };
        let uvs = wgpu::VertexBufferLayout {
            array_stride: 8,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![3 => Float32x2],
        };
        let mesh_pipeline = pipeline(
            "radiosity mesh pipeline",
            &pipeline_layout,
            "vs_main",
            "fs_main",
            &[Some(static_vertices.clone()), Some(colours.clone())],
            // Surfaces are one-sided (lit from the side their normal points to): from outside a
            // room you see into it, like a doll's house.
            Some(wgpu::Face::Back),
            // Reversed z: nearer is greater.
            wgpu::CompareFunction::Greater,
        );
        let textured_pipeline = pipeline(
            "radiosity textured pipeline",
            &textured_layout,
            "vs_textured",
            "fs_textured",
            &[Some(static_vertices), Some(colours), Some(uvs)],
            Some(wgpu::Face::Back),
            wgpu::CompareFunction::Greater,
        );
        let background_pipeline = pipeline(
            "radiosity background pipeline",
            &pipeline_layout,
            "vs_background",
            "fs_background",
            &[],
            None,
            wgpu::CompareFunction::Always,
        );
        Self {
            mesh_pipeline,
            textured_pipeline,
            background_pipeline,
            texture_cache,
            textures_shown: AtomicBool::new(false),
            uniforms,
            bind_group,
            format,
            samples,
            geometry: None,
            coarse: false,
            coarse_budget: COARSE_TRIANGLES,
        }
    }

    /// The colour format the pipelines were made for.
    pub fn format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// Samples per pixel the pipeline was made for.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// The mesh being drawn.
    pub fn mesh(&self) -> Option<&Arc<Mesh>> {
        self.geometry.as_ref().map(|g| &g.mesh)
    }

    /// Uploads `mesh` (if it is not the one already uploaded) to be drawn untextured; colours
    /// start black.
    pub fn set_mesh(&mut self, device: &wgpu::Device, mesh: &Arc<Mesh>) {
        self.upload_mesh(device, None, mesh, &[]);
    }

    /// Uploads `mesh` (if it is not the one already uploaded with texture coordinates) with
    /// the texture coordinates of its elements' corners, `uvs` ([`radiosity_image::element_uvs`]
    /// of the scene it was built from): elements that have them and whose material has a
    /// texture show it (see [`FrameParams::textures`]). Each distinct texture is uploaded once,
    /// with its mip chain, and kept for the next mesh of the same scene. Colours start black.
    pub fn set_textured_mesh(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        mesh: &Arc<Mesh>,
        uvs: &[Option<ElementUvs>],
    ) {
        self.upload_mesh(device, Some(queue), mesh, uvs);
    }

    /// Whether the uploaded mesh has textured elements.
    pub fn has_textures(&self) -> bool {
        self.geometry.as_ref().is_some_and(|g| g.textured.is_some())
    }

    fn upload_mesh(
        &mut self,
        device: &wgpu::Device,
        queue: Option<&wgpu::Queue>,
        mesh: &Arc<Mesh>,
        uvs: &[Option<ElementUvs>],
    ) {
        let uvs = if queue.is_some() { uvs } else { &[] };
        if self.geometry.as_ref().is_some_and(|g| Arc::ptr_eq(&g.mesh, mesh) && g.uvs_given != uvs.is_empty())
        {
            return;
        }
        let (lo, hi) = mesh.bounds();
        let origin = if lo.is_finite() && hi.is_finite() { (lo + hi) * 0.5 } else { DVec3::ZERO };
        let mut triangles = oriented_triangles(mesh);
        // Untextured first, in mesh order (an untextured mesh keeps its order exactly), then
        // the textured ones by material, so each material is one draw.
        let material = |e: u32| {
            textured::texture_of(mesh, uvs, e).map(|_| {
                let patch = &mesh.patches[mesh.elements[e as usize].patch as usize];
                mesh.surfaces[patch.surface as usize].material
            })
        };
        triangles.sort_by_key(|&(e, _)| material(e));
        let first_textured = triangles.partition_point(|&(e, _)| material(e).is_none());
        let edges = edge_flags(mesh, &triangles);
        let vertex = |v: u32, edges: u32| StaticVertex {
            position: (mesh.positions[v as usize] - origin).as_vec3().to_array(),
            edges,
        };
        let mut vertices = Vec::with_capacity(triangles.len() * 3);
        for ((_, tri), flags) in triangles.iter().zip(&edges) {
            vertices.extend(tri.iter().map(|&v| vertex(v, *flags)));
        }
        let coarse = (triangles.len() > 2 * self.coarse_budget)
            .then(|| crate::coarse::coarse_mesh(mesh, &triangles, self.coarse_budget))
            .flatten()
            .map(|coarse| {
                // No subdivision lines on the coarse copy: its edges are no element's.
                let at = |i: u32| StaticVertex {
                    position: (coarse.positions[i as usize] - origin).as_vec3().to_array(),
                    edges: 0,
                };
                let vertices: Vec<StaticVertex> =
                    coarse.triangles.iter().flat_map(|t| t.corners.map(at)).collect();
                CoarseGeometry {
                    vertices: vertex_buffer(device, "radiosity coarse vertices", &vertices),
                    colours: colour_buffer(device, "radiosity coarse colours", vertices.len()),
                    triangles: coarse.triangles,
                }
            });
        let textured = queue.and_then(|queue| {
            TexturedDraw::new(device, queue, &mut self.texture_cache, mesh, uvs, &triangles, first_textured)
        });
        self.geometry = Some(Geometry {
            mesh: mesh.clone(),
            triangles,
            origin,
            colours: colour_buffer(device, "radiosity mesh colours", vertices.len()),
            vertices: vertex_buffer(device, "radiosity mesh vertices", &vertices),
            scratch: Vec::new(),
            coarse,
            full_stale: false,
            uvs_given: !uvs.is_empty(),
            textured,
        });
    }

    /// Sets the most triangles of the coarse copy made for the next mesh uploaded (default
    /// [`COARSE_TRIANGLES`]); meshes with more than twice as many get one.
    pub fn set_coarse_budget(&mut self, triangles: usize) {
        self.coarse_budget = triangles.max(1);
    }

    /// Triangles drawn per frame at full detail and, when there is one, by the coarse copy.
    pub fn triangle_counts(&self) -> (usize, Option<usize>) {
        self.geometry
            .as_ref()
            .map_or((0, None), |g| (g.triangles.len(), g.coarse.as_ref().map(|c| c.triangles.len())))
    }

    /// Chooses what [`Self::paint`] draws: the coarse copy (when the mesh has one) or every
    /// element. Drawing every element after the coarse copy was shown needs the colours of
    /// the shown solution uploaded again: see [`Self::full_colours_stale`].
    pub fn set_coarse(&mut self, coarse: bool) {
        self.coarse = coarse;
    }

    /// Whether the full mesh's colours lag the last solution given (only the coarse copy's
    /// were uploaded while it was drawn).
    pub fn full_colours_stale(&self) -> bool {
        self.geometry.as_ref().is_some_and(|g| g.full_stale)
    }

    /// Uploads the colours `mode` shows from `solution` (which must belong to the uploaded
    /// mesh; a mismatched one is ignored).
    pub fn set_solution(&mut self, queue: &wgpu::Queue, solution: &Solution, mode: DisplayMode) {
        let Some(g) = self.geometry.as_mut() else { return };
        let (n_vertices, n_elements) = (g.mesh.positions.len(), g.mesh.elements.len());
        if solution.vertex_radiosity.len() != n_vertices
            || solution.element_radiosity.len() != n_elements
            || solution.element_unshot.len() != n_elements
        {
            return;
        }
        let f = |c: Rgb| [c.r as f32, c.g as f32, c.b as f32];
        let corner = |e: u32, v: u32| match mode {
            DisplayMode::Smooth | DisplayMode::FalseColour => f(solution.vertex_radiosity[v as usize]),
            DisplayMode::FlatElements => f(solution.element_radiosity[e as usize]),
            DisplayMode::Unshot => f(solution.element_unshot[e as usize].abs()),
            DisplayMode::Illuminance => {
                f(irradiance_of(&g.mesh, e as usize, solution.vertex_radiosity[v as usize]))
            }
        };
        g.scratch.clear();
        if let Some(c) = &g.coarse {
            for t in &c.triangles {
                g.scratch.extend(t.colours.map(|v| corner(t.element, v)));
            }
            queue.write_buffer(&c.colours, 0, bytemuck::cast_slice(&g.scratch));
            // While the coarse copy is drawn, the full mesh's colours (six times as many
            // corners or more) wait until it is drawn again.
            if self.coarse {
                g.full_stale = true;
                return;
            }
            g.scratch.clear();
        }
        for &(e, tri) in &g.triangles {
            g.scratch.extend(tri.map(|v| corner(e, v)));
        }
        queue.write_buffer(&g.colours, 0, bytemuck::cast_slice(&g.scratch));
        g.full_stale = false;
    }

    /// Writes the frame's settings for the next [`Self::paint`]; `width_px` is the width of
    /// the viewport in pixels (it sets the wireframe line width).
    pub fn prepare(&self, queue: &wgpu::Queue, frame: &FrameParams, width_px: u32) {
        let origin = self.geometry.as_ref().map_or(DVec3::ZERO, |g| g.origin);
        let clip_from_local = frame.clip_from_world * DMat4::from_translation(origin);
        let uniforms = Uniforms {
            clip_from_local: clip_from_local.as_mat4().to_cols_array_2d(),
            background: frame.background,
            exposure_scale: (2f64.powf(frame.exposure_ev) / std::f64::consts::PI) as f32,
            tone_op: shader_operator(frame.operator),
            mode: u32::from(frame.mode.is_false_colour()),
            wire: frame.wireframe.shader_bits(),
            log_min: frame.log_range.0 as f32,
            log_max: frame.log_range.1 as f32,
            // Thin lines on small views, a little wider on big ones.
            wire_half_width: (width_px as f32 / 2400.0).clamp(0.25, 0.8),
            output_linear: u32::from(self.format.is_srgb()),
        };
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&uniforms));
        self.textures_shown.store(frame.textures && !frame.mode.is_false_colour(), Ordering::Relaxed);
    }

    /// Records the frame into `pass`, within the pass's current viewport: first the background
    /// (which also resets depth there), then the mesh. The pass must target this renderer's
    /// format and sample count with a [`DEPTH_FORMAT`] depth buffer.
    pub fn paint(&self, pass: &mut wgpu::RenderPass<'_>) {
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.set_pipeline(&self.background_pipeline);
        pass.draw(0..3, 0..1);
        let Some(g) = &self.geometry else { return };
        let (vertices, colours, triangles) = match &g.coarse {
            Some(c) if self.coarse => (&c.vertices, &c.colours, c.triangles.len()),
            _ => (&g.vertices, &g.colours, g.triangles.len()),
        };
        let textured = g
            .textured
            .as_ref()
            .filter(|_| !(self.coarse && g.coarse.is_some()) && self.textures_shown.load(Ordering::Relaxed));
        let plain = textured.map_or(triangles, |t| t.first_triangle as usize);
        if plain > 0 {
            pass.set_pipeline(&self.mesh_pipeline);
            pass.set_vertex_buffer(0, vertices.slice(..));
            pass.set_vertex_buffer(1, colours.slice(..));
            pass.draw(0..(plain * 3) as u32, 0..1);
        }
        if let Some(t) = textured {
            // The textured triangles' vertices, counted from the first: the texture
            // coordinates cover only them.
            let corner = u64::from(t.first_triangle) * 3;
            pass.set_pipeline(&self.textured_pipeline);
            pass.set_vertex_buffer(0, vertices.slice(corner * std::mem::size_of::<StaticVertex>() as u64..));
            pass.set_vertex_buffer(1, colours.slice(corner * 12..));
            pass.set_vertex_buffer(2, t.uvs.slice(..));
            for (range, bind_group) in &t.batches {
                pass.set_bind_group(1, bind_group, &[]);
                pass.draw(range.start * 3..range.end * 3, 0..1);
            }
        }
    }

    /// Draws a whole frame into `target` and submits it.
    pub fn draw(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        target: &RenderTarget,
        frame: &FrameParams,
    ) {
        debug_assert_eq!(
            (target.format, target.samples),
            (self.format, self.samples),
            "target and pipelines differ"
        );
        self.prepare(queue, frame, target.size[0]);
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("radiosity view") });
        {
            let (view, resolve_target) = match &target.msaa_view {
                Some(msaa) => (msaa, Some(&target.colour_view)),
                None => (&target.colour_view, None),
            };
            // Load-op clears are not needed (paint clears its viewport) but are cheap and make
            // the target's content defined outside the viewport too.
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("radiosity view pass"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &target.depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            self.paint(&mut pass);
        }
        queue.submit([encoder.finish()]);
    }
}

/// A vertex buffer holding `vertices`.
fn vertex_buffer(device: &wgpu::Device, label: &str, vertices: &[StaticVertex]) -> wgpu::Buffer {
    use wgpu::util::DeviceExt;
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytemuck::cast_slice(vertices),
        usage: wgpu::BufferUsages::VERTEX,
    })
}

/// A colour buffer for `corners` triangle corners (RGB f32), written at each snapshot.
fn colour_buffer(device: &wgpu::Device, label: &str, corners: usize) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: (corners.max(1) * 12) as u64,
        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

mod display;
mod exposure;
mod textured;
mod triangles;

pub use display::{
    Detail, DisplayMode, Wireframe, false_colour, false_colour_range, irradiance_of, shader_operator,
};
pub use exposure::{AUTO_EXPOSURE_SAMPLES, auto_exposure_ev};
pub use triangles::{edge_flags, oriented_triangles};

#[cfg(test)]
mod tests;
