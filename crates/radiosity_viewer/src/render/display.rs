//! What the surfaces show and how: the display modes, the subdivision overlay, how much of a
//! big mesh is drawn, and the false-colour scale shared by the shader and the legend.

use radiosity_core::Rgb;
use radiosity_image::ToneOperator;
use radiosity_mesh::Mesh;
use radiosity_solver::Solution;

/// The operator's id in the shader (`OP_*` in `tonemap.wgsl`).
pub fn shader_operator(op: ToneOperator) -> u32 {
    match op {
        ToneOperator::Linear => 0,
        ToneOperator::Reinhard => 1,
        ToneOperator::Aces => 2,
    }
}

/// What the surfaces show.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DisplayMode {
    /// Vertex radiosity interpolated across elements, tone mapped.
    #[default]
    Smooth,
    /// Each element's own radiosity, tone mapped: shows the subdivision.
    FlatElements,
    /// False colour of log luminance of the (smooth) radiosity, with a legend.
    FalseColour,
    /// False colour of each element's unshot radiosity ΔB: where light still waits.
    Unshot,
    /// False colour of log illuminance, the light arriving ([`irradiance_of`]): lux in a
    /// photometric scene, what a lighting designer reads.
    Illuminance,
}

impl DisplayMode {
    /// Every mode, in panel order.
    pub const ALL: [DisplayMode; 5] = [
        DisplayMode::Smooth,
        DisplayMode::FlatElements,
        DisplayMode::FalseColour,
        DisplayMode::Illuminance,
        DisplayMode::Unshot,
    ];

    /// Label in the panel.
    pub fn label(self) -> &'static str {
        match self {
            DisplayMode::Smooth => "smooth",
            DisplayMode::FlatElements => "flat elements",
            DisplayMode::FalseColour => "false colour",
            DisplayMode::Unshot => "unshot energy",
            DisplayMode::Illuminance => "illuminance",
        }
    }

    /// One sentence for the panel's tooltip.
    pub fn description(self) -> &'static str {
        match self {
            DisplayMode::Smooth => "vertex radiosity interpolated across elements, as `render` shows it",
            DisplayMode::FlatElements => "each element's own radiosity: shows the subdivision",
            DisplayMode::FalseColour => "log luminance of the radiosity on a colour scale, with a legend",
            DisplayMode::Unshot => "radiosity still waiting to be shot, on a log colour scale",
            DisplayMode::Illuminance => {
                "the light arriving, (B − emission) / ρ, on a log colour scale: lux in a scene with units \
                 (black surfaces show none)"
            }
        }
    }

    /// Whether the mode is drawn in false colour with a legend.
    pub fn is_false_colour(self) -> bool {
        matches!(self, DisplayMode::FalseColour | DisplayMode::Unshot | DisplayMode::Illuminance)
    }
}

/// Which subdivision lines are drawn over the surfaces.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wireframe {
    /// None.
    #[default]
    Off,
    /// Patch outlines (the shooters).
    Patches,
    /// Element outlines, patch outlines on top.
    Elements,
}

impl Wireframe {
    /// Every choice, in panel order.
    pub const ALL: [Wireframe; 3] = [Wireframe::Off, Wireframe::Patches, Wireframe::Elements];

    /// Label in the panel.
    pub fn label(self) -> &'static str {
        match self {
            Wireframe::Off => "off",
            Wireframe::Patches => "patches",
            Wireframe::Elements => "elements",
        }
    }

    /// The overlay's bits in the shader (`wire` in `scene.wgsl`).
    pub(super) fn shader_bits(self) -> u32 {
        match self {
            Wireframe::Off => 0,
            Wireframe::Patches => 2,
            Wireframe::Elements => 3,
        }
    }
}

/// How much of a big mesh is drawn (see [`crate::coarse`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Detail {
    /// On a CPU rasteriser, the coarse copy while the camera moves or the solve runs and the
    /// whole mesh once the view rests; on a GPU, always the whole mesh.
    #[default]
    Auto,
    /// Always every element.
    Full,
    /// Always the coarse copy (when the mesh has one).
    Coarse,
}

impl Detail {
    /// Every choice, in panel order.
    pub const ALL: [Detail; 3] = [Detail::Auto, Detail::Full, Detail::Coarse];

    /// Label in the panel.
    pub fn label(self) -> &'static str {
        match self {
            Detail::Auto => "auto",
            Detail::Full => "full",
            Detail::Coarse => "coarse",
        }
    }
}

/// The irradiance (W/unit²) at a point of element `e` of `mesh` whose radiosity is `b`:
/// E = (B − emission) / ρ per channel (B = emission + ρE), none where ρ is 0 (what a black
/// surface receives cannot be read back from its radiosity).
pub fn irradiance_of(mesh: &Mesh, e: usize, b: Rgb) -> Rgb {
    let m = mesh.element_material(e);
    (b - m.emission).zip_map(m.reflectance, |x, r| if r > 0.0 { (x / r).max(0.0) } else { 0.0 })
}

/// The false-colour range, log10 of luminance, of what `mode` shows on `mesh`: four decades
/// below the brightest value (a dark corner must not squash the whole scale), or `(−1, 0)`
/// when nothing is lit yet.
pub fn false_colour_range(solution: &Solution, mesh: &Mesh, mode: DisplayMode) -> (f64, f64) {
    let irradiance: Vec<Rgb>;
    let values: &[Rgb] = match mode {
        DisplayMode::Unshot => &solution.element_unshot,
        DisplayMode::Illuminance if solution.element_radiosity.len() == mesh.elements.len() => {
            irradiance = solution
                .element_radiosity
                .iter()
                .enumerate()
                .map(|(e, b)| irradiance_of(mesh, e, *b))
                .collect();
            &irradiance
        }
        _ => &solution.vertex_radiosity,
    };
    let max = values.iter().map(|c| c.abs().luminance()).filter(|l| l.is_finite()).fold(0.0, f64::max);
    if max <= 0.0 {
        return (-1.0, 0.0);
    }
    let min = values
        .iter()
        .map(|c| c.abs().luminance())
        .filter(|l| l.is_finite() && *l > 0.0)
        .fold(max, f64::min)
        .max(max * 1e-4);
    let (lo, hi) = (min.log10(), max.log10());
    if hi - lo < 1e-3 { (hi - 0.5, hi + 0.5) } else { (lo, hi) }
}

/// The Turbo false-colour ramp at t in [0, 1], display values in [0, 1]; the same polynomial
/// as `false_colour` in `tonemap.wgsl` (for the legend drawn by egui).
pub fn false_colour(t: f64) -> [f64; 3] {
    let t = t.clamp(0.0, 1.0);
    let v = [1.0, t, t * t, t * t * t, t.powi(4), t.powi(5)];
    let dot = |k: [f64; 6]| v.iter().zip(k).map(|(a, b)| a * b).sum::<f64>().clamp(0.0, 1.0);
    [
        dot([0.13572138, 4.61539260, -42.66032258, 132.13108234, -152.94239396, 59.28637943]),
        dot([0.09140261, 2.19418839, 4.84296658, -14.18503333, 4.27729857, 2.82956604]),
        dot([0.10667330, 12.64194608, -60.58204836, 110.36276771, -89.90310912, 27.34824973]),
    ]
}
