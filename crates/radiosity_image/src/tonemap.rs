//! Tone mapping: from linear radiance to display colour, as pure functions shared by every
//! display path (the CPU renderer's PNG now, the viewer's shader later).
//!
//! The pipeline is: exposure (a scale of 2^EV, one for the whole picture), then an operator
//! that compresses [0, ∞) into [0, 1], then the sRGB transfer function.
//!
//! * Exposure and the `auto` key: Reinhard, Stark, Shirley & Ferwerda 2002, "Photographic
//!   tone reproduction for digital images", eq. 1–2: the log-average luminance L̄ is mapped to
//!   the middle-grey key a = 0.18, i.e. scale = a / L̄, EV = log2(a / L̄). As a camera's
//!   averaging meter does, L̄ is taken over the lit part of the picture only (see
//!   [`metered_exposure_ev`]): near-black pixels and lamps are left out, and the exposure is
//!   then held down so the brightest lit surfaces stay under display white.
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

/// The most an automatic exposure lets the brightest lit surfaces (the 98th percentile of the
/// lit pixels that are not highlights, see [`metered_exposure_ev`]) reach after exposure,
/// before the operator. On the default ACES curve 4 is display 0.973 (sRGB 252 of 255), just
/// below its shoulder's clip at 7.24; with Reinhard it is 0.8. `linear` clips above 1 by its
/// nature, so its brightest 2 % of surfaces may clip.
pub const AUTO_EXPOSURE_WHITE: f64 = 4.0;

/// The share of the lit picture (by weight) that [`metered_exposure_ev`] treats as
/// highlights: the brightest 2 %, where a lamp seen directly and the surfaces right beside it
/// lie. They set neither the key nor the cap, so a lamp does not darken the room.
pub const AUTO_EXPOSURE_HIGHLIGHTS: f64 = 0.02;

/// Samples more than this many stops below the 90th percentile are black to the meter.
/// A display shows about 12 stops: sRGB code value 1 of 255 is linear 3.0e-4, 11.7 stops
/// under white, and the ACES toe sends anything 7 stops under middle grey there. Such pixels
/// (unlit insides and back faces, the residue a solver or an interpolation leaves on them,
/// background) carry nothing about how bright the lit room is, yet 30 % of them at 1e-7
/// pull a plain log-average down by 5 stops and blow the room out to white.
const AUTO_EXPOSURE_DARK_STOPS: f64 = 12.0;

/// Samples more than this many stops above the median of the lit ones are highlights
/// whatever their share of the picture: 7 stops above middle grey is radiance 23 after
/// exposure, far past white for every operator (ACES clips at 7.24), so only a lamp is ever
/// that bright; holding it under white would darken the whole room by several stops.
const AUTO_EXPOSURE_HIGHLIGHT_STOPS: f64 = 7.0;

/// One reading for [`metered_exposure_ev`]: a pixel, or a surface element seen from the
/// camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeterSample {
    /// Luminance of the radiance seen (`Rgb::luminance`, linear).
    pub luminance: f64,
    /// How much of the view it covers: 1 for a pixel, a solid angle for an element.
    pub weight: f64,
    /// Whether it is known to be an emitter (a lamp seen directly). A picture's pixels do not
    /// know and pass `false`; the highlight rule then finds lamps by their brightness.
    pub emitter: bool,
}

/// Automatic exposure in stops from what the camera sees, as a photographer's averaging meter
/// reads a scene: the key of the lit, non-highlight part goes to middle grey, held down so the
/// brightest lit surfaces stay under display white. `None` when nothing lit is seen.
///
/// 1. Lit samples: finite luminance > 0 and weight > 0, emitters left out (unless only
///    emitters are seen, as in a furnace, where they are the scene), and those more than 12
///    stops under the weighted 90th percentile left out as black (see the constant's note).
///    The 90th percentile, not the median, is the reference so that a picture that is mostly
///    black still has its lit part as the reference, and a lamp covering up to a tenth of it
///    does not make the room look black.
/// 2. Highlights: the lit samples lying wholly in the top [`AUTO_EXPOSURE_HIGHLIGHTS`] of the
///    weight, and any more than 7 stops above the weighted median. What is left is the body.
/// 3. Key: L̄ = exp(Σ w ln L / Σ w) over the body, EV_key = log2(0.18 / L̄) (Reinhard et al.
///    2002, eq. 1–2, with the pixels weighted).
/// 4. Cap: EV_cap = log2([`AUTO_EXPOSURE_WHITE`] / L_top), L_top the brightest of the body
///    (about the 98th percentile of the lit samples), so a high-contrast room is never blown
///    out; the exposure is min(EV_key, EV_cap). A dim scene keeps EV_key, which lifts it to
///    middle grey whatever its scale.
///
/// Both the CPU renderer ([`auto_exposure_ev`], over pixels) and the viewer (over the
/// elements in view, weighted by solid angle) meter through this function, so they agree.
pub fn metered_exposure_ev(samples: impl IntoIterator<Item = MeterSample>) -> Option<f64> {
    let mut lit: Vec<MeterSample> = samples
        .into_iter()
        .filter(|s| s.luminance.is_finite() && s.luminance > 0.0 && s.weight.is_finite() && s.weight > 0.0)
        .collect();
    if lit.iter().any(|s| !s.emitter) {
        lit.retain(|s| !s.emitter);
    }
    if lit.is_empty() {
        return None;
    }
    lit.sort_unstable_by(|a, b| a.luminance.total_cmp(&b.luminance));

    // Weighted quantile: the luminance of the first sample (ascending) at which the running
    // weight reaches q of the total.
    let quantile = |lit: &[MeterSample], q: f64| -> f64 {
        let total: f64 = lit.iter().map(|s| s.weight).sum();
        let mut run = 0.0;
        for s in lit {
            run += s.weight;
            if run >= q * total {
                return s.luminance;
            }
        }
        lit[lit.len() - 1].luminance // rounding left the running sum just short
    };

    let black = quantile(&lit, 0.9) * (-AUTO_EXPOSURE_DARK_STOPS).exp2();
    let first_lit = lit.partition_point(|s| s.luminance < black);
    let lit = &lit[first_lit..]; // never empty: the 90th percentile itself is above `black`

    let too_bright = quantile(lit, 0.5) * AUTO_EXPOSURE_HIGHLIGHT_STOPS.exp2();
    let total: f64 = lit.iter().map(|s| s.weight).sum();
    let (mut end, mut above) = (lit.len(), 0.0);
    // Whole samples only, so a small picture (or a uniform one) keeps every sample; the
    // median sample is never above `too_bright` and a share of 2 % never covers all weight,
    // so the body is never empty.
    while end > 1 {
        let s = lit[end - 1];
        if s.luminance > too_bright || above + s.weight <= AUTO_EXPOSURE_HIGHLIGHTS * total {
            above += s.weight;
            end -= 1;
        } else {
            break;
        }
    }
    let body = &lit[..end];

    let (sum, weight) =
        body.iter().fold((0.0, 0.0), |(s, w), m| (s + m.weight * m.luminance.ln(), w + m.weight));
    let key_ev = (AUTO_EXPOSURE_KEY / (sum / weight).exp()).log2();
    let cap_ev = (AUTO_EXPOSURE_WHITE / body[body.len() - 1].luminance).log2();
    Some(key_ev.min(cap_ev))
}

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
    /// From the picture itself: the log-average luminance of its lit pixels is mapped to
    /// middle grey ([`AUTO_EXPOSURE_KEY`]), held down so the brightest lit surfaces stay under
    /// display white ([`auto_exposure_ev`]). Still one exposure for the whole picture. The
    /// default.
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

/// The automatic exposure (stops) of `image`: [`metered_exposure_ev`] over its pixels, each
/// of weight 1 (a picture does not know which pixels are lamps; the highlight rule finds
/// them). The key of the lit pixels goes to middle grey, EV = log2(0.18 / L̄) (Reinhard et
/// al. 2002, eq. 2), held down so their 98th percentile stays under display white.
/// 0 for a black picture.
pub fn auto_exposure_ev(image: &HdrImage) -> f64 {
    metered_exposure_ev(image.pixels().iter().map(|p| MeterSample {
        luminance: p.luminance(),
        weight: 1.0,
        emitter: false,
    }))
    .unwrap_or(0.0)
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

    /// The exposure the rule before the meter picked: the plain log-average of every pixel
    /// above zero to middle grey.
    fn plain_log_average_ev(image: &HdrImage) -> f64 {
        image.log_average_luminance().map_or(0.0, |l| (AUTO_EXPOSURE_KEY / l).log2())
    }

    /// A fixed, well-spread value in [0, 1) for pixel `i` (the golden-ratio sequence), so the
    /// synthetic pictures need no random generator.
    fn spread(i: u32) -> f64 {
        (f64::from(i) * 0.618_033_988_749_895).fract()
    }

    /// The sRGB display value (0..1) of one grey pixel's green channel, and whether any of
    /// its channels is at 255.
    fn display(p: [u8; 3]) -> (f64, bool) {
        (f64::from(p[1]) / 255.0, p.contains(&255))
    }

    /// A furnished room lit by one bright panel, as `render` sees it: 70 % of the pixels lit
    /// surfaces between 0.5 and 2 (walls, floor, table, chairs), 1 % the panel at 500, 25 %
    /// unlit insides and back faces holding a residue of 1e-7 and 5 % background at 0. The old
    /// rule let the residue drag the log-average down 6 stops and drew the room white.
    #[test]
    fn auto_exposure_keeps_a_bright_lamp_room_off_white() {
        #[derive(Clone, Copy, PartialEq)]
        enum Kind {
            Lit,
            Lamp,
            Residue,
            Background,
        }
        let kind = |i: u32| match i % 100 {
            0 => Kind::Lamp,
            1..=25 => Kind::Residue,
            26..=30 => Kind::Background,
            _ => Kind::Lit,
        };
        let (w, h) = (200, 150);
        let picture = HdrImage::from_fn(w, h, |x, y| {
            let i = y * w + x;
            match kind(i) {
                Kind::Lit => grey(0.5 * 4.0_f64.powf(spread(i))),
                Kind::Lamp => grey(500.0),
                Kind::Residue => grey(1e-7),
                Kind::Background => Rgb::ZERO,
            }
        });
        let ev = auto_exposure_ev(&picture);
        let old = plain_log_average_ev(&picture);
        eprintln!("lamp room: auto {ev:+.2} EV, plain log-average {old:+.2} EV");
        for op in ToneOperator::ALL {
            let srgb = tone_map_image(&picture, &ToneParams::new(ev, op));
            let mut lit: Vec<(f64, bool)> = (0..w * h)
                .filter(|i| kind(*i) == Kind::Lit)
                .map(|i| display(srgb.pixels[i as usize]))
                .collect();
            let clipped = lit.iter().filter(|(_, white)| *white).count() as f64 / lit.len() as f64;
            lit.sort_by(|a, b| a.0.total_cmp(&b.0));
            let median = lit[lit.len() / 2].0;
            assert!(clipped < 0.02, "{op}: {:.1} % of the lit pixels clip to white", clipped * 100.0);
            assert!((0.25..=0.75).contains(&median), "{op}: median lit pixel at display {median:.3}");
        }
        // The plain log-average would have blown the room out: its median lit pixel clips.
        let srgb = tone_map_image(&picture, &ToneParams::new(old, ToneOperator::Aces));
        let lit: Vec<_> =
            (0..w * h).filter(|i| kind(*i) == Kind::Lit).map(|i| display(srgb.pixels[i as usize])).collect();
        assert!(old > ev + 5.0, "old {old:+.2} EV vs {ev:+.2} EV");
        assert!(
            lit.iter().filter(|(_, white)| *white).count() * 2 > lit.len(),
            "old rule: most lit pixels white"
        );
    }

    /// A dim scene (radiance 1e-4 everywhere) is lifted to middle grey by the key, not left
    /// black, and the cap does not hold it down.
    #[test]
    fn auto_exposure_lifts_a_dim_scene() {
        let picture = HdrImage::from_fn(64, 48, |x, y| grey(1e-4 * (1.0 + 0.2 * spread(y * 64 + x))));
        let ev = auto_exposure_ev(&picture);
        let srgb = tone_map_image(&picture, &ToneParams::new(ev, ToneOperator::Aces));
        let mut values: Vec<f64> = srgb.pixels.iter().map(|p| display(*p).0).collect();
        values.sort_by(f64::total_cmp);
        let median = values[values.len() / 2];
        assert!(median > 0.2, "dim scene drawn at display {median:.3} (EV {ev:+.2})");
        let flat = HdrImage::from_fn(8, 8, |_, _| grey(1e-4));
        assert!((auto_exposure_ev(&flat) - (AUTO_EXPOSURE_KEY / 1e-4).log2()).abs() < 1e-9);
    }

    /// A high-contrast room: 90 % dim surfaces around 0.01 and a sunlit patch at 1.0 on 10 %
    /// of the picture. The key alone would put the patch at 11 (past ACES white); the cap holds
    /// it at [`AUTO_EXPOSURE_WHITE`], and the dim part stays visible.
    #[test]
    fn auto_exposure_holds_bright_surfaces_under_white() {
        let picture = HdrImage::from_fn(100, 100, |x, y| {
            let i = y * 100 + x;
            if i % 10 == 0 { grey(1.0) } else { grey(0.005 * 4.0_f64.powf(spread(i))) }
        });
        let ev = auto_exposure_ev(&picture);
        assert!((ev - AUTO_EXPOSURE_WHITE.log2()).abs() < 1e-9, "capped at the patch: {ev:+.3} EV");
        let srgb = tone_map_image(&picture, &ToneParams::new(ev, ToneOperator::Aces));
        assert!(srgb.pixels.iter().all(|p| !display(*p).1), "nothing clips");
        assert!(srgb.pixels.iter().all(|p| display(*p).0 > 0.02), "the dim part is not black");
        // The plain log-average clips the patch.
        let old = plain_log_average_ev(&picture);
        let srgb = tone_map_image(&picture, &ToneParams::new(old, ToneOperator::Aces));
        assert!(srgb.pixels.iter().filter(|p| display(**p).1).count() >= 1000, "old {old:+.2} EV");
    }

    /// A Cornell-box-like picture — 30 % background at 0, the lamp at 250× the median on
    /// 0.7 %, the rest spread over 6 stops — meters within a fifth of a stop of the plain
    /// log-average, which served it well (a little brighter: the lamp no longer counts).
    #[test]
    fn auto_exposure_of_a_cornell_like_picture_is_close_to_the_plain_key() {
        let picture = HdrImage::from_fn(200, 150, |x, y| {
            let i = y * 200 + x;
            match i % 1000 {
                0..=299 => Rgb::ZERO,
                300..=306 => grey(12.4),
                _ => Rgb::new(0.9, 1.0, 1.1) * (0.0035 * 64.0_f64.powf(spread(i))),
            }
        });
        let (ev, old) = (auto_exposure_ev(&picture), plain_log_average_ev(&picture));
        assert!(ev >= old && ev - old < 0.2, "{ev:+.3} EV vs {old:+.3} EV");
    }

    /// Samples flagged as emitters are left out (the viewer knows its lamps), unless nothing
    /// else is seen; weights count as pixel shares; nothing lit gives `None`.
    #[test]
    fn the_meter_leaves_out_emitters_and_weighs_samples() {
        let sample = |luminance, weight, emitter| MeterSample { luminance, weight, emitter };
        let room = [sample(0.5, 1.0, false), sample(2.0, 1.0, false)];
        let ev = metered_exposure_ev(room).unwrap();
        assert!((ev - (AUTO_EXPOSURE_KEY / 1.0).log2()).abs() < 1e-12);
        let with_lamp = [room[0], room[1], sample(1e4, 5.0, true)];
        assert_eq!(metered_exposure_ev(with_lamp), Some(ev));
        let only_lamp = [sample(1e4, 5.0, true)];
        assert!((metered_exposure_ev(only_lamp).unwrap() - (AUTO_EXPOSURE_KEY / 1e4).log2()).abs() < 1e-12);
        // Weight 3 on 0.5 and 1 on 8: L̄ = exp((3 ln 0.5 + ln 8) / 4) = 1.
        let weighted = [sample(0.5, 3.0, false), sample(8.0, 1.0, false)];
        assert!((metered_exposure_ev(weighted).unwrap() - AUTO_EXPOSURE_KEY.log2()).abs() < 1e-12);
        assert_eq!(metered_exposure_ev([sample(0.0, 1.0, false), sample(f64::NAN, 1.0, false)]), None);
        assert_eq!(metered_exposure_ev([sample(1.0, 0.0, false)]), None);
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
