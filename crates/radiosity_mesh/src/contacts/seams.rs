//! Seams: the lines along which other faces meet a surface across most of it, and the
//! surface cut along them before it is meshed.
//!
//! A skirting board's top meets the wall along the wall's whole length, a wall stands across
//! a floor that runs on under it into a bay, a cupboard's plinth goes 1 mm into the floor: on
//! one side of such a line the surface is lit, on the other it lies in a gap a few millimetres
//! wide that light hardly enters. An element across the line takes the average of the two
//! and shoots it into the gap from a few millimetres away, where the form factor to the
//! board's back is close to one: the living room's skirting backs came out 30 times too
//! bright. Cut along the line (a value discontinuity, D0, of discontinuity meshing: Heckbert
//! 1992; Lischinski, Tampieri & Greenberg 1992), the elements in the gap receive only what
//! reaches them.
//!
//! Closed convex footprints are cut out by [`Contacts::cut`]; a seam is any face meeting the
//! plane, closed or not, whose lines together cover at least [`MIN_COVER`] of the surface's
//! chord along that line. Short contacts (a chair leg's side) do not cut the whole surface:
//! their light is left to the grading near inside corners and adaptive subdivision.

use glam::DVec3;

use super::{Contacts, PolygonId, slab_box};
use crate::planar::{area, bounds, clean, clip};
use radiosity_core::Polygon;

/// Most seams cutting one surface, the longest first: each doubles at most the pieces.
const MAX_SEAMS: usize = 8;

/// Least share of a surface's chord along a line that faces must meet for the line to cut.
const MIN_COVER: f64 = 0.5;

/// A face meets the surface when its lowest point lies within this fraction of the
/// surface's bounding-box diagonal of the plane (or below it): models put a skirting's top
/// 0.1–1 mm off the wall, more than the 1e-4 planarity tolerance of a 5 m wall.
const REACH: f64 = 1e-3;

/// Faces whose normal is within this cosine of the surface's lie flat over it: they meet it
/// in an area or not at all, never along a line.
const FLAT_COS: f64 = 0.95;

/// Most faces' lines gathered for one surface; past it the surface is not seamed (a floor
/// under a scanned model's hundred thousand facets would cost their product).
const MAX_SEGMENTS: usize = 20_000;

/// A line on a surface's plane: a point of it and its unit direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Seam {
    pub(crate) at: DVec3,
    pub(crate) dir: DVec3,
}

impl Seam {
    /// Signed distance of `x` from the line, within the plane of unit normal `n`.
    fn side(&self, n: DVec3, x: DVec3) -> f64 {
        n.cross(self.dir).dot(x - self.at)
    }
}

/// The interval of the line `at + t·dir` inside convex `poly` (on the plane of unit normal
/// `n`), if the line crosses it.
fn chord(poly: &[DVec3], n: DVec3, seam: &Seam) -> Option<(f64, f64)> {
    let mut range: Option<(f64, f64)> = None;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        let (sa, sb) = (seam.side(n, a), seam.side(n, b));
        if (sa > 0.0) == (sb > 0.0) && sa != 0.0 && sb != 0.0 {
            continue;
        }
        let x = if sa == sb { a } else { a + (b - a) * (sa / (sa - sb)) };
        let t = seam.dir.dot(x - seam.at);
        range = Some(range.map_or((t, t), |(lo, hi)| (lo.min(t), hi.max(t))));
    }
    range.filter(|(lo, hi)| hi > lo)
}

/// The total length of the union of `intervals`.
fn union_length(mut intervals: Vec<(f64, f64)>) -> f64 {
    intervals.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut total = 0.0;
    let mut current: Option<(f64, f64)> = None;
    for (lo, hi) in intervals {
        current = match current {
            Some((clo, chi)) if lo <= chi => Some((clo, chi.max(hi))),
            Some((clo, chi)) => {
                total += chi - clo;
                Some((lo, hi))
            }
            None => Some((lo, hi)),
        };
    }
    total + current.map_or(0.0, |(lo, hi)| hi - lo)
}

/// The length of the intersection of two interval unions.
fn overlap(a: &[(f64, f64)], b: &[(f64, f64)]) -> f64 {
    let pairs = a.iter().flat_map(|&(alo, ahi)| {
        b.iter().filter_map(move |&(blo, bhi)| {
            let (lo, hi) = (alo.max(blo), ahi.min(bhi));
            (hi > lo).then_some((lo, hi))
        })
    });
    union_length(pairs.collect())
}

impl Contacts<'_> {
    /// The seams of the surface covering the convex polygons `region` (corners on one plane
    /// of unit normal `n`; the surface's own polygon is `id` when it is one), longest first,
    /// at most [`MAX_SEAMS`].
    /// With `both_sides` (a two-sided surface), faces meeting its back cut it too.
    pub(crate) fn seams<P: AsRef<[DVec3]>>(
        &self,
        region: &[P],
        n: DVec3,
        id: Option<PolygonId>,
        both_sides: bool,
    ) -> Vec<Seam> {
        self.lines_across(region, n, id, both_sides, false)
    }

    /// A small face `target` (too small to look for what stands on it, see
    /// `builder::is_large`) cut where other faces pass through it: a door handle's stem
    /// through the door, one part of a model sunk into another. The part beyond the other
    /// face lies in other light: as one element with the rest, a handle's stem took the lit
    /// side's light and gave it to the dark side (Bitterli's Veach Ajar: the handles in the
    /// dark room took direct light that cannot reach them, 65–118 % too bright). Faces that
    /// only touch it (its neighbours, what stands on it) leave a small face whole: cut
    /// along them, a model's facets fragment. `None` when nothing passes through it.
    pub(crate) fn small_face_cut(
        &self,
        target: &Polygon,
        id: Option<PolygonId>,
        both_sides: bool,
    ) -> Option<Vec<Polygon>> {
        let n = target.normal();
        let seams = self.lines_across(std::slice::from_ref(&target.vertices()), n, id, both_sides, true);
        let tiny = 1e-9 * target.area();
        let pieces = cut_along(target, &seams, n, tiny);
        if pieces.len() < 2 {
            return None;
        }
        as_polygons(pieces, target, n, tiny)
    }

    /// The lines along which other faces meet the plane of `region` (see [`Self::seams`]);
    /// for a `small` face only faces passing through it count, and a line divides it when a
    /// tenth of the seams' reach lies on each side (a part poking a millimetre through: the
    /// reach is a thousandth of the face's diagonal).
    fn lines_across<P: AsRef<[DVec3]>>(
        &self,
        region: &[P],
        n: DVec3,
        id: Option<PolygonId>,
        both_sides: bool,
        small: bool,
    ) -> Vec<Seam> {
        let Some(first) = region.first().and_then(|p| p.as_ref().first().copied()) else {
            return Vec::new();
        };
        let all: Vec<DVec3> = region.iter().flat_map(|p| p.as_ref().iter().copied()).collect();
        let (lo, hi) = bounds(&all);
        let diagonal = lo.distance(hi);
        let eps = REACH * diagonal;
        let d = n.dot(first);
        let (qlo, qhi) = slab_box(lo, hi, n, 0.0, eps);
        // Each face meeting the plane gives the segment where it crosses the level of its
        // lowest point (or the plane, for a face reaching through it), moved onto the plane.
        let mut segments: Vec<(DVec3, DVec3)> = Vec::new();
        for &(other, p, _, _) in self.near(qlo, qhi, 0.0) {
            if Some(other) == id || p.normal().dot(n).abs() > FLAT_COS {
                continue;
            }
            let pv = p.vertices();
            // Faces meeting the back of a two-sided surface cut it too: they shape the light
            // its back face takes, which shares its elements.
            for side in if both_sides { [1.0, -1.0].as_slice() } else { [1.0].as_slice() } {
                let heights: Vec<f64> = pv.iter().map(|&q| side * (n.dot(q) - d)).collect();
                let low = heights.iter().copied().fold(f64::INFINITY, f64::min);
                let high = heights.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                if low > eps || high <= 0.1 * eps {
                    continue; // above the surface, or not rising off it on this side
                }
                if small && low >= -eps {
                    continue; // touching a small face, not passing through it
                }
                let level = low.max(0.0) + 1e-7 * diagonal;
                let mut ends = Vec::with_capacity(2);
                for i in 0..pv.len() {
                    let j = (i + 1) % pv.len();
                    let (hi_, hj) = (heights[i] - level, heights[j] - level);
                    if (hi_ >= 0.0) != (hj >= 0.0) {
                        let x = pv[i] + (pv[j] - pv[i]) * (hi_ / (hi_ - hj));
                        ends.push(x - n * (n.dot(x) - d));
                    }
                }
                if let [a, b] = ends[..]
                    && a.distance(b) > 1e-6 * diagonal
                {
                    segments.push((a, b));
                    if segments.len() > MAX_SEGMENTS {
                        return Vec::new();
                    }
                }
            }
        }
        // Segments on one line (within `eps` of it at both ends, directions within 1e-4 rad)
        // gathered, in a fixed order.
        segments.sort_by(|x, y| {
            crate::planar::lexicographic(x.0, y.0).then(crate::planar::lexicographic(x.1, y.1))
        });
        let mut lines: Vec<(Seam, Vec<(f64, f64)>)> = Vec::new();
        for (a, b) in segments {
            let dir = (b - a).normalize();
            let found = lines.iter_mut().find(|(s, _)| {
                s.dir.dot(dir).abs() > 1.0 - 5e-9 && s.side(n, a).abs() <= eps && s.side(n, b).abs() <= eps
            });
            match found {
                Some((s, spans)) => {
                    let (ta, tb) = (s.dir.dot(a - s.at), s.dir.dot(b - s.at));
                    spans.push((ta.min(tb), ta.max(tb)));
                }
                None => {
                    // The direction's sign fixed (its largest component positive), so a line
                    // is the same whichever way its first segment ran.
                    let big = dir.abs().max_element();
                    let sign = if dir.to_array().iter().find(|c| c.abs() == big).is_some_and(|&c| c < 0.0) {
                        -1.0
                    } else {
                        1.0
                    };
                    let s = Seam { at: a, dir: dir * sign };
                    let (ta, tb) = (0.0_f64, s.dir.dot(b - a));
                    lines.push((s, vec![(ta.min(tb), ta.max(tb))]));
                }
            }
        }
        let mut kept: Vec<(f64, Seam)> = lines
            .into_iter()
            .filter_map(|(s, spans)| {
                let chords: Vec<(f64, f64)> =
                    region.iter().filter_map(|p| chord(p.as_ref(), n, &s)).collect();
                let across = union_length(chords.clone());
                let met = overlap(&spans, &chords);
                // A line along the surface's outline divides nothing.
                let sides = all.iter().map(|&q| s.side(n, q));
                let (below, above) = sides.fold((0.0_f64, 0.0_f64), |(b, a), v| (b.min(v), a.max(v)));
                let beyond = if small { 0.1 * eps } else { eps };
                let divides = below < -beyond && above > beyond;
                (divides && across > 0.0 && met >= MIN_COVER * across).then_some((met, s))
            })
            .collect();
        kept.sort_by(|a, b| b.0.total_cmp(&a.0));
        kept.truncate(MAX_SEAMS);
        kept.into_iter().map(|(_, s)| s).collect()
    }
}

/// The corners of the convex pieces of `target` (facing unit `n`) cut along `seams` (see
/// [`cut_pieces`]).
pub(crate) fn cut_along(target: &Polygon, seams: &[Seam], n: DVec3, tiny: f64) -> Vec<Vec<DVec3>> {
    let mut pieces = vec![target.vertices().to_vec()];
    for seam in seams {
        pieces = cut_pieces(pieces, seam, n, tiny);
    }
    pieces
}

/// `pieces` of `target` (facing unit `n`) as polygons, those of at most `tiny` area left out;
/// `None` when the validation refuses one (a sliver of round-off: the caller keeps `target`
/// whole).
pub(crate) fn as_polygons(
    pieces: Vec<Vec<DVec3>>,
    target: &Polygon,
    n: DVec3,
    tiny: f64,
) -> Option<Vec<Polygon>> {
    pieces
        .into_iter()
        .filter(|p| area(p, n) > tiny)
        .map(|p| Polygon::try_new(clean(p, target)).ok())
        .collect()
}

/// Convex `pieces` (on the plane of unit normal `n`) cut along `seam`: a piece with more
/// than `tiny` area on both sides becomes two.
pub(crate) fn cut_pieces(pieces: Vec<Vec<DVec3>>, seam: &Seam, n: DVec3, tiny: f64) -> Vec<Vec<DVec3>> {
    let mut out = Vec::with_capacity(pieces.len() + 1);
    for piece in pieces {
        let left = clip(&piece, |x| seam.side(n, x));
        let right = clip(&piece, |x| -seam.side(n, x));
        if area(&left, n) > tiny && area(&right, n) > tiny {
            out.push(left);
            out.push(right);
        } else {
            out.push(piece);
        }
    }
    out
}

/// Triangles (counter-clockwise about unit normal `n`) cut along `seams`, each cut triangle
/// into three (a triangle and a quad split by its diagonal), or two where the line passes
/// through a corner. A shared edge is cut at the
/// same point from both sides (its ends taken in a fixed order), so the triangles still meet
/// corner to corner.
pub(crate) fn cut_triangles(mut triangles: Vec<[DVec3; 3]>, seams: &[Seam], n: DVec3) -> Vec<[DVec3; 3]> {
    let Some(first) = triangles.first().map(|t| t[0]) else {
        return triangles;
    };
    let (lo, hi) = triangles.iter().flatten().fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    // A corner this near the line counts as on it, the same for every triangle that has
    // it: a cut would leave a sliver thinner than the seams' own tolerance.
    let on = 1e-4 * lo.distance(hi).max(f64::MIN_POSITIVE);
    for seam in seams {
        let mut out = Vec::with_capacity(triangles.len() + 8);
        for t in triangles {
            let s = t.map(|p| seam.side(n, p));
            let sign = s.map(|v| {
                if v > on {
                    1
                } else if v < -on {
                    -1
                } else {
                    0
                }
            });
            // The corner alone on its side, with the other two strictly on the other.
            let lone = (0..3)
                .find(|&k| sign[k] != 0 && sign[(k + 1) % 3] == -sign[k] && sign[(k + 2) % 3] == -sign[k]);
            if let Some(k) = lone {
                let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                let ab = crossing(a, b, seam, n);
                let ca = crossing(c, a, seam, n);
                out.extend([[a, ab, ca], [ab, b, c], [ab, c, ca]]);
                continue;
            }
            // A corner on the line, the other two on either side: two triangles.
            let through = (0..3).find(|&k| sign[k] == 0 && sign[(k + 1) % 3] * sign[(k + 2) % 3] == -1);
            if let Some(k) = through {
                let (a, b, c) = (t[k], t[(k + 1) % 3], t[(k + 2) % 3]);
                let bc = crossing(b, c, seam, n);
                out.extend([[a, b, bc], [a, bc, c]]);
                continue;
            }
            out.push(t);
        }
        triangles = out;
    }
    triangles
}

/// Where edge `a`–`b` crosses `seam`, computed from its ends in lexicographic order so that
/// both triangles sharing the edge get the same point bit for bit.
fn crossing(a: DVec3, b: DVec3, seam: &Seam, n: DVec3) -> DVec3 {
    let (p, q) = if crate::planar::lexicographic(a, b).is_le() { (a, b) } else { (b, a) };
    let (sp, sq) = (seam.side(n, p), seam.side(n, q));
    p + (q - p) * (sp / (sp - sq))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_triangle_cut_by_a_line_keeps_its_area_and_its_shared_edge_points() {
        let n = DVec3::Z;
        let seam = Seam { at: DVec3::new(0.0, 0.3, 0.0), dir: DVec3::X };
        // Two triangles sharing the edge (1,0)–(0,1), listed in opposite directions.
        let a = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let b = [DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        let cut = cut_triangles(vec![a, b], &[seam], n);
        assert_eq!(cut.len(), 6);
        let total: f64 = cut.iter().map(|t| (t[1] - t[0]).cross(t[2] - t[0]).dot(n) * 0.5).sum();
        assert!((total - 1.0).abs() < 1e-12, "{total}");
        assert!(cut.iter().all(|t| (t[1] - t[0]).cross(t[2] - t[0]).dot(n) > 0.0));
        // No triangle straddles the line.
        for t in &cut {
            let s = t.map(|p| seam.side(n, p));
            assert!(!(s.iter().any(|&v| v > 1e-12) && s.iter().any(|&v| v < -1e-12)), "{t:?}");
        }
        // The crossing on the shared edge is one point, from either triangle.
        let on_edge: Vec<DVec3> = cut
            .iter()
            .flatten()
            .copied()
            .filter(|p| (p.x + p.y - 1.0).abs() < 1e-12 && (p.y - 0.3).abs() < 1e-12)
            .collect();
        assert!(on_edge.len() >= 2 && on_edge.iter().all(|p| p.to_array() == on_edge[0].to_array()));
    }

    #[test]
    fn a_convex_piece_is_cut_only_where_both_sides_have_area() {
        let n = DVec3::Y;
        let square = vec![DVec3::ZERO, DVec3::Z, DVec3::new(1.0, 0.0, 1.0), DVec3::X];
        let inside = Seam { at: DVec3::new(0.0, 0.0, 0.25), dir: DVec3::X };
        let pieces = cut_pieces(vec![square.clone()], &inside, n, 1e-9);
        assert_eq!(pieces.len(), 2);
        let areas: Vec<f64> = pieces.iter().map(|p| area(p, n)).collect();
        assert!((areas.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert!(areas.iter().any(|a| (a - 0.25).abs() < 1e-12));
        let edge = Seam { at: DVec3::ZERO, dir: DVec3::X };
        assert_eq!(cut_pieces(vec![square], &edge, n, 1e-9).len(), 1);
    }
}
