//! The mesh's element triangles as the GPU draws them: wound towards their lit side, with
//! the wireframe's edge flags.

use radiosity_mesh::Mesh;

/// The mesh's element triangles, each wound counter-clockwise seen from the side its element
/// faces, so back-face culling keeps the lit side whatever order the mesher used.
pub fn oriented_triangles(mesh: &Mesh) -> Vec<(u32, [u32; 3])> {
    mesh.element_triangles()
        .map(|(e, [a, b, c])| {
            let p = |i: u32| mesh.positions[i as usize];
            let n = (p(b) - p(a)).cross(p(c) - p(a));
            if n.dot(mesh.elements[e as usize].normal) < 0.0 { (e, [a, c, b]) } else { (e, [a, b, c]) }
        })
        .collect()
}

/// Wireframe flags of every triangle: for edge i (opposite corner i), bit 2i when it is an
/// element edge (not a quad's diagonal) and bit 2i+1 when it is also on its patch's outline
/// (no other element of the same patch shares it).
pub fn edge_flags(mesh: &Mesh, triangles: &[(u32, [u32; 3])]) -> Vec<u32> {
    use std::collections::HashMap;
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    // How many elements of each patch use each element edge.
    let mut uses: HashMap<(u32, (u32, u32)), u32> = HashMap::new();
    for el in &mesh.elements {
        let v = el.vertex_indices();
        for i in 0..v.len() {
            *uses.entry((el.patch, key(v[i], v[(i + 1) % v.len()]))).or_default() += 1;
        }
    }
    triangles
        .iter()
        .map(|&(e, tri)| {
            let el = &mesh.elements[e as usize];
            let v = el.vertex_indices();
            let is_element_edge =
                |a: u32, b: u32| (0..v.len()).any(|i| key(v[i], v[(i + 1) % v.len()]) == key(a, b));
            let mut flags = 0;
            for i in 0..3 {
                let (a, b) = (tri[(i + 1) % 3], tri[(i + 2) % 3]);
                if is_element_edge(a, b) {
                    flags |= 1 << (2 * i);
                    if uses.get(&(el.patch, key(a, b))) == Some(&1) {
                        flags |= 2 << (2 * i);
                    }
                }
            }
            flags
        })
        .collect()
}
