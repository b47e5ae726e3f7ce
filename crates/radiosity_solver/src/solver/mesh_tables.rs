//! What the solver precomputes once per mesh: per-element geometry that every row reads,
//! element neighbours, and the ray-skipping structures over the blocking triangles.

use glam::{DVec3, Vec3A};
use radiosity_core::Rgb;
use radiosity_mesh::{Mesh, Patch};

use super::SolverError;
use crate::occluders::{OccluderBoxes, blocking_triangles};
use crate::shaft::Blockers;
use crate::solution::RimFits;

/// Per-mesh tables, fixed when the solver is made.
pub(super) struct MeshTables {
    /// Per vertex, the area of the elements around it (the weights of vertex radiosity).
    pub(super) vertex_area: Vec<f64>,
    /// The rim vertices' linear fits (see [`RimFits`]).
    pub(super) rim_fits: RimFits,
    /// Element areas, packed for the shot loop.
    pub(super) element_area: Vec<f64>,
    /// Per element, the mean of its vertices: the one quadrature point of a far element (the
    /// centre of the bilinear map, see `for_each_point`), which every row needs.
    pub(super) vertex_means: Vec<DVec3>,
    /// Per element, its patch (the loops over a row's elements read this, not the 168-byte
    /// elements).
    pub(super) element_patch: Vec<u32>,
    /// Per element, its circumradius about its centre (see [`element_radius`]).
    pub(super) element_radii: Vec<f64>,
    /// Per element, its corners lifted off it by the ray offset (see [`lift_corners`]).
    pub(super) lifted_corners: Vec<[Vec3A; 4]>,
    /// Per patch, its elements' range, packed (the loops over every patch of a row touch
    /// these and not the patches' corners: a model's rows span 200 k patches).
    pub(super) patch_elements: Vec<std::ops::Range<usize>>,
    /// Consecutive patches in fixed blocks, for the passes over every patch of a row (see
    /// [`super::parallel::patch_blocks`]).
    pub(super) patch_blocks: Vec<std::ops::Range<usize>>,
    /// Per patch, its reflectance (a patch's elements share its surface's material).
    pub(super) patch_reflectance: Vec<Rgb>,
    /// Per patch, the largest circumradius of its elements (about their centres).
    pub(super) patch_element_radius: Vec<f64>,
    /// Elements sharing an edge (see [`element_neighbours`]): element `e`'s are
    /// `neighbours[neighbour_start[e]..neighbour_start[e + 1]]`.
    pub(super) neighbour_start: Vec<u32>,
    pub(super) neighbours: Vec<u32>,
    /// Σ of the element areas.
    pub(super) total_area: f64,
    /// Area-weighted mean reflectance (the ambient term's interreflection factor).
    pub(super) mean_reflectance: Rgb,
    /// Ray origins and targets are lifted this far off their surfaces: a millionth of the
    /// scene's diagonal.
    pub(super) ray_offset: f64,
    /// Boxes around the blocking triangles: a segment whose box meets none needs no ray.
    pub(super) occluder_boxes: OccluderBoxes,
    /// The blocking triangles for shaft culling and candidate lists.
    pub(super) blockers: Blockers,
}

impl MeshTables {
    /// The tables of `mesh`.
    pub(super) fn new(mesh: &Mesh) -> Self {
        let n = mesh.elements.len();
        let mut vertex_area = vec![0.0; mesh.positions.len()];
        for el in &mesh.elements {
            for &v in el.vertex_indices() {
                vertex_area[v as usize] += el.area;
            }
        }
        let total_area = mesh.total_area();
        let mean_reflectance = (mesh.elements.iter().enumerate())
            .map(|(e, el)| mesh.element_material(e).reflectance * el.area)
            .sum::<Rgb>()
            / total_area;
        let (lo, hi) = mesh.bounds();
        // One scan for both ray-skipping structures (it can cost T × V half-space tests).
        let blocking = blocking_triangles(mesh);
        let element_radii: Vec<f64> = (0..n).map(|e| element_radius(mesh, e)).collect();
        let patch_element_radius = mesh
            .patches
            .iter()
            .map(|p| {
                element_radii[p.elements.start as usize..p.elements.end as usize]
                    .iter()
                    .copied()
                    .fold(0.0, f64::max)
            })
            .collect();
        let (neighbour_start, neighbours) = element_neighbours(mesh);
        let ray_offset = 1e-6 * (hi - lo).length();
        let patch_elements: Vec<std::ops::Range<usize>> =
            mesh.patches.iter().map(|p| p.elements.start as usize..p.elements.end as usize).collect();
        Self {
            vertex_area,
            rim_fits: RimFits::new(mesh),
            element_area: mesh.elements.iter().map(|el| el.area).collect(),
            vertex_means: (0..n)
                .map(|e| mesh.element_corners(e).sum::<DVec3>() / f64::from(mesh.elements[e].vertex_count))
                .collect(),
            element_patch: mesh.elements.iter().map(|el| el.patch).collect(),
            element_radii,
            lifted_corners: lift_corners(mesh, ray_offset),
            patch_blocks: super::parallel::patch_blocks(&patch_elements),
            patch_elements,
            patch_reflectance: mesh
                .patches
                .iter()
                .map(|p| mesh.materials[mesh.surfaces[p.surface as usize].material as usize].reflectance)
                .collect(),
            patch_element_radius,
            neighbour_start,
            neighbours,
            total_area,
            mean_reflectance,
            ray_offset,
            occluder_boxes: OccluderBoxes::new(&blocking),
            blockers: Blockers::new(mesh, &blocking),
        }
    }

    /// Element `e`'s edge neighbours.
    pub(super) fn neighbours_of(&self, e: usize) -> &[u32] {
        &self.neighbours[self.neighbour_start[e] as usize..self.neighbour_start[e + 1] as usize]
    }
}

/// Checks that the mesh has elements and that its patches own consecutive runs of them, in
/// order (as `Mesh::build` makes them): a row is split into one slice per patch.
///
/// # Errors
/// [`SolverError::EmptyMesh`] or [`SolverError::BadMesh`].
pub(super) fn check_patch_runs(mesh: &Mesh) -> Result<(), SolverError> {
    if mesh.elements.is_empty() {
        return Err(SolverError::EmptyMesh);
    }
    let mut next = 0;
    for (q, p) in mesh.patches.iter().enumerate() {
        if p.elements.start != next || p.elements.end < p.elements.start {
            return Err(SolverError::BadMesh { patch: q });
        }
        next = p.elements.end;
    }
    if next as usize != mesh.elements.len() {
        return Err(SolverError::BadMesh { patch: mesh.patches.len() });
    }
    Ok(())
}

/// Each element's neighbours: the elements sharing an edge with it (the mesh shares
/// vertices within a surface, across its patches too), as `(start, list)`: element `e`'s
/// are `list[start[e]..start[e + 1]]`. Edge neighbours, not vertex ones: on the Cornell box
/// the diagonal neighbours added rays and changed neither the object means nor the render
/// beyond their noise.
fn element_neighbours(mesh: &Mesh) -> (Vec<u32>, Vec<u32>) {
    // Two elements are neighbours when they share two vertices, i.e. a pair of vertices (an
    // edge, or a quad's diagonal): every element's vertex pairs, sorted, put the elements
    // sharing one side by side. (Looking at every element around each vertex was quadratic
    // in a vertex's valence: the apex of a fan of 10⁵ triangles, a many-cornered light,
    // took minutes.)
    let mut pairs: Vec<(u32, u32, u32)> = Vec::new();
    for (e, el) in mesh.elements.iter().enumerate() {
        let v = el.vertex_indices();
        for i in 0..v.len() {
            for j in i + 1..v.len() {
                pairs.push((v[i].min(v[j]), v[i].max(v[j]), e as u32));
            }
        }
    }
    pairs.sort_unstable();
    let mut found: Vec<(u32, u32)> = Vec::new();
    for run in pairs.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        for &(_, _, a) in run {
            found.extend(run.iter().filter(|&&(_, _, b)| b != a).map(|&(_, _, b)| (a, b)));
        }
    }
    drop(pairs);
    found.sort_unstable();
    found.dedup();
    // Each element's neighbours in the order a walk over its vertices meets them (by the
    // first of its vertices they share, then by number): the order the table has always had,
    // so that what reads it (in that order) gives the same results as before.
    let (mut start, mut list) =
        (Vec::with_capacity(mesh.elements.len() + 1), Vec::with_capacity(found.len()));
    start.push(0);
    let mut next = found.as_slice();
    for (e, el) in mesh.elements.iter().enumerate() {
        let count = next.iter().take_while(|&&(a, _)| a as usize == e).count();
        let (mine, rest) = next.split_at(count);
        next = rest;
        let own = el.vertex_indices();
        let first_shared = |n: u32| {
            let theirs = mesh.elements[n as usize].vertex_indices();
            own.iter().position(|v| theirs.contains(v)).unwrap_or(own.len())
        };
        let mut ordered: Vec<(usize, u32)> = mine.iter().map(|&(_, n)| (first_shared(n), n)).collect();
        ordered.sort_unstable();
        list.extend(ordered.into_iter().map(|(_, n)| n));
        start.push(list.len() as u32);
    }
    (start, list)
}

/// Every element's corners lifted off its surface by `offset` along its normal, in single
/// precision (a triangle's fourth slot stays zero): the origins of its rays, the same
/// points every row.
fn lift_corners(mesh: &Mesh, offset: f64) -> Vec<[Vec3A; 4]> {
    (0..mesh.elements.len())
        .map(|e| {
            let lift = mesh.elements[e].normal * offset;
            let mut out = [Vec3A::ZERO; 4];
            for (l, p) in out.iter_mut().zip(mesh.element_corners(e)) {
                *l = (p + lift).as_vec3().into();
            }
            out
        })
        .collect()
}

/// Circumradius of element `e` about its centre.
fn element_radius(mesh: &Mesh, e: usize) -> f64 {
    let c = mesh.elements[e].centre;
    mesh.element_corners(e).map(|p| p.distance(c)).fold(0.0, f64::max)
}

/// A patch's circumradius about its centre.
pub(super) fn patch_radius(patch: &Patch) -> f64 {
    patch.corners().iter().map(|c| c.distance(patch.centre)).fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiosity_scenes::furnace_box;

    /// In a box meshed into quads, an element inside a face has four edge neighbours, one at
    /// a face's corner two (vertices are not shared across surfaces), and the relation is
    /// symmetric.
    #[test]
    fn neighbours_share_an_edge_within_a_surface() {
        let scene = furnace_box(0.5, 1.0);
        let mesh = Mesh::build(&scene, &scene.mesh_params()).unwrap();
        let tables = MeshTables::new(&mesh);
        let mut counts = std::collections::BTreeSet::new();
        for e in 0..mesh.elements.len() {
            let own = tables.neighbours_of(e);
            counts.insert(own.len());
            for &n in own {
                assert!(tables.neighbours_of(n as usize).contains(&(e as u32)), "{e} and {n}");
                let surface = |e: usize| mesh.patches[mesh.elements[e].patch as usize].surface;
                assert_eq!(surface(n as usize), surface(e), "{e} and {n}");
            }
        }
        assert_eq!(counts.first(), Some(&2));
        assert_eq!(counts.last(), Some(&4));
    }

    #[test]
    fn patches_must_own_consecutive_runs() {
        let scene = furnace_box(0.5, 1.0);
        let mut mesh = Mesh::build(&scene, &scene.mesh_params()).unwrap();
        assert_eq!(check_patch_runs(&mesh), Ok(()));
        mesh.patches[1].elements.start += 1;
        assert_eq!(check_patch_runs(&mesh), Err(SolverError::BadMesh { patch: 1 }));
    }
}
