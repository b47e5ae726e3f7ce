//! Enclosed shooters: a shooter whose every probe ray meets a surface sends all of its power
//! into the scene, so its shot must deliver all of it.
//!
//! A row's form factors and visibility are estimates, and their sum over a closed room falls
//! short of the Σⱼ Fᵢⱼ = 1 that an enclosure obeys (Cohen & Wallace §4.2): most of all where a
//! group's near field is lit through its points' regularised kernel, in the crevices of a
//! model (see `clusters::POINTS`). A shortfall of a fraction of a per cent per shot is
//! multiplied by 1/(1 − ρ) over the bounces: a closed room of ρ = 0.95 came out 3 % dark on
//! every wall, and a sofa of ρ = 0.95 in it 11–21 % dark on every cushion (its crevices down
//! to −90 %). So a shot from an enclosed shooter gives what its row failed to deliver back to
//! its receivers (`Tally::shoot`): a group's to the receivers in its near field, where the
//! kernel lost it; a patch's to all, in proportion. A shooter that sees out of an open scene
//! (a probe ray meets nothing) keeps its row as it is: its shortfall is light that leaves.

use glam::DVec3;
use radiosity_accel::RayQuery;

use crate::sampling::Rng;

/// Probe rays per shooter. All of them meeting a surface leaves less than 2.3 % of the
/// shooter's hemisphere open at 95 % confidence (1 − 0.05^(1/128)); the refund is capped
/// (`tally::MAX_REFUND`), so a shooter misjudged so gains at most that.
pub(super) const PROBES: usize = 128;

/// Task key of the probes' random streams.
const PROBE_STREAM: u64 = 0x656e_636c_6f73_6564;

/// Whether [`PROBES`] rays from `points` (positions and normals, taken in turn), each in a
/// cosine-distributed direction over its point's hemisphere, all meet a triangle of `accel`
/// or `hull` within `reach`. `key` picks the random stream (the shooter), so the answer is the
/// same on every run and thread count.
pub(super) fn encloses(
    accel: &dyn RayQuery,
    hull: &dyn RayQuery,
    points: &[(DVec3, DVec3)],
    reach: f64,
    seed: u64,
    key: u64,
) -> bool {
    if points.is_empty() {
        return false;
    }
    let mut rng = Rng::for_task(seed, PROBE_STREAM, key);
    (0..PROBES).all(|k| {
        let (p, n) = points[k % points.len()];
        let (t, b) = n.any_orthonormal_pair();
        let (u, v) = (rng.next_f64(), rng.next_f64());
        // Malley's method: a uniform point on the disc lifted to the hemisphere.
        let (r, phi) = (u.sqrt(), std::f64::consts::TAU * v);
        let d = t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u).max(0.0).sqrt();
        // Off the shooter's own surface by more than the segment's end margin.
        let from = p + n * (1e-6 * reach);
        let to = from + d * reach;
        let (from, to) = (from.as_vec3(), to.as_vec3());
        accel.occluded(from, to) || hull.occluded(from, to)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use radiosity_accel::Bvh;

    /// The six faces of the unit cube as triangles.
    fn cube(open_top: bool) -> Vec<[Vec3; 3]> {
        let c = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
        let quads = [
            [c(0., 0., 0.), c(1., 0., 0.), c(1., 0., 1.), c(0., 0., 1.)],
            [c(0., 1., 0.), c(1., 1., 0.), c(1., 1., 1.), c(0., 1., 1.)],
            [c(0., 0., 0.), c(0., 1., 0.), c(0., 1., 1.), c(0., 0., 1.)],
            [c(1., 0., 0.), c(1., 1., 0.), c(1., 1., 1.), c(1., 0., 1.)],
            [c(0., 0., 0.), c(1., 0., 0.), c(1., 1., 0.), c(0., 1., 0.)],
            [c(0., 0., 1.), c(1., 0., 1.), c(1., 1., 1.), c(0., 1., 1.)],
        ];
        (quads.iter().enumerate())
            .filter(|&(i, _)| !(open_top && i == 1))
            .flat_map(|(_, q)| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect()
    }

    /// From the floor of a closed box every probe meets a wall; with the lid off some leave.
    #[test]
    fn a_closed_box_encloses_its_floor_and_an_open_one_does_not() {
        let none = Bvh::new(&[]);
        let floor = [(DVec3::new(0.5, 0.0, 0.5), DVec3::Y), (DVec3::new(0.2, 0.0, 0.7), DVec3::Y)];
        let closed = Bvh::new(&cube(false));
        assert!(encloses(&closed, &none, &floor, 4.0, 1, 0));
        assert!(encloses(&none, &closed, &floor, 4.0, 1, 0), "hull triangles count too");
        let open = Bvh::new(&cube(true));
        assert!(!encloses(&open, &none, &floor, 4.0, 1, 0));
        assert!(!encloses(&closed, &none, &[], 4.0, 1, 0), "no points: not known to be enclosed");
    }
}
