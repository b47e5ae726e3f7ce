//! Primary visibility: the element a ray meets first, and the radiosity and shading normal
//! at the point it meets, interpolated over the element (barycentric on triangles, inverse
//! bilinear on quads).

use std::f64::consts::PI;
use std::sync::Arc;

use glam::{DVec2, DVec3, Vec3};
use radiosity_accel::{Bvh, Hit, RayQuery};
use radiosity_core::Rgb;
use radiosity_mesh::Mesh;
use radiosity_solver::Solution;

use crate::gather::Emitters;

use super::params::{RenderError, Shading};
use super::{Renderer, SurfaceHit};

impl Renderer {
    /// Builds the ray-query structure over the element triangles of `mesh` (the elements, not
    /// the coarser occluders, so a hit names the element whose radiosity to use).
    pub fn new(mesh: Arc<Mesh>) -> Self {
        let (triangle_element, triangles): (Vec<u32>, Vec<[Vec3; 3]>) = mesh
            .element_triangles()
            .map(|(e, t)| (e, t.map(|i| mesh.positions[i as usize].as_vec3())))
            .unzip();
        let accel = Bvh::new(&triangles);
        let blockers = radiosity_solver::occluder_queries(&mesh);
        let emitters = Emitters::new(&mesh);
        let (lo, hi) = mesh.bounds();
        let lift = 1e-6 * (hi - lo).length().max(f64::MIN_POSITIVE);
        let shading_normals = shading_normals(&mesh);
        Self {
            mesh,
            accel,
            triangle_element,
            blockers,
            emitters,
            lift,
            shading_normals,
            textures: None,
            sky: None,
        }
    }

    /// The element a ray along `dir` sees at BVH triangle `triangle`: where a two-sided
    /// object puts two elements back to back in one place, the one that faces the ray
    /// (which of the two coplanar triangles the BVH reports first is arbitrary).
    pub(super) fn facing_element(&self, triangle: u32, dir: DVec3) -> usize {
        let e = self.triangle_element[triangle as usize] as usize;
        if self.mesh.elements[e].normal.dot(dir) > 0.0 { self.mesh.element_twin(e).unwrap_or(e) } else { e }
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
    pub(super) fn surface_point(&self, origin: DVec3, dir: DVec3, hit: &Hit) -> (usize, DVec3, f64, bool) {
        let e = self.facing_element(hit.triangle, dir);
        let el = &self.mesh.elements[e];
        let denom = el.normal.dot(dir);
        let distance =
            if denom.abs() > 1e-12 { el.normal.dot(el.centre - origin) / denom } else { f64::from(hit.t) };
        (e, origin + dir * distance, distance, denom < 0.0)
    }

    /// The first element triangle along `origin + t·dir` (`dir` unit) that is there: hits on
    /// the clear texels of an alpha-masked face (known once [`Renderer::with_textures`] gave
    /// the faces' texture coordinates) are passed, the ray going on a lift beyond each.
    pub(super) fn closest_seen(&self, origin: DVec3, dir: DVec3) -> Option<Hit> {
        let mut from = 0.0;
        // A bound on faces passed, far above any real stack of leaves along one ray.
        for _ in 0..256 {
            let start = origin + dir * from;
            let hit = self.accel.closest_hit(start.as_vec3(), dir.as_vec3(), f32::MAX)?;
            // Only a mesh with masked faces has holes (and it has them only where the scene's
            // texture coordinates say).
            let masked = !self.mesh.masked_occluders.is_empty();
            let passed = masked
                && self.textures.as_ref().is_some_and(|textures| {
                    let (e, _, distance, _) = self.surface_point(start, dir, &hit);
                    let material = self.mesh.element_material(e);
                    let Some(texture) = material.texture.as_ref().filter(|t| t.mask.is_some()) else {
                        return false;
                    };
                    let object = self.mesh.element_object(e) as u32;
                    textures
                        .uv(object, start, dir, distance)
                        .is_some_and(|uv| !radiosity_mesh::opaque_at(texture, uv))
                });
            if !passed {
                return Some(Hit { t: hit.t + from as f32, ..hit });
            }
            from += f64::from(hit.t) + self.lift;
        }
        None
    }

    /// `trace` for a solution already checked and a unit direction.
    pub(super) fn trace_unchecked(
        &self,
        solution: &Solution,
        origin: DVec3,
        dir: DVec3,
        shading: Shading,
    ) -> Option<SurfaceHit> {
        let hit = self.closest_seen(origin, dir)?;
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
    pub(super) fn interpolate(&self, solution: &Solution, e: usize, p: DVec3) -> Rgb {
        self.interpolate_values(&solution.vertex_radiosity, e, p)
    }

    /// Any per-vertex quantity at `p` (on element `e`'s plane), interpolated from `e`'s vertices.
    pub(super) fn interpolate_values<T>(&self, vertex_values: &[T], e: usize, p: DVec3) -> T
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
    pub(super) fn corner_weights(&self, e: usize, p: DVec3) -> [f64; 4] {
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
    pub(super) fn shading_frame(&self, e: usize, x: DVec3) -> (DVec3, DVec3) {
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
}

/// Barycentric weights of `p` in the triangle `(0, b, c)`, clamped into the triangle.
pub(super) fn barycentric(p: DVec2, b: DVec2, c: DVec2) -> [f64; 3] {
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
pub(super) fn inverse_bilinear(p: DVec2, a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> (f64, f64) {
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
pub(super) fn shading_normals(mesh: &Mesh) -> Vec<DVec3> {
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

/// Whether every vertex normal of `el` is its own normal, within round-off of a normal
/// computed from other corners of the same plane (3e-5 rad): there is nothing to interpolate.
pub(super) fn is_flat(el: &radiosity_mesh::Element, normals: &[DVec3]) -> bool {
    el.vertex_indices().iter().all(|&v| normals[v as usize].dot(el.normal) > 1.0 - 5e-10)
}
