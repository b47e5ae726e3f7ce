//! A model's faces as surfaces: coplanar edge-connected triangles grouped, a triangle pair
//! that forms a convex quad meshed as that quad, a group's lattice placed edge by edge.

// Fx hashing: the mesher's maps hold millions of small integer keys (a vertex's bits, an
// edge's two indices), where SipHash was a third of the meshing time of a 834 k-triangle
// model; nothing here is keyed by untrusted input an attacker could collide.
use rustc_hash::FxHashMap as HashMap;

use radiosity_core::{MeshParams, Polygon, PolygonMesh};

use crate::builder::SurfaceBuilder;
use crate::lattice::{mesh_triangle_lattice, triangle_steps};
use crate::union_find::UnionFind;

/// How the faces of a [`PolygonMesh`] are cut into surfaces: groups of triangles (face
/// numbers), each meshed with shared vertices; a face of 4+ vertices is a group of its own.
///
/// Two triangles join one group when they share an edge (by vertex index) used by no other
/// face, are coplanar (normals within ~1e-4 rad, the far vertex within 1e-6 of the longest
/// edge off the plane) and either their whole coplanar set needs step counts within a factor
/// 2 of each other (then all are meshed with the set's largest steps) or they need the same
/// steps; either way the lattice points on a common edge coincide bit for bit.
pub(crate) fn group_mesh_faces(m: &PolygonMesh, params: &MeshParams) -> Vec<Vec<u32>> {
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
    let steps = |f: usize| {
        let v = polys[f].vertices();
        triangle_steps(&[v[0], v[1], v[2]], params)
    };
    let mut pairs: Vec<(u32, u32)> = edges
        .values()
        .filter(|&&(a, b, count)| count == 2 && b != u32::MAX && coplanar(a as usize, b as usize))
        .map(|&(a, b, _)| (a.min(b), a.max(b)))
        .collect();
    // HashMap order is arbitrary; sorting keeps the grouping (and so the mesh) deterministic.
    pairs.sort_unstable();
    // First pass: every coplanar edge-connected set. A set of exactly two triangles is kept
    // whole (it becomes a quad when convex); larger sets are split where the steps differ.
    let mut all = UnionFind::new(faces.len());
    for &(a, b) in &pairs {
        all.union(a, b);
    }
    // Per set: its size and the least and most lattice steps (np · ne) of its triangles.
    let mut size = vec![0u32; faces.len()];
    let mut step_range = vec![(usize::MAX, 0usize); faces.len()];
    for f in 0..faces.len() as u32 {
        let r = all.find(f) as usize;
        size[r] += 1;
        if is_tri(f as usize) {
            let (np, ne) = steps(f as usize);
            step_range[r] = (step_range[r].0.min(np * ne), step_range[r].1.max(np * ne));
        }
    }
    let mut same_steps = UnionFind::new(faces.len());
    for &(a, b) in &pairs {
        let r = all.find(a) as usize;
        // A set whose triangles need at most twice as many steps as each other is meshed
        // whole with the largest steps (at most 2× finer per edge than each one needs, the
        // common case of an n-gon split by an exporter); otherwise only equal steps join.
        let whole = size[r] == 2 || step_range[r].1 <= 2 * step_range[r].0;
        if whole || steps(a as usize) == steps(b as usize) {
            same_steps.union(a, b);
        }
    }
    let mut group_of: HashMap<u32, usize> = HashMap::default();
    let mut groups: Vec<Vec<u32>> = Vec::new();
    for f in 0..faces.len() as u32 {
        let r = same_steps.find(f);
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

/// Meshes a group of coplanar triangles into `b` with the same steps for all, placing lattice
/// points on an edge from the edge's lower vertex index so both triangles on a shared edge
/// compute the same bits and their vertices merge.
pub(crate) fn mesh_triangle_group(
    b: &mut SurfaceBuilder,
    m: &PolygonMesh,
    group: &[u32],
    params: &MeshParams,
) {
    let (mut np, mut ne) = (1, 1);
    for &f in group {
        let v = m.polygons()[f as usize].vertices();
        let (p, e) = triangle_steps(&[v[0], v[1], v[2]], params);
        np = np.max(p);
        ne = ne.max(e);
    }
    let n = np * ne;
    let pos = m.positions();
    for &f in group {
        let idx = &m.faces()[f as usize];
        let normal = m.polygons()[f as usize].normal();
        let t = [idx[0], idx[1], idx[2]];
        let edge = |p: u32, q: u32, k: usize| {
            // Point k of n from vertex p towards q, computed from the lower index.
            let (a, c, k) = if p < q { (p, q, k) } else { (q, p, n - k) };
            let (pa, pc) = (pos[a as usize], pos[c as usize]);
            if k == 0 {
                pa
            } else if k == n {
                pc
            } else {
                pa + (pc - pa) * (k as f64 / n as f64)
            }
        };
        let at = |i: usize, j: usize| {
            if j == 0 {
                edge(t[0], t[1], i)
            } else if i == 0 {
                edge(t[0], t[2], j)
            } else if i + j == n {
                edge(t[1], t[2], j)
            } else {
                let [p0, p1, p2] = t.map(|i| pos[i as usize]);
                p0 + (p1 - p0) * (i as f64 / n as f64) + (p2 - p0) * (j as f64 / n as f64)
            }
        };
        mesh_triangle_lattice(b, &at, normal, np, ne);
    }
}
