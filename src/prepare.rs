//! What every command that solves shares: the solve options, loading and meshing a scene,
//! and running the solver with a progress bar.

use std::io::IsTerminal;
use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use radiosity_core::{MeshParams, Scene};
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
    });
    if input { 2 } else { 1 }
}

/// Form factor choice on the command line.
#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum FormFactorArg {
    /// Exact point-to-polygon, integrated over the receiver.
    Exact,
    /// The source document's point-to-point formula (inaccurate up close).
    Point,
}

/// Options shared by every command that solves; each overrides the scene file.
#[derive(Args, Clone, Debug)]
pub struct SolveOpts {
    /// Longest patch edge, scene units (overrides the scene's [mesh]).
    #[arg(long)]
    pub patch_size: Option<f64>,
    /// Longest element edge, scene units (overrides the scene's [mesh]).
    #[arg(long)]
    pub element_size: Option<f64>,
    /// Stop when unshot power / emitted power falls to this (default 1e-3).
    #[arg(long)]
    pub unshot_threshold: Option<f64>,
    /// Stop after this many shots.
    #[arg(long)]
    pub max_shots: Option<u64>,
    /// Stop after this many seconds of solving.
    #[arg(long)]
    pub time_limit: Option<f64>,
    /// Multiply every emission by this (the light intensity).
    #[arg(long, default_value_t = 1.0)]
    pub light_scale: f64,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Seed of the visibility sampling.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Form factor method.
    #[arg(long, value_enum, default_value_t = FormFactorArg::Exact)]
    pub form_factor: FormFactorArg,
    /// Visibility rays per receiver from a bright shooter (see --bright-share).
    #[arg(long, default_value_t = 8)]
    pub visibility_rays: u32,
    /// More rays from a bright shooter for a receiver whose neighbours' first visibility rays
    /// saw a penumbra; 0: none.
    #[arg(long, default_value_t = 12)]
    pub penumbra_rays: u32,
    /// Visibility rays per receiver from a dim shooter.
    #[arg(long, default_value_t = 1)]
    pub dim_rays: u32,
    /// A shooter is bright when its first shot carries at least this share of the first
    /// (largest) shot's power; 0: every shooter is.
    #[arg(long, default_value_t = 0.01, value_name = "SHARE")]
    pub bright_share: f64,
    /// Memory for keeping each shooter's form factors for its next shots, in MiB (0: keep
    /// none; the answer is the same, only slower).
    #[arg(long, default_value_t = 256, value_name = "MIB")]
    pub row_cache_mib: usize,
    /// Over-relaxation factor ω in [1, 2) (1: plain shooting).
    #[arg(long, default_value_t = 1.0)]
    pub overshoot: f64,
    /// Add the ambient term (Cohen 1988) to the reported solution.
    #[arg(long)]
    pub ambient: bool,
}

/// A scene ready to solve.
pub struct Prepared {
    /// The scene as loaded (light scale applied).
    pub scene: Scene,
    /// Its mesh and the ray queries over its occluders.
    pub problem: Problem,
    /// Solver settings from the scene and the options.
    pub params: SolverParams,
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
}

/// Loads `scene_arg` (a scene file, a model file — `.obj`, `.gltf`, `.glb` — or a built-in
/// name) and checks the options against it: the one
/// place where command-line solve options become parameters.
///
/// # Errors
/// Bad scene files and out-of-range options (exit code 2).
pub fn settings(scene_arg: &str, o: &SolveOpts) -> Result<Settings> {
    if o.threads == Some(0) {
        return Err(input("--threads must be at least 1".into()));
    }
    // A model file given where a scene is expected loads as a scene of its parts; what the
    // loader dropped or defaulted (degenerate faces, a missing MTL) is said once, here.
    let radiosity_io::LoadedScene { scene, warnings } = radiosity_io::resolve_scene(scene_arg)?;
    for w in &warnings {
        eprintln!("warning: {w}");
    }
    if !(o.light_scale.is_finite() && o.light_scale > 0.0) {
        return Err(input(format!("--light-scale must be a finite number > 0, got {}", o.light_scale)));
    }
    let base = scene.mesh_params();
    let patch = o.patch_size.unwrap_or(base.patch_size);
    let element = o.element_size.unwrap_or(if o.patch_size.is_some() {
        patch.min(base.element_size)
    } else {
        base.element_size
    });
    let mesh_params = MeshParams::try_new(patch, element).map_err(|e| input(format!("mesh options: {e}")))?;
    let time_limit = match o.time_limit.or(scene.solver.time_limit) {
        Some(t) if t.is_finite() && t >= 0.0 => Some(Duration::from_secs_f64(t)),
        Some(t) => return Err(input(format!("--time-limit must be a number of seconds ≥ 0, got {t}"))),
        None => None,
    };
    let solver_params = SolverParams {
        form_factor: match o.form_factor {
            FormFactorArg::Exact => FormFactorMethod::Exact,
            FormFactorArg::Point => FormFactorMethod::PointToPoint,
        },
        visibility_rays: o.visibility_rays,
        penumbra_rays: o.penumbra_rays,
        dim_rays: o.dim_rays,
        bright_share: o.bright_share,
        unshot_threshold: o.unshot_threshold.or(scene.solver.unshot_threshold).unwrap_or(1e-3),
        max_shots: o.max_shots.or(scene.solver.max_shots),
        time_limit,
        seed: o.seed,
        ambient: if o.ambient { Ambient::On } else { Ambient::Off },
        overshoot: if o.overshoot == 1.0 { Overshoot::Off } else { Overshoot::Relaxation(o.overshoot) },
        row_cache_bytes: o.row_cache_mib.saturating_mul(1 << 20),
        ..SolverParams::default()
    };
    Ok(Settings { scene, mesh_params, solver_params })
}

/// [`settings`], then the light scale and the [`Problem`] (mesh and ray queries); sets the
/// global thread pool when `--threads` is given.
///
/// # Errors
/// Bad scene files, out-of-range options, meshes that would be too large (exit code 2).
pub fn prepare(scene_arg: &str, o: &SolveOpts) -> Result<Prepared> {
    let Settings { mut scene, mesh_params, solver_params } = settings(scene_arg, o)?;
    if let Some(t) = o.threads {
        // The global pool can be set once per process; a second call is a harmless no-op.
        let _ = rayon::ThreadPoolBuilder::new().num_threads(t).build_global();
    }
    scene.scale_emission(o.light_scale);
    let problem = Problem::new(&scene, &mesh_params)?;
    Ok(Prepared { scene, problem, params: solver_params })
}

/// Runs the solver to a stop criterion, with a progress bar on stderr when it is a terminal.
///
/// # Errors
/// Solver parameter errors (exit code 2).
pub fn run_solver(p: &Prepared) -> Result<(Solver, StepReport)> {
    let mut solver = p.problem.solver(p.params.clone())?;
    let bar = if std::io::stderr().is_terminal() {
        let bar = ProgressBar::new(1000);
        bar.set_style(
            ProgressStyle::with_template("{spinner} solving [{bar:30}] {msg}")
                .expect("valid template")
                .progress_chars("=> "),
        );
        bar
    } else {
        ProgressBar::hidden()
    };
    let threshold = p.params.unshot_threshold;
    let start = Instant::now();
    let report = loop {
        let r = solver.step(StepBudget::Time(Duration::from_millis(100)));
        // Progress on a log scale: from 1 (nothing shot) down to the threshold.
        let done = (r.unshot_fraction.max(threshold).ln() / threshold.ln()).clamp(0.0, 1.0);
        bar.set_position((done * 1000.0) as u64);
        let secs = start.elapsed().as_secs_f64();
        let eta = if done > 0.0 { secs * (1.0 - done) / done } else { f64::NAN };
        bar.set_message(format!(
            "{} shots, unshot {:.3} %, {:.2} M rays/s, ETA {:.1} s",
            r.total_shots,
            r.unshot_fraction * 100.0,
            r.rays as f64 / secs.max(1e-9) / 1e6,
            eta
        ));
        if r.stop_reason.is_some() {
            break r;
        }
    };
    bar.finish_and_clear();
    Ok((solver, report))
}

/// Refuses to overwrite an existing file unless `force` is set.
///
/// # Errors
/// The file exists and `force` is false (exit code 2).
pub fn check_writable(path: &Path, force: bool) -> Result<()> {
    if path.exists() && !force {
        bail!(InputError(format!("{} exists; pass --force to overwrite it", path.display())));
    }
    Ok(())
}

/// Writes `text` to `path`, or to stdout when `path` is `-`.
///
/// # Errors
/// The file exists without `force`, or cannot be written.
pub fn write_output(path: &str, text: &str, force: bool) -> Result<()> {
    if path == "-" {
        println!("{text}");
        return Ok(());
    }
    check_writable(Path::new(path), force)?;
    std::fs::write(path, text).with_context(|| format!("cannot write {path}"))
}
