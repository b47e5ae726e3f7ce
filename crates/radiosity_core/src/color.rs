//! Linear RGB triples for radiometric quantities (radiosity W/m², power W, reflectance).

use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Sub, SubAssign};

/// A linear RGB triple: radiosity, radiance, power or reflectance, one value per channel.
///
/// Never gamma-encoded: display encoding happens once, at the very end of a display path.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Rgb {
    /// Red channel.
    pub r: f64,
    /// Green channel.
    pub g: f64,
    /// Blue channel.
    pub b: f64,
}

impl Rgb {
    /// All channels zero.
    pub const ZERO: Rgb = Rgb::splat(0.0);
    /// All channels one.
    pub const ONE: Rgb = Rgb::splat(1.0);

    /// A triple from its three channels.
    pub const fn new(r: f64, g: f64, b: f64) -> Self {
        Self { r, g, b }
    }

    /// The same value in every channel.
    pub const fn splat(v: f64) -> Self {
        Self::new(v, v, v)
    }

    /// A triple from an array `[r, g, b]`.
    pub const fn from_array(a: [f64; 3]) -> Self {
        Self::new(a[0], a[1], a[2])
    }

    /// The channels as an array `[r, g, b]`.
    pub const fn to_array(self) -> [f64; 3] {
        [self.r, self.g, self.b]
    }

    /// Sum of the three channels (used for "total power" over the spectrum).
    pub fn sum(self) -> f64 {
        self.r + self.g + self.b
    }

    /// Rec. 709 / sRGB relative luminance Y of a linear triple.
    pub fn luminance(self) -> f64 {
        0.2126 * self.r + 0.7152 * self.g + 0.0722 * self.b
    }

    /// Largest channel.
    pub fn max_channel(self) -> f64 {
        self.r.max(self.g).max(self.b)
    }

    /// Smallest channel.
    pub fn min_channel(self) -> f64 {
        self.r.min(self.g).min(self.b)
    }

    /// True when every channel is finite (not NaN, not infinite).
    pub fn is_finite(self) -> bool {
        self.r.is_finite() && self.g.is_finite() && self.b.is_finite()
    }

    /// Channel-wise absolute value.
    pub fn abs(self) -> Self {
        Self::new(self.r.abs(), self.g.abs(), self.b.abs())
    }

    /// Applies `f` to every channel.
    pub fn map(self, f: impl Fn(f64) -> f64) -> Self {
        Self::new(f(self.r), f(self.g), f(self.b))
    }

    /// Applies `f` to every pair of channels of `self` and `o` (`a.zip_map(b, f64::max)`: the
    /// channel-wise maximum).
    pub fn zip_map(self, o: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        Self::new(f(self.r, o.r), f(self.g, o.g), f(self.b, o.b))
    }
}

impl Add for Rgb {
    type Output = Rgb;
    fn add(self, o: Rgb) -> Rgb {
        Rgb::new(self.r + o.r, self.g + o.g, self.b + o.b)
    }
}
impl AddAssign for Rgb {
    fn add_assign(&mut self, o: Rgb) {
        *self = *self + o;
    }
}
impl Sub for Rgb {
    type Output = Rgb;
    fn sub(self, o: Rgb) -> Rgb {
        Rgb::new(self.r - o.r, self.g - o.g, self.b - o.b)
    }
}
impl SubAssign for Rgb {
    fn sub_assign(&mut self, o: Rgb) {
        *self = *self - o;
    }
}
impl Mul for Rgb {
    type Output = Rgb;
    fn mul(self, o: Rgb) -> Rgb {
        Rgb::new(self.r * o.r, self.g * o.g, self.b * o.b)
    }
}
impl Mul<f64> for Rgb {
    type Output = Rgb;
    fn mul(self, s: f64) -> Rgb {
        Rgb::new(self.r * s, self.g * s, self.b * s)
    }
}
impl MulAssign<f64> for Rgb {
    fn mul_assign(&mut self, s: f64) {
        *self = *self * s;
    }
}
impl Div<f64> for Rgb {
    type Output = Rgb;
    fn div(self, s: f64) -> Rgb {
        Rgb::new(self.r / s, self.g / s, self.b / s)
    }
}
impl std::iter::Sum for Rgb {
    fn sum<I: Iterator<Item = Rgb>>(iter: I) -> Rgb {
        iter.fold(Rgb::ZERO, |a, b| a + b)
    }
}
