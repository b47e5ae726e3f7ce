//! Picture statistics for regression tests and reports: what a picture says per object.

use radiosity_core::Rgb;

use crate::{HdrImage, Rendering};

/// Mean radiance of the pixels that show one object.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ObjectPixels {
    /// Mean radiance over those pixels, W·sr⁻¹/unit² per channel.
    pub mean_radiance: Rgb,
    /// How many pixels.
    pub pixels: usize,
}

/// Per object (index into `Mesh::object_names`, `object_count` of them), the mean radiance of
/// the pixels *inside* its silhouette: pixels whose centre ray hits the object and whose eight
/// neighbours' centre rays hit it too. `None` for an object with no such pixel.
///
/// Edge pixels are left out because their jittered samples mix the object with whatever lies
/// beside it; keeping them would make the statistic depend on the sampling, not on the light.
/// The diagonal neighbours count too: next to an emitter's corner a pixel whose four side
/// neighbours are all ceiling still has samples on the lamp, a thousand times brighter, and
/// a handful of such pixels moved the Cornell ceiling's mean by 2–3 % from seed to seed.
pub fn object_mean_radiance(rendering: &Rendering, object_count: usize) -> Vec<Option<ObjectPixels>> {
    let img = &rendering.radiance;
    let (w, h) = (img.width() as usize, img.height() as usize);
    let ids = &rendering.object_ids;
    let mut sums = vec![(Rgb::ZERO, 0usize); object_count];
    for y in 1..h.saturating_sub(1) {
        for x in 1..w.saturating_sub(1) {
            let i = y * w + x;
            let Some(id) = ids[i] else { continue };
            let interior = [i - w - 1, i - w, i - w + 1, i - 1, i + 1, i + w - 1, i + w, i + w + 1]
                .iter()
                .all(|&j| ids[j] == Some(id));
            if interior && (id as usize) < object_count {
                let s = &mut sums[id as usize];
                s.0 += img.pixels()[i];
                s.1 += 1;
            }
        }
    }
    sums.into_iter()
        .map(|(sum, n)| (n > 0).then(|| ObjectPixels { mean_radiance: sum / n as f64, pixels: n }))
        .collect()
}

/// Per-pixel absolute difference `|a − b|`, channel-wise: the "difference" picture a failing
/// image test writes next to the actual and expected ones.
///
/// # Panics
/// When the two pictures differ in size.
pub fn difference_image(a: &HdrImage, b: &HdrImage) -> HdrImage {
    assert_eq!((a.width(), a.height()), (b.width(), b.height()), "pictures differ in size");
    let pixels = a.pixels().iter().zip(b.pixels()).map(|(p, q)| (*p - *q).abs()).collect();
    HdrImage::from_pixels(a.width(), a.height(), pixels)
}
