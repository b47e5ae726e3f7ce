//! The shooter's runs of elements as its near receivers weigh them: a receiver near the
//! shooter draws its ray ends by the form factor kernel over runs of the shooter's elements
//! ([`NearEnds`], used by `rays`), and the runs are laid out once per row ([`NearRuns`]).

use glam::{DVec3, Vec4};

use super::elements::ShooterElement;

/// The ray ends of a receiver near the shooter, drawn in proportion to the point-to-point
/// form factor kernel cos θ cos θ' / r² from the receiver's centre (Cohen & Wallace §4.9)
/// times each shooter element's share of the shooter's unshot power (see `first_shots`).
///
/// The fraction of unblocked rays is then the visibility as the form factor counts it:
/// Σ_k F_k V_k / Σ_k F_k over the parts k of the shooter. Ends drawn by area alone count
/// every part by its area instead. Far from the shooter the two agree; near it they do not.
/// A facet between two shelves, a few centimetres from the wall behind them, sees the wall
/// between the shelves under a large form factor and the wall above and below them (hidden
/// by the shelves) under a small one; drawn by area, most of its rays went to the hidden
/// part, and the facets on a furnished room's shelves came out 5–7 % dark.
pub(super) struct NearEnds {
    /// Cumulative kernel × unshot share over runs of consecutive shooter elements.
    cumulative: [f64; RUNS],
    /// Runs in use.
    runs: usize,
    /// Elements per run (the last may hold fewer).
    per_run: usize,
}

/// Most runs of shooter elements a near receiver weighs: a shooter of more elements is cut
/// into this many runs of consecutive ones (pieces of its rows: small beside the distance).
const RUNS: usize = 256;

/// The shooter's runs of elements as every near receiver weighs them (see [`NearEnds`]),
/// laid out once per row: each run's middle element's centre about the shooter's centre
/// and its share of the unshot power, in single precision, coordinate by coordinate.
#[derive(Default)]
pub(super) struct NearRuns {
    origin: DVec3,
    /// Four runs to a lane group; the last group is padded with runs of no share.
    x: Vec<Vec4>,
    y: Vec<Vec4>,
    z: Vec<Vec4>,
    share: Vec<Vec4>,
    runs: usize,
    per_run: usize,
}

impl NearRuns {
    /// Lays out the runs of `elements`, whose cumulative unshot shares are `cdf`, about
    /// `origin`.
    pub(super) fn load(&mut self, elements: &[ShooterElement], cdf: &[f64], origin: DVec3) {
        let per_run = elements.len().div_ceil(RUNS).max(1);
        let runs = elements.len().div_ceil(per_run);
        (self.origin, self.per_run, self.runs) = (origin, per_run, runs);
        let groups = runs.div_ceil(4);
        for v in [&mut self.x, &mut self.y, &mut self.z, &mut self.share] {
            v.clear();
            v.resize(groups, Vec4::ZERO);
        }
        for r in 0..runs {
            let (first, end) = (r * per_run, ((r + 1) * per_run).min(elements.len()));
            let (below, above) = shares(cdf, first..end);
            let c = (elements[(first + end) / 2].centre - origin).as_vec3();
            let (g, lane) = (r / 4, r % 4);
            self.x[g][lane] = c.x;
            self.y[g][lane] = c.y;
            self.z[g][lane] = c.z;
            self.share[g][lane] = (above - below) as f32;
        }
    }

    /// The kernel's table for a receiver centred at `centre` with normal `n`, of a shooter
    /// with normal `ns`, or `None` when it sees none of the shooter. The caller has checked
    /// that the receiver is near and small enough for its centre to stand for it.
    pub(super) fn weigh(&self, centre: DVec3, n: DVec3, ns: DVec3) -> Option<NearEnds> {
        let (n, ns) = (n.as_vec3(), ns.as_vec3());
        let p = (centre - self.origin).as_vec3();
        let runs = self.runs;
        // Four runs at a time in single precision, then summed in order: a near receiver of
        // a wall patch weighed a hundred runs one by one in double precision, and that was
        // a twentieth of a furnished room's solve.
        let mut cumulative = [0.0; RUNS];
        let mut total = 0.0;
        let lanes = self.x.iter().zip(&self.y).zip(&self.z).zip(&self.share);
        for (four, out) in lanes.zip(cumulative[..runs].chunks_mut(4)) {
            let (((x, y), z), share) = four;
            let d = [*x - Vec4::splat(p.x), *y - Vec4::splat(p.y), *z - Vec4::splat(p.z)];
            let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let cos_r = (d[0] * n.x + d[1] * n.y + d[2] * n.z).max(Vec4::ZERO);
            let cos_s = (-(d[0] * ns.x + d[1] * ns.y + d[2] * ns.z)).max(Vec4::ZERO);
            let live = r2.cmpgt(Vec4::ZERO);
            let terms = Vec4::select(
                live,
                *share * cos_r * cos_s / Vec4::select(live, r2 * r2, Vec4::ONE),
                Vec4::ZERO,
            );
            for (c, t) in out.iter_mut().zip(terms.to_array()) {
                total += f64::from(t);
                *c = total;
            }
        }
        (total > 0.0 && total.is_finite()).then_some(NearEnds { cumulative, runs, per_run: self.per_run })
    }
}

impl NearEnds {
    /// The range of the shooter's cumulative shares (see `ray_ends::shooter_point`) of the
    /// run at `t` ∈ [0, 1) of the kernel's mass.
    pub(super) fn run(&self, t: f32, cdf: &[f64]) -> (f64, f64) {
        let cumulative = &self.cumulative[..self.runs];
        let at = f64::from(t) * cumulative[self.runs - 1];
        let r = cumulative.partition_point(|&c| c <= at).min(self.runs - 1);
        shares(cdf, r * self.per_run..((r + 1) * self.per_run).min(cdf.len()))
    }
}

/// The cumulative shares below and at the end of the shooter elements `run` (not empty).
fn shares(cdf: &[f64], run: std::ops::Range<usize>) -> (f64, f64) {
    (if run.start == 0 { 0.0 } else { cdf[run.start - 1] }, cdf[run.end - 1])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::elements::unit_squares;

    /// A shooter of more elements than [`RUNS`] is cut into runs of consecutive ones: each
    /// run carries its elements' share of the unshot power and its middle element's centre,
    /// the shares sum to the whole, and the lanes past the last run carry nothing.
    #[test]
    fn near_runs_carry_their_elements_shares_and_centres() {
        let elements = unit_squares(25);
        let n = elements.len();
        // Uneven power: element k holds 1 + k % 3.
        let mut cdf = Vec::with_capacity(n);
        let mut acc = 0.0;
        for k in 0..n {
            acc += (1 + k % 3) as f64;
            cdf.push(acc);
        }
        let cdf: Vec<f64> = cdf.iter().map(|c| c / acc).collect();
        let origin = DVec3::new(12.0, 12.0, 0.0);
        let mut table = NearRuns::default();
        table.load(&elements, &cdf, origin);
        assert_eq!(table.per_run, 3);
        assert_eq!(table.runs, 209);
        assert_eq!(table.share.len(), 53, "four runs to a lane group");
        let mut total = 0.0;
        for r in 0..table.runs {
            let (g, lane) = (r / 4, r % 4);
            let (first, end) = (3 * r, (3 * r + 3).min(n));
            let power: f64 = (first..end).map(|k| (1 + k % 3) as f64).sum::<f64>() / acc;
            assert!((f64::from(table.share[g][lane]) - power).abs() < 1e-6, "run {r}");
            let centre = elements[(first + end) / 2].centre - origin;
            let laid = DVec3::new(table.x[g][lane].into(), table.y[g][lane].into(), table.z[g][lane].into());
            assert!(laid.distance(centre) < 1e-5, "run {r}: {laid} for {centre}");
            total += f64::from(table.share[g][lane]);
        }
        assert!((total - 1.0).abs() < 1e-5, "{total}");
        for lane in table.runs % 4..4 {
            assert_eq!(table.share[table.runs / 4][lane], 0.0);
        }
    }
}
