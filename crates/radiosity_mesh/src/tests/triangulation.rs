//! A model's triangulation does not decide its meshing: the same surfaces written as one
//! triangle or cut into sixteen mesh alike.

use super::*;

/// The point `k` quarters of the way along edge `p → q`, made once per edge.
fn quarter_point(
    p: u32,
    q: u32,
    k: u32,
    positions: &mut Vec<DVec3>,
    on_edge: &mut HashMap<(u32, u32, u32), u32>,
) -> u32 {
    match k {
        0 => p,
        4 => q,
        _ => {
            let (lo, hi, k) = if p < q { (p, q, k) } else { (q, p, 4 - k) };
            *on_edge.entry((lo, hi, k)).or_insert_with(|| {
                let (x, y) = (positions[lo as usize], positions[hi as usize]);
                positions.push(x + (y - x) * (f64::from(k) / 4.0));
                (positions.len() - 1) as u32
            })
        }
    }
}

/// `m` with every triangle cut into 16 by a 4 × 4 barycentric lattice, the points on an edge
/// shared by the triangles on both sides (as a modeller's subdivision writes them).
fn cut_into_16(m: &PolygonMesh) -> PolygonMesh {
    let mut positions = m.positions().to_vec();
    let mut on_edge = HashMap::default();
    let mut faces = Vec::new();
    for f in m.faces() {
        let (a, b, c) = (f[0], f[1], f[2]);
        let mut at = HashMap::default();
        for i in 0..=4u32 {
            for j in 0..=4 - i {
                let v = if j == 0 {
                    quarter_point(a, b, i, &mut positions, &mut on_edge)
                } else if i == 0 {
                    quarter_point(a, c, j, &mut positions, &mut on_edge)
                } else if i + j == 4 {
                    quarter_point(b, c, j, &mut positions, &mut on_edge)
                } else {
                    let [pa, pb, pc] = [a, b, c].map(|v| positions[v as usize]);
                    positions.push(pa + (pb - pa) * (f64::from(i) / 4.0) + (pc - pa) * (f64::from(j) / 4.0));
                    (positions.len() - 1) as u32
                };
                at.insert((i, j), v);
            }
        }
        for i in 0..4 {
            for j in 0..4 - i {
                faces.push(vec![at[&(i, j)], at[&(i + 1, j)], at[&(i, j + 1)]]);
                if i + j + 2 <= 4 {
                    faces.push(vec![at[&(i + 1, j)], at[&(i + 1, j + 1)], at[&(i, j + 1)]]);
                }
            }
        }
    }
    PolygonMesh::try_new(positions, faces).unwrap()
}

#[test]
fn a_model_cut_into_16_meshes_as_the_model_does() {
    // A room of quads (each written as two triangles), a slanted roof triangle, a fan of
    // slivers and a small object's facets: cut into 16 pieces each, still the same surfaces.
    let mut positions = Vec::new();
    let mut faces: Vec<Vec<u32>> = Vec::new();
    let quad = |q: [DVec3; 4], positions: &mut Vec<DVec3>, faces: &mut Vec<Vec<u32>>| {
        let base = positions.len() as u32;
        positions.extend(q);
        faces.push(vec![base, base + 1, base + 2]);
        faces.push(vec![base, base + 2, base + 3]);
    };
    let (w, h, d) = (6.0, 2.8, 5.0);
    let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    quad([p(0.0, 0.0, 0.0), p(0.0, 0.0, d), p(w, 0.0, d), p(w, 0.0, 0.0)], &mut positions, &mut faces);
    quad([p(0.0, h, 0.0), p(w, h, 0.0), p(w, h, d), p(0.0, h, d)], &mut positions, &mut faces);
    quad([p(0.0, 0.0, 0.0), p(w, 0.0, 0.0), p(w, h, 0.0), p(0.0, h, 0.0)], &mut positions, &mut faces);
    // A fan of slivers from one corner of the far wall, as an exporter writes an n-gon.
    let base = positions.len() as u32;
    positions.push(p(0.0, 0.0, d));
    for k in 0..=8 {
        positions.push(p(w * f64::from(k) / 8.0, h, d));
    }
    positions.push(p(w, 0.0, d));
    for k in 0..8 {
        faces.push(vec![base, base + 2 + k, base + 1 + k]);
    }
    faces.push(vec![base, base + 10, base + 9]);
    // Small facets of an object: a tetrahedron 10 cm across.
    let t = positions.len() as u32;
    positions.extend([p(3.0, 1.0, 2.0), p(3.1, 1.0, 2.0), p(3.0, 1.1, 2.0), p(3.0, 1.0, 2.1)]);
    faces.extend([
        vec![t, t + 2, t + 1],
        vec![t, t + 1, t + 3],
        vec![t, t + 3, t + 2],
        vec![t + 1, t + 2, t + 3],
    ]);
    let model = PolygonMesh::try_new(positions, faces).unwrap();
    let cut = cut_into_16(&model);
    assert_eq!(cut.faces().len(), 16 * model.faces().len());
    let params = MeshParams::try_new(1.0, 0.25).unwrap();
    let a = Mesh::build(&scene_of(Shape::Mesh(model)), &params).unwrap();
    let b = Mesh::build(&scene_of(Shape::Mesh(cut)), &params).unwrap();
    assert_eq!(b.surfaces.len(), a.surfaces.len());
    assert_eq!(b.patches.len(), a.patches.len());
    assert_eq!(b.elements.len(), a.elements.len());
    assert!((a.total_area() - b.total_area()).abs() < 1e-9 * a.total_area());
    assert_eq!(euler_characteristic(&b), euler_characteristic(&a));
}

/// A lone small triangle that a thin panel passes through, and a large one: written as one
/// triangle or cut into sixteen (merged into their outline), each meshes alike. The sixteen
/// pieces of the small one were cut along the panel and the one triangle was not.
#[test]
fn a_lone_triangle_meshes_alike_whatever_its_triangulation() {
    let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
    for size in [0.3, 3.0] {
        let positions = vec![
            p(0.0, 0.0, 0.0),
            p(size, 0.0, 0.0),
            p(0.0, size, 0.0),
            // A panel across the triangle's plane along x = size / 3.
            p(size / 3.0, -0.1, -0.05),
            p(size / 3.0, size + 0.1, -0.05),
            p(size / 3.0, size + 0.1, 0.05),
            p(size / 3.0, -0.1, 0.05),
        ];
        let faces = vec![vec![0, 1, 2], vec![3, 4, 5], vec![3, 5, 6]];
        let model = PolygonMesh::try_new(positions, faces).unwrap();
        let params = MeshParams::try_new(1.0, 0.25).unwrap();
        let a = Mesh::build(&scene_of(Shape::Mesh(model.clone())), &params).unwrap();
        let b = Mesh::build(&scene_of(Shape::Mesh(cut_into_16(&model))), &params).unwrap();
        let in_plane = |m: &Mesh| m.elements.iter().filter(|e| e.normal.z.abs() > 0.99).count();
        assert_eq!(in_plane(&b), in_plane(&a), "triangle of side {size}");
        assert_eq!(b.elements.len(), a.elements.len(), "triangle of side {size}");
    }
}
