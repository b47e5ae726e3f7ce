//! What every command that solves shares: a loaded scene ([`crate::load_scene`]) meshed into a
//! [`Prepared`] problem, and the solver run on it with a progress bar.

use std::time::Duration;

use anyhow::{Context, Result};
use radiosity_core::{Scene, UpAxis};

use crate::load_scene::{Settings, load_settings, settings};
use crate::progress::{Progress, spinning};
use crate::solve_opts::SolveOpts;
use radiosity_solver::{Problem, Solver, SolverParams, StepBudget, StepReport};

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
    use crate::solve_opts::{MeshOpts, SCENE_HELP};

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
