//! What a lighting designer takes away: `radiosity grid` (CSV, the false-colour sheet, the
//! HTML report) and `render --false-colour lux`, and the bad requests each refuses before
//! writing anything.

use std::path::{Path, PathBuf};
use std::process::Command;

fn radiosity(args: &[&str], dir: &Path) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_radiosity")).args(args).current_dir(dir).output().unwrap()
}

fn office() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/photometry/office.toml")
}

/// The PNG signature, decoded from the report's first embedded picture.
fn first_embedded_png(html: &str) -> Vec<u8> {
    let start = html.find("data:image/png;base64,").expect("an embedded picture") + 22;
    let end = start + html[start..].find('"').unwrap();
    let alphabet = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let digits: Vec<u32> = html[start..end]
        .bytes()
        .filter(|b| *b != b'=')
        .map(|b| alphabet.iter().position(|a| *a == b).expect("a base64 digit") as u32)
        .collect();
    let mut out = Vec::new();
    for chunk in digits.chunks(4) {
        let n = chunk.iter().enumerate().fold(0, |n, (k, d)| n | d << (18 - 6 * k));
        out.extend(n.to_be_bytes()[1..chunk.len()].iter());
    }
    out
}

#[test]
fn grid_writes_the_csv_the_sheet_and_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let scene = office();
    let o = radiosity(
        &[
            "grid",
            scene.to_str().unwrap(),
            "-o",
            "g.csv",
            "--png",
            "g.png",
            "--report",
            "r.html",
            "--max-shots",
            "200",
            "-q",
        ],
        dir.path(),
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let table = String::from_utf8_lossy(&o.stdout);
    assert!(table.contains("work plane") && table.contains("Em lx"), "{table}");

    let csv = std::fs::read_to_string(dir.path().join("g.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("grid,x,y,z,lux"));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 45, "9 × 5 points");
    assert!(rows.iter().all(|r| r.len() == 5 && r[0] == "work plane" && r[2] == "0.8"));
    let lux: Vec<f64> = rows.iter().map(|r| r[4].parse().unwrap()).collect();
    assert!(lux.iter().all(|e| (200.0..2000.0).contains(e)), "{lux:?}");

    let sheet = radiosity_image::read_png(&dir.path().join("g.png")).unwrap();
    // A plot 640 px wide for the grid's 5 m, its legend and margins.
    assert!(sheet.width > 700 && sheet.height > 400, "{} × {}", sheet.width, sheet.height);
    // The lowest and the highest band are both there.
    let scale = radiosity_image::LuxScale::for_range(
        lux.iter().copied().fold(f64::INFINITY, f64::min),
        lux.iter().copied().fold(0.0, f64::max),
    );
    for band in [0, scale.levels.len()] {
        let colour = scale.band_colour(band);
        assert!(sheet.pixels.contains(&colour), "band {band} {colour:?} missing");
    }

    let html = std::fs::read_to_string(dir.path().join("r.html")).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>") && html.trim_end().ends_with("</html>"));
    assert!(html.contains("<h1>Office</h1>"));
    // The schedule: one type, six of it, and the total; then each position.
    assert!(html.contains("<td>downlight</td><td class=\"n\">6</td>"), "the luminaires' schedule");
    assert_eq!(html.matches("<td>downlight #").count(), 6);
    assert!(html.contains("U<sub>0</sub>"));
    // Self-contained: no link to any other file.
    assert!(!html.contains("src=\"http") && !html.contains("href="));
    assert_eq!(&first_embedded_png(&html)[..8], b"\x89PNG\r\n\x1a\n");
}

#[test]
fn grid_refuses_bad_requests_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let scene = office();
    let scene = scene.to_str().unwrap();
    let refused = |args: &[&str], says: &str| {
        let o = radiosity(args, dir.path());
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
    };
    refused(&["grid", scene, "-q"], "nothing to write");
    refused(&["grid", "cornell", "-o", "g.csv", "--report", "r.html", "-q"], "no calculation grid");
    refused(&["grid", scene, "--png", "g.jpg", "-q"], "--png");
    refused(&["grid", scene, "-o", "same.csv", "--report", "same.csv", "-q"], "same file");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "nothing written");
    // A file that is there stays as it is without --force.
    std::fs::write(dir.path().join("g.csv"), "mine").unwrap();
    refused(&["grid", scene, "-o", "g.csv", "--png", "g.png", "-q"], "--force");
    assert_eq!(std::fs::read_to_string(dir.path().join("g.csv")).unwrap(), "mine");
    assert!(!dir.path().join("g.png").exists());
}

#[test]
fn false_colour_renders_lux_of_photometric_scenes_only() {
    let dir = tempfile::tempdir().unwrap();
    let o = radiosity(&["render", "cornell", "--false-colour", "lux", "-o", "c.png", "-q"], dir.path());
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("not a photometric scene"), "{err}");
    assert!(!dir.path().join("c.png").exists());

    let scene = office();
    let args = [
        "render",
        scene.to_str().unwrap(),
        "--false-colour",
        "lux",
        "-o",
        "o.png",
        "--exr",
        "o.exr",
        "--width",
        "96",
        "--height",
        "72",
        "--spp",
        "1",
        "--max-shots",
        "200",
        "-q",
    ];
    let o = radiosity(&args, dir.path());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let picture = radiosity_image::read_png(&dir.path().join("o.png")).unwrap();
    // The picture, the legend beside it and the line under it.
    assert!(picture.width > 96 && picture.height > 72);
    // Every pixel of the view sees a lit grey surface: coloured, none without data.
    let view: Vec<[u8; 3]> = (0..72)
        .flat_map(|y| (0..96).map(move |x| (x, y)))
        .map(|(x, y)| picture.pixels[y * picture.width as usize + x])
        .collect();
    assert!(!view.contains(&radiosity_image::NO_DATA));
    assert!(view.iter().filter(|p| p[0] != p[2]).count() > view.len() / 2, "false colours");
    // The linear picture is still the radiance.
    assert!(dir.path().join("o.exr").exists());
}
