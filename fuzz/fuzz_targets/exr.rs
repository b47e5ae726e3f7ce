//! An OpenEXR picture (`tonemap`'s and `compare`'s input), read from a file as the command
//! reads it. Any error is fine; a panic, an abort or a hang is a finding.
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

use libfuzzer_sys::fuzz_target;

/// The file each input is written to, one per process.
fn file() -> &'static PathBuf {
    static FILE: OnceLock<PathBuf> = OnceLock::new();
    FILE.get_or_init(|| std::env::temp_dir().join(format!("radiosity-fuzz-{}.exr", std::process::id())))
}

fuzz_target!(|data: &[u8]| {
    if std::fs::write(file(), data).is_ok() {
        let _ = radiosity_image::read_exr(file());
    }
});
