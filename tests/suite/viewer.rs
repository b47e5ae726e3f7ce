//! `radiosity view` end to end: the real window under a virtual X display (Xvfb) with Mesa's
//! CPU drivers, as CI has them after `./setup.sh`. The test fails — it never skips — when no
//! display can be started, so a machine that cannot run the viewer cannot pass.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use radiosity_image::{SrgbImage, read_png};

/// Generous: a debug build solving 150 shots on two busy cores, plus Mesa's shader compiles.
const TIMEOUT: Duration = Duration::from_secs(300);

fn xvfb_run() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/xvfb-run.sh")
}

/// Runs `radiosity ARGS` under scripts/xvfb-run.sh, killing it after [`TIMEOUT`].
fn run_view(args: &[&str]) -> std::process::Output {
    let child = Command::new(xvfb_run())
        .arg(env!("CARGO_BIN_EXE_radiosity"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot run {}: {e}", xvfb_run().display()));
    let pid = child.id();
    let start = Instant::now();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(child.wait_with_output());
    });
    match rx.recv_timeout(TIMEOUT) {
        Ok(out) => out.expect("wait for the viewer"),
        Err(_) => {
            // SIGTERM: the script then ends the viewer and its Xvfb too.
            let _ = Command::new("kill").arg(pid.to_string()).status();
            panic!(
                "radiosity {} did not finish within {:?} (started {:?} ago)",
                args.join(" "),
                TIMEOUT,
                start.elapsed()
            );
        }
    }
}

fn check_ran(out: &std::process::Output, what: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "{what} failed ({}). A headless machine needs Xvfb and Mesa: run ./setup.sh.\nstderr:\n{stderr}",
        out.status
    );
}

fn pixel(img: &SrgbImage, x: u32, y: u32) -> [f64; 3] {
    img.pixels[(y * img.width + x) as usize].map(f64::from)
}

/// Share of pixels in column `x` (middle half of the rows) that are clearly red, clearly green.
fn column_colours(img: &SrgbImage, x: u32) -> (f64, f64) {
    let h = img.height;
    let (mut red, mut green, mut n) = (0.0, 0.0, 0.0);
    for y in h / 4..3 * h / 4 {
        let [r, g, b] = pixel(img, x, y);
        if r > 90.0 && r > 1.8 * g && r > 1.8 * b {
            red += 1.0;
        }
        if g > 60.0 && g > 1.5 * r && g > 1.5 * b {
            green += 1.0;
        }
        n += 1.0;
    }
    (red / n, green / n)
}

/// The Cornell box seen from its camera: the red wall on the left and the green wall on the
/// right of the 3D view, the picture lit (not blank) and not blown out. The panel sits on the
/// right of the window, so only the left 70 % (the view) is measured, and the walls are found
/// as the centroids of the columns where they dominate.
#[test]
fn view_cornell_screenshot_shows_the_lit_box() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("cornell.png");
    let out = run_view(&[
        "view",
        "cornell",
        "--screenshot",
        png.to_str().unwrap(),
        "--after-shots",
        "150",
        "--width",
        "960",
        "--height",
        "600",
    ]);
    check_ran(&out, "radiosity view cornell --screenshot");
    let img = read_png(&png).unwrap_or_else(|e| panic!("{e}"));
    // Keep the picture to look at.
    let keep = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("view_cornell.png");
    std::fs::copy(&png, &keep).unwrap();
    eprintln!("{} ({}×{}); {}", keep.display(), img.width, img.height, String::from_utf8_lossy(&out.stderr));
    assert!(img.width >= 900 && img.height >= 560, "the whole window: {}×{}", img.width, img.height);

    let view_width = (f64::from(img.width) * 0.7) as u32;
    let (mut red_sum, mut red_x, mut green_sum, mut green_x) = (0.0, 0.0, 0.0, 0.0);
    for x in 0..view_width {
        let (r, g) = column_colours(&img, x);
        red_sum += r;
        red_x += r * f64::from(x);
        green_sum += g;
        green_x += g * f64::from(x);
    }
    let columns = f64::from(view_width);
    assert!(red_sum > 0.05 * columns, "no red wall: {red_sum} column-shares");
    assert!(green_sum > 0.05 * columns, "no green wall: {green_sum} column-shares");
    let (red_at, green_at) = (red_x / red_sum / columns, green_x / green_sum / columns);
    eprintln!("red wall centroid {red_at:.2}, green wall centroid {green_at:.2} of the view width");
    assert!(red_at < 0.35, "the red wall must be on the left of the view: centroid at {red_at:.2}");
    assert!(green_at > 0.65, "the green wall must be on the right of the view: centroid at {green_at:.2}");

    let pixels: Vec<[f64; 3]> = (0..img.height)
        .flat_map(|y| (0..view_width).map(move |x| (x, y)))
        .map(|(x, y)| pixel(&img, x, y))
        .collect();
    let mean = pixels.iter().map(|p| (p[0] + p[1] + p[2]) / 3.0).sum::<f64>() / pixels.len() as f64;
    eprintln!("mean {mean:.1} of 255");
    assert!(mean > 50.0, "the box must be lit: mean {mean:.1} of 255");
    let white = pixels.iter().filter(|p| p.iter().all(|c| *c >= 250.0)).count() as f64 / pixels.len() as f64;
    eprintln!("{:.2} % white", white * 100.0);
    assert!(white < 0.05, "blown out: {:.1} % of the view is white", white * 100.0);
}

/// A bad scene file gets the same one-line error as every command, and no window.
#[test]
fn view_of_a_bad_file_fails_with_the_loader_error() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, "name = \"x\"\n[[material]]\nname = \"m\"\nreflectance = [2, 0, 0]\n").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_radiosity")).arg("view").arg(&bad).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.starts_with("error: ") && stderr.trim_end().lines().count() == 1, "{stderr}");
    assert!(stderr.contains("bad.toml:"), "names the file: {stderr}");
}

/// Without a display, `view` fails at once and its first line says what to do — run it under
/// the virtual display script — before winit's cause, which loses the path into winit's
/// source that its message carries.
#[test]
fn without_a_display_the_error_says_to_use_xvfb_first() {
    let out = Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(["view", "cornell"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("WAYLAND_SOCKET")
        .stdin(Stdio::null())
        .output()
        .expect("run radiosity view");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "view without a display succeeded:\n{stderr}");
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    let first = stderr.lines().next().unwrap_or_default();
    assert!(
        first.starts_with("error: no display to open a window on")
            && first.contains("scripts/xvfb-run.sh radiosity view cornell"),
        "{stderr}"
    );
    let cause = first.split_once("(cause: ").map(|(_, c)| c).unwrap_or_default();
    assert!(cause.contains("DISPLAY"), "the cause is gone: {stderr}");
    assert!(!stderr.contains(".cargo/registry") && !stderr.contains("panicked"), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
}
