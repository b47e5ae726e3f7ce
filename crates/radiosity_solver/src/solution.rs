//! What a solve produces: radiosity per element and per vertex, and summaries per object.

use glam::{DMat3, DVec3};
use radiosity_core::Rgb;
use radiosity_mesh::Mesh;

/// A snapshot of the solution, linear radiosity in W/unit².
#[derive(Clone, Debug, Default)]
pub struct Solution {
    /// Radiosity B of every element (with the ambient term when it is on).
    pub element_radiosity: Vec<Rgb>,
    /// Radiosity interpolated at every mesh vertex: the area-weighted mean of the elements
    /// around it, all on one surface (vertices are never shared across surfaces).
    pub vertex_radiosity: Vec<Rgb>,
    /// Of each element's radiosity, the part reflected straight from the emitters' own
    /// emission (ρ · H_direct): what a final gather recomputes per pixel by shadow rays, kept
    /// apart so it is not counted twice. Empty when the solver does not track it.
    pub element_direct: Vec<Rgb>,
    /// [`Solution::element_direct`] interpolated at every vertex, like `vertex_radiosity`.
    pub vertex_direct: Vec<Rgb>,
    /// Unshot radiosity ΔB of every element (what it still has to shoot).
    pub element_unshot: Vec<Rgb>,
    /// Shots done when the snapshot was taken.
    pub shots: u64,
    /// Unshot power / emitted power when the snapshot was taken.
    pub unshot_fraction: f64,
}

/// Area-weighted result for one object.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjectRadiosity {
    /// Object name.
    pub name: String,
    /// Total area, scene units².
    pub area: f64,
    /// Emitted power per channel, E·A.
    pub emitted_power: Rgb,
    /// Area-weighted mean radiosity per channel (of the front face, the one its normals
    /// point to, for a two-sided object).
    pub radiosity: Rgb,
    /// Of a two-sided object, the area-weighted mean radiosity of its back face.
    pub radiosity_back: Option<Rgb>,
}

impl Solution {
    /// Per-object area-weighted mean radiosity, in scene object order.
    pub fn object_radiosity(&self, mesh: &Mesh) -> Vec<ObjectRadiosity> {
        object_radiosity(mesh, &self.element_radiosity)
    }
}

/// Per-object area-weighted mean of `element_radiosity` over `mesh`, in scene object order
/// (front and back faces apart).
pub(crate) fn object_radiosity(mesh: &Mesh, element_radiosity: &[Rgb]) -> Vec<ObjectRadiosity> {
    let mut out: Vec<ObjectRadiosity> = mesh
        .object_names
        .iter()
        .map(|n| ObjectRadiosity {
            name: n.clone(),
            area: 0.0,
            emitted_power: Rgb::ZERO,
            radiosity: Rgb::ZERO,
            radiosity_back: None,
        })
        .collect();
    let mut back_area = vec![0.0; out.len()];
    for (e, el) in mesh.elements.iter().enumerate() {
        let object = mesh.element_object(e);
        let o = &mut out[object];
        o.emitted_power += mesh.element_material(e).emission * el.area;
        if mesh.element_is_back(e) {
            back_area[object] += el.area;
            *o.radiosity_back.get_or_insert(Rgb::ZERO) += element_radiosity[e] * el.area;
        } else {
            o.area += el.area;
            o.radiosity += element_radiosity[e] * el.area;
        }
    }
    for (o, back_area) in out.iter_mut().zip(back_area) {
        if o.area > 0.0 {
            o.radiosity = o.radiosity / o.area;
        }
        if let Some(b) = &mut o.radiosity_back
            && back_area > 0.0
        {
            *b = *b / back_area;
        }
    }
    out
}

/// Area-weighted average of element values at each vertex, over the elements around it and
/// around the vertices it is pooled with ([`radiosity_core::Smoothing`]); at the vertices on
/// a surface's rim, the linear fit of `rims` instead.
pub(crate) fn vertex_average(
    mesh: &Mesh,
    element_values: &[Rgb],
    vertex_area: &[f64],
    rims: &RimFits,
) -> Vec<Rgb> {
    let mut sums = vec![Rgb::ZERO; mesh.positions.len()];
    for (el, value) in mesh.elements.iter().zip(element_values) {
        for &i in el.vertex_indices() {
            sums[i as usize] += *value * el.area;
        }
    }
    let mut out: Vec<Rgb> = (0..sums.len())
        .map(|v| {
            let (mut sum, mut area) = (sums[v], vertex_area[v]);
            for (u, w) in mesh.smoothing.partners_of(v) {
                sum += sums[u as usize] * w;
                area += vertex_area[u as usize] * w;
            }
            if area > 0.0 { sum / area } else { sum }
        })
        .collect();
    rims.apply(element_values, &mut out);
    out
}

/// Linear extrapolation of element values to the vertices on a surface's rim (its outline,
/// a hole cut around a contact).
///
/// An element's radiosity is its mean, which a smooth field takes near the element's centre.
/// The mean of the elements around an inside vertex is then the field at the vertex to second
/// order, but around a rim vertex every element lies on one side: the average is the field
/// half an element inwards. Where the light changes fast towards an edge (a block's foot
/// darkening towards the floor, a face darkening towards its far corner) the rim came out
/// 10–25 % too bright. A weighted least-squares plane through the element centres of the
/// vertex's two rings of elements, evaluated at the vertex, is exact for a linear field
/// (Cohen & Wallace 1993, §9.2.2, on extrapolating nodal values at boundaries).
#[derive(Clone, Debug, Default)]
pub(crate) struct RimFits {
    /// The rim vertices.
    vertices: Vec<u32>,
    /// Vertex `vertices[i]`'s terms are `terms[start[i]..start[i + 1]]`.
    start: Vec<u32>,
    /// (element, weight): the value at the vertex is Σ weight · value.
    terms: Vec<(u32, f64)>,
}

/// Most elements around a vertex whose elements join a rim vertex's second ring (see
/// [`RimFits::new`]): far above a mesh's usual six or eight, reached only by fans of many
/// triangles about one vertex, whose rim vertices have their first ring and the other
/// second-ring elements to fit, so that the fits cost time linear in the mesh.
const MAX_RING_VALENCE: usize = 256;

impl RimFits {
    /// The fits of `mesh`'s rim vertices: those whose elements' angles at them sum to less
    /// than a full turn (by more than 0.1 rad) and that are pooled with no other vertex.
    pub(crate) fn new(mesh: &Mesh) -> Self {
        let around = VertexElements::new(mesh);
        let mut angle = vec![0.0f64; mesh.positions.len()];
        for el in &mesh.elements {
            let idx = el.vertex_indices();
            for (k, &v) in idx.iter().enumerate() {
                let p = mesh.positions[v as usize];
                let prev = mesh.positions[idx[(k + idx.len() - 1) % idx.len()] as usize] - p;
                let next = mesh.positions[idx[(k + 1) % idx.len()] as usize] - p;
                angle[v as usize] += prev.angle_between(next);
            }
        }
        let elements_at = |v: u32| around.of(v as usize);
        let mut fits = Self { vertices: Vec::new(), start: vec![0], terms: Vec::new() };
        let mut ring: Vec<u32> = Vec::new();
        for (v, &turn) in angle.iter().enumerate() {
            let first = elements_at(v as u32);
            if first.is_empty()
                || turn > std::f64::consts::TAU - 0.1
                || mesh.smoothing.partners_of(v).next().is_some()
            {
                continue;
            }
            ring.clear();
            ring.extend_from_slice(first);
            for &e in first {
                for &u in mesh.elements[e as usize].vertex_indices() {
                    // The second ring leaves out the elements around a vertex of more than
                    // `MAX_RING_VALENCE` (the centre of a fan of 10⁵ triangles): each of the
                    // fan's rim vertices took in the whole fan, 26 GB of terms.
                    let around_u = elements_at(u);
                    if around_u.len() <= MAX_RING_VALENCE {
                        ring.extend_from_slice(around_u);
                    }
                }
            }
            ring.sort_unstable();
            ring.dedup();
            if let Some(weights) = plane_fit(mesh, mesh.positions[v], &ring) {
                fits.vertices.push(v as u32);
                fits.terms.extend(ring.iter().copied().zip(weights));
                fits.start.push(fits.terms.len() as u32);
            }
        }
        fits
    }

    /// Replaces the rim vertices' values in `vertex_values` by their fits to `element_values`,
    /// kept within the elements' range widened by half of it on each side and never below
    /// zero: a fit across a sharp shadow edge would otherwise overshoot.
    fn apply(&self, element_values: &[Rgb], vertex_values: &mut [Rgb]) {
        for (i, &v) in self.vertices.iter().enumerate() {
            let terms = &self.terms[self.start[i] as usize..self.start[i + 1] as usize];
            let (mut fit, mut lo, mut hi) =
                (Rgb::ZERO, Rgb::splat(f64::INFINITY), Rgb::splat(f64::NEG_INFINITY));
            for &(e, w) in terms {
                let b = element_values[e as usize];
                fit += b * w;
                lo = lo.zip_map(b, f64::min);
                hi = hi.zip_map(b, f64::max);
            }
            let spread = hi - lo;
            vertex_values[v as usize] = fit
                .zip_map(lo - spread * 0.5, f64::max)
                .zip_map(hi + spread * 0.5, f64::min)
                .map(|c| c.max(0.0));
        }
    }
}

/// The elements around each vertex, packed: vertex `v`'s are
/// `elements[start[v]..start[v + 1]]`, in element order.
pub(crate) struct VertexElements {
    start: Vec<u32>,
    elements: Vec<u32>,
}

impl VertexElements {
    /// The elements around every vertex of `mesh`.
    pub(crate) fn new(mesh: &Mesh) -> Self {
        let nv = mesh.positions.len();
        let mut start = vec![0u32; nv + 1];
        for el in &mesh.elements {
            for &v in el.vertex_indices() {
                start[v as usize + 1] += 1;
            }
        }
        for v in 0..nv {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut elements = vec![0u32; start[nv] as usize];
        for (e, el) in mesh.elements.iter().enumerate() {
            for &v in el.vertex_indices() {
                elements[fill[v as usize] as usize] = e as u32;
                fill[v as usize] += 1;
            }
        }
        Self { start, elements }
    }

    /// The elements around vertex `v`.
    pub(crate) fn of(&self, v: usize) -> &[u32] {
        &self.elements[self.start[v] as usize..self.start[v + 1] as usize]
    }
}

/// Weights w_k (one per element of `ring`) with Σ w_k B_k the value at `at` of the plane
/// a + g·(c − at) fitted to the values B_k at the element centres c_k by least squares
/// weighted by area. `None` when the centres do not span the plane.
fn plane_fit(mesh: &Mesh, at: DVec3, ring: &[u32]) -> Option<Vec<f64>> {
    let n = mesh.elements[ring[0] as usize].normal;
    let (tu, tv) = n.any_orthonormal_pair();
    let scale =
        (ring.iter().map(|&e| mesh.elements[e as usize].area).sum::<f64>() / ring.len() as f64).sqrt();
    if scale <= 0.0 {
        return None;
    }
    let basis = |e: u32| {
        let d = (mesh.elements[e as usize].centre - at) / scale;
        DVec3::new(1.0, d.dot(tu), d.dot(tv))
    };
    let mut m = DMat3::ZERO;
    for &e in ring {
        let b = basis(e);
        let w = mesh.elements[e as usize].area / (scale * scale);
        m += DMat3::from_cols(b * (w * b.x), b * (w * b.y), b * (w * b.z));
    }
    // Well conditioned only when the centres spread in both directions of the plane.
    if m.determinant().abs() < 1e-6 * m.x_axis.x.powi(3) {
        return None;
    }
    // Row 0 of M⁻¹ (M is symmetric): the value at `at` is e₀ · M⁻¹ Σ w_k b_k B_k.
    let row = m.inverse().x_axis;
    Some(ring.iter().map(|&e| mesh.elements[e as usize].area / (scale * scale) * row.dot(basis(e))).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiosity_core::{Material, MeshParams, Object, Polygon, Scene, Shape, Sides};

    /// One unit square in z = 0, meshed into 0.25 elements.
    fn square_mesh() -> Mesh {
        // Emitting: a scene needs light, though the fits look at nothing but the mesh.
        let grey = Material::try_new("grey", Rgb::splat(0.5), Rgb::ONE).unwrap();
        let square = vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        let object = Object {
            name: "square".into(),
            material: 0,
            shape: Shape::Polygons(vec![Polygon::try_new(square).unwrap()]),
            sides: Sides::One,
        };
        let scene = Scene::try_new("square", None, vec![grey], vec![object]).unwrap();
        Mesh::build(&scene, &MeshParams::try_new(1.0, 0.25).unwrap()).unwrap()
    }

    fn vertex_areas(mesh: &Mesh) -> Vec<f64> {
        let mut area = vec![0.0; mesh.positions.len()];
        for el in &mesh.elements {
            for &v in el.vertex_indices() {
                area[v as usize] += el.area;
            }
        }
        area
    }

    /// A field linear over the surface, given as its element means, comes back exactly at
    /// every vertex, the rim's included; the plain average is half an element off there.
    #[test]
    fn rim_vertices_take_a_linear_field_exactly() {
        let mesh = square_mesh();
        let field = |p: DVec3| 1.0 + 2.0 * p.x + 3.0 * p.y;
        let values: Vec<Rgb> = mesh.elements.iter().map(|el| Rgb::splat(field(el.centre))).collect();
        let area = vertex_areas(&mesh);
        let rims = RimFits::new(&mesh);
        assert_eq!(rims.vertices.len(), 16, "the 16 vertices on a 4 × 4 grid's outline");
        let fitted = vertex_average(&mesh, &values, &area, &rims);
        for (v, b) in fitted.iter().enumerate() {
            let expected = field(mesh.positions[v]);
            assert!(
                (b.r - expected).abs() < 1e-9,
                "vertex {v} at {}: {} vs {expected}",
                mesh.positions[v],
                b.r
            );
        }
        let plain = vertex_average(&mesh, &values, &area, &RimFits::default());
        let corner = (0..mesh.positions.len()).find(|&v| mesh.positions[v] == DVec3::ZERO).unwrap();
        assert!((plain[corner].r - field(DVec3::ZERO) - 0.625).abs() < 1e-9, "{}", plain[corner].r);
    }

    /// Across a sharp step the fit stays within the elements' range widened by half of it,
    /// and never goes below zero.
    #[test]
    fn rim_fits_stay_near_the_values_they_fit() {
        let mesh = square_mesh();
        let values: Vec<Rgb> =
            mesh.elements.iter().map(|el| Rgb::splat(if el.centre.x < 0.3 { 0.0 } else { 1.0 })).collect();
        let fitted = vertex_average(&mesh, &values, &vertex_areas(&mesh), &RimFits::new(&mesh));
        for b in &fitted {
            assert!((0.0..=1.5).contains(&b.r), "{}", b.r);
        }
    }
}
