//! An irradiance cache for [`Gather::Full`](crate::Gather::Full) pictures (Ward, Rubinstein &
//! Clear 1988, "A ray tracing solution for diffuse interreflection"; the screen-space radius
//! limits of Tabellion & Lamorlette 2004, "An approximate global illumination system for
//! computer generated films").
//!
//! The light a surface reflects towards the eye after one bounce varies slowly except near
//! other surfaces (contacts, corners). Gathering it per pixel sample spends hundreds of rays a
//! pixel and still leaves several per cent of noise; gathering it with many more rays at a few
//! *records* and interpolating between them gives a picture without that noise for a fraction
//! of the rays. Each record keeps the indirect irradiance at its point and a radius of
//! validity: a fraction of the harmonic mean distance its rays travelled (near a contact or a
//! corner the irradiance changes over the distance to it, so records there are small and
//! dense), clamped to a few pixels' width on either side so that records are neither finer
//! than the picture can show nor coarser than its detail.
//!
//! Records are placed where the picture needs them, deterministically: on a grid of pixel
//! centres every 16 pixels, then every 8, 4, 2 and 1, a pixel gets a record only where those
//! already made do not cover its centre. The records of one level are gathered in parallel
//! from streams keyed by their pixel, so any thread count gives the same cache.

use glam::DVec3;
use radiosity_core::Rgb;
use rayon::prelude::*;

/// The grid steps, in pixels, at which records are placed, coarse to fine.
const LEVELS: [usize; 5] = [16, 8, 4, 2, 1];

/// A record's radius of validity as a fraction of the harmonic mean distance of its rays
/// (Ward et al.'s accuracy parameter a).
pub(crate) const ACCURACY: f64 = 0.1;

/// Radii are kept between these many pixels' widths at the record's depth.
const MIN_RADIUS_PIXELS: f64 = 1.5;
const MAX_RADIUS_PIXELS: f64 = 20.0;

/// A record covers a point whose normal turns from its own by up to about this much:
/// √(1 − cos 10°).
const NORMAL_TOLERANCE: f64 = 0.087_155;

/// A record is not used for a point farther off its tangent plane than this fraction of its
/// radius (a book's cover beside the table it lies on: same normal, another surface).
const PLANE_TOLERANCE: f64 = 0.25;

/// A record whose radius spans more than this many pixels is gathered again with more rays:
/// (radius / this)² times as many, at most [`MAX_RAY_FACTOR`]. A large record speaks for
/// many pixels, so its noise shows as a blotch; small ones are many and average theirs out.
/// Few records are large, so this costs little.
const PLAIN_RADIUS_PIXELS: f64 = 5.0;

/// The most a record's rays are multiplied by.
pub(crate) const MAX_RAY_FACTOR: u32 = 8;

/// A pixel centre is left without a record of its own when the weights of those covering it
/// add up to this much.
const COVERED: f64 = 0.5;

/// Within its radius a record's gradient may move its irradiance by at most this fraction of
/// itself. The gradient of a record beside a contact, where rays travel a hair's width, is
/// far steeper than the irradiance a little way off; unlimited, it lit the foot of the
/// Cornell box's short block 10–60 % too bright (whole-picture error 3.4 % against 2.5 %).
const GRADIENT_LIMIT: f64 = 0.5;

/// Pixels per side of a lookup bucket.
const BUCKET: usize = 8;

/// A point a record may be placed at: what a pixel's centre sees.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Site {
    /// The point, world space.
    pub point: DVec3,
    /// Its shading normal (unit).
    pub normal: DVec3,
    /// Where its gathering rays leave from: the point, lifted off its surface.
    pub origin: DVec3,
    /// The width of one pixel at the point's distance from the eye, scene units.
    pub pixel_size: f64,
}

/// What a record's gathering rays found.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Gathered {
    /// The irradiance from the light the surfaces around reflect, W/unit².
    pub irradiance: Rgb,
    /// The harmonic mean of the distances the rays travelled (∞ when none hit anything).
    pub harmonic_distance: f64,
    /// How the irradiance changes as the point moves in its plane, per channel (W/unit² per
    /// unit of distance; Ward & Heckbert 1992).
    pub gradient: [DVec3; 3],
}

#[derive(Clone, Copy, Debug)]
struct Record {
    point: DVec3,
    normal: DVec3,
    radius: f64,
    irradiance: Rgb,
    gradient: [DVec3; 3],
}

impl Record {
    /// The record `found` makes at `site`: its radius [`ACCURACY`] × the harmonic mean
    /// distance within the pixel limits, and its gradient limited so that within the radius
    /// it moves the irradiance by at most [`GRADIENT_LIMIT`] of itself.
    fn new(site: &Site, found: &Gathered) -> Self {
        let radius = Self::radius_for(site, found);
        let [r, g, b] = found.gradient;
        let luminance_gradient = (
            Rgb::new(r.x, g.x, b.x).luminance(),
            Rgb::new(r.y, g.y, b.y).luminance(),
            Rgb::new(r.z, g.z, b.z).luminance(),
        );
        let steepness = DVec3::from(luminance_gradient).length() * radius;
        let allowed = GRADIENT_LIMIT * found.irradiance.luminance();
        let scale = if steepness > allowed { allowed / steepness } else { 1.0 };
        Self {
            point: site.point,
            normal: site.normal,
            radius,
            irradiance: found.irradiance,
            gradient: found.gradient.map(|g| g * scale),
        }
    }

    fn radius_for(site: &Site, found: &Gathered) -> f64 {
        (ACCURACY * found.harmonic_distance)
            .clamp(MIN_RADIUS_PIXELS * site.pixel_size, MAX_RADIUS_PIXELS * site.pixel_size)
    }

    /// The weight with which this record speaks for point `x` of unit normal `n`: 1 at the
    /// record, falling linearly to 0 at its radius or as the normals turn apart (Tabellion &
    /// Lamorlette's form of Ward's error estimate, bounded, so no one record dominates).
    fn weight(&self, x: DVec3, n: DVec3) -> f64 {
        let d = x - self.point;
        if d.dot(self.normal).abs() > PLANE_TOLERANCE * self.radius {
            return 0.0;
        }
        let by_distance = d.length() / self.radius;
        let by_normal = (1.0 - n.dot(self.normal)).max(0.0).sqrt() / NORMAL_TOLERANCE;
        1.0 - by_distance.max(by_normal)
    }

    /// The record's irradiance carried to `x` along its gradient (first order; never below
    /// zero).
    fn irradiance_at(&self, x: DVec3) -> Rgb {
        let d = x - self.point;
        let [r, g, b] = self.gradient.map(|g| g.dot(d));
        (self.irradiance + Rgb::new(r, g, b)).map(|c| c.max(0.0))
    }
}

/// Records of indirect irradiance over one picture, looked up by pixel.
pub(crate) struct IrradianceCache {
    records: Vec<Record>,
    /// Record indices per bucket of `BUCKET × BUCKET` pixels, row-major.
    buckets: Vec<Vec<u32>>,
    columns: usize,
}

impl IrradianceCache {
    /// Places and gathers the records of a `width × height` picture whose pixel centres see
    /// `sites` (row-major; `None` where there is nothing to record: the sky, a back face, a
    /// black surface). `gather(pixel, site, factor)` gathers one record with `factor` times the
    /// plain number of rays.
    pub(crate) fn build(
        width: usize,
        height: usize,
        sites: &[Option<Site>],
        gather: impl Fn(usize, &Site, u32) -> Gathered + Sync,
    ) -> Self {
        let (columns, rows) = (width.div_ceil(BUCKET), height.div_ceil(BUCKET));
        let mut cache = Self { records: Vec::new(), buckets: vec![Vec::new(); columns * rows], columns };
        let mut placed = vec![false; sites.len()];
        for step in LEVELS {
            let wanted: Vec<usize> = (0..height)
                .step_by(step)
                .flat_map(|y| (0..width).step_by(step).map(move |x| y * width + x))
                .collect::<Vec<_>>()
                .into_par_iter()
                .filter(|&i| {
                    let Some(site) = &sites[i] else { return false };
                    !placed[i] && cache.coverage(i % width, i / width, site.point, site.normal) < COVERED
                })
                .collect();
            let records: Vec<(Record, usize)> = wanted
                .par_iter()
                .map(|&i| {
                    let site = sites[i].as_ref().expect("wanted sites exist");
                    let mut found = gather(i, site, 1);
                    let pixels = Record::radius_for(site, &found) / site.pixel_size;
                    let factor = ((pixels / PLAIN_RADIUS_PIXELS).powi(2) as u32).min(MAX_RAY_FACTOR);
                    if factor > 1 {
                        found = gather(i, site, factor);
                    }
                    let record = Record::new(site, &found);
                    (record, (record.radius / site.pixel_size).ceil() as usize + 1)
                })
                .collect();
            for (&i, (record, reach)) in wanted.iter().zip(records) {
                placed[i] = true;
                // Filed under every bucket its radius can reach on the screen (a pixel's width
                // more for the samples off the pixel's centre), so a lookup reads one bucket.
                let (x, y) = (i % width, i / width);
                let (x0, x1) = (x.saturating_sub(reach) / BUCKET, ((x + reach) / BUCKET).min(columns - 1));
                let (y0, y1) = (y.saturating_sub(reach) / BUCKET, ((y + reach) / BUCKET).min(rows - 1));
                for by in y0..=y1 {
                    for bx in x0..=x1 {
                        cache.buckets[by * columns + bx].push(cache.records.len() as u32);
                    }
                }
                cache.records.push(record);
            }
        }
        cache
    }

    /// How many records the cache holds.
    #[cfg(test)]
    pub(crate) fn len(&self) -> usize {
        self.records.len()
    }

    /// The records that may cover a point seen in pixel `(x, y)`, with their weights there.
    fn covering(
        &self,
        x: usize,
        y: usize,
        point: DVec3,
        normal: DVec3,
    ) -> impl Iterator<Item = (f64, &Record)> {
        self.buckets[(y / BUCKET) * self.columns + x / BUCKET]
            .iter()
            .map(move |&r| {
                let record = &self.records[r as usize];
                (record.weight(point, normal), record)
            })
            .filter(|(w, _)| *w > 0.0)
    }

    fn coverage(&self, x: usize, y: usize, point: DVec3, normal: DVec3) -> f64 {
        self.covering(x, y, point, normal).map(|(w, _)| w).sum()
    }

    /// The indirect irradiance at `point` (unit normal `normal`), seen in pixel `(x, y)`:
    /// the weighted mean of the records that cover it, or `None` where none does (a sample
    /// of an edge pixel that sees another surface than the pixel's centre).
    pub(crate) fn lookup(&self, x: usize, y: usize, point: DVec3, normal: DVec3) -> Option<Rgb> {
        let (sum, weights) =
            self.covering(x, y, point, normal).fold((Rgb::ZERO, 0.0), |(sum, weights), (w, record)| {
                (sum + record.irradiance_at(point) * w, weights + w)
            });
        (weights > 0.0).then(|| sum / weights)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flat_sites(width: usize, height: usize) -> Vec<Option<Site>> {
        (0..width * height)
            .map(|i| {
                let point = DVec3::new((i % width) as f64, (i / width) as f64, 0.0);
                Some(Site { point, normal: DVec3::Z, origin: point, pixel_size: 1.0 })
            })
            .collect()
    }

    /// A cache over a `w × h` plane whose records all find `irradiance` (a function of the
    /// record's point) and `harmonic_distance`, with `slope` as the gradient of every channel.
    fn cache_over(
        w: usize,
        h: usize,
        irradiance: impl Fn(DVec3) -> f64 + Sync,
        harmonic_distance: f64,
        slope: DVec3,
    ) -> (Vec<Option<Site>>, IrradianceCache) {
        let sites = flat_sites(w, h);
        let cache = IrradianceCache::build(w, h, &sites, |_, site, _| Gathered {
            irradiance: Rgb::splat(irradiance(site.point)),
            harmonic_distance,
            gradient: [slope; 3],
        });
        (sites, cache)
    }

    /// Far from everything (rays that travel far), records are as large as allowed and few;
    /// every pixel centre is covered, and a lookup returns the (here uniform) irradiance.
    #[test]
    fn open_surfaces_take_few_large_records() {
        let (w, h) = (64, 48);
        let (sites, cache) = cache_over(w, h, |_| 2.0, f64::INFINITY, DVec3::ZERO);
        assert!(cache.len() <= (w / 8 + 1) * (h / 8 + 1), "{} records", cache.len());
        for (i, site) in sites.iter().enumerate() {
            let site = site.unwrap();
            let got = cache.lookup(i % w, i / w, site.point, site.normal).expect("covered");
            assert!((got.sum() / 3.0 - 2.0).abs() < 1e-12);
        }
    }

    /// Records carry their irradiance along their gradients: where the light grows linearly
    /// (1 + x/100, gentle enough for the limit to leave it whole), every lookup between
    /// records is exact, not the records' blend.
    #[test]
    fn gradients_make_linear_light_exact_between_records() {
        let (w, h) = (64, 48);
        let light = |p: DVec3| 1.0 + 0.01 * p.x;
        let (_, cache) = cache_over(w, h, light, f64::INFINITY, DVec3::new(0.01, 0.0, 0.0));
        let p = DVec3::new(37.3, 21.6, 0.0);
        let got = cache.lookup(37, 21, p, DVec3::Z).expect("covered").r;
        assert!((got - light(p)).abs() < 1e-12, "{got} against {}", light(p));
        let (_, flat) = cache_over(w, h, light, f64::INFINITY, DVec3::ZERO);
        let blended = flat.lookup(37, 21, p, DVec3::Z).expect("covered").r;
        assert!((blended - light(p)).abs() > 1e-3, "without gradients the records blend: {blended}");
    }

    /// Records whose rays travel a short way (a contact nearby) are small, so the cache holds
    /// many more of them; a point whose normal turns away from every record's, or that lies
    /// off their plane, is not covered.
    #[test]
    fn near_surfaces_take_dense_records_and_other_planes_none() {
        let (w, h) = (32, 32);
        let (_, far) = cache_over(w, h, |_| 1.0, f64::INFINITY, DVec3::ZERO);
        let (_, near) = cache_over(w, h, |_| 1.0, 2.0 / ACCURACY, DVec3::ZERO);
        assert!(near.len() > 10 * far.len(), "{} against {}", near.len(), far.len());
        let p = DVec3::new(10.0, 10.0, 0.0);
        assert!(far.lookup(10, 10, p, DVec3::Z).is_some());
        assert!(far.lookup(10, 10, p, DVec3::X).is_none(), "a wall's normal");
        assert!(far.lookup(10, 10, p + DVec3::Z * 8.0, DVec3::Z).is_none(), "a parallel plane 8 pixels up");
    }
}
