//! The meshed scene: surfaces → patches → elements, and what the solver, the renderer and the
//! exporters read of it.

use std::ops::Range;

use glam::DVec3;
use radiosity_core::Material;

use crate::Smoothing;

/// A receiving element: a planar convex triangle or quad.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Element {
    /// Indices into [`Mesh::positions`], counter-clockwise; only the first `vertex_count`.
    pub vertices: [u32; 4],
    /// 3 or 4.
    pub vertex_count: u8,
    /// The patch this element belongs to.
    pub patch: u32,
    /// Centroid.
    pub centre: DVec3,
    /// Unit normal of the lit side.
    pub normal: DVec3,
    /// Area, scene units².
    pub area: f64,
}

impl Element {
    /// The vertex indices in use.
    pub fn vertex_indices(&self) -> &[u32] {
        &self.vertices[..self.vertex_count as usize]
    }
}

/// A shooting patch: a planar convex triangle or quad made of contiguous elements.
#[derive(Clone, Debug, PartialEq)]
pub struct Patch {
    /// Corner positions, counter-clockwise; only the first `corner_count`.
    pub corners: [DVec3; 4],
    /// 3 or 4.
    pub corner_count: u8,
    /// Unit normal of the lit side.
    pub normal: DVec3,
    /// Centroid.
    pub centre: DVec3,
    /// Area (sum of its elements' areas), scene units².
    pub area: f64,
    /// Its elements, a range into [`Mesh::elements`].
    pub elements: Range<u32>,
    /// The surface it belongs to.
    pub surface: u32,
}

impl Patch {
    /// The corners in use.
    pub fn corners(&self) -> &[DVec3] {
        &self.corners[..self.corner_count as usize]
    }
}

/// One input polygon, one sphere, or one group of coplanar edge-connected triangles of a
/// polygon mesh: the unit within which vertices are shared.
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    /// Index into [`Mesh::object_names`].
    pub object: u32,
    /// Index into [`Mesh::materials`].
    pub material: u32,
    /// Its patches, a range into [`Mesh::patches`].
    pub patches: Range<u32>,
    /// True for the back face of a two-sided object ([`radiosity_core::Sides::Two`]): the same geometry as
    /// its `twin`, wound the other way.
    pub back: bool,
    /// The surface on the other face of a two-sided object: same elements in the same order,
    /// reversed. `None` for one-sided objects.
    pub twin: Option<u32>,
}

/// The meshed scene: surfaces → patches → elements, plus the coarse occluder triangles that
/// visibility rays test against.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Vertex positions (shared within a surface only).
    pub positions: Vec<DVec3>,
    /// Per-vertex shading normals (the sphere's true normal on spheres).
    pub shading_normals: Vec<DVec3>,
    /// Receiving elements, grouped by patch.
    pub elements: Vec<Element>,
    /// Shooting patches, grouped by surface.
    pub patches: Vec<Patch>,
    /// Surfaces.
    pub surfaces: Vec<Surface>,
    /// Object names, in scene order.
    pub object_names: Vec<String>,
    /// Materials, in scene order.
    pub materials: Vec<Material>,
    /// The scene's geometry as triangles (input polygons fan-triangulated, sphere facets), for
    /// visibility: far fewer than the element triangles, hence faster rays.
    pub occluders: Vec<[DVec3; 3]>,
    /// The occluders of alpha-masked materials, in occluder order: rays pass their clear texels.
    pub masked_occluders: Vec<crate::MaskedOccluder>,
    /// Vertices of other surfaces that smooth shading pools with each vertex.
    pub smoothing: Smoothing,
    /// Per object, the area left out of the mesh because a solid stands on it or it lies
    /// flat against another surface ([`MeshParams::contacts`]), scene units².
    pub hidden_area: Vec<f64>,
    /// Per object, how many more surfaces its polygons were cut into along shadow outlines
    /// ([`MeshParams::shadow_outlines`]).
    pub shadow_pieces: Vec<u32>,
    /// True when the scene had too many large faces to look for contacts on all of them:
    /// some were meshed whole.
    pub contacts_incomplete: bool,
    /// True when looking for geometry near elements ([`MeshParams::proximity_refinement`])
    /// ran out of its budget: some elements near other geometry were left unrefined.
    pub proximity_incomplete: bool,
}

impl Mesh {
    /// Whether element `e` lies on the back face of a two-sided object.
    pub fn element_is_back(&self, e: usize) -> bool {
        let patch = &self.patches[self.elements[e].patch as usize];
        self.surfaces[patch.surface as usize].back
    }

    /// The element on the other face of element `e` (the same place, wound the other way),
    /// when `e` belongs to a two-sided object.
    pub fn element_twin(&self, e: usize) -> Option<usize> {
        let patch = &self.patches[self.elements[e].patch as usize];
        let surface = &self.surfaces[patch.surface as usize];
        let twin = &self.surfaces[surface.twin? as usize];
        let first = |s: &Surface| self.patches[s.patches.start as usize].elements.start as usize;
        Some(e - first(surface) + first(twin))
    }

    /// The material of element `e`.
    pub fn element_material(&self, e: usize) -> &Material {
        let patch = &self.patches[self.elements[e].patch as usize];
        &self.materials[self.surfaces[patch.surface as usize].material as usize]
    }

    /// The object index of element `e`.
    pub fn element_object(&self, e: usize) -> usize {
        let patch = &self.patches[self.elements[e].patch as usize];
        self.surfaces[patch.surface as usize].object as usize
    }

    /// Corner positions of element `e`.
    pub fn element_corners(&self, e: usize) -> impl Iterator<Item = DVec3> + '_ {
        self.elements[e].vertex_indices().iter().map(|&i| self.positions[i as usize])
    }

    /// Element triangles for drawing and ray casting: `(element, [v0, v1, v2])` with vertex
    /// indices into [`Mesh::positions`]; a quad gives two triangles sharing its first vertex.
    pub fn element_triangles(&self) -> impl Iterator<Item = (u32, [u32; 3])> + '_ {
        self.elements.iter().enumerate().flat_map(|(e, el)| {
            let v = el.vertices;
            let first = std::iter::once((e as u32, [v[0], v[1], v[2]]));
            let second = (el.vertex_count == 4).then_some((e as u32, [v[0], v[2], v[3]]));
            first.chain(second)
        })
    }

    /// Per surface, the area of its one-sided, non-emitting patches that no light lies in
    /// front of (every corner of every emitting patch, and every point of `luminaires`, on
    /// or behind the patch's plane, some strictly behind): they
    /// can receive only reflected light, never direct light, whatever is in between. A large
    /// flat surface like that usually has its normals the wrong way round (a room's walls
    /// modelled facing out); a curved object's far side is many small surfaces.
    /// `luminaires` are the points the scene's point luminaires light from
    /// ([`radiosity_core::Luminaire::light_point`]).
    pub fn area_facing_away_from_light(&self, luminaires: &[DVec3]) -> Vec<f64> {
        let mut away = vec![0.0; self.surfaces.len()];
        let emitting =
            |p: &Patch| self.materials[self.surfaces[p.surface as usize].material as usize].is_emitter();
        let lamps: Vec<DVec3> = (self.patches.iter().filter(|p| emitting(p)))
            .flat_map(|p| p.corners().to_vec())
            .chain(luminaires.iter().copied())
            .collect();
        let (lo, hi) = self.bounds();
        let margin = 1e-9 * (hi - lo).length();
        for p in self.patches.iter().filter(|p| !emitting(p)) {
            let surface = &self.surfaces[p.surface as usize];
            // A lamp in the surface's own plane (the Cornell lamp in its ceiling) lights it
            // no more than one behind it, but it is no sign of a wrong normal: it needs one
            // lamp point strictly behind.
            let side = |q: &DVec3| p.normal.dot(*q - p.centre);
            if surface.twin.is_none()
                && lamps.iter().all(|q| side(q) <= margin)
                && lamps.iter().any(|q| side(q) < -margin)
            {
                away[p.surface as usize] += p.area;
            }
        }
        away
    }

    /// Total area, scene units².
    pub fn total_area(&self) -> f64 {
        self.elements.iter().map(|e| e.area).sum()
    }

    /// Axis-aligned bounds of all vertices.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        self.positions
            .iter()
            .fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            })
    }
}
