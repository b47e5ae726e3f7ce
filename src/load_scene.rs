//! From the SCENE argument to a scene ready to mesh: resolved (file, model or built-in name),
//! stood upright, lights scaled, closed models sealed, with every note the user should see.

use std::time::Duration;

use anyhow::Result;
use radiosity_core::{MeshParams, Rgb, Scene, UpAxis};
use radiosity_solver::{Ambient, FormFactorMethod, Overshoot, SolverParams};

use crate::errors::InputError;
use crate::progress::spinning;
use crate::solve_opts::{FormFactorArg, MAX_EMISSION, MAX_RAYS, MAX_THREADS, SolveOpts};

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
        && let Some(guess) = radiosity_io::likely_up(&scene)
    {
        crate::output::note(format_args!(
            "note: the scene looks {up} up ({reason}) but is read +y up; if it lies on its side, add --up {up} (or up = \"{up}\" in a scene file)",
            up = guess.up,
            reason = guess.reason
        ))?;
    }
    let up = up.unwrap_or_default();
    // On the scene as given: sealing may turn a solid around the only light inside out.
    let trapped =
        spinning("finding luminaires inside solids", || radiosity_mesh::luminaires_in_solids(&scene));
    for t in &trapped.enclosed {
        crate::output::note(format_args!(
            "warning: luminaire '{}' is inside the closed object '{}': its light meets only the back of that object's faces and stays inside it; move the luminaire out (a fitting's photometric centre belongs just outside its body)",
            scene.lighting.luminaires[t.luminaire].name, scene.objects[t.object].name
        ))?;
    }
    if o.mesh.sides.is_none() {
        let sealed = spinning("finding closed models", || radiosity_mesh::seal_closed_objects(&mut scene));
        let names = |keep: fn(&radiosity_mesh::Sealed) -> bool| {
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
    // Luminaires are scaled too (`Scene::scale_emission`): their power, lm / 683 per channel
    // of their unit-luminance colour, counts with the emitters'.
    let luminaires: Rgb = (scene.lighting.luminaires.iter())
        .map(|l| l.colour * (l.flux() / radiosity_core::LUMENS_PER_WATT))
        .sum();
    let power = (scene.emitted_power() + luminaires).max_channel() * light_scale;
    if !power.is_finite() {
        return Err(input(format!(
            "--light-scale {light_scale}: the scene's emitted power would be {power}; lower the scale or the emissions"
        )));
    }
    Ok(())
}
