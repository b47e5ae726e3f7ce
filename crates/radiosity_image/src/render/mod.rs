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

use std::sync::Arc;

use glam::DVec3;
use radiosity_accel::Bvh;
use radiosity_core::Rgb;
use radiosity_mesh::Mesh;
use radiosity_solver::Solution;

use crate::HdrImage;
use crate::gather::Emitters;

mod film;
mod final_gather;
mod params;
mod primary;
#[cfg(test)]
mod tests;
mod texture;

pub use params::{RenderError, RenderParams, Shading};
pub use texture::{ElementUvs, element_uvs};

/// An irradiance-cache record gathers this many times [`RenderParams::gather_rays`] (1 024
/// rays at the default). A record speaks for the pixels around it, so its noise shows as a
/// blotch that more samples per pixel do not average out: on the Cornell box at 64 samples
/// per pixel, records of 512 rays left 0.64 % of noise per pixel, as much as the direct
/// light's, and 1 024 rays 0.45 %.
pub const RECORD_RAYS_PER_GATHER_RAY: u32 = 128;

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
    blockers: std::sync::Arc<dyn radiosity_accel::RayQuery>,
    /// The emitting elements, for shadow rays.
    emitters: Emitters,
    /// How far a secondary ray's origin is lifted off its surface: 1e-6 of the scene's
    /// diagonal, far above f32 round-off of positions, far below any feature.
    lift: f64,
    /// Per vertex, the normal a final gather shades with (see `primary::shading_normals`); empty
    /// when every vertex's is its own surface's normal (no smoothing across facets).
    shading_normals: Vec<DVec3>,
    /// The scene's textured faces ([`Renderer::with_textures`]); `None`: every surface shows
    /// its material's mean colour.
    textures: Option<texture::Textures>,
    /// The sky seen where a view ray leaves the scene ([`Renderer::with_sky`]).
    sky: Option<radiosity_core::Sky>,
}

impl Renderer {
    /// The renderer showing `sky` where a view ray leaves the scene (the scene's `[sky]`; the
    /// solve has its light on the surfaces already). Without one, nothing is seen there.
    pub fn with_sky(mut self, sky: Option<radiosity_core::Sky>) -> Self {
        self.sky = sky;
        self
    }

    /// The radiance a view ray along `dir` that leaves the scene meets: the sky's, or none.
    fn background(&self, dir: DVec3) -> Rgb {
        self.sky.as_ref().map_or(Rgb::ZERO, |s| s.radiosity_towards(dir) * (1.0 / std::f64::consts::PI))
    }

    /// The renderer showing the colour textures of `scene`'s materials, which must be the
    /// scene `mesh` was built from: where a ray meets a textured face, the light it reflects
    /// is scaled by the texel's albedo over the material's mean reflectance (which the solve
    /// used). Surfaces without a texture render exactly as without this.
    pub fn with_textures(mut self, scene: &radiosity_core::Scene) -> Self {
        self.textures = texture::Textures::new(scene);
        self
    }

    /// Light `b` (radiosity, or radiance when `per_sr`) seen at element `e` of `object`
    /// along the ray from `origin` along unit `dir` at `distance`, as its texture shows it:
    /// `b` itself, to the bit, where there is none.
    fn textured(
        &self,
        b: Rgb,
        per_sr: bool,
        e: usize,
        object: u32,
        ray: (DVec3, DVec3),
        distance: f64,
    ) -> Rgb {
        let Some(textures) = &self.textures else { return b };
        let material = self.mesh.element_material(e);
        let Some(image) = &material.texture else { return b };
        // A ray along an edge between two model faces may slip between them in the BVH's
        // single precision: once more, a thousandth of the way towards the element's centre.
        let uv = textures.uv(object, ray.0, ray.1, distance).or_else(|| {
            let p = ray.0 + ray.1 * distance;
            let q = p + (self.mesh.elements[e].centre - p) * 1e-3;
            textures.uv(object, ray.0, (q - ray.0).normalize_or_zero(), (q - ray.0).length())
        });
        let Some(uv) = uv else { return b };
        let emitted = if per_sr { material.emission / std::f64::consts::PI } else { material.emission };
        texture::shown(b, emitted, texture::ratio(material, image, uv))
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
}
