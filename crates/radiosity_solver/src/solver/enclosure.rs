//! Enclosed and open shooters: a shooter whose every probe ray meets a surface sends all of its
//! power into the scene, so its shot must deliver all of it; one some of whose probe rays
//! leave must deliver the share that does not leave.
//!
//! A row's form factors and visibility are estimates, and their sum over a closed room falls
//! short of the Σⱼ Fᵢⱼ = 1 that an enclosure obeys (Cohen & Wallace §4.2): most of all where a
//! group's near field is lit through its points' regularised kernel, in the crevices of a
//! model (see `clusters::POINTS`). A shortfall of a fraction of a per cent per shot is
//! multiplied by 1/(1 − ρ) over the bounces: a closed room of ρ = 0.95 came out 3 % dark on
//! every wall, and a sofa of ρ = 0.95 in it 11–21 % dark on every cushion (its crevices down
//! to −90 %). So a shot from an enclosed shooter gives what its row failed to deliver back to
//! its receivers (`Tally::shoot`): a group's to the receivers in its near field, where the
//! kernel lost it; a patch's to all, in proportion.
//!
//! In a room with an opening (a window, an open side) the same rows fall short by the same
//! kernel, and the sofa stayed 8–10 % dark: so a shooter that sees out and does not emit is
//! probed again, with enough rays to measure the share of its light that leaves
//! ([`Probes::escaping_share`]), and its shot delivers the rest; a row within twice the probes'
//! standard error of it is taken as it is. An emitter that sees out keeps its row: it is
//! drawn with many rays, and its probes' noise would move the largest shot of the solve.
use glam::DVec3;
use radiosity_accel::RayQuery;

use crate::sampling::Rng;

/// Probe rays per shooter. All of them meeting a surface leaves less than 2.3 % of the
/// shooter's hemisphere open at 95 % confidence (1 − 0.05^(1/128)); the refund is capped
/// (`tally::MAX_REFUND`), so a shooter misjudged so gains at most that.
pub(super) const PROBES: usize = 128;

/// Task key of the probes' random streams.
const PROBE_STREAM: u64 = 0x656e_636c_6f73_6564;

/// Probe rays cast into a scene: its ray structure and the triangles it leaves out (`hull`),
/// how far they reach, and the solve's seed.
pub(super) struct Probes<'a> {
    /// The scene's ray structure.
    pub(super) accel: &'a dyn RayQuery,
    /// The occluder triangles `accel` leaves out (see `occluders::hull_triangles`).
    pub(super) hull: &'a dyn RayQuery,
    /// How far a probe ray reaches.
    pub(super) reach: f64,
    /// The solve's seed.
    pub(super) seed: u64,
}

impl Probes<'_> {
    /// Whether [`PROBES`] rays from `points` (positions and normals, taken in turn), each in a
    /// cosine-distributed direction over its point's hemisphere, all meet a triangle of `accel` or
    /// `hull` within `reach`. `key` picks the random stream (the shooter), so the answer is the
    /// same on every run and thread count.
    pub(super) fn encloses(&self, points: &[(DVec3, DVec3)], key: u64) -> bool {
        !points.is_empty() && self.escaping(points, Rng::for_task(self.seed, PROBE_STREAM, key), PROBES) == 0
    }

    /// The share of an open shooter's power that leaves the scene, estimated by probe rays as in
    /// [`Self::encloses`] from its own stream (`key`): the form factor from a point to what it sees
    /// is the cosine-weighted share of its hemisphere that meets it (Nusselt's analogue, Cohen &
    /// Wallace §4.4), so the share of cosine-distributed rays that meet nothing is the share of its
    /// light that leaves. At least [`SHARE_PROBES`] rays, more where a share p needs them for a
    /// standard error √(p(1 − p)/n) of [`SHARE_ERROR`], up to [`MAX_SHARE_PROBES`]; a share of 0.25
    /// so takes 1 920 rays (whole chunks of [`SHARE_CHUNK`]). Returns the share and its standard
    /// error.
    pub(super) fn escaping_share(&self, points: &[(DVec3, DVec3)], key: u64) -> (f64, f64) {
        // Chunks of rays with streams of their own, traced in parallel: a count is the same
        // whatever thread traced which chunk.
        let count = |chunks: std::ops::Range<usize>| -> usize {
            use rayon::prelude::*;
            chunks
                .into_par_iter()
                .map(|c| {
                    let rng = Rng::for_task(self.seed, SHARE_STREAM ^ key, c as u64);
                    self.escaping(points, rng, SHARE_CHUNK)
                })
                .sum()
        };
        let first_chunks = SHARE_PROBES / SHARE_CHUNK;
        let first = count(0..first_chunks);
        let p = first as f64 / SHARE_PROBES as f64;
        let wanted = (p * (1.0 - p) / (SHARE_ERROR * SHARE_ERROR)).ceil() as usize;
        let chunks = wanted.clamp(SHARE_PROBES, MAX_SHARE_PROBES).div_ceil(SHARE_CHUNK);
        let n = chunks * SHARE_CHUNK;
        let p = (first + count(first_chunks..chunks)) as f64 / n as f64;
        (p, (p * (1.0 - p) / n as f64).sqrt())
    }

    /// How many of `probes` rays from `points` (taken in turn), in cosine-distributed directions
    /// drawn from `rng`, meet no triangle of `accel` or `hull` within `reach`.
    fn escaping(&self, points: &[(DVec3, DVec3)], mut rng: Rng, probes: usize) -> usize {
        if points.is_empty() {
            return probes;
        }
        let (accel, hull, reach) = (self.accel, self.hull, self.reach);
        (0..probes)
            .filter(|&k| {
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
                !(accel.occluded(from, to) || hull.occluded(from, to))
            })
            .count()
    }
}

/// Probe rays of one random stream of [`Probes::escaping_share`], traced as one task.
const SHARE_CHUNK: usize = 128;

/// Probe rays of [`Probes::escaping_share`] before it judges how many it needs.
const SHARE_PROBES: usize = 512;

/// The standard error [`Probes::escaping_share`] aims at.
const SHARE_ERROR: f64 = 0.01;

/// The most probe rays [`Probes::escaping_share`] traces (a share of one half: 1.1 %).
const MAX_SHARE_PROBES: usize = 2048;

/// Task key of the escaping share's random streams.
const SHARE_STREAM: u64 = 0x6573_6361_7065_7321;

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;
    use radiosity_accel::Bvh;

    /// Probes of seed 1 reaching 4 units into `accel` and `hull`.
    fn probes<'a>(accel: &'a Bvh, hull: &'a Bvh) -> Probes<'a> {
        Probes { accel, hull, reach: 4.0, seed: 1 }
    }

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
        assert!(probes(&closed, &none).encloses(&floor, 0));
        assert!(probes(&none, &closed).encloses(&floor, 0), "hull triangles count too");
        let open = Bvh::new(&cube(true));
        assert!(!probes(&open, &none).encloses(&floor, 0));
        assert!(!probes(&closed, &none).encloses(&[], 0), "no points: not known to be enclosed");
    }

    /// From the floor's centre of a unit cube with its lid off, the light that leaves is the form
    /// factor to the opening, a coaxial parallel square at height 1: four rectangles of ½ × ½ with
    /// a corner above the point, each (1/2π)[A/√(1+A²) atan(B/√(1+A²)) + B/√(1+B²) atan(A/√(1+B²))]
    /// with A = B = ½ (Howell, catalogue B-3), 0.2394 in all. The estimate's standard error is
    /// about 1 %: asserted within three of it, and the error it reports within a tenth of √(p(1 −
    /// p)/n).
    #[test]
    fn an_open_box_lets_out_the_form_factor_of_its_opening() {
        let (a, b) = (0.5f64, 0.5f64);
        let quarter = (a / (1.0 + a * a).sqrt() * (b / (1.0 + a * a).sqrt()).atan()
            + b / (1.0 + b * b).sqrt() * (a / (1.0 + b * b).sqrt()).atan())
            / std::f64::consts::TAU;
        let exact = 4.0 * quarter;
        assert!((exact - 0.2394).abs() < 1e-4, "{exact}");
        let open = Bvh::new(&cube(true));
        let none = Bvh::new(&[]);
        let floor = [(DVec3::new(0.5, 0.0, 0.5), DVec3::Y)];
        for seed in 1..4 {
            let (share, error) = Probes { seed, ..probes(&open, &none) }.escaping_share(&floor, 0);
            assert!((share - exact).abs() < 3.0 * error, "seed {seed}: {share} ± {error} against {exact}");
            let n = (exact * (1.0 - exact) / (SHARE_ERROR * SHARE_ERROR)).ceil();
            assert!((error - (exact * (1.0 - exact) / n).sqrt()).abs() < 0.1 * error, "{error}");
        }
        let closed = Bvh::new(&cube(false));
        assert_eq!(
            probes(&closed, &none).escaping_share(&floor, 0),
            (0.0, 0.0),
            "nothing leaves a closed box"
        );
    }
}
