//! An OBJ model and its MTL library: the input is the OBJ's text, then a NUL byte, then the
//! MTL's (written to a file the OBJ's `mtllib m.mtl` line names). Any error is fine; a panic,
//! an abort or a hang is a finding.
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;
use radiosity_io::{ModelFormat, Transform, parse_model};

/// The folder the MTL is written into, one per process.
fn folder() -> &'static PathBuf {
    static FOLDER: OnceLock<PathBuf> = OnceLock::new();
    FOLDER.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("radiosity-fuzz-obj-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a temporary folder");
        dir
    })
}

fuzz_target!(|data: &[u8]| {
    let (obj, mtl) = match data.iter().position(|&b| b == 0) {
        Some(k) => (&data[..k], &data[k + 1..]),
        None => (data, &[][..]),
    };
    let dir = folder();
    if std::fs::write(dir.join("m.mtl"), mtl).is_err() {
        return;
    }
    let mut bytes = b"mtllib m.mtl\n".to_vec();
    bytes.extend_from_slice(obj);
    let _ = parse_model(&bytes, "fuzz.obj", Some(dir), ModelFormat::Obj, &Transform::default());
});
