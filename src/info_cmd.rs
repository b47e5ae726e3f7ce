//! `radiosity info`: what a scene holds, before solving it.

use std::fmt::Write;

use anyhow::Result;
use clap::Args;
use radiosity_core::Rgb;

use crate::prepare::prepare_unlit;
use crate::solve_opts::{MeshOpts, SolveOpts};

/// Arguments of `radiosity info`.
#[derive(Args)]
pub struct InfoArgs {
    /// The scene to load: see [`SCENE_HELP`](crate::solve_opts::SCENE_HELP).
    #[arg(help = crate::solve_opts::SCENE_HELP)]
    pub scene: String,
    #[command(flatten)]
    pub mesh: MeshOpts,
    /// Multiply every emission and luminaire intensity by this (the emitted power reported).
    #[arg(long, allow_negative_numbers = true, default_value_t = 1.0)]
    pub light_scale: f64,
}

/// Runs `info`.
pub fn run(a: InfoArgs) -> Result<()> {
    // A model without a light yet is described all the same: the light is what `info` says
    // is missing.
    let (p, no_light) = prepare_unlit(&a.scene, &SolveOpts::with_mesh(a.mesh, a.light_scale))?;
    let (scene, mesh) = (&p.scene, p.problem.mesh());
    // One text, one write: a closed pipe or a full disk is one error, not a panic.
    let mut out = String::new();
    let (lo, hi) = mesh.bounds();
    // In the file's frame, as the user's tools show the model.
    let (corner, other) = (p.up.from_y_up(lo), p.up.from_y_up(hi));
    let (lo, hi) = (corner.min(other), corner.max(other));
    let _ = writeln!(out, "scene      {}", scene.name);
    let _ = writeln!(out, "bounds     {:?} .. {:?}", lo.to_array(), hi.to_array());
    let _ = writeln!(out, "materials  {}", scene.materials.len());
    let _ = writeln!(out, "objects    {}", scene.objects.len());
    let _ = writeln!(out, "surfaces   {}", mesh.surfaces.len());
    let _ = writeln!(out, "patches    {}", mesh.patches.len());
    let _ = writeln!(out, "elements   {}", mesh.elements.len());
    let unrefined = p.problem.unrefined_elements();
    if unrefined != mesh.elements.len() {
        let _ = writeln!(
            out,
            "adaptive   {unrefined} elements before adaptive subdivision quartered those where the light changes steeply"
        );
    }
    let groups = radiosity_solver::shooter_groups(mesh);
    if groups > 0 {
        let _ = writeln!(
            out,
            "groups     {groups} groups of a model's small facets shoot as one (solve --clusters false: each alone)"
        );
    }
    let _ = writeln!(out, "occluders  {} triangles", mesh.occluders.len());
    // Contact cuts: what each object lost under the solids standing on it.
    for (name, hidden) in mesh.object_names.iter().zip(&mesh.hidden_area) {
        if *hidden > 0.0 {
            let _ = writeln!(out, "hidden     {hidden:.6e} units² of '{name}' under solids standing on it");
        }
    }
    for (name, &pieces) in mesh.object_names.iter().zip(&mesh.shadow_pieces) {
        if pieces > 0 {
            let _ =
                writeln!(out, "shadows    '{name}' cut along shadow outlines into {pieces} more surfaces");
        }
    }
    let _ = writeln!(out, "area       {:.6e}", mesh.total_area());
    let emitted: Rgb =
        (0..mesh.elements.len()).map(|e| mesh.element_material(e).emission * mesh.elements[e].area).sum();
    let _ = writeln!(out, "emitted    [{:.6e}, {:.6e}, {:.6e}] W", emitted.r, emitted.g, emitted.b);
    if !scene.lighting.luminaires.is_empty() {
        let (count, flux) = (scene.lighting.luminaires.len(), scene.lighting.luminaire_flux());
        let _ = writeln!(out, "luminaires {count}, {flux:.6e} lm in all");
    }
    let mut warnings = Vec::new();
    let has_light = no_light.is_none();
    if let Some(e) = no_light {
        warnings.push(format!("no light: a solve would be black; {}", radiosity_core::one_line(&e)));
    }
    for m in &scene.materials {
        if m.reflectance.max_channel() > 0.95 {
            warnings.push(format!(
                "material '{}' reflects {:.3} in a channel: light bounces ~{:.0} times, convergence is slow",
                m.name,
                m.reflectance.max_channel(),
                1.0 / (1.0 - m.reflectance.max_channel())
            ));
        }
        if m.is_emitter() && m.reflectance.max_channel() > 0.0 {
            warnings.push(format!("light material '{}' also reflects light (reflectance > 0)", m.name));
        }
    }
    if mesh.elements.len() > 1_000_000 {
        warnings.push(format!("{} elements: solving will be slow; raise element_size", mesh.elements.len()));
    }
    // Large flat surfaces that no light is in front of, summed per object.
    let total = mesh.total_area();
    let mut away = vec![0.0; mesh.object_names.len()];
    let (lo, hi) = mesh.bounds();
    let step = 1e-6 * lo.distance(hi);
    let luminaires: Vec<_> = scene.lighting.luminaires.iter().map(|l| l.light_point(step)).collect();
    for (surface, area) in mesh.surfaces.iter().zip(mesh.area_facing_away_from_light(&luminaires)) {
        if area > 0.05 * total {
            away[surface.object as usize] += area;
        }
    }
    for (name, away) in mesh.object_names.iter().zip(away) {
        if has_light && away > 0.0 {
            warnings.push(format!(
                "object '{name}': one-sided surfaces making {:.0} % of the scene's area face away from every light, so they get no direct light; if they should, flip their normals or make them two-sided (sides = 2, --sides 2)",
                away / total * 100.0
            ));
        }
    }
    if mesh.contacts_incomplete {
        warnings
            .push("too many large faces to look for contacts on all of them: some are meshed whole".into());
    }
    if mesh.proximity_incomplete {
        warnings.push(
            "too much geometry near too many elements to refine them all for it: some are left as meshed"
                .into(),
        );
    }
    if scene.camera.is_none() {
        warnings.push("no [camera]: views frame the whole scene".into());
    }
    for w in &warnings {
        let _ = writeln!(out, "warning    {w}");
    }
    crate::output::stdout(&out)
}
