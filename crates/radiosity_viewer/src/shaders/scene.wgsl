// The lit mesh: a non-indexed triangle list, one colour per vertex of each triangle (vertex
// radiosity for smooth shading, the element's value for flat shading), tone mapped per pixel
// after interpolation, as the CPU renderer does. Needs tonemap.wgsl before it.
//
// Textured materials are drawn by vs_textured/fs_textured: the same, with the reflected part
// of the radiosity scaled by the texel's albedo over the material's mean reflectance (the
// rule `render` follows), one draw per material with its texture in group 1.

struct Uniforms {
    // Clip space from mesh-local space (world minus the mesh origin, so f32 keeps precision).
    clip_from_local: mat4x4<f32>,
    background: vec4<f32>,
    // Radiosity → exposed radiance: 2^EV / π.
    exposure_scale: f32,
    tone_op: u32,
    // 0: tone-mapped colour; 1: false colour of log10 luminance in [log_min, log_max].
    mode: u32,
    // Bit 0: element edges; bit 1: patch edges.
    wire: u32,
    log_min: f32,
    log_max: f32,
    // Half width of wireframe lines, pixels.
    wire_half_width: f32,
    // 1 when the target stores linear values (an sRGB format encodes on write).
    output_linear: u32,
};

@group(0) @binding(0) var<uniform> u: Uniforms;

struct VsIn {
    @builtin(vertex_index) index: u32,
    @location(0) position: vec3<f32>,
    // Per triangle edge i (opposite corner i): bit 2i element edge, bit 2i+1 patch edge.
    @location(1) edges: u32,
    @location(2) colour: vec3<f32>,
};

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) colour: vec3<f32>,
    @location(1) bary: vec3<f32>,
    @location(2) @interpolate(flat) edges: u32,
};

fn vertex(index: u32, position: vec3<f32>, edges: u32, colour: vec3<f32>) -> VsOut {
    var out: VsOut;
    out.clip = u.clip_from_local * vec4<f32>(position, 1.0);
    out.colour = colour;
    let corner = index % 3u;
    out.bary = vec3<f32>(f32(corner == 0u), f32(corner == 1u), f32(corner == 2u));
    out.edges = edges;
    return out;
}

@vertex
fn vs_main(in: VsIn) -> VsOut {
    return vertex(in.index, in.position, in.edges, in.colour);
}

// Coverage of the nearest edge of the kinds in `mask` (2 bits per edge), from the pixel's
// distance to it in pixels.
fn edge_coverage(bary: vec3<f32>, edges: u32, mask: u32, half_width: f32) -> f32 {
    let d = bary / max(fwidth(bary), vec3<f32>(1e-6));
    var nearest = 1e9;
    for (var i = 0u; i < 3u; i = i + 1u) {
        if ((edges >> (2u * i)) & mask) != 0u {
            nearest = min(nearest, d[i]);
        }
    }
    return 1.0 - smoothstep(half_width, half_width + 1.0, nearest);
}

// Display value → what the target stores.
fn output(display: vec3<f32>) -> vec4<f32> {
    if u.output_linear == 1u {
        let lo = display / 12.92;
        let hi = pow((display + vec3<f32>(0.055)) / 1.055, vec3<f32>(2.4));
        return vec4<f32>(select(hi, lo, display <= vec3<f32>(0.04045)), 1.0);
    }
    return vec4<f32>(display, 1.0);
}

// The background: one triangle over the whole viewport at the far plane (reversed z: 0),
// written whatever the depth buffer holds. This clears colour and depth inside a render pass
// that someone else began (egui's), where a load-op clear is not ours to choose.
@vertex
fn vs_background(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let x = f32((index << 1u) & 2u) * 2.0 - 1.0;
    let y = f32(index & 2u) * 2.0 - 1.0;
    return vec4<f32>(x, y, 0.0, 1.0);
}

@fragment
fn fs_background() -> @location(0) vec4<f32> {
    return output(u.background.rgb);
}

@fragment
fn fs_main(in: VsOut) -> @location(0) vec4<f32> {
    return shade(in.colour, in.bary, in.edges);
}

// What a pixel of radiosity `colour` shows, with the subdivision lines over it.
fn shade(colour: vec3<f32>, bary: vec3<f32>, edges: u32) -> vec4<f32> {
    var rgb: vec3<f32>;
    if u.mode == 1u {
        let l = luminance(colour);
        if l <= 0.0 {
            rgb = vec3<f32>(0.0);
        } else {
            rgb = false_colour((log(l) / log(10.0) - u.log_min) / max(u.log_max - u.log_min, 1e-6));
        }
    } else {
        rgb = tone_map(colour, u.exposure_scale, u.tone_op);
    }
    // Derivatives (fwidth) need uniform control flow: these branches test only uniforms.
    // Skipping them when the overlay is off saves a CPU rasteriser a good share of its work.
    if (u.wire & 1u) != 0u {
        let element_line = edge_coverage(bary, edges, 1u, u.wire_half_width);
        rgb = mix(rgb, vec3<f32>(0.05, 0.05, 0.05), element_line * 0.6);
    }
    if (u.wire & 2u) != 0u {
        let patch_line = edge_coverage(bary, edges, 2u, u.wire_half_width * 1.3);
        rgb = mix(rgb, vec3<f32>(1.0, 0.85, 0.2), patch_line * 0.85);
    }
    return output(rgb);
}

// A textured material (render/textured.rs).
struct Material {
    // Emitted radiosity E (w unused): shown as it is, not scaled by the texture.
    emission: vec4<f32>,
    // Per channel, the texture's factor over the mean reflectance; negative where the mean
    // is 0 (the ratio is then 1).
    factor_over_mean: vec4<f32>,
};

// sRGB texels, decoded to linear by the hardware before it filters.
@group(1) @binding(0) var albedo_texture: texture_2d<f32>;
@group(1) @binding(1) var albedo_sampler: sampler;
@group(1) @binding(2) var<uniform> material: Material;

struct TexturedIn {
    @builtin(vertex_index) index: u32,
    @location(0) position: vec3<f32>,
    @location(1) edges: u32,
    @location(2) colour: vec3<f32>,
    @location(3) uv: vec2<f32>,
};

struct TexturedOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) colour: vec3<f32>,
    @location(1) bary: vec3<f32>,
    @location(2) @interpolate(flat) edges: u32,
    @location(3) uv: vec2<f32>,
};

@vertex
fn vs_textured(in: TexturedIn) -> TexturedOut {
    let v = vertex(in.index, in.position, in.edges, in.colour);
    return TexturedOut(v.clip, v.colour, v.bary, v.edges, in.uv);
}

@fragment
fn fs_textured(in: TexturedOut) -> @location(0) vec4<f32> {
    // Sampled before any branch: mip selection takes derivatives, which need uniform control
    // flow.
    let texel = textureSample(albedo_texture, albedo_sampler, in.uv);
    // Alpha is an alpha mask's share that is there (1 without one): a clear texel shows
    // what lies behind it.
    if texel.a < 0.5 {
        discard;
    }
    let albedo = texel.rgb;
    let k = material.factor_over_mean.rgb;
    let ratio = select(albedo * k, vec3<f32>(1.0), k < vec3<f32>(0.0));
    let e = material.emission.rgb;
    return shade(e + (in.colour - e) * ratio, in.bary, in.edges);
}
