//! One surface's geometry before it joins the mesh, and the small measures every lattice uses.

// Fx hashing: the mesher's maps hold millions of small integer keys (a vertex's bits, an
// edge's two indices), where SipHash was a third of the meshing time of a 834 k-triangle
// model; nothing here is keyed by untrusted input an attacker could collide.
use rustc_hash::FxHashMap as HashMap;

use glam::DVec3;
use radiosity_core::{MeshParams, Polygon};

/// Geometry of one surface before it joins the mesh: local vertices, elements labelled by a
/// local patch number, and patch corner lists.
#[derive(Default)]
pub(crate) struct SurfaceBuilder {
    pub(crate) positions: Vec<DVec3>,
    pub(crate) normals: Vec<DVec3>,
    pub(crate) index: HashMap<[u64; 3], u32>,
    pub(crate) elements: Vec<(Vec<u32>, usize)>,
    pub(crate) patches: Vec<Vec<DVec3>>,
}

impl SurfaceBuilder {
    /// The index of the vertex at exactly `p`, added with normal `n` if new.
    pub(crate) fn vertex(&mut self, p: DVec3, n: DVec3) -> u32 {
        let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
        *self.index.entry(key).or_insert_with(|| {
            self.positions.push(p);
            self.normals.push(n);
            (self.positions.len() - 1) as u32
        })
    }
}

/// Whether polygon `p` meshes into several elements. A face that meshes into a few gains
/// nothing from a cut or a grading (the facets of a tessellated model): only larger ones are
/// looked at for contacts and inside corners.
pub(crate) fn is_large(p: &Polygon, params: &MeshParams) -> bool {
    is_large_area(p.area(), params)
}

/// [`is_large`] for a region of area `area` (a model's triangles merged into one outline).
pub(crate) fn is_large_area(area: f64, params: &MeshParams) -> bool {
    area >= 4.0 * params.element_size * params.element_size
}

pub(crate) fn divisions(length: f64, size: f64) -> usize {
    ((length / size) * (1.0 - 1e-9)).ceil().max(1.0) as usize
}

pub(crate) fn polygon_area_normal(pts: &[DVec3]) -> (f64, DVec3, DVec3) {
    let mut n = DVec3::ZERO;
    for (i, &a) in pts.iter().enumerate() {
        n += a.cross(pts[(i + 1) % pts.len()]);
    }
    let area = 0.5 * n.length();
    // Area-weighted centroid via a fan from the first vertex.
    let mut c = DVec3::ZERO;
    let mut total = 0.0;
    for i in 1..pts.len() - 1 {
        let a = 0.5 * (pts[i] - pts[0]).cross(pts[i + 1] - pts[0]).length();
        c += (pts[0] + pts[i] + pts[i + 1]) / 3.0 * a;
        total += a;
    }
    let centre = if total > 0.0 { c / total } else { pts.iter().copied().sum::<DVec3>() / pts.len() as f64 };
    (area, n.normalize_or_zero(), centre)
}
