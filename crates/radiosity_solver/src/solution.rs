//! What a solve produces: radiosity per element and per vertex, and summaries per object.

use radiosity_core::{Mesh, Rgb};

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
                *o.radiosity_back.get_or_insert(Rgb::ZERO) += self.element_radiosity[e] * el.area;
            } else {
                o.area += el.area;
                o.radiosity += self.element_radiosity[e] * el.area;
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
}

/// Area-weighted average of element values at each vertex, over the elements around it and
/// around the vertices it is pooled with ([`radiosity_core::Smoothing`]).
pub(crate) fn vertex_average(mesh: &Mesh, element_values: &[Rgb], vertex_area: &[f64]) -> Vec<Rgb> {
    let mut sums = vec![Rgb::ZERO; mesh.positions.len()];
    for (el, value) in mesh.elements.iter().zip(element_values) {
        for &i in el.vertex_indices() {
            sums[i as usize] += *value * el.area;
        }
    }
    (0..sums.len())
        .map(|v| {
            let (mut sum, mut area) = (sums[v], vertex_area[v]);
            for (u, w) in mesh.smoothing.partners_of(v) {
                sum += sums[u as usize] * w;
                area += vertex_area[u as usize] * w;
            }
            if area > 0.0 { sum / area } else { sum }
        })
        .collect()
}
