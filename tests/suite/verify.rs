//! `radiosity verify`, `render --reference` and `compare` end to end: the reference agrees with
//! a right solve and catches a wrong one.

use std::process::{Command, Output};

fn radiosity(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_radiosity")).args(args).output().expect("run radiosity")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn verify_json(args: &[&str]) -> serde_json::Value {
    let mut all = vec!["verify"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["--json", "-"]);
    let o = radiosity(&all);
    assert!(o.status.success(), "{}", stderr(&o));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// The furnace solved right (B = 2 to the 1e-3 unshot remainder, ~0.1 %) agrees with a
/// reference of 40 k paths (~0.4 % standard error) within 3 σ; every field the report
/// promises is there.
#[test]
fn verify_agrees_with_a_right_solve() {
    let r = verify_json(&["furnace", "--paths", "40000"]);
    for key in ["objects", "paths", "seconds", "summary", "shots", "elements"] {
        assert!(r.get(key).is_some(), "report lacks {key}");
    }
    let o = &r["objects"][0];
    for key in ["name", "area", "radiosity", "reference", "stderr"] {
        assert!(o.get(key).is_some(), "object lacks {key}");
    }
    let (b, reference, se) = (
        o["radiosity"][0].as_f64().unwrap(),
        o["reference"][0].as_f64().unwrap(),
        o["stderr"][0].as_f64().unwrap(),
    );
    assert!((reference - 2.0).abs() < 3.0 * se, "reference {reference} ± {se}");
    assert!((b - reference).abs() < 3.0 * se, "solve {b} vs reference {reference} ± {se}");
    assert_eq!(r["summary"]["over_3_sigma"], 0, "{}", r["summary"]);
    assert!(r["paths"].as_u64().unwrap() >= 40_000);
}

/// A solve whose reflectances are scaled by 0.9 (B = 1/(1 − 0.45) = 1.82 instead of 2, 9 %
/// dark) is caught: the furnace differs by far more than 3 σ and the summary says so.
#[test]
fn verify_catches_a_wrong_solve() {
    let r = verify_json(&["furnace", "--paths", "40000", "--solve-reflectance-scale", "0.9"]);
    assert_eq!(r["summary"]["over_3_sigma"], 1, "{}", r["summary"]);
    let o = &r["objects"][0];
    let pct = o["difference_percent"][0].as_f64().unwrap();
    assert!((pct - (-9.1)).abs() < 1.0, "{pct} %");
    assert!(o["difference_sigma"][0].as_f64().unwrap() < -10.0);
    // The human-readable table carries the same verdict.
    let o = radiosity(&["verify", "furnace", "--paths", "8192", "--solve-reflectance-scale", "0.9"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("1 of 1 objects differ by more than 3 σ"), "{text}");
}

/// Elements on request: a seeded sample with solve values, estimates and the RMS difference;
/// and one thread or two give the same report.
#[test]
fn verify_samples_elements_and_ignores_the_thread_count() {
    let run = |threads: &str| {
        verify_json(&[
            "two-plates",
            "--paths",
            "8192",
            "--elements",
            "6",
            "--element-paths",
            "4096",
            "--threads",
            threads,
        ])
    };
    let one = run("1");
    let sample = &one["element_sample"];
    assert_eq!(sample["count"], 6);
    assert_eq!(sample["elements"].as_array().unwrap().len(), 6);
    assert!(sample["rms_difference_percent"].as_f64().unwrap().is_finite());
    let two = run("2");
    assert_eq!(one["objects"], two["objects"]);
    assert_eq!(one["element_sample"]["elements"], two["element_sample"]["elements"]);
}

/// Bad options are input errors (exit code 2).
#[test]
fn verify_rejects_bad_options() {
    for args in [
        &["verify", "furnace", "--paths", "0"][..],
        &["verify", "furnace", "--stderr-target", "0"],
        &["verify", "furnace", "--solve-reflectance-scale", "3"],
        &["compare", "missing-a.exr", "missing-b.exr"],
    ] {
        let o = radiosity(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
    }
}

/// The furnace from inside, rendered by the solver and by the reference (both L = 2/π): `compare`
/// finds them equal to within the reference's noise (256 paths per pixel, ~3 % per pixel,
/// ~0.2 % over the 384 pixels), and writes the difference picture.
#[test]
fn render_reference_and_compare() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    let view = [
        "--width",
        "24",
        "--height",
        "16",
        "--camera-position",
        "0.5,0.5,0.3",
        "--look-at",
        "0.9,0.7,1.0",
        "--fov",
        "70",
    ];
    let mut args = vec!["render", "furnace", "--reference", "--exr"];
    let reference = path("reference.exr");
    args.push(&reference);
    args.extend_from_slice(&view);
    let o = radiosity(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("mean relative standard error per pixel"), "{}", stderr(&o));
    let solved = path("solved.pfm");
    let mut args = vec!["render", "furnace", "--pfm", &solved];
    args.extend_from_slice(&view);
    let o = radiosity(&args);
    assert!(o.status.success(), "{}", stderr(&o));

    let diff = path("diff.png");
    let o = radiosity(&["compare", &solved, &reference, "-o", &diff, "--json", "-"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let y = r["channels"].as_array().unwrap().iter().find(|c| c["channel"] == "Y").unwrap();
    assert_eq!(y["pixels"], 24 * 16);
    let bias = y["mean_relative_difference"].as_f64().unwrap();
    assert!(bias.abs() < 0.01, "mean relative difference {bias}");
    assert!(y["mean_relative_error"].as_f64().unwrap() < 0.05, "{y}");
    assert!(std::path::Path::new(&diff).exists());

    // A picture compared with itself is exact.
    let o = radiosity(&["compare", &reference, &reference, "--json", "-"]);
    let r: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(r["channels"].as_array().unwrap().iter().all(|c| c["rmse"] == 0.0));
}

/// A scene with back faces sums them apart: the back of a model gets little light and
/// large relative differences, which would set the median of the whole scene. The totals
/// stay over every object; front and back each get their own verdict, in the text and the
/// report.
#[test]
fn verify_sums_front_and_back_faces_apart() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("plate.toml");
    std::fs::write(&scene, crate::cli::PLATE_BETWEEN_LAMPS).unwrap();
    let r = verify_json(&[scene.to_str().unwrap(), "--paths", "20000"]);
    let summary = &r["summary"];
    let (front, back) = (&summary["front_faces"], &summary["back_faces"]);
    assert_eq!(summary["objects"], 4, "{summary}");
    assert_eq!(front["objects"], 3, "{summary}");
    assert_eq!(back["objects"], 1, "{summary}");
    assert_eq!(back["worst"]["name"], "plate (back)", "{summary}");
    let over = |s: &serde_json::Value| s["over_3_sigma"].as_u64().unwrap();
    assert_eq!(over(front) + over(back), over(summary), "{summary}");
    let text = summary["text"].as_str().unwrap();
    assert!(text.starts_with("front faces: ") && text.contains("\nback faces: "), "{text}");
}
