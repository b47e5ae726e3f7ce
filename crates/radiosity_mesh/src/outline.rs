//! A coplanar group of a model's triangles as the region it covers: its outline, with the
//! points that lie on a straight run of it dropped, triangulated afresh.
//!
//! An exporter's triangulation is not a property of the surface: a wall written as 2
//! triangles, as 32 (a CAD tessellation, a subdivided quad) or as a fan of slivers around a
//! window is the same wall and should give the same patches and elements. So the group's
//! outline (its boundary edges, chained into loops) is taken with every corner that lies on
//! the straight line between its neighbours left out, which gives back the outline the
//! surface had before it was cut, and that outline alone decides the meshing: a convex
//! outline is meshed as one polygon (a quad as a quad lattice, as a face of four corners would
//! be), any other as an ear-clipping triangulation of it (holes included) whose triangles are
//! cut by bisection (`model_faces::mesh_triangle_group`).
//!
//! Where the outline is not a plain set of loops (an edge run twice the same way, a corner
//! where the region touches itself), or the triangulation does not cover the group's area,
//! the group's own triangles are used instead: nothing is lost, only the merging.

// Fx hashing: the mesher's maps hold millions of small integer keys (a vertex's bits, an
// edge's two indices), where SipHash was a third of the meshing time of a 834 k-triangle
// model; nothing here is keyed by untrusted input an attacker could collide.
use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use glam::{DVec2, DVec3};
use radiosity_core::{Polygon, PolygonMesh};

/// Most outline corners triangulated afresh: ear clipping is quadratic in the corners in its
/// worst case, and an outline longer than this (a terrain's border) keeps its own triangles.
const MAX_OUTLINE_CORNERS: usize = 4096;

/// A corner is on a straight run of the outline when it lies off the line through its two
/// neighbours by less than this fraction of their distance: the rounding of a point
/// interpolated between them, not a real bend.
const STRAIGHT: f64 = 1e-9;

/// How a coplanar group of triangles is to be meshed.
#[derive(Debug)]
pub(crate) enum Outline {
    /// The outline is one convex polygon of four corners or more: mesh it as that polygon.
    Convex(Polygon),
    /// Triangles covering the group (corners counter-clockwise about its normal), fewer
    /// than or as many as its own.
    Triangles(Vec<[DVec3; 3]>),
}

/// The outline of the coplanar, consistently wound triangles `group` of `m`, or `None` where
/// it is not a plain set of loops or cannot be triangulated (see the module's notes).
pub(crate) fn outline(m: &PolygonMesh, group: &[u32]) -> Option<Outline> {
    let faces = m.faces();
    let pos = m.positions();
    // Directed edges of the group; an inside edge is run once each way, an outline edge once.
    let mut directed: HashMap<(u32, u32), u32> = HashMap::default();
    for &f in group {
        let t = &faces[f as usize];
        for k in 0..3 {
            *directed.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
        }
    }
    let mut next: HashMap<u32, u32> = HashMap::default();
    for (&(a, b), &count) in &directed {
        if count > 1 {
            return None;
        }
        if directed.contains_key(&(b, a)) {
            continue;
        }
        // Two outline edges leaving one corner: the region touches itself there.
        if next.insert(a, b).is_some() {
            return None;
        }
    }
    // Loops, each started from its lowest index so the result does not depend on hash order.
    let mut starts: Vec<u32> = next.keys().copied().collect();
    starts.sort_unstable();
    let mut seen: HashSet<u32> = HashSet::default();
    let mut loops: Vec<Vec<DVec3>> = Vec::new();
    for s in starts {
        if seen.contains(&s) {
            continue;
        }
        let mut ring = Vec::new();
        let mut v = s;
        loop {
            if !seen.insert(v) {
                return None;
            }
            ring.push(pos[v as usize]);
            v = *next.get(&v)?;
            if v == s {
                break;
            }
        }
        let ring = straightened(ring);
        if ring.len() < 3 {
            return None;
        }
        loops.push(ring);
    }
    let corners: usize = loops.iter().map(Vec::len).sum();
    if loops.is_empty() || corners > MAX_OUTLINE_CORNERS {
        return None;
    }
    let normal = m.polygons()[group[0] as usize].normal();
    let area: f64 = group.iter().map(|&f| m.polygons()[f as usize].area()).sum();
    if let [ring] = &loops[..]
        && ring.len() >= 4
        && let Ok(p) = Polygon::try_new(ring.clone())
        && p.normal().dot(normal) > 0.0
        && (p.area() - area).abs() <= 1e-9 * area.max(f64::MIN_POSITIVE)
    {
        return Some(Outline::Convex(p));
    }
    triangulate(&loops, normal, area).map(Outline::Triangles)
}

/// `ring` without the corners that lie on the straight line between their neighbours,
/// dropped until none is left.
fn straightened(mut ring: Vec<DVec3>) -> Vec<DVec3> {
    loop {
        let n = ring.len();
        if n < 4 {
            return ring;
        }
        let straight = |k: usize| {
            let (a, b, c) = (ring[(k + n - 1) % n], ring[k], ring[(k + 1) % n]);
            let span = c - a;
            let len2 = span.length_squared();
            // Off the line by |(b − a) × span| / |span|, against STRAIGHT · |span|; and
            // between a and c, so that a spike doubling back is kept.
            len2 > 0.0
                && (b - a).cross(span).length_squared() <= STRAIGHT * STRAIGHT * len2 * len2
                && (b - a).dot(span) > 0.0
                && (c - b).dot(span) > 0.0
        };
        let keep: Vec<bool> = (0..n).map(|k| !straight(k)).collect();
        if keep.iter().all(|&k| k) {
            return ring;
        }
        // Drop every other straight corner per pass at most, so that a neighbour a dropped
        // corner was measured against is still there when it is dropped.
        let mut dropped_last = false;
        let mut out = Vec::with_capacity(n);
        for (k, &p) in ring.iter().enumerate() {
            // The last corner's next neighbour is the first: not both in one pass.
            let wraps = k == n - 1 && !keep[0];
            if !keep[k] && !dropped_last && !wraps {
                dropped_last = true;
            } else {
                out.push(p);
                dropped_last = false;
            }
        }
        ring = out;
    }
}

/// Ear-clipping triangulation of the outer loop and holes `loops` (3-D corners in a plane of
/// normal `normal`), the triangles counter-clockwise about it; `None` unless they cover
/// `area` (within rounding) with no inverted triangle.
fn triangulate(loops: &[Vec<DVec3>], normal: DVec3, area: f64) -> Option<Vec<[DVec3; 3]>> {
    let (u, v) = normal.any_orthonormal_pair();
    let origin = loops[0][0];
    let flat = |p: DVec3| DVec2::new((p - origin).dot(u), (p - origin).dot(v));
    let signed_area = |ring: &[DVec3]| {
        let n = ring.len();
        (0..n).map(|k| flat(ring[k]).perp_dot(flat(ring[(k + 1) % n]))).sum::<f64>() * 0.5
    };
    // One outer loop (counter-clockwise about the normal), the others holes (clockwise).
    let outer: Vec<usize> = (0..loops.len()).filter(|&k| signed_area(&loops[k]) > 0.0).collect();
    let [outer] = outer[..] else {
        return None;
    };
    let order = std::iter::once(outer).chain((0..loops.len()).filter(|&k| k != outer));
    let mut corners: Vec<DVec3> = Vec::new();
    let mut holes = Vec::new();
    for k in order {
        if !corners.is_empty() {
            holes.push(corners.len());
        }
        corners.extend(&loops[k]);
    }
    let coords: Vec<f64> = corners.iter().flat_map(|&p| flat(p).to_array()).collect();
    let indices = earcutr::earcut(&coords, &holes, 2).ok()?;
    let mut triangles = Vec::with_capacity(indices.len() / 3);
    let mut covered = 0.0;
    for t in indices.chunks_exact(3) {
        let [a, b, c] = [t[0], t[1], t[2]].map(|i| corners[i]);
        let twice = (b - a).cross(c - a).dot(normal);
        if twice > 0.0 {
            triangles.push([a, b, c]);
        } else if twice < 0.0 {
            triangles.push([a, c, b]);
        } else {
            continue;
        }
        covered += twice.abs() * 0.5;
    }
    ((covered - area).abs() <= 1e-7 * area && !triangles.is_empty()).then_some(triangles)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_on_a_straight_run_are_dropped_and_bends_kept() {
        let ring = [(0.0, 0.0), (0.5, 0.0), (1.0, 0.0), (1.0, 1.0), (0.25, 1.0), (0.0, 1.0), (0.0, 0.5)]
            .map(|(x, y)| DVec3::new(x, y, 0.0))
            .to_vec();
        let out = straightened(ring);
        assert_eq!(out.len(), 4);
        // A spike that doubles back on itself is not a straight run.
        let spike =
            [(0.0, 0.0), (2.0, 0.0), (1.0, 0.0), (1.0, 1.0)].map(|(x, y)| DVec3::new(x, y, 0.0)).to_vec();
        assert_eq!(straightened(spike).len(), 4);
    }
}
