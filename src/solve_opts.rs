//! The options every command that meshes and solves a scene shares, as the command line
//! spells them, and their limits.

use clap::{Args, ValueEnum};
use radiosity_solver::{FormFactorMethod, Overshoot, SolverParams};

/// Most visibility, penumbra or dim rays per receiver: 1024 is 64× the `accurate()` preset's
/// count, far past where more rays change an answer, and keeps a shot's ray count (rays ×
/// receivers) within what a run can finish.
pub const MAX_RAYS: u32 = 1024;

/// Most worker threads: beyond what any machine this runs on has, low enough that asking
/// for them is a mistake to report rather than thousands of threads to spawn.
pub const MAX_THREADS: usize = 1024;

/// Largest emission × light scale, W/m²: far above any physical light (the sun's surface
/// gives 6.3e7), low enough that radiosity sums over many bounces and elements stay finite.
pub const MAX_EMISSION: f64 = 1e30;

/// Form factor choice on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum FormFactorArg {
    /// Exact point-to-polygon, integrated over the receiver.
    Exact,
    /// The source document's point-to-point formula (inaccurate up close).
    Point,
}

/// Help of every command's SCENE argument: each form [`radiosity_io::resolve_scene_with`]
/// takes, so that none of them is a surprise.
pub const SCENE_HELP: &str = "A scene file (.toml), a model file (.obj with its .mtl, .gltf, .glb) or a built-in \
                              name (cornell, furnace, seed-room, two-plates)";

/// Options that decide the mesh, shared by every command that meshes a scene; each
/// overrides the scene file. `info` takes only these: it counts, it does not solve.
#[derive(Args, Clone, Debug)]
pub struct MeshOpts {
    /// Longest patch edge, scene units (overrides the scene's `[mesh]`).
    #[arg(long, allow_negative_numbers = true)]
    pub patch_size: Option<f64>,
    /// Longest element edge, scene units (overrides the scene's `[mesh]`).
    #[arg(long, allow_negative_numbers = true)]
    pub element_size: Option<f64>,
    /// Smooth shading joins the facets of one object whose normals differ by less than this,
    /// degrees in [0, 180); 0 shades every facet on its own [default: the scene's `[mesh]`
    /// crease_angle, else 40].
    #[arg(long, allow_negative_numbers = true, value_name = "DEGREES")]
    pub crease_angle: Option<f64>,
    /// Sides of every object from a model file (an OBJ or glTF given as SCENE, `mesh`
    /// objects): 1 (front faces only) or 2 (both faces receive and reflect), over what the
    /// file and the scene file say [default: OBJ two-sided, glTF as its doubleSided flag].
    #[arg(long, value_parser = clap::value_parser!(u8).range(1..=2), value_name = "1|2")]
    pub sides: Option<u8>,
    /// The model's up axis: x, y, z, -x, -y or -z (architectural and CAD models are mostly z
    /// up). The scene is turned so that it stands upright; coordinates you give
    /// (--camera-position, --look-at) and get back (PLY, lightmap OBJ, element centres) stay
    /// in the file's frame, glTF output is +y up by its spec [default: the scene file's `up`,
    /// else y].
    #[arg(long, value_name = "AXIS", allow_hyphen_values = true)]
    pub up: Option<String>,
    /// The length unit of the scene's coordinates: m, cm, mm, in or ft; lux and cd/m² are
    /// reported with it [default: the scene file's `units`, else m].
    #[arg(long, value_name = "UNIT")]
    pub units: Option<String>,
    /// Cut surfaces along the outlines of solids standing on them (a block on the floor) and
    /// leave the covered part out of the solve [default: the scene's `[mesh]` contacts, else
    /// true].
    #[arg(long, value_name = "true|false")]
    pub contacts: Option<bool>,
    /// Cut surfaces along the outlines of the penumbrae and umbrae that convex solids (a
    /// block, a box) cast from the bright emitters and luminaires, so shadow edges fall on
    /// element edges
    /// [default: the scene's `[mesh]` shadow_outlines, else true].
    #[arg(long, value_name = "true|false")]
    pub shadow_outlines: Option<bool>,
    /// Halve the elements along inside corners (a wall meeting the floor, a block on it) this
    /// many times towards the corner, 0 to 6; 0 grades nothing [default: the scene's `[mesh]`
    /// corner_refinement, else 2].
    #[arg(long, value_name = "LEVELS")]
    pub corner_refinement: Option<u32>,
    /// Quarter the elements that other geometry comes nearer to than half their size (a wall
    /// behind a model, a board under the next shelf) this many times, 0 to 4; 0: none
    /// [default: the scene's `[mesh]` proximity_refinement, else 1].
    #[arg(long, value_name = "LEVELS")]
    pub proximity_refinement: Option<u32>,
    /// Quarter the elements where the light changes steeply (shadow edges), found by a quick
    /// probe solve, this many times, 0 to 4; 0: none [default: the scene's `[mesh]`
    /// adaptive_levels, else 2].
    #[arg(long, value_name = "LEVELS")]
    pub adaptive_levels: Option<u32>,
}

/// Options shared by every command that solves; each overrides the scene file.
#[derive(Args, Clone, Debug)]
pub struct SolveOpts {
    #[command(flatten)]
    pub mesh: MeshOpts,
    /// Stop when unshot power / emitted power falls to this, in (0, 1) [default: the scene's
    /// `[solver]`, else the solver's default, 1e-3].
    #[arg(long, allow_negative_numbers = true)]
    pub unshot_threshold: Option<f64>,
    /// Stop after this many shots.
    #[arg(long)]
    pub max_shots: Option<u64>,
    /// Stop after this many seconds of solving, in (0, 1e9].
    #[arg(long, allow_negative_numbers = true)]
    pub time_limit: Option<f64>,
    /// Multiply every emission and every luminaire's intensity by this (the light intensity).
    #[arg(long, allow_negative_numbers = true, default_value_t = 1.0)]
    pub light_scale: f64,
    /// Worker threads, 1 to 1024 (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Seed of the visibility sampling.
    #[arg(long, default_value_t = SolverParams::default().seed)]
    pub seed: u64,
    /// Form factor method.
    #[arg(long, value_enum, default_value_t = FormFactorArg::from(SolverParams::default().form_factor))]
    pub form_factor: FormFactorArg,
    /// Visibility rays per receiver from a bright shooter (see --bright-share), 1 to 1024.
    #[arg(long, default_value_t = SolverParams::default().visibility_rays)]
    pub visibility_rays: u32,
    /// More rays from a bright shooter for a receiver whose neighbours' first visibility rays
    /// saw a penumbra; 0: none; at most 1024.
    #[arg(long, default_value_t = SolverParams::default().penumbra_rays)]
    pub penumbra_rays: u32,
    /// Visibility rays per receiver from a dim shooter, 1 to 1024.
    #[arg(long, default_value_t = SolverParams::default().dim_rays)]
    pub dim_rays: u32,
    /// A shooter is bright when its first shot carries at least this share of the first
    /// (largest) shot's power; 0: every shooter is.
    #[arg(long, allow_negative_numbers = true, default_value_t = SolverParams::default().bright_share, value_name = "SHARE")]
    pub bright_share: f64,
    /// Let the small facets of a tessellated model shoot in groups of one cell (1/16 of the
    /// scene's diagonal) each, so that a model's shots follow its size and not its triangle
    /// count; false: every facet shoots on its own.
    #[arg(long, value_name = "true|false", default_value_t = SolverParams::default().clustering, action = clap::ArgAction::Set)]
    pub clusters: bool,
    /// Let the facets of a group far from a shooter that does not emit share one visibility estimate of a
    /// few rays instead of a ray each (needs `--clusters true`); false: a ray per facet.
    #[arg(long, value_name = "true|false", default_value_t = SolverParams::default().shared_visibility, action = clap::ArgAction::Set)]
    pub shared_visibility: bool,
    /// Memory for keeping each shooter's form factors for its next shots, in MiB (0: keep
    /// none; the answer is the same, only slower). Default: 256, or room for 64 rows of form
    /// factors (4 bytes per element each) when the mesh is bigger.
    #[arg(long, value_name = "MIB")]
    pub row_cache_mib: Option<usize>,
    /// Over-relaxation factor ω in [1, 2) (1: plain shooting).
    #[arg(long, allow_negative_numbers = true, default_value_t = overshoot_factor(SolverParams::default().overshoot))]
    pub overshoot: f64,
    /// Add the ambient term (Cohen 1988) to the reported solution (the solver's default is
    /// off).
    #[arg(long)]
    pub ambient: bool,
}

impl SolveOpts {
    /// The solve options of a command line that gives only `mesh` and `light_scale`: every
    /// other option at the default its `#[arg]` declares, so the defaults live in one place.
    pub fn with_mesh(mesh: MeshOpts, light_scale: f64) -> Self {
        /// A command line of solve options alone, to read their defaults from.
        #[derive(clap::Parser)]
        struct Defaults {
            #[command(flatten)]
            solve: SolveOpts,
        }
        let defaults = <Defaults as clap::Parser>::parse_from(["radiosity"]).solve;
        SolveOpts { mesh, light_scale, ..defaults }
    }
}

impl From<FormFactorMethod> for FormFactorArg {
    fn from(m: FormFactorMethod) -> Self {
        match m {
            FormFactorMethod::Exact => FormFactorArg::Exact,
            FormFactorMethod::PointToPoint => FormFactorArg::Point,
        }
    }
}

/// The over-relaxation factor ω of an [`Overshoot`] (1 when off).
fn overshoot_factor(o: Overshoot) -> f64 {
    match o {
        Overshoot::Off => 1.0,
        Overshoot::Relaxation(w) => w,
    }
}
