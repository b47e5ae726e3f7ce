//! Stratified points on patches (the seeded streams are `radiosity_core::random`).
//!
//! Every stochastic choice draws from a stream keyed by `(seed, shooter, element)`, never by
//! a thread, so one thread and many give bit-identical results.

use glam::{DVec3, Vec3A};
pub(crate) use radiosity_core::random::{Rng, four_units};

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

/// Strata for `count` samples in the unit square: `columns × rows = count` cells, one sample
/// each, with the columns the smallest divisor of `count` not below √count (12 samples:
/// 4 × 3, 8: 4 × 2, a prime: one row). Every cell must hold a sample or the estimate is
/// biased: a square `k × k` grid for every count, as this was once, left the last quarter
/// of both patches unsampled with 12 samples on 4 × 4, and ⌈√count⌉ columns with as many
/// rows as it takes, as it was next, left the corner cell empty with 8 samples on 3 × 3
/// (a block side 2 % too bright against 64 rays).
///
/// Samples come row after row; each call to [`Strata::next`] moves to the next stratum
/// (counters, not a division per sample: rays are cheap enough for that to show).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Strata {
    count: u32,
    columns: u32,
    rows: u32,
    scale: (f32, f32),
    at: (u32, u32),
}

impl Strata {
    /// The grid for `count` samples (at least one cell), at its first stratum.
    pub(crate) fn new(count: u32) -> Self {
        let count = count.max(1);
        let columns = (1..=count).find(|&c| c * c >= count && count.is_multiple_of(c)).unwrap_or(count);
        let rows = count / columns;
        Self { count, columns, rows, scale: (1.0 / columns as f32, 1.0 / rows as f32), at: (0, 0) }
    }

    /// How many samples it was made for.
    pub(crate) fn count(&self) -> u32 {
        self.count
    }

    /// The current stratum's cell `(column, row)`; then moves on to the next.
    pub(crate) fn next(&mut self) -> (u32, u32) {
        let cell = self.at;
        self.at.0 += 1;
        if self.at.0 == self.columns {
            self.at = (0, (self.at.1 + 1) % self.rows);
        }
        cell
    }

    /// A jittered point of `cell`, in [0, 1)².
    pub(crate) fn jitter(&self, cell: (u32, u32), rng: &mut Rng) -> (f32, f32) {
        let (a, b) = rng.next_f32_pair();
        let u = ((cell.0 as f32 + a) * self.scale.0).min(ONE_BELOW);
        (u, ((cell.1 as f32 + b) * self.scale.1).min(ONE_BELOW))
    }
}

/// The largest f32 below 1: a jittered coordinate rounded up to 1 is clamped back into its
/// cell's half-open range.
pub(crate) const ONE_BELOW: f32 = 1.0 - f32::EPSILON / 2.0;

/// The point at `(u, v)` ∈ [0,1)² on a triangle or convex quad in single precision: the map
/// of [`point_on`], for ray origins that are traced in single precision anyway.
pub(crate) fn point_on_f32(poly: &[Vec3A], u: f32, v: f32) -> Vec3A {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Every cell of the grid holds exactly one sample, for every count.
    #[test]
    fn strata_cover_the_square_for_every_count() {
        let mut rng = Rng::for_task(1, 2, 3);
        for count in 1..=40u32 {
            let mut strata = Strata::new(count);
            let (c, r) = (strata.columns as usize, strata.rows as usize);
            let mut cells = vec![0u32; c * r];
            for _ in 0..count {
                let cell = strata.next();
                let (u, v) = strata.jitter(cell, &mut rng);
                assert!((0.0..1.0).contains(&u) && (0.0..1.0).contains(&v), "count {count}: ({u}, {v})");
                cells[(v * r as f32) as usize * c + (u * c as f32) as usize] += 1;
            }
            for row in 0..r {
                assert!(
                    cells[row * c..(row + 1) * c].iter().any(|&n| n > 0),
                    "count {count}: row {row} empty"
                );
            }
            for col in 0..c.min(count as usize) {
                assert!((0..r).any(|row| cells[row * c + col] > 0), "count {count}: column {col} empty");
            }
            assert_eq!(c * r, count as usize, "count {count}: {c} × {r}");
            assert!(cells.iter().all(|&n| n == 1), "count {count}: {cells:?}");
            assert!(c >= r, "count {count}: {c} × {r}");
        }
    }
}
