//! What a shooter's first shot fixes for all its shots: how its unshot power is spread over
//! its elements (where its rays end, whether it is uneven) and whether it is bright.
//!
//! A patch lit on one part only (half under a block, half in a shadow) then shoots from that
//! part instead of spreading its power over the dark part, whose rays would be blocked and
//! its light lost. The spread is kept for its later shots, so that they reuse the same rays
//! (and its row of form factors); the light a patch receives later comes mostly the same way
//! as the first.

use radiosity_core::Mesh;

use super::tally::Tally;
use super::uneven::NONUNIFORM;

/// Per shooter, what its first shot fixed.
pub(super) struct FirstShots {
    /// Per element, the cumulative share of its patch's unshot power over the patch's
    /// elements, fixed at the patch's first shot.
    cdf: Vec<f64>,
    /// Per patch, whether it has shot.
    frozen: Vec<bool>,
    /// Per element, its unshot radiosity over its patch's mean at the patch's first shot.
    density: Vec<f64>,
    /// Per patch, whether some element's density strays from 1 by more than [`NONUNIFORM`].
    nonuniform: Vec<bool>,
    /// Per patch, whether its first shot was bright (see `SolverParams::bright_share`).
    bright: Vec<bool>,
    /// Power of the solve's first shot, the largest.
    pub(super) first_shot_power: f64,
}

impl FirstShots {
    /// Nothing fixed yet, for `mesh`.
    pub(super) fn new(mesh: &Mesh) -> Self {
        let (n, patches) = (mesh.elements.len(), mesh.patches.len());
        Self {
            cdf: vec![0.0; n],
            frozen: vec![false; patches],
            density: vec![1.0; n],
            nonuniform: vec![false; patches],
            bright: vec![false; patches],
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
}
