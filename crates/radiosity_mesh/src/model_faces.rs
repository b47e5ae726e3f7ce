//! A model's faces as surfaces: coplanar edge-connected triangles grouped, a triangle pair
//! that forms a convex quad meshed as that quad, a group's lattice placed edge by edge.

// Fx hashing: the mesher's maps hold millions of small integer keys (a vertex's bits, an
// edge's two indices), where SipHash was a third of the meshing time of a 834 k-triangle
// model; nothing here is keyed by untrusted input an attacker could collide.
use rustc_hash::FxHashMap as HashMap;

use glam::DVec3;
use radiosity_core::{Polygon, PolygonMesh};

use crate::union_find::UnionFind;

/// How the faces of a [`PolygonMesh`] are cut into surfaces: groups of triangles (face
/// numbers), each meshed with shared vertices; a face of 4+ vertices is a group of its own.
///
/// Two triangles join one group when they share an edge (by vertex index) used by no other
/// face and are coplanar (normals within ~1e-4 rad, the far vertex within 1e-6 of the longest
/// edge off the plane): a wall however its exporter triangulated it is one surface.
pub(crate) fn group_mesh_faces(m: &PolygonMesh) -> Vec<Vec<u32>> {
    let faces = m.faces();
    let polys = m.polygons();
    let is_tri = |f: usize| faces[f].len() == 3;
    // Edge → the (up to two) triangles using it, and how many faces use it at all.
    let mut edges: HashMap<(u32, u32), (u32, u32, u32)> = HashMap::default();
    for (f, face) in faces.iter().enumerate() {
        for k in 0..face.len() {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            let e = edges.entry((a.min(b), a.max(b))).or_insert((u32::MAX, u32::MAX, 0));
            if is_tri(f) {
                if e.0 == u32::MAX {
                    e.0 = f as u32;
                } else if e.1 == u32::MAX {
                    e.1 = f as u32;
                }
            }
            e.2 += 1;
        }
    }
    let coplanar = |a: usize, b: usize| {
        let (pa, pb) = (&polys[a], &polys[b]);
        if pa.normal().dot(pb.normal()) < 1.0 - 5e-9 {
            return false;
        }
        let v = pa.vertices();
        let longest = (0..3).map(|k| v[k].distance(v[(k + 1) % 3])).fold(0.0, f64::max);
        pb.vertices().iter().all(|p| (*p - v[0]).dot(pa.normal()).abs() <= 1e-6 * longest)
    };
    let mut pairs: Vec<(u32, u32)> = edges
        .values()
        .filter(|&&(a, b, count)| count == 2 && b != u32::MAX && coplanar(a as usize, b as usize))
        .map(|&(a, b, _)| (a.min(b), a.max(b)))
        .collect();
    // HashMap order is arbitrary; sorting keeps the grouping (and so the mesh) deterministic.
    pairs.sort_unstable();
    // Every coplanar edge-connected set is one surface: its triangles are cut where each is
    // long (see `mesh_triangle_group`), so they need not share a step count to fit together.
    let mut coplanar_sets = UnionFind::new(faces.len());
    for &(a, b) in &pairs {
        coplanar_sets.union(a, b);
    }
    let mut group_of: HashMap<u32, usize> = HashMap::default();
    let mut groups: Vec<Vec<u32>> = Vec::new();
    for f in 0..faces.len() as u32 {
        let r = coplanar_sets.find(f);
        let g = *group_of.entry(r).or_insert_with(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[g].push(f);
    }
    groups
}

/// The quad formed by two triangles sharing an edge, when it is planar and convex.
pub(crate) fn pair_as_quad(m: &PolygonMesh, a: usize, b: usize) -> Option<Polygon> {
    let (fa, fb) = (&m.faces()[a], &m.faces()[b]);
    // Rotate `a` so that its edge k→k+1 is the one `b` shares (b runs it the other way).
    for k in 0..3 {
        let (u, v) = (fa[k], fa[(k + 1) % 3]);
        if let Some(j) = (0..3).find(|&j| fb[j] == v && fb[(j + 1) % 3] == u) {
            let w = fb[(j + 2) % 3];
            let x = fa[(k + 2) % 3];
            // Start at `v`: for the usual fan split of a quad [0 1 2] [0 2 3] that is the quad's
            // own first vertex, so the lattice (and element order) is the quad's exactly.
            let pts = [v, x, u, w].map(|i| m.positions()[i as usize]);
            return Polygon::try_new(pts.to_vec()).ok();
        }
    }
    None
}

/// The triangles of `group`, faces of `m` with three corners each.
pub(crate) fn group_triangles(m: &PolygonMesh, group: &[u32]) -> Vec<[DVec3; 3]> {
    let pos = m.positions();
    group
        .iter()
        .map(|&f| {
            let idx = &m.faces()[f as usize];
            [idx[0], idx[1], idx[2]].map(|i| pos[i as usize])
        })
        .collect()
}
