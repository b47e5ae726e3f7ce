//! The largest mesh the mesher makes, and the estimate that refuses a scene before meshing it.

use radiosity_core::{MeshParams, Polygon, Scene, Shape};
use thiserror::Error;

use crate::builder::divisions;

/// Why a scene could not be meshed.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum MeshError {
    /// The subdivision would create more elements than the limit.
    #[error(
        "the mesh would have more than {limit} elements by object '{object}' (patch_size {}, element_size {}); use a larger element_size ([mesh] in the scene, or --element-size)",
        short_number(*.patch_size),
        short_number(*.element_size)
    )]
    TooManyElements {
        /// The object at which the running count passed the limit.
        object: String,
        /// The limit.
        limit: usize,
        /// Patch size asked for.
        patch_size: f64,
        /// Element size asked for.
        element_size: f64,
    },
}

/// A number as a person reads it: plain in the usual range, in exponent form otherwise (a
/// `1e300` is not printed as 301 digits).
fn short_number(v: f64) -> String {
    if v == 0.0 || (1e-4..1e9).contains(&v.abs()) { format!("{v}") } else { format!("{v:e}") }
}

/// Most elements a mesh may have; beyond this memory and time explode, so it is an error
/// rather than a hang.
pub const MAX_ELEMENTS: usize = 20_000_000;

pub(crate) fn estimate_polygon_elements(poly: &Polygon, params: &MeshParams) -> usize {
    let v = poly.vertices();
    // The bounding box's diagonal bounds the diameter (within √3) in linear time: the
    // pairwise maximum was quadratic in the corners (39 s for a 10⁵-gon).
    let (lo, hi) = v.iter().fold((v[0], v[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let per_edge = divisions(lo.distance(hi), params.element_size) as f64;
    // A fan of k-2 triangles with n² elements each bounds every case.
    (per_edge * per_edge * (v.len() - 2) as f64).min(usize::MAX as f64) as usize
}

/// An upper bound on the elements `shape` meshes into with `params`, computed in time linear in
/// its corners (saturating, never overflowing).
pub fn estimate_elements(shape: &Shape, params: &MeshParams) -> usize {
    let polygons = |ps: &[Polygon]| {
        ps.iter().fold(0usize, |n, p| n.saturating_add(estimate_polygon_elements(p, params)))
    };
    match shape {
        Shape::Polygons(ps) => polygons(ps),
        Shape::Sphere(s) => {
            let k = divisions(std::f64::consts::PI * s.radius, params.element_size).max(6) as f64;
            (k * k * 4.0).min(usize::MAX as f64) as usize
        }
        Shape::Mesh(m) => polygons(m.polygons()),
    }
}

/// The index of the object with which the running total of [`estimate_elements`] over
/// `scene`'s objects first passes [`MAX_ELEMENTS`], if any: the object a too-large mesh is
/// blamed on (scene loaders report it with its line before anything is meshed).
pub fn first_object_over_limit(scene: &Scene, params: &MeshParams) -> Option<usize> {
    let mut total = 0usize;
    scene.objects.iter().position(|o| {
        let faces = usize::from(o.sides.count());
        total = total.saturating_add(estimate_elements(&o.shape, params).saturating_mul(faces));
        total > MAX_ELEMENTS
    })
}
