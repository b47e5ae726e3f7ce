//! Means over surfaces: many independent paths per object (or per region), their sample
//! mean and standard error, in deterministic batches.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use radiosity_core::Rgb;
use radiosity_core::glam::DVec3;
use radiosity_core::random::Rng;
use rayon::prelude::*;

use crate::geometry::{Geometry, Primitive, SurfacePoint, pick};
use crate::{Estimate, EstimateParams, PathBudget, Progress, Region};

/// Paths per batch: the unit of work and of the random streams.
pub(crate) const BATCH: u64 = 4096;

/// Task keys of the streams: objects, regions, pixels.
pub(crate) const OBJECT_TASK: u64 = 0x6f62_6a00_0000_0000; // "obj"
pub(crate) const REGION_TASK: u64 = 0x7265_6700_0000_0000; // "reg"
pub(crate) const POINT_TASK: u64 = 0x7074_0000_0000_0000; // "pt"

/// Sums of one batch (or of several), per channel and for luminance.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Moments {
    pub n: u64,
    pub mean: [f64; 4],
    /// Sum of squared deviations from the mean.
    pub m2: [f64; 4],
}

impl Moments {
    pub fn from_samples(samples: &[Rgb]) -> Self {
        let n = samples.len() as u64;
        if n == 0 {
            return Self::default();
        }
        let values = |s: &Rgb| [s.r, s.g, s.b, s.luminance()];
        let mut mean = [0.0; 4];
        for s in samples {
            for (m, v) in mean.iter_mut().zip(values(s)) {
                *m += v;
            }
        }
        mean.iter_mut().for_each(|m| *m /= n as f64);
        let mut m2 = [0.0; 4];
        for s in samples {
            for ((q, v), m) in m2.iter_mut().zip(values(s)).zip(mean) {
                *q += (v - m) * (v - m);
            }
        }
        Self { n, mean, m2 }
    }

    /// Two sets of samples as one (Chan, Golub & LeVeque 1979).
    pub fn merge(self, o: Self) -> Self {
        if self.n == 0 {
            return o;
        }
        if o.n == 0 {
            return self;
        }
        let n = self.n + o.n;
        let (a, b) = (self.n as f64, o.n as f64);
        let mut mean = [0.0; 4];
        let mut m2 = [0.0; 4];
        for i in 0..4 {
            let delta = o.mean[i] - self.mean[i];
            mean[i] = self.mean[i] + delta * b / n as f64;
            m2[i] = self.m2[i] + o.m2[i] + delta * delta * a * b / n as f64;
        }
        Self { n, mean, m2 }
    }

    pub fn estimate(&self) -> Estimate {
        let se = |i: usize| {
            if self.n < 2 { f64::INFINITY } else { (self.m2[i] / (self.n - 1) as f64 / self.n as f64).sqrt() }
        };
        Estimate {
            mean: Rgb::new(self.mean[0], self.mean[1], self.mean[2]),
            stderr: Rgb::new(se(0), se(1), se(2)),
            luminance: self.mean[3],
            luminance_stderr: se(3),
            paths: self.n,
        }
    }

    /// Largest standard error relative to the mean over the channels with a mean > 0 (0
    /// when every channel is 0: nothing to estimate).
    fn relative_stderr(&self) -> f64 {
        let e = self.estimate();
        let (m, s) = (e.mean.to_array(), e.stderr.to_array());
        (0..3).filter(|&i| m[i] > 0.0).map(|i| s[i] / m[i]).fold(0.0, f64::max)
    }
}

/// Where each target's samples are drawn.
pub(crate) enum Target<'a> {
    Object(u32),
    Region(&'a PreparedRegion),
    /// The irradiance at a point facing a unit normal (a calculation-grid point).
    Point(DVec3, DVec3),
}

/// A region ready to sample: its fan triangles by area, its normal, and how to put points
/// on the object's true surface.
pub(crate) struct PreparedRegion {
    triangles: Vec<[DVec3; 3]>,
    cdf: Vec<f64>,
    normal: DVec3,
    object: u32,
    /// The object's sphere, when it is one: points are projected onto it.
    sphere: Option<(DVec3, f64, bool)>,
}

impl PreparedRegion {
    pub fn new(g: &Geometry, r: &Region) -> Option<Self> {
        let object = g.objects.get(r.object)?;
        let c = &r.corners;
        if c.len() < 3 {
            return None;
        }
        let mut triangles = Vec::new();
        let mut cdf = Vec::new();
        let mut area = 0.0;
        let mut newell = DVec3::ZERO;
        for i in 1..c.len() - 1 {
            let t = [c[0], c[i], c[i + 1]];
            let n = (t[1] - t[0]).cross(t[2] - t[0]);
            area += 0.5 * n.length();
            newell += n;
            triangles.push(t);
            cdf.push(area);
        }
        if !(area > 0.0 && area.is_finite()) {
            return None;
        }
        let sphere = object.pieces.first().and_then(|&p| match g.pieces[p as usize].shape {
            Primitive::Sphere { center, radius, inward } => Some((center, radius, inward)),
            Primitive::Polygon { .. } => None,
        });
        Some(Self { triangles, cdf, normal: newell.normalize(), object: r.object as u32, sphere })
    }

    fn sample(&self, u: [f64; 3]) -> SurfacePoint {
        let t = &self.triangles[pick(&self.cdf, u[0])];
        let s = u[1].sqrt();
        let p = t[0] * (1.0 - s) + t[1] * (s * (1.0 - u[2])) + t[2] * (s * u[2]);
        match self.sphere {
            Some((c, r, inward)) => {
                let d = (p - c).normalize();
                SurfacePoint { p: c + d * r, n: if inward { -d } else { d }, object: self.object }
            }
            None => SurfacePoint { p, n: self.normal, object: self.object },
        }
    }
}

fn batch(g: &Geometry, target: &Target, seed: u64, task: u64, index: u64, max_reflections: u32) -> Moments {
    let mut rng = Rng::for_task(seed, task, index);
    let samples: Vec<Rgb> = (0..BATCH)
        .map(|_| {
            let x = match target {
                Target::Object(o) => {
                    let u = [rng.next_f64(), rng.next_f64(), rng.next_f64(), rng.next_f64()];
                    if g.sample_is_clear(*o, u) {
                        // No surface at this point of a masked face: it counts as dark.
                        return Rgb::ZERO;
                    }
                    g.sample_object(*o, u)
                }
                Target::Region(r) => r.sample([rng.next_f64(), rng.next_f64(), rng.next_f64()]),
                Target::Point(p, n) => return g.irradiance_at(*p, *n, &mut rng),
            };
            g.radiosity_at(x, max_reflections, &mut rng)
        })
        .collect();
    Moments::from_samples(&samples)
}

/// Estimates every target: rounds of batches run in parallel; per target the batches are
/// merged in index order, so the numbers do not depend on the thread count. The time limit
/// and `stop` (asked before each batch) end it early, with what the batches done so far
/// give; the flag returned says so.
pub(crate) fn estimate_targets(
    g: &Geometry,
    targets: &[(Target, u64)],
    params: &EstimateParams,
    progress: &(dyn Fn(Progress) + Sync),
    stop: &(dyn Fn() -> bool + Sync),
) -> (Vec<Moments>, bool) {
    let start = Instant::now();
    let deadline = params.time_limit.map(|t| start + t);
    let n = targets.len();
    let mut moments = vec![Moments::default(); n];
    let mut batches_done = vec![0u64; n];
    let (first, cap, target_se) = match params.budget {
        PathBudget::Fixed { paths } => {
            let b = paths.div_ceil(BATCH).max(1);
            (b, b, 0.0)
        }
        PathBudget::Adaptive { relative_stderr, max_paths } => {
            let cap = max_paths.div_ceil(BATCH).max(1);
            (16.min(cap), cap, relative_stderr)
        }
    };
    let done_paths = AtomicU64::new(0);
    let mut planned = 0u64;
    let mut timed_out = false;
    let mut round = 0;
    loop {
        // How many more batches each target gets this round.
        let mut work: Vec<(usize, u64)> = Vec::new();
        for i in 0..n {
            let have = batches_done[i];
            let want = if round == 0 {
                first
            } else if matches!(params.budget, PathBudget::Fixed { .. }) {
                cap
            } else {
                let rel = moments[i].relative_stderr();
                if rel <= target_se {
                    have
                } else {
                    // Paths needed by the 1/√N law, 10 % extra, at most 4× what it has
                    // (early error estimates are themselves noisy).
                    let need = (have as f64 * (rel / target_se).powi(2) * 1.1).ceil() as u64;
                    need.min(4 * have).min(cap).max(have + 1)
                }
            };
            let want = want.min(cap);
            for b in have..want {
                work.push((i, b));
            }
        }
        if work.is_empty() {
            break;
        }
        planned += work.len() as u64 * BATCH;
        let results: Vec<Option<Moments>> = work
            .par_iter()
            .map(|&(i, b)| {
                if deadline.is_some_and(|d| Instant::now() >= d) || stop() {
                    return None;
                }
                let (target, task) = &targets[i];
                let m = batch(g, target, params.seed, *task, b, params.max_reflections);
                let done = done_paths.fetch_add(BATCH, Ordering::Relaxed) + BATCH;
                progress(Progress { paths_done: done, paths_planned: planned, elapsed: start.elapsed() });
                Some(m)
            })
            .collect();
        for (&(i, b), r) in work.iter().zip(&results) {
            // Batches merge in index order; a batch skipped by the time limit ends its target.
            if let Some(m) = r
                && b == batches_done[i]
            {
                moments[i] = moments[i].merge(*m);
                batches_done[i] += 1;
            } else {
                timed_out = true;
            }
        }
        if timed_out {
            break;
        }
        round += 1;
    }
    (moments, timed_out)
}
