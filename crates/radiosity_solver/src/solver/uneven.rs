//! Uneven shooters: a patch whose unshot radiosity is far from even over its elements (a
//! floor patch half under a block) is seen brighter or darker than its mean, depending on
//! which part of it a receiver sees. Receivers that touch such a shooter weight their form
//! factor by the density of the part they see; clusters of nearby shooter elements keep that
//! weighting cheap.

use glam::{DVec3, Vec4};

use super::elements::ShooterElement;
use crate::form_factor::{point_to_point, point_to_polygon_x4};
use crate::shaft::bounds;

/// A shooter with an element whose unshot density strays from the mean by more than this
/// share weights the form factors of the receivers that touch it or are near it (see
/// `receive`). The density is fixed with the shooter's row (see `first_shots`), so only
/// strong, lasting structure is trusted:
/// shadows and contact lines (a block standing on the patch: dark under it on every shot),
/// not the gentle gradients of indirect light, which change from shot to shot. Measured: at
/// 0.05 the ρ = 0.5 furnace's elements drift 2.4 % from E/(1 − ρ); at 0.5 they stay within
/// its 0.5 % test, and the Cornell box's coarse patches match 35 mm shooters to 0.8 % RMS.
pub(super) const NONUNIFORM: f64 = 0.5;

/// Up to [`CLUSTER`] nearby elements of an uneven shooter, so that a receiver needs to visit
/// the elements of only the clusters it is close to (see [`density_weight`]).
#[derive(Clone, Debug)]
pub(super) struct Cluster {
    /// Its elements, as a range of the order [`cluster_elements`] fills.
    pub(super) members: std::ops::Range<usize>,
    /// Area-weighted centre of its elements.
    pub(super) centre: DVec3,
    /// Radius about `centre` that holds all its elements.
    pub(super) radius: f64,
    /// Its elements' area.
    pub(super) area: f64,
    /// Area-weighted mean density of its elements.
    density: f64,
    /// Its elements four at a time (see [`Lanes`]).
    lanes: Vec<Lanes>,
}

/// Four elements of a [`Cluster`] side by side, about the cluster's centre, in single
/// precision: [`density_weight`] takes their point-to-point terms four at a time (one by
/// one, they were a tenth of a furnished room's solve).
#[derive(Clone, Debug)]
struct Lanes {
    x: Vec4,
    y: Vec4,
    z: Vec4,
    /// Each element's area; 0 in lanes past `count`.
    area: Vec4,
    density: Vec4,
    /// (4 radii)²: nearer than that, the element's exact polygon formula is taken.
    exact_within: Vec4,
    /// The elements (indices into the shooter's).
    members: [u32; 4],
    count: usize,
}

/// Most elements in one [`Cluster`].
const CLUSTER: usize = 16;

/// How an uneven shooter's unshot radiosity is spread over its elements: its clusters,
/// each with its elements' densities (unshot radiosity over the shooter's mean).
#[derive(Clone, Copy)]
pub(super) struct Uneven<'a> {
    pub(super) clusters: &'a [Cluster],
}

/// Cuts the shooter's elements into clusters of at most [`CLUSTER`] nearby ones: fills
/// `order` with the element indices, cluster after cluster, and `clusters` with the pieces.
pub(super) fn cluster_elements(
    elements: &[ShooterElement],
    density: &[f64],
    order: &mut Vec<u32>,
    clusters: &mut Vec<Cluster>,
) {
    order.clear();
    clusters.clear();
    order.extend(0..elements.len() as u32);
    build_clusters(order, 0, elements, density, clusters);
}

/// Cuts `order` (indices into `elements`) by median splits along the longest extent of the
/// element centres until each piece holds at most [`CLUSTER`] elements; appends the pieces.
fn build_clusters(
    order: &mut [u32],
    base: usize,
    elements: &[ShooterElement],
    density: &[f64],
    out: &mut Vec<Cluster>,
) {
    let el = |k: &u32| &elements[*k as usize];
    if order.len() > CLUSTER {
        let (lo, hi) = bounds(order.iter().map(|k| &el(k).centre));
        let axis = (hi - lo).max_position();
        let mid = order.len() / 2;
        order.select_nth_unstable_by(mid, |a, b| el(a).centre[axis].total_cmp(&el(b).centre[axis]));
        let (left, right) = order.split_at_mut(mid);
        build_clusters(left, base, elements, density, out);
        build_clusters(right, base + mid, elements, density, out);
        return;
    }
    let area: f64 = order.iter().map(|k| el(k).area).sum();
    let centre = order.iter().map(|k| el(k).centre * el(k).area).sum::<DVec3>() / area;
    let radius = order.iter().map(|k| el(k).centre.distance(centre) + el(k).radius).fold(0.0, f64::max);
    let lanes = order
        .chunks(4)
        .map(|four| {
            let mut lanes = Lanes {
                x: Vec4::ZERO,
                y: Vec4::ZERO,
                z: Vec4::ZERO,
                area: Vec4::ZERO,
                density: Vec4::ZERO,
                exact_within: Vec4::ZERO,
                members: [0; 4],
                count: four.len(),
            };
            for (lane, &k) in four.iter().enumerate() {
                let (e, c) = (el(&k), (el(&k).centre - centre).as_vec3());
                (lanes.x[lane], lanes.y[lane], lanes.z[lane]) = (c.x, c.y, c.z);
                lanes.area[lane] = e.area as f32;
                lanes.density[lane] = density[k as usize] as f32;
                lanes.exact_within[lane] = (16.0 * e.radius * e.radius) as f32;
                lanes.members[lane] = k;
            }
            lanes
        })
        .collect();
    let density = order.iter().map(|k| density[*k as usize] * el(k).area).sum::<f64>() / area;
    out.push(Cluster { members: base..base + order.len(), centre, radius, area, density, lanes });
}

/// Σ_k d_k F_{p→k} / Σ_k F_{p→k} over the shooter's elements k: how much brighter than its
/// mean the shooter looks from `p`; 1 when `p` sees none of it.
/// Clusters more than four radii away count as one element.
pub(super) fn density_weight(
    p: DVec3,
    n: DVec3,
    ns: DVec3,
    uneven: &Uneven,
    elements: &[ShooterElement],
) -> f64 {
    let (mut weighted, mut plain) = (0.0, 0.0);
    let (n32, ns32) = (n.as_vec3(), ns.as_vec3());
    for c in uneven.clusters {
        if c.centre.distance_squared(p) >= 16.0 * c.radius * c.radius {
            let f = point_to_point(p, n, c.centre, ns, c.area);
            weighted += c.density * f;
            plain += f;
            continue;
        }
        // Each element's point-to-point factor (`point_to_point`: cos θ cos θ' A / (π r²),
        // at most 1), or its exact one within four radii (`point_to_polygon_x4`).
        let q = (p - c.centre).as_vec3();
        for lanes in &c.lanes {
            let d = [lanes.x - Vec4::splat(q.x), lanes.y - Vec4::splat(q.y), lanes.z - Vec4::splat(q.z)];
            let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let cos_r = (d[0] * n32.x + d[1] * n32.y + d[2] * n32.z).max(Vec4::ZERO);
            let cos_s = (-(d[0] * ns32.x + d[1] * ns32.y + d[2] * ns32.z)).max(Vec4::ZERO);
            let live = r2.cmpgt(Vec4::ZERO);
            let far = cos_r * cos_s * lanes.area
                / (Vec4::splat(std::f32::consts::PI) * Vec4::select(live, r2 * r2, Vec4::ONE));
            let far = Vec4::select(live, far.min(Vec4::ONE), Vec4::ZERO).to_array();
            let exact = r2.cmplt(lanes.exact_within).bitmask();
            let density = lanes.density.to_array();
            for k in 0..lanes.count {
                let f = if exact >> k & 1 == 1 {
                    point_to_polygon_x4(p, n, elements[lanes.members[k] as usize].corners())
                } else {
                    f64::from(far[k])
                };
                weighted += f64::from(density[k]) * f;
                plain += f;
            }
        }
    }
    if plain > 0.0 { weighted / plain } else { 1.0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::elements::unit_squares;

    /// Every element lands in exactly one cluster of at most [`CLUSTER`], each cluster's
    /// sphere holds its elements, and its area and density are its elements' sum and
    /// area-weighted mean.
    #[test]
    fn clusters_partition_the_elements_and_bound_them() {
        let elements = unit_squares(9);
        let density: Vec<f64> = (0..elements.len()).map(|k| (k % 7) as f64 * 0.3).collect();
        let (mut order, mut clusters) = (Vec::new(), Vec::new());
        cluster_elements(&elements, &density, &mut order, &mut clusters);
        let mut seen = vec![0; elements.len()];
        let mut next = 0;
        for c in &clusters {
            assert_eq!(c.members.start, next, "clusters tile the order");
            next = c.members.end;
            assert!(!c.members.is_empty() && c.members.len() <= CLUSTER);
            let members = &order[c.members.clone()];
            let area: f64 = members.iter().map(|&k| elements[k as usize].area).sum();
            let mean = members.iter().map(|&k| density[k as usize]).sum::<f64>() / members.len() as f64;
            assert!((c.area - area).abs() < 1e-12 && (c.density - mean).abs() < 1e-12);
            for &k in members {
                seen[k as usize] += 1;
                for p in elements[k as usize].corners() {
                    assert!(p.distance(c.centre) <= c.radius + 1e-12, "corner outside its cluster");
                }
            }
        }
        assert_eq!(next, order.len());
        assert!(seen.iter().all(|&n| n == 1));
        assert!(clusters.len() >= 81 / CLUSTER);
    }

    /// An even shooter weighs 1 from anywhere; a shooter bright on one half looks brighter
    /// from above that half than from above the other, near and far (one cluster's mean).
    #[test]
    fn density_weight_follows_the_part_a_receiver_sees() {
        let elements = unit_squares(8);
        let (mut order, mut clusters) = (Vec::new(), Vec::new());
        let even = vec![1.0; elements.len()];
        cluster_elements(&elements, &even, &mut order, &mut clusters);
        let uneven = Uneven { clusters: &clusters };
        let down = -DVec3::Z;
        for p in [DVec3::new(1.0, 4.0, 0.5), DVec3::new(4.0, 4.0, 100.0)] {
            let w = density_weight(p, down, DVec3::Z, &uneven, &elements);
            assert!((w - 1.0).abs() < 1e-12, "{p}: {w}");
        }
        // Left half (x < 4) twice the mean, right half empty.
        let density: Vec<f64> = elements.iter().map(|e| if e.centre.x < 4.0 { 2.0 } else { 0.0 }).collect();
        cluster_elements(&elements, &density, &mut order, &mut clusters);
        let uneven = Uneven { clusters: &clusters };
        let over_left = density_weight(DVec3::new(1.0, 4.0, 0.5), down, DVec3::Z, &uneven, &elements);
        let over_right = density_weight(DVec3::new(7.0, 4.0, 0.5), down, DVec3::Z, &uneven, &elements);
        assert!(over_left > 1.8 && over_right < 0.2, "{over_left}, {over_right}");
        let far = density_weight(DVec3::new(4.0, 4.0, 1000.0), down, DVec3::Z, &uneven, &elements);
        assert!((far - 1.0).abs() < 1e-3, "{far}");
    }
}
