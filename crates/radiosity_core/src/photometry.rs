//! Photometric quantities: length units, the RGB ↔ lumen rule, luminaires with goniometric
//! intensity distributions (type C), and calculation grids.
//!
//! # The rule between RGB and photometry
//!
//! Every solver value stays linear RGB "radiometric" power (W) and radiosity (W per scene
//! unit²). Photometric figures are their luminance Y, the Y of linear sRGB / Rec. 709
//! primaries, at the maximum luminous efficacy 683 lm/W:
//!
//!   Y = 683 · (0.2126 R + 0.7152 G + 0.0722 B)
//!
//! so a white (R = G = B) power of Φ/683 W is Φ lumens, and an irradiance H (W/unit²) is
//! 683 · Y(H) / s² lux with s the scene unit in metres ([`LengthUnit::metres`]). A luminaire's
//! or emitter's colour ([`colour_of_cct`], or a given `[r, g, b]`) is scaled to Y = 1 first,
//! so its colour never changes its lumens.
//!
//! # Luminaires
//!
//! A [`Luminaire`] is a point source at its photometric centre with the intensity
//! I(C, γ) (cd) of a type C goniometric table ([`IntensityTable`]; CIE 102, IES LM-63): γ the
//! angle from the photometric nadir ([`Luminaire::nadir`]), C the azimuth about it from the
//! C0 half-plane ([`Luminaire::c0`]). The irradiance it gives a point at distance d, its
//! normal at θ to the direction towards the luminaire, is the inverse-square law
//! E = I(C, γ) · cos θ / d² (lux with d in metres).
//!
//! Between the table's angles I is interpolated bilinearly in C and γ (periodic in C), so
//! neither plane nor cone shows steps.
//!
//! A luminaire with a luminous opening ([`Opening`]) is a point only far away. Nearer than
//! [`NEAR_FIELD_RATIO`] times the opening's size, a receiver sees it as cells of the
//! opening, each a point source with its share of the intensity, each far enough for the
//! inverse-square law ([`Luminaire::sources_towards`]): the near-field calculation of
//! CIE 121 and of the lighting-design programs, whose point approximation alone is 1 % off at
//! five times the size and 12 % at twice it.

use std::f64::consts::PI;
use std::sync::Arc;

use glam::DVec3;

use crate::{Rgb, SkyMap};

/// Maximum luminous efficacy: lumens per watt of the RGB power (see the module doc).
pub const LUMENS_PER_WATT: f64 = 683.0;

/// The length unit of a scene's coordinates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LengthUnit {
    /// Metres (the default: what lux are measured in).
    #[default]
    Metre,
    /// Centimetres.
    Centimetre,
    /// Millimetres.
    Millimetre,
    /// Inches.
    Inch,
    /// Feet.
    Foot,
}

impl LengthUnit {
    /// Every unit with its scene-file name.
    pub const ALL: [(&'static str, LengthUnit); 5] = [
        ("m", LengthUnit::Metre),
        ("cm", LengthUnit::Centimetre),
        ("mm", LengthUnit::Millimetre),
        ("in", LengthUnit::Inch),
        ("ft", LengthUnit::Foot),
    ];

    /// The unit named `m`, `cm`, `mm`, `in` or `ft`.
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.iter().find(|(n, _)| *n == name).map(|&(_, u)| u)
    }

    /// Its scene-file name.
    pub fn as_str(self) -> &'static str {
        Self::ALL.iter().find(|(_, u)| *u == self).map_or("m", |(n, _)| n)
    }

    /// One unit in metres.
    pub fn metres(self) -> f64 {
        match self {
            LengthUnit::Metre => 1.0,
            LengthUnit::Centimetre => 0.01,
            LengthUnit::Millimetre => 0.001,
            LengthUnit::Inch => 0.0254,
            LengthUnit::Foot => 0.3048,
        }
    }

    /// Lux per W/unit² of Y: 683 / s².
    pub fn lux_per_irradiance(self) -> f64 {
        LUMENS_PER_WATT / (self.metres() * self.metres())
    }
}

/// Photometric Y (lm, lx or cd/m², as the quantity) of an RGB power, irradiance or radiance
/// in watts (per unit² per the caller's units): 683 · Y(rgb).
pub fn photometric_y(rgb: Rgb) -> f64 {
    LUMENS_PER_WATT * rgb.luminance()
}

/// `colour` scaled to luminance Y = 1, or `None` when it has no luminance (black, negative or
/// not finite).
pub fn unit_luminance(colour: Rgb) -> Option<Rgb> {
    let y = colour.luminance();
    let ok = [colour.r, colour.g, colour.b].iter().all(|c| c.is_finite() && *c >= 0.0);
    (ok && y > 0.0 && y.is_finite()).then(|| colour / y)
}

/// Linear sRGB of a black body at `kelvin` (1 667 – 25 000 K, clamped), scaled to Y = 1: the
/// chromaticity of the Planckian locus by Kim et al.'s cubic fit (2002, "Design of advanced
/// color temperature control system for HDTV applications"), then XYZ → linear sRGB (IEC
/// 61966-2-1), negative channels (outside the sRGB gamut, below ~1 900 K) clipped to 0.
pub fn colour_of_cct(kelvin: f64) -> Rgb {
    let t = kelvin.clamp(1667.0, 25000.0);
    let (t1, t2, t3) = (1e3 / t, 1e6 / (t * t), 1e9 / (t * t * t));
    let x = if t <= 4000.0 {
        -0.2661239 * t3 - 0.2343589 * t2 + 0.8776956 * t1 + 0.179910
    } else {
        -3.0258469 * t3 + 2.1070379 * t2 + 0.2226347 * t1 + 0.240390
    };
    let y = if t <= 2222.0 {
        -1.1063814 * x.powi(3) - 1.34811020 * x * x + 2.18555832 * x - 0.20219683
    } else if t <= 4000.0 {
        -0.9549476 * x.powi(3) - 1.37418593 * x * x + 2.09137015 * x - 0.16748867
    } else {
        3.0817580 * x.powi(3) - 5.87338670 * x * x + 3.75112997 * x - 0.37001483
    };
    let (cx, cy, cz) = (x / y, 1.0, (1.0 - x - y) / y);
    let r = 3.2404542 * cx - 1.5371385 * cy - 0.4985314 * cz;
    let g = -0.9692660 * cx + 1.8760108 * cy + 0.0415560 * cz;
    let b = 0.0556434 * cx - 0.2040259 * cy + 1.0572252 * cz;
    let rgb = Rgb::new(r.max(0.0), g.max(0.0), b.max(0.0));
    unit_luminance(rgb).unwrap_or(Rgb::ONE)
}

/// A type C intensity distribution, expanded to every C plane: I(C, γ) in cd on a grid of
/// C in [0°, 360°] (the first angle 0°, the last 360°, a copy of the first) and γ from the
/// file's first to last angle (0–90°, 0–180° or 90–180°); I = 0 outside the γ range.
#[derive(Clone, Debug, PartialEq)]
pub struct IntensityTable {
    c_deg: Vec<f64>,
    gamma_deg: Vec<f64>,
    /// `candela[c * gamma_deg.len() + g]`.
    candela: Vec<f64>,
}

/// Why an intensity table cannot be made from its angles and values.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum IntensityError {
    /// The C angles do not start at 0°, end at 360° and increase.
    #[error("C angles must increase strictly from 0° to 360° after symmetry, got {0:?}")]
    BadC(Vec<f64>),
    /// The γ angles do not increase within [0°, 180°].
    #[error("γ angles must increase strictly within [0°, 180°], got first {first} last {last}")]
    BadGamma {
        /// First angle.
        first: f64,
        /// Last angle.
        last: f64,
    },
    /// The value count is not C planes × γ angles.
    #[error("{got} intensity values for {c} C planes × {gamma} γ angles")]
    Count {
        /// Values given.
        got: usize,
        /// C planes.
        c: usize,
        /// γ angles.
        gamma: usize,
    },
    /// A value is negative or not finite.
    #[error("intensity {0} cd is not a finite number ≥ 0")]
    BadValue(f64),
}

impl IntensityTable {
    /// A table from full-circle C angles (0° … 360°), γ angles and the values per C plane.
    ///
    /// # Errors
    /// [`IntensityError`] for angles out of order or range, a wrong count or a bad value.
    pub fn try_new(c_deg: Vec<f64>, gamma_deg: Vec<f64>, candela: Vec<f64>) -> Result<Self, IntensityError> {
        let increasing = |a: &[f64]| a.windows(2).all(|w| w[0] < w[1]) && a.iter().all(|x| x.is_finite());
        if c_deg.len() < 2 || c_deg[0] != 0.0 || *c_deg.last().unwrap_or(&0.0) != 360.0 || !increasing(&c_deg)
        {
            return Err(IntensityError::BadC(c_deg));
        }
        let (first, last) =
            (gamma_deg.first().copied().unwrap_or(f64::NAN), gamma_deg.last().copied().unwrap_or(f64::NAN));
        if gamma_deg.is_empty()
            || !increasing(&gamma_deg)
            || !(0.0..=180.0).contains(&first)
            || !(0.0..=180.0).contains(&last)
        {
            return Err(IntensityError::BadGamma { first, last });
        }
        if candela.len() != c_deg.len() * gamma_deg.len() {
            return Err(IntensityError::Count { got: candela.len(), c: c_deg.len(), gamma: gamma_deg.len() });
        }
        if let Some(&v) = candela.iter().find(|v| !(v.is_finite() && **v >= 0.0)) {
            return Err(IntensityError::BadValue(v));
        }
        Ok(Self { c_deg, gamma_deg, candela })
    }

    /// A rotationally symmetric table from I(γ) alone.
    ///
    /// # Errors
    /// As [`IntensityTable::try_new`].
    pub fn symmetric(gamma_deg: Vec<f64>, candela: Vec<f64>) -> Result<Self, IntensityError> {
        let both = candela.iter().chain(&candela).copied().collect();
        Self::try_new(vec![0.0, 360.0], gamma_deg, both)
    }

    /// The same intensity `candela` in every direction (an isotropic point source).
    pub fn isotropic(candela: f64) -> Self {
        Self { c_deg: vec![0.0, 360.0], gamma_deg: vec![0.0, 180.0], candela: vec![candela; 4] }
    }

    /// The C angles, degrees, 0 … 360.
    pub fn c_deg(&self) -> &[f64] {
        &self.c_deg
    }

    /// The γ angles, degrees.
    pub fn gamma_deg(&self) -> &[f64] {
        &self.gamma_deg
    }

    /// Largest intensity, cd.
    pub fn max_candela(&self) -> f64 {
        self.candela.iter().copied().fold(0.0, f64::max)
    }

    /// I(C, γ) in cd, interpolated bilinearly (C periodic); 0 outside the γ range.
    pub fn candela(&self, c_deg: f64, gamma_deg: f64) -> f64 {
        let g = &self.gamma_deg;
        let (g0, g1) = (g[0], g[g.len() - 1]);
        if !(g0..=g1).contains(&gamma_deg) {
            return 0.0;
        }
        let (gi, gt) = bracket(g, gamma_deg);
        let c = c_deg.rem_euclid(360.0);
        let (ci, ct) = bracket(&self.c_deg, c);
        let n = g.len();
        let at = |ci: usize, gi: usize| self.candela[ci * n + gi];
        let gi1 = (gi + 1).min(n - 1);
        let ci1 = (ci + 1).min(self.c_deg.len() - 1);
        let a = at(ci, gi) * (1.0 - gt) + at(ci, gi1) * gt;
        let b = at(ci1, gi) * (1.0 - gt) + at(ci1, gi1) * gt;
        a * (1.0 - ct) + b * ct
    }

    /// Luminous flux Φ = ∫ I dω over the sphere, lm: the interpolated table integrated by
    /// the midpoint rule on a 1° × 0.5° grid (an error far below 0.1 % for any table whose
    /// angles are 1° apart or more).
    pub fn flux(&self) -> f64 {
        let (nc, ng) = (360, 360);
        let dc = 360.0 / nc as f64;
        let dg = 180.0 / ng as f64;
        let mut sum = 0.0;
        for j in 0..ng {
            let gamma = (j as f64 + 0.5) * dg;
            let band =
                ((j as f64 * dg).to_radians().cos() - ((j + 1) as f64 * dg).to_radians().cos()) / nc as f64;
            let mut ring = 0.0;
            for i in 0..nc {
                ring += self.candela((i as f64 + 0.5) * dc, gamma);
            }
            sum += ring * band;
        }
        sum * 2.0 * PI
    }
}

/// The index `i` with `a[i] ≤ x ≤ a[i + 1]` (clamped) and the fraction of the way.
fn bracket(a: &[f64], x: f64) -> (usize, f64) {
    if a.len() == 1 {
        return (0, 0.0);
    }
    let i = a.partition_point(|&v| v <= x).saturating_sub(1).min(a.len() - 2);
    let t = ((x - a[i]) / (a[i + 1] - a[i])).clamp(0.0, 1.0);
    (i, t)
}

/// Receivers at least this many times a cell's size from the opening (its nearest point)
/// take the cell as a point. The cells' midpoint rule was checked against the exact
/// illuminance of a uniform rectangle (configuration factor B-3, Howell) from 0.25 to 2 of
/// its length below it, under it and up to three lengths aside: within 0.5 % everywhere,
/// the worst at grazing incidence (1.5 % at a ratio of 8 measured from the centre instead).
pub const NEAR_FIELD_RATIO: f64 = 10.0;

/// Most cells along a side of an opening (a receiver touching the opening).
const MAX_OPENING_CELLS: u32 = 32;

/// A luminaire's luminous opening, flat across its nadir, scene units: `length` along C0,
/// `width` along C90 (IES LM-63's width, length; EULUMDAT's luminous area). Both zero: a
/// point. `round`: an ellipse (a disc when both are equal) inside that rectangle.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Opening {
    /// Extent along C0.
    pub length: f64,
    /// Extent along C90.
    pub width: f64,
    /// An ellipse instead of a rectangle.
    pub round: bool,
}

/// A placed luminaire: a type C distribution, scaled, coloured and turned into the scene,
/// shining from a point or a luminous [`Opening`].
#[derive(Clone, Debug, PartialEq)]
pub struct Luminaire {
    /// Name, for reports (the file stem and its number).
    pub name: String,
    /// Photometric centre, scene units.
    pub position: DVec3,
    /// Unit direction of γ = 0 (the photometric nadir), world space.
    pub nadir: DVec3,
    /// Unit direction of the C0 half-plane at γ = 90°, perpendicular to `nadir`.
    pub c0: DVec3,
    /// Unit direction of the C90 half-plane at γ = 90°: `c0 × nadir`, so that C grows
    /// counter-clockwise seen from above a downlight (IES LM-63, CIE 102).
    pub c90: DVec3,
    /// The distribution, cd before `scale`.
    pub table: Arc<IntensityTable>,
    /// Factor on every intensity of the table (file multipliers, lumen scaling, maintenance).
    pub scale: f64,
    /// Colour at luminance Y = 1.
    pub colour: Rgb,
    /// Where the light leaves from; a point by default.
    pub opening: Opening,
}

impl Luminaire {
    /// A luminaire at `position` aimed along `nadir` (any length > 0) with the C0 plane
    /// turned `rotation_deg` about it from the default: the horizontal direction of +x
    /// projected off the nadir (+z when the nadir is along x).
    pub fn aimed(
        name: impl Into<String>,
        position: DVec3,
        nadir: DVec3,
        rotation_deg: f64,
        table: Arc<IntensityTable>,
        scale: f64,
        colour: Rgb,
    ) -> Self {
        let nadir = nadir.normalize();
        let reference = if nadir.x.abs() > 0.9 { DVec3::Z } else { DVec3::X };
        let c0 = (reference - nadir * nadir.dot(reference)).normalize();
        let c90 = c0.cross(nadir);
        let (s, c) = rotation_deg.to_radians().sin_cos();
        let (c0, c90) = (c0 * c + c90 * s, c90 * c - c0 * s);
        Self {
            name: name.into(),
            position,
            nadir,
            c0,
            c90,
            table,
            scale,
            colour,
            opening: Opening::default(),
        }
    }

    /// The point of the opening at `(u, v)` ∈ [0, 1]²: a rectangle's bilinear map, an
    /// ellipse's concentric map (Shirley & Chiu 1997), both area-preserving, so uniform
    /// `(u, v)` give uniform points and a grid's cell centres equal cells.
    pub fn point_on_opening(&self, u: f64, v: f64) -> DVec3 {
        let (mut a, mut b) = (2.0 * u - 1.0, 2.0 * v - 1.0);
        if self.opening.round && (a != 0.0 || b != 0.0) {
            let (r, phi) =
                if a.abs() > b.abs() { (a, PI / 4.0 * b / a) } else { (b, PI / 2.0 - PI / 4.0 * a / b) };
            (a, b) = (r * phi.cos(), r * phi.sin());
        }
        self.position + self.c0 * (0.5 * self.opening.length * a) + self.c90 * (0.5 * self.opening.width * b)
    }

    /// The point sources a receiver at `p` sees the luminaire as, with their shares of its
    /// intensity (summing to 1): its centre alone at [`NEAR_FIELD_RATIO`] times the
    /// opening's size and beyond; nearer, the centres of the opening cut into cells that
    /// far from `p` each.
    pub fn sources_towards(&self, p: DVec3) -> impl Iterator<Item = (DVec3, f64)> + '_ {
        // Distance to the opening's nearest point: an oblique receiver beside a long
        // opening is nearer its end than its centre.
        let w = p - self.position;
        let (x, y) = (w.dot(self.c0), w.dot(self.c90));
        let (half_l, half_w) = (0.5 * self.opening.length, 0.5 * self.opening.width);
        let (dx, dy) = (x - x.clamp(-half_l, half_l), y - y.clamp(-half_w, half_w));
        let d = (dx * dx + dy * dy + w.dot(self.nadir).powi(2)).sqrt();
        let cells = |side: f64| {
            let n = (NEAR_FIELD_RATIO * side / d).ceil();
            if n.is_finite() { (n as u32).clamp(1, MAX_OPENING_CELLS) } else { MAX_OPENING_CELLS }
        };
        let (mut na, mut nb) = (cells(self.opening.length), cells(self.opening.width));
        if self.opening.round {
            // The concentric map needs a square grid.
            (na, nb) = (na.max(nb), na.max(nb));
        }
        let share = 1.0 / f64::from(na * nb);
        (0..na * nb).map(move |k| {
            let (i, j) = (k % na, k / na);
            let (u, v) = ((f64::from(i) + 0.5) / f64::from(na), (f64::from(j) + 0.5) / f64::from(nb));
            (self.point_on_opening(u, v), share)
        })
    }

    /// Intensity towards unit direction `dir` (from the luminaire), cd.
    pub fn candela_towards(&self, dir: DVec3) -> f64 {
        let z = dir.dot(self.nadir).clamp(-1.0, 1.0);
        let gamma = z.acos().to_degrees();
        let (x, y) = (dir.dot(self.c0), dir.dot(self.c90));
        let c = if x * x + y * y > 1e-24 { y.atan2(x).to_degrees() } else { 0.0 };
        self.scale * self.table.candela(c, gamma)
    }

    /// Radiant intensity towards unit `dir` in the renderer's RGB units (W/sr, so that
    /// I · cos θ / d² is an irradiance in W/unit² whatever the unit): cd / 683 · colour.
    pub fn intensity_towards(&self, dir: DVec3) -> Rgb {
        self.colour * (self.candela_towards(dir) / LUMENS_PER_WATT)
    }

    /// Luminous flux, lm.
    pub fn flux(&self) -> f64 {
        self.scale * self.table.flux()
    }

    /// Where its light goes on the whole: the flux-weighted mean of the directions it shines
    /// in, ∫ I(ω) ω dω / ∫ I(ω) dω, a vector of length 0 (as much light every way: an
    /// isotropic lamp) to 1 (all of it along one direction). The nadir's length for a
    /// Lambertian downlight is 2/3. Midpoint rule on a 10° × 5° grid of C and γ: coarse, but
    /// this says which side of the lamp the light is on, not how much arrives.
    pub fn mean_light_direction(&self) -> DVec3 {
        let (nc, ng) = (36, 36);
        let (dc, dg) = (2.0 * PI / f64::from(nc), PI / f64::from(ng));
        let (mut weighted, mut total) = (DVec3::ZERO, 0.0);
        for j in 0..ng {
            let gamma = (f64::from(j) + 0.5) * dg;
            // The solid angle of the cell: sin γ dγ dC.
            let cell = gamma.sin() * dg * dc;
            for i in 0..nc {
                let c = (f64::from(i) + 0.5) * dc;
                let sideways = self.c0 * c.cos() + self.c90 * c.sin();
                let dir = self.nadir * gamma.cos() + sideways * gamma.sin();
                let candela = self.table.candela(c.to_degrees(), gamma.to_degrees()) * cell;
                weighted += dir * candela;
                total += candela;
            }
        }
        if total > 0.0 { weighted / total } else { DVec3::ZERO }
    }

    /// The point it lights from, for deciding which side of a surface its light is on: its
    /// photometric centre moved `step` (scene units) along [`Luminaire::mean_light_direction`]
    /// when that is clearly one way (length ≥ 0.1), else the centre itself. A recessed
    /// downlight's centre lies in its ceiling's plane; the point just below it is in the room.
    pub fn light_point(&self, step: f64) -> DVec3 {
        let mean = self.mean_light_direction();
        if mean.length() >= 0.1 { self.position + mean.normalize() * step } else { self.position }
    }

    /// Irradiance (W/unit²) at `p` with unit normal `n` from its intensity leaving `source`
    /// (its centre, or a point of its opening), when nothing is in the way.
    pub fn irradiance_from(&self, source: DVec3, p: DVec3, n: DVec3) -> Rgb {
        let w = source - p;
        let d2 = w.length_squared();
        if d2 <= 0.0 {
            return Rgb::ZERO;
        }
        let d = d2.sqrt();
        let cos = n.dot(w) / d;
        if cos <= 0.0 {
            return Rgb::ZERO;
        }
        self.intensity_towards(-w / d) * (cos / d2)
    }
}

/// A rectangle of points where illuminance is wanted (EN 12464-1's calculation grid): cell
/// centres of `divisions` cells over the parallelogram `origin + s·u + t·v`, s, t ∈ [0, 1],
/// lifted `height` along `normal`. Outputs only: a grid casts no shadow.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// Name, for reports.
    pub name: String,
    /// One corner, scene units.
    pub origin: DVec3,
    /// First edge, scene units.
    pub u: DVec3,
    /// Second edge, scene units.
    pub v: DVec3,
    /// Cells along `u` and `v`, each ≥ 1.
    pub divisions: [u32; 2],
    /// Unit normal the illuminance is measured on (horizontal illuminance: +y).
    pub normal: DVec3,
    /// Offset along `normal`, scene units.
    pub height: f64,
}

impl Grid {
    /// EN 12464-1 (2021, Annex A / 4.4) grid spacing for a side of `d` metres:
    /// p = 0.2 · 5^log10(d), at most 10 m.
    pub fn standard_spacing(d_metres: f64) -> f64 {
        (0.2 * 5f64.powf(d_metres.max(1e-9).log10())).min(10.0)
    }

    /// The points, row by row along `u` then `v`.
    pub fn points(&self) -> Vec<DVec3> {
        let [nu, nv] = self.divisions;
        let lift = self.normal * self.height;
        (0..nv)
            .flat_map(|j| {
                (0..nu).map(move |i| {
                    let s = (f64::from(i) + 0.5) / f64::from(nu);
                    let t = (f64::from(j) + 0.5) / f64::from(nv);
                    self.origin + self.u * s + self.v * t + lift
                })
            })
            .collect()
    }
}

/// Sunlight: parallel light from a direction at infinity, the sun's 0.53° disc taken as a
/// point (its shadows sharp). It shoots first, exactly, as the luminaires do.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sun {
    /// Unit direction from the scene towards the sun.
    pub towards: DVec3,
    /// Irradiance on a plane facing the sun, W/unit² per channel.
    pub irradiance: Rgb,
}

impl Sun {
    /// Irradiance on a surface of unit normal `n` when nothing is in the way: E cos θ.
    pub fn irradiance_on(&self, n: DVec3) -> Rgb {
        self.irradiance * n.dot(self.towards).max(0.0)
    }
}

/// The light from infinity, which shoots first: the sun and the sky, either or both.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Daylight {
    /// Sunlight.
    pub sun: Option<Sun>,
    /// Skylight.
    pub sky: Option<Sky>,
}

impl Daylight {
    /// Whether there is neither.
    pub fn is_none(&self) -> bool {
        self.sun.is_none() && self.sky.is_none()
    }
}

/// How a sky's radiance varies over the dome.
#[derive(Clone, Debug, PartialEq)]
pub enum SkyModel {
    /// The same radiance everywhere above the horizon.
    Uniform,
    /// The CIE standard overcast sky (Moon & Spencer 1942; CIE S 011/E:2003, sky type 1):
    /// L(θ) = L_z (1 + 2 cos θ) / 3, θ from the zenith, three times brighter at the zenith
    /// than at the horizon. The sky of daylight factors.
    CieOvercast,
    /// The CIE standard clear sky (CIE S 011/E:2003, sky type 12, Kittler, Perez & Darula
    /// 1998): brightest around the sun, darkest about 90° from it, with the gradation
    /// φ(Z) = 1 + a e^(b / cos Z) and the scattering indicatrix
    /// f(χ) = 1 + c (e^(dχ) − e^(dπ/2)) + e cos²χ, a = −1, b = −0.32, c = 10, d = −3,
    /// e = 0.45; L / L_z = f(χ) φ(Z) / (f(Z_s) φ(0)), χ the angle to the sun, Z_s its zenith
    /// angle. The sun's own disc is not in it: give a `[sun]` for that.
    CieClear {
        /// Unit direction towards the sun.
        sun: DVec3,
    },
    /// An environment map (an HDRI), over the whole sphere: its lower half is the ground's
    /// light from infinity. [`SkyModel::relative_radiance`] is its luminance.
    Map {
        /// The radiance texels.
        map: Arc<SkyMap>,
        /// Unit direction of the map's middle column, at right angles to the zenith.
        forward: DVec3,
    },
}

impl SkyModel {
    /// The radiance along unit `towards` over the zenith's (`towards` above the horizon of
    /// the unit `zenith`).
    pub fn relative_radiance(&self, towards: DVec3, zenith: DVec3) -> f64 {
        let cos_z = towards.dot(zenith);
        match *self {
            Self::Uniform => 1.0,
            Self::CieOvercast => (1.0 + 2.0 * cos_z) / 3.0,
            Self::CieClear { sun } => {
                let gradation = |cos_z: f64| if cos_z > 0.0 { 1.0 - (-0.32 / cos_z).exp() } else { 1.0 };
                let indicatrix = |chi: f64| {
                    1.0 + 10.0 * ((-3.0 * chi).exp() - (-1.5 * PI).exp()) + 0.45 * chi.cos().powi(2)
                };
                let chi = towards.dot(sun).clamp(-1.0, 1.0).acos();
                let sun_zenith = sun.dot(zenith).clamp(-1.0, 1.0).acos();
                indicatrix(chi) * gradation(cos_z) / (indicatrix(sun_zenith) * gradation(1.0))
            }
            Self::Map { ref map, forward } => map.radiance(towards, zenith, forward).luminance(),
        }
    }

    /// The irradiance on an unobstructed horizontal plane over π L_z: ∫ g(ω) cos θ dω / π,
    /// 1 for the uniform sky, 2 ∫₀¹ (1 + 2μ)/3 μ dμ = 7/9 for the overcast one; for the
    /// clear sky by the midpoint rule over 256 rings of μ = cos θ and 512 azimuths (dω = dμ dφ).
    pub fn horizontal_factor(&self, zenith: DVec3) -> f64 {
        match self {
            Self::Uniform => 1.0,
            Self::CieOvercast => 7.0 / 9.0,
            // A map's own light: its horizontal irradiance's luminance over π.
            Self::Map { map, .. } => map.horizontal_irradiance().luminance() / PI,
            Self::CieClear { .. } => {
                let (t, b) = zenith.any_orthonormal_pair();
                let (rings, around) = (256, 512);
                let mut sum = 0.0;
                for i in 0..rings {
                    let mu = (f64::from(i) + 0.5) / f64::from(rings);
                    let s = (1.0 - mu * mu).sqrt();
                    for j in 0..around {
                        let phi = 2.0 * PI * (f64::from(j) + 0.5) / f64::from(around);
                        let towards = zenith * mu + (t * phi.cos() + b * phi.sin()) * s;
                        sum += self.relative_radiance(towards, zenith) * mu;
                    }
                }
                sum * 2.0 / f64::from(rings * around)
            }
        }
    }
}

/// Skylight: diffuse light from a dome at infinity above the horizon, shooting first, by
/// shadow rays towards it, as the sun does. Below the horizon there is no sky (the ground
/// outside the model is black: model the ground to have it reflect), but for a map's lower
/// half.
#[derive(Clone, Debug, PartialEq)]
pub struct Sky {
    /// Unit direction of the zenith (the scene's up).
    pub zenith: DVec3,
    /// How its radiance varies with height.
    pub model: SkyModel,
    /// Radiance at the zenith times π, W/unit² per channel: the radiosity a surface of that
    /// radiance has, so that an unobstructed horizontal plane under a uniform sky receives
    /// it as irradiance.
    pub zenith_radiosity: Rgb,
    /// Shadow rays per element towards it (stratified over the element's hemisphere).
    pub rays: u32,
}

impl Sky {
    /// Rays per element when the scene does not say.
    pub const DEFAULT_RAYS: u32 = 64;

    /// A sky of `model` whose unobstructed horizontal irradiance is `horizontal`.
    pub fn from_horizontal(model: SkyModel, zenith: DVec3, horizontal: Rgb, rays: u32) -> Self {
        let zenith_radiosity = horizontal * (1.0 / model.horizontal_factor(zenith));
        Self { zenith, model, zenith_radiosity, rays }
    }

    /// π times the radiance seen along unit direction `towards` (0 at and below the horizon):
    /// what a ray escaping the scene that way brings, in radiosity units.
    pub fn radiosity_towards(&self, towards: DVec3) -> Rgb {
        if let SkyModel::Map { map, forward } = &self.model {
            let l = map.radiance(towards, self.zenith, *forward);
            return Rgb::new(
                l.r * self.zenith_radiosity.r,
                l.g * self.zenith_radiosity.g,
                l.b * self.zenith_radiosity.b,
            );
        }
        if towards.dot(self.zenith) > 0.0 {
            self.zenith_radiosity * self.model.relative_radiance(towards, self.zenith)
        } else {
            Rgb::ZERO
        }
    }

    /// Irradiance on an unobstructed horizontal plane facing the zenith.
    pub fn horizontal_irradiance(&self) -> Rgb {
        if let SkyModel::Map { map, .. } = &self.model {
            let e = map.horizontal_irradiance();
            let s = self.zenith_radiosity * (1.0 / PI);
            return Rgb::new(e.r * s.r, e.g * s.g, e.b * s.b);
        }
        self.zenith_radiosity * self.model.horizontal_factor(self.zenith)
    }

    /// A sky of environment map `map` (middle column towards `forward`), its radiance times
    /// `scale` per channel: `zenith_radiosity` holds π × `scale`.
    pub fn from_map(map: Arc<SkyMap>, zenith: DVec3, forward: DVec3, scale: Rgb, rays: u32) -> Self {
        Self { zenith, model: SkyModel::Map { map, forward }, zenith_radiosity: scale * PI, rays }
    }
}

/// The photometric part of a scene: its unit, luminaires and grids.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Lighting {
    /// The unit the scene's coordinates are in, when it says (`None`: metres are assumed for
    /// photometric figures).
    pub units: Option<LengthUnit>,
    /// Point luminaires.
    pub luminaires: Vec<Luminaire>,
    /// Calculation grids.
    pub grids: Vec<Grid>,
    /// Sunlight, when the scene has it.
    pub sun: Option<Sun>,
    /// Skylight, when the scene has it.
    pub sky: Option<Sky>,
}

impl Lighting {
    /// The unit, metres when none was given.
    pub fn unit(&self) -> LengthUnit {
        self.units.unwrap_or_default()
    }

    /// Whether the scene asks for photometric figures (a unit, a luminaire or a grid).
    pub fn is_photometric(&self) -> bool {
        self.units.is_some() || !self.luminaires.is_empty() || !self.grids.is_empty()
    }

    /// The light from infinity: the sun and the sky.
    pub fn daylight(&self) -> Daylight {
        Daylight { sun: self.sun, sky: self.sky.clone() }
    }

    /// Total luminaire flux, lm.
    pub fn luminaire_flux(&self) -> f64 {
        self.luminaires.iter().map(Luminaire::flux).sum()
    }

    /// Every position and direction mapped by `f`, a rotation (the scene's up axis).
    pub(crate) fn map_exactly(&mut self, f: &impl Fn(DVec3) -> DVec3) {
        for l in &mut self.luminaires {
            l.position = f(l.position);
            l.nadir = f(l.nadir);
            l.c0 = f(l.c0);
            l.c90 = f(l.c90);
        }
        if let Some(sun) = &mut self.sun {
            sun.towards = f(sun.towards);
        }
        if let Some(sky) = &mut self.sky {
            sky.zenith = f(sky.zenith);
            match &mut sky.model {
                SkyModel::CieClear { sun } => *sun = f(*sun),
                SkyModel::Map { forward, .. } => *forward = f(*forward),
                SkyModel::Uniform | SkyModel::CieOvercast => {}
            }
        }
        for g in &mut self.grids {
            g.origin = f(g.origin);
            g.u = f(g.u);
            g.v = f(g.v);
            g.normal = f(g.normal);
        }
    }
}
