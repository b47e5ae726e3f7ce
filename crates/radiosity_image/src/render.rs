//! The CPU renderer: ray casts a lit mesh from a pinhole camera into a picture of radiance.
//!
//! Every surface is Lambertian, so the radiance leaving a point towards the eye is
//! L = B / π whatever the direction (B the radiosity, W/unit²), and a picture needs only one
//! primary ray per sample — no further bounces: the radiosity solution already holds them.
//!
//! B at a hit point is either the element's own value ([`Shading::Flat`]) or interpolated from
//! the solution's vertex radiosity ([`Shading::Smooth`], Gouraud-style as in Cohen et al.
//! 1986): barycentric on triangles, bilinear on quads (inverse bilinear mapping, after Quílez,
//! "Inverse bilinear interpolation", 2010). Both are linear along an edge between its two
//! vertices, so neighbouring elements agree on their shared edge and the result is continuous
//! across element edges; vertices are shared only within one surface, so nothing is blended
//! round a corner.
//!
//! Samples: `samples_per_pixel` jittered positions per pixel, on a stratified √n × √n grid
//! first, any rest uniformly in the pixel; the box-filtered mean is the pixel. Random numbers
//! come from `(seed, pixel index)`, so any thread count gives the same picture.

use std::f64::consts::PI;
use std::sync::Arc;

use glam::{DVec2, DVec3, Vec3};
use radiosity_accel::{Bvh, Hit, RayQuery};
use radiosity_core::random::Rng;
use radiosity_core::{Camera, CameraRays, Rgb};
use radiosity_mesh::Mesh;
use radiosity_solver::Solution;
use rayon::prelude::*;
use thiserror::Error;

use crate::HdrImage;
use crate::cache::{Gathered, IrradianceCache, Site};
use crate::gather::{self, DirectMis, Emitters, Gather, Seen};

/// Task key of the pixels' streams (`Rng::for_task(seed, PIXEL_TASK, pixel)`).
const PIXEL_TASK: u64 = 0x7069_7865_6c73; // "pixels"
/// Task key of gathered texels' streams.
const TEXEL_TASK: u64 = 0x7465_7865_6c73; // "texels"
/// Task key of irradiance-cache records' streams (keyed by the record's pixel).
const RECORD_TASK: u64 = 0x7265_636f_7264; // "record"

/// An irradiance-cache record gathers this many times [`RenderParams::gather_rays`] (1 024
/// rays at the default). A record speaks for the pixels around it, so its noise shows as a
/// blotch that more samples per pixel do not average out: on the Cornell box at 64 samples
/// per pixel, records of 512 rays left 0.64 % of noise per pixel, as much as the direct
/// light's, and 1 024 rays 0.45 %.
pub const RECORD_RAYS_PER_GATHER_RAY: u32 = 128;

/// A gathering ray shorter than this many sides of the element it lands on takes the direct
/// light there by its own rays ([`Renderer::reflected`]). On the Cornell box (`--gather
/// full`, against the path tracer): error 1.74 → 1.63 %, bias 1.12 → 0.84 %, for 13 % more
/// render time; 1 or 4 sides instead of 2 moved the error by 0.01–0.02 %, and 2 + 2 rays
/// where they land instead of 4 + 4 neither the time nor the error.
const SHORT_RAY: f64 = 2.0;

/// Shadow rays a short gathering ray takes where it lands (stratified over the emitters),
/// and as many cosine-weighted directions, their estimates combined by the balance
/// heuristic.
const LANDING_SHADOW_RAYS: u32 = 4;

/// What the samples of one pixel or texel take (see [`Renderer::effort_from`]).
#[derive(Clone, Copy, Debug)]
struct Effort {
    /// Times `shadow_rays`.
    light_factor: u32,
    /// Whether the direct light takes cosine-weighted directions besides the emitter points.
    cosines: bool,
}

impl Effort {
    /// Nothing more than the parameters say.
    const PLAIN: Effort = Effort { light_factor: 1, cosines: true };
}

/// Which share of its pixel's (or texel's) strata a sample takes: stratum `index` of the
/// emitter points and directions, the emitter points' lattice turned by the pixel's
/// `rotation` (see [`gather::lattice_point`]).
#[derive(Clone, Copy, Debug)]
struct Stratum {
    index: u32,
    rotation: f64,
}

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

/// What a single ray sees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    /// The element hit, index into [`Mesh::elements`].
    pub element: u32,
    /// Its object, index into [`Mesh::object_names`].
    pub object: u32,
    /// Hit point, world space.
    pub p_world: DVec3,
    /// Distance along the (unit) ray direction, scene units.
    pub distance: f64,
    /// True when the ray meets the lit (front) side of the element.
    pub front_facing: bool,
    /// Radiance towards the eye, W·sr⁻¹/unit² per channel: B/π on the front side, 0 on the
    /// back (radiosity surfaces are one-sided; nothing leaves their back).
    pub radiance: Rgb,
}

/// A rendered picture and, per pixel, the object seen through its centre.
#[derive(Clone, Debug, PartialEq)]
pub struct Rendering {
    /// Linear radiance per pixel.
    pub radiance: HdrImage,
    /// Per pixel (top row first), the object hit by a ray through the pixel's centre, or
    /// `None` where that ray leaves the scene.
    pub object_ids: Vec<Option<u32>>,
}

/// Ray casts one lit mesh: holds a BVH over the element triangles (built once, reused for
/// every picture and every snapshot of the solution).
pub struct Renderer {
    mesh: Arc<Mesh>,
    accel: Bvh,
    /// Element of every triangle given to the BVH.
    triangle_element: Vec<u32>,
    /// The scene's blocking polygons (as the solver sees them), for shadow rays: a shadow ray
    /// needs only whether something is in the way, and the input polygons are far fewer than
    /// the element triangles (the Cornell box: 10 triangles against 20 000).
    blockers: Bvh,
    /// The emitting elements, for shadow rays.
    emitters: Emitters,
    /// How far a secondary ray's origin is lifted off its surface: 1e-6 of the scene's
    /// diagonal, far above f32 round-off of positions, far below any feature.
    lift: f64,
    /// Per vertex, the normal a final gather shades with (see [`shading_normals`]); empty
    /// when every vertex's is its own surface's normal (no smoothing across facets).
    shading_normals: Vec<DVec3>,
}

impl Renderer {
    /// Builds the ray-query structure over the element triangles of `mesh` (the elements, not
    /// the coarser occluders, so a hit names the element whose radiosity to use).
    pub fn new(mesh: Arc<Mesh>) -> Self {
        let (triangle_element, triangles): (Vec<u32>, Vec<[Vec3; 3]>) = mesh
            .element_triangles()
            .map(|(e, t)| (e, t.map(|i| mesh.positions[i as usize].as_vec3())))
            .unzip();
        let accel = Bvh::new(&triangles);
        let blockers = Bvh::new(&radiosity_solver::occluder_triangles(&mesh));
        let emitters = Emitters::new(&mesh);
        let (lo, hi) = mesh.bounds();
        let lift = 1e-6 * (hi - lo).length().max(f64::MIN_POSITIVE);
        let shading_normals = shading_normals(&mesh);
        Self { mesh, accel, triangle_element, blockers, emitters, lift, shading_normals }
    }

    /// The element a ray along `dir` sees at BVH triangle `triangle`: where a two-sided
    /// object puts two elements back to back in one place, the one that faces the ray
    /// (which of the two coplanar triangles the BVH reports first is arbitrary).
    fn facing_element(&self, triangle: u32, dir: DVec3) -> usize {
        let e = self.triangle_element[triangle as usize] as usize;
        if self.mesh.elements[e].normal.dot(dir) > 0.0 { self.mesh.element_twin(e).unwrap_or(e) } else { e }
    }

    /// The mesh being drawn.
    pub fn mesh(&self) -> &Arc<Mesh> {
        &self.mesh
    }

    /// Whether `solution` holds the solver's direct part for every element and vertex.
    fn has_direct_part(&self, solution: &Solution) -> bool {
        solution.vertex_direct.len() == self.mesh.positions.len()
            && solution.element_direct.len() == self.mesh.elements.len()
    }

    fn check(&self, solution: &Solution) -> Result<(), RenderError> {
        let m = &self.mesh;
        if solution.element_radiosity.len() != m.elements.len()
            || solution.vertex_radiosity.len() != m.positions.len()
        {
            return Err(RenderError::SolutionMismatch {
                solution_elements: solution.element_radiosity.len(),
                solution_vertices: solution.vertex_radiosity.len(),
                mesh_elements: m.elements.len(),
                mesh_vertices: m.positions.len(),
            });
        }
        Ok(())
    }

    /// Traces one ray from `origin` along `direction` (any length > 0) and returns what it
    /// sees, or `None` when it leaves the scene.
    ///
    /// # Errors
    /// [`RenderError::SolutionMismatch`] when `solution` was computed for another mesh.
    pub fn trace(
        &self,
        solution: &Solution,
        origin: DVec3,
        direction: DVec3,
        shading: Shading,
    ) -> Result<Option<SurfaceHit>, RenderError> {
        self.check(solution)?;
        Ok(self.trace_unchecked(solution, origin, direction.normalize(), shading))
    }

    /// Where the BVH's `hit` of the ray from `origin` along unit `dir` lies: the element that
    /// faces the ray, the point on its plane, the distance, and whether it is its front side.
    /// The hit is recomputed in double precision against the element's plane: the BVH works
    /// in single precision, and interpolation wants the point on the plane.
    fn surface_point(&self, origin: DVec3, dir: DVec3, hit: &Hit) -> (usize, DVec3, f64, bool) {
        let e = self.facing_element(hit.triangle, dir);
        let el = &self.mesh.elements[e];
        let denom = el.normal.dot(dir);
        let distance =
            if denom.abs() > 1e-12 { el.normal.dot(el.centre - origin) / denom } else { f64::from(hit.t) };
        (e, origin + dir * distance, distance, denom < 0.0)
    }

    /// `trace` for a solution already checked and a unit direction.
    fn trace_unchecked(
        &self,
        solution: &Solution,
        origin: DVec3,
        dir: DVec3,
        shading: Shading,
    ) -> Option<SurfaceHit> {
        let hit = self.accel.closest_hit(origin.as_vec3(), dir.as_vec3(), f32::MAX)?;
        let (e, p_world, distance, front_facing) = self.surface_point(origin, dir, &hit);
        let radiance = if front_facing {
            let b = match shading {
                Shading::Flat => solution.element_radiosity[e],
                Shading::Smooth => self.interpolate(solution, e, p_world),
            };
            b / PI
        } else {
            Rgb::ZERO
        };
        Some(SurfaceHit {
            element: e as u32,
            object: self.mesh.element_object(e) as u32,
            p_world,
            distance,
            front_facing,
            radiance,
        })
    }

    /// Radiosity at `p` (on element `e`'s plane), interpolated from its vertices.
    fn interpolate(&self, solution: &Solution, e: usize, p: DVec3) -> Rgb {
        self.interpolate_values(&solution.vertex_radiosity, e, p)
    }

    /// Any per-vertex quantity at `p` (on element `e`'s plane), interpolated from `e`'s vertices.
    fn interpolate_values<T>(&self, vertex_values: &[T], e: usize, p: DVec3) -> T
    where
        T: Copy + std::ops::Mul<f64, Output = T> + std::ops::Add<Output = T>,
    {
        let idx = self.mesh.elements[e].vertex_indices();
        let w = self.corner_weights(e, p);
        (1..idx.len())
            .fold(vertex_values[idx[0] as usize] * w[0], |sum, k| sum + vertex_values[idx[k] as usize] * w[k])
    }

    /// The weights of element `e`'s corners at point `p` of its plane: barycentric on a
    /// triangle, bilinear on a quad (unused ones 0).
    fn corner_weights(&self, e: usize, p: DVec3) -> [f64; 4] {
        let el = &self.mesh.elements[e];
        let idx = el.vertex_indices();
        let pos = |k: usize| self.mesh.positions[idx[k] as usize];
        // Work in 2D on the element's plane, in units of the element's size, so that the
        // tolerances below are relative.
        let origin = pos(0);
        let axis_u = (pos(1) - origin).normalize_or_zero();
        let axis_v = el.normal.cross(axis_u);
        let scale = 1.0 / el.area.sqrt().max(f64::MIN_POSITIVE);
        let to_2d = |q: DVec3| DVec2::new((q - origin).dot(axis_u), (q - origin).dot(axis_v)) * scale;
        let p2 = to_2d(p);
        if idx.len() == 3 {
            let w = barycentric(p2, to_2d(pos(1)), to_2d(pos(2)));
            [w[0], w[1], w[2], 0.0]
        } else {
            let (s, t) = inverse_bilinear(p2, DVec2::ZERO, to_2d(pos(1)), to_2d(pos(2)), to_2d(pos(3)));
            [(1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t]
        }
    }

    /// The unit normal a gather uses at point `x` of element `e`, and where its secondary
    /// rays leave from.
    ///
    /// The normal is the element's own, or where the mesh smooths across facets, the vertex
    /// normals interpolated as the radiosity is (Phong 1975), so the direct light computed
    /// per pixel does not bring back the facets that the smoothed indirect part hides.
    ///
    /// The origin is `x` lifted off the surface by `lift` along that normal, and first, on a
    /// facet shaded with interpolated normals, moved out to the curved surface those normals
    /// describe. Each corner's tangent plane that `x` lies below pushes it up to that plane,
    /// and the pushes are blended with the corners' weights (Hanika 2021, "Hacking the
    /// shadow terminator", Ray Tracing Gems II ch. 4). Without it, shadow rays from a facet
    /// of a tessellated sphere near its terminator hit the neighbouring facets, which the
    /// smooth normals say are not there: a band of dark speckles where the light grazes the
    /// surface. Both come from one set of corner weights.
    fn shading_frame(&self, e: usize, x: DVec3) -> (DVec3, DVec3) {
        let el = &self.mesh.elements[e];
        if self.shading_normals.is_empty() || is_flat(el, &self.shading_normals) {
            return (el.normal, x + el.normal * self.lift);
        }
        let w = self.corner_weights(e, x);
        let corners = el.vertex_indices().iter().zip(w);
        let smooth = corners.clone().fold(DVec3::ZERO, |n, (&v, w)| n + self.shading_normals[v as usize] * w);
        let smooth = smooth.normalize_or_zero();
        // Far from the facet's own normal only on a degenerate fan; keep the facet's there.
        let n = if smooth.dot(el.normal) > 0.1 { smooth } else { el.normal };
        let push = corners.fold(DVec3::ZERO, |push, (&v, w)| {
            let (corner, normal) = (self.mesh.positions[v as usize], self.shading_normals[v as usize]);
            push - normal * ((x - corner).dot(normal).min(0.0) * w)
        });
        (n, x + push + n * self.lift)
    }

    /// Renders `solution` seen from `camera`.
    ///
    /// # Errors
    /// [`RenderError::BadParameter`] for out-of-range settings, [`RenderError::SolutionMismatch`]
    /// when `solution` was computed for another mesh.
    pub fn render(
        &self,
        solution: &Solution,
        camera: &Camera,
        params: &RenderParams,
    ) -> Result<Rendering, RenderError> {
        self.render_with_progress(solution, camera, params, &|| {})
    }

    /// As [`Renderer::render`], calling `row_done` (from any worker thread) after each row.
    ///
    /// # Errors
    /// As [`Renderer::render`].
    pub fn render_with_progress(
        &self,
        solution: &Solution,
        camera: &Camera,
        params: &RenderParams,
        row_done: &(dyn Fn() + Sync),
    ) -> Result<Rendering, RenderError> {
        params.validate()?;
        self.check(solution)?;
        if params.gather == Gather::Direct && !self.has_direct_part(solution) {
            return Err(RenderError::NoDirectPart);
        }
        let (w, h) = (params.width as usize, params.height as usize);
        let rays = CameraRays::new(camera, params.width, params.height);
        // What the centre ray of a pixel, or the ray through a pixel corner, sees: the object
        // and whether it emits (a lamp is often one face of a larger object).
        let what = |hit: &Hit| {
            let e = self.triangle_element[hit.triangle as usize] as usize;
            let emits = self.mesh.element_material(e).emission.max_channel() > 0.0;
            (self.mesh.element_object(e) as u32, emits)
        };
        let first_hit =
            |dir: DVec3| self.accel.closest_hit(camera.position.as_vec3(), dir.as_vec3(), f32::MAX);
        let seen = |px: f64, py: f64| first_hit(rays.direction(px, py)).as_ref().map(what);
        // Pixel corners: (w + 1) × (h + 1), shared by the four pixels around each.
        let corners: Vec<Option<(u32, bool)>> = (0..=h)
            .into_par_iter()
            .flat_map_iter(|y| (0..=w).map(move |x| (x, y)))
            .map(|(x, y)| if params.edge_factor > 1 { seen(x as f64, y as f64) } else { None })
            .collect();
        let centre_dir = |i: usize| rays.direction((i % w) as f64 + 0.5, (i / w) as f64 + 0.5);
        let centre_hits: Vec<Option<Hit>> =
            (0..w * h).into_par_iter().map(|i| first_hit(centre_dir(i))).collect();
        // What each pixel's centre sees of the emitters, neighbours probing with different
        // sets of points (see `gather::PROBE_SETS`): a pixel is then judged by its 3 × 3
        // neighbourhood, four sets' worth of points for the price of one.
        let probed: Vec<Option<Seen>> = (0..w * h)
            .into_par_iter()
            .map(|i| {
                let set = (i % w) % 2 + 2 * ((i / w) % 2);
                self.probe(camera.position, centre_dir(i), centre_hits[i].as_ref()?, params, set)
            })
            .collect();
        let effort_of = |x: usize, y: usize, p: &RenderParams| {
            let around = (y.saturating_sub(1)..(y + 2).min(h))
                .flat_map(|j| (x.saturating_sub(1)..(x + 2).min(w)).map(move |i| j * w + i));
            match probed[y * w + x] {
                Some(own) => Self::effort_from(around.filter_map(|i| probed[i]).fold(own, Seen::union), p),
                None => Effort::PLAIN,
            }
        };
        let cache = (params.gather == Gather::Full).then(|| {
            // One pixel's width per unit of distance from the eye.
            let pixel_angle = 2.0 * (camera.fov_y_deg.to_radians() * 0.5).tan() / f64::from(params.height);
            let sites: Vec<Option<Site>> = (0..w * h)
                .into_par_iter()
                .map(|i| {
                    let (e, point, distance, front) =
                        self.surface_point(camera.position, centre_dir(i), centre_hits[i].as_ref()?);
                    let reflects = self.mesh.element_material(e).reflectance.max_channel() > 0.0;
                    // A thousandth of the way to the element's centre: a centre ray that
                    // meets a corner's edge (within the single-precision hit) would otherwise
                    // gather from the edge itself, half its rays slipping past the other
                    // surface — one dark record as large as its far-travelled rays say.
                    let point = point + (self.mesh.elements[e].centre - point) * 1e-3;
                    // A record's radius is clamped between multiples of this: it must be a
                    // positive number (an eye on a surface would make it 0).
                    let pixel_size = distance * pixel_angle;
                    let sized = pixel_size.is_finite() && pixel_size > 0.0;
                    let (normal, origin) = self.shading_frame(e, point);
                    (front && reflects && sized).then_some(Site { point, normal, origin, pixel_size })
                })
                .collect();
            IrradianceCache::build(w, h, &sites, |i, site, factor| {
                let key = i as u64 * u64::from(crate::cache::MAX_RAY_FACTOR + 1) + u64::from(factor);
                let mut rng = Rng::for_task(params.seed, RECORD_TASK, key);
                let count = params.gather_rays * RECORD_RAYS_PER_GATHER_RAY * factor;
                self.gather_record(solution, site, count, params.shading, &mut rng)
            })
        });
        let mut pixels = vec![Rgb::ZERO; w * h];
        let mut object_ids = vec![None; w * h];
        let plain = *params;
        let edge =
            RenderParams { samples_per_pixel: params.samples_per_pixel * params.edge_factor, ..*params };
        // A lamp's outline: the lamp is tens of times brighter than what lies beside it, so
        // a pixel's share of it, counted in samples, is that much noisier against the
        // pixel's value. These few pixels (a lamp's perimeter) take the edge factor squared.
        let lamp_edge = RenderParams {
            samples_per_pixel: params.samples_per_pixel
                * (params.edge_factor * params.edge_factor).min(RenderParams::MAX_EDGE_FACTOR),
            ..*params
        };
        pixels.par_chunks_mut(w).zip(object_ids.par_chunks_mut(w)).enumerate().for_each(|(y, (row, ids))| {
            for x in 0..w {
                let index = (y * w + x) as u64;
                let mut rng = Rng::for_task(params.seed, PIXEL_TASK, index);
                let centre_hit = centre_hits[y * w + x];
                let centre = centre_hit.as_ref().map(what);
                ids[x] = centre.map(|(object, _)| object);
                // An edge is decided from rays apart from the pixel's samples, so that
                // sampling more where the outline runs does not bias the pixel: a decision
                // taken from its own samples would keep the low estimate of a pixel whose
                // samples all missed a sliver of the lamp.
                let around =
                    [(x, y), (x + 1, y), (x, y + 1), (x + 1, y + 1)].map(|(i, j)| corners[j * (w + 1) + i]);
                let on_edge = params.edge_factor > 1 && around.iter().any(|c| *c != centre);
                let emits = |c: &Option<(u32, bool)>| c.is_some_and(|(_, emits)| emits);
                let on_lamp = on_edge && around.iter().chain([&centre]).any(emits);
                let p = match (on_edge, on_lamp) {
                    (_, true) => &lamp_edge,
                    (true, false) => &edge,
                    (false, false) => &plain,
                };
                let n = p.samples_per_pixel;
                let effort = effort_of(x, y, p);
                // Sample i's place in the pixel is stratum i of the pixel's grid; the strata
                // of the emitters and of the hemisphere it takes are drawn apart from that, so
                // that where only some samples see a surface (the pixels along an outline,
                // all from one side of the pixel) they still sample the whole lamp and not
                // one end of it: tied together, the floor's front edge read up to 45 % bright
                // in the short block's penumbra and 55 % dark beside it.
                let strata = shuffled(n, &mut rng);
                let rotation = rng.next_f64();
                let mut sum = Rgb::ZERO;
                for i in 0..n {
                    let dir = rays.jittered_direction(x as u32, y as u32, i, n, &mut rng);
                    if let Some(hit) = self.trace_unchecked(solution, camera.position, dir, p.shading) {
                        sum += match p.gather {
                            Gather::None => hit.radiance,
                            _ if !hit.front_facing => Rgb::ZERO,
                            gather => {
                                let e = hit.element as usize;
                                let cached = cache.as_ref().map(|c| (c, x, y));
                                self.gathered_sample(
                                    solution,
                                    e,
                                    hit.p_world,
                                    gather,
                                    p,
                                    effort,
                                    Stratum { index: strata[i as usize], rotation },
                                    cached,
                                    &mut rng,
                                ) / PI
                            }
                        };
                    }
                }
                row[x] = sum / f64::from(n);
            }
            row_done();
        });
        Ok(Rendering { radiance: HdrImage::from_pixels(params.width, params.height, pixels), object_ids })
    }
}

impl Renderer {
    /// Radiosity B (W/unit²) leaving point `p` of element `e` (on its plane), gathered with
    /// `params.gather` from `params.samples_per_pixel` samples stratified as a pixel's are,
    /// from the stream keyed by `(params.seed, key)`: a lightmap's texels, where `key` names
    /// the texel. [`Gather::None`] gives the solution interpolated as [`Shading::Smooth`].
    ///
    /// # Errors
    /// [`RenderError::BadParameter`], [`RenderError::SolutionMismatch`] and
    /// [`RenderError::NoDirectPart`] as [`Renderer::render`]; an element index out of range is
    /// a bug in the caller (panics).
    pub fn gathered_radiosity(
        &self,
        solution: &Solution,
        e: usize,
        p: DVec3,
        params: &RenderParams,
        key: u64,
    ) -> Result<Rgb, RenderError> {
        params.validate()?;
        self.check(solution)?;
        if params.gather == Gather::None {
            return Ok(self.interpolate(solution, e, p));
        }
        if params.gather == Gather::Direct && !self.has_direct_part(solution) {
            return Err(RenderError::NoDirectPart);
        }
        let mut rng = Rng::for_task(params.seed, TEXEL_TASK, key);
        let n = params.samples_per_pixel;
        let effort = Self::effort_from(self.probe_at(e, p, 0), params);
        let rotation = rng.next_f64();
        let sum: Rgb = (0..n)
            .map(|index| {
                let stratum = Stratum { index, rotation };
                self.gathered_sample(solution, e, p, params.gather, params, effort, stratum, None, &mut rng)
            })
            .sum();
        Ok(sum / f64::from(n))
    }

    /// What the point a pixel's centre ray (from `eye` along `dir`, meeting `hit`) sees of
    /// the emitters, by probe set `set`; `None` without a gather or on a surface's back.
    fn probe(&self, eye: DVec3, dir: DVec3, hit: &Hit, params: &RenderParams, set: usize) -> Option<Seen> {
        if params.gather == Gather::None {
            return None;
        }
        match self.surface_point(eye, dir, hit) {
            (e, p, _, true) => Some(self.probe_at(e, p, set)),
            _ => None,
        }
    }

    /// What point `p` of element `e` sees of the emitters, by probe set `set`.
    fn probe_at(&self, e: usize, p: DVec3, set: usize) -> Seen {
        let (n, origin) = self.shading_frame(e, p);
        self.emitters.probe(&self.blockers, p, n, origin, set)
    }

    /// What the samples of a point take, from what probe rays apart from theirs saw there
    /// (so that spending more where it pays does not bias the estimate):
    /// `params.penumbra_factor` times the shadow rays where it sees part of the emitters, and
    /// no cosine directions for the direct light where every emitter point it sees is far
    /// and small enough for points drawn on the emitters alone (see [`Emitters::probe`]).
    fn effort_from(seen: Seen, params: &RenderParams) -> Effort {
        let light_factor = if seen.partly() { params.penumbra_factor } else { 1 };
        Effort { light_factor, cosines: !seen.small }
    }

    /// One sample of the radiosity leaving `x` on element `e` with a final gather, taking
    /// `stratum` of its pixel's or texel's emitter points and directions and what `effort`
    /// asks (see the `gather` module for the estimators). With [`Gather::Full`], `cache` (and the pixel the sample belongs to)
    /// gives the indirect light where a record covers `x`; elsewhere the sample gathers it.
    #[allow(clippy::too_many_arguments)]
    fn gathered_sample(
        &self,
        solution: &Solution,
        e: usize,
        x: DVec3,
        gather: Gather,
        params: &RenderParams,
        effort: Effort,
        stratum: Stratum,
        cache: Option<(&IrradianceCache, usize, usize)>,
        rng: &mut Rng,
    ) -> Rgb {
        let material = self.mesh.element_material(e);
        let (n, origin) = self.shading_frame(e, x);
        let lights = if self.emitters.is_empty() { 0 } else { params.shadow_rays * effort.light_factor };
        let cached = match (gather, cache) {
            (Gather::Full, Some((cache, px, py))) => cache.lookup(px, py, x, n),
            _ => None,
        };
        let gathers = gather == Gather::Full && cached.is_none();
        // As many cosine directions as emitter points for the direct light alone: the two
        // strategies' balance is what keeps the 1/r² next to a large emitter in check.
        let cosines = match gather {
            _ if gathers => params.gather_rays,
            _ if lights > 0 && effort.cosines => lights,
            _ => 0,
        };
        let mis = DirectMis { lights, cosines };
        let strata = params.samples_per_pixel * lights;
        let mut direct = gather::emitter_samples(
            &self.emitters,
            &self.blockers,
            x,
            n,
            origin,
            stratum.index * lights,
            strata,
            stratum.rotation,
            mis,
            rng,
        );
        // With a cache, samples of one pixel take different numbers of rays.
        let whole = cache.is_none();
        let (cosine_direct, reflected) =
            self.cosine_rays(solution, origin, n, params, stratum.index, mis, gathers, whole, rng);
        direct += cosine_direct;
        let indirect = match gather {
            Gather::Direct => self.indirect_part(solution, e, x, params.shading),
            _ => material.reflectance * cached.unwrap_or(reflected),
        };
        material.emission + material.reflectance * direct + indirect
    }

    /// `mis.cosines` cosine-weighted rays leaving from `origin` (normal `n`), stratified over the pixel's
    /// samples when `whole`, else over these rays alone: returns their half of the direct
    /// irradiance (emission where they land, MIS weighted) and, when `reflect`, the
    /// irradiance from the light the solution reflects (B − E where they land: ∫ L cos θ dω
    /// with pdf cos θ / π is π · mean(L), and L = (B − E)/π).
    #[allow(clippy::too_many_arguments)]
    fn cosine_rays(
        &self,
        solution: &Solution,
        origin: DVec3,
        n: DVec3,
        params: &RenderParams,
        sample: u32,
        mis: DirectMis,
        reflect: bool,
        whole: bool,
        rng: &mut Rng,
    ) -> (Rgb, Rgb) {
        let count = mis.cosines;
        if count == 0 {
            return (Rgb::ZERO, Rgb::ZERO);
        }
        // Stratified over the pixel's samples when every sample takes its share of one grid;
        // over the sample's own rays when a cache decides sample by sample who gathers (a
        // sample's share of the pixel's grid is one band of directions, biased alone).
        let (first, strata) =
            if whole { (sample * count, params.samples_per_pixel * count) } else { (0, count) };
        let (columns, rows) = gather::grid(strata);
        let (mut direct, mut reflected) = (Rgb::ZERO, Rgb::ZERO);
        for j in first..first + count {
            let (cx, cy) = (j % columns, j / columns);
            let u = (f64::from(cx) + rng.next_f64()) / f64::from(columns);
            let v = (f64::from(cy) + rng.next_f64()) / f64::from(rows);
            let dir = gather::cosine_direction(n, u, v);
            let Some((e, distance, cos_y)) = self.land(origin, dir) else {
                continue;
            };
            if cos_y <= 0.0 {
                continue; // the back of a one-sided surface: nothing leaves it
            }
            direct += self.emitted(e, n.dot(dir), cos_y, distance, mis);
            if reflect {
                reflected +=
                    self.reflected(solution, e, origin + dir * distance, distance, params.shading, rng);
            }
        }
        (direct, reflected / f64::from(count))
    }

    /// A cosine-weighted direction's share of the direct irradiance (MIS weighted, see
    /// [`DirectMis::term`]) when it lands on element `e` at `distance`, cosines `cos_x` at
    /// its origin and `cos_y` at `e`: nothing unless `e` emits.
    fn emitted(&self, e: usize, cos_x: f64, cos_y: f64, distance: f64, mis: DirectMis) -> Rgb {
        let emission = self.mesh.element_material(e).emission;
        if emission.max_channel() <= 0.0 {
            return Rgb::ZERO;
        }
        mis.term(emission, cos_x, cos_y, distance * distance, self.emitters.pdf_area_of(emission))
    }

    /// Where a secondary ray from `origin` along unit `dir` lands: the element that faces it,
    /// the distance, and the cosine between the ray and that element's normal, reversed
    /// (positive on its front side, where light leaves it). `None` when it leaves the scene.
    fn land(&self, origin: DVec3, dir: DVec3) -> Option<(usize, f64, f64)> {
        let hit = self.accel.closest_hit(origin.as_vec3(), dir.as_vec3(), f32::MAX)?;
        let e = self.facing_element(hit.triangle, dir);
        let el = &self.mesh.elements[e];
        let cos_y = -el.normal.dot(dir);
        // On the element's plane in double precision where the ray is not along it.
        let distance =
            if cos_y.abs() > 1e-12 { el.normal.dot(origin - el.centre) / cos_y } else { f64::from(hit.t) };
        Some((e, distance, cos_y))
    }

    /// The radiosity point `y` of element `e` reflects as a gathering ray that travelled
    /// `distance` sees it: B − E from the solution (its emission is direct light, sampled
    /// apart). A ray shorter than [`SHORT_RAY`] times the element's side lands where the mesh
    /// is too coarse for it, beside a contact or a shadow's edge: there the direct part is
    /// taken by [`LANDING_SHADOW_RAYS`] rays from `y` and only the rest, B − E −
    /// B_direct, from the solution (as [`Gather::Direct`] does at a pixel). The foot of the
    /// Cornell box's short block gathered from the floor's penumbra, smoothed over its
    /// elements, and read 30–145 % bright within 3 mm of the floor.
    fn reflected(
        &self,
        solution: &Solution,
        e: usize,
        y: DVec3,
        distance: f64,
        shading: Shading,
        rng: &mut Rng,
    ) -> Rgb {
        let material = self.mesh.element_material(e);
        let short = distance < SHORT_RAY * self.mesh.elements[e].area.sqrt();
        if !short || self.emitters.is_empty() || !self.has_direct_part(solution) {
            let b = match shading {
                Shading::Flat => solution.element_radiosity[e],
                Shading::Smooth => self.interpolate(solution, e, y),
            };
            return (b - material.emission).map(|c| c.max(0.0));
        }
        let (n, origin) = self.shading_frame(e, y);
        // Both strategies, as at a pixel: points on a large emitter alone blow up beside it
        // (a corner of a furnace).
        let lights = LANDING_SHADOW_RAYS;
        let mis = DirectMis { lights, cosines: lights };
        let rotation = rng.next_f64();
        let mut direct = gather::emitter_samples(
            &self.emitters,
            &self.blockers,
            y,
            n,
            origin,
            0,
            lights,
            rotation,
            mis,
            rng,
        );
        for _ in 0..lights {
            let dir = gather::cosine_direction(n, rng.next_f64(), rng.next_f64());
            if let Some((hit, distance, cos_y)) = self.land(origin, dir) {
                direct += self.emitted(hit, n.dot(dir), cos_y, distance, mis);
            }
        }
        material.reflectance * direct + self.indirect_part(solution, e, y, shading)
    }

    /// What the solution holds at point `y` of element `e` besides emission and direct light,
    /// B − E − B_direct, clamped because the direct part and the total are interpolated apart.
    fn indirect_part(&self, solution: &Solution, e: usize, y: DVec3, shading: Shading) -> Rgb {
        let (total, direct) = match shading {
            Shading::Flat => (solution.element_radiosity[e], solution.element_direct[e]),
            Shading::Smooth => {
                (self.interpolate(solution, e, y), self.interpolate_values(&solution.vertex_direct, e, y))
            }
        };
        (total - self.mesh.element_material(e).emission - direct).map(|c| c.max(0.0))
    }

    /// Gathers one irradiance-cache record at `site`: `count` cosine-weighted rays on a
    /// stratified grid, each taking the reflected radiosity where it lands (as
    /// [`Renderer::cosine_rays`]), and the harmonic mean of the distances they travel (Ward et
    /// al. 1988), which sizes the record.
    fn gather_record(
        &self,
        solution: &Solution,
        site: &Site,
        count: u32,
        shading: Shading,
        rng: &mut Rng,
    ) -> Gathered {
        let (columns, rows) = gather::grid(count);
        let origin = site.origin;
        let mut values = vec![Rgb::ZERO; count as usize];
        let mut distances = vec![f64::INFINITY; count as usize];
        for j in 0..count {
            let u = (f64::from(j % columns) + rng.next_f64()) / f64::from(columns);
            let v = (f64::from(j / columns) + rng.next_f64()) / f64::from(rows);
            let dir = gather::cosine_direction(site.normal, u, v);
            let Some((e, distance, cos_y)) = self.land(origin, dir) else {
                continue;
            };
            distances[j as usize] = distance.max(self.lift);
            if cos_y > 0.0 {
                values[j as usize] =
                    self.reflected(solution, e, origin + dir * distance, distance, shading, rng);
            }
        }
        let inverse_distances: f64 = distances.iter().map(|d| 1.0 / d).sum();
        Gathered {
            irradiance: values.iter().copied().sum::<Rgb>() / f64::from(count),
            harmonic_distance: if inverse_distances > 0.0 {
                f64::from(count) / inverse_distances
            } else {
                f64::INFINITY
            },
            gradient: gather::irradiance_gradient(site.normal, columns, rows, &values, &distances),
        }
    }
}

/// Barycentric weights of `p` in the triangle `(0, b, c)`, clamped into the triangle.
fn barycentric(p: DVec2, b: DVec2, c: DVec2) -> [f64; 3] {
    let det = b.perp_dot(c);
    if det.abs() < 1e-300 {
        return [1.0, 0.0, 0.0];
    }
    let u = p.perp_dot(c) / det;
    let v = b.perp_dot(p) / det;
    // A hit may sit a hair outside its triangle (single-precision BVH); clamping keeps the
    // weights a convex combination.
    let (u, v) = (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
    let s = u + v;
    let (u, v) = if s > 1.0 { (u / s, v / s) } else { (u, v) };
    [1.0 - u - v, u, v]
}

/// Bilinear coordinates `(s, t)` in [0, 1]² of `p` in the convex quad `a b c d`, where
/// P(s, t) = a + (b − a)s + (d − a)t + (a − b + c − d)st (Quílez 2010). Coordinates are in
/// units of the quad's size.
fn inverse_bilinear(p: DVec2, a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> (f64, f64) {
    let (e, f, g, h) = (b - a, d - a, a - b + c - d, p - a);
    let k2 = g.perp_dot(f);
    let k1 = e.perp_dot(f) + h.perp_dot(g);
    let k0 = h.perp_dot(e);
    // s from t, using whichever axis divides best.
    let s_of = |t: f64| {
        let den = e + g * t;
        let num = h - f * t;
        if den.x.abs() > den.y.abs() { num.x / den.x } else { num.y / den.y }
    };
    let t = if k2.abs() < 1e-9 {
        // A parallelogram (or a trapezoid with these sides parallel): the equation is linear.
        -k0 / k1
    } else {
        let disc = (k1 * k1 - 4.0 * k0 * k2).max(0.0).sqrt();
        let t1 = (-k1 - disc) / (2.0 * k2);
        let t2 = (-k1 + disc) / (2.0 * k2);
        let inside = |t: f64| (-1e-6..=1.0 + 1e-6).contains(&t) && (-1e-6..=1.0 + 1e-6).contains(&s_of(t));
        if inside(t1) || !inside(t2) { t1 } else { t2 }
    };
    let t = if t.is_finite() { t } else { 0.0 };
    let s = s_of(t);
    let s = if s.is_finite() { s } else { 0.0 };
    (s.clamp(0.0, 1.0), t.clamp(0.0, 1.0))
}

/// Per vertex of `mesh`, its own shading normal ([`Mesh::shading_normals`]: its surface's
/// normal, a sphere's true normal) averaged with those of the vertices it pools with
/// ([`Mesh::smoothing`], weighted as the radiosity is), normalised: a shading normal that
/// turns smoothly across the facets of a curved model. Empty when every vertex's is its
/// elements' own normal (flat scenes such as the Cornell box), so they render as with
/// facet normals.
fn shading_normals(mesh: &Mesh) -> Vec<DVec3> {
    let own = &mesh.shading_normals;
    let normals: Vec<DVec3> = (0..own.len())
        .map(|v| {
            let sum = mesh.smoothing.partners_of(v).fold(own[v], |n, (q, w)| n + own[q as usize] * w);
            let n = sum.normalize_or_zero();
            if n == DVec3::ZERO { own[v] } else { n }
        })
        .collect();
    let turned = mesh.elements.iter().any(|el| !is_flat(el, &normals));
    if turned { normals } else { Vec::new() }
}

/// `0..n` in an order drawn from `rng` (Fisher–Yates; the modulo's bias is below 2⁻⁵⁰).
fn shuffled(n: u32, rng: &mut Rng) -> Vec<u32> {
    let mut order: Vec<u32> = (0..n).collect();
    for i in (1..order.len()).rev() {
        let j = rng.next_u64() % (i as u64 + 1);
        order.swap(i, j as usize);
    }
    order
}

/// Whether every vertex normal of `el` is its own normal, within round-off of a normal
/// computed from other corners of the same plane (3e-5 rad): there is nothing to interpolate.
fn is_flat(el: &radiosity_mesh::Element, normals: &[DVec3]) -> bool {
    el.vertex_indices().iter().all(|&v| normals[v as usize].dot(el.normal) > 1.0 - 5e-10)
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiosity_core::{Facing, Material, MeshParams, Object, Polygon, Scene, Shape, Sides, Sphere};

    /// A sample that gathers on its own (a cache covers its neighbours, not it) must spread
    /// its rays over the whole hemisphere, not over its share of the pixel's grid, which is
    /// one band of directions. On the Cornell box's ceiling 5 mm from the green wall (half the
    /// hemisphere is that wall), 2 000 such samples of 8 rays, each the 4th of its pixel's 16,
    /// average within 3 % of a 4 096-ray record (their noise, about 0.5 %, and the record's,
    /// well under that). Given its share of the pixel's grid instead, it read twice the
    /// record's irradiance.
    #[test]
    fn a_sample_that_gathers_alone_covers_the_whole_hemisphere() {
        let scene = radiosity_core::cornell_box();
        let problem = radiosity_solver::Problem::new(&scene, &scene.mesh_params()).unwrap();
        let mut solver = problem.solver(radiosity_solver::SolverParams::preview()).unwrap();
        solver.solve();
        let solution = solver.solution();
        let renderer = Renderer::new(problem.mesh().clone());
        let hit = renderer
            .trace(&solution, DVec3::new(5.0, 300.0, 300.0), DVec3::Y, Shading::Smooth)
            .unwrap()
            .expect("the ceiling");
        let (e, x) = (hit.element as usize, hit.p_world);
        let (n, origin) = renderer.shading_frame(e, x);
        let site = Site { point: x, normal: n, origin, pixel_size: 1.0 };
        let mut rng = Rng::for_task(1, 2, 3);
        let record = renderer.gather_record(&solution, &site, 4096, Shading::Smooth, &mut rng);
        let params = RenderParams { gather: Gather::Full, ..RenderParams::default() };
        let mis = DirectMis { lights: 0, cosines: params.gather_rays };
        let count = 2000;
        let alone: Rgb = (0..count)
            .map(|_| renderer.cosine_rays(&solution, origin, n, &params, 3, mis, true, false, &mut rng).1)
            .sum::<Rgb>()
            / f64::from(count);
        let (got, expected) = (alone.luminance(), record.irradiance.luminance());
        assert!((got / expected - 1.0).abs() < 0.03, "alone {got} against the record's {expected}");
    }

    /// A gathering ray that lands a hair's width away, on a floor element half in a blocker's
    /// shadow, takes the light of the point it lands on and not the element's mean: under
    /// the blocker (where nothing lights the floor, the rest of the scene being black) about
    /// none; in the open, the lamp's direct light (the closed form of a point under a
    /// square). A long ray still takes the element's mean.
    #[test]
    fn short_gathering_rays_see_the_light_where_they_land() {
        let light = Material::try_new("light", Rgb::ZERO, Rgb::splat(1.0)).unwrap();
        let grey = Material::try_new("grey", Rgb::splat(0.5), Rgb::ZERO).unwrap();
        let black = Material::try_new("black", Rgb::ZERO, Rgb::ZERO).unwrap();
        let square = |x0: f64, x1: f64, y0: f64, y1: f64, z: f64, up: bool| {
            let mut v = vec![
                DVec3::new(x0, y0, z),
                DVec3::new(x1, y0, z),
                DVec3::new(x1, y1, z),
                DVec3::new(x0, y1, z),
            ];
            if !up {
                v.reverse();
            }
            Polygon::try_new(v).unwrap()
        };
        let object = |name: &str, material: usize, polygon: Polygon, sides: Sides| Object {
            name: name.into(),
            material,
            shape: Shape::Polygons(vec![polygon]),
            sides,
        };
        let objects = vec![
            object("lamp", 0, square(-0.25, 0.25, -0.25, 0.25, 1.0, false), Sides::One),
            object("floor", 1, square(-2.0, 2.0, -2.0, 2.0, 0.0, true), Sides::One),
            // Over x < 0.1 at half height: the floor's x < 0 is in full shadow.
            object("sheet", 2, square(-3.0, 0.1, -3.0, 3.0, 0.5, true), Sides::Two { emits_back: false }),
        ];
        let scene = Scene::try_new("half shadow", None, vec![light, grey, black], objects).unwrap();
        // One element for the whole floor, no cut along the shadow: the mesh's worst case.
        let mut params = MeshParams::try_new(8.0, 8.0).unwrap();
        params.shadow_outlines = false;
        params.contacts = false;
        params.corner_refinement = 0;
        params.adaptive_levels = 0;
        let problem = radiosity_solver::Problem::new(&scene, &params).unwrap();
        let mut solver = problem.solver(radiosity_solver::SolverParams::default()).unwrap();
        solver.solve();
        let solution = solver.solution();
        let renderer = Renderer::new(problem.mesh().clone());
        let mesh = renderer.mesh().clone();
        let floor = mesh.object_names.iter().position(|n| n == "floor").unwrap();
        let elements: Vec<usize> =
            (0..mesh.elements.len()).filter(|&e| mesh.element_object(e) == floor).collect();
        assert_eq!(elements.len(), 1, "the floor is one element");
        let e = elements[0];
        let mean = solution.element_radiosity[e].to_array()[0];
        let mut rng = Rng::for_task(1, 0, 0);
        let mut at = |x: f64, distance: f64| {
            let y = DVec3::new(x, 0.0, 0.0);
            (0..256)
                .map(|_| renderer.reflected(&solution, e, y, distance, Shading::Flat, &mut rng).to_array()[0])
                .sum::<f64>()
                / 256.0
        };
        let (shadow, open, far) = (at(-1.0, 1e-3), at(0.6, 1e-3), at(-1.0, 100.0));
        // ρ E F from a point 1 below a square lamp of side 0.5, 0.6 off its axis; F summed
        // over the four rectangles the point's foot cuts the lamp into (Howell B-3, a
        // differential area to a parallel rectangle from a corner).
        let corner = |a: f64, b: f64| {
            let (x, y) = (a.abs(), b.abs());
            let f = (x / (1.0 + x * x).sqrt() * (y / (1.0 + x * x).sqrt()).atan()
                + y / (1.0 + y * y).sqrt() * (x / (1.0 + y * y).sqrt()).atan())
                / (2.0 * PI);
            f * a.signum() * b.signum()
        };
        let f = corner(0.25 - 0.6, 0.25) - corner(-0.25 - 0.6, 0.25) - corner(0.25 - 0.6, -0.25)
            + corner(-0.25 - 0.6, -0.25);
        let expected = 0.5 * f;
        assert!(mean > 0.05 * expected, "the element's mean {mean} against {expected} in the open");
        assert!(shadow < 0.02 * mean, "under the sheet: {shadow}, the element's mean {mean}");
        assert!((open / expected - 1.0).abs() < 0.05, "in the open: {open}, closed form {expected}");
        assert_eq!(far, mean, "a long ray takes the element's mean");
    }

    /// A tessellated ball under a small lamp: from points whose interpolated normal sees the
    /// lamp low over the horizon (cosine under 0.25), a shadow ray to the lamp meets nothing,
    /// as on the round ball those normals describe. Leaving from the facets themselves, 36 of
    /// the 204 such rays hit the neighbouring facets.
    #[test]
    fn shadow_rays_leave_a_smooth_ball_as_a_round_one() {
        let light = Material::try_new("light", Rgb::ZERO, Rgb::splat(1.0)).unwrap();
        let white = Material::try_new("white", Rgb::splat(0.5), Rgb::ZERO).unwrap();
        let lamp = [(-0.05, -0.05), (-0.05, 0.05), (0.05, 0.05), (0.05, -0.05)]
            .map(|(x, y)| DVec3::new(x, y, 10.0))
            .to_vec();
        let objects = vec![
            Object {
                name: "lamp".into(),
                material: 0,
                shape: Shape::Polygons(vec![Polygon::try_new(lamp).unwrap()]),
                sides: Sides::One,
            },
            Object {
                name: "ball".into(),
                material: 1,
                shape: Shape::Sphere(Sphere::try_new(DVec3::ZERO, 1.0, Facing::Outward).unwrap()),
                sides: Sides::One,
            },
        ];
        let scene = Scene::try_new("ball", None, vec![light, white], objects).unwrap();
        let mesh = Arc::new(Mesh::build(&scene, &MeshParams::try_new(0.5, 0.25).unwrap()).unwrap());
        let renderer = Renderer::new(mesh.clone());
        let target = DVec3::new(0.0, 0.0, 10.0);
        let (mut grazing, mut blocked, mut blocked_plain) = (0, 0, 0);
        for (e, el) in
            mesh.elements.iter().enumerate().filter(|&(e, _)| mesh.element_material(e).emission == Rgb::ZERO)
        {
            for &corner in el.vertex_indices() {
                let x = el.centre.lerp(mesh.positions[corner as usize], 0.8);
                let (n, origin) = renderer.shading_frame(e, x);
                let cos = n.dot((target - x).normalize());
                if !(0.0..0.25).contains(&cos) {
                    continue;
                }
                grazing += 1;
                let hit = |origin: DVec3| renderer.blockers.occluded(origin.as_vec3(), target.as_vec3());
                blocked += usize::from(hit(origin));
                blocked_plain += usize::from(hit(x + n * renderer.lift));
            }
        }
        assert!(grazing > 100, "{grazing} points near the terminator");
        assert!(blocked * 100 <= grazing, "{blocked} of {grazing} shadow rays blocked");
        assert!(blocked_plain * 10 > grazing, "the facets block only {blocked_plain} of {grazing}");
    }

    #[test]
    fn inverse_bilinear_inverts_the_bilinear_map() {
        let quads = [
            [DVec2::ZERO, DVec2::new(1.0, 0.0), DVec2::new(1.0, 1.0), DVec2::new(0.0, 1.0)],
            [DVec2::ZERO, DVec2::new(2.0, 0.0), DVec2::new(1.5, 1.0), DVec2::new(0.3, 0.8)],
            [DVec2::ZERO, DVec2::new(0.0, 1.0), DVec2::new(-1.2, 1.1), DVec2::new(-1.0, 0.0)],
        ];
        for [a, b, c, d] in quads {
            for i in 0..=10 {
                for j in 0..=10 {
                    let (s, t) = (f64::from(i) / 10.0, f64::from(j) / 10.0);
                    let p = a + (b - a) * s + (d - a) * t + (a - b + c - d) * (s * t);
                    let (s2, t2) = inverse_bilinear(p, a, b, c, d);
                    assert!((s - s2).abs() < 1e-9 && (t - t2).abs() < 1e-9, "({s}, {t}) -> ({s2}, {t2})");
                }
            }
        }
    }

    #[test]
    fn barycentric_weights_sum_to_one_and_locate_points() {
        let (b, c) = (DVec2::new(2.0, 0.0), DVec2::new(0.0, 1.0));
        let w = barycentric(DVec2::new(0.5, 0.25), b, c);
        assert!((w[1] - 0.25).abs() < 1e-12 && (w[2] - 0.25).abs() < 1e-12 && (w[0] - 0.5).abs() < 1e-12);
        let w = barycentric(DVec2::new(5.0, 5.0), b, c);
        assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-12 && w.iter().all(|x| *x >= 0.0));
    }

    #[test]
    fn camera_puts_plus_x_on_the_left_when_looking_down_plus_z() {
        let cam = Camera::try_new(DVec3::ZERO, DVec3::Z, DVec3::Y, 60.0).unwrap();
        let rays = CameraRays::new(&cam, 100, 50);
        assert!(rays.direction(0.0, 25.0).x > 0.0);
        assert!(rays.direction(100.0, 25.0).x < 0.0);
        assert!(rays.direction(50.0, 0.0).y > 0.0);
        // The top edge is at half the vertical field of view.
        let top = rays.direction(50.0, 0.0);
        assert!((top.y.atan2(top.z).to_degrees() - 30.0).abs() < 1e-9);
    }

    #[test]
    fn render_params_are_validated() {
        assert!(RenderParams::default().validate().is_ok());
        assert!(RenderParams::preview().validate().is_ok());
        assert!(RenderParams::high_quality().validate().is_ok());
        let bad = RenderParams { samples_per_pixel: 0, ..RenderParams::default() };
        assert!(matches!(bad.validate(), Err(RenderError::BadParameter { name: "samples_per_pixel", .. })));
        let bad = RenderParams { width: 0, ..RenderParams::default() };
        assert!(bad.validate().is_err());
    }
}
