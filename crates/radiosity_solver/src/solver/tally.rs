//! The physics state of a solve: radiosity B and unshot radiosity ΔB per element, unshot
//! power per patch, and the power bookkeeping (emitted = absorbed + unshot + escaped).

use radiosity_core::Rgb;
use radiosity_mesh::Mesh;
use rayon::prelude::*;

use super::SolverError;
use super::luminaires::LuminaireLight;
use super::mesh_tables::MeshTables;
use super::parallel::Carve;
use super::row::{CLUSTER_TERM, NearField, Row};

/// The most an enclosed shooter's shot is scaled up by to deliver all of its power (see
/// [`super::enclosure`]): three times for a group's near receivers (its points' kernel gives a
/// receiver at one point-disc radius 69 % of its share, and crevices are nearer), which also
/// bounds what a shooter wrongly judged enclosed can create.
const MAX_REFUND: f64 = 3.0;

/// The most an enclosed patch's shot is scaled up by: its rows fall short by a fraction of a
/// per cent (the ceiling of a closed room with a sofa: 0.4 %).
const MAX_PATCH_REFUND: f64 = 1.25;

/// Power bookkeeping per channel: emitted + created = absorbed + unshot + escaped, to
/// round-off.
///
/// A shot delivers Σ_j A_j F_ji ΔB_i to its receivers, and by reciprocity (Cohen & Wallace
/// §2.5) Σ_j A_j F_ji = A_i Σ_j F_ij ≤ A_i: no shot can deliver more than the shooter's
/// power. Discretisation breaks that bound where receivers' point form factors overstate
/// what they see of a nearby shooter; the excess is `created`, kept apart from `escaped` so
/// the two cannot hide each other in a closed room.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnergyBalance {
    /// Σ E·A.
    pub emitted: Rgb,
    /// Power absorbed by surfaces, (1 − ρ) of what they received.
    pub absorbed: Rgb,
    /// Power not yet shot, Σ ΔB·A.
    pub unshot: Rgb,
    /// Power shot that reached no element (left an open scene).
    pub escaped: Rgb,
    /// Power delivered beyond what the shooters shot: Σ over shots of the receivers' excess,
    /// per channel (zero for a solver that conserves energy shot by shot).
    pub created: Rgb,
}

impl EnergyBalance {
    /// (emitted + created) − (absorbed + unshot + escaped) per channel, relative to the
    /// emitted power: round-off only.
    pub fn residual(&self) -> Rgb {
        let gap = self.emitted + self.created - self.absorbed - self.unshot - self.escaped;
        gap.zip_map(self.emitted, |g, e| if e > 0.0 { g / e } else { 0.0 })
    }
}

/// Who shoots: one patch, or a group of a model's facets (see `clusters`).
#[derive(Clone, Copy)]
pub(super) struct Shooters<'a> {
    /// The patches.
    pub(super) patches: &'a [u32],
    /// Their total area.
    pub(super) area: f64,
    /// A group's centre and the reach of its near field (see `clusters::FAR`): the
    /// receivers within it are those its shot's shortfall is given back to.
    pub(super) near_reach: Option<(glam::DVec3, f64)>,
    /// The share of the shooter's power its shot must deliver (see [`super::enclosure`]): 1
    /// when every probe ray met a surface, less where some left; none to take its row as it
    /// is.
    pub(super) delivers: Option<Delivery>,
}

/// What a shooter's shot must deliver (see [`super::enclosure`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Delivery {
    /// The share of its power that meets a surface: 1 when enclosed.
    pub(super) share: f64,
    /// The standard error of `share` (0 when enclosed): a row that delivers within twice
    /// this of it is taken as it is, so the probes' noise does not move rows that were right.
    pub(super) error: f64,
}

/// Radiosity, unshot radiosity and power tallies.
pub(super) struct Tally {
    /// B per element, W/unit².
    pub(super) radiosity: Vec<Rgb>,
    /// ΔB per element, W/unit².
    pub(super) unshot: Vec<Rgb>,
    /// Σ ΔB·A over each patch's elements, W.
    pub(super) patch_unshot_power: Vec<Rgb>,
    /// Per element, the radiosity it reflected straight from the emitters' own emission (the
    /// first bounce of direct light), W/unit²: what a final gather recomputes per pixel by
    /// shadow rays (Chen et al. 1991) and must not count twice.
    pub(super) direct: Vec<Rgb>,
    /// Per patch, the part of its unshot power that is its own emission, not yet shot, W.
    patch_unshot_emission: Vec<Rgb>,
    /// Σ E·A, W.
    pub(super) emitted: Rgb,
    pub(super) absorbed: Rgb,
    pub(super) escaped: Rgb,
    /// Power delivered beyond a shot's own (see [`EnergyBalance::created`]).
    pub(super) created: Rgb,
    /// Σ |unshot power| / Σ emitted power, summed over channels.
    pub(super) unshot_fraction: f64,
    /// Per patch, its |unshot power| summed over channels, as last tallied.
    pub(super) patch_abs: Vec<f64>,
    /// Σ `patch_abs`, kept up to date patch by patch (a model's 200 k patches summed after
    /// every shot cost more than the shot), and summed afresh every [`RESUM`] shots.
    abs_total: f64,
    /// Shots since `abs_total` was summed afresh.
    since_sum: u32,
    /// The patches whose unshot power the last shot changed, with the change of their
    /// |unshot power|.
    pub(super) changed: Vec<(u32, f64)>,
}

/// Shots between fresh sums of the unshot power, so rounding cannot pile up.
pub(super) const RESUM: u32 = 256;

/// Below this many elements a shot is applied on one thread (a parallel pass costs more).
const APPLY_PARALLEL_MIN: usize = 32_768;

/// Consecutive receiving spans of one shot with their factors, their elements' radiosity and
/// unshot radiosity, their patches' unshot power and |unshot power| (patches from
/// `patches.0` on), and what its receivers took in.
struct Chunk<'a> {
    spans: &'a [(u32, u32)],
    factors: &'a [f32],
    radiosity: &'a mut [Rgb],
    unshot: &'a mut [Rgb],
    patches: (usize, &'a mut [Rgb], &'a mut [f64]),
    took: Took,
}

/// What one chunk of a shot's receivers took in, summed in the chunk's patch order.
#[derive(Default)]
struct Took {
    /// Irradiance times area, W.
    received: Rgb,
    /// The part of it absorbed, W.
    absorbed: Rgb,
    /// The change of Σ |unshot power|.
    abs_delta: f64,
    /// (patch, change of its |unshot power|), in patch order.
    changed: Vec<(u32, f64)>,
}

/// A shot is applied in about this many chunks of consecutive receiving spans...
const CHUNKS: usize = 256;

/// ... of at least this many spans each.
const MIN_SPANS_PER_CHUNK: usize = 16;

/// Calls `f(patch, its elements)` for every patch the row's `spans` cover, in order (a span
/// is whole consecutive patches).
fn for_each_patch(
    tables: &MeshTables,
    spans: &[(u32, u32)],
    mut f: impl FnMut(usize, std::ops::Range<usize>),
) {
    for &(first, count) in spans {
        let (mut e, end) = (first as usize, first as usize + count as usize);
        while e < end {
            let patch = tables.element_patch[e] as usize;
            let next = tables.patch_elements[patch].end.min(end);
            f(patch, e..next);
            e = next;
        }
    }
}

impl Tally {
    /// Shot 0: B = E and ΔB = E on every element.
    ///
    /// # Errors
    /// [`SolverError::NoEmission`] when nothing emits.
    #[cfg(test)]
    pub(super) fn new(mesh: &Mesh) -> Result<Self, SolverError> {
        Self::lit(mesh, None)
    }

    /// Shot 0: B = E and ΔB = E on every element, plus ρ times the luminaires' direct light.
    ///
    /// # Errors
    /// [`SolverError::NoEmission`] when nothing emits and there is no luminaire,
    /// [`SolverError::DarkLuminaires`] when nothing emits and no luminaire lights anything,
    /// [`SolverError::DarkDaylight`] when a sun or sky alone lights nothing.
    pub(super) fn lit(mesh: &Mesh, luminaires: Option<&LuminaireLight>) -> Result<Self, SolverError> {
        let n = mesh.elements.len();
        let emission: Vec<Rgb> = (0..n).map(|e| mesh.element_material(e).emission).collect();
        let emitted: Rgb = mesh.elements.iter().zip(&emission).map(|(el, e)| *e * el.area).sum();
        if emitted.sum() <= 0.0 {
            match luminaires {
                None => return Err(SolverError::NoEmission),
                Some(light) if light.is_dark() && light.count == 0 => return Err(SolverError::DarkDaylight),
                Some(light) if light.is_dark() => {
                    return Err(SolverError::DarkLuminaires { count: light.count });
                }
                Some(_) => {}
            }
        }
        let patch_unshot_emission = (mesh.patches.iter())
            .map(|p| p.elements.clone().map(|e| emission[e as usize] * mesh.elements[e as usize].area).sum())
            .collect();
        let mut tally = Self {
            direct: vec![Rgb::ZERO; n],
            patch_unshot_emission,
            radiosity: emission.clone(),
            unshot: emission,
            patch_unshot_power: vec![Rgb::ZERO; mesh.patches.len()],
            emitted,
            absorbed: Rgb::ZERO,
            escaped: Rgb::ZERO,
            created: Rgb::ZERO,
            unshot_fraction: 1.0,
            patch_abs: vec![0.0; mesh.patches.len()],
            abs_total: 0.0,
            since_sum: RESUM,
            changed: Vec::new(),
        };
        if let Some(light) = luminaires {
            tally.add_luminaires(light, mesh);
        }
        for (p, patch) in mesh.patches.iter().enumerate() {
            tally.patch_unshot_power[p] = (patch.elements.start..patch.elements.end)
                .map(|e| tally.unshot[e as usize] * mesh.elements[e as usize].area)
                .sum();
        }
        for (abs, power) in tally.patch_abs.iter_mut().zip(&tally.patch_unshot_power) {
            *abs = power.abs().sum();
        }
        tally.update_unshot_fraction();
        Ok(tally)
    }

    /// Puts the luminaires' `light` into the tally: B and ΔB gain ρ·E; the luminaires' power
    /// counts as emitted, what the elements absorb of it as absorbed, and the rest as escaped
    /// (or, if the sampled elements received more than the luminaires emit, as created).
    fn add_luminaires(&mut self, light: &LuminaireLight, mesh: &Mesh) {
        let mut received = Rgb::ZERO;
        let mut absorbed = Rgb::ZERO;
        for (e, h) in light.irradiance.iter().enumerate() {
            let rho = mesh.element_material(e).reflectance;
            let area = mesh.elements[e].area;
            self.radiosity[e] += rho * *h;
            self.unshot[e] += rho * *h;
            received += *h * area;
            absorbed += (Rgb::ONE - rho) * *h * area;
        }
        self.emitted += light.power;
        self.absorbed += absorbed;
        let gap = light.power - received;
        self.escaped += gap.map(|g| g.max(0.0));
        self.created += gap.map(|g| (-g).max(0.0));
    }

    /// Recomputes the unshot fraction from the patches' unshot power.
    pub(super) fn update_unshot_fraction(&mut self) {
        self.since_sum += 1;
        if self.since_sum >= RESUM {
            self.since_sum = 0;
            self.abs_total = self.patch_abs.iter().sum();
        }
        self.unshot_fraction = self.abs_total / self.emitted.sum();
    }

    /// Patch `q`'s unshot power changed: its |power|, the total, and the changed list follow.
    fn changed(&mut self, q: usize) {
        let new = self.patch_unshot_power[q].abs().sum();
        let delta = new - self.patch_abs[q];
        self.abs_total += delta;
        self.patch_abs[q] = new;
        self.changed.push((q as u32, delta));
    }

    /// Shoots ω times the shooter's unshot radiosity through its row of form factors: every
    /// receiving element j gains ρ_j · ω ΔB_i · F_{j→i} in B_j and ΔB_j (Cohen et al. 1988,
    /// with F_{j→i} already the reciprocal form), and the shooter keeps (1 − ω) ΔB_i. The
    /// shooter is one patch or a group of them (`shooters`, of total area `area`), whose ΔB_i
    /// is then their unshot power over their area. The receivers touching a patch shooter
    /// take the part of it they see instead (`row::NearField`), and the others but the
    /// `grouped` facets (per patch, `Clusters::members`) make up the difference.
    pub(super) fn shoot(
        &mut self,
        mesh: &Mesh,
        tables: &MeshTables,
        by: Shooters,
        row: &Row,
        omega: f64,
        grouped: &[bool],
    ) {
        let Shooters { patches: shooters, area, .. } = by;
        let power: Rgb = shooters.iter().map(|&q| self.patch_unshot_power[q as usize]).sum();
        let mut shot_b = power * (omega / area);
        self.changed.clear();
        // The receivers touching the shooter see the part of it next to them (see
        // `row::NearField`): what each gets, taken before the shooter's ΔB is spent. Not when
        // overshooting: what is left unshot then swings above and below zero over a patch,
        // and the ρ = 0.8 furnace ended 0.2 % off.
        let plain = NearField::default();
        let near = if omega == 1.0 { &row.near } else { &plain };
        let cluster_b: Vec<Rgb> = near
            .clusters
            .iter()
            .map(|&(start, end)| {
                let members = &near.members[start as usize..end as usize];
                let a: f64 = members.iter().map(|&k| tables.element_area[k as usize]).sum();
                members
                    .iter()
                    .map(|&k| self.unshot[k as usize] * tables.element_area[k as usize])
                    .sum::<Rgb>()
                    / a
            })
            .collect();
        let part_b = |part: u32| {
            if part & CLUSTER_TERM != 0 {
                cluster_b[(part & !CLUSTER_TERM) as usize]
            } else {
                self.unshot[part as usize]
            }
        };
        let near_b: Vec<Rgb> = near
            .receivers
            .iter()
            .map(|&(_, _, first, count)| {
                let terms = &near.terms[first as usize..(first + count) as usize];
                let kept: f64 = terms.iter().map(|t| f64::from(t.1)).sum();
                let seen: Rgb = terms.iter().map(|&(part, phi)| part_b(part) * f64::from(phi)).sum();
                (seen + power * ((1.0 - kept).max(0.0) / area)) * omega
            })
            .collect();
        // What they gain or lose against the mean goes to (comes from) the other receivers,
        // as if they saw the shooter whole, so the shot carries the same power in all:
        // Σ_j A_j F_j ΔB_j over the near ones plus s · ΔB̄ · rest equals ΔB̄ Σ_j A_j F_j.
        let mut near_scale = Rgb::ONE;
        if !near.receivers.is_empty() && near.rest > 0.0 {
            let (mut near_power, mut near_share) = (Rgb::ZERO, 0.0);
            for (&(e, f, _, _), b) in near.receivers.iter().zip(&near_b) {
                let af = tables.element_area[e as usize] * f64::from(f);
                near_power += *b * af;
                near_share += af;
            }
            let expected = shot_b * (near.rest + near_share);
            near_scale = (expected - near_power)
                .zip_map(shot_b * near.rest, |a, b| if b > 0.0 { (a / b).clamp(0.5, 2.0) } else { 1.0 });
        }
        let mean_b = shot_b;
        shot_b = shot_b * near_scale;
        // A shooter's shortfall against what it must deliver given back (see `enclosure`):
        // `near_gain` scales what the receivers within a group's near field take, `gain`
        // what all take.
        let (mut near_gain, mut gain) = (Rgb::ONE, Rgb::ONE);
        if let Some(Delivery { share, error }) = by.delivers
            && omega == 1.0
        {
            let (far, near_part) = self.delivered(mesh, tables, by, row, &near_b, shot_b, mean_b, grouped);
            let sent = mean_b * (area * share);
            // An open shooter's row that delivers within twice the probes' standard error of
            // its share is as right as they can tell (the Cornell box's rows: moved by their
            // noise alone, its worst face went from 1.2 to 1.7 % off).
            let off = (far + near_part - sent)
                .zip_map(mean_b * area, |d, s| if s > 0.0 { d.abs() / s } else { 0.0 });
            let ratio =
                |lo: f64, hi: f64| move |a: f64, b: f64| if b > 0.0 { (a / b).clamp(lo, hi) } else { 1.0 };
            if error == 0.0 || off.max_channel() > 2.0 * error {
                if near_part.max_channel() > 0.0 {
                    near_gain = (sent - far).zip_map(near_part, ratio(1.0 / MAX_REFUND, MAX_REFUND));
                } else {
                    gain = sent.zip_map(far, ratio(1.0 / MAX_PATCH_REFUND, MAX_PATCH_REFUND));
                }
            }
        }
        shot_b = shot_b * gain;
        let mean_b_rx = mean_b * gain;
        let near_b: Vec<Rgb> = near_b.into_iter().map(|b| b * gain).collect();
        let reach = by.near_reach.filter(|_| near_gain != Rgb::ONE);
        let gain_of = |e: usize| match reach {
            Some((c, r)) if mesh.elements[e].centre.distance_squared(c) <= r * r => near_gain,
            _ => Rgb::ONE,
        };
        // A model's grouped facets take the mean: a scan beside a room patch sees it whole,
        // and scaled with the rest the bunnies of a furnished room came out 3–3.6 % bright.
        let b_of = |patch: usize| if grouped[patch] { mean_b_rx } else { shot_b };
        // The shooters keep (1 − ω) of their unshot radiosity before the receivers gain:
        // a group's facets also receive from each other.
        for &q in shooters {
            let patch = &mesh.patches[q as usize];
            for e in patch.elements.start..patch.elements.end {
                self.unshot[e as usize] *= 1.0 - omega;
            }
            self.patch_unshot_power[q as usize] *= 1.0 - omega;
            self.changed(q as usize);
        }
        // Each receiving span (whole consecutive patches, see `Row`) takes, patch by patch,
        // ρ × the shot's radiosity times F per element, and each patch its Σ F·A; spans own
        // disjoint elements and patches, so they may run in parallel, in chunks of
        // consecutive spans (one task per span cost more than the arithmetic). The chunks'
        // sums are then added in span order: the same numbers for any thread count.
        let per_chunk = (row.spans.len() / CHUNKS).max(MIN_SPANS_PER_CHUNK);
        let mut chunks: Vec<Chunk> = Vec::with_capacity(row.spans.len().div_ceil(per_chunk));
        let (mut radiosity, mut unshot) = (Carve::new(&mut self.radiosity), Carve::new(&mut self.unshot));
        let (mut power, mut abs) =
            (Carve::new(&mut self.patch_unshot_power), Carve::new(&mut self.patch_abs));
        let mut offset = 0;
        for spans in row.spans.chunks(per_chunk) {
            let first = spans[0].0 as usize;
            let (last, count) = spans[spans.len() - 1];
            let end = last as usize + count as usize;
            let (first_patch, end_patch) =
                (tables.element_patch[first] as usize, tables.element_patch[end - 1] as usize + 1);
            let (r, u) = (radiosity.take(first..end), unshot.take(first..end));
            let (p, a) = (power.take(first_patch..end_patch), abs.take(first_patch..end_patch));
            let factors: usize = spans.iter().map(|&(_, c)| c as usize).sum();
            chunks.push(Chunk {
                spans,
                factors: &row.factors[offset..offset + factors],
                radiosity: r,
                unshot: u,
                patches: (first_patch, p, a),
                took: Took::default(),
            });
            offset += factors;
        }
        let receive = |chunk: &mut Chunk| {
            let Chunk { spans, factors, radiosity, unshot, patches: (first_patch, power, abs), took } = chunk;
            let base = spans[0].0 as usize;
            let mut offset = 0;
            for_each_patch(tables, spans, |patch, elements| {
                let per_factor = tables.patch_reflectance[patch] * b_of(patch);
                let area = &tables.element_area[elements.clone()];
                let local = elements.start - base;
                let mut seen = Rgb::ZERO;
                for k in 0..elements.len() {
                    let f = f64::from(factors[offset + k]);
                    let m = gain_of(elements.start + k);
                    let reflected = per_factor * m * f; // ρ × irradiance from this shot, W/unit²
                    radiosity[local + k] += reflected;
                    unshot[local + k] += reflected;
                    seen += m * (f * area[k]);
                }
                offset += elements.len();
                let gained = tables.patch_reflectance[patch] * b_of(patch) * seen;
                let span_received = b_of(patch) * seen;
                took.received += span_received;
                took.absorbed += span_received - gained;
                let q = patch - *first_patch;
                power[q] += gained;
                let new = power[q].abs().sum();
                let delta = new - abs[q];
                abs[q] = new;
                took.abs_delta += delta;
                took.changed.push((patch as u32, delta));
            });
        };
        if mesh.elements.len() < APPLY_PARALLEL_MIN || rayon::current_num_threads() == 1 {
            chunks.iter_mut().for_each(receive);
        } else {
            chunks.par_iter_mut().for_each(receive);
        }
        let mut received = Rgb::ZERO;
        for chunk in chunks {
            let took = chunk.took;
            received += took.received;
            self.absorbed += took.absorbed;
            self.abs_total += took.abs_delta;
            self.changed.extend(took.changed);
        }
        // The near receivers: their own share in place of the (scaled) mean's.
        for (&(e, f, _, _), b) in near.receivers.iter().zip(&near_b) {
            let e = e as usize;
            let patch = tables.element_patch[e] as usize;
            let irradiance = (*b - shot_b) * f64::from(f);
            let reflected = tables.patch_reflectance[patch] * irradiance;
            self.radiosity[e] += reflected;
            self.unshot[e] += reflected;
            let area = tables.element_area[e];
            received += irradiance * area;
            self.absorbed += (irradiance - reflected) * area;
            self.patch_unshot_power[patch] += reflected * area;
            self.changed(patch);
        }
        // What left the shot unreceived escaped; a shot that delivered more than it carried
        // created the excess (per channel: a coloured shot can do one and not the other).
        let left = mean_b * area - received;
        self.escaped += left.map(|x| x.max(0.0));
        self.created += left.map(|x| (-x).max(0.0));
        self.tally_direct(tables, by, row, omega, near_scale * gain, grouped);
    }

    /// What a shot's row would deliver (irradiance × area, before any refund): to the
    /// receivers outside the group's near field (with the near receivers' own shares), and
    /// to those within it (see [`Shooters::near_reach`]; nothing for a patch's shot).
    #[allow(clippy::too_many_arguments)]
    fn delivered(
        &self,
        mesh: &Mesh,
        tables: &MeshTables,
        by: Shooters,
        row: &Row,
        near_b: &[Rgb],
        shot_b: Rgb,
        mean_b: Rgb,
        grouped: &[bool],
    ) -> (Rgb, Rgb) {
        let b_of = |patch: usize| if grouped[patch] { mean_b } else { shot_b };
        let is_near = |e: usize| match by.near_reach {
            Some((c, r)) => mesh.elements[e].centre.distance_squared(c) <= r * r,
            None => false,
        };
        let (mut far, mut near) = (Rgb::ZERO, Rgb::ZERO);
        let mut offset = 0;
        for_each_patch(tables, &row.spans, |patch, elements| {
            let (mut seen_far, mut seen_near) = (0.0, 0.0);
            for (k, e) in elements.clone().enumerate() {
                let x = f64::from(row.factors[offset + k]) * tables.element_area[e];
                if is_near(e) {
                    seen_near += x;
                } else {
                    seen_far += x;
                }
            }
            offset += elements.len();
            far += b_of(patch) * seen_far;
            near += b_of(patch) * seen_near;
        });
        for (&(e, f, _, _), b) in row.near.receivers.iter().zip(near_b) {
            far += (*b - shot_b) * f64::from(f) * tables.element_area[e as usize];
        }
        (far, near)
    }

    /// Adds to each receiver the part of this shot that is the shooter's own emission (its
    /// direct light), scaled as the shot's other receivers were (`scale`, but for the
    /// `grouped` facets; see `shoot`). Only emitters' shots carry any, so the extra pass is
    /// rare.
    fn tally_direct(
        &mut self,
        tables: &MeshTables,
        by: Shooters,
        row: &Row,
        omega: f64,
        scale: Rgb,
        grouped: &[bool],
    ) {
        let Shooters { patches: shooters, area, .. } = by;
        let emission: Rgb = shooters.iter().map(|&q| self.patch_unshot_emission[q as usize]).sum();
        if emission.max_channel() <= 0.0 {
            return;
        }
        let shot_e = emission * (omega / area);
        for &q in shooters {
            self.patch_unshot_emission[q as usize] *= 1.0 - omega;
        }
        let mut offset = 0;
        for_each_patch(tables, &row.spans, |patch, elements| {
            let per_factor =
                tables.patch_reflectance[patch] * if grouped[patch] { shot_e } else { shot_e * scale };
            let factors = &row.factors[offset..offset + elements.len()];
            for (direct, f) in self.direct[elements.clone()].iter_mut().zip(factors) {
                *direct += per_factor * f64::from(*f);
            }
            offset += elements.len();
        });
    }

    /// Power bookkeeping, with the unshot power summed fresh from the elements.
    pub(super) fn energy(&self, mesh: &Mesh) -> EnergyBalance {
        let unshot = self.unshot.iter().zip(&mesh.elements).map(|(u, el)| *u * el.area).sum();
        EnergyBalance {
            emitted: self.emitted,
            absorbed: self.absorbed,
            unshot,
            escaped: self.escaped,
            created: self.created,
        }
    }
}
