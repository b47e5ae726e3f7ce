//! Building a mesh's smoothing table ([`Smoothing`]): vertices of different surfaces in one
//! place, then T-junctions, each pair kept below the crease angle.

use glam::DVec3;

use crate::{Mesh, Smoothing};

impl Smoothing {
    /// The table for `mesh` with `crease_angle_deg` (0: none). Places are matched on a grid
    /// of 1e-7 of the scene's diagonal, so points an exporter or the mesher computed along
    /// an edge from either end still meet.
    pub(crate) fn new(mesh: &Mesh, crease_angle_deg: f64) -> Self {
        if crease_angle_deg <= 0.0 || mesh.positions.is_empty() {
            return Self::default();
        }
        let cos_limit = crease_angle_deg.to_radians().cos();
        let mut vertex_surface = vec![u32::MAX; mesh.positions.len()];
        for el in &mesh.elements {
            let surface = mesh.patches[el.patch as usize].surface;
            for &v in el.vertex_indices() {
                vertex_surface[v as usize] = surface;
            }
        }
        // Two vertices may pool: other surfaces, the same object and face, a bend below the
        // crease angle.
        let compatible = |a: u32, b: u32| {
            let (sa, sb) = (vertex_surface[a as usize], vertex_surface[b as usize]);
            let (ta, tb) = (&mesh.surfaces[sa as usize], &mesh.surfaces[sb as usize]);
            sa != sb
                && ta.object == tb.object
                && ta.back == tb.back
                && mesh.shading_normals[a as usize].dot(mesh.shading_normals[b as usize]) > cos_limit
        };
        let (lo, hi) = mesh.bounds();
        let diagonal = (hi - lo).length().max(f64::MIN_POSITIVE);
        let grid = 1e-7 * diagonal;
        // Vertices sorted by place, those in one place side by side (sorting millions of them
        // is faster than a map of lists, which allocated a list per place). Places are counted
        // from the lowest corner, so indices stay below 2·10⁷: from the origin, a scene far
        // away saturated them, and all its vertices shared one place (every pair a partner).
        let mut places: Vec<([i64; 3], u32)> = (0..mesh.positions.len())
            .filter(|&v| vertex_surface[v] != u32::MAX)
            .map(|v| ((mesh.positions[v] - lo).to_array().map(|c| (c / grid).round() as i64), v as u32))
            .collect();
        places.sort_unstable();
        let mut pairs: Vec<(u32, u32, f32)> = Vec::new();
        for group in places.chunk_by(|x, y| x.0 == y.0).filter(|g| g.len() > 1) {
            for &(_, a) in group {
                pairs.extend(group.iter().filter(|&&(_, b)| compatible(a, b)).map(|&(_, b)| (a, b, 1.0)));
            }
        }
        drop(places);
        t_junctions(mesh, &vertex_surface, 1e-6 * diagonal, &compatible, &mut pairs);
        if pairs.is_empty() {
            return Self::default();
        }
        // Bucketed by vertex (a counting sort: a scanned model pools each of its millions of
        // vertices with several others), then each vertex's few partners in order.
        let mut offsets = vec![0u32; mesh.positions.len() + 1];
        for &(a, _, _) in &pairs {
            offsets[a as usize + 1] += 1;
        }
        for v in 0..mesh.positions.len() {
            offsets[v + 1] += offsets[v];
        }
        let mut filled = offsets.clone();
        let mut by_vertex = vec![(0u32, 0.0f32); pairs.len()];
        for &(a, b, w) in &pairs {
            by_vertex[filled[a as usize] as usize] = (b, w);
            filled[a as usize] += 1;
        }
        drop(pairs);
        for v in 0..mesh.positions.len() {
            by_vertex[offsets[v] as usize..offsets[v + 1] as usize]
                .sort_unstable_by_key(|&(b, w)| (b, w.to_bits()));
        }
        let (partners, weights) = by_vertex.into_iter().unzip();
        Self { offsets, partners, weights }
    }
}

/// Adds to `pairs`, for every vertex on a surface's outline that lies strictly inside an
/// outline edge (a, b) of another surface it may pool with (`compatible`), the pairs
/// (v, a, 1 − t) and (v, b, t), t its place along the edge. Outline edges are element edges
/// used once within their surface; they are found through a uniform grid of cells as large
/// as the median of them, so each vertex tests only the edges of its own cell. (Cells as
/// large as the longest edge put a whole model's vertices in one cell beside a room's long
/// walls: 30 k triangles took 9 s.)
fn t_junctions(
    mesh: &Mesh,
    vertex_surface: &[u32],
    tolerance: f64,
    compatible: &dyn Fn(u32, u32) -> bool,
    pairs: &mut Vec<(u32, u32, f32)>,
) {
    // Every element edge, sorted: an edge used once within its surface stands alone.
    let mut edges: Vec<(u32, u32)> = (mesh.elements.iter())
        .flat_map(|el| {
            let v = el.vertex_indices();
            (0..v.len()).map(move |k| (v[k].min(v[(k + 1) % v.len()]), v[k].max(v[(k + 1) % v.len()])))
        })
        .collect();
    edges.sort_unstable();
    let outline: Vec<(u32, u32)> =
        edges.chunk_by(|x, y| x == y).filter(|run| run.len() == 1).map(|run| run[0]).collect();
    drop(edges);
    // Copies: the facets of a model repeat each corner and edge of their neighbours, and the
    // two faces of a two-sided object each other's; every place and every segment is tested
    // once, its copies only on a hit (on a million facets, testing each copy was 143 M tests
    // and most of the meshing time). Copies are found by sorting (ends as bits, lower end
    // first): a sort of millions of entries beats a map of them.
    let bits = |p: DVec3| p.to_array().map(f64::to_bits);
    let mut copies: Vec<([u64; 3], [u64; 3], u32, u32)> = outline
        .iter()
        .map(|&(a, b)| {
            let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
            if bits(pa) <= bits(pb) { (bits(pa), bits(pb), a, b) } else { (bits(pb), bits(pa), b, a) }
        })
        .collect();
    copies.sort_unstable();
    let mut segments: Vec<(DVec3, DVec3)> = Vec::new(); // start, direction
    let mut edge_start = vec![0usize];
    for run in copies.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        let (from, to) = (mesh.positions[run[0].2 as usize], mesh.positions[run[0].3 as usize]);
        segments.push((from, to - from));
        edge_start.push(edge_start.last().copied().unwrap_or(0) + run.len());
    }
    let edge_copies: Vec<(u32, u32)> = copies.iter().map(|&(_, _, from, to)| (from, to)).collect();
    drop(copies);
    let mut lengths: Vec<f64> = segments.iter().map(|(_, d)| d.length()).collect();
    if lengths.is_empty() {
        return;
    }
    let total_length: f64 = lengths.iter().sum();
    let middle = lengths.len() / 2;
    let median = *lengths.select_nth_unstable_by(middle, f64::total_cmp).1;
    // The median edge, but no smaller than:
    // * an eighth of the mean edge: a long slanted edge enters a cell per `size` of its
    //   length, so the (cell, edge) entries below number at most 27 · (8 + 1) per edge
    //   whatever the lengths (a 5 000-corner star's ear-clipped slivers, each as long as the
    //   star, beside its finely meshed outline, asked for 3 GB of entries);
    // * twice the tolerance, which the long-edge walk assumes is below a cell, and which keeps
    //   every cell index below 10⁶ (the tolerance is a millionth of the mesh's diagonal), so
    //   cell arithmetic cannot overflow whatever the coordinates.
    let size = median.max(total_length / (8.0 * lengths.len() as f64)).max(2.0 * tolerance);
    if !(size > 0.0 && size.is_finite()) {
        return;
    }
    // Cells are counted from the mesh's lowest corner, not the origin: far from the origin,
    // indices of points divided by a small cell would saturate the integer conversion, and
    // every point out there would share one cell.
    let (origin, _) = mesh.bounds();
    let cell = |p: DVec3| ((p - origin) / size).floor().as_i64vec3().to_array();
    // (cell, segment) for every cell a segment passes near, sorted by cell: a cell's segments
    // are one run, found by binary search.
    let mut cells: Vec<([i64; 3], u32)> = Vec::new();
    let mut touched = Vec::new();
    for (i, &(pa, d)) in segments.iter().enumerate() {
        let pb = pa + d;
        let (lo, hi) =
            (cell(pa.min(pb) - DVec3::splat(tolerance)), cell(pa.max(pb) + DVec3::splat(tolerance)));
        touched.clear();
        let box_cells = (0..3).map(|k| (hi[k] - lo[k] + 1) as u64).product::<u64>();
        if box_cells <= 27 {
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        touched.push([x, y, z]);
                    }
                }
            }
        } else {
            // A long slanted edge: the cells around points one cell apart along it. A point
            // within `tolerance` (far below a cell) of the edge is within a cell of one of
            // them, so in a neighbouring cell.
            let steps = (d.length() / size).ceil() as usize;
            for s in 0..=steps {
                let c = cell(pa.lerp(pb, s as f64 / steps as f64));
                for k in 0..27 {
                    touched.push([c[0] + k % 3 - 1, c[1] + k / 3 % 3 - 1, c[2] + k / 9 - 1]);
                }
            }
            touched.sort_unstable();
            touched.dedup();
        }
        cells.extend(touched.iter().map(|&c| (c, i as u32)));
    }
    cells.sort_unstable();
    let in_cell = |c: [i64; 3]| {
        let first = cells.partition_point(|&(k, _)| k < c);
        cells[first..].iter().take_while(move |&&(k, _)| k == c).map(|&(_, i)| i)
    };
    // The outline's vertices, copies of one place next to each other.
    // (Each vertex ends two outline edges: its index is deduplicated before the 32-byte
    // entries are made.)
    let mut outline_vertices: Vec<u32> = outline.iter().flat_map(|&(a, b)| [a, b]).collect();
    drop(outline);
    outline_vertices.sort_unstable();
    outline_vertices.dedup();
    let mut on_outline: Vec<([u64; 3], u32)> =
        outline_vertices.iter().map(|&v| (bits(mesh.positions[v as usize]), v)).collect();
    drop(outline_vertices);
    on_outline.sort_unstable();
    for place in on_outline.chunk_by(|x, y| x.0 == y.0) {
        let p = mesh.positions[place[0].1 as usize];
        for i in in_cell(cell(p)) {
            let (pa, d) = segments[i as usize];
            let t = (p - pa).dot(d) / d.length_squared();
            let end = tolerance / d.length();
            if !(t > end && t < 1.0 - end && (pa + d * t).distance(p) < tolerance) {
                continue;
            }
            for &(_, v) in place {
                for &(a, b) in &edge_copies[edge_start[i as usize]..edge_start[i as usize + 1]] {
                    if vertex_surface[a as usize] != vertex_surface[v as usize] && compatible(v, a) {
                        pairs.push((v, a, (1.0 - t) as f32));
                        pairs.push((v, b, t as f32));
                    }
                }
            }
        }
    }
}
