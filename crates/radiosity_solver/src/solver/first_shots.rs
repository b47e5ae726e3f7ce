//! What a shooter's first shot fixes for its shots: how its unshot power is spread over its
//! elements (where its rays end, whether it is uneven) and whether it is bright.
//!
//! A patch lit on one part only (half under a block, half in a shadow) then shoots from that
//! part instead of spreading its power over the dark part, whose rays would be blocked and
//! its light lost. The spread is kept for its later shots, so that they reuse the same rays
//! (and its row of form factors), until the spread of the power it has to shoot has moved
//! too far from it ([`FirstShots::refresh_if_drifted`]): then it is fixed again and the row
//! computed again. Its brightness stays that of its first shot.

use radiosity_mesh::Mesh;

use super::tally::Tally;
use super::uneven::NONUNIFORM;

/// Share of a patch's unshot power that must have moved between its elements since its spread
/// was fixed for the spread to be fixed again (and its row computed again).
///
/// A patch's first shot carries its direct light, with the shadows in it; later shots carry
/// light from the room, spread differently. A row kept from the first shot shoots the later
/// ones from where the first one's power was, and weights its near receivers by that spread:
/// the Cornell box's dark block faces, which see floor and wall patches whose shadowed part
/// is near them, came out 1.5–1.9 % dark (means over four seeds), every object within 0.86 %
/// with the spread fixed again past 0.2 (0.3: 1.2 %), for 1.3 times the rays.
pub(super) const DRIFT: f64 = 0.2;

/// A bright shooter carrying at least this share of the power the solve started with (the
/// emitted power) takes all of `SolverParams::penumbra_rays`; one carrying less, a part in
/// proportion (see [`FirstShots::penumbra_rays`]). A half: a lamp of one or two patches
/// takes them all (the Cornell box's is one); each patch of a lamp cut in four, half.
///
/// The visibility noise a shooter leaves in a receiver grows with its share s of the power
/// and falls as the square root of its rays n, and independent shooters' noises add in
/// quadrature: with n ∝ s, a lamp cut into patches leaves the noise one patch with all the
/// rays would, Σ s²/(c s) = 1/c. The seed room's lamp is four patches of a quarter: at a
/// fixed 56 its solve took 29 % longer for noise the quarters already average.
const FULL_PENUMBRA_SHARE: f64 = 0.5;

/// Least penumbra rays of a bright shooter (when `SolverParams::penumbra_rays` is not
/// fewer): the count the lit patches of the Cornell box were measured unbiased with
/// (`tests/suite/discretisation.rs::penumbra_rays_leave_direct_light_unbiased`).
const LEAST_PENUMBRA_RAYS: u32 = 12;

/// Per shooter, what its first shot fixed.
pub(super) struct FirstShots {
    /// Per element, the cumulative share of its patch's unshot power over the patch's
    /// elements, fixed at the patch's first shot and again when it drifts.
    cdf: Vec<f64>,
    /// Per patch, whether it has shot.
    frozen: Vec<bool>,
    /// Per element, its unshot radiosity over its patch's mean at the patch's first shot.
    density: Vec<f64>,
    /// Per patch, whether some element's density strays from 1 by more than [`NONUNIFORM`].
    nonuniform: Vec<bool>,
    /// Per patch, whether its first shot was bright (see `SolverParams::bright_share`).
    bright: Vec<bool>,
    /// Per patch, its first shot's share of [`Self::start_power`].
    share: Vec<f64>,
    /// The power the solve starts with unshot: the emitted power.
    pub(super) start_power: f64,
    /// Power of the solve's first shot, the largest.
    pub(super) first_shot_power: f64,
}

impl FirstShots {
    /// Nothing fixed yet, for `mesh` and the solve's `tally` at shot 0.
    pub(super) fn new(mesh: &Mesh, tally: &Tally) -> Self {
        let (n, patches) = (mesh.elements.len(), mesh.patches.len());
        Self {
            cdf: vec![0.0; n],
            frozen: vec![false; patches],
            density: vec![1.0; n],
            nonuniform: vec![false; patches],
            bright: vec![false; patches],
            share: vec![0.0; patches],
            start_power: tally.patch_unshot_power.iter().map(|p| p.abs().sum()).sum(),
            first_shot_power: 0.0,
        }
    }

    /// Fixes `shooter`'s spread and brightness from the tally, at its first shot (a later
    /// call changes nothing). `first_of_solve` marks the solve's first shot, whose power
    /// sets the scale of `bright_share`.
    pub(super) fn freeze(
        &mut self,
        mesh: &Mesh,
        shooter: usize,
        tally: &Tally,
        first_of_solve: bool,
        bright_share: f64,
    ) {
        if self.frozen[shooter] {
            return;
        }
        self.frozen[shooter] = true;
        // Bright or dim (see `SolverParams::bright_share`), by the first shot's power too: a
        // recomputed row must be the kept one.
        let power = tally.patch_unshot_power[shooter].abs().sum();
        if first_of_solve {
            self.first_shot_power = power;
        }
        self.bright[shooter] = power >= bright_share * self.first_shot_power;
        self.share[shooter] = if self.start_power > 0.0 { power / self.start_power } else { 0.0 };
        self.spread(mesh, shooter, tally);
    }

    /// Fixes `shooter`'s spread again when the spread of its unshot power has drifted from the
    /// fixed one by more than [`DRIFT`] (half the summed differences of the elements' shares:
    /// the share of its power that moved); whether it did. Its brightness stays.
    pub(super) fn refresh_if_drifted(&mut self, mesh: &Mesh, shooter: usize, tally: &Tally) -> bool {
        if !self.frozen[shooter] {
            return false;
        }
        let range = mesh.patches[shooter].elements.clone();
        let (first, end) = (range.start as usize, range.end as usize);
        let elements = &mesh.elements[first..end];
        let power = |k: usize| (tally.unshot[first + k] * elements[k].area).abs().sum();
        let total: f64 = (0..elements.len()).map(power).sum();
        if !(total > 0.0 && total.is_finite()) {
            return false;
        }
        let cdf = &self.cdf[first..end];
        let moved: f64 = (0..elements.len())
            .map(|k| (power(k) / total - (cdf[k] - if k == 0 { 0.0 } else { cdf[k - 1] })).abs())
            .sum::<f64>()
            / 2.0;
        if moved <= DRIFT {
            return false;
        }
        self.spread(mesh, shooter, tally);
        true
    }

    /// Fixes `shooter`'s spread (ray ends, densities, evenness) from the tally.
    fn spread(&mut self, mesh: &Mesh, shooter: usize, tally: &Tally) {
        let range = mesh.patches[shooter].elements.clone();
        let (first, end) = (range.start as usize, range.end as usize);
        let elements = &mesh.elements[first..end];
        let mut acc = 0.0;
        for ((c, u), el) in self.cdf[first..end].iter_mut().zip(&tally.unshot[first..end]).zip(elements) {
            acc += (*u * el.area).abs().sum();
            *c = acc;
        }
        if acc <= 0.0 || !acc.is_finite() {
            acc = 0.0;
            for (c, el) in self.cdf[first..end].iter_mut().zip(elements) {
                acc += el.area;
                *c = acc;
            }
        }
        for c in &mut self.cdf[first..end] {
            *c /= acc;
        }
        // Density of each element's share against an even spread: share_k · A_p / A_k.
        let area = mesh.patches[shooter].area;
        let mut below = 0.0;
        let mut nonuniform = false;
        for ((d, &c), el) in self.density[first..end].iter_mut().zip(&self.cdf[first..end]).zip(elements) {
            *d = (c - below) * area / el.area;
            below = c;
            nonuniform |= (*d - 1.0).abs() > NONUNIFORM;
        }
        self.nonuniform[shooter] = nonuniform;
    }

    /// The cumulative shares of `shooter`'s elements (see [`super::ray_ends`]).
    pub(super) fn cdf(&self, mesh: &Mesh, shooter: usize) -> &[f64] {
        let r = &mesh.patches[shooter].elements;
        &self.cdf[r.start as usize..r.end as usize]
    }

    /// The densities of `shooter`'s elements, when they are uneven.
    pub(super) fn uneven_density(&self, mesh: &Mesh, shooter: usize) -> Option<&[f64]> {
        let r = &mesh.patches[shooter].elements;
        self.nonuniform[shooter].then(|| &self.density[r.start as usize..r.end as usize])
    }

    /// Whether `shooter`'s first shot was bright.
    pub(super) fn bright(&self, shooter: usize) -> bool {
        self.bright[shooter]
    }

    /// The penumbra rays of `shooter` when bright, at most `most`: `most` from a share of
    /// [`FULL_PENUMBRA_SHARE`] of the emitted power up, a part in proportion below, at least
    /// [`LEAST_PENUMBRA_RAYS`]; rounded down to a count whose strata make a near-square grid
    /// (k × k or k × (k + 1): a prime count would stratify one axis only). Fixed at its first
    /// shot, like its brightness, so that a row computed again is the one kept.
    pub(super) fn penumbra_rays(&self, shooter: usize, most: u32) -> u32 {
        let wanted = (f64::from(most) * (self.share[shooter] / FULL_PENUMBRA_SHARE).min(1.0)) as u32;
        near_square(wanted.max(LEAST_PENUMBRA_RAYS).min(most))
    }
}

/// The largest count up to `n` of the form k × k or k × (k + 1) (`n` itself below 2).
fn near_square(n: u32) -> u32 {
    if n < 2 {
        return n;
    }
    let k = n.isqrt();
    if k * (k + 1) <= n { k * (k + 1) } else { k * k }
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiosity_core::Rgb;
    use radiosity_mesh::Mesh;
    use radiosity_scenes::two_plates;

    /// Penumbra rays follow the shooter's share of the emitted power: all of them from half
    /// of it up, a part in proportion below, never under the least (nor over the most), and
    /// always a near-square count.
    #[test]
    fn penumbra_rays_follow_the_share_of_the_power() {
        let scene = two_plates(1.0, 1.0, 0.5, 1.0);
        let mesh = Mesh::build(&scene, &radiosity_core::MeshParams::try_new(1.0, 0.25).unwrap()).unwrap();
        let mut shots = FirstShots::new(&mesh, &Tally::new(&mesh).unwrap());
        let rays = |shots: &mut FirstShots, share: f64, most: u32| {
            shots.share[0] = share;
            shots.penumbra_rays(0, most)
        };
        assert_eq!(rays(&mut shots, 1.0, 56), 56);
        assert_eq!(rays(&mut shots, 0.5, 56), 56);
        assert_eq!(rays(&mut shots, 0.25, 56), 25, "28 wanted, rounded down to 5 × 5");
        assert_eq!(rays(&mut shots, 0.01, 56), LEAST_PENUMBRA_RAYS);
        assert_eq!(rays(&mut shots, 1.0, 4), 4, "the most wins over the least");
        assert_eq!(rays(&mut shots, 1.0, 0), 0);
        for n in 2..200 {
            let k = near_square(n);
            let side = k.isqrt();
            assert!(k <= n && (side * side == k || side * (side + 1) == k), "{n} → {k}");
            assert!(near_square(n + 1) >= k);
        }
    }

    /// The receiving plate of two plates, one patch of 16 elements: its spread is fixed at its
    /// first shot, kept while its unshot power moves little, and fixed again (its ray ends
    /// following the power) once more than [`DRIFT`] of it has moved; its brightness stays.
    #[test]
    fn a_spread_is_fixed_again_when_the_power_moves() {
        let scene = two_plates(1.0, 1.0, 0.5, 1.0);
        let mesh = Mesh::build(&scene, &radiosity_core::MeshParams::try_new(1.0, 0.25).unwrap()).unwrap();
        let plate = (0..mesh.patches.len())
            .find(|&p| mesh.patches[p].elements.len() == 16)
            .expect("a 16-element patch");
        let range = mesh.patches[plate].elements.clone();
        let (first, end) = (range.start as usize, range.end as usize);
        let mut tally = Tally::new(&mesh).unwrap();
        let mut shots = FirstShots::new(&mesh, &tally);
        let set = |tally: &mut Tally, values: &dyn Fn(usize) -> f64| {
            for e in first..end {
                tally.unshot[e] = Rgb::splat(values(e - first));
            }
            tally.patch_unshot_power[plate] =
                (first..end).map(|e| tally.unshot[e] * mesh.elements[e].area).sum();
        };
        set(&mut tally, &|_| 1.0);
        assert!(!shots.refresh_if_drifted(&mesh, plate, &tally), "nothing fixed yet");
        shots.freeze(&mesh, plate, &tally, false, 0.01);
        let bright = shots.bright(plate);
        // A tenth of the power moves to the first element: kept.
        set(&mut tally, &|k| if k == 0 { 1.0 + 0.1 * 16.0 / 0.9 } else { 1.0 });
        assert!(!shots.refresh_if_drifted(&mesh, plate, &tally));
        // All of it on the first element: fixed again, every ray end there.
        set(&mut tally, &|k| if k == 0 { 1.0 } else { 0.0 });
        assert!(shots.refresh_if_drifted(&mesh, plate, &tally));
        assert!(
            shots.cdf(&mesh, plate).iter().all(|&c| (c - 1.0).abs() < 1e-12),
            "{:?}",
            shots.cdf(&mesh, plate)
        );
        assert!(shots.uneven_density(&mesh, plate).is_some());
        assert_eq!(shots.bright(plate), bright);
        assert!(!shots.refresh_if_drifted(&mesh, plate, &tally), "fixed where it now is");
    }
}
