//! Smooth shading across surfaces: which vertices of different surfaces pool their radiosity
//! (same place, or a T-junction on an outline edge), below the crease angle.

/// Which vertices of *different* surfaces share their radiosity in smooth shading: those in
/// one place, on one object and one face of it, whose normals differ by less than the crease
/// angle. Vertices are never shared across surfaces (light must not leak round a corner),
/// so a tessellated curve — one surface per facet — would otherwise shade as facets, and two
/// coplanar polygons of one object (the Cornell ceiling round its lamp) would show their
/// common edge. The test is made per vertex against each neighbour, not chained, so a run of
/// slight bends never carries smoothing across a sharp crease (the usual crease-angle rule of
/// modelling tools).
///
/// Where the two surfaces' lattices do not meet point for point (a T-junction: a vertex of
/// one lies inside an element edge of the other), the vertex pools with that edge's two ends
/// in proportion to where it lies on it, so both sides show nearly the same value there.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Smoothing {
    /// Per vertex, a range into `partners` and `weights` (`offsets[v]..offsets[v + 1]`);
    /// empty when the vertex pools with nobody (or the whole table is empty: no smoothing).
    pub offsets: Vec<u32>,
    /// The vertices pooled with each vertex, itself not included.
    pub partners: Vec<u32>,
    /// The weight of each partner's element sums: 1 for a vertex in the same place, the
    /// linear-interpolation weight for the ends of an edge it lies on.
    pub weights: Vec<f32>,
}

impl Smoothing {
    /// The vertices pooled with vertex `v`, with their weights.
    pub fn partners_of(&self, v: usize) -> impl Iterator<Item = (u32, f64)> + '_ {
        let range = match (self.offsets.get(v), self.offsets.get(v + 1)) {
            (Some(&a), Some(&b)) => a as usize..b as usize,
            _ => 0..0,
        };
        self.partners[range.clone()].iter().copied().zip(self.weights[range].iter().map(|&w| f64::from(w)))
    }
}
