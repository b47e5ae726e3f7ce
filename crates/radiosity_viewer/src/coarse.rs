//! A coarser copy of a big mesh, drawn while the camera moves or the solve runs so that the
//! view stays interactive on a CPU rasteriser.
//!
//! Vertex clustering (Rossignac & Borrel 1993): space is cut into cubic cells, every vertex in
//! a cell is replaced by one point, and the triangles left with three corners in three
//! different cells are kept. The cell size bounds what is lost: a triangle larger than a
//! cell keeps its corners, so walls and floors meshed coarser than the cell keep every
//! element and their light, while a scan's sub-millimetre facets merge into cell-sized ones.
//! A cell's point minimises the squared distances to the planes of its triangles (the
//! quadric error of Garland & Heckbert 1997, used for clustering by Lindstrom 2000), so it
//! stays on the crease where a wall meets the floor and on the corner of a box: no sawtooth
//! along edges, no cracks between the faces. Border edges add the plane through them square
//! to their triangle, so open borders do not shrink by half a cell either.
//!
//! The colours stay the solution's vertex radiosity, at every new snapshot, with nothing to
//! recompute: each corner shows a vertex of its cell whose triangle faces the same way (one
//! of six directions), the one nearest the cell's centre. The two sides of a wall thinner than
//! a cell share a cell, and the lit side must not take the colour of the dark one.

use glam::{DMat3, DVec3};
use radiosity_mesh::Mesh;
use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

/// One drawn triangle of a [`CoarseMesh`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CoarseTriangle {
    /// The element of the full triangle it came from: the value the flat modes show.
    pub element: u32,
    /// Its corners, indices into [`CoarseMesh::positions`], counter-clockwise seen from the side
    /// its element faces.
    pub corners: [u32; 3],
    /// Mesh vertices whose radiosity each corner shows.
    pub colours: [u32; 3],
}

/// A coarser copy of a mesh's triangles (see the module documentation).
#[derive(Clone, Debug)]
pub struct CoarseMesh {
    /// One point per cell that keeps a triangle.
    pub positions: Vec<DVec3>,
    /// The triangles to draw.
    pub triangles: Vec<CoarseTriangle>,
    /// Edge of the clustering cells, scene units.
    pub cell: f64,
}

/// Most triangles the coarse copy keeps, by default; meshes over twice as many get one (a
/// smaller copy would cost more than it saves). On lavapipe (2 cores, 1200 × 760 px) a room
/// with 0.17 M coarse triangles draws at about 18 frames per second, against 7.5 for its 1.7 M.
pub const COARSE_TRIANGLES: usize = 200_000;

/// The coarse copy of `triangles` (`(element, corners)`, as [`crate::render::oriented_triangles`]
/// gives them) with at most `budget` triangles, from the finest cell size that fits;
/// `None` when the mesh has no extent.
pub fn coarse_mesh(mesh: &Mesh, triangles: &[(u32, [u32; 3])], budget: usize) -> Option<CoarseMesh> {
    let (lo, hi) = mesh.bounds();
    let diagonal = (hi - lo).length();
    if !(diagonal.is_finite() && diagonal > 0.0) {
        return None;
    }
    let budget = budget.max(1);
    // Kept triangles fall roughly as the square of the cell size: a few passes find the size.
    let mut cell = diagonal / 4096.0;
    let mut keys = vec![0u64; mesh.positions.len()];
    loop {
        cell_keys(mesh, lo, cell, &mut keys);
        let kept = triangles.iter().filter(|(_, t)| distinct(&keys, t)).count();
        if kept <= budget {
            break;
        }
        cell *= (kept as f64 / budget as f64).sqrt().max(1.1);
    }
    Some(cluster(mesh, triangles, &keys, lo, cell))
}

/// Packs each vertex's cell (21 bits per axis from `lo`) into `keys`.
fn cell_keys(mesh: &Mesh, lo: DVec3, cell: f64, keys: &mut [u64]) {
    const MASK: u64 = (1 << 21) - 1;
    for (key, p) in keys.iter_mut().zip(&mesh.positions) {
        let c = ((*p - lo) / cell).floor();
        let axis = |x: f64| (x.max(0.0) as u64).min(MASK);
        *key = axis(c.x) | axis(c.y) << 21 | axis(c.z) << 42;
    }
}

/// Whether the triangle's corners lie in three different cells.
fn distinct(keys: &[u64], t: &[u32; 3]) -> bool {
    let [a, b, c] = t.map(|v| keys[v as usize]);
    a != b && b != c && a != c
}

/// One of six directions: the dominant axis of `n` and its sign.
fn facing(n: DVec3) -> u8 {
    let a = n.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    axis * 2 + u8::from(n[axis as usize] < 0.0)
}

/// The vertex nearest its cell's centre (ties: the lower index), so the choice depends on the
/// mesh alone.
fn keep_nearest(slot: &mut (u32, f64), v: u32, d: f64) {
    if d < slot.1 || (d == slot.1 && v < slot.0) {
        *slot = (v, d);
    }
}

/// What a cell gathers: the quadric of its triangles' planes (Σ w n nᵀ and Σ w (n·p) n, w the
/// triangle's area) and the mean of its vertices.
struct Quadric {
    nn: DMat3,
    nd: DVec3,
    sum: DVec3,
    count: f64,
}

impl Quadric {
    /// Nothing gathered (glam's default matrix is the identity, not zero).
    const EMPTY: Quadric = Quadric { nn: DMat3::ZERO, nd: DVec3::ZERO, sum: DVec3::ZERO, count: 0.0 };

    /// The point nearest every plane, pulled slightly to the vertices' mean where the planes
    /// leave it free (one plane: anywhere on it; two: along their crease), and the mean when
    /// the answer strays out of the cell (nearly parallel planes).
    fn point(&self, cell: f64, lo: DVec3) -> DVec3 {
        let mean = self.sum / self.count;
        let eps = 1e-4 * (self.nn.x_axis.x + self.nn.y_axis.y + self.nn.z_axis.z).max(f64::MIN_POSITIVE);
        let a = self.nn + DMat3::from_diagonal(DVec3::splat(eps));
        let x = a.inverse() * (self.nd + eps * mean);
        let centre = lo + ((mean - lo) / cell).floor() * cell + DVec3::splat(0.5 * cell);
        let inside = (x - centre).abs().max_element() <= 0.75 * cell;
        if x.is_finite() && inside { x } else { mean }
    }
}

/// Per triangle, bit i set when its edge from corner i to corner i + 1 belongs to no other
/// triangle: a surface's open border, or where it meets another surface that has vertices of
/// its own. By sorting rather than hashing: a few million edges sort in a fraction of a second.
fn border_edges(triangles: &[(u32, [u32; 3])]) -> Vec<u8> {
    use rayon::prelude::*;
    let mut edges: Vec<(u64, u32)> = triangles
        .iter()
        .enumerate()
        .flat_map(|(k, (_, t))| {
            (0..3).map(move |i| {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                ((u64::from(a.min(b)) << 32) | u64::from(a.max(b)), (k * 3 + i) as u32)
            })
        })
        .collect();
    edges.par_sort_unstable();
    let mut borders = vec![0u8; triangles.len()];
    for run in edges.chunk_by(|a, b| a.0 == b.0) {
        if let [(_, at)] = run {
            borders[*at as usize / 3] |= 1 << (at % 3);
        }
    }
    borders
}

/// n nᵀ.
fn outer(n: DVec3) -> DMat3 {
    DMat3::from_cols(n * n.x, n * n.y, n * n.z)
}

/// Builds the coarse triangles for the cells in `keys` of edge `cell`.
fn cluster(mesh: &Mesh, triangles: &[(u32, [u32; 3])], keys: &[u64], lo: DVec3, cell: f64) -> CoarseMesh {
    let off_centre = |v: u32| {
        let p = (mesh.positions[v as usize] - lo) / cell;
        (p - p.floor() - DVec3::splat(0.5)).length_squared()
    };
    let mut quadrics: HashMap<u64, Quadric> = HashMap::default();
    let mut colour: HashMap<(u64, u8), (u32, f64)> = HashMap::default();
    let borders = border_edges(triangles);
    for (&(e, t), border) in triangles.iter().zip(borders) {
        let side = facing(mesh.elements[e as usize].normal);
        let p = t.map(|v| mesh.positions[v as usize]);
        let cross = (p[1] - p[0]).cross(p[2] - p[0]);
        let (w, n) = (0.5 * cross.length(), cross.normalize_or_zero());
        let (mut nn, mut nd) = (outer(n) * w, n * (n.dot(p[0]) * w));
        // A border edge also pins its cells to the plane through it square to the triangle
        // (Lindstrom 2000), or the clustered surface would shrink from its border by up to
        // half a cell; where another surface meets it square, that plane is the other's.
        for i in 0..3 {
            if border & (1 << i) != 0 {
                let edge = p[(i + 1) % 3] - p[i];
                let m = edge.cross(n).normalize_or_zero();
                let w = edge.length_squared();
                nn += outer(m) * w;
                nd += m * (m.dot(p[i]) * w);
            }
        }
        for v in t {
            let (key, d) = (keys[v as usize], off_centre(v));
            let q = quadrics.entry(key).or_insert(Quadric::EMPTY);
            q.nn += nn;
            q.nd += nd;
            q.sum += mesh.positions[v as usize];
            q.count += 1.0;
            colour.entry((key, side)).and_modify(|slot| keep_nearest(slot, v, d)).or_insert((v, d));
        }
    }
    // Each cell's point, solved once.
    let points: HashMap<u64, DVec3> = quadrics.iter().map(|(&k, q)| (k, q.point(cell, lo))).collect();
    let mut seen: HashSet<([u64; 3], u8)> = HashSet::default();
    let mut index: HashMap<u64, u32> = HashMap::default();
    let mut positions = Vec::new();
    let mut out = Vec::new();
    for &(e, t) in triangles {
        if !distinct(keys, &t) {
            continue;
        }
        let normal = mesh.elements[e as usize].normal;
        let side = facing(normal);
        let cells = t.map(|v| keys[v as usize]);
        let mut sorted = cells;
        sorted.sort_unstable();
        if !seen.insert((sorted, side)) {
            continue;
        }
        let p = cells.map(|k| points[&k]);
        // A triangle folded over by the merge would show its back: leave it out.
        if (p[1] - p[0]).cross(p[2] - p[0]).dot(normal) <= 0.0 {
            continue;
        }
        let corners = [0, 1, 2].map(|i| {
            *index.entry(cells[i]).or_insert_with(|| {
                positions.push(p[i]);
                (positions.len() - 1) as u32
            })
        });
        out.push(CoarseTriangle { element: e, corners, colours: cells.map(|k| colour[&(k, side)].0) });
    }
    CoarseMesh { positions, triangles: out, cell }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::oriented_triangles;
    use radiosity_core::{Facing, MeshParams, Object, Scene, Shape, box_faces};

    fn mesh_of(scene: &Scene, patch: f64, element: f64) -> Mesh {
        Mesh::build(scene, &MeshParams::try_new(patch, element).unwrap()).unwrap()
    }

    fn area(p: [DVec3; 3]) -> f64 {
        0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length()
    }

    /// A finely meshed box shrinks to the budget with no degenerate or folded triangle, every
    /// corner and colour a vertex of the mesh on the same face, and its area kept within the
    /// cells lost along the face edges.
    #[test]
    fn a_fine_box_shrinks_to_the_budget_and_keeps_its_area() {
        let scene = radiosity_scenes::furnace_box(0.5, 0.5);
        let mesh = mesh_of(&scene, 0.25, 0.02);
        let triangles = oriented_triangles(&mesh);
        assert!(triangles.len() > 20_000, "{} triangles", triangles.len());
        let coarse = coarse_mesh(&mesh, &triangles, 2_000).unwrap();
        let n = coarse.triangles.len();
        assert!((500..=2_000).contains(&n), "{n} triangles, cell {}", coarse.cell);
        let full_area: f64 =
            triangles.iter().map(|&(_, t)| area(t.map(|v| mesh.positions[v as usize]))).sum();
        let coarse_area: f64 =
            coarse.triangles.iter().map(|t| area(t.corners.map(|i| coarse.positions[i as usize]))).sum();
        // The corners stay on the box's faces, edges and corners (a point strays off a plane
        // only by the 1e-4 pull towards its vertices' mean).
        let lost = 1e-3 * full_area;
        assert!(
            (coarse_area - full_area).abs() <= lost,
            "area {coarse_area} against {full_area} (cell {})",
            coarse.cell
        );
        for t in &coarse.triangles {
            let el = &mesh.elements[t.element as usize];
            let off_face = |q: DVec3| (q - el.centre).dot(el.normal).abs();
            let p = t.corners.map(|i| coarse.positions[i as usize]);
            assert!((p[1] - p[0]).cross(p[2] - p[0]).dot(el.normal) > 0.0, "{t:?} folded");
            for q in p {
                // Every corner on its face's plane, the box's edges and corners included (but
                // for the 1e-4 pull towards the vertices' mean).
                assert!(
                    off_face(q) < 1e-3 * coarse.cell,
                    "{t:?}: corner {q} off its face by {}",
                    off_face(q)
                );
            }
            for v in t.colours {
                // The colour comes from the same face.
                let q = mesh.positions[v as usize];
                assert!(off_face(q) < 1e-9, "{t:?}: colour vertex {v} off the face by {}", off_face(q));
            }
        }
    }

    /// A thin slab (thinner than a cell): the top's triangles take their colours from the top's
    /// vertices and the bottom's from the bottom's, though both sides share the cells.
    #[test]
    fn each_side_of_a_thin_slab_keeps_its_own_colours() {
        let mut scene = radiosity_scenes::furnace_box(0.5, 0.5);
        let slab =
            box_faces(DVec3::new(0.1, 0.5, 0.1), DVec3::new(0.9, 0.502, 0.9), Facing::Outward, 0.0).unwrap();
        scene.objects.push(Object::new("slab", 0, Shape::Polygons(slab)));
        let mesh = mesh_of(&scene, 0.2, 0.01);
        let triangles = oriented_triangles(&mesh);
        let coarse = coarse_mesh(&mesh, &triangles, 1_000).unwrap();
        assert!(coarse.cell > 0.002, "cell {}", coarse.cell);
        let (mut up, mut down) = (0, 0);
        for t in &coarse.triangles {
            let el = &mesh.elements[t.element as usize];
            let n = el.normal;
            if n.y.abs() < 0.9 || (el.centre.y - 0.501).abs() > 0.01 {
                continue;
            }
            for v in t.colours {
                let y = mesh.positions[v as usize].y;
                assert_eq!(y > 0.501, n.y > 0.0, "{t:?}: colour vertex at y = {y}");
            }
            if n.y > 0.0 { up += 1 } else { down += 1 }
        }
        assert!(up > 50 && down > 50, "{up} up, {down} down");
    }

    /// A mesh already within the budget comes back whole.
    #[test]
    fn a_small_mesh_keeps_every_triangle() {
        let scene = radiosity_scenes::furnace_box(0.5, 0.5);
        let mesh = mesh_of(&scene, 0.5, 0.25);
        let triangles = oriented_triangles(&mesh);
        let coarse = coarse_mesh(&mesh, &triangles, triangles.len()).unwrap();
        // Coincident vertices (a box's faces meeting) may trade indices, not places.
        // Each vertex is its own cell's point, to rounding.
        let at = |e: u32, p: [DVec3; 3]| (e, p.map(|q| (q * 1e6).round().to_array().map(|x| x as i64)));
        let mut kept: Vec<_> = coarse
            .triangles
            .iter()
            .map(|t| at(t.element, t.corners.map(|i| coarse.positions[i as usize])))
            .collect();
        let mut all: Vec<_> =
            triangles.iter().map(|&(e, t)| at(e, t.map(|v| mesh.positions[v as usize]))).collect();
        kept.sort_unstable();
        all.sort_unstable();
        assert_eq!(kept, all);
    }
}
