//! A model's colour texture and alpha mask: pictures show its texels, the solve its mean and mask.

/// How a texture coordinate outside [0, 1] comes back into the image (glTF's sampler modes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    /// The image tiles the plane.
    #[default]
    Repeat,
    /// The edge texels stretch outwards (MTL's `-clamp on`).
    ClampToEdge,
    /// The image tiles the plane, every other copy mirrored.
    MirroredRepeat,
}

/// Diffuse albedo per texel, addressed by (u, v) with v running down from the image's top row
/// (glTF's convention; OBJ's upward v is turned by its loader). Texels stay 8-bit sRGB, a
/// third of the memory of linear floats; the albedo is `factor` × the texel decoded.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// Texels per row, ≥ 1.
    pub width: u32,
    /// Rows, ≥ 1.
    pub height: u32,
    /// `width × height` sRGB-encoded colours, top row first.
    pub texels: Vec<[u8; 3]>,
    /// What the decoded texel is multiplied by, per channel: MTL's `Kd`, glTF's
    /// `baseColorFactor`.
    pub factor: [f64; 3],
    /// Wrap along u, then along v.
    pub wrap: [Wrap; 2],
    /// Per texel, whether the surface is there (an alpha mask after its cutoff: glTF's
    /// `alphaMode MASK`, MTL's `map_d`); `None`: everywhere. Light and rays pass elsewhere.
    pub mask: Option<Vec<bool>>,
}
