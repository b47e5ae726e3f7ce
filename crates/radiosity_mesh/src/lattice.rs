//! Lattices: a quad's bilinear grid, a triangle's barycentric one, a polygon's fan of them and
//! a sphere's latitude/longitude facets. Lattice points are computed with one formula per
//! surface, so shared points are bit-identical and merge exactly.

// Fx hashing: the mesher's maps hold millions of small integer keys (a vertex's bits, an
// edge's two indices), where SipHash was a third of the meshing time of a 834 k-triangle
// model; nothing here is keyed by untrusted input an attacker could collide.
use rustc_hash::FxHashMap as HashMap;

use glam::DVec3;
use radiosity_core::{Facing, MeshParams, Polygon, Sphere};

use crate::bisection::mesh_triangles;
use crate::builder::{SurfaceBuilder, divisions, polygon_area_normal};

/// A convex planar quad: one bilinear lattice whose lines at every `ne` step are patch edges.
pub(crate) fn mesh_quad(b: &mut SurfaceBuilder, c: [DVec3; 4], normal: DVec3, params: &MeshParams) {
    let len_u = c[0].distance(c[1]).max(c[3].distance(c[2]));
    let len_v = c[0].distance(c[3]).max(c[1].distance(c[2]));
    let (npu, npv) = (divisions(len_u, params.patch_size), divisions(len_v, params.patch_size));
    let neu = divisions(len_u / npu as f64, params.element_size);
    let nev = divisions(len_v / npv as f64, params.element_size);
    let (nu, nv) = (npu * neu, npv * nev);
    let at = |i: usize, j: usize| {
        let (u, v) = (i as f64 / nu as f64, j as f64 / nv as f64);
        c[0] * ((1.0 - u) * (1.0 - v)) + c[1] * (u * (1.0 - v)) + c[2] * (u * v) + c[3] * ((1.0 - u) * v)
    };
    let base = b.patches.len();
    for pj in 0..npv {
        for pi in 0..npu {
            let (i0, j0, i1, j1) = (pi * neu, pj * nev, (pi + 1) * neu, (pj + 1) * nev);
            b.patches.push(vec![at(i0, j0), at(i1, j0), at(i1, j1), at(i0, j1)]);
        }
    }
    for j in 0..nv {
        for i in 0..nu {
            let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
            let v = q.map(|p| b.vertex(p, normal)).to_vec();
            b.elements.push((v, base + (j / nev) * npu + i / neu));
        }
    }
}

/// A triangle: one barycentric lattice with `np * ne` steps per edge; its lines at every `ne`
/// step (in all three directions) are patch edges, so each element lies in exactly one patch.
pub(crate) fn mesh_triangle(b: &mut SurfaceBuilder, t: [DVec3; 3], normal: DVec3, np: usize, ne: usize) {
    let n = np * ne;
    let at = |i: usize, j: usize| {
        t[0] + (t[1] - t[0]) * (i as f64 / n as f64) + (t[2] - t[0]) * (j as f64 / n as f64)
    };
    mesh_triangle_lattice(b, &at, normal, np, ne);
}

/// The lattice of [`mesh_triangle`] with lattice point `(i, j)` (`i` steps along the first
/// edge, `j` along the third, `np * ne` steps per edge) placed by `at`.
pub(crate) fn mesh_triangle_lattice(
    b: &mut SurfaceBuilder,
    at: &dyn Fn(usize, usize) -> DVec3,
    normal: DVec3,
    np: usize,
    ne: usize,
) {
    let n = np * ne;
    let coarse = |i: usize, j: usize| at(i * ne, j * ne);
    let mut patch_of: HashMap<(usize, usize, bool), usize> = HashMap::default();
    let mut label = |b: &mut SurfaceBuilder, x3: usize, y3: usize| {
        // Centroid in lattice units times 3, to stay in integers.
        let (pp, qq) = (x3 / (3 * ne), y3 / (3 * ne));
        let up = (x3 - 3 * ne * pp) + (y3 - 3 * ne * qq) < 3 * ne;
        *patch_of.entry((pp, qq, up)).or_insert_with(|| {
            let corners = if up {
                vec![coarse(pp, qq), coarse(pp + 1, qq), coarse(pp, qq + 1)]
            } else {
                vec![coarse(pp + 1, qq), coarse(pp + 1, qq + 1), coarse(pp, qq + 1)]
            };
            b.patches.push(corners);
            b.patches.len() - 1
        })
    };
    for j in 0..n {
        for i in 0..n - j {
            let up = [(i, j), (i + 1, j), (i, j + 1)];
            let p = label(b, 3 * i + 1, 3 * j + 1);
            let v = up.map(|(a, c)| b.vertex(at(a, c), normal)).to_vec();
            b.elements.push((v, p));
            if i + j + 2 <= n {
                let down = [(i + 1, j), (i + 1, j + 1), (i, j + 1)];
                let p = label(b, 3 * i + 2, 3 * j + 2);
                let v = down.map(|(a, c)| b.vertex(at(a, c), normal)).to_vec();
                b.elements.push((v, p));
            }
        }
    }
}

pub(crate) fn mesh_polygon(b: &mut SurfaceBuilder, poly: &Polygon, params: &MeshParams) {
    let v = poly.vertices();
    if v.len() == 4 {
        mesh_quad(b, [v[0], v[1], v[2], v[3]], poly.normal(), params);
        return;
    }
    if v.len() == 3 {
        // As a model's triangles are: a scene file's triangle and the same triangle in an OBJ
        // mesh alike, and a sliver in a few pieces rather than a lattice.
        mesh_triangles(b, &[[v[0], v[1], v[2]]], poly.normal(), params);
        return;
    }
    // Fan triangles share the lattice step count so that points on shared diagonals are
    // computed by the same formula and merge exactly.
    let fans: Vec<[DVec3; 3]> = (1..v.len() - 1).map(|i| [v[0], v[i], v[i + 1]]).collect();
    let longest = |t: &[DVec3; 3]| t[0].distance(t[1]).max(t[1].distance(t[2])).max(t[2].distance(t[0]));
    let np = fans.iter().map(|t| divisions(longest(t), params.patch_size)).max().unwrap_or(1);
    let ne = fans.iter().map(|t| divisions(longest(t) / np as f64, params.element_size)).max().unwrap_or(1);
    for t in fans {
        mesh_triangle(b, t, poly.normal(), np, ne);
    }
}

/// Fewest latitude bands of an emitting sphere. Its facets are inscribed, so they hold less
/// area than the sphere, and an emitter's power is its area times its exitance: at the six
/// bands a lamp of a metre's radius got from 0.5 m elements, the sun sphere above Dabrovic's
/// Sponza emitted 5.6 % too little and every surface came out 5–7 % dark against `verify`.
/// The shortfall falls as the square of the bands: 24 leave about 0.5 %.
const MIN_EMITTER_BANDS: usize = 24;

/// A latitude/longitude tessellation; every facet is one patch and one element (a curved
/// surface has no planar patch bigger than a facet). An `emitting` sphere gets at least
/// [`MIN_EMITTER_BANDS`] bands.
pub(crate) fn mesh_sphere(b: &mut SurfaceBuilder, s: &Sphere, params: &MeshParams, emitting: bool) {
    use std::f64::consts::PI;
    let fewest = if emitting { MIN_EMITTER_BANDS } else { 6 };
    let n_lat = divisions(PI * s.radius, params.element_size).max(fewest);
    let n_lon = divisions(2.0 * PI * s.radius, params.element_size).max(2 * n_lat).max(12);
    let sign = if s.facing == Facing::Inward { -1.0 } else { 1.0 };
    let dir = |k: usize, m: usize| {
        let (theta, phi) = (PI * k as f64 / n_lat as f64, 2.0 * PI * (m % n_lon) as f64 / n_lon as f64);
        if k == 0 {
            DVec3::Y
        } else if k == n_lat {
            -DVec3::Y
        } else {
            DVec3::new(theta.sin() * phi.cos(), theta.cos(), theta.sin() * phi.sin())
        }
    };
    for k in 0..n_lat {
        for m in 0..n_lon {
            let mut ring = vec![dir(k, m), dir(k, m + 1), dir(k + 1, m + 1), dir(k + 1, m)];
            ring.dedup();
            if ring.first() == ring.last() && ring.len() > 3 {
                ring.pop();
            }
            let mut pts: Vec<DVec3> = ring.iter().map(|d| s.center + *d * s.radius).collect();
            let (_, n, c) = polygon_area_normal(&pts);
            let mut dirs = ring;
            if n.dot(c - s.center) * sign < 0.0 {
                pts.reverse();
                dirs.reverse();
            }
            let verts = pts.iter().zip(&dirs).map(|(p, d)| b.vertex(*p, *d * sign)).collect();
            b.patches.push(pts);
            b.elements.push((verts, b.patches.len() - 1));
        }
    }
}
