//! A linear high-dynamic-range picture: radiance per pixel, nothing display-encoded.

use radiosity_core::Rgb;

/// A picture of linear radiance (W·sr⁻¹ per unit², per channel), top row first, left to right.
///
/// Values are stored as they were computed: never clamped, never gamma-encoded. Display
/// encoding happens once, in [`crate::tone_map_image`].
#[derive(Clone, Debug, PartialEq)]
pub struct HdrImage {
    width: u32,
    height: u32,
    pixels: Vec<Rgb>,
}

impl HdrImage {
    /// A black picture of `width × height` pixels (either may be 0).
    pub fn new(width: u32, height: u32) -> Self {
        Self { width, height, pixels: vec![Rgb::ZERO; width as usize * height as usize] }
    }

    /// A picture from its pixels, top row first.
    ///
    /// # Panics
    /// When `pixels.len() != width * height` (a bug in the caller).
    pub fn from_pixels(width: u32, height: u32, pixels: Vec<Rgb>) -> Self {
        assert_eq!(pixels.len(), width as usize * height as usize, "pixel count must be width × height");
        Self { width, height, pixels }
    }

    /// A picture whose pixel `(x, y)` (x to the right, y down from the top row) is `f(x, y)`.
    pub fn from_fn(width: u32, height: u32, f: impl Fn(u32, u32) -> Rgb) -> Self {
        let pixels =
            (0..height).flat_map(|y| (0..width).map(move |x| (x, y))).map(|(x, y)| f(x, y)).collect();
        Self { width, height, pixels }
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// All pixels, top row first.
    pub fn pixels(&self) -> &[Rgb] {
        &self.pixels
    }

    /// All pixels, mutable, top row first.
    pub fn pixels_mut(&mut self) -> &mut [Rgb] {
        &mut self.pixels
    }

    /// Pixel `(x, y)`, y down from the top row.
    ///
    /// # Panics
    /// When `(x, y)` is outside the picture.
    pub fn pixel(&self, x: u32, y: u32) -> Rgb {
        assert!(x < self.width && y < self.height, "pixel ({x}, {y}) outside {}×{}", self.width, self.height);
        self.pixels[y as usize * self.width as usize + x as usize]
    }

    /// Sets pixel `(x, y)`.
    ///
    /// # Panics
    /// When `(x, y)` is outside the picture.
    pub fn set_pixel(&mut self, x: u32, y: u32, value: Rgb) {
        assert!(x < self.width && y < self.height, "pixel ({x}, {y}) outside {}×{}", self.width, self.height);
        self.pixels[y as usize * self.width as usize + x as usize] = value;
    }

    /// Log-average (geometric mean) luminance of the pixels whose luminance is > 0
    /// (Reinhard et al. 2002, eq. 1), or `None` when there is none.
    ///
    /// Pixels of zero luminance — background seen through an open side, or the unlit back of
    /// a surface — are left out rather than offset by a small δ: they carry no information
    /// about how bright the lit scene is, and a δ would make the result depend on how much
    /// background the camera happens to see. Near-black pixels do still count here, as the
    /// plain statistic; the automatic exposure ([`crate::auto_exposure_ev`]) meters the lit
    /// pixels only.
    pub fn log_average_luminance(&self) -> Option<f64> {
        let (sum, count) = self
            .pixels
            .iter()
            .map(|p| p.luminance())
            .filter(|l| l.is_finite() && *l > 0.0)
            .fold((0.0, 0usize), |(s, n), l| (s + l.ln(), n + 1));
        (count > 0).then(|| (sum / count as f64).exp())
    }
}
