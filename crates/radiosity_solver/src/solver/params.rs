//! The solver's settings: [`SolverParams`] and the closed choices it holds.

use std::time::Duration;

use super::SolverError;

/// How the form factor from a receiving element to a shooting patch is computed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FormFactorMethod {
    /// Exact point-to-polygon form factor integrated over the receiver (accurate at any range).
    #[default]
    Exact,
    /// The source document's `cosθi cosθj A / (π r²)` between centres (wrong up close).
    PointToPoint,
}

/// Whether snapshots add the ambient term.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Ambient {
    /// Snapshots show only the light shot so far.
    #[default]
    Off,
    /// Snapshots add ρ_j · R · (unshot power / total area), R = 1/(1 − mean ρ) (Cohen 1988):
    /// a flat estimate of the light still to come, so early pictures are not too dark.
    On,
}

/// Whether shots over-relax.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum Overshoot {
    /// Shoot exactly the unshot radiosity.
    #[default]
    Off,
    /// Shoot ω times the unshot radiosity, ω in [1, 2).
    Relaxation(f64),
}

impl Overshoot {
    /// The over-relaxation factor ω a shot multiplies the unshot radiosity by (1 when off).
    pub(super) fn omega(self) -> f64 {
        match self {
            Overshoot::Off => 1.0,
            Overshoot::Relaxation(w) => w,
        }
    }
}

/// The row cache's least budget by default, bytes.
const AUTO_ROW_CACHE_BYTES: usize = 256 << 20;

/// Full rows (4 bytes per element) the default row cache has room for at least.
const AUTO_ROW_CACHE_ROWS: usize = 64;

/// Solver settings; every field has a unit, a range and a default.
#[derive(Clone, Debug, PartialEq)]
pub struct SolverParams {
    /// Form factor method. Default [`FormFactorMethod::Exact`].
    pub form_factor: FormFactorMethod,
    /// Visibility rays per receiving element from a bright shooter (see `bright_share`),
    /// ≥ 1. Default 8.
    pub visibility_rays: u32,
    /// More rays from a bright shooter for a receiver whose neighbours' first
    /// `visibility_rays` saw a penumbra (one of them partly lit, or some lit and some dark),
    /// 0 for none: this many from a shooter carrying half the emitted power or more, fewer in
    /// proportion to its share below that, at least 12 (its noise in a receiver scales with
    /// its share). Default 56: 64 rays in all for an element in a lamp's penumbra, whose own
    /// value the viewer and a baked export show (on the Cornell box its seed-to-seed noise
    /// is 9 % against 19 % with 12, for 2 % more solve time; see docs/PERFORMANCE.md).
    pub penumbra_rays: u32,
    /// Visibility rays per receiving element from a dim shooter, ≥ 1. Default 1.
    pub dim_rays: u32,
    /// A shooter is bright when its first shot carries at least this share of the power of
    /// the solve's first (largest) shot, in [0, 1]; 0 makes every shooter bright.
    ///
    /// Rays go where their noise shows: a shooter's visibility noise in a receiver scales
    /// with its power, and the many dim shooters' noises, independent, average out. On the
    /// Cornell box, many rays from the few bright shooters and one from each dim one give
    /// less seed-to-seed noise than a middling count from every shooter, for fewer rays and
    /// instructions; the surfaces lit by dim shooters only get a little noisier. Default 0.01.
    pub bright_share: f64,
    /// Largest receiver quadrature, Gauss cells per side, in 1..=256. Default 2: measured on
    /// the ρ = 0.9 furnaces (box, sphere), the worst element is within 3.7e-5 / 2.0e-5 of
    /// E/(1 − ρ) at 2 and 4.2e-5 / 4.5e-5 at 8 (the row sums, not the cells next to the
    /// shooter, limit the accuracy), and the Cornell box's objects move by at most 5.5e-4,
    /// while the source document's case (large facets, all near each other) runs several
    /// times faster.
    pub max_quadrature: u32,
    /// Stop when unshot power / emitted power ≤ this, in (0, 1). Default 1e-3.
    pub unshot_threshold: f64,
    /// Stop after this many shots. Default none.
    pub max_shots: Option<u64>,
    /// Stop after this much solving time. Default none.
    pub time_limit: Option<Duration>,
    /// Seed of every random stream. Default 0.
    pub seed: u64,
    /// Ambient term in snapshots. Default off.
    pub ambient: Ambient,
    /// Over-relaxation. Default off.
    pub overshoot: Overshoot,
    /// Turns off every shortcut meant to change only the speed, not the answer: per-patch
    /// shaft culling and candidate lists, and per-patch quadrature decisions. Each element
    /// then takes the plain path (its own quadrature choice, rays through the caller's ray
    /// structure), and no shooter's row of form factors is kept (see `row_cache_bytes`).
    /// For tests that the shortcuts give the same answer. Default false.
    pub reference_path: bool,
    /// Memory for keeping each shooter's row of form factors, in bytes. A patch is shot
    /// several times (Cornell: ~4), and its form factors and visibility are the same each
    /// time (its rays are drawn from a stream keyed by the shooter, not by the shot), so a
    /// kept row turns a later shot into one multiply-add per receiving element. Rows cost
    /// 4 bytes per receiving element; past the budget rows are recomputed, which gives the
    /// same numbers, only slower. `None` (the default): 256 MiB, or room for 64 full rows
    /// when that is more (a mesh of more than about a
    /// million elements: its rows are megabytes each, and with 64 of them the shooters that
    /// shoot most often keep theirs: a 954 k-triangle room solved in 85 s, not 181 s).
    pub row_cache_bytes: Option<usize>,
    /// Group the small facets of tessellated models into shooters of one cell each (see the
    /// solver's `clusters` module): the shots then follow the scene's extent, not its
    /// triangle count. Scenes of polygons and spheres have no such facets. Default true.
    pub clustering: bool,
    /// Far from a shooter that does not emit, the facets of a group share one visibility estimate of
    /// `SHARED_RAYS` rays instead of a ray each (see the solver's `shared` module): a row's
    /// rays then follow the groups, not the facets. Needs `clustering`. Default true.
    pub shared_visibility: bool,
}

impl Default for SolverParams {
    fn default() -> Self {
        Self {
            form_factor: FormFactorMethod::Exact,
            visibility_rays: 8,
            penumbra_rays: 56,
            dim_rays: 1,
            bright_share: 0.01,
            max_quadrature: 2,
            unshot_threshold: 1e-3,
            max_shots: None,
            time_limit: None,
            seed: 0,
            ambient: Ambient::Off,
            overshoot: Overshoot::Off,
            reference_path: false,
            row_cache_bytes: None,
            clustering: true,
            shared_visibility: true,
        }
    }
}

impl SolverParams {
    /// The row cache's budget in bytes for a mesh of `elements` elements (see
    /// `row_cache_bytes`).
    pub fn row_cache_budget(&self, elements: usize) -> usize {
        self.row_cache_bytes.unwrap_or_else(|| AUTO_ROW_CACHE_BYTES.max(AUTO_ROW_CACHE_ROWS * 4 * elements))
    }

    /// Fast and rough, for interactive previews: one visibility ray from every shooter,
    /// coarse quadrature, ambient term on, stop at 1 % unshot.
    pub fn preview() -> Self {
        Self {
            visibility_rays: 1,
            dim_rays: 1,
            max_quadrature: 1,
            unshot_threshold: 1e-2,
            ambient: Ambient::On,
            ..Self::default()
        }
    }

    /// Slow and accurate: 16 visibility rays and penumbra rays from every shooter, fine
    /// quadrature, stop at 0.01 % unshot.
    pub fn accurate() -> Self {
        Self {
            visibility_rays: 16,
            bright_share: 0.0,
            max_quadrature: 64,
            unshot_threshold: 1e-4,
            ..Self::default()
        }
    }

    /// Checks every field against its range.
    ///
    /// # Errors
    /// [`SolverError::BadParameter`] for the first field out of range.
    pub(super) fn validate(&self) -> Result<(), SolverError> {
        let bad = |name, value: String, expected| Err(SolverError::BadParameter { name, value, expected });
        if !(self.unshot_threshold > 0.0 && self.unshot_threshold < 1.0) {
            return bad("unshot_threshold", self.unshot_threshold.to_string(), "a number in (0, 1)");
        }
        if self.visibility_rays == 0 {
            return bad("visibility_rays", "0".into(), "at least 1");
        }
        if self.dim_rays == 0 {
            return bad("dim_rays", "0".into(), "at least 1");
        }
        if !(0.0..=1.0).contains(&self.bright_share) {
            return bad("bright_share", self.bright_share.to_string(), "a share in [0, 1]");
        }
        if self.max_quadrature == 0 || self.max_quadrature > 256 {
            return bad("max_quadrature", self.max_quadrature.to_string(), "1 to 256");
        }
        if let Overshoot::Relaxation(w) = self.overshoot
            && !(1.0..2.0).contains(&w)
        {
            return bad("overshoot", w.to_string(), "ω in [1, 2)");
        }
        if self.max_shots == Some(0) {
            return bad("max_shots", "0".into(), "at least 1");
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_are_valid_and_out_of_range_fields_are_named() {
        for p in [SolverParams::default(), SolverParams::preview(), SolverParams::accurate()] {
            assert_eq!(p.validate(), Ok(()));
        }
        let named = |p: SolverParams| match p.validate() {
            Err(SolverError::BadParameter { name, .. }) => name,
            other => panic!("{other:?}"),
        };
        assert_eq!(named(SolverParams { unshot_threshold: 1.0, ..Default::default() }), "unshot_threshold");
        assert_eq!(named(SolverParams { dim_rays: 0, ..Default::default() }), "dim_rays");
        assert_eq!(named(SolverParams { max_quadrature: 257, ..Default::default() }), "max_quadrature");
        assert_eq!(
            named(SolverParams { overshoot: Overshoot::Relaxation(2.0), ..Default::default() }),
            "overshoot"
        );
        assert_eq!(Overshoot::Off.omega(), 1.0);
        // The row cache: 256 MiB, or 64 full rows of a big mesh; a budget given is kept.
        let auto = SolverParams::default();
        assert_eq!(auto.row_cache_budget(10_000), 256 << 20);
        assert_eq!(auto.row_cache_budget(2_000_000), 64 * 4 * 2_000_000);
        assert_eq!(SolverParams { row_cache_bytes: Some(0), ..auto }.row_cache_budget(2_000_000), 0);
        assert_eq!(Overshoot::Relaxation(1.5).omega(), 1.5);
    }
}
