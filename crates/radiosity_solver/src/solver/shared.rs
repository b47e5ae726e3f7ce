//! Receiving groups: far from a shooter that does not emit, the facets of a shooter group
//! share one visibility estimate instead of tracing a ray each.
//!
//! A row's cost was one ray per receiving element, and a tessellated model's facets are most
//! of the elements: on a 120 k-triangle room 84 % of a row's rays went to them, and past
//! that size every row is traced again at each shot because the rows no longer fit their
//! cache. Reflected light comes from surfaces large and near enough to cast soft shadows
//! only, so across a small group far away its visibility changes slowly: the group traces
//! [`SHARED_RAYS`] rays from members drawn by their share of the row's power (area ×
//! unoccluded form factor) and every member takes their unblocked fraction. That fraction is
//! an unbiased estimate of the group's power-weighted visibility,
//! Σ_k A_k F_k V_k / Σ_k A_k F_k, so what the group receives in all is kept; what is lost is
//! the variation of reflected light's visibility inside one group. Emitters (their sharp
//! shadows are the ones the eye reads) and near shooters keep a ray per element, as do
//! groups too small to gain. This is the receiving half of clustering (Smits, Arvo &
//! Greenberg 1994 link a far cluster as one receiver; Sillion 1995 estimates a cluster's
//! visibility from a few rays), with the irradiance still pushed to each facet through its
//! own unoccluded form factor. Sharing for every shooter that was not bright (≥ 1 % of the
//! first shot) instead gave the same object means on the 30 k and 120 k rooms (within
//! 0.3 %) and took 11 % longer on the 120 k one.

use rayon::prelude::*;

use super::clusters::Clusters;
use crate::sampling::Rng;
use glam::DVec3;

/// A receiving group shares its visibility when its centre is at least this many times the
/// sum of its radius and the shooter's away from the shooter's centre.
const SHARE_DISTANCE: f64 = 2.5;

/// Rays a sharing group traces (from members drawn by power, stratified).
const SHARED_RAYS: u32 = 16;

/// Random streams of the draws are keyed apart from elements' and groups' own.
const SHARED_STREAM: u64 = 0x7368_6172_6564_0000;

/// Which receiving groups share their visibility in one row.
#[derive(Default)]
pub(super) struct Sharing {
    /// Per group, whether it shares.
    groups: Vec<bool>,
}

/// What one sharing group received from a shot.
#[derive(Default)]
pub(super) struct Shared {
    /// Its member elements' unoccluded form factors, in the group's element order.
    pub(super) factors: Vec<f64>,
    /// (unblocked, traced) of its shared rays, a draw that needed no ray counted as one
    /// unblocked; (0, 0) when nothing of it receives.
    pub(super) seen: (u32, u32),
    /// Rays it traced.
    rays: u32,
}

impl Shared {
    /// The fraction of its rays that were unblocked (1 when it traced none).
    pub(super) fn visibility(&self) -> f64 {
        if self.seen.1 == 0 { 1.0 } else { f64::from(self.seen.0) / f64::from(self.seen.1) }
    }
}

impl Sharing {
    /// Chooses the sharing groups for a shooter centred at `centre` with circumradius
    /// `radius`: none when it `emits` or when sharing is off, else those at least
    /// [`SHARE_DISTANCE`] radii away with more members than [`SHARED_RAYS`]; `shooter_group`
    /// is the shooting group, which never shares (its members receive from each other up
    /// close).
    pub(super) fn choose(
        &mut self,
        clusters: &Clusters,
        centre: DVec3,
        radius: f64,
        emits: bool,
        enabled: bool,
        shooter_group: Option<usize>,
    ) {
        self.groups.clear();
        self.groups.extend((0..clusters.len()).map(|g| {
            let group = clusters.group(g);
            enabled
                && !emits
                && Some(g) != shooter_group
                && group.patches.len() > SHARED_RAYS as usize
                && group.centre.distance(centre) > SHARE_DISTANCE * (group.radius + radius)
        }));
    }

    /// Whether any group shares.
    pub(super) fn any(&self) -> bool {
        self.groups.iter().any(|&s| s)
    }

    /// Whether patch `q`'s elements take their group's shared visibility.
    pub(super) fn shares(&self, clusters: &Clusters, q: usize) -> bool {
        self.group_of(clusters, q).is_some()
    }

    /// Element `e`'s group, when it shares.
    pub(super) fn element_group(&self, clusters: &Clusters, e: usize) -> Option<usize> {
        clusters.group_of_element(e).filter(|&g| self.groups[g])
    }

    /// Patch `q`'s group, when it shares.
    pub(super) fn group_of(&self, clusters: &Clusters, q: usize) -> Option<usize> {
        clusters.group_of(q).filter(|&g| self.groups[g])
    }

    /// Each sharing group's receiving: `factors(g)` gives group `g`'s member elements'
    /// unoccluded form factors (in the group's element order), then [`SHARED_RAYS`] members
    /// drawn by area × factor, stratified, trace `ray(e)` (the (unblocked, traced) of
    /// element `e`'s own first ray; drawn twice, the same ray). Returns, per group, its
    /// factors and what its rays saw (empty and (0, 0) when it does not share), and the
    /// rays traced. Each group draws from its own stream, so the threads change nothing.
    pub(super) fn receive(
        &self,
        clusters: &Clusters,
        area: &[f64],
        (seed, stream): (u64, u64),
        factors: impl Fn(usize) -> Vec<f64> + Sync,
        ray: impl Fn(usize) -> (u32, u32) + Sync,
    ) -> (Vec<Shared>, u64) {
        let one = |g: usize| -> Shared {
            if !self.groups[g] {
                return Shared::default();
            }
            let elements = &clusters.group(g).elements;
            let factors = factors(g);
            let weight = |k: usize| area[elements[k] as usize] * factors[k];
            let total: f64 = (0..elements.len()).map(weight).sum();
            if !(total > 0.0 && total.is_finite()) {
                return Shared { factors, ..Shared::default() };
            }
            let mut rng = Rng::for_task(seed, stream ^ SHARED_STREAM, g as u64);
            let (mut visible, mut drawn, mut rays) = (0, 0, 0);
            let (mut walked, mut k) = (0.0, 0);
            for j in 0..SHARED_RAYS {
                // Stratified over the cumulative weights: the j-th draw lands in the j-th
                // slice of the group's power.
                let t = (f64::from(j) + rng.next_f64()) / f64::from(SHARED_RAYS) * total;
                while k + 1 < elements.len() && walked + weight(k) < t {
                    walked += weight(k);
                    k += 1;
                }
                let (v, n) = ray(elements[k] as usize);
                rays += n;
                // No ray needed (nothing can block it): one unblocked.
                let (v, n) = if n == 0 { (1, 1) } else { (v, n) };
                visible += v;
                drawn += n;
            }
            Shared { factors, seen: (visible, drawn), rays }
        };
        let received: Vec<Shared> = (0..self.groups.len()).into_par_iter().map(one).collect();
        let rays = received.iter().map(|r| u64::from(r.rays)).sum();
        (received, rays)
    }
}
