//! A scene file: parsed and validated, then meshed when its mesh is small (the bad-input
//! aborts of the past were in meshing what the loader accepted). Any error is fine; a panic,
//! an abort or a hang is a finding.
#![no_main]

use libfuzzer_sys::fuzz_target;
use radiosity_mesh::{Mesh, estimate_elements};

/// Largest estimated mesh that is meshed: big enough for every canonical scene, small enough
/// to keep each run quick.
const MESH_LIMIT: usize = 20_000;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(loaded) = radiosity_io::parse_scene(text, "fuzz.toml") else { return };
    let scene = loaded.scene;
    let params = scene.mesh_params();
    let estimate = scene
        .objects
        .iter()
        .map(|o| estimate_elements(&o.shape, &params))
        .fold(0usize, usize::saturating_add);
    if estimate <= MESH_LIMIT {
        let _ = Mesh::build(&scene, &params);
    }
});
