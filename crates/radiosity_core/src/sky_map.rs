//! An environment map as a sky: an equirectangular image of linear radiance (an HDRI), whose
//! rows run from the zenith (top) to the nadir and whose columns go once round the horizon.

use std::f64::consts::PI;

use glam::DVec3;

use crate::Rgb;

/// Linear radiance per texel of an equirectangular image, W/(unit² sr) before the sky's scale.
#[derive(Clone, Debug, PartialEq)]
pub struct SkyMap {
    width: u32,
    height: u32,
    texels: Vec<Rgb>,
}

impl SkyMap {
    /// A map of `width × height` texels, top row first; every texel finite and non-negative.
    ///
    /// # Errors
    /// Sizes that do not match, or a texel that is negative or not finite.
    pub fn try_new(width: u32, height: u32, texels: Vec<Rgb>) -> Result<Self, String> {
        if width < 2 || height < 2 || texels.len() != width as usize * height as usize {
            return Err(format!("a {width} × {height} map needs {} texels, at least 2 × 2", width * height));
        }
        if let Some(k) = texels.iter().position(|t| !t.to_array().iter().all(|c| c.is_finite() && *c >= 0.0))
        {
            return Err(format!(
                "texel {} of row {} is negative or not a number",
                k % width as usize,
                k / width as usize
            ));
        }
        Ok(Self { width, height, texels })
    }

    /// Radiance along unit `towards`, the map's top row towards unit `zenith` and its middle
    /// column towards unit `forward` (at right angles to `zenith`), its columns going round
    /// to the right as one faces `forward`: u = ½ + atan2(d·right, d·forward)/2π,
    /// v = acos(d·zenith)/π. Bilinear, wrapping round the horizon.
    pub fn radiance(&self, towards: DVec3, zenith: DVec3, forward: DVec3) -> Rgb {
        let right = forward.cross(zenith);
        let u = 0.5 + towards.dot(right).atan2(towards.dot(forward)) / (2.0 * PI);
        let v = towards.dot(zenith).clamp(-1.0, 1.0).acos() / PI;
        let (w, h) = (f64::from(self.width), f64::from(self.height));
        let (x, y) = (u * w - 0.5, (v * h - 0.5).clamp(0.0, h - 1.0));
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let texel = |i: f64, j: f64| {
            self.texels[j.min(h - 1.0) as usize * self.width as usize + i.rem_euclid(w) as usize]
        };
        texel(x0, y0) * ((1.0 - fx) * (1.0 - fy))
            + texel(x0 + 1.0, y0) * (fx * (1.0 - fy))
            + texel(x0, y0 + 1.0) * ((1.0 - fx) * fy)
            + texel(x0 + 1.0, y0 + 1.0) * (fx * fy)
    }

    /// Irradiance on an open horizontal plane facing the top row: Σ L ∫ cos θ sin θ dθ dφ
    /// over the upper half's texels, each integral exact over its band.
    pub fn horizontal_irradiance(&self) -> Rgb {
        let (w, h) = (self.width as usize, self.height as usize);
        let dphi = 2.0 * PI / w as f64;
        let mut sum = Rgb::ZERO;
        for j in 0..h {
            let (t0, t1) = (PI * j as f64 / h as f64, (PI * (j + 1) as f64 / h as f64).min(PI / 2.0));
            if t0 >= PI / 2.0 {
                break;
            }
            let weight = dphi * 0.5 * (t1.sin().powi(2) - t0.sin().powi(2));
            let row: Rgb = self.texels[j * w..(j + 1) * w].iter().copied().sum();
            sum += row * weight;
        }
        sum
    }
}
