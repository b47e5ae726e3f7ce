//! How a command fails: [`InputError`] for what the user gave (exit code 2), anything else
//! exit code 1.

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
            || c.is::<radiosity_mesh::MeshError>()
            || c.is::<radiosity_solver::SolverError>()
            || c.is::<radiosity_image::RenderError>()
    });
    if input { 2 } else { 1 }
}
