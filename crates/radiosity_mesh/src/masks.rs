//! Alpha-masked faces (foliage, chains, fences: glTF `alphaMode MASK`, MTL `map_d`): where a
//! material's mask is clear there is no surface, so light and rays pass.
//!
//! Two consequences for the solve. Its visibility rays test a masked occluder triangle's
//! texel where they cross it ([`MaskedOccluder`], in the ray structure the solver builds).
//! And an element of a masked face covers holes as well as leaf: it receives over its whole
//! area but only the part that is there reflects, so its material's reflectance is scaled by
//! the opaque share of the object's faces ([`coverage`]). The element's radiosity is then the
//! mean over its area, holes counted as dark, which is what a path tracer's per-object mean
//! of the same faces gives; a picture divides it by the scaled reflectance and shows the
//! leaf's own irradiance on the opaque texels.

use std::sync::Arc;

use radiosity_core::{Texture, Wrap};

/// Texel `i` of a row or column of `n` texels after wrapping by `wrap` (glTF's modes).
pub fn wrapped(i: i64, n: u32, wrap: Wrap) -> usize {
    let n = i64::from(n.max(1));
    let i = match wrap {
        Wrap::Repeat => i.rem_euclid(n),
        Wrap::ClampToEdge => i.clamp(0, n - 1),
        Wrap::MirroredRepeat => {
            let m = i.rem_euclid(2 * n);
            if m < n { m } else { 2 * n - 1 - m }
        }
    };
    i as usize
}

/// Whether the surface of `texture`'s material is there at `uv`: the nearest texel of its
/// mask (a cut-off mask is not filtered); true without a mask or for a coordinate that is not
/// finite.
pub fn opaque_at(texture: &Texture, uv: [f64; 2]) -> bool {
    let Some(mask) = &texture.mask else { return true };
    if !(uv[0].is_finite() && uv[1].is_finite()) {
        return true;
    }
    // Clamped far out of range, where the i64 conversion would saturate anyway.
    let texel = |c: f64, n: u32| (c.clamp(-1e9, 1e9) * f64::from(n)).floor() as i64;
    let x = wrapped(texel(uv[0], texture.width), texture.width, texture.wrap[0]);
    let y = wrapped(texel(uv[1], texture.height), texture.height, texture.wrap[1]);
    mask.get(y * texture.width as usize + x).copied().unwrap_or(true)
}

/// The texture coordinates at barycentric weights `(u, v)` (of the second and third corners)
/// of a triangle whose corners have coordinates `uv`.
pub fn uv_at(uv: &[[f64; 2]; 3], u: f64, v: f64) -> [f64; 2] {
    let w = 1.0 - u - v;
    [0, 1].map(|k| uv[0][k] * w + uv[1][k] * u + uv[2][k] * v)
}

/// Fewest and most points [`coverage`] takes on a triangle.
const COVERAGE_POINTS: (usize, usize) = (256, 1 << 16);

/// The share of a triangle (corner coordinates `uv`) where `texture`'s mask is set: the mean
/// over points of Roberts' R2 sequence folded into the triangle, four per texel it covers
/// (within [`COVERAGE_POINTS`]). A regular lattice aliases with a regular mask: 16 rows on a
/// 64 × 64 checkerboard landed every point on its white squares.
pub fn coverage(texture: &Texture, uv: &[[f64; 2]; 3]) -> f64 {
    if texture.mask.is_none() {
        return 1.0;
    }
    let (e1, e2) = ([0, 1].map(|k| uv[1][k] - uv[0][k]), [0, 1].map(|k| uv[2][k] - uv[0][k]));
    let texels =
        0.5 * (e1[0] * e2[1] - e1[1] * e2[0]).abs() * f64::from(texture.width) * f64::from(texture.height);
    let n = if texels.is_finite() { (4.0 * texels) as usize } else { COVERAGE_POINTS.1 };
    let n = n.clamp(COVERAGE_POINTS.0, COVERAGE_POINTS.1);
    // R2: the plastic number's powers (Roberts 2018, "The unreasonable effectiveness of
    // quasirandom sequences").
    let g = 1.324_717_957_244_746;
    let (a1, a2) = (1.0 / g, 1.0 / (g * g));
    let there = (0..n)
        .filter(|&i| {
            let (mut u, mut v) = ((0.5 + a1 * i as f64).fract(), (0.5 + a2 * i as f64).fract());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            opaque_at(texture, uv_at(uv, u, v))
        })
        .count();
    there as f64 / n as f64
}

/// An occluder triangle ([`crate::Mesh::occluders`]) of an alpha-masked material: a ray that
/// crosses it where the mask is clear goes on.
#[derive(Clone, Debug)]
pub struct MaskedOccluder {
    /// Its index in [`crate::Mesh::occluders`].
    pub occluder: u32,
    /// Texture coordinates of its three corners.
    pub uv: [[f64; 2]; 3],
    /// The material's texture, which holds the mask.
    pub texture: Arc<Texture>,
}

impl MaskedOccluder {
    /// Whether a ray passes the triangle at barycentric weights `(u, v)` of its second and
    /// third corners.
    pub fn clear_at(&self, u: f64, v: f64) -> bool {
        !opaque_at(&self.texture, uv_at(&self.uv, u, v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A `w` × `h` white texture whose mask is `there(x, y)`.
    fn masked(w: u32, h: u32, there: impl Fn(u32, u32) -> bool) -> Texture {
        Texture {
            width: w,
            height: h,
            texels: vec![[255; 3]; (w * h) as usize],
            factor: [1.0; 3],
            wrap: [Wrap::Repeat; 2],
            mask: Some((0..h).flat_map(|y| (0..w).map(move |x| (x, y))).map(|(x, y)| there(x, y)).collect()),
        }
    }

    #[test]
    fn the_nearest_texel_decides_and_wraps() {
        let t = masked(2, 1, |x, _| x == 0);
        assert!(opaque_at(&t, [0.25, 0.5]));
        assert!(!opaque_at(&t, [0.75, 0.5]));
        assert!(opaque_at(&t, [1.25, 0.5]), "repeat");
        assert!(!opaque_at(&t, [-0.25, 0.5]), "repeat below zero");
        let solid = Texture { mask: None, ..t };
        assert!(opaque_at(&solid, [0.75, 0.5]));
    }

    #[test]
    fn coverage_is_the_share_of_the_triangle_that_is_there() {
        let t = masked(64, 64, |x, _| x < 32);
        let full = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        // Area of {x < 1/2} in the triangle x + y < 1: 1/2 − 1/8 = 3/8, of 1/2 in all.
        assert!((coverage(&t, &full) - 0.75).abs() < 0.03, "{}", coverage(&t, &full));
        // Regular masks, fine and coarse: a lattice of points would alias with them.
        for n in [8, 64, 256] {
            let checker = masked(n, n, |x, y| (x + y) % 2 == 0);
            let c = coverage(&checker, &full);
            assert!((c - 0.5).abs() < 0.02, "{n} × {n}: {c}");
        }
    }
}
