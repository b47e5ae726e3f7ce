//! Picture files round-trip, and PFM is laid out the standard way.

use std::path::PathBuf;

use radiosity_core::Rgb;
use radiosity_image::{
    HdrImage, ImageFileError, SrgbImage, decode_pfm, encode_pfm, read_exr, read_hdr, read_pfm, read_png,
    write_exr, write_hdr, write_pfm, write_png,
};

fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("radiosity_image_files");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A picture whose every pixel is different, spanning many orders of magnitude (HDR) and
/// including zero; rounded to f32, the files' precision, so a round trip must be exact.
fn test_picture() -> HdrImage {
    HdrImage::from_fn(7, 5, |x, y| {
        let v = f64::from(x + 10 * y);
        let p = Rgb::new(v * 0.25, (v * 0.5).exp2() / 64.0, if x == 0 { 0.0 } else { 1000.0 + v / 3.0 });
        p.map(|c| f64::from(c as f32))
    })
}

#[test]
fn exr_round_trips_linear_values() {
    let path = scratch("round_trip.exr");
    let img = test_picture();
    write_exr(&path, &img).unwrap();
    assert_eq!(read_exr(&path).unwrap(), img);
    // Chosen by extension too.
    write_hdr(&path, &img).unwrap();
    assert_eq!(read_hdr(&path).unwrap(), img);
}

#[test]
fn pfm_round_trips_linear_values() {
    let path = scratch("round_trip.pfm");
    let img = test_picture();
    write_pfm(&path, &img).unwrap();
    assert_eq!(read_pfm(&path).unwrap(), img);
    write_hdr(&path, &img).unwrap();
    assert_eq!(read_hdr(&path).unwrap(), img);
}

/// The standard PFM layout: header `PF\n<w> <h>\n<scale>\n`, negative scale for
/// little-endian, then rows from the bottom of the picture up.
#[test]
fn pfm_is_bottom_row_first_and_little_endian() {
    // 2 × 2: top row red-ish, bottom row blue-ish.
    let img = HdrImage::from_pixels(
        2,
        2,
        vec![
            Rgb::new(1.0, 0.0, 0.0),
            Rgb::new(2.0, 0.0, 0.0),
            Rgb::new(0.0, 0.0, 3.0),
            Rgb::new(0.0, 0.0, 4.0),
        ],
    );
    let bytes = encode_pfm(&img);
    let header = b"PF\n2 2\n-1.0\n";
    assert_eq!(&bytes[..header.len()], header);
    let floats: Vec<f32> =
        bytes[header.len()..].chunks(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
    assert_eq!(floats, [0.0, 0.0, 3.0, 0.0, 0.0, 4.0, 1.0, 0.0, 0.0, 2.0, 0.0, 0.0]);

    // A big-endian file (positive scale) written by hand decodes to the same picture.
    let mut big = b"PF\n2 2\n1.0\n".to_vec();
    for f in &floats {
        big.extend_from_slice(&f.to_be_bytes());
    }
    assert_eq!(decode_pfm(&big, "big.pfm".as_ref()).unwrap(), img);

    // A grey (Pf) file spreads its one channel to all three.
    let mut grey = b"Pf\n1 2\n-1.0\n".to_vec();
    for f in [5.0_f32, 6.0] {
        grey.extend_from_slice(&f.to_le_bytes());
    }
    let g = decode_pfm(&grey, "grey.pfm".as_ref()).unwrap();
    assert_eq!(g.pixel(0, 0), Rgb::splat(6.0));
    assert_eq!(g.pixel(0, 1), Rgb::splat(5.0));
}

#[test]
fn malformed_pfm_is_an_error_that_says_why() {
    let cases: [(&[u8], &str); 4] = [
        (b"P6\n2 2\n255\n", "not 'PF'"),
        (b"PF\n2 x\n-1.0\n", "height"),
        (b"PF\n2 2\n0\n", "scale"),
        (b"PF\n2 2\n-1.0\n\0\0\0\0", "needs 48 bytes"),
    ];
    for (bytes, expected) in cases {
        let err = decode_pfm(bytes, "bad.pfm".as_ref()).unwrap_err();
        assert!(matches!(err, ImageFileError::BadPfm { .. }));
        assert!(err.to_string().contains(expected), "{err}");
        assert!(err.to_string().contains("bad.pfm"), "{err}");
    }
}

#[test]
fn png_round_trips_8_bit_srgb() {
    let path = scratch("round_trip.png");
    let img = SrgbImage {
        width: 3,
        height: 2,
        pixels: vec![[0, 0, 0], [255, 0, 0], [0, 255, 0], [0, 0, 255], [12, 34, 56], [255, 255, 255]],
    };
    write_png(&path, &img).unwrap();
    assert_eq!(read_png(&path).unwrap(), img);
}

#[test]
fn unknown_extensions_and_empty_pictures_are_refused() {
    let err = write_hdr(&scratch("picture.tiff"), &test_picture()).unwrap_err();
    assert!(err.to_string().contains(".exr or .pfm"), "{err}");
    assert!(matches!(
        write_pfm(&scratch("empty.pfm"), &HdrImage::new(0, 3)),
        Err(ImageFileError::Empty { .. })
    ));
    let missing = read_exr(&scratch("does/not/exist.exr")).unwrap_err();
    assert!(missing.to_string().contains("exist.exr"), "{missing}");
}

/// Declared sizes are checked before anything is allocated: a PFM header of 2³¹ × 2³¹ (whose
/// byte count once wrapped around and then indexed past the data), and an EXR whose header
/// claims 100 000 × 100 000 (240 GB as linear RGB).
#[test]
fn huge_declared_sizes_are_refused_before_allocating() {
    for header in
        ["PF\n2147483648 2147483648\n-1.0\n", "Pf\n4294967295 4294967295\n1.0\n", "PF\n100000 100000\n-1\n"]
    {
        let mut bytes = header.as_bytes().to_vec();
        bytes.extend_from_slice(&[0; 64]);
        let e = decode_pfm(&bytes, &PathBuf::from("h.pfm")).unwrap_err();
        assert!(matches!(e, ImageFileError::TooLarge { .. }), "{header:?}: {e}");
    }
    // A real EXR whose data and display windows are patched to 100 000².
    let path = scratch("huge.exr");
    write_exr(&path, &test_picture()).unwrap();
    let mut bytes = std::fs::read(&path).unwrap();
    for name in [&b"dataWindow\0box2i\0"[..], &b"displayWindow\0box2i\0"[..]] {
        let at = bytes.windows(name.len()).position(|w| w == name).unwrap() + name.len() + 4;
        for (k, v) in [0i32, 0, 99_999, 99_999].into_iter().enumerate() {
            bytes[at + 4 * k..at + 4 * k + 4].copy_from_slice(&v.to_le_bytes());
        }
    }
    std::fs::write(&path, &bytes).unwrap();
    let e = read_exr(&path).unwrap_err();
    assert!(
        matches!(
            e,
            ImageFileError::TooLarge { width: 100_000, height: 100_000, .. } | ImageFileError::Exr { .. }
        ),
        "{e}"
    );
}

/// Only regular files are read: a folder or a device is refused at once, not read forever.
#[cfg(unix)]
#[test]
fn only_regular_files_are_read() {
    for path in ["/dev/zero", "/dev/null", "/tmp"] {
        let e = read_pfm(&PathBuf::from(path)).unwrap_err();
        assert!(matches!(e, ImageFileError::NotAFile { .. }), "{path}: {e}");
        let e = read_exr(&PathBuf::from(path)).unwrap_err();
        assert!(matches!(e, ImageFileError::NotAFile { .. }), "{path}: {e}");
    }
}

/// Writers go through a temporary file and a rename: a failed write leaves the target as it
/// was (the EXR writer used to delete it), and a successful one leaves no temporary file.
#[test]
fn writes_are_atomic() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("p.exr");
    write_exr(&path, &test_picture()).unwrap();
    write_pfm(&dir.path().join("p.pfm"), &test_picture()).unwrap();
    write_png(&dir.path().join("p.png"), &SrgbImage { width: 1, height: 1, pixels: vec![[1, 2, 3]] })
        .unwrap();
    let mut names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into())
        .collect();
    names.sort();
    assert_eq!(names, ["p.exr", "p.pfm", "p.png"]);
    // An empty picture cannot be written: the old file stays.
    let before = std::fs::read(&path).unwrap();
    assert!(write_exr(&path, &HdrImage::new(0, 0)).is_err());
    assert_eq!(std::fs::read(&path).unwrap(), before);
    // A folder that does not exist: an error, nothing made.
    assert!(write_pfm(&dir.path().join("no/p.pfm"), &test_picture()).is_err());
}
