//! A group's unshot power fixed at its first shot: its far-field axes, its near-field
//! points, and when its spread has drifted far enough to fix it again.

use super::*;
use crate::sampling::{Rng, point_on};
use crate::solver::SolverParams;
use crate::solver::elements::corners_of;
use crate::solver::first_shots::DRIFT;
use crate::solver::mesh_tables::MeshTables;

/// Bins per side of the grid that sorts a group's normals by their two minor components
/// (the major one is the group's facing): 16 bins of about 20° each, so that the clamp of
/// each bin's summed normal loses little (Σ_k w_k (n_k·d)⁺ ≥ (Σ_k w_k n_k · d)⁺, equal when
/// no member of the bin faces away from d). One vector for the whole group left its far
/// receivers 1–4 % dark.
pub(super) const BINS: usize = 4;

/// The bin of normal `n` (see [`BINS`]).
pub(super) fn normal_bin(n: DVec3) -> usize {
    let minor = match facing(n) / 2 {
        0 => (n.y, n.z),
        1 => (n.x, n.z),
        _ => (n.x, n.y),
    };
    // The minor components of a normal whose major axis is largest lie within ±1/√2.
    let cell = |c: f64| {
        (((c * std::f64::consts::FRAC_1_SQRT_2.recip() + 1.0) * 0.5 * BINS as f64) as usize).min(BINS - 1)
    };
    cell(minor.0) * BINS + cell(minor.1)
}

impl Clusters {
    /// Fixes group `g`'s spread at its first shot (nothing on later ones): `first_power`
    /// is the power of the solve's first shot.
    pub(in crate::solver) fn freeze(
        &mut self,
        g: usize,
        mesh: &Mesh,
        unshot: &[Rgb],
        tables: &MeshTables,
        params: &SolverParams,
        first_power: f64,
    ) {
        let group = &mut self.groups[g];
        if group.frozen.is_some() {
            return;
        }
        let elements: Vec<usize> = group.elements.iter().map(|&e| e as usize).collect();
        let weight = |e: usize| (unshot[e] * mesh.elements[e].area).abs().sum();
        let mut total: f64 = elements.iter().map(|&e| weight(e)).sum();
        let by_area = !(total > 0.0 && total.is_finite());
        let share = |e: usize| if by_area { mesh.elements[e].area } else { weight(e) };
        if by_area {
            total = elements.iter().map(|&e| mesh.elements[e].area).sum();
        }
        let mut bins = [(DVec3::ZERO, 0.0); BINS * BINS];
        for &e in &elements {
            let n = mesh.elements[e].normal;
            let bin = &mut bins[normal_bin(n)];
            bin.0 += n * (share(e) / total);
            bin.1 += share(e) / total;
        }
        // Each bin's summed normal at the length of the bin's share: the clamped lobe of a
        // vector a sends out π|a| over the sphere, and |Σ w_k n_k| < Σ w_k when the normals
        // differ, so unscaled the far field lost what a curved group's bins spread (the
        // members' own lobes send out exactly their shares).
        let axes: Vec<DVec3> = bins
            .into_iter()
            .filter(|(a, _)| *a != DVec3::ZERO)
            .map(|(a, w)| a.normalize_or_zero() * w)
            .collect();
        let axes = axes
            .chunks(4)
            .map(|four| {
                let mut lanes = [Vec4::ZERO; 3];
                for (lane, a) in four.iter().enumerate() {
                    let a = a.as_vec3();
                    (lanes[0][lane], lanes[1][lane], lanes[2][lane]) = (a.x, a.y, a.z);
                }
                lanes
            })
            .collect();
        let mut cdf = Vec::with_capacity(elements.len());
        let mut acc = 0.0;
        for &e in &elements {
            acc += share(e) / total;
            cdf.push(acc);
        }
        // A jittered √POINTS × √POINTS grid mapped by the shares: u picks the element, v and
        // the rest of u place the point in it (as a patch's ray ends, `ray_ends.rs`).
        let side = (POINTS as f64).sqrt() as usize;
        let mut rng = Rng::for_task(params.seed, GROUP_STREAM ^ g as u64, u64::MAX);
        let mut points = Vec::with_capacity(POINTS);
        for b in 0..side {
            for a in 0..side {
                let u = (a as f64 + rng.next_f64()) / side as f64;
                let v = (b as f64 + rng.next_f64()) / side as f64;
                let k = cdf.partition_point(|&c| c <= u).min(cdf.len() - 1);
                let below = if k == 0 { 0.0 } else { cdf[k - 1] };
                let width = cdf[k] - below;
                let u = if width > 0.0 { ((u - below) / width).clamp(0.0, 1.0 - f64::EPSILON) } else { 0.5 };
                let e = elements[k];
                let corners = corners_of(mesh, e);
                let corners = &corners[..mesh.elements[e].vertex_count as usize];
                points.push((point_on(corners, u, v), mesh.elements[e].normal, mesh.elements[e].patch));
            }
        }
        let lifted = points.iter().map(|(p, n, _)| (*p + *n * tables.ray_offset).as_vec3()).collect();
        // Bright or dim by its first shot's power: a spread fixed again keeps it.
        let bright = group.first_bright.unwrap_or_else(|| {
            total_power(&group.patches, mesh, unshot) >= params.bright_share * first_power
        });
        group.first_bright = Some(bright);
        let near = NearPoints::new(group.centre, &points);
        group.frozen = Some(Frozen { axes, points, lifted, near, bright, cdf });
    }

    /// Lets group `g`'s spread be fixed again (by the next [`Clusters::freeze`]) when the
    /// spread of its unshot power has drifted from the fixed one by more than [`DRIFT`] (half
    /// the summed differences of its elements' shares: the share of its power that moved);
    /// whether it did. Its brightness stays.
    ///
    /// A group's first shot carries the direct light on its facets: a cushion's lit top. Its
    /// later shots carry the light of the room, which also reaches the facets turned away
    /// from the lamp, towards the backrest the cushion leans on. Shot from the first spread,
    /// that light left from the lit top instead, and the crevice between the two went dark:
    /// a sofa's cushions (ρ = 0.95) came out 17–29 % dark, and its frame 8 %.
    pub(in crate::solver) fn refresh_if_drifted(&mut self, g: usize, mesh: &Mesh, unshot: &[Rgb]) -> bool {
        let group = &mut self.groups[g];
        let Some(frozen) = &group.frozen else { return false };
        let power = |e: u32| (unshot[e as usize] * mesh.elements[e as usize].area).abs().sum();
        let total: f64 = group.elements.iter().map(|&e| power(e)).sum();
        if !(total > 0.0 && total.is_finite()) {
            return false;
        }
        let mut below = 0.0;
        let mut moved = 0.0;
        for (&e, &c) in group.elements.iter().zip(&frozen.cdf) {
            moved += (power(e) / total - (c - below)).abs();
            below = c;
        }
        if moved / 2.0 <= DRIFT {
            return false;
        }
        group.frozen = None;
        true
    }
}
