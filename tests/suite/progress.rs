//! Long steps are never silent: without a terminal, a progress line every few seconds (here
//! shortened by the hidden `--progress-interval`); `--quiet` silences them; `verify` states its
//! reference's time budget and precision, and Ctrl-C prints what it has so far.

use std::io::{BufRead, BufReader, Read};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn radiosity(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_radiosity")).args(args).output().expect("run radiosity")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A reference that runs a second or so: enough for several lines 0.1 s apart.
const LONG_REFERENCE: [&str; 6] = ["--max-shots", "20", "--paths", "300000", "--progress-interval", "0.1"];

/// Without a terminal the reference prints timed lines saying how far it is; the results are
/// the same with `--quiet`, which prints none of them.
#[test]
fn log_lines_say_how_far_and_quiet_silences_them() {
    let mut args = vec!["verify", "cornell", "--json", "-"];
    args.extend_from_slice(&LONG_REFERENCE);
    let o = radiosity(&args);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    let lines: Vec<&str> = err.lines().filter(|l| l.starts_with('[') && l.contains(" s] ")).collect();
    assert!(lines.iter().any(|l| l.contains("] reference: ") && l.contains("M paths/s")), "{err}");
    args.push("--quiet");
    let q = radiosity(&args);
    let quiet = stderr(&q);
    assert!(q.status.success(), "{quiet}");
    assert!(!quiet.lines().any(|l| l.starts_with('[') && l.contains(" s] ")), "{quiet}");
    // Progress changes no result.
    let objects =
        |o: &Output| serde_json::from_slice::<serde_json::Value>(&o.stdout).unwrap()["objects"].clone();
    assert_eq!(objects(&o), objects(&q));
}

/// Without options, the reference has a time budget, said before it starts, and its
/// precision is said after it.
#[test]
fn verify_states_its_budget_and_precision() {
    let o = radiosity(&["verify", "two-plates", "--max-shots", "5", "--json", "-"]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("at most 120 s (the default budget"), "{err}");
    assert!(err.contains("standard error at most"), "{err}");
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["reference_time_limit"], 120.0);
    assert_eq!(report["interrupted"], false);
    let o = radiosity(&["verify", "two-plates", "--reference-time", "0"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// Ctrl-C during the reference: the table of what it has so far is printed, the run says it
/// was interrupted, and exits with 130 as a shell reports Ctrl-C.
#[test]
fn ctrl_c_during_verify_prints_what_it_has() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_radiosity"))
        .args(["verify", "cornell", "--max-shots", "20", "--paths", "1000000000"])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = BufReader::new(child.stderr.take().unwrap());
    let mut said = String::new();
    let start = Instant::now();
    while !said.contains("reference: path tracing") {
        assert!(start.elapsed() < Duration::from_secs(60), "no reference started: {said}");
        if err.read_line(&mut said).unwrap() == 0 {
            panic!("ended early: {said}");
        }
    }
    // The reference has begun its billion paths per object; let it run a moment.
    std::thread::sleep(Duration::from_millis(300));
    let pid = libc::pid_t::try_from(child.id()).unwrap();
    // SAFETY: sends a signal to the child this test started and still holds.
    assert_eq!(unsafe { libc::kill(pid, libc::SIGINT) }, 0);
    let mut rest = String::new();
    err.read_to_string(&mut rest).unwrap();
    let mut table = String::new();
    child.stdout.take().unwrap().read_to_string(&mut table).unwrap();
    let status = child.wait().unwrap();
    said += &rest;
    assert_eq!(status.code(), Some(130), "{said}");
    assert!(said.contains("stopped by Ctrl-C") && said.contains("interrupted:"), "{said}");
    assert!(table.contains("reference Y") && table.contains("floor"), "{table}");
}
