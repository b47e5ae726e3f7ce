//! Meshes that follow contacts: where a solid stands on a flat surface (a block on the floor,
//! a cupboard against a wall), the surface is cut along the solid's footprint before it is
//! meshed, and the covered part is left out — it neither shoots nor receives. These are the
//! value discontinuities (D0) of discontinuity meshing (Heckbert 1992; Lischinski, Tampieri &
//! Greenberg 1992): radiosity jumps from the lit floor to the dark floor under the block, so
//! an element that straddles the outline averages the two, and that diluted value is what the
//! block's sides then receive from the floor.
//!
//! A footprint is found from the solid's own faces: the edges of faces that stand on the
//! surface's plane (one edge in it, the rest on its lit side) chain into a closed loop. A convex
//! loop cuts; anything else (an open shape, a concave outline) is left as it was. A face lying
//! flat against the surface, facing it (a box's bottom), is hidden whole.
//!
//! The surface minus a convex footprint is cut into convex pieces by the footprint's edge
//! lines in turn (piece k: outside edge k, inside edges 1‥k−1), each piece meshed as its own
//! surface; smoothing pools their vertices as it does for any coplanar surfaces of one object.
//! Footprints of more than [`MAX_FOOTPRINT_CORNERS`] corners do not cut (see there).

use rustc_hash::FxHashMap as HashMap;

use glam::DVec3;

use crate::planar::{
    area, area_signed, bounds, contains_within, distance_to_polygon, key, lexicographic, plane, split,
    tolerance,
};
use radiosity_core::{Polygon, Scene, Shape};

/// A polygon of a scene: the object and the polygon's index within it (a face index for a
/// model mesh).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct PolygonId {
    pub(crate) object: usize,
    pub(crate) index: usize,
}

/// Most corners of a footprint that cuts: boxes, wedges and prisms of furniture. The pieces
/// around a footprint run from each of its edges to the surface's outline, so a round one
/// (a cylinder's 24 sides) cuts the surface into thin wedges that mesh into many elements;
/// those are meshed whole, as without contacts.
const MAX_FOOTPRINT_CORNERS: usize = 8;

/// A solid set into a surface by at most this share of its height above it stands on it: its
/// footprint is where its faces cross the surface. Exported models often sink doors, table
/// legs and cupboards a centimetre into the floor so that no crack shows; their footprints
/// went unfound, the floor ran on under them, and a floor element under a door took the
/// light of the lit room on one side and gave it to the dark room on the other (Bitterli's
/// *Veach, Ajar*). A box sunk a third of its height is another case (it passes through).
const SHALLOW_SINK: f64 = 0.05;

/// Most polygon pairs looked at while finding contacts (bounding boxes first): a model of
/// many large faces would otherwise cost targets × faces. Past it, surfaces are meshed uncut.
const PAIR_BUDGET: u64 = 200_000_000;

/// Most candidates looked at by [`Contacts::geometry_within`] (bounding boxes first), apart
/// from [`PAIR_BUDGET`]: a fan of 60 000 slivers about one vertex lists each in every query
/// near it (their boxes span the fan), and its refinement took elements × slivers. Past it,
/// no more elements are quartered for nearby geometry.
const PROXIMITY_BUDGET: u64 = 50_000_000;

/// An inside corner needs the other polygon's front to turn at least this much towards the
/// surface (the cosine between its normal and the direction into the surface): 0.1 leaves out
/// faces within 6° of lying flat, whose corner with the surface is hardly a corner.
const INSIDE_CORNER_COS: f64 = 0.1;

/// Every polygon of a scene that can stand on another, with its bounding box.
pub(crate) struct Contacts<'a> {
    candidates: Vec<(PolygonId, &'a Polygon, DVec3, DVec3)>,
    /// The candidates by where they are, so that a query visits those near it only.
    grid: Grid,
    pairs_left: std::cell::Cell<u64>,
    /// What is left of [`PROXIMITY_BUDGET`].
    proximity_left: std::cell::Cell<u64>,
    /// Per object, whether its material emits (see [`Contacts::geometry_within`]).
    emits: Vec<bool>,
}

/// A uniform grid over the candidates' bounds: each cell lists the candidates whose boxes
/// overlap it, in candidate order; a candidate over more than [`Grid::SPREAD`] cells (a
/// floor, a wall) is listed in `large` instead. Without it every query looked at every
/// candidate, and a room holding a 30 k-facet model spent the pair budget before the floor
/// was reached: its table legs and sofa were meshed uncut.
struct Grid {
    lo: DVec3,
    cell: DVec3,
    dims: [usize; 3],
    cells: Vec<Vec<u32>>,
    large: Vec<u32>,
}

impl Grid {
    /// Most cells a candidate is listed in; one over more goes to `large`.
    const SPREAD: usize = 64;
    /// Most cells in a grid (64³: 6 MB of empty lists).
    const MAX_CELLS: usize = 64 * 64 * 64;

    /// The grid of the candidates' bounding `boxes`, in candidate order.
    fn new(boxes: impl ExactSizeIterator<Item = (DVec3, DVec3)> + Clone) -> Self {
        let count = boxes.len();
        let (lo, hi) = boxes
            .clone()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), (a, b)| (lo.min(a), hi.max(b)));
        let (cell, dims) = Self::shape(hi - lo, count);
        let mut grid =
            Self { lo, cell, dims, cells: vec![Vec::new(); dims.iter().product()], large: Vec::new() };
        if count == 0 {
            return grid;
        }
        for (k, (a, b)) in boxes.enumerate() {
            let (from, to) = (grid.cell_of(a), grid.cell_of(b));
            let spread = (0..3).map(|i| to[i] - from[i] + 1).product::<usize>();
            if spread > Self::SPREAD {
                grid.large.push(k as u32);
                continue;
            }
            grid.for_cells(from, to, |c| c.push(k as u32));
        }
        grid
    }

    /// Cell size and cells per axis for `count` candidates spread over `extent`: about four
    /// candidates a cell, at most [`Grid::MAX_CELLS`] cells, and cubic cells, so that a long
    /// thin scene is cut along its length. (The same number of cells on every axis made a
    /// row of 50 000 tiles 2 000 tiles a cell, and the search for each tile's neighbours
    /// quadratic.)
    fn shape(extent: DVec3, count: usize) -> (DVec3, [usize; 3]) {
        let extent =
            DVec3::from_array(extent.to_array().map(|e| if e.is_finite() { e.max(0.0) } else { 0.0 }));
        let longest = extent.max_element();
        if longest <= 0.0 {
            return (DVec3::splat(1e-9), [1; 3]);
        }
        let target = (count as f64 / 4.0).clamp(1.0, Self::MAX_CELLS as f64);
        // A flat scene (every candidate in one plane) has no volume: its thin axes count as a
        // millionth of the longest, so the cells are sized by its area.
        let thick = extent.max(DVec3::splat(longest * 1e-6));
        let mut size = (thick.x * thick.y * thick.z / target).cbrt();
        let dims_for = |size: f64| extent.to_array().map(|e| ((e / size).ceil() as usize).max(1));
        let mut dims = dims_for(size);
        // Rounding up on each axis may pass the bound: coarsen until it holds.
        while dims.iter().map(|&d| d as f64).product::<f64>() > Self::MAX_CELLS as f64 {
            size *= 1.25;
            dims = dims_for(size);
        }
        let cell = extent / DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64);
        (cell.max(DVec3::splat(1e-9)), dims)
    }

    /// The length of the grid's diagonal: no two candidates lie farther apart.
    fn diagonal(&self) -> f64 {
        (self.cell * DVec3::new(self.dims[0] as f64, self.dims[1] as f64, self.dims[2] as f64)).length()
    }

    /// The cell holding `p`, clamped into the grid.
    fn cell_of(&self, p: DVec3) -> [usize; 3] {
        let t = ((p - self.lo) / self.cell).floor();
        [0, 1, 2].map(|i| (t[i].max(0.0) as usize).min(self.dims[i] - 1))
    }

    /// Calls `f` on every cell from `from` to `to`, both included.
    fn for_cells(&mut self, from: [usize; 3], to: [usize; 3], mut f: impl FnMut(&mut Vec<u32>)) {
        for z in from[2]..=to[2] {
            for y in from[1]..=to[1] {
                let row = (z * self.dims[1] + y) * self.dims[0];
                self.cells[row + from[0]..=row + to[0]].iter_mut().for_each(&mut f);
            }
        }
    }

    /// The candidates listed in the cells overlapping `[lo, hi]`, and the large ones, each
    /// once, in candidate order.
    fn near(&self, lo: DVec3, hi: DVec3) -> Vec<u32> {
        let (from, to) = (self.cell_of(lo), self.cell_of(hi));
        let mut out = self.large.clone();
        for z in from[2]..=to[2] {
            for y in from[1]..=to[1] {
                let row = (z * self.dims[1] + y) * self.dims[0];
                for cell in &self.cells[row + from[0]..=row + to[0]] {
                    out.extend_from_slice(cell);
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}

impl Grid {
    /// Whether `f` holds for some candidate listed in the cells overlapping `[lo, hi]` or
    /// among the large ones, stopping at the first (a candidate may be offered twice).
    fn any_near(&self, lo: DVec3, hi: DVec3, mut f: impl FnMut(u32) -> bool) -> bool {
        if self.large.iter().any(|&k| f(k)) {
            return true;
        }
        let (from, to) = (self.cell_of(lo), self.cell_of(hi));
        for z in from[2]..=to[2] {
            for y in from[1]..=to[1] {
                let row = (z * self.dims[1] + y) * self.dims[0];
                if self.cells[row + from[0]..=row + to[0]].iter().flatten().any(|&k| f(k)) {
                    return true;
                }
            }
        }
        false
    }
}

/// A surface cut along footprints.
pub(crate) struct Cut {
    /// Convex pieces covering the surface minus the footprints, in a fixed order.
    pub(crate) pieces: Vec<Polygon>,
    /// Area covered by the footprints, scene units².
    pub(crate) hidden: f64,
}

impl<'a> Contacts<'a> {
    /// The polygons of `scene` (polygon objects and model meshes; spheres touch in a point).
    pub(crate) fn new(scene: &'a Scene) -> Self {
        let mut candidates = Vec::new();
        for (object, o) in scene.objects.iter().enumerate() {
            let polygons: &[Polygon] = match &o.shape {
                Shape::Polygons(ps) => ps,
                Shape::Mesh(m) => m.polygons(),
                Shape::Sphere(_) => &[],
            };
            for (index, p) in polygons.iter().enumerate() {
                let v = p.vertices();
                let (lo, hi) = bounds(v);
                candidates.push((PolygonId { object, index }, p, lo, hi));
            }
        }
        let grid = Grid::new(candidates.iter().map(|c| (c.2, c.3)));
        let emits =
            scene.objects.iter().map(|o| scene.materials[o.material].emission.max_channel() > 0.0).collect();
        Self {
            candidates,
            grid,
            pairs_left: std::cell::Cell::new(PAIR_BUDGET),
            proximity_left: std::cell::Cell::new(PROXIMITY_BUDGET),
            emits,
        }
    }

    /// Whether the budget of polygon pairs ran out (some surfaces were meshed uncut).
    pub(crate) fn budget_spent(&self) -> bool {
        self.pairs_left.get() == 0
    }

    /// Whether [`PROXIMITY_BUDGET`] ran out (some elements near other geometry were left
    /// unrefined).
    pub(crate) fn proximity_budget_spent(&self) -> bool {
        self.proximity_left.get() == 0
    }

    /// The candidates whose bounding boxes touch `[lo, hi]` widened by `eps`, in candidate
    /// order, or none once the budget is spent.
    fn near(
        &self,
        lo: DVec3,
        hi: DVec3,
        eps: f64,
    ) -> impl Iterator<Item = &(PolygonId, &'a Polygon, DVec3, DVec3)> {
        let (lo, hi) = (lo - eps, hi + eps);
        let listed = self.grid.near(lo, hi);
        let n = listed.len() as u64;
        let left = self.pairs_left.get();
        let allowed = left >= n;
        self.pairs_left.set(if allowed { left - n } else { 0 });
        listed
            .into_iter()
            .map(|k| &self.candidates[k as usize])
            .filter(move |c| allowed && c.2.cmple(hi).all() && c.3.cmpge(lo).all())
    }

    /// Whether polygon `id` lies flat against another polygon and within it, facing it (a
    /// box's bottom on the floor): no light can reach it.
    pub(crate) fn is_pressed_flat(&self, id: PolygonId, poly: &Polygon) -> bool {
        let v = poly.vertices();
        let (lo, hi) = bounds(v);
        self.near(lo, hi, tolerance(poly)).any(|&(other, p, _, _)| {
            other != id && p.normal().dot(poly.normal()) < -0.999 && {
                let eps = tolerance(p);
                let (n, d) = plane(p);
                v.iter().all(|&q| (n.dot(q) - d).abs() <= eps && contains_within(p.vertices(), n, q, eps))
            }
        })
    }

    /// The edges of convex `target` (polygon `id`, or one made of model faces when `None`)
    /// along which another polygon stands on its front side and turns its own front towards
    /// `target`'s: inside corners, where a wall meets the floor, a block's side the floor, two
    /// walls each other, or a piece of a cut surface meets the solid standing on it. Light
    /// changes steeply towards such an edge (each surface sees less of the room and more of
    /// the other's dim corner), so the mesher grades its elements there. Each edge as its two
    /// corners, in the polygon's order.
    pub(crate) fn inside_corners(&self, target: &Polygon, id: Option<PolygonId>) -> Vec<(DVec3, DVec3)> {
        let v = target.vertices();
        let n = target.normal();
        let edges: Vec<(DVec3, DVec3)> = (0..v.len()).map(|i| (v[i], v[(i + 1) % v.len()])).collect();
        let mut met = vec![false; edges.len()];
        // One pass over the polygons near the target (one share of the pair budget), each
        // tried against every edge still unmet.
        let (lo, hi) = bounds(v);
        for &(other, p, _, _) in self.near(lo, hi, tolerance(target)) {
            if Some(other) == id {
                continue;
            }
            let eps = tolerance(p);
            let (m, d) = plane(p);
            let on_plane = |q: DVec3| (m.dot(q) - d).abs() <= eps;
            if !p.vertices().iter().any(|&q| n.dot(q - v[0]) > eps) {
                continue; // nothing of it on the target's front side
            }
            for (k, &(a, b)) in edges.iter().enumerate() {
                // Into the polygon from the edge, within its plane (its corners run
                // counter-clockwise about its normal).
                let inward = n.cross(b - a).normalize_or_zero();
                met[k] = met[k]
                    || (m.dot(inward) > INSIDE_CORNER_COS
                        && on_plane(a)
                        && on_plane(b)
                        && [0.25, 0.5, 0.75]
                            .iter()
                            .any(|&t| contains_within(p.vertices(), m, a + (b - a) * t, eps)));
            }
        }
        edges.into_iter().zip(met).filter(|&(_, m)| m).map(|(e, _)| e).collect()
    }

    /// Whether some polygon comes within `reach` of point `c` of a surface facing `n`, on its
    /// front side (a vertex more than `eps` in front of the surface's plane through `c`):
    /// something near enough to shape the light there (see `grading::refine_near`). The
    /// surface's own polygon and its coplanar neighbours lie in that plane and do not count,
    /// nor does anything wholly behind it (a board's edges seen from its top), nor a polygon
    /// whose plane holds one of `corners` (the surface's inside corners, graded apart: a wall
    /// seen from the floor beside it). Emitters do not count either: the ceiling around a
    /// lamp hung 1 cm under it, quartered, showed the fans of its refined elements as dark
    /// streaks around the lamp in the smooth display (the bunny rooms' lamps), while the
    /// models that the refinement is for stand among surfaces that do not emit.
    pub(crate) fn geometry_within(
        &self,
        c: DVec3,
        n: DVec3,
        reach: f64,
        eps: f64,
        corners: &[(DVec3, DVec3)],
    ) -> bool {
        if self.proximity_budget_spent() {
            return false;
        }
        let r = DVec3::splat(reach);
        self.grid.any_near(c - r, c + r, |k| {
            let left = self.proximity_left.get();
            if left == 0 {
                return false;
            }
            self.proximity_left.set(left - 1);
            let (id, p, lo, hi) = &self.candidates[k as usize];
            if self.emits[id.object] || c.clamp(*lo, *hi).distance_squared(c) >= reach * reach {
                return false;
            }
            let v = p.vertices();
            if !v.iter().any(|&q| n.dot(q - c) > eps) {
                return false;
            }
            // The other face of an inside corner, or a piece of it (a wall given as two
            // triangles): its plane holds the corner's edge.
            let (m, d) = plane(p);
            let slack = tolerance(p).max(eps);
            if corners.iter().any(|&(a, b)| (m.dot(a) - d).abs() <= slack && (m.dot(b) - d).abs() <= slack) {
                return false;
            }
            distance_to_polygon(c, m, v) < reach
        })
    }

    /// `target` (polygon `id`, or a polygon made of model faces when `None`) cut along the
    /// footprints of the solids standing on it; `None` when nothing stands on it or the cut
    /// would not mesh well (then it is meshed whole, as without contacts).
    pub(crate) fn cut(
        &self,
        target: &Polygon,
        id: Option<PolygonId>,
        both_sides: bool,
        estimate: impl Fn(&Polygon) -> usize,
    ) -> Option<Cut> {
        let n = target.normal();
        let whole = target.area();
        let tiny = 1e-9 * whole;
        // Seams first (lines across the surface), then the footprints out of their pieces.
        let lines = self.seams(std::slice::from_ref(&target.vertices()), n, id, both_sides);
        let seamed = seams::cut_along(target, &lines, n, tiny);
        let footprints = self.footprints(target, id);
        let mut pieces = seamed.clone();
        let mut hidden = 0.0;
        for f in &footprints {
            let mut next = Vec::new();
            for piece in pieces {
                let (outside, inside) = split(&piece, f, n);
                next.extend(outside);
                hidden += area(&inside, n);
            }
            pieces = next;
        }
        // The footprints lie elsewhere on the plane.
        let footprinted = hidden > tiny;
        if !footprinted {
            (pieces, hidden) = (seamed.clone(), 0.0);
        }
        let polygons = |pieces: Vec<Vec<DVec3>>| seams::as_polygons(pieces, target, n, tiny);
        // Slivers mesh into many thin elements: footprints cut only when their pieces cost at
        // most four times the surface's elements. Seams are few and run across the surface
        // (strips, not wedges), and always cut.
        let seams_only =
            || polygons(seamed.clone()).filter(|p| p.len() > 1).map(|pieces| Cut { pieces, hidden: 0.0 });
        if !footprinted {
            return seams_only();
        }
        let cut = polygons(pieces)?;
        let pieces_elements: usize = cut.iter().map(&estimate).sum();
        let before = if seamed.len() == 1 {
            estimate(target)
        } else {
            seamed.iter().filter_map(|p| Polygon::try_new(p.clone()).ok()).map(|p| estimate(&p)).sum()
        };
        if pieces_elements > 4 * before.max(1) {
            return seams_only();
        }
        Some(Cut { pieces: cut, hidden })
    }

    /// The convex footprints of the solids standing on `target`, each counter-clockwise about
    /// its normal from its lowest corner, sorted by that corner (so a scene given as TOML,
    /// OBJ or glTF cuts the same way).
    fn footprints(&self, target: &Polygon, id: Option<PolygonId>) -> Vec<Vec<DVec3>> {
        let v = target.vertices();
        let (lo, hi) = bounds(v);
        let eps = tolerance(target);
        let (n, d) = plane(target);
        let height = |q: DVec3| n.dot(q) - d;
        let mut edges: Vec<Edge> = Vec::new();
        // A solid that stands partly over the edge is seen whole: faces up to the target's
        // size beyond it count. Only faces with an edge on the plane matter, so the box is
        // widened along the plane only: a floor's query then lists what stands near the
        // floor, not the whole room above it.
        let reach = lo.distance(hi);
        let (lo, hi) = slab_box(lo, hi, n, reach, eps);
        for &(other, p, _, _) in self.near(lo, hi, 0.0) {
            if Some(other) == id {
                continue;
            }
            let pv = p.vertices();
            let heights: Vec<f64> = pv.iter().map(|&q| height(q)).collect();
            let (below, above) = heights.iter().fold((0.0_f64, 0.0_f64), |(b, a), &h| (b.min(h), a.max(h)));
            if above <= eps {
                continue;
            }
            if below < -eps {
                // Set a little into the surface: its line across the plane is its edge on it.
                if -below <= SHALLOW_SINK * above
                    && let Some((a, b)) = crossing(pv, &heights, n, eps)
                {
                    let centre = pv.iter().copied().sum::<DVec3>() / pv.len() as f64;
                    edges.push((a, b, p.normal(), centre));
                }
                continue;
            }
            for i in 0..pv.len() {
                let j = (i + 1) % pv.len();
                if heights[i].abs() <= eps && heights[j].abs() <= eps {
                    // Onto the plane exactly, so the loop's corners are the target's plane.
                    let centre = pv.iter().copied().sum::<DVec3>() / pv.len() as f64;
                    edges.push((pv[i] - n * heights[i], pv[j] - n * heights[j], p.normal(), centre));
                }
            }
        }
        let mut loops: Vec<Vec<DVec3>> = chain(&edges, n)
            .into_iter()
            .filter_map(|l| convex_loop(l, n))
            .filter(|f| f.len() <= MAX_FOOTPRINT_CORNERS)
            .filter(|f| self.enclosed(f.iter().copied().sum::<DVec3>() / f.len() as f64, n, eps))
            .collect();
        loops.sort_by(|a, b| lexicographic(a[0], b[0]));
        loops
    }

    /// Whether `p`, a point of a footprint on a plane with normal `n`, lies inside a closed
    /// solid: the first face straight above it is met from behind. An open box or a cup
    /// standing on a table leaves the table inside it lit, so that footprint must not cut.
    /// Faces met at the same height (a table leg's top against the table top's underside)
    /// count as one: met from behind if any of them is, since the point is inside the solid
    /// whose face that is.
    fn enclosed(&self, p: DVec3, n: DVec3, eps: f64) -> bool {
        let origin = p + n * eps;
        // Only faces whose boxes meet the ray straight above can be met: the box from the
        // point to the far side of every candidate (one column of cells when the plane is
        // square to an axis, as floors and table tops are).
        let end = origin + n * self.grid.diagonal();
        let mut first: Option<(f64, bool)> = None;
        for &(_, poly, _, _) in self.near(origin.min(end), origin.max(end), eps) {
            let pn = poly.normal();
            let denominator = pn.dot(n);
            if denominator.abs() < 1e-12 {
                continue;
            }
            let t = pn.dot(poly.vertices()[0] - origin) / denominator;
            if t <= 0.0 || !contains_within(poly.vertices(), pn, origin + n * t, 0.0) {
                continue;
            }
            let behind = denominator > 0.0;
            first = match first {
                Some((best, b)) if (t - best).abs() <= eps => Some((best.min(t), b || behind)),
                Some((best, _)) if t < best => Some((t, behind)),
                None => Some((t, behind)),
                keep => keep,
            };
        }
        first.is_some_and(|(_, from_behind)| from_behind)
    }
}

/// Where a convex face of corners `pv` at `heights` above a plane of unit normal `n` crosses
/// it: the two points, in the face's order, projected onto the plane; `None` unless exactly
/// two. A crossing on an edge is computed from its corners in a fixed order, so that the two
/// faces sharing the edge find the same point bit for bit and their segments chain.
fn crossing(pv: &[DVec3], heights: &[f64], n: DVec3, eps: f64) -> Option<(DVec3, DVec3)> {
    let mut points = Vec::with_capacity(2);
    for i in 0..pv.len() {
        let j = (i + 1) % pv.len();
        let (hi, hj) = (heights[i], heights[j]);
        if hi.abs() <= eps {
            points.push(pv[i] - n * hi);
        } else if hj.abs() > eps && (hi < 0.0) != (hj < 0.0) {
            let ((a, ha), (b, hb)) = if lexicographic(pv[i], pv[j]).is_lt() {
                ((pv[i], hi), (pv[j], hj))
            } else {
                ((pv[j], hj), (pv[i], hi))
            };
            let q = a + (b - a) * (ha / (ha - hb));
            points.push(q - n * n.dot(q - a + n * ha));
        }
    }
    match points[..] {
        [a, b] if a != b => Some((a, b)),
        _ => None,
    }
}

/// The bounding box of the points within `eps` of the plane through the box `[lo, hi]` (of
/// a polygon in that plane, unit normal `n`) that lie within `reach` of the box along the
/// plane. Along axis k a step t in the plane moves by at most |t| √(1 − n_k²), so an axis the
/// plane is square to is widened by `eps` alone.
fn slab_box(lo: DVec3, hi: DVec3, n: DVec3, reach: f64, eps: f64) -> (DVec3, DVec3) {
    // Steps in the plane within the widened box are at most its diagonal long.
    let span = lo.distance(hi) + 2.0 * 3f64.sqrt() * reach;
    let widen = DVec3::from_array(
        n.to_array().map(|c| (eps + span * (1.0 - c * c).max(0.0).sqrt()).min(reach + eps)),
    );
    (lo - widen, hi + widen)
}

/// An edge of a face standing on a surface: its two corners on the surface's plane, the
/// face's normal and the face's vertex mean.
type Edge = (DVec3, DVec3, DVec3, DVec3);

/// Closed loops of `edges` (matched by exact corner positions; faces of one solid share
/// them) around which every edge's face turns its lit side outwards: the outline of a solid
/// standing on the plane whose normal is `n`, not the walls of a room standing around its
/// floor. A corner that does not join exactly two edges ends its component: no loop.
///
/// An edge of two faces back to back (a sofa's seat and its arm, two boxes pressed side by
/// side) lies inside the outline of the two and is dropped, so that they stand on one
/// footprint: kept, it met the two boxes' other edges at corners of three, and the floor
/// under the sofa was meshed uncut. (A face given twice, once each way round, as some
/// models give their faces, is one face: its two copies share their centre.)
fn chain(edges: &[Edge], n: DVec3) -> Vec<Vec<DVec3>> {
    let pair_of = |a: DVec3, b: DVec3| {
        let (ka, kb) = (key(a), key(b));
        if ka < kb { (ka, kb) } else { (kb, ka) }
    };
    let mut face_normal = HashMap::default();
    let mut first_face = HashMap::default();
    let mut inside = std::collections::HashSet::new();
    for &(a, b, normal, centre) in edges {
        if key(a) == key(b) {
            continue;
        }
        let pair = pair_of(a, b);
        match first_face.get(&pair) {
            None => {
                face_normal.insert(pair, normal);
                first_face.insert(pair, (normal, centre));
            }
            Some(&(first, at)) if first.dot(normal) < 0.0 && key(at) != key(centre) => {
                inside.insert(pair);
            }
            // The same face again: it counts once.
            Some(_) => {}
        }
    }
    let mut next: HashMap<[u64; 3], Vec<DVec3>> = HashMap::default();
    let mut added = std::collections::HashSet::new();
    for &(a, b, _, _) in edges {
        let pair = pair_of(a, b);
        if key(a) == key(b) || inside.contains(&pair) || !added.insert(pair) {
            continue;
        }
        next.entry(key(a)).or_default().push(b);
        next.entry(key(b)).or_default().push(a);
    }
    let mut starts: Vec<DVec3> = edges.iter().map(|e| e.0).collect();
    let outwards = |lp: &[DVec3]| {
        let sign = area_signed(lp, n).signum();
        (0..lp.len()).all(|i| {
            let (a, b) = (lp[i], lp[(i + 1) % lp.len()]);
            let pair = if key(a) < key(b) { (key(a), key(b)) } else { (key(b), key(a)) };
            // Right of a counter-clockwise edge is out of the loop.
            face_normal.get(&pair).is_some_and(|f| f.dot((b - a).cross(n)) * sign > 0.0)
        })
    };
    starts.sort_by(|a, b| lexicographic(*a, *b));
    let mut seen = std::collections::HashSet::new();
    let mut loops = Vec::new();
    for start in starts {
        if seen.contains(&key(start)) {
            continue;
        }
        let mut lp = vec![start];
        seen.insert(key(start));
        let (mut prev, mut at) = (start, start);
        let closed = loop {
            let Some(ns) = next.get(&key(at)).filter(|ns| ns.len() == 2) else { break false };
            let step = if key(ns[0]) != key(prev) || lp.len() == 1 { ns[0] } else { ns[1] };
            if key(step) == key(start) {
                break lp.len() >= 3;
            }
            if !seen.insert(key(step)) {
                break false;
            }
            lp.push(step);
            (prev, at) = (at, step);
        };
        if closed && outwards(&lp) {
            loops.push(lp);
        }
    }
    loops
}

/// `lp` without collinear corners, counter-clockwise about `n`, from its lowest corner; `None`
/// unless convex with an area.
fn convex_loop(lp: Vec<DVec3>, n: DVec3) -> Option<Vec<DVec3>> {
    let scale = lp.iter().map(|p| p.distance(lp[0])).fold(0.0, f64::max);
    let k = lp.len();
    let turn = |i: usize| {
        let (a, b, c) = (lp[(i + k - 1) % k], lp[i], lp[(i + 1) % k]);
        (b - a).cross(c - b).dot(n)
    };
    let tiny = 1e-9 * scale * scale;
    let mut corners: Vec<DVec3> = (0..k).filter(|&i| turn(i).abs() > tiny).map(|i| lp[i]).collect();
    if corners.len() < 3 {
        return None;
    }
    if area_signed(&corners, n) < 0.0 {
        corners.reverse();
    }
    let k = corners.len();
    let convex = (0..k).all(|i| {
        let (a, b, c) = (corners[(i + k - 1) % k], corners[i], corners[(i + 1) % k]);
        (b - a).cross(c - b).dot(n) > tiny
    });
    if !convex {
        return None;
    }
    let first = (0..k).min_by(|&i, &j| lexicographic(corners[i], corners[j]))?;
    corners.rotate_left(first);
    Some(corners)
}

pub(crate) mod seams;

#[cfg(test)]
mod tests;
