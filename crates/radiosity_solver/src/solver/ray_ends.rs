//! Where a shooter's rays end: one jittered point per cell of a [`TARGETS`] × [`TARGETS`]
//! grid over the unit square, mapped onto the shooter by its unshot power at its first shot
//! (see [`super::first_shots`]). A ray's stratified `(u, v)` picks its cell's point, so the
//! rays keep their stratification and cost a lookup each instead of a draw. (Receivers near
//! the shooter draw theirs afresh by the form factor instead, see `near_runs::NearEnds`.)

use glam::{DVec3, Vec3};

use super::elements::ShooterElement;
use crate::sampling::{Rng, point_on};

/// Ray-end cells per side of the unit square: 256 points on each shooter, far more than the
/// 4 to 16 rays of one receiver.
pub(super) const TARGETS: usize = 16;

/// Fills `targets` with the ray ends on the shooter (key `stream`, elements `elements` with
/// cumulative shares `cdf`) and `lifted` with the same points lifted by `lift` in single
/// precision, as the rays take them. The jitter comes from the shooter's own stream, so every
/// shot of it gets the same ends.
pub(super) fn draw_ray_ends(
    seed: u64,
    stream: u64,
    cdf: &[f64],
    elements: &[ShooterElement],
    lift: DVec3,
    targets: &mut Vec<DVec3>,
    lifted: &mut Vec<Vec3>,
) {
    let mut rng = Rng::for_task(seed, stream, u64::MAX);
    targets.clear();
    for b in 0..TARGETS {
        for a in 0..TARGETS {
            let u = (a as f64 + rng.next_f64()) / TARGETS as f64;
            let v = (b as f64 + rng.next_f64()) / TARGETS as f64;
            targets.push(shooter_point(cdf, elements, u, v));
        }
    }
    lifted.clear();
    lifted.extend(targets.iter().map(|t| (*t + lift).as_vec3()));
}

/// The point at `(u, v)` ∈ [0,1)² on the shooter, drawn by unshot power: `u` picks the
/// element from the cumulative shares and, rescaled into that element's share, places the
/// point within it with `v`, so stratification in `(u, v)` carries over.
pub(super) fn shooter_point(cdf: &[f64], elements: &[ShooterElement], u: f64, v: f64) -> DVec3 {
    let k = cdf.partition_point(|&c| c <= u).min(cdf.len() - 1);
    let below = if k == 0 { 0.0 } else { cdf[k - 1] };
    let share = cdf[k] - below;
    let u = if share > 0.0 { ((u - below) / share).clamp(0.0, 1.0 - f64::EPSILON) } else { 0.5 };
    point_on(elements[k].corners(), u, v)
}

/// Index in the ray-end table of the cell that holds `(u, v)` ∈ [0,1)².
pub(super) fn target_cell(u: f32, v: f32) -> usize {
    let cell = |x: f32| ((x * TARGETS as f32) as u32).min(TARGETS as u32 - 1) as usize;
    cell(v) * TARGETS + cell(u)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x: f64, width: f64) -> ShooterElement {
        let corners = [
            DVec3::new(x, 0.0, 0.0),
            DVec3::new(x + width, 0.0, 0.0),
            DVec3::new(x + width, 1.0, 0.0),
            DVec3::new(x, 1.0, 0.0),
        ];
        let centre = DVec3::new(x + 0.5 * width, 0.5, 0.0);
        ShooterElement { corners, count: 4, centre, radius: 0.5 * (1.0 + width * width).sqrt(), area: width }
    }

    /// Cells are row after row, `u` along a row; every `(u, v)` of a cell maps to it, the
    /// edges included, and values at (or rounded up to) 1 stay in the last cell.
    #[test]
    fn ray_end_cells_tile_the_square() {
        assert_eq!(target_cell(0.0, 0.0), 0);
        assert_eq!(target_cell(0.999, 0.0), TARGETS - 1);
        assert_eq!(target_cell(0.0, 0.999), TARGETS * (TARGETS - 1));
        assert_eq!(target_cell(1.0, 1.0), TARGETS * TARGETS - 1);
        let step = 1.0 / TARGETS as f32;
        for b in 0..TARGETS {
            for a in 0..TARGETS {
                for (du, dv) in [(0.0, 0.0), (0.5, 0.5), (0.99, 0.01)] {
                    let (u, v) = ((a as f32 + du) * step, (b as f32 + dv) * step);
                    assert_eq!(target_cell(u, v), b * TARGETS + a, "({u}, {v})");
                }
            }
        }
    }

    /// Ray ends follow the unshot power: with all of it on the second of two elements, every
    /// end lies on that one, spread over it; with an even spread, each element gets ends in
    /// proportion to its area. The table is the same on every call (the shooter's stream).
    #[test]
    fn ray_ends_follow_the_unshot_power() {
        let elements = [square(0.0, 1.0), square(1.0, 3.0)];
        let (mut targets, mut lifted) = (Vec::new(), Vec::new());
        let lift = DVec3::Z * 0.5;
        draw_ray_ends(0, 7, &[0.0, 1.0], &elements, lift, &mut targets, &mut lifted);
        assert_eq!(targets.len(), TARGETS * TARGETS);
        assert!(targets.iter().all(|t| t.x >= 1.0 && t.x <= 4.0));
        let (lo, hi) = targets.iter().fold((f64::MAX, f64::MIN), |(lo, hi), t| (lo.min(t.x), hi.max(t.x)));
        assert!(lo < 1.2 && hi > 3.8, "{lo}..{hi}");
        assert!(lifted.iter().zip(&targets).all(|(l, t)| (l.as_dvec3() - (*t + lift)).length() < 1e-6));
        draw_ray_ends(0, 7, &[0.25, 1.0], &elements, lift, &mut targets, &mut lifted);
        let on_first = targets.iter().filter(|t| t.x < 1.0).count();
        assert_eq!(on_first, TARGETS * TARGETS / 4);
        let again = targets.clone();
        draw_ray_ends(0, 7, &[0.25, 1.0], &elements, lift, &mut targets, &mut lifted);
        assert_eq!(targets, again);
        draw_ray_ends(0, 8, &[0.25, 1.0], &elements, lift, &mut targets, &mut lifted);
        assert_ne!(targets, again, "another shooter, another jitter");
    }
}
