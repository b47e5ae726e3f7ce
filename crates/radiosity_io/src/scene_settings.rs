//! The `[mesh]` and `[solver]` tables of a scene file: validated by the core's constructors,
//! each error pointed at its value.

use radiosity_core::{MeshParams, SceneError, SolverSettings};

use crate::LoadError;
use crate::desc::{MeshDesc, SolverDesc};
use crate::locate::Locator;

/// The `[mesh]` table as mesh parameters, each error at the value's span.
pub(crate) fn mesh_params(loc: &Locator, d: &MeshDesc) -> Result<MeshParams, LoadError> {
    let params = MeshParams::try_new(*d.patch_size.get_ref(), *d.element_size.get_ref()).map_err(|e| {
        let (field, span) = match e {
            SceneError::BadMeshSize { key: "patch_size", .. } => ("patch_size", d.patch_size.span()),
            _ => ("element_size", d.element_size.span()),
        };
        loc.at(span, format!("mesh.{field}"), e.to_string())
    })?;
    let params = params.with_contacts(d.contacts.unwrap_or(true));
    let params = params.with_shadow_outlines(d.shadow_outlines.unwrap_or(true));
    let params = match &d.corner_refinement {
        Some(levels) => params
            .with_corner_refinement(*levels.get_ref())
            .map_err(|e| loc.at(levels.span(), "mesh.corner_refinement", e.to_string()))?,
        None => params,
    };
    let params = match &d.proximity_refinement {
        Some(levels) => params
            .with_proximity_refinement(*levels.get_ref())
            .map_err(|e| loc.at(levels.span(), "mesh.proximity_refinement", e.to_string()))?,
        None => params,
    };
    let params = match &d.adaptive_levels {
        Some(levels) => params
            .with_adaptive_levels(*levels.get_ref())
            .map_err(|e| loc.at(levels.span(), "mesh.adaptive_levels", e.to_string()))?,
        None => params,
    };
    match &d.crease_angle {
        Some(a) => params
            .with_crease_angle(*a.get_ref())
            .map_err(|e| loc.at(a.span(), "mesh.crease_angle", e.to_string())),
        None => Ok(params),
    }
}

/// The `[solver]` table as solver settings, each error at the value's span.
pub(crate) fn solver_settings(loc: &Locator, d: &SolverDesc) -> Result<SolverSettings, LoadError> {
    let mut settings = SolverSettings::default();
    if let Some(t) = &d.unshot_threshold {
        let v = *t.get_ref();
        // Written so that NaN fails too.
        if !(v > 0.0 && v < 1.0) {
            return Err(loc.at(
                t.span(),
                "solver.unshot_threshold",
                format!("expected a fraction of the emitted power in (0, 1), e.g. 0.001, got {v}"),
            ));
        }
        settings.unshot_threshold = Some(v);
    }
    if let Some(n) = &d.max_shots {
        let v = *n.get_ref();
        let Ok(shots) = u64::try_from(v) else {
            return Err(loc.at(
                n.span(),
                "solver.max_shots",
                format!("expected a whole number ≥ 1, got {v}"),
            ));
        };
        if shots == 0 {
            return Err(loc.at(n.span(), "solver.max_shots", "expected a whole number ≥ 1, got 0"));
        }
        settings.max_shots = Some(shots);
    }
    if let Some(t) = &d.time_limit {
        let v = *t.get_ref();
        if !(v > 0.0 && v <= radiosity_core::MAX_TIME_LIMIT_SECONDS) {
            return Err(loc.at(
                t.span(),
                "solver.time_limit",
                format!(
                    "expected a finite number of seconds > 0 and ≤ {:e}, got {v}",
                    radiosity_core::MAX_TIME_LIMIT_SECONDS
                ),
            ));
        }
        settings.time_limit = Some(v);
    }
    Ok(settings)
}
