//! What every command that solves shares: the solve options, loading and meshing a scene,
//! and running the solver with a progress bar.

use std::time::Duration;

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};
use radiosity_core::{MeshParams, Scene, UpAxis};

use crate::progress::{Progress, spinning};
use radiosity_solver::{
    Ambient, FormFactorMethod, Overshoot, Problem, Solver, SolverParams, StepBudget, StepReport,
};

/// An error in what the user gave us (a file, an option): exit code 2.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct InputError(pub String);

/// Exit code for an error: 2 for bad input, 1 for anything else.
pub fn exit_code(e: &anyhow::Error) -> u8 {
    let input = e.chain().any(|c| {
        c.is::<InputError>()
            || c.is::<radiosity_io::LoadError>()
            || c.is::<radiosity_core::SceneError>()
            || c.is::<radiosity_core::MeshError>()
            || c.is::<radiosity_solver::SolverError>()
            || c.is::<radiosity_image::RenderError>()
    });
    if input { 2 } else { 1 }
}

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
    /// block, a box) cast from the bright emitters, so shadow edges fall on element edges
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
    /// Multiply every emission by this (the light intensity).
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

/// A scene ready to solve.
pub struct Prepared {
    /// The scene as loaded (light scale applied).
    pub scene: Scene,
    /// Its mesh and the ray queries over its occluders.
    pub problem: Problem,
    /// Solver settings from the scene and the options.
    pub params: SolverParams,
    /// The up axis of the file the scene came from: the scene itself is turned +y up, and
    /// coordinates given or reported go through [`UpAxis::to_y_up`] and back.
    pub up: UpAxis,
}

fn input(msg: String) -> anyhow::Error {
    InputError(msg).into()
}

/// A scene with every solve option checked and turned into parameters, not yet meshed.
pub struct Settings {
    /// The scene as loaded; the light scale is NOT applied yet (callers apply it when they
    /// mesh, so the viewer can change it live).
    pub scene: Scene,
    /// Subdivision from the scene and the options.
    pub mesh_params: MeshParams,
    /// Solver settings from the scene and the options.
    pub solver_params: SolverParams,
    /// The file's up axis ([`Prepared::up`]).
    pub up: UpAxis,
}

/// Loads `scene_arg` (a scene file, a model file — `.obj`, `.gltf`, `.glb` — or a built-in
/// name) and checks the options against it: the one
/// place where command-line solve options become parameters.
///
/// # Errors
/// Bad scene files and out-of-range options (exit code 2).
pub fn settings(scene_arg: &str, o: &SolveOpts) -> Result<Settings> {
    let (settings, no_light) = load_settings(scene_arg, o)?;
    // Said after the loader's warnings, which often explain it (a missing MTL).
    match no_light {
        Some(e) => Err(e.into()),
        None => Ok(settings),
    }
}

/// [`settings`] for a command that describes a scene rather than solving it: a scene in which
/// nothing emits loads, with the error a solve would give.
///
/// # Errors
/// As [`settings`], except a missing light.
pub fn load_settings(scene_arg: &str, o: &SolveOpts) -> Result<(Settings, Option<radiosity_io::LoadError>)> {
    if let Some(t) = o.threads
        && !(1..=MAX_THREADS).contains(&t)
    {
        return Err(input(format!("--threads must be 1 to {MAX_THREADS}, got {t}")));
    }
    for (option, value, least) in [
        ("--visibility-rays", o.visibility_rays, 1),
        ("--penumbra-rays", o.penumbra_rays, 0),
        ("--dim-rays", o.dim_rays, 1),
    ] {
        if !(least..=MAX_RAYS).contains(&value) {
            return Err(input(format!("{option} must be {least} to {MAX_RAYS}, got {value}")));
        }
    }
    let up = o.mesh.up.as_deref().map(parse_up).transpose()?;
    let units = o.mesh.units.as_deref().map(parse_units).transpose()?;
    // A model file given where a scene is expected loads as a scene of its parts; what the
    // loader dropped or defaulted (degenerate faces, a missing MTL) is said once, here.
    let options = radiosity_io::LoadOptions {
        model_sides: o.mesh.sides.map(|n| match n {
            1 => radiosity_core::Sides::One,
            _ => radiosity_core::Sides::Two { emits_back: false },
        }),
        // A missing light is returned after the warnings are out, not in place of them.
        allow_no_light: true,
        up,
        units,
    };
    let radiosity_io::LoadedScene { mut scene, warnings, no_light, up } =
        spinning(&format!("loading {scene_arg}"), || radiosity_io::resolve_scene_with(scene_arg, &options))?;
    for w in &warnings {
        crate::output::note(format_args!("warning: {w}"))?;
    }
    // A building model from an architectural tool is mostly z up and would lie on its side:
    // say which flag stands it up, unless an up axis was declared.
    if up.is_none()
        && let Some(guess) = scene.likely_up()
    {
        crate::output::note(format_args!(
            "note: the scene looks {up} up ({reason}) but is read +y up; if it lies on its side, add --up {up} (or up = \"{up}\" in a scene file)",
            up = guess.up,
            reason = guess.reason
        ))?;
    }
    let up = up.unwrap_or_default();
    if o.mesh.sides.is_none() {
        let sealed = spinning("finding closed models", || radiosity_core::seal_closed_objects(&mut scene));
        let names = |keep: fn(&radiosity_core::Sealed) -> bool| {
            let objects: Vec<usize> = sealed.iter().filter(|s| keep(s)).map(|s| s.object).collect();
            (!objects.is_empty()).then(|| name_list(&scene, &objects))
        };
        if let Some(closed) = names(|s| s.hole_share == 0.0) {
            crate::output::note(format_args!(
                "note: {closed} closed with the light on one side only: meshed one-sided, no light reaches the other (--sides 2 meshes both faces)"
            ))?;
        }
        if let Some(turned) = names(|s| s.turned) {
            crate::output::note(format_args!(
                "note: {turned} wound with the light on the back of every face: turned over"
            ))?;
        }
        if let Some(holed) = names(|s| s.hole_share > 0.0) {
            let widest = sealed.iter().map(|s| s.hole_share).fold(0.0, f64::max);
            crate::output::note(format_args!(
                "note: {holed} closed but for small holes (at most {:.1} % of the area) with the light on one side only: meshed one-sided, the light through the holes absorbed (--sides 2 meshes both faces)",
                widest * 100.0
            ))?;
        }
    }
    if !(o.light_scale.is_finite() && o.light_scale > 0.0) {
        return Err(input(format!("--light-scale must be a finite number > 0, got {}", o.light_scale)));
    }
    check_light_scale(&scene, o.light_scale)?;
    let base = scene.mesh_params();
    let patch = o.mesh.patch_size.unwrap_or(base.patch_size);
    let element = o.mesh.element_size.unwrap_or(if o.mesh.patch_size.is_some() {
        patch.min(base.element_size)
    } else {
        base.element_size
    });
    let mesh_params = MeshParams::try_new(patch, element)
        .and_then(|m| m.with_crease_angle(o.mesh.crease_angle.unwrap_or(base.crease_angle_deg)))
        .map(|m| m.with_contacts(o.mesh.contacts.unwrap_or(base.contacts)))
        .map(|m| m.with_shadow_outlines(o.mesh.shadow_outlines.unwrap_or(base.shadow_outlines)))
        .and_then(|m| m.with_corner_refinement(o.mesh.corner_refinement.unwrap_or(base.corner_refinement)))
        .and_then(|m| {
            m.with_proximity_refinement(o.mesh.proximity_refinement.unwrap_or(base.proximity_refinement))
        })
        .and_then(|m| m.with_adaptive_levels(o.mesh.adaptive_levels.unwrap_or(base.adaptive_levels)))
        .map_err(|e| input(format!("mesh options: {e}")))?;
    // The scene file's limit is checked (with its line) by the loader; this is the option's.
    let time_limit = match o.time_limit.or(scene.solver.time_limit) {
        Some(t) if t > 0.0 && t <= radiosity_core::MAX_TIME_LIMIT_SECONDS => Some(Duration::from_secs_f64(t)),
        Some(t) => {
            return Err(input(format!(
                "--time-limit must be a number of seconds in (0, {:e}], got {t}",
                radiosity_core::MAX_TIME_LIMIT_SECONDS
            )));
        }
        None => None,
    };
    if let Some(t) = o.unshot_threshold
        && !(t > 0.0 && t < 1.0)
    {
        return Err(input(format!("--unshot-threshold must be a fraction in (0, 1), got {t}")));
    }
    if o.max_shots == Some(0) {
        return Err(input("--max-shots must be at least 1".into()));
    }
    if !(0.0..=1.0).contains(&o.bright_share) {
        return Err(input(format!("--bright-share must be a share in [0, 1], got {}", o.bright_share)));
    }
    if !(1.0..2.0).contains(&o.overshoot) {
        return Err(input(format!("--overshoot must be ω in [1, 2), got {}", o.overshoot)));
    }
    let defaults = SolverParams::default();
    let solver_params = SolverParams {
        form_factor: match o.form_factor {
            FormFactorArg::Exact => FormFactorMethod::Exact,
            FormFactorArg::Point => FormFactorMethod::PointToPoint,
        },
        visibility_rays: o.visibility_rays,
        penumbra_rays: o.penumbra_rays,
        dim_rays: o.dim_rays,
        bright_share: o.bright_share,
        unshot_threshold: o
            .unshot_threshold
            .or(scene.solver.unshot_threshold)
            .unwrap_or(defaults.unshot_threshold),
        max_shots: o.max_shots.or(scene.solver.max_shots),
        time_limit,
        seed: o.seed,
        ambient: if o.ambient { Ambient::On } else { Ambient::Off },
        overshoot: if o.overshoot == 1.0 { Overshoot::Off } else { Overshoot::Relaxation(o.overshoot) },
        row_cache_bytes: o.row_cache_mib.map(|mib| mib.saturating_mul(1 << 20)),
        clustering: o.clusters,
        shared_visibility: o.shared_visibility,
        ..defaults
    };
    Ok((Settings { scene, mesh_params, solver_params, up }, no_light))
}

/// `--units`' unit.
///
/// # Errors
/// Any other name, listing the accepted ones (exit code 2).
fn parse_units(name: &str) -> Result<radiosity_core::LengthUnit> {
    radiosity_core::LengthUnit::parse(name)
        .ok_or_else(|| input(format!("--units must be one of m, cm, mm, in, ft, got '{name}'")))
}

/// `--up`'s axis.
///
/// # Errors
/// Any other name, listing the accepted ones (exit code 2).
fn parse_up(name: &str) -> Result<UpAxis> {
    UpAxis::parse(name)
        .ok_or_else(|| input(format!("--up must be one of {}, got '{name}'", UpAxis::NAMES.join(", "))))
}

/// The names of `objects` of `scene`, quoted, the first three and a count of the rest.
fn name_list(scene: &Scene, objects: &[usize]) -> String {
    let mut names: Vec<String> =
        objects.iter().take(3).map(|&i| format!("'{}'", scene.objects[i].name)).collect();
    if objects.len() > 3 {
        names.push(format!("{} more", objects.len() - 3));
    }
    let verb = if objects.len() == 1 { "is" } else { "are" };
    format!("{} {verb}", names.join(", "))
}

/// [`settings`], then the light scale and the [`Problem`] (mesh and ray queries); sets the
/// global thread pool when `--threads` is given.
///
/// # Errors
/// Bad scene files, out-of-range options, meshes that would be too large (exit code 2).
pub fn prepare(scene_arg: &str, o: &SolveOpts) -> Result<Prepared> {
    mesh(scene_arg, settings(scene_arg, o)?, o)
}

/// [`prepare`] for a command that describes a scene: one without a light is meshed too,
/// with the error a solve would give.
///
/// # Errors
/// As [`prepare`], except a missing light.
pub fn prepare_unlit(scene_arg: &str, o: &SolveOpts) -> Result<(Prepared, Option<radiosity_io::LoadError>)> {
    let (settings, no_light) = load_settings(scene_arg, o)?;
    Ok((mesh(scene_arg, settings, o)?, no_light))
}

/// The light scale and the [`Problem`] of checked settings of the scene `scene_arg` names.
fn mesh(scene_arg: &str, settings: Settings, o: &SolveOpts) -> Result<Prepared> {
    let Settings { mut scene, mesh_params, solver_params, up } = settings;
    if let Some(t) = o.threads {
        // One call per process: an error is the system refusing the threads.
        rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build_global()
            .with_context(|| format!("cannot start {t} worker threads (--threads)"))?;
    }
    scene.scale_emission(o.light_scale);
    // The scene's loader names the line of a mesh over the element limit; one that only the
    // command's options make too large (or a model file's, which has no [mesh]) is named by
    // its file here.
    let problem =
        spinning("meshing", || Problem::new(&scene, &mesh_params)).with_context(|| scene_arg.to_owned())?;
    Ok(Prepared { scene, problem, params: solver_params, up })
}

/// Refuses a light scale whose product with an emission passes [`MAX_EMISSION`], or whose
/// emitted power is not finite: the solve would overflow to infinities and report `null`
/// radiosities.
///
/// # Errors
/// The material and the product (exit code 2).
fn check_light_scale(scene: &Scene, light_scale: f64) -> Result<()> {
    for m in &scene.materials {
        let scaled = m.emission.max_channel() * light_scale;
        // NaN fails this test too.
        if scaled.is_nan() || scaled > MAX_EMISSION {
            return Err(input(format!(
                "--light-scale {light_scale}: material '{}' would emit {scaled:e} W/m², more than {MAX_EMISSION:e}",
                m.name
            )));
        }
    }
    let power = scene.emitted_power().max_channel() * light_scale;
    if !power.is_finite() {
        return Err(input(format!(
            "--light-scale {light_scale}: the scene's emitted power would be {power}; lower the scale or the emissions"
        )));
    }
    Ok(())
}

/// Runs the solver to a stop criterion (or a Ctrl-C that [`crate::interrupt::catch`] caught),
/// with its progress on stderr ([`Progress`]).
///
/// # Errors
/// Solver parameter errors (exit code 2); stderr that cannot be written.
pub fn run_solver(p: &Prepared) -> Result<(Solver, StepReport)> {
    let mut solver = p.problem.solver(p.params.clone())?;
    let threshold = p.params.unshot_threshold.max(radiosity_solver::UNSHOT_FLOOR);
    if p.params.unshot_threshold < radiosity_solver::UNSHOT_FLOOR {
        crate::output::note(format_args!(
            "note: an unshot threshold of {:e} is below what the solution can show: the solve stops at {:e}, where a shot changes no radiosity by more than round-off",
            p.params.unshot_threshold,
            radiosity_solver::UNSHOT_FLOOR
        ))?;
    }
    let progress = Progress::bar("solving", 1000, "");
    let report = loop {
        let r = solver.step(StepBudget::Time(Duration::from_millis(100)));
        // Progress on a log scale: from 1 (nothing shot) down to the threshold.
        let done = (r.unshot_fraction.max(threshold).ln() / threshold.ln()).clamp(0.0, 1.0);
        let secs = progress.elapsed().as_secs_f64();
        let eta = if done > 0.0 { secs * (1.0 - done) / done } else { f64::NAN };
        if r.stop_reason.is_some() || crate::interrupt::requested() {
            break r;
        }
        progress.set(
            (done * 1000.0) as u64,
            1000,
            format!(
                "{} shots, unshot {:.3} %, {:.2} M rays/s, ETA {:.1} s",
                r.total_shots,
                r.unshot_fraction * 100.0,
                r.rays as f64 / secs.max(1e-9) / 1e6,
                eta
            ),
        );
    };
    drop(progress);
    // A light behind a wall or facing out of the scene: everything it emitted escaped and the
    // converged picture is black. Say why instead of leaving it to be guessed.
    let energy = solver.energy();
    let emitted = energy.emitted.max_channel();
    // Every surface absorbs (1 − ρ) > 0 of what reaches it: nothing absorbed, most escaped.
    // "Nothing" up to 1e-5: rays to the thin elements graded into a corner just under the
    // lamp's ceiling pass the ceiling's edge within the ray offset (a lamp above a box's
    // ceiling lights its walls' top elements with 1e-7 of its power).
    if energy.absorbed.max_channel() <= 1e-5 * emitted && energy.escaped.max_channel() >= 0.5 * emitted {
        crate::output::note(format_args!(
            "warning: no light reached any surface: all the emitted power left the scene. Is the light behind a wall or above a ceiling, or facing away from the scene (emission leaves the front face, the side its normal points to)?"
        ))?;
    }
    Ok((solver, report))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The SCENE help names every built-in scene the loader knows, and no other.
    #[test]
    fn scene_help_names_every_builtin() {
        let listed = SCENE_HELP.rsplit_once('(').unwrap().1.trim_end_matches(')');
        let listed: Vec<&str> = listed.split(", ").collect();
        assert_eq!(listed, radiosity_io::BUILTIN_SCENES);
    }

    /// `info`'s solve options are the declared defaults with its own mesh options and scale.
    #[test]
    fn solve_options_from_mesh_options_keep_the_declared_defaults() {
        let mesh = MeshOpts {
            patch_size: Some(50.0),
            element_size: None,
            crease_angle: Some(0.0),
            sides: Some(1),
            up: None,
            units: None,
            contacts: None,
            shadow_outlines: None,
            corner_refinement: None,
            proximity_refinement: None,
            adaptive_levels: None,
        };
        let o = SolveOpts::with_mesh(mesh, 2.0);
        assert_eq!((o.mesh.patch_size, o.mesh.crease_angle, o.mesh.sides), (Some(50.0), Some(0.0), Some(1)));
        assert_eq!(o.light_scale, 2.0);
        let d = SolverParams::default();
        assert_eq!(
            (o.seed, o.visibility_rays, o.max_shots, o.threads),
            (d.seed, d.visibility_rays, None, None)
        );
    }
}
