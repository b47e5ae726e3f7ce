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
//! the variation of reflected light's visibility inside one group. So a unit whose rays
//! disagree (some blocked, some not: a shadow's edge, or a wall with members on both sides)
//! does not share: its members trace their own rays ([`Shared::mixed`]). Emitters (their sharp
//! shadows are the ones the eye reads) and near shooters keep a ray per element, as do
//! groups too small to gain. This is the receiving half of clustering (Smits, Arvo &
//! Greenberg 1994 link a far cluster as one receiver; Sillion 1995 estimates a cluster's
//! visibility from a few rays), with the irradiance still pushed to each facet through its
//! own unoccluded form factor. Sharing for every shooter that was not bright (≥ 1 % of the
//! first shot) instead gave the same object means on the 30 k and 120 k rooms (within
//! 0.3 %) and took 11 % longer on the 120 k one.
//!
//! A group too near the shooter to share whole (a floor patch under a scanned statue) may
//! still be far from each of its tiles, the runs of at most 64 facets that lie together
//! (`clusters::Tile`): those share on their own, by the same test against their own radius.
//! On a 834 k-triangle room most of a row's time went to the facets of such near groups,
//! each with its own plan, quadrature and rays.

use rayon::prelude::*;

use super::clusters::Clusters;
use crate::sampling::Rng;
use glam::DVec3;

/// A receiving group or tile shares its visibility when its centre is at least this many
/// times the sum of its radius and the shooter's away from the shooter's centre.
const SHARE_DISTANCE: f64 = 2.5;

/// Rays a sharing group traces (from members drawn by power, stratified).
const SHARED_RAYS: u32 = 16;

/// Random streams of the draws are keyed apart from elements' and groups' own.
const SHARED_STREAM: u64 = 0x7368_6172_6564_0000;

/// A tile's draws are keyed apart from whole groups'.
const TILE_KEY: u64 = 1 << 40;

/// Not sharing.
const NONE: u32 = u32::MAX;

/// Which receiving groups and tiles share their visibility in one row.
#[derive(Default)]
pub(super) struct Sharing {
    /// Per element, the unit it shares with, or [`NONE`]: a row asks this of every element
    /// several times (its plan, its first pass, its penumbra rays, its result), and on a
    /// million elements a lookup through groups and tiles was 5 % of the solve.
    unit_of: Vec<u32>,
    /// The units that share: a whole group or one tile.
    units: Vec<Unit>,
}

/// A run of one group's elements that shares one visibility estimate.
#[derive(PartialEq)]
struct Unit {
    /// Its group.
    group: usize,
    /// Its elements: a range of the group's `elements`.
    elements: std::ops::Range<usize>,
    /// Its random stream's key.
    key: u64,
}

/// What one sharing unit received from a shot.
#[derive(Default)]
pub(super) struct Shared {
    /// Its member elements' unoccluded form factors, in the unit's element order.
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

    /// Whether its rays disagree (some blocked, some not): the unit straddles a shadow's edge,
    /// or a wall with members on both sides, so its members trace their own rays instead
    /// (a group's rays are drawn by power, and behind a wall the facets took the lit side's
    /// visibility: in Bitterli's *Veach, Ajar* with 0.15 m patches an object by the door
    /// came out +271 %).
    pub(super) fn mixed(&self) -> bool {
        self.seen.0 > 0 && self.seen.0 < self.seen.1
    }
}

impl Sharing {
    /// Chooses what shares for a shooter centred at `centre` with circumradius `radius`:
    /// nothing when it `emits` or when sharing is off, else the groups with more members
    /// than [`SHARED_RAYS`] at least [`SHARE_DISTANCE`] radii away, and of the others, the
    /// tiles that are; `shooter_group` is the shooting group, which never shares (its
    /// members receive from each other up close).
    pub(super) fn choose(
        &mut self,
        clusters: &Clusters,
        centre: DVec3,
        radius: f64,
        emits: bool,
        enabled: bool,
        shooter_group: Option<usize>,
    ) {
        if self.unit_of.is_empty() {
            self.unit_of.resize(clusters.element_count(), NONE);
        }
        let mut units = Vec::new();
        let far = |c: DVec3, r: f64, members: usize| {
            members > SHARED_RAYS as usize && c.distance(centre) > SHARE_DISTANCE * (r + radius)
        };
        let groups = if enabled && !emits { 0..clusters.len() } else { 0..0 };
        for g in groups.filter(|&g| Some(g) != shooter_group) {
            let group = clusters.group(g);
            if far(group.centre, group.radius, group.patches.len()) {
                units.push(Unit { group: g, elements: 0..group.elements.len(), key: g as u64 });
                continue;
            }
            for t in group.tiles.clone().map(|t| t as usize) {
                let tile = clusters.tile(t);
                if far(tile.centre, tile.radius, tile.patches as usize) {
                    let elements = tile.elements.start as usize..tile.elements.end as usize;
                    units.push(Unit { group: g, elements, key: TILE_KEY | t as u64 });
                }
            }
        }
        // Successive shooters far from a model share the same units: marking a million
        // elements again for each took 5 ms, 8 % of a shot of a 1 M-triangle room.
        if units == self.units {
            return;
        }
        // Only the last row's sharing elements are marked.
        for unit in &self.units {
            for &e in &clusters.group(unit.group).elements[unit.elements.clone()] {
                self.unit_of[e as usize] = NONE;
            }
        }
        self.units = units;
        for (u, unit) in self.units.iter().enumerate() {
            for &e in &clusters.group(unit.group).elements[unit.elements.clone()] {
                self.unit_of[e as usize] = u as u32;
            }
        }
    }

    /// Whether anything shares.
    pub(super) fn any(&self) -> bool {
        !self.units.is_empty()
    }

    /// Element `e`'s sharing unit and its place in the unit's elements, when it shares.
    pub(super) fn member(&self, clusters: &Clusters, e: usize) -> Option<(usize, usize)> {
        let unit = *self.unit_of.get(e)?;
        (unit != NONE).then(|| (unit as usize, clusters.slot(e) - self.units[unit as usize].elements.start))
    }

    /// Whether element `e` shares.
    pub(super) fn shares(&self, e: usize) -> bool {
        self.unit_of.get(e).is_some_and(|&u| u != NONE)
    }

    /// Each sharing unit's receiving: `factors(g, range)` gives the unoccluded form factors
    /// of group `g`'s members in `range` of its elements, then [`SHARED_RAYS`] members
    /// drawn by area × factor, stratified, trace `ray(e)` (the (unblocked, traced) of
    /// element `e`'s own first ray; drawn twice, the same ray). Returns, per unit (see
    /// [`Sharing::member`]), its factors and what its rays saw, and the rays traced. Each
    /// unit draws from its own stream, so the threads change nothing.
    pub(super) fn receive(
        &self,
        clusters: &Clusters,
        area: &[f64],
        (seed, stream): (u64, u64),
        factors: impl Fn(usize, std::ops::Range<usize>) -> Vec<f64> + Sync,
        ray: impl Fn(usize) -> (u32, u32) + Sync,
    ) -> (Vec<Shared>, u64) {
        let one = |unit: &Unit| -> Shared {
            let elements = &clusters.group(unit.group).elements[unit.elements.clone()];
            let factors = factors(unit.group, unit.elements.clone());
            let weight = |k: usize| area[elements[k] as usize] * factors[k];
            let total: f64 = (0..elements.len()).map(weight).sum();
            if !(total > 0.0 && total.is_finite()) {
                return Shared { factors, ..Shared::default() };
            }
            let mut rng = Rng::for_task(seed, stream ^ SHARED_STREAM, unit.key);
            let (mut visible, mut drawn, mut rays) = (0, 0, 0);
            let (mut walked, mut k) = (0.0, 0);
            for j in 0..SHARED_RAYS {
                // Stratified over the cumulative weights: the j-th draw lands in the j-th
                // slice of the unit's power.
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
        let received: Vec<Shared> = self.units.par_iter().map(one).collect();
        let rays = received.iter().map(|r| u64::from(r.rays)).sum();
        (received, rays)
    }
}
