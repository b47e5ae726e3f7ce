//! An IES LM-63 or EULUMDAT photometric file (a `[[luminaire]]`'s `file`), parsed as text the
//! way the loader parses it; the first byte picks the format. Any error is fine; a panic, an
//! abort or a hang is a finding. A table that parses is also evaluated and integrated, which
//! must not panic either.
#![no_main]

use libfuzzer_sys::fuzz_target;
use radiosity_io::{PhotometricFormat, parse_photometry};

fuzz_target!(|data: &[u8]| {
    let Some((&first, rest)) = data.split_first() else { return };
    let format = if first & 1 == 0 { PhotometricFormat::Ies } else { PhotometricFormat::Eulumdat };
    let text: String = rest.iter().map(|&b| char::from(b)).collect();
    if let Ok(p) = parse_photometry(&text, "fuzz", format) {
        let _ = p.table.candela(f64::from(first) * 1.7, 33.0);
        let _ = p.table.flux();
    }
});
