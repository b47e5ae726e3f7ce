//! Seeded random streams and stratified points on patches.
//!
//! Every stochastic choice draws from a stream keyed by `(seed, shooter, element)`, never by
//! a thread, so one thread and many give bit-identical results.

use glam::DVec3;

/// SplitMix64 finaliser (Steele, Lea & Flood 2014): a strong 64-bit mix.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A small SplitMix64 stream.
pub(crate) struct Rng(u64);

impl Rng {
    /// The stream for one `(seed, task, element)` task.
    pub(crate) fn for_task(seed: u64, task: u64, element: u64) -> Self {
        Rng(mix(seed ^ mix(task ^ mix(element))))
    }

    /// A uniform number in [0, 1).
    pub(crate) fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        (mix(self.0) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The point at `(u, v)` ∈ [0,1)² on a triangle (area-uniform, Shirley's square-to-triangle
/// map) or a convex quad (bilinear).
pub(crate) fn point_on(poly: &[DVec3], u: f64, v: f64) -> DVec3 {
    if poly.len() == 4 {
        poly[0] * ((1.0 - u) * (1.0 - v))
            + poly[1] * (u * (1.0 - v))
            + poly[2] * (u * v)
            + poly[3] * ((1.0 - u) * v)
    } else {
        let s = u.sqrt();
        poly[0] * (1.0 - s) + poly[1] * (s * (1.0 - v)) + poly[2] * (s * v)
    }
}

/// Stratum `(i, j)` of a `k × k` grid for sample `index` of `count`, jittered by `rng`.
pub(crate) fn stratified(index: u32, count: u32, rng: &mut Rng) -> (f64, f64) {
    let k = (count as f64).sqrt().ceil().max(1.0) as u32;
    let (i, j) = (index % k, (index / k) % k);
    ((i as f64 + rng.next_f64()) / k as f64, (j as f64 + rng.next_f64()) / k as f64)
}
