//! Adaptive subdivision decided outside the mesher: which elements to quarter when a scene is
//! meshed again.

// Fx hashing: the mesher's maps hold millions of small integer keys (a vertex's bits, an
// edge's two indices), where SipHash was a third of the meshing time of a 834 k-triangle
// model; nothing here is keyed by untrusted input an attacker could collide.
use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use glam::DVec3;

use crate::Mesh;
use crate::builder::{SurfaceBuilder, polygon_area_normal};

/// Elements to quarter when a scene is meshed again, level after level (see
/// [`Mesh::build_refined`]): adaptive subdivision (Cohen, Greenberg, Immel & Brock 1986)
/// decided outside the mesher, e.g. where a solution's radiosity changes steeply.
///
/// An element is named by its surface and the exact bits of its centre, which the same scene,
/// parameters and earlier levels reproduce.
#[derive(Clone, Debug, Default)]
pub struct Refinement {
    pub(crate) levels: Vec<HashMap<u32, HashSet<[u64; 3]>>>,
}

impl Refinement {
    /// Adds a level: the `elements` of `mesh` (built with this refinement's levels so far).
    /// An element on the back of a two-sided surface names its front twin (the back is
    /// a copy of the front's mesh). Returns how many elements the level names.
    pub fn add_level(&mut self, mesh: &Mesh, elements: impl IntoIterator<Item = usize>) -> usize {
        let mut level: HashMap<u32, HashSet<[u64; 3]>> = HashMap::default();
        let mut count = 0;
        for e in elements {
            let e = if mesh.element_is_back(e) { mesh.element_twin(e).unwrap_or(e) } else { e };
            let surface = mesh.patches[mesh.elements[e].patch as usize].surface;
            let c = mesh.elements[e].centre;
            count += usize::from(level.entry(surface).or_default().insert([c.x, c.y, c.z].map(f64::to_bits)));
        }
        if count > 0 {
            self.levels.push(level);
        }
        count
    }
}

/// The key of the element with vertices `vs` in `b`: its centre's bits, computed as
/// [`Mesh`]'s element centres are.
pub(crate) fn centre_key(b: &SurfaceBuilder, vs: &[u32]) -> [u64; 3] {
    let pts: Vec<DVec3> = vs.iter().map(|&i| b.positions[i as usize]).collect();
    let c = polygon_area_normal(&pts).2;
    [c.x, c.y, c.z].map(f64::to_bits)
}
