//! A rendered picture in false colour by illuminance: each pixel coloured by the lux falling
//! on the surface it sees, in the bands of a [`LuxScale`], iso-lux lines between the bands,
//! with the legend beside it.
//!
//! A diffuse surface of reflectance ρ and emission Lₑ under irradiance E sends radiance
//! L = (Lₑ + ρ E) / π towards the eye, so the picture's own radiance gives back
//! E = (π L − Lₑ) / ρ per channel, its Rec. 709 Y in lux. A surface with a black channel
//! (ρ = 0 there) keeps nothing of its light to read back: its pixels are grey, as is the
//! background.

use radiosity_core::Rgb;

use crate::canvas::{BLACK, Canvas, WHITE};
use crate::font::text_height;
use crate::lux_scale::{LuxScale, format_lux};
use crate::{Rendering, SrgbImage};

/// The colour of the iso-lux lines between bands.
const ISO_LINE: [u8; 3] = [40, 40, 40];

/// The colour of a pixel whose illuminance is unknown.
pub const NO_DATA: [u8; 3] = [96, 96, 96];

/// What the picture needs of a surface: its reflectance and its emission (radiosity it
/// emits, W/unit², as the solver's materials hold it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceLight {
    /// Reflectance per channel.
    pub reflectance: Rgb,
    /// Emitted radiosity per channel.
    pub emission: Rgb,
}

/// The illuminance (lx) on the surface seen through each pixel of `rendering`: `surfaces`
/// per object index of the rendering ([`Rendering::object_ids`]), `None` for an object whose
/// light cannot be read back; `to_lux` turns W/unit² into lx.
pub fn pixel_illuminance(
    rendering: &Rendering,
    surfaces: &[Option<SurfaceLight>],
    to_lux: f64,
) -> Vec<Option<f64>> {
    rendering
        .radiance
        .pixels()
        .iter()
        .zip(&rendering.object_ids)
        .map(|(l, id)| {
            let s = (*id).and_then(|o| surfaces.get(o as usize).copied().flatten())?;
            if s.reflectance.min_channel() <= 0.0 {
                return None;
            }
            let e = (*l * std::f64::consts::PI - s.emission).zip_map(s.reflectance, |x, r| x / r);
            Some((e.luminance() * to_lux).max(0.0))
        })
        .collect()
}

/// The `q`-quantile (0..1) of `values`.
fn quantile(sorted: &[f64], q: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * q).round() as usize]
}

/// The scale for a picture's values: from the 2nd to the 98th percentile, so that a few
/// pixels by a lamp do not flatten the rest into one band.
pub fn picture_scale(lux: &[Option<f64>]) -> LuxScale {
    let mut v: Vec<f64> = lux.iter().flatten().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return LuxScale::for_range(0.0, 0.0);
    }
    v.sort_by(f64::total_cmp);
    LuxScale::for_range(quantile(&v, 0.02), quantile(&v, 0.98))
}

/// The false-colour picture of `lux` (`width` × `height`, top row first), the legend at its
/// right and the mean and range of the lit pixels under it.
///
/// # Panics
/// When `lux` does not hold `width` × `height` values (a bug in the caller).
pub fn false_colour_picture(lux: &[Option<f64>], width: u32, height: u32) -> SrgbImage {
    assert_eq!(lux.len(), width as usize * height as usize, "a picture of another size");
    let scale = picture_scale(lux);
    let s = if height >= 400 { 2 } else { 1 };
    let legend_w = (14 + 6) * s + crate::font::text_width("100000", s) + 12;
    let foot = text_height(s) + 12;
    let mut c = Canvas::new(width + 16 + legend_w, height + foot, WHITE);
    let band = |e: &Option<f64>| e.map(|e| scale.band(e));
    let w = width as usize;
    for (i, e) in lux.iter().enumerate() {
        let (x, y) = ((i % w) as i64, (i / w) as i64);
        // Iso-lux lines where the band changes between two pixels that both have a value.
        let here = band(e);
        let right = (i % w + 1 < w).then(|| band(&lux[i + 1])).flatten();
        let below = lux.get(i + w).and_then(band);
        let edge = here.is_some_and(|b| [right, below].into_iter().flatten().any(|o| o != b));
        c.set(x, y, if edge { ISO_LINE } else { e.map_or(NO_DATA, |e| scale.colour(e)) });
    }
    scale.draw_legend(&mut c, i64::from(width) + 12, 4, height.saturating_sub(8), s);
    let seen: Vec<f64> = lux.iter().flatten().copied().collect();
    if !seen.is_empty() {
        let mean = seen.iter().sum::<f64>() / seen.len() as f64;
        let max = seen.iter().copied().fold(0.0, f64::max);
        let min = seen.iter().copied().fold(f64::INFINITY, f64::min);
        let text = format!(
            "surfaces seen: mean {} lx, {} to {} lx",
            format_lux(mean),
            format_lux(min),
            format_lux(max)
        );
        c.text(6, i64::from(height) + 6, &text, s, BLACK);
    }
    c.into_image()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HdrImage;

    #[test]
    fn the_lux_read_back_is_what_fell_on_the_surface() {
        // ρ 0.5 under 100 W/unit²: B = 50, L = 50 / π.
        let l = Rgb::splat(50.0 / std::f64::consts::PI);
        let rendering = Rendering {
            radiance: HdrImage::from_pixels(3, 1, vec![l, l, Rgb::ZERO]),
            object_ids: vec![Some(0), Some(1), None],
        };
        let grey = SurfaceLight { reflectance: Rgb::splat(0.5), emission: Rgb::ZERO };
        let black = SurfaceLight { reflectance: Rgb::new(0.5, 0.0, 0.5), emission: Rgb::ZERO };
        let lux = pixel_illuminance(&rendering, &[Some(grey), Some(black)], 683.0);
        assert!((lux[0].unwrap() - 100.0 * 683.0).abs() < 1e-6, "{lux:?}");
        assert_eq!(&lux[1..], &[None, None]);
        let picture = false_colour_picture(&lux, 3, 1);
        assert_eq!(picture.pixels[1], NO_DATA);
        assert!(picture.width > 3 && picture.height > 1);
    }
}
