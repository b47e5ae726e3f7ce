//! `radiosity bench --real`: a scene solved as `solve` does and judged against `verify`'s
//! path tracer, as a row of the table and a `{"case": "real"}` entry of the JSON.

use std::process::Command;

/// The Cornell box as a "real room": every field is there, the solve is right to within
/// the reference's noise (median object under 1 %), and the two stops are timed in order.
#[test]
fn bench_real_reports_the_cornell_box() {
    let out = Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(["bench", "--real", "cornell", "--real-reference-seconds", "5", "--json", "-"])
        .output()
        .expect("run radiosity");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // The table comes first on stdout, then the JSON document.
    let json = &stdout[stdout.find("\n{").expect("JSON after the table") + 1..];
    let v: serde_json::Value = serde_json::from_str(json).unwrap();
    let cases = v["cases"].as_array().unwrap();
    // --real leaves out the fixed cases.
    assert_eq!(cases.len(), 1, "{cases:?}");
    let c = &cases[0];
    assert_eq!(c["case"], "real");
    assert_eq!(c["scene"], "cornell");
    for key in
        ["triangles", "surfaces", "patches", "elements", "shots", "peak_heap_bytes", "objects_compared"]
    {
        assert!(c[key].as_u64().unwrap() > 0, "{key}: {c}");
    }
    let (coarse, fine) =
        (c["seconds_to_1_percent"].as_f64().unwrap(), c["seconds_to_0_1_percent"].as_f64().unwrap());
    assert!(0.0 < coarse && coarse <= fine, "{coarse} {fine}");
    assert!(fine <= c["solve_seconds"].as_f64().unwrap());
    assert_eq!(c["stop_reason"], "converged");
    assert!(c["unshot_fraction"].as_f64().unwrap() <= 1e-3);
    for key in ["emitted", "absorbed", "escaped", "unshot", "created", "residual"] {
        assert_eq!(c["energy"][key].as_array().map(Vec::len), Some(3), "{key}");
    }
    assert!(c["energy"]["residual"].as_array().unwrap().iter().all(|r| r.as_f64().unwrap().abs() < 1e-9));
    assert!(c["reference"]["paths"].as_u64().unwrap() > 0);
    let front = &c["summary"]["front_faces"];
    let median = front["median_abs_difference_percent"].as_f64().unwrap();
    assert!(median < 1.0, "median |difference| {median} %: {front}");
    assert!(front["area_weighted_difference_percent"].as_f64().is_some());
    assert!(front["over_3_sigma"].as_u64().is_some());
    assert!(front["worst"]["difference_percent"].as_f64().is_some());
    let objects = c["objects"].as_array().unwrap();
    assert_eq!(objects.len() as u64, c["objects_compared"].as_u64().unwrap());
    assert!(objects.iter().all(|o| o["difference_percent"].as_f64().is_some()), "{objects:?}");
    // The Cornell box is one-sided: no back faces to sum.
    assert!(c["summary"].get("back_faces").is_none());
    assert!(stdout.contains("(f) real rooms"), "{stdout}");
}

/// A reference budget that is not a positive number of seconds is refused before any solve.
#[test]
fn bench_real_refuses_a_bad_reference_budget() {
    for bad in ["0", "-1", "nan", "inf"] {
        let out = Command::new(env!("CARGO_BIN_EXE_radiosity"))
            .args(["bench", "--real", "cornell", "--real-reference-seconds", bad])
            .output()
            .expect("run radiosity");
        assert_eq!(out.status.code(), Some(2), "{bad}: {}", String::from_utf8_lossy(&out.stderr));
        assert!(String::from_utf8_lossy(&out.stderr).contains("--real-reference-seconds"));
    }
}
