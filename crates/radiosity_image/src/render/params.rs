//! What a picture is asked for: its size, samples, shading and gather, validated, and why a
//! render can be refused.

use thiserror::Error;

use crate::gather::Gather;

/// How radiosity is taken at a hit point.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Shading {
    /// Interpolated from the element's vertices: smooth within a surface, never across one.
    #[default]
    Smooth,
    /// The element's own radiosity: shows the mesh, as the solver sees it.
    Flat,
}

impl Shading {
    /// The name on the command line: `smooth` or `flat`.
    pub fn as_str(self) -> &'static str {
        match self {
            Shading::Smooth => "smooth",
            Shading::Flat => "flat",
        }
    }
}

/// Renderer settings; every field has a unit, a range and a default.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderParams {
    /// Picture width in pixels, in 1..=16384. Default 640.
    pub width: u32,
    /// Picture height in pixels, in 1..=16384; width × height at most
    /// [`MAX_PICTURE_PIXELS`](crate::MAX_PICTURE_PIXELS). Default 480.
    pub height: u32,
    /// Jittered samples per pixel, in 1..=4096. Default 16 (4 × 4 strata: clean edges).
    pub samples_per_pixel: u32,
    /// Radiosity at a hit point. Default [`Shading::Smooth`].
    pub shading: Shading,
    /// Seed of the jitter. Default 0.
    pub seed: u64,
    /// Where the light of a pixel comes from. Default [`Gather::None`] (the solution only).
    pub gather: Gather,
    /// Shadow rays to the emitters per sample with a gather, in 1..=1024. Default 2 (32 per
    /// pixel at 16 samples, stratified over the emitters).
    pub shadow_rays: u32,
    /// Gathering rays with [`Gather::Full`], in 1..=1024: a picture's irradiance-cache records
    /// take [`RECORD_RAYS_PER_GATHER_RAY`] times this many each (and a sample that no record
    /// covers this many); a lightmap's texels this many per sample. Default 8.
    pub gather_rays: u32,
    /// Pixels on a geometric edge (their corners and centre do not all see the same object,
    /// or not all an emitter) take this many times `samples_per_pixel`, in 1..=64; 1 treats
    /// them as any other; those on an emitter's outline take its square (at most 64).
    /// Default 4.
    pub edge_factor: u32,
    /// With a gather, pixels (and texels) whose point sees some of the emitters and not all
    /// of them (a penumbra, or a lamp cut by the surface's horizon) take this many times
    /// `shadow_rays`, in 1..=64; 1 treats them as any other. Default 4.
    pub penumbra_factor: u32,
}

impl Default for RenderParams {
    fn default() -> Self {
        Self {
            width: 640,
            height: 480,
            samples_per_pixel: 16,
            shading: Shading::Smooth,
            seed: 0,
            gather: Gather::None,
            shadow_rays: 2,
            gather_rays: 8,
            edge_factor: 4,
            penumbra_factor: 4,
        }
    }
}

impl RenderParams {
    /// Largest width or height accepted.
    pub const MAX_SIDE: u32 = 16384;
    /// Largest number of samples per pixel accepted.
    pub const MAX_SAMPLES: u32 = 4096;
    /// Largest number of shadow or gathering rays per sample accepted.
    pub const MAX_GATHER_RAYS: u32 = 1024;
    /// Largest [`RenderParams::edge_factor`] and [`RenderParams::penumbra_factor`] accepted.
    pub const MAX_EDGE_FACTOR: u32 = 64;

    /// Small and quick, for thumbnails and tests: 160 × 120, 4 samples per pixel.
    pub fn preview() -> Self {
        Self { width: 160, height: 120, samples_per_pixel: 4, ..Self::default() }
    }

    /// Large and clean, for figures: 1280 × 960, 64 samples per pixel.
    pub fn high_quality() -> Self {
        Self { width: 1280, height: 960, samples_per_pixel: 64, ..Self::default() }
    }

    /// Checks every field's range.
    ///
    /// # Errors
    /// [`RenderError::BadParameter`] naming the first field out of range.
    pub fn validate(&self) -> Result<(), RenderError> {
        let check = |name: &'static str, value: u32, max: u32| {
            if (1..=max).contains(&value) {
                Ok(())
            } else {
                Err(RenderError::BadParameter {
                    name,
                    value: u64::from(value),
                    expected: format!("1..={max}"),
                })
            }
        };
        check("width", self.width, Self::MAX_SIDE)?;
        check("height", self.height, Self::MAX_SIDE)?;
        // The memory estimate: each pixel's linear radiance (24 bytes), the tone-mapped and
        // encoded copies (~16 bytes) — about 40 bytes a pixel, 2.5 GiB at the limit.
        let pixels = u64::from(self.width) * u64::from(self.height);
        if pixels > crate::MAX_PICTURE_PIXELS {
            return Err(RenderError::BadParameter {
                name: "width × height",
                value: pixels,
                expected: format!(
                    "at most {} pixels (e.g. 8192 × 8192; about 40 bytes of memory a pixel)",
                    crate::MAX_PICTURE_PIXELS
                ),
            });
        }
        check("samples_per_pixel", self.samples_per_pixel, Self::MAX_SAMPLES)?;
        check("shadow_rays", self.shadow_rays, Self::MAX_GATHER_RAYS)?;
        check("gather_rays", self.gather_rays, Self::MAX_GATHER_RAYS)?;
        check("edge_factor", self.edge_factor, Self::MAX_EDGE_FACTOR)?;
        check("penumbra_factor", self.penumbra_factor, Self::MAX_EDGE_FACTOR)
    }
}

/// Why a picture cannot be rendered.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum RenderError {
    /// A parameter is out of range.
    #[error("render parameter {name} = {value} is out of range: expected {expected}")]
    BadParameter {
        /// Field name.
        name: &'static str,
        /// Value given.
        value: u64,
        /// The accepted range.
        expected: String,
    },
    /// [`Gather::Direct`] needs the solution's direct part, which this solution does not hold.
    #[error("--gather direct needs the solver's direct-light part, which this solution does not hold")]
    NoDirectPart,
    /// The solution was computed for another mesh.
    #[error(
        "the solution does not fit the mesh: {solution_elements} element and {solution_vertices} vertex values for {mesh_elements} elements and {mesh_vertices} vertices"
    )]
    SolutionMismatch {
        /// Element values in the solution.
        solution_elements: usize,
        /// Vertex values in the solution.
        solution_vertices: usize,
        /// Elements in the mesh.
        mesh_elements: usize,
        /// Vertices in the mesh.
        mesh_vertices: usize,
    },
}
