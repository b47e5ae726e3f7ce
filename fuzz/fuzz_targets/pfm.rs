//! A PFM picture (`tonemap`'s and `compare`'s input): header and pixels. Any error is fine;
//! a panic, an abort or a hang is a finding.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = radiosity_image::decode_pfm(data, std::path::Path::new("fuzz.pfm"));
});
