//! A glTF model, JSON or binary (GLB), with no folder to read other files from. Any error is
//! fine; a panic, an abort or a hang is a finding.
#![no_main]

use libfuzzer_sys::fuzz_target;
use radiosity_io::{ModelFormat, Transform, parse_model};

fuzz_target!(|data: &[u8]| {
    let _ = parse_model(data, "fuzz.glb", None, ModelFormat::Gltf, &Transform::default());
});
