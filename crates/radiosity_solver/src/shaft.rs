//! Shaft culling (Haines & Wallace 1991, "Shaft culling for efficient ray-cast radiosity"):
//! before the rays between a shooting patch and a receiving patch are traced, find the few
//! blocking triangles that can meet any segment between the two. Most pairs in a room have
//! none (no ray at all); the rest usually have a handful, which a ray tests one by one far
//! faster than it walks a tree.
//!
//! The shaft here is the bounding box of both patches (grown by the ray offsets) cut by the
//! two patch planes: every segment from a point of one patch to a point of the other lies in
//! the convex hull of both, so a triangle outside that box, or wholly behind the far side of
//! either plane, cannot block it. The test is conservative — a kept triangle may miss every
//! ray — so the answer of a ray is the same as the full query's.

use glam::{DVec3, Vec3};
use radiosity_accel::{CandidateTriangles, Segments4};
use radiosity_mesh::Mesh;

/// Above this many blocking triangles the per-patch scan costs more than it saves; every
/// pair then goes to the caller's ray structure.
const SCAN_LIMIT: usize = 512;

/// Triangles per cluster box.
const CLUSTER: usize = 16;

/// Candidate lists longer than this go to the caller's ray structure instead.
pub(crate) const FEW: usize = 48;

/// Most side planes of a shaft.
const MAX_PLANES: usize = 24;

/// How the rays between one shooter and one receiving patch are answered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Visibility {
    /// No blocking triangle meets the shaft: every pair is fully visible, no ray is traced.
    Clear,
    /// A few triangles meet it: rays test those only.
    Few,
    /// Too many to list: rays go to the full ray structure.
    Tree,
}

/// Two convex polygons with their plane normals, whose segments' ends are lifted off the
/// planes by at most `offset`.
#[derive(Clone, Copy)]
pub(crate) struct Pair<'a> {
    pub(crate) a: &'a [DVec3],
    pub(crate) na: DVec3,
    pub(crate) b: &'a [DVec3],
    pub(crate) nb: DVec3,
    pub(crate) offset: f64,
}

/// The blocking triangles of a mesh with their bounding boxes, for shaft tests.
pub(crate) struct Blockers {
    boxes: Vec<(DVec3, DVec3)>,
    /// Runs of `CLUSTER` consecutive triangles (neighbours, as meshes come) with the box
    /// around each run: a shaft that misses the run's box skips all its triangles.
    clusters: Vec<(DVec3, DVec3)>,
    /// The triangles for the candidate-list tests.
    triangles: CandidateTriangles,
    /// Absolute slack for the single-precision rounding of ray ends and triangles.
    slack: f64,
    /// Some triangles are alpha-masked: the candidate lists' tests know no masks, so every
    /// pair goes to the ray structure, which does.
    masked: bool,
}

impl Blockers {
    /// Blockers over `tris` (the mesh's blocking triangles) in single precision.
    pub(crate) fn new(mesh: &Mesh, tris: &[[DVec3; 3]]) -> Self {
        let tris: Vec<[Vec3; 3]> = tris.iter().map(|t| t.map(|p| p.as_vec3())).collect();
        let (lo, hi) = mesh.bounds();
        let scale = lo.abs().max(hi.abs()).max_element().max(f64::MIN_POSITIVE);
        Self { masked: !mesh.masked_occluders.is_empty(), ..Self::from_triangles(&tris, 1e-6 * scale) }
    }

    /// Blockers over single-precision triangles, with `slack` for their rounding.
    pub(crate) fn from_triangles(tris: &[[Vec3; 3]], slack: f64) -> Self {
        // Boxes of the single-precision triangles the rays are really tested against.
        let boxes: Vec<(DVec3, DVec3)> = tris
            .iter()
            .map(|t| {
                let (a, b, c) = (t[0].as_dvec3(), t[1].as_dvec3(), t[2].as_dvec3());
                (a.min(b).min(c), a.max(b).max(c))
            })
            .collect();
        let clusters = boxes
            .chunks(CLUSTER)
            .map(|c| c.iter().fold(c[0], |(lo, hi), (a, b)| (lo.min(*a), hi.max(*b))))
            .collect();
        Self { boxes, clusters, triangles: CandidateTriangles::new(tris), slack, masked: false }
    }

    /// True when the per-patch scan is affordable.
    pub(crate) fn scannable(&self) -> bool {
        !self.masked && self.boxes.len() <= SCAN_LIMIT
    }

    /// Gathers into `out` the triangles that may block a segment between polygon `a` (plane
    /// normal `na`) and polygon `b` (normal `nb`), whose ends are lifted off their planes by
    /// at most `offset`. Besides the box and the two polygon planes, the side planes of the
    /// convex hull of both polygons are tried (the shaft of Haines & Wallace).
    pub(crate) fn gather(&self, pair: Pair, out: &mut Vec<u32>) -> Visibility {
        let Pair { a, na, b, nb, offset } = pair;
        out.clear();
        if !self.scannable() {
            return Visibility::Tree;
        }
        let margin = 2.0 * offset + self.slack;
        let (lo, hi) = bounds(a.iter().chain(b));
        let (lo, hi) = (lo - DVec3::splat(margin), hi + DVec3::splat(margin));
        let base = base_planes(a, na, b, nb, margin);
        // Box and base planes first; the side planes cost more and matter only when
        // something is left.
        let meets = |(tlo, thi): &(DVec3, DVec3)| {
            tlo.cmple(hi).all() && lo.cmple(*thi).all() && !outside(tlo, thi, &base)
        };
        for (c, cluster) in self.clusters.iter().enumerate() {
            if !meets(cluster) {
                continue;
            }
            let first = c * CLUSTER;
            for (i, b) in self.boxes[first..(first + CLUSTER).min(self.boxes.len())].iter().enumerate() {
                if meets(b) {
                    out.push((first + i) as u32);
                }
            }
        }
        if !out.is_empty() {
            let mut planes = [(DVec3::ZERO, 0.0); MAX_PLANES];
            let count = hull_planes(a, b, margin, &mut planes);
            out.retain(|&i| !self.outside(i as usize, &planes[..count]));
        }
        match out.len() {
            0 => Visibility::Clear,
            n if n <= FEW => Visibility::Few,
            _ => {
                out.clear();
                Visibility::Tree
            }
        }
    }

    /// True when triangle `i` lies wholly outside one of `planes` (each `(n, d)` keeps the
    /// points with `n·x ≥ d`).
    fn outside(&self, i: usize, planes: &[(DVec3, f64)]) -> bool {
        let (lo, hi) = &self.boxes[i];
        outside(lo, hi, planes)
    }

    /// The full query's answer for a segment that only the triangles at `indices` can meet.
    #[cfg(test)]
    pub(crate) fn occluded_by(&self, from: Vec3, to: Vec3, indices: &[u32]) -> bool {
        self.triangles.occluded_by(from, to, indices)
    }

    /// Which of up to four segments the triangles at `indices` block (bit `i` for segment
    /// `i`), the full query's answers; the first blocking triangle moves to the front of
    /// `indices`, so the next rays of the same element, which likely meet it too, test it
    /// first. The answer does not depend on the order.
    pub(crate) fn occluded_x4(&self, segments: &Segments4, indices: &mut [u32]) -> u32 {
        self.triangles.occluded_x4(segments, indices)
    }
}

/// True when the box `[lo, hi]` lies wholly outside one of `planes` (each `(n, d)` keeps the
/// points with `n·x ≥ d`): the box corner furthest along n bounds everything inside it.
fn outside(lo: &DVec3, hi: &DVec3, planes: &[(DVec3, f64)]) -> bool {
    planes.iter().any(|(n, d)| n.dot(DVec3::select(n.cmpge(DVec3::ZERO), *hi, *lo)) < *d)
}

/// Axis-aligned bounds of some points.
pub(crate) fn bounds<'a>(points: impl IntoIterator<Item = &'a DVec3>) -> (DVec3, DVec3) {
    points.into_iter().fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(a, b), p| {
        (a.min(*p), b.max(*p))
    })
}

/// The planes of the two polygons, as half-spaces `n·x ≥ d` holding the convex hull of both
/// (grown by `margin`): each polygon's own plane, lowered to the lowest point of the other.
fn base_planes(a: &[DVec3], na: DVec3, b: &[DVec3], nb: DVec3, margin: f64) -> [(DVec3, f64); 2] {
    let low = |n: DVec3, pts: &[DVec3], own: DVec3| pts.iter().map(|p| n.dot(*p)).fold(n.dot(own), f64::min);
    [(na, low(na, b, a[0]) - margin), (nb, low(nb, a, b[0]) - margin)]
}

/// Side planes of the convex hull of polygons `a` and `b`, as half-spaces `n·x ≥ d` grown by
/// `margin`: every plane through an edge of one polygon and a vertex of the other that has
/// all points of both on one side. Returns how many were written.
fn hull_planes(a: &[DVec3], b: &[DVec3], margin: f64, out: &mut [(DVec3, f64); MAX_PLANES]) -> usize {
    let mut count = 0;
    let (lo, hi) = bounds(a.iter().chain(b));
    let scale = hi - lo;
    let tolerance = 1e-9 * scale.length();
    for (edges, others) in [(a, b), (b, a)] {
        for i in 0..edges.len() {
            let (p, q) = (edges[i], edges[(i + 1) % edges.len()]);
            for v in others {
                let n = (q - p).cross(*v - p);
                let len = n.length();
                if len <= 1e-12 * scale.length_squared() {
                    continue;
                }
                let n = n / len;
                let d = n.dot(p);
                // Which sides the points fall on; most planes split them, and stop early.
                let (mut below, mut above) = (false, false);
                for x in a.iter().chain(b) {
                    let h = n.dot(*x) - d;
                    below |= h < -tolerance;
                    above |= h > tolerance;
                    if below && above {
                        break;
                    }
                }
                let plane = match (below, above) {
                    (false, _) => (n, d - margin),
                    (true, false) => (-n, -d - margin),
                    (true, true) => continue,
                };
                if count < MAX_PLANES {
                    out[count] = plane;
                    count += 1;
                }
            }
        }
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{Rng, point_on};
    use radiosity_accel::{BruteForce, RayQuery};

    fn quad(c: DVec3, u: DVec3, v: DVec3) -> Vec<DVec3> {
        vec![c - u - v, c + u - v, c + u + v, c - u + v]
    }

    /// Conservative: every triangle that blocks some segment between the two polygons is in
    /// the candidate list (or the pair goes to the tree), for random polygons and triangles.
    #[test]
    fn no_blocking_triangle_is_ever_left_out() {
        let mut rng = Rng::for_task(7, 0, 0);
        let mut r = move || rng.next_f64();
        let mut checked_blocked = 0;
        for case in 0..300 {
            let mut v = || DVec3::new(r() - 0.5, r() - 0.5, r() - 0.5);
            let tris: Vec<[Vec3; 3]> = (0..40)
                .map(|_| {
                    let c = v() * 2.0;
                    [c, c + v() * 0.6, c + v() * 0.6].map(|p| p.as_vec3())
                })
                .collect();
            let (ca, cb) = (v() * 2.0, v() * 2.0);
            let a = quad(ca, v() * 0.4, v() * 0.4);
            let b = quad(cb, v() * 0.4, v() * 0.4);
            let normal = |p: &[DVec3]| (p[1] - p[0]).cross(p[3] - p[0]).normalize();
            let (na, nb) = (normal(&a), normal(&b));
            let blockers = Blockers::from_triangles(&tris, 1e-6);
            let mut out = Vec::new();
            let vis = blockers.gather(Pair { a: &a, na, b: &b, nb, offset: 0.0 }, &mut out);
            if vis == Visibility::Tree {
                continue;
            }
            for s in 0..200 {
                let mut rng = Rng::for_task(case, s, 1);
                let p = point_on(&a, rng.next_f64(), rng.next_f64());
                let q = point_on(&b, rng.next_f64(), rng.next_f64());
                for (t, tri) in tris.iter().enumerate() {
                    if BruteForce::new(&[*tri]).occluded(p.as_vec3(), q.as_vec3()) {
                        checked_blocked += 1;
                        assert!(out.contains(&(t as u32)), "case {case}: triangle {t} blocks but was culled");
                    }
                }
                let all: Vec<u32> = (0..tris.len() as u32).collect();
                assert_eq!(
                    blockers.occluded_by(p.as_vec3(), q.as_vec3(), &out),
                    blockers.occluded_by(p.as_vec3(), q.as_vec3(), &all),
                    "case {case}"
                );
            }
        }
        assert!(checked_blocked > 1000, "only {checked_blocked} blocked segments were checked");
    }

    /// The shaft removes what the box alone keeps: a triangle beside the line between two
    /// small facing squares, inside their bounding box, is culled by a side plane.
    #[test]
    fn side_planes_cull_inside_the_box() {
        let a = quad(DVec3::ZERO, DVec3::X * 0.1, DVec3::Y * 0.1);
        let b = quad(DVec3::new(1.0, 1.0, 1.0), DVec3::X * 0.1, DVec3::Y * 0.1);
        let tri = [DVec3::new(0.9, 0.1, 0.5), DVec3::new(0.95, 0.1, 0.5), DVec3::new(0.9, 0.15, 0.55)];
        let blockers = Blockers::from_triangles(&[tri.map(|p| p.as_vec3())], 1e-9);
        let mut out = Vec::new();
        assert_eq!(
            blockers.gather(Pair { a: &a, na: DVec3::Z, b: &b, nb: -DVec3::Z, offset: 0.0 }, &mut out),
            Visibility::Clear
        );
        let on_line = [DVec3::splat(0.45), DVec3::new(0.55, 0.45, 0.5), DVec3::new(0.5, 0.55, 0.5)];
        let blockers = Blockers::from_triangles(&[on_line.map(|p| p.as_vec3())], 1e-9);
        assert_eq!(
            blockers.gather(Pair { a: &a, na: DVec3::Z, b: &b, nb: -DVec3::Z, offset: 0.0 }, &mut out),
            Visibility::Few
        );
    }
}
