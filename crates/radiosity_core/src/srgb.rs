//! The sRGB transfer functions (IEC 61966-2-1:1999), shared by every path that turns linear
//! colour into display values or back: picture files, lit-mesh export, texture import.
//!
//! Encoding: c ≤ 0.0031308 → 12.92c, else 1.055 c^(1/2.4) − 0.055; decoding is its inverse,
//! c ≤ 0.04045 → c / 12.92, else ((c + 0.055) / 1.055)^2.4.

use crate::Rgb;

/// The sRGB transfer function (IEC 61966-2-1): linear [0, 1] → encoded [0, 1]. Input outside
/// [0, 1] is clamped first.
pub fn srgb_encode(linear: f64) -> f64 {
    let c = if linear > 0.0 { linear.min(1.0) } else { 0.0 };
    if c <= 0.003_130_8 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

/// The inverse sRGB transfer function (IEC 61966-2-1): encoded [0, 1] → linear [0, 1]. Input
/// outside [0, 1] is clamped first.
pub fn srgb_decode(encoded: f64) -> f64 {
    let c = if encoded > 0.0 { encoded.min(1.0) } else { 0.0 };
    if c <= 0.040_45 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// Encodes display-linear colour in [0, 1] to 8-bit sRGB, rounding to nearest.
pub fn encode_srgb(display: Rgb) -> [u8; 3] {
    display.to_array().map(|c| (srgb_encode(c) * 255.0).round() as u8)
}
