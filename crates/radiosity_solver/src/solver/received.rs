//! What a receiving element learns from a shooter: its form factor without visibility and
//! what its rays saw ([`Received`]), and one set of rays' count ([`Seen`]). Plain data that
//! the passes of a row fill and the penumbra decision reads.

/// What one element learns from one shooter's first pass: its form factor without
/// visibility, and its pilot rays.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Received {
    /// F_{e→shooter} without visibility (weighted for uneven shooters); 0 when it cannot
    /// receive.
    pub(super) unoccluded: f64,
    /// The same before the uneven shooter's weighting (equal to `unoccluded` otherwise).
    pub(super) unweighted: f64,
    /// Unblocked rays among `traced`.
    pub(super) visible: u32,
    /// Rays traced; 0 when the pair needs none (nothing can block it).
    pub(super) traced: u32,
    /// Σ of the unblocked rays' kernel weights (see [`Seen`]).
    pub(super) kernel_visible: f32,
    /// Σ of the traced rays' kernel weights; 0 when the rays carry none (the visibility is
    /// then the plain fraction `visible / traced`).
    pub(super) kernel_traced: f32,
}

/// What an element's rays to the shooter saw: how many were unblocked of how many traced,
/// and the same weighted by each ray's form factor kernel (see [`super::rays::draw`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Seen {
    /// Unblocked rays.
    pub(super) visible: u32,
    /// Rays traced.
    pub(super) traced: u32,
    /// Σ kernel weight of the unblocked rays.
    pub(super) kernel_visible: f32,
    /// Σ kernel weight of all rays.
    pub(super) kernel_traced: f32,
}

impl Seen {
    /// One more ray of kernel weight `weight`, unblocked or not.
    pub(super) fn add(&mut self, unblocked: bool, weight: f32) {
        self.traced += 1;
        self.kernel_traced += weight;
        if unblocked {
            self.visible += 1;
            self.kernel_visible += weight;
        }
    }
}

impl std::ops::AddAssign<Seen> for Received {
    fn add_assign(&mut self, seen: Seen) {
        self.visible += seen.visible;
        self.traced += seen.traced;
        self.kernel_visible += seen.kernel_visible;
        self.kernel_traced += seen.kernel_traced;
    }
}

impl Received {
    /// The element's form factor with visibility.
    pub(super) fn factor(&self) -> f64 {
        self.unoccluded * self.visibility()
    }

    /// The form factor with visibility, before the uneven shooter's weighting.
    pub(super) fn unweighted_factor(&self) -> f64 {
        self.unweighted * self.visibility()
    }

    /// The unblocked share of the transfer: each ray counted by its form factor kernel
    /// (Σ K V / Σ K), or by one where the rays carry no weights.
    fn visibility(&self) -> f64 {
        if self.traced == 0 {
            1.0
        } else if self.kernel_traced > 0.0 {
            f64::from(self.kernel_visible) / f64::from(self.kernel_traced)
        } else {
            f64::from(self.visible) / f64::from(self.traced)
        }
    }
}
