//! An independent Monte Carlo reference for the radiosity renderer: unbiased path tracing of
//! the diffuse scene on its *input* geometry — the scene's polygons, exact spheres and model
//! faces, never the solver's mesh — so that a solve can be checked against the truth rather
//! than against a finer solve that shares its errors.
//!
//! It shares no code with the solver's form factors, meshing or sampling; it has its own
//! triangle list and BVH (`radiosity_accel`) of the input polygons and intersects spheres
//! analytically. The estimator (module `path`): points drawn uniformly by area on each
//! object, next-event estimation towards emitters chosen by power, cosine-weighted bounces,
//! Russian roulette (Kajiya 1986; Arvo & Kirk 1990; Pharr, Jakob & Humphreys, *Physically
//! Based Rendering*, ch. 13–14). Every batch of paths draws from its own stream
//! `Rng::for_task(seed, task, batch)` and batches merge in a fixed order, so one thread and
//! many give identical numbers.
//!
//! ```
//! use radiosity_scenes::furnace_box;
//! use radiosity_reference::{EstimateParams, PathBudget, Reference};
//!
//! // The furnace: B = E / (1 − ρ) = 2 everywhere.
//! let reference = Reference::new(&furnace_box(0.5, 1.0));
//! let params = EstimateParams { budget: PathBudget::Fixed { paths: 20_000 }, ..EstimateParams::default() };
//! let estimates = reference.estimate_objects(&params, &|_| {});
//! let b = &estimates.objects[0].estimate;
//! assert!((b.mean.r - 2.0).abs() < 4.0 * b.stderr.r);
//! ```
#![warn(missing_docs)]
#![forbid(unsafe_code)]

mod estimate;
mod geometry;
mod path;
mod render;

use std::time::{Duration, Instant};

use radiosity_core::glam::DVec3;
use radiosity_core::{Camera, Rgb, Scene};
use thiserror::Error;

use estimate::{OBJECT_TASK, POINT_TASK, PreparedRegion, REGION_TASK, Target, estimate_targets};
use geometry::Geometry;

/// How many paths an estimate takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PathBudget {
    /// Exactly this many paths per target (rounded up to whole batches of 4096).
    Fixed {
        /// Paths per object or region.
        paths: u64,
    },
    /// Paths until the standard error of every channel is at most `relative_stderr` of its
    /// mean, or `max_paths` per target. The number of paths depends on the estimates, which
    /// depend only on the seed: still the same for any thread count.
    Adaptive {
        /// Target standard error relative to the mean, e.g. 0.001.
        relative_stderr: f64,
        /// Most paths per target.
        max_paths: u64,
    },
}

/// Settings of an estimate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimateParams {
    /// Paths per target. Default: adaptive, 0.1 % standard error, at most 2²⁶ paths (the
    /// Cornell box: 2 cores, ~45 s).
    pub budget: PathBudget,
    /// Seed of every stream. Default 0.
    pub seed: u64,
    /// Stop after this long (whole rounds of batches still merge in order, but which batches
    /// finish in time depends on the machine). Default: none.
    pub time_limit: Option<Duration>,
    /// Reflections counted: 0 gives the emission alone, 1 emission plus direct light, …;
    /// default `u32::MAX` (all: the full solution). Tests use 1 to check direct light against
    /// closed-form form factors.
    pub max_reflections: u32,
}

impl Default for EstimateParams {
    fn default() -> Self {
        Self {
            budget: PathBudget::Adaptive { relative_stderr: 0.001, max_paths: 1 << 26 },
            seed: 0,
            time_limit: None,
            max_reflections: u32::MAX,
        }
    }
}

/// Where an estimate stands; given to the progress callback after every batch, from any
/// worker thread.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Progress {
    /// Paths traced so far.
    pub paths_done: u64,
    /// Paths planned so far (grows from round to round of an adaptive estimate).
    pub paths_planned: u64,
    /// Time since the estimate started.
    pub elapsed: Duration,
}

/// A mean radiosity and its standard error, W/unit² per channel, emission included (as the
/// solver reports radiosity).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// Sample mean per channel.
    pub mean: Rgb,
    /// Standard error of the mean per channel (sample standard deviation / √paths).
    pub stderr: Rgb,
    /// Mean luminance (Rec. 709 Y of each sample).
    pub luminance: f64,
    /// Standard error of `luminance`.
    pub luminance_stderr: f64,
    /// Paths averaged.
    pub paths: u64,
}

/// The estimate for one scene object.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectEstimate {
    /// Object name, as in the scene (and in the solver's reports).
    pub name: String,
    /// Area of its input geometry (a sphere's exact 4πR²), scene units².
    pub area: f64,
    /// Its area-mean radiosity.
    pub estimate: Estimate,
}

/// Estimates for every object of a scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Estimates {
    /// Per object, in scene order.
    pub objects: Vec<ObjectEstimate>,
    /// Paths traced in all.
    pub paths: u64,
    /// Wall-clock time.
    pub elapsed: Duration,
    /// True when the time limit cut the estimate short.
    pub timed_out: bool,
}

/// A planar convex piece of one object's surface to average over, e.g. a mesh element.
/// Points are drawn uniformly on the polygon `corners` (counter-clockwise seen from the lit
/// side); on a sphere they are projected onto the true sphere.
#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    /// Index of the object in the scene.
    pub object: usize,
    /// Corners, 3 or more, counter-clockwise seen from the lit side.
    pub corners: Vec<DVec3>,
}

/// Settings of a reference picture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PictureParams {
    /// Width in pixels, 1..=16384.
    pub width: u32,
    /// Height in pixels, 1..=16384.
    pub height: u32,
    /// Paths per pixel, each through a jittered film position (stratified as the radiosity
    /// renderer's samples), 1..=1 048 576.
    pub samples_per_pixel: u32,
    /// Seed. Default 0.
    pub seed: u64,
}

/// A reference picture: linear radiance per pixel and its standard error.
#[derive(Clone, Debug, PartialEq)]
pub struct Picture {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Radiance per pixel (W·sr⁻¹/unit²), top row first.
    pub radiance: Vec<Rgb>,
    /// Standard error of each pixel's radiance (infinite with one sample per pixel).
    pub stderr: Vec<Rgb>,
}

/// Why an estimate cannot be made.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum ReferenceError {
    /// A region is degenerate or names an object that does not exist.
    #[error("region {index} is not a polygon of 3+ corners with area > 0 on an existing object")]
    BadRegion {
        /// Index of the region.
        index: usize,
    },
    /// A picture setting is out of range.
    #[error("picture parameter {name} = {value} is out of range: expected {expected}")]
    BadParameter {
        /// Field name.
        name: &'static str,
        /// Value given.
        value: u64,
        /// Accepted range.
        expected: &'static str,
    },
}

/// The estimator for one scene: its input geometry, BVH and emitters.
pub struct Reference {
    geometry: Geometry,
}

impl Reference {
    /// Prepares `scene` (a validated scene always has an emitter).
    pub fn new(scene: &Scene) -> Self {
        Self { geometry: Geometry::new(scene) }
    }

    /// Names and areas of the objects, in scene order, then the back faces of two-sided
    /// objects (named `NAME (back)`), in scene order too.
    pub fn objects(&self) -> impl Iterator<Item = (&str, f64)> {
        self.geometry.objects.iter().map(|o| (o.name.as_str(), o.area))
    }

    /// The index among [`Reference::objects`] of the back face of scene object `object`, when
    /// it is two-sided: what a [`Region`] on that face names.
    pub fn back_object(&self, object: usize) -> Option<usize> {
        self.geometry.back_objects.get(object).copied().flatten().map(|i| i as usize)
    }

    /// The mean radiosity of every object, with its standard error.
    pub fn estimate_objects(
        &self,
        params: &EstimateParams,
        progress: &(dyn Fn(Progress) + Sync),
    ) -> Estimates {
        self.estimate_objects_until(params, progress, &|| false)
    }

    /// [`Reference::estimate_objects`], ended early once `stop` says so (asked before each
    /// batch of paths, from any worker thread: a user's Ctrl-C), with what the batches done
    /// by then give; [`Estimates::timed_out`] is then set, as by the time limit.
    pub fn estimate_objects_until(
        &self,
        params: &EstimateParams,
        progress: &(dyn Fn(Progress) + Sync),
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Estimates {
        let start = Instant::now();
        let targets: Vec<(Target, u64)> = (0..self.geometry.objects.len() as u32)
            .map(|o| (Target::Object(o), OBJECT_TASK | u64::from(o)))
            .collect();
        let (moments, timed_out) = estimate_targets(&self.geometry, &targets, params, progress, stop);
        let objects = self
            .geometry
            .objects
            .iter()
            .zip(&moments)
            .map(|(o, m)| ObjectEstimate { name: o.name.clone(), area: o.area, estimate: m.estimate() })
            .collect();
        Estimates { objects, paths: moments.iter().map(|m| m.n).sum(), elapsed: start.elapsed(), timed_out }
    }

    /// The mean radiosity over each region, with its standard error.
    ///
    /// # Errors
    /// [`ReferenceError::BadRegion`] for a degenerate region or an unknown object.
    pub fn estimate_regions(
        &self,
        regions: &[Region],
        params: &EstimateParams,
        progress: &(dyn Fn(Progress) + Sync),
    ) -> Result<Vec<Estimate>, ReferenceError> {
        self.estimate_regions_until(regions, params, progress, &|| false)
    }

    /// [`Reference::estimate_regions`], ended early once `stop` says so (as
    /// [`Reference::estimate_objects_until`]); a region no batch reached has no paths.
    ///
    /// # Errors
    /// As [`Reference::estimate_regions`].
    pub fn estimate_regions_until(
        &self,
        regions: &[Region],
        params: &EstimateParams,
        progress: &(dyn Fn(Progress) + Sync),
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Result<Vec<Estimate>, ReferenceError> {
        let prepared = regions
            .iter()
            .enumerate()
            .map(|(index, r)| {
                PreparedRegion::new(&self.geometry, r).ok_or(ReferenceError::BadRegion { index })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let targets: Vec<(Target, u64)> =
            prepared.iter().enumerate().map(|(i, r)| (Target::Region(r), REGION_TASK | i as u64)).collect();
        let (moments, _) = estimate_targets(&self.geometry, &targets, params, progress, stop);
        Ok(moments.iter().map(|m| m.estimate()).collect())
    }

    /// The irradiance (W/unit² per channel, not radiosity) at each point facing its unit
    /// normal, with its standard error: the luminaires' light by next-event estimation and
    /// the light of every surface by cosine-weighted paths. Points may lie in the air (a
    /// work plane) or on a surface (lift them off it by a hair). Lux are
    /// `estimate.luminance · LengthUnit::lux_per_irradiance()`.
    pub fn estimate_points(
        &self,
        points: &[(DVec3, DVec3)],
        params: &EstimateParams,
        progress: &(dyn Fn(Progress) + Sync),
        stop: &(dyn Fn() -> bool + Sync),
    ) -> Vec<Estimate> {
        let targets: Vec<(Target, u64)> = points
            .iter()
            .enumerate()
            .map(|(i, &(p, n))| (Target::Point(p, n.normalize()), POINT_TASK | i as u64))
            .collect();
        let (moments, _) = estimate_targets(&self.geometry, &targets, params, progress, stop);
        moments.iter().map(|m| m.estimate()).collect()
    }

    /// Renders what `camera` sees: per pixel the mean radiance of `samples_per_pixel` paths;
    /// `row_done` is called (from any worker thread) after each row.
    ///
    /// # Errors
    /// [`ReferenceError::BadParameter`] for a size or sample count out of range.
    pub fn render(
        &self,
        camera: &Camera,
        params: &PictureParams,
        row_done: &(dyn Fn() + Sync),
    ) -> Result<Picture, ReferenceError> {
        let check = |name, value: u32, max: u32, expected| {
            if (1..=max).contains(&value) {
                Ok(())
            } else {
                Err(ReferenceError::BadParameter { name, value: u64::from(value), expected })
            }
        };
        check("width", params.width, 16384, "1..=16384")?;
        check("height", params.height, 16384, "1..=16384")?;
        check("samples_per_pixel", params.samples_per_pixel, 1 << 20, "1..=1048576")?;
        Ok(render::render(&self.geometry, camera, params, row_done))
    }
}
