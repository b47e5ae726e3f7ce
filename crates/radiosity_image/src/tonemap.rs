//! Tone mapping: from linear radiance to display colour, as pure functions shared by every
//! display path (the CPU renderer's PNG now, the viewer's shader later).
//!
//! The pipeline is: exposure (a scale of 2^EV, one for the whole picture), then an operator
//! that compresses [0, ∞) into [0, 1], then the sRGB transfer function.
//!
//! * Exposure and the `auto` key: Reinhard, Stark, Shirley & Ferwerda 2002, "Photographic
//!   tone reproduction for digital images", eq. 1–2: the log-average luminance L̄ is mapped to
//!   the middle-grey key a = 0.18, i.e. scale = a / L̄, EV = log2(a / L̄).
//! * [`ToneOperator::Reinhard`]: the same paper's simple operator, eq. 3, L_d = L / (1 + L),
//!   applied to luminance with the colour scaled by L_d / L (so hue is kept), then clamped.
//! * [`ToneOperator::Aces`]: Narkowicz 2015, "ACES Filmic Tone Mapping Curve", the rational fit
//!   f(x) = x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14) of the ACES RRT + sRGB ODT, per channel.
//! * sRGB encoding: `radiosity_core::srgb_encode` (IEC 61966-2-1:1999).

use std::fmt;
use std::str::FromStr;

use radiosity_core::{Rgb, encode_srgb};
use thiserror::Error;

use crate::HdrImage;

/// Middle grey: the display value the log-average luminance is mapped to by
/// [`Exposure::Auto`] (Reinhard et al. 2002, the "key" a = 0.18).
pub const AUTO_EXPOSURE_KEY: f64 = 0.18;

/// How the compressed range is mapped into [0, 1].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ToneOperator {
    /// Exposure only, then clamp to [0, 1]: faithful up to white, everything brighter clips.
    Linear,
    /// Reinhard et al. 2002 simple operator on luminance, L / (1 + L): never clips, flattens
    /// highlights.
    Reinhard,
    /// Narkowicz 2015 fit of the ACES filmic curve, per channel: a toe, a shoulder, and
    /// highlights that desaturate towards white like film.
    #[default]
    Aces,
}

impl ToneOperator {
    /// Every operator, in the order a menu lists them.
    pub const ALL: [ToneOperator; 3] = [ToneOperator::Linear, ToneOperator::Reinhard, ToneOperator::Aces];

    /// The operator's name on the command line and in files: `linear`, `reinhard`, `aces`.
    pub fn as_str(self) -> &'static str {
        match self {
            ToneOperator::Linear => "linear",
            ToneOperator::Reinhard => "reinhard",
            ToneOperator::Aces => "aces",
        }
    }
}

impl fmt::Display for ToneOperator {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A tone-mapping setting that could not be parsed.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum ToneParseError {
    /// Not one of the operator names.
    #[error("unknown tone operator '{0}'; expected one of linear, reinhard, aces")]
    UnknownOperator(String),
    /// Neither a finite number of stops nor `auto` nor `auto±stops`.
    #[error(
        "exposure must be a number of stops (EV, e.g. -1.5), 'auto', or 'auto+1' / 'auto-0.5' (stops from auto), got '{0}'"
    )]
    BadExposure(String),
}

impl FromStr for ToneOperator {
    type Err = ToneParseError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|o| o.as_str().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| ToneParseError::UnknownOperator(s.to_owned()))
    }
}

/// How the exposure of a picture is chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Exposure {
    /// A fixed exposure in stops: radiance is multiplied by 2^EV before the operator.
    Ev(f64),
    /// From the picture itself: its log-average luminance is mapped to middle grey
    /// ([`AUTO_EXPOSURE_KEY`]). Still one exposure for the whole picture. The default.
    #[default]
    Auto,
    /// [`Exposure::Auto`] plus this many stops (`auto+1` is one stop brighter than auto):
    /// brighter or darker than the automatic choice, whatever the scene's scale.
    AutoPlus(f64),
}

impl Exposure {
    /// The exposure in stops for `image`: the fixed value, or [`auto_exposure_ev`] of it.
    pub fn ev_for(self, image: &HdrImage) -> f64 {
        match self {
            Exposure::Ev(ev) => ev,
            Exposure::Auto => auto_exposure_ev(image),
            Exposure::AutoPlus(offset) => auto_exposure_ev(image) + offset,
        }
    }
}

impl fmt::Display for Exposure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Exposure::Ev(ev) => write!(f, "{ev}"),
            Exposure::Auto => f.write_str("auto"),
            Exposure::AutoPlus(offset) => write!(f, "auto{offset:+}"),
        }
    }
}

impl FromStr for Exposure {
    type Err = ToneParseError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim();
        if t.eq_ignore_ascii_case("auto") {
            return Ok(Exposure::Auto);
        }
        if let Some(rest) = t.get(..4).filter(|a| a.eq_ignore_ascii_case("auto")).map(|_| &t[4..]) {
            return match rest.trim().parse::<f64>() {
                Ok(offset) if offset.is_finite() && rest.trim_start().starts_with(['+', '-']) => {
                    Ok(Exposure::AutoPlus(offset))
                }
                _ => Err(ToneParseError::BadExposure(s.to_owned())),
            };
        }
        match t.parse::<f64>() {
            Ok(ev) if ev.is_finite() => Ok(Exposure::Ev(ev)),
            _ => Err(ToneParseError::BadExposure(s.to_owned())),
        }
    }
}

/// The exposure (stops) that maps the log-average luminance of `image` to middle grey:
/// EV = log2(0.18 / L̄) (Reinhard et al. 2002, eq. 2). 0 for a black picture.
pub fn auto_exposure_ev(image: &HdrImage) -> f64 {
    image.log_average_luminance().map_or(0.0, |l| (AUTO_EXPOSURE_KEY / l).log2())
}

/// Tone mapping settings: one exposure for the whole picture and an operator.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ToneParams {
    /// Exposure in stops: radiance is multiplied by 2^`exposure_ev`. Any finite value;
    /// default 0 (radiance 1 maps to display 1 before the operator). Use
    /// [`Exposure::ev_for`] to get it from a picture.
    pub exposure_ev: f64,
    /// The operator. Default [`ToneOperator::Aces`].
    pub operator: ToneOperator,
}

impl ToneParams {
    /// Settings with exposure `exposure_ev` stops and `operator`.
    pub fn new(exposure_ev: f64, operator: ToneOperator) -> Self {
        Self { exposure_ev, operator }
    }

    /// The linear factor 2^EV applied to radiance.
    pub fn exposure_scale(&self) -> f64 {
        self.exposure_ev.exp2()
    }
}

/// Narkowicz 2015 ACES filmic fit, one channel, input ≥ 0, output in [0, 1].
fn aces_narkowicz(x: f64) -> f64 {
    let (a, b, c, d, e) = (2.51, 0.03, 2.43, 0.59, 0.14);
    if x.is_infinite() {
        // The curve tends to a/c > 1, so it is clamped to 1 long before; ∞/∞ would be NaN.
        return 1.0;
    }
    ((x * (a * x + b)) / (x * (c * x + d) + e)).clamp(0.0, 1.0)
}

/// Tone maps one linear radiance to display-referred linear colour in [0, 1] per channel
/// (apply [`radiosity_core::encode_srgb`] to get display values).
///
/// Negative and NaN channels (which a solver with over-relaxation may briefly produce) are
/// treated as 0; +∞ maps to 1.
pub fn tone_map(radiance: Rgb, params: &ToneParams) -> Rgb {
    let clean = |c: f64| if c > 0.0 { c } else { 0.0 }; // NaN > 0 is false
    let x = radiance.map(clean) * params.exposure_scale();
    match params.operator {
        ToneOperator::Linear => x.map(|c| c.min(1.0)),
        ToneOperator::Reinhard => {
            let l = x.luminance();
            if l.is_nan() || l <= 0.0 {
                return Rgb::ZERO;
            }
            if l.is_infinite() {
                return x.map(|c| if c > 0.0 { 1.0 } else { 0.0 });
            }
            // Scaling the colour by L_d / L keeps its hue; saturated colours may then exceed 1
            // in one channel, which is clipped.
            (x * (1.0 / (1.0 + l))).map(|c| c.min(1.0))
        }
        ToneOperator::Aces => x.map(aces_narkowicz),
    }
}

/// An 8-bit sRGB picture, ready to show or to save as PNG: `[r, g, b]` per pixel, top row
/// first.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SrgbImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Pixels, top row first, `width * height` of them.
    pub pixels: Vec<[u8; 3]>,
}

impl SrgbImage {
    /// The pixels as one byte slice `r g b r g b …`.
    pub fn as_bytes(&self) -> Vec<u8> {
        self.pixels.iter().flatten().copied().collect()
    }
}

/// Tone maps and sRGB-encodes a whole picture with one exposure.
pub fn tone_map_image(image: &HdrImage, params: &ToneParams) -> SrgbImage {
    SrgbImage {
        width: image.width(),
        height: image.height(),
        pixels: image.pixels().iter().map(|p| encode_srgb(tone_map(*p, params))).collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(v: f64) -> Rgb {
        Rgb::splat(v)
    }

    /// Known values, worked by hand from the published formulas.
    #[test]
    fn operators_match_a_table_of_known_values() {
        let table: [(ToneOperator, f64, f64, f64); 11] = [
            // (operator, exposure EV, input grey, expected display-linear grey)
            (ToneOperator::Linear, 0.0, 0.5, 0.5),
            (ToneOperator::Linear, 0.0, 2.0, 1.0),
            (ToneOperator::Linear, 1.0, 0.25, 0.5),
            (ToneOperator::Linear, -2.0, 2.0, 0.5),
            (ToneOperator::Reinhard, 0.0, 1.0, 0.5),
            (ToneOperator::Reinhard, 0.0, 3.0, 0.75),
            (ToneOperator::Reinhard, 1.0, 0.5, 0.5),
            // ACES: f(1) = 2.54 / 3.16; f(0.18) = 0.086724 / 0.324932.
            (ToneOperator::Aces, 0.0, 1.0, 2.54 / 3.16),
            (
                ToneOperator::Aces,
                0.0,
                0.18,
                0.18 * (2.51 * 0.18 + 0.03) / (0.18 * (2.43 * 0.18 + 0.59) + 0.14),
            ),
            (ToneOperator::Aces, 0.0, 0.0, 0.0),
            (ToneOperator::Aces, 0.0, 1e6, 1.0),
        ];
        for (op, ev, input, expected) in table {
            let out = tone_map(grey(input), &ToneParams::new(ev, op));
            for c in out.to_array() {
                assert!((c - expected).abs() < 1e-6, "{op} EV {ev} of {input}: {c} vs {expected}");
            }
        }
        assert!((2.54_f64 / 3.16 - 0.803_797).abs() < 1e-6);
    }

    #[test]
    fn operators_are_monotonic_and_bounded() {
        let colours = [grey(1.0), Rgb::new(1.0, 0.2, 0.05), Rgb::new(0.0, 0.0, 1.0), Rgb::new(0.3, 0.9, 0.1)];
        for op in ToneOperator::ALL {
            for c in colours {
                let mut last = Rgb::ZERO;
                for k in 0..400 {
                    let scale = 1e-4 * 1.05_f64.powi(k);
                    let out = tone_map(c * scale, &ToneParams::new(0.0, op));
                    for (a, b) in out.to_array().into_iter().zip(last.to_array()) {
                        assert!((0.0..=1.0).contains(&a), "{op}: {a} out of range");
                        assert!(a >= b - 1e-15, "{op}: not monotonic at scale {scale}: {a} < {b}");
                    }
                    last = out;
                }
            }
            // Exposure is monotonic too.
            let mut last = 0.0;
            for ev in -20..20 {
                let y = tone_map(grey(0.3), &ToneParams::new(f64::from(ev) * 0.5, op)).g;
                assert!(y >= last);
                last = y;
            }
        }
    }

    #[test]
    fn bad_values_do_not_poison_the_picture() {
        for op in ToneOperator::ALL {
            let p = ToneParams::new(0.0, op);
            assert_eq!(tone_map(Rgb::new(f64::NAN, -1.0, 0.0), &p), Rgb::ZERO);
            let inf = tone_map(Rgb::new(f64::INFINITY, 0.0, 0.0), &p);
            assert!(inf.is_finite() && inf.r == 1.0, "{op}: {inf:?}");
        }
    }

    #[test]
    fn auto_exposure_maps_the_log_average_to_middle_grey() {
        // Half the pixels at 2, half at 8: geometric mean 4, so EV = log2(0.18 / 4).
        let img = HdrImage::from_fn(4, 2, |x, _| if x % 2 == 0 { grey(2.0) } else { grey(8.0) });
        let ev = Exposure::Auto.ev_for(&img);
        assert!((ev - (0.18_f64 / 4.0).log2()).abs() < 1e-12);
        // Background (zero) pixels do not change it.
        let mut with_background = HdrImage::new(8, 2);
        for (i, p) in with_background.pixels_mut().iter_mut().enumerate().take(8) {
            *p = img.pixels()[i];
        }
        assert!((auto_exposure_ev(&with_background) - ev).abs() < 1e-12);
        assert_eq!(auto_exposure_ev(&HdrImage::new(3, 3)), 0.0);
        assert_eq!(Exposure::Ev(-1.5).ev_for(&img), -1.5);
    }

    #[test]
    fn settings_parse_from_their_names() {
        assert_eq!("auto".parse::<Exposure>(), Ok(Exposure::Auto));
        assert_eq!("-1.5".parse::<Exposure>(), Ok(Exposure::Ev(-1.5)));
        assert!("bright".parse::<Exposure>().is_err());
        assert_eq!("auto+1".parse::<Exposure>(), Ok(Exposure::AutoPlus(1.0)));
        assert_eq!("AUTO-0.5".parse::<Exposure>(), Ok(Exposure::AutoPlus(-0.5)));
        for bad in ["auto1", "auto+", "auto+nan", "autox", "auto+inf"] {
            assert!(bad.parse::<Exposure>().is_err(), "{bad}");
        }
        let picture = HdrImage::from_pixels(2, 1, vec![Rgb::splat(0.5), Rgb::splat(2.0)]);
        let auto = Exposure::Auto.ev_for(&picture);
        assert_eq!(Exposure::AutoPlus(1.0).ev_for(&picture), auto + 1.0);
        assert!("nan".parse::<Exposure>().is_err());
        for op in ToneOperator::ALL {
            assert_eq!(op.as_str().parse::<ToneOperator>(), Ok(op));
        }
        assert!(matches!("filmic".parse::<ToneOperator>(), Err(ToneParseError::UnknownOperator(_))));
    }
}
