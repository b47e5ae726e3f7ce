//! Elements graded towards inside corners, and quartered where the light asks. Where a wall
//! meets the floor or a block stands on it, radiosity falls steeply in the last few
//! centimetres before the corner (each surface sees less of the room there, and more of the
//! other's dim corner), and an element as wide as the rest of the surface averages that fall
//! away: smooth shading then shows the corner as bright as the open surface, and a final
//! gather that looks the solution up near a corner inherits the error. A geometric grading of
//! the mesh towards such edges (the a-priori half of Cohen, Greenberg, Immel & Brock 1986's
//! adaptive subdivision, as discontinuity meshing does for value discontinuities: Heckbert
//! 1992, D1 edges) puts thin elements where the fall is.
//!
//! The same splits serve adaptive subdivision ([`Splits::quarter_marked`], driven by
//! `radiosity_solver::Problem`): elements named by a refinement are cut in four.
//!
//! Each level halves the elements that have a side on a graded edge, parallel to that edge:
//! a quad into two quads, a triangle into a trapezoid on the edge and a triangle above it. An
//! element with sides on two graded edges (a surface's corner) is cut into four. Elements
//! along one edge split their shared sides at the same midpoints, so a strip along a
//! lattice's edge stays conforming; any other element that now has a new vertex inside one of
//! its sides is cut into triangles that use it, so smooth shading has no T-vertex to tear at.
//! Each element keeps its patch.

use rustc_hash::FxHashMap as HashMap;

use glam::DVec3;

use crate::builder::SurfaceBuilder;

/// Whether point `p` lies on segment `(a, b)` within `tol`.
fn on_segment(p: DVec3, (a, b): (DVec3, DVec3), tol: f64) -> bool {
    let d = b - a;
    let len2 = d.length_squared();
    if len2 <= 0.0 {
        return false;
    }
    let t = (p - a).dot(d) / len2;
    let slack = tol / len2.sqrt();
    t >= -slack && t <= 1.0 + slack && (a + d * t).distance(p) <= tol
}

/// The normal of a new vertex among `vertices`: their normals' mean (a tessellated curve's
/// facets keep their smooth normals; a flat surface's stay its own).
fn mean_normal(b: &SurfaceBuilder, vertices: &[u32]) -> DVec3 {
    vertices.iter().map(|&v| b.normals[v as usize]).sum::<DVec3>().normalize_or_zero()
}

/// Element splits on one surface: grading towards inside corners, then quartering of marked
/// elements (adaptive refinement), then [`Splits::conform`]. The splits share their record
/// of the midpoints cut into element sides, which `conform` uses.
#[derive(Default)]
pub(crate) struct Splits {
    /// The midpoint that splits each element side cut so far, by the side's vertex pair.
    midpoints: HashMap<(u32, u32), u32>,
}

impl Splits {
    /// The midpoint of side `i` of element `vs`, made (and recorded) if new.
    fn midpoint(&mut self, b: &mut SurfaceBuilder, vs: &[u32], i: usize) -> u32 {
        let (p, q) = (vs[i], vs[(i + 1) % vs.len()]);
        let normal = mean_normal(b, &[p, q]);
        let m = b.vertex((b.positions[p as usize] + b.positions[q as usize]) * 0.5, normal);
        self.midpoints.insert((p.min(q), p.max(q)), m);
        m
    }

    /// Element `vs` cut in four: at its sides' midpoints (and its centre, for a quad).
    fn quarter(&mut self, b: &mut SurfaceBuilder, vs: &[u32]) -> Vec<Vec<u32>> {
        let k = vs.len();
        let m: Vec<u32> = (0..k).map(|i| self.midpoint(b, vs, i)).collect();
        if k == 4 {
            let centre = (0..4).map(|i| b.positions[vs[i] as usize]).sum::<DVec3>() * 0.25;
            let o = b.vertex(centre, mean_normal(b, vs));
            (0..4).map(|i| vec![vs[i], m[i], o, m[(i + 3) % 4]]).collect()
        } else {
            vec![vec![vs[0], m[0], m[2]], vec![m[0], vs[1], m[1]], vec![m[2], m[1], vs[2]], m]
        }
    }

    /// Grades the elements of `b` towards `edges` (segments of its outline), `levels` times.
    pub(crate) fn grade(&mut self, b: &mut SurfaceBuilder, edges: &[(DVec3, DVec3)], levels: u32) {
        if edges.is_empty() || levels == 0 {
            return;
        }
        let tol = edges.iter().map(|&(a, c)| a.distance(c)).fold(0.0, f64::max) * 1e-7;
        for _ in 0..levels {
            let elements = std::mem::take(&mut b.elements);
            for (vs, patch) in elements {
                let k = vs.len();
                let touching: Vec<usize> = (0..k)
                    .filter(|&i| {
                        let (p, q) = (b.positions[vs[i] as usize], b.positions[vs[(i + 1) % k] as usize]);
                        edges.iter().any(|&e| on_segment(p, e, tol) && on_segment(q, e, tol))
                    })
                    .collect();
                let children: Vec<Vec<u32>> = match (k, touching.as_slice()) {
                    (_, []) => vec![vs],
                    // One side on the edge, or two opposite sides of a quad: halve across the
                    // two sides that meet it.
                    (4, [s]) | (4, [s, _]) if touching.len() == 1 || touching[1] == s + 2 => {
                        let s = *s;
                        let (m1, m3) =
                            (self.midpoint(b, &vs, (s + 1) % 4), self.midpoint(b, &vs, (s + 3) % 4));
                        let c = |j: usize| vs[(s + j) % 4];
                        vec![vec![c(0), c(1), m1, m3], vec![m3, m1, c(2), c(3)]]
                    }
                    (3, [s]) => {
                        let s = *s;
                        let (m1, m2) =
                            (self.midpoint(b, &vs, (s + 1) % 3), self.midpoint(b, &vs, (s + 2) % 3));
                        let c = |j: usize| vs[(s + j) % 3];
                        vec![vec![c(0), c(1), m1, m2], vec![m2, m1, c(2)]]
                    }
                    // Sides on two edges (a corner of the surface): in four.
                    _ => self.quarter(b, &vs),
                };
                b.elements.extend(children.into_iter().map(|c| (c, patch)));
            }
        }
    }

    /// Cuts every element for which `marked` holds (given the builder and its vertices) in
    /// four.
    pub(crate) fn quarter_marked(
        &mut self,
        b: &mut SurfaceBuilder,
        marked: &dyn Fn(&SurfaceBuilder, &[u32]) -> bool,
    ) {
        let elements = std::mem::take(&mut b.elements);
        for (vs, patch) in elements {
            if marked(b, &vs) {
                let children = self.quarter(b, &vs);
                b.elements.extend(children.into_iter().map(|c| (c, patch)));
            } else {
                b.elements.push((vs, patch));
            }
        }
    }

    /// Ends the splits: every element left with a split vertex inside one of its sides is cut
    /// into triangles that use it (see [`conform`]).
    pub(crate) fn conform(self, b: &mut SurfaceBuilder) {
        if !self.midpoints.is_empty() {
            conform(b, &self.midpoints);
        }
    }
}

/// Grades the elements of `b` towards `edges` (segments of its outline), `levels` times, and
/// conforms the result.
pub(crate) fn grade(b: &mut SurfaceBuilder, edges: &[(DVec3, DVec3)], levels: u32) {
    let mut splits = Splits::default();
    splits.grade(b, edges, levels);
    splits.conform(b);
}

/// Quarters the elements of `b` that something comes nearer to than half their size (their
/// own half-width, from their centre), `levels` times while they are larger than `min_size`,
/// and conforms the result. `near(centre, reach)` says whether other geometry comes within
/// `reach` of an element's centre on the surface's front side.
///
/// Light on a surface changes over about the distance to what stands near it: behind a
/// model 10 cm from a wall, under a shelf, around a model's feet. An element larger than
/// that distance averages the bright and the dim, and a small object among such elements
/// gets back their mean: a cow on a shelf, between boards 26 cm elements wide, came out 3 %
/// dark against the path tracer (the same scene with 10 cm elements: within 0.6 %). The
/// criterion is geometric (element size against distance, as the local feature size of
/// mesh generation), so it costs no probe solve and holds for meshes of any size. Reaching
/// a whole element size instead of half added twice the elements (the Cornell box 12 570
/// against 11 990) and did not bring the cow nearer (−0.1 % against −0.7 %, means over
/// three seeds, each ±1 %).
pub(crate) fn refine_near(
    b: &mut SurfaceBuilder,
    levels: u32,
    min_size: f64,
    near: &dyn Fn(DVec3, f64) -> bool,
) {
    let mut splits = Splits::default();
    for _ in 0..levels {
        let before = b.elements.len();
        splits.quarter_marked(b, &|b, vs| {
            let k = vs.len();
            let p = |i: usize| b.positions[vs[i % k] as usize];
            let size = (0..k).map(|i| p(i).distance(p(i + 1))).fold(0.0, f64::max);
            let centre = (0..k).map(p).sum::<DVec3>() / k as f64;
            // Strictly larger: a grid lays elements a little under the element size, and
            // each of `levels` quarterings must still find them above `min_size` (the
            // element size over 2^levels).
            size > min_size * (1.0 + 1e-9) && near(centre, 0.5 * size)
        });
        if b.elements.len() == before {
            break;
        }
    }
    splits.conform(b);
}

/// Cuts every element with a split vertex inside one of its sides into triangles that use
/// it: a fan from a corner whose own two sides are whole, or else from the element's centre.
fn conform(b: &mut SurfaceBuilder, midpoints: &HashMap<(u32, u32), u32>) {
    // The vertices strictly inside side (p, q), in order from p.
    fn inside(p: u32, q: u32, midpoints: &HashMap<(u32, u32), u32>, out: &mut Vec<u32>) {
        if let Some(&m) = midpoints.get(&(p.min(q), p.max(q))) {
            inside(p, m, midpoints, out);
            out.push(m);
            inside(m, q, midpoints, out);
        }
    }
    let elements = std::mem::take(&mut b.elements);
    for (vs, patch) in elements {
        let k = vs.len();
        // The outline with split vertices, and which corners have a split side.
        let mut outline = Vec::with_capacity(2 * k);
        let mut split_side = vec![false; k];
        for i in 0..k {
            outline.push(vs[i]);
            let before = outline.len();
            inside(vs[i], vs[(i + 1) % k], midpoints, &mut outline);
            split_side[i] = outline.len() > before;
        }
        if outline.len() == k {
            b.elements.push((vs, patch));
            continue;
        }
        // A corner whose sides (the one after it and the one before it) are both whole sees
        // every other outline point across the element: a fan from it has no flat triangle.
        let apex = (0..k).find(|&i| !split_side[i] && !split_side[(i + k - 1) % k]);
        match apex {
            Some(i) => {
                let start = outline.iter().position(|&v| v == vs[i]).unwrap_or(0);
                let ring: Vec<u32> =
                    (0..outline.len()).map(|j| outline[(start + j) % outline.len()]).collect();
                for j in 1..ring.len() - 1 {
                    b.elements.push((vec![ring[0], ring[j], ring[j + 1]], patch));
                }
            }
            None => {
                let centre =
                    outline.iter().map(|&v| b.positions[v as usize]).sum::<DVec3>() / outline.len() as f64;
                let o = b.vertex(centre, mean_normal(b, &vs));
                for j in 0..outline.len() {
                    b.elements.push((vec![o, outline[j], outline[(j + 1) % outline.len()]], patch));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(b: &SurfaceBuilder) -> f64 {
        b.elements
            .iter()
            .map(|(vs, _)| {
                let p: Vec<DVec3> = vs.iter().map(|&v| b.positions[v as usize]).collect();
                (1..p.len() - 1).map(|i| 0.5 * (p[i] - p[0]).cross(p[i + 1] - p[0]).z).sum::<f64>()
            })
            .sum()
    }

    /// Every element side is either used twice with opposite directions or lies on the
    /// outline of the unit square: no T-vertex, no overlap, no hole.
    fn assert_conforming(b: &SurfaceBuilder) {
        let mut sides: HashMap<(u32, u32), i32> = HashMap::default();
        for (vs, _) in &b.elements {
            for i in 0..vs.len() {
                let (p, q) = (vs[i], vs[(i + 1) % vs.len()]);
                *sides.entry((p, q)).or_default() += 1;
            }
        }
        for (&(p, q), &n) in &sides {
            assert_eq!(n, 1, "side {p}-{q} used {n} times in one direction");
            if !sides.contains_key(&(q, p)) {
                let (a, c) = (b.positions[p as usize], b.positions[q as usize]);
                let on_outline = |f: fn(DVec3) -> f64| {
                    (f(a) - f(c)).abs() < 1e-12 && (f(a).abs() < 1e-12 || (f(a) - 1.0).abs() < 1e-12)
                };
                assert!(on_outline(|v| v.x) || on_outline(|v| v.y), "inner side {a}-{c} has no neighbour");
            }
        }
    }

    fn unit_square_grid(n: usize, triangles: bool) -> SurfaceBuilder {
        let mut b = SurfaceBuilder::default();
        let z = DVec3::Z;
        for j in 0..n {
            for i in 0..n {
                let at = |i: usize, j: usize| DVec3::new(i as f64 / n as f64, j as f64 / n as f64, 0.0);
                let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)].map(|p| b.vertex(p, z));
                if triangles {
                    b.elements.push((vec![q[0], q[1], q[2]], 0));
                    b.elements.push((vec![q[0], q[2], q[3]], 0));
                } else {
                    b.elements.push((q.to_vec(), 0));
                }
            }
        }
        b
    }

    #[test]
    fn graded_quads_stay_conforming_and_keep_their_area() {
        let mut b = unit_square_grid(4, false);
        let (o, x, y) = (DVec3::ZERO, DVec3::X, DVec3::Y);
        grade(&mut b, &[(o, x), (y, o)], 2);
        assert!((area(&b) - 1.0).abs() < 1e-12);
        assert_conforming(&b);
        // The thinnest elements along the bottom edge are a quarter as tall as the others.
        let min_height = b
            .elements
            .iter()
            .filter(|(vs, _)| vs.iter().any(|&v| b.positions[v as usize].y == 0.0))
            .map(|(vs, _)| vs.iter().map(|&v| b.positions[v as usize].y).fold(0.0, f64::max))
            .fold(1.0, f64::min);
        assert!((min_height - 0.0625).abs() < 1e-12, "{min_height}");
        // Strips along two edges of a 4×4 grid: 4 + 4 columns of 3 elements minus the
        // corner, which is cut in four twice.
        assert!(b.elements.len() > 16 && b.elements.len() < 60, "{}", b.elements.len());
    }

    #[test]
    fn graded_triangles_stay_conforming_and_keep_their_area() {
        let mut b = unit_square_grid(3, true);
        grade(&mut b, &[(DVec3::X, DVec3::new(1.0, 1.0, 0.0))], 3);
        assert!((area(&b) - 1.0).abs() < 1e-12);
        assert_conforming(&b);
        assert!(b.elements.iter().all(|(vs, _)| vs.len() >= 3 && vs.len() <= 4));
    }

    #[test]
    fn no_edges_change_nothing() {
        let mut b = unit_square_grid(2, false);
        let before = b.elements.clone();
        grade(&mut b, &[], 2);
        assert_eq!(b.elements, before);
    }
}
