//! The bad-input and fault corpus, end to end through the `radiosity` binary: every case ends
//! in a clean error — the expected exit code, one line on stderr naming the option, file,
//! line or key at fault, no panic — within a deadline (a hang fails the test), and no output
//! file is lost or left half written.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Far above any case here (each refuses before solving, or solves a few shots); a case that
/// runs into it is a hang.
const DEADLINE: Duration = Duration::from_secs(60);

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_radiosity"))
}

/// Runs `cmd` to its end, killing it at [`DEADLINE`] (then the test fails: a hang).
fn finish(mut cmd: Command, what: &str) -> Output {
    let mut child = cmd.stdin(Stdio::null()).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > DEADLINE {
            let _ = child.kill();
            panic!("{what}: still running after {DEADLINE:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

fn run(args: &[&str]) -> Output {
    let mut cmd = bin();
    cmd.args(args);
    finish(cmd, &args.join(" "))
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Asserts a clean input error: exit 2, one line, no panic, every needle in the message.
fn assert_input_error(o: &Output, what: &str, needles: &[&str]) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{what}: {err}");
    assert!(!err.contains("panicked"), "{what}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{what}: {err}");
    assert!(err.len() < 1200, "{what}: a long message: {err}");
    for n in needles {
        assert!(err.contains(n), "{what}: '{n}' not in: {err}");
    }
}

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// A one-square-metre lamp above a floor, for scene-value cases to break one key of.
const SCENE: &str = "[[material]]\nname = \"lamp\"\nreflectance = [0, 0, 0]\nemission = [1, 1, 1]\n\
[[material]]\nname = \"grey\"\nreflectance = [0.5, 0.5, 0.5]\n\
[[object]]\nname = \"lamp\"\ntype = \"polygon\"\nmaterial = \"lamp\"\nvertices = [[0, 1, 0], [0, 1, 1], [1, 1, 1], [1, 1, 0]]\n\
[[object]]\nname = \"floor\"\ntype = \"polygon\"\nmaterial = \"grey\"\nvertices = [[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]]\n";

#[test]
fn out_of_range_options_are_one_line_errors() {
    let cases: &[(&[&str], &str)] = &[
        (&["solve", "two-plates", "--time-limit", "1e20"], "--time-limit"),
        (&["solve", "two-plates", "--time-limit", "1e308"], "--time-limit"),
        (&["solve", "two-plates", "--time-limit", "-1"], "--time-limit"),
        (&["solve", "two-plates", "--time-limit", "inf"], "--time-limit"),
        (&["solve", "two-plates", "--threads", "10000"], "--threads"),
        (&["solve", "two-plates", "--threads", "0"], "--threads"),
        (&["solve", "two-plates", "--visibility-rays", "4294967295"], "--visibility-rays"),
        (&["solve", "two-plates", "--penumbra-rays", "4294967295"], "--penumbra-rays"),
        (&["solve", "two-plates", "--dim-rays", "4294967295"], "--dim-rays"),
        (&["solve", "two-plates", "--dim-rays", "0"], "--dim-rays"),
        (&["solve", "two-plates", "--light-scale", "1e308"], "--light-scale"),
        (&["solve", "two-plates", "--light-scale", "-1"], "--light-scale"),
        (&["solve", "two-plates", "--unshot-threshold", "0"], "--unshot-threshold"),
        (&["solve", "two-plates", "--max-shots", "0"], "--max-shots"),
        (&["solve", "two-plates", "--overshoot", "2.5"], "--overshoot"),
        (&["solve", "two-plates", "--bright-share", "nan"], "--bright-share"),
        (&["render", "two-plates", "-o", "never.png", "--fov", "-5"], "fov"),
        (&["render", "two-plates", "-o", "never.png", "--fov", "180"], "fov"),
        (&["render", "two-plates", "-o", "never.png", "--width", "16384", "--height", "16384"], "pixels"),
        (&["render", "two-plates", "-o", "never.png", "--width", "0"], "width"),
        (&["render", "two-plates", "-o", "never.png", "--penumbra-factor", "0"], "penumbra_factor"),
        (&["render", "two-plates", "-o", "never.png", "--penumbra-factor", "65"], "penumbra_factor"),
    ];
    for (args, needle) in cases {
        let o = run(args);
        assert_input_error(&o, &args.join(" "), &[needle]);
    }
    assert!(!Path::new("never.png").exists());
}

#[test]
fn bad_scene_values_name_file_line_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("time.toml", format!("{SCENE}[solver]\ntime_limit = 1e308\n"), "solver.time_limit"),
        ("time0.toml", format!("{SCENE}[solver]\ntime_limit = 0\n"), "solver.time_limit"),
        ("rho4.toml", SCENE.replace("[0.5, 0.5, 0.5]", "[0.5, 0.5, 0.5, 0.5]"), "reflectance"),
        ("rho2.toml", SCENE.replace("[0.5, 0.5, 0.5]", "[0.5, 0.5]"), "reflectance"),
        ("vertex4.toml", SCENE.replace("[1, 0, 1]", "[1, 0, 1, 7]"), "vertices"),
        ("emission4.toml", SCENE.replace("emission = [1, 1, 1]", "emission = [1, 1, 1, 1]"), "emission"),
        (
            "box4.toml",
            format!(
                "{SCENE}[[object]]\nname = \"b\"\ntype = \"box\"\nmaterial = \"grey\"\nmin = [0, 0, 0, 0]\nmax = [1, 1, 1]\n"
            ),
            "min",
        ),
        (
            "camera4.toml",
            format!("{SCENE}[camera]\nposition = [0, 0, 5, 1]\nlook_at = [0, 0, 0]\n"),
            "position",
        ),
    ];
    for (name, text, key) in cases {
        let path = write(dir.path(), name, &text);
        let o = run(&["info", path.to_str().unwrap()]);
        assert_input_error(&o, name, &[name, key]);
        // file:line:col
        let err = stderr(&o);
        let after = &err[err.find(name).unwrap() + name.len()..];
        assert!(after.starts_with(':') && after[1..2].parse::<u32>().is_ok(), "{name}: no line in {err}");
    }
}

/// A FIFO would block a reader forever, `/dev/zero` would fill the memory: both are refused
/// before a byte is read, as scene, model, MTL and picture.
#[cfg(unix)]
#[test]
fn fifos_and_devices_are_refused_not_read() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("scene.toml");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    let o = run(&["info", fifo.to_str().unwrap()]);
    assert_input_error(&o, "fifo scene", &["scene.toml", "not a regular file"]);
    let o = run(&["info", "/dev/zero"]);
    assert_input_error(&o, "/dev/zero", &["/dev/zero", "not a regular file"]);
    let pfm = dir.path().join("in.pfm");
    assert!(Command::new("mkfifo").arg(&pfm).status().unwrap().success());
    let out = dir.path().join("out.png");
    let o = run(&["tonemap", pfm.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_input_error(&o, "fifo pfm", &["in.pfm", "not a regular file"]);
    // An OBJ whose MTL is a FIFO: the library is not read (a warning), the load goes on.
    let obj = write(dir.path(), "m.obj", &format!("mtllib m.mtl\n{}", OBJ_BODY));
    assert!(Command::new("mkfifo").arg(dir.path().join("m.mtl")).status().unwrap().success());
    // `info` describes the model, lightless without its library.
    let o = run(&["info", obj.to_str().unwrap()]);
    assert!(o.status.success(), "fifo mtl: {}", stderr(&o));
    assert!(stderr(&o).contains("m.mtl: not a regular file"), "fifo mtl: {}", stderr(&o));
}

/// Two quads: a lamp (material `lamp`) above a floor (material `grey`).
const OBJ_BODY: &str = "v 0 1 0\nv 0 1 1\nv 1 1 1\nv 1 1 0\nv 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\n\
o lamp\nusemtl lamp\nf 1 2 3 4\no floor\nusemtl grey\nf 5 6 7 8\n";

#[test]
fn malformed_mtl_lines_are_errors_with_their_line() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write(dir.path(), "m.obj", &format!("mtllib m.mtl\n{OBJ_BODY}"));
    let good = "newmtl lamp\nKd 0 0 0\nKe 1 1 1\nnewmtl grey\nKd 0.5 0.5 0.5\n";
    // One number is the MTL spec's grey (it used to panic inside the OBJ crate): accepted.
    write(dir.path(), "m.mtl", &good.replace("Kd 0.5 0.5 0.5", "Kd 0.5"));
    let o = run(&["info", obj.to_str().unwrap()]);
    assert!(o.status.success(), "Kd with one number: {}", stderr(&o));
    let cases = [
        (good.replace("Kd 0.5 0.5 0.5", "Kd 0.5 0.5"), 5, "Kd"),
        (good.replace("Kd 0.5 0.5 0.5", "Kd 0.5 0.5 0.5 0.5"), 5, "Kd"),
        (good.replace("Ke 1 1 1", "Ke"), 3, "Ke"),
        (good.replace("Ke 1 1 1", "Ke 1 x 1"), 3, "Ke"),
        (good.replace("Ke 1 1 1", "Ke spectral lamp.spd"), 3, "Ke"),
        (good.replace("Kd 0 0 0", "Kd nan 0 0"), 2, "Kd"),
        (format!("{good}Ns\n"), 6, "Ns"),
        (format!("{good}illum many\n"), 6, "illum"),
        (format!("{good}map_Kd\n"), 6, "map_Kd"),
        (format!("newmtl\n{good}"), 1, "newmtl"),
    ];
    for (text, line, key) in cases {
        write(dir.path(), "m.mtl", &text);
        let o = run(&["info", obj.to_str().unwrap()]);
        assert_input_error(&o, &text, &[&format!("m.mtl:{line}"), key]);
    }
}

/// The warning that explains the missing light comes first, once; then the error, exit 2.
/// `info` describes the same model, saying what a solve would lack.
#[test]
fn a_missing_mtl_is_warned_of_before_the_no_light_error() {
    let dir = tempfile::tempdir().unwrap();
    let obj = write(dir.path(), "m.obj", &format!("mtllib gone.mtl\n{OBJ_BODY}"));
    let o = run(&["solve", obj.to_str().unwrap()]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    // The usemtl lines that name no known material are warned of too.
    let (error, warnings) =
        err.trim_end().lines().collect::<Vec<_>>().split_last().map(|(e, w)| (*e, w.to_vec())).unwrap();
    assert!(error.starts_with("error: ") && error.contains("no light"), "{err}");
    assert!(warnings.iter().all(|w| w.starts_with("warning: ")), "{err}");
    assert!(warnings.iter().any(|w| w.contains("gone.mtl")), "{err}");
    assert_eq!(err.matches("gone.mtl").count(), 1, "each warning once, none in the error: {err}");

    let o = run(&["info", obj.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stderr(&o).matches("gone.mtl").count(), 1, "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("warning    no light: a solve would be black; "), "{out}");
}

#[test]
fn an_undefined_usemtl_is_a_warning_with_its_line() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "m.mtl", "newmtl lamp\nKd 0 0 0\nKe 1 1 1\n");
    let obj = write(dir.path(), "m.obj", &format!("mtllib m.mtl\n{OBJ_BODY}"));
    let o = run(&["info", obj.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("m.obj:14") && err.contains("usemtl 'grey'"), "{err}");
}

#[test]
fn picture_headers_are_checked_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.png");
    for (name, header) in [
        ("huge.pfm", "PF\n2147483648 2147483648\n-1.0\n"),
        ("wrap.pfm", "PF\n4294967295 4294967295\n-1.0\n"),
        ("big.pfm", "PF\n100000 100000\n-1.0\n"),
        ("short.pfm", "PF\n4 4\n-1.0\n"),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, header.as_bytes()).unwrap();
        let o = run(&["tonemap", path.to_str().unwrap(), "-o", out.to_str().unwrap()]);
        assert_input_error(&o, name, &[name]);
    }
    assert!(!out.exists());
    // An OpenEXR header declaring 4096 × 4096 pixels (within the pixel limit) and then no
    // data: refused by its size against the file's before a pixel is allocated.
    let path = dir.path().join("hollow.exr");
    std::fs::write(&path, exr_header(4096, 4096, None)).unwrap();
    let o = run(&["tonemap", path.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_input_error(&o, "hollow.exr", &["hollow.exr", "4096×4096", "bytes can hold"]);
    assert!(!out.exists());
    // A 4 × 3 picture in tiles of 2²⁴ × 2²¹ pixels: the tile buffer is not allocated either
    // (a fuzzer's 487-byte file of this kind took 1.9 GB).
    let path = dir.path().join("tiles.exr");
    std::fs::write(&path, exr_header(4, 3, Some((1 << 24, 1 << 21)))).unwrap();
    let o = run(&["tonemap", path.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_input_error(&o, "tiles.exr", &["tiles.exr", "tiles of 16777216×2097152", "bytes can"]);
    assert!(!out.exists());
    // The fuzzer's file itself, with its tile offsets and data.
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bad/huge-tiles.exr");
    let o = run(&["tonemap", path.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert_input_error(&o, "huge-tiles.exr", &["huge-tiles.exr", "tiles of 16777280×3604480"]);
    assert!(!out.exists());
}

/// An OpenEXR header (RGB half floats, no compression) of a `width` × `height` picture, in
/// scan lines or in one level of `tiles` (width, height), and no pixel data.
fn exr_header(width: i32, height: i32, tiles: Option<(u32, u32)>) -> Vec<u8> {
    // Version 2; bit 9 of the version field marks a single-part tiled file.
    let mut b = vec![0x76, 0x2f, 0x31, 0x01, 2, if tiles.is_some() { 2 } else { 0 }, 0, 0];
    let mut attribute = |name: &str, kind: &str, value: &[u8]| {
        for text in [name, kind] {
            b.extend_from_slice(text.as_bytes());
            b.push(0);
        }
        b.extend_from_slice(&(value.len() as i32).to_le_bytes());
        b.extend_from_slice(value);
    };
    let mut channels = Vec::new();
    for c in ["B", "G", "R"] {
        channels.extend_from_slice(c.as_bytes());
        channels.extend_from_slice(&[0, 1, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0]);
    }
    channels.push(0);
    let window: Vec<u8> = [0, 0, width - 1, height - 1].iter().flat_map(|v: &i32| v.to_le_bytes()).collect();
    attribute("channels", "chlist", &channels);
    attribute("compression", "compression", &[0]);
    attribute("dataWindow", "box2i", &window);
    attribute("displayWindow", "box2i", &window);
    attribute("lineOrder", "lineOrder", &[0]);
    attribute("pixelAspectRatio", "float", &1f32.to_le_bytes());
    attribute("screenWindowCenter", "v2f", &[0; 8]);
    attribute("screenWindowWidth", "float", &1f32.to_le_bytes());
    if let Some((w, h)) = tiles {
        let description: Vec<u8> =
            [w.to_le_bytes(), h.to_le_bytes()].concat().into_iter().chain([0]).collect();
        attribute("tiles", "tiledesc", &description);
    }
    b.push(0);
    b
}

/// A polygon of `n` corners on the unit circle, as a scene file's `vertices`.
fn disc(n: usize) -> String {
    let corners: Vec<String> = (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            format!("[{:.12}, 0, {:.12}]", a.cos(), -a.sin())
        })
        .collect();
    format!("[{}]", corners.join(", "))
}

/// A light of the most corners a polygon may have (1024) meshes into its fan; one of 10⁵ or
/// 10⁶ corners, which never finished solving (a patch per fan triangle, each shot visiting
/// every patch), is refused at its line, as is a model face of 5 000 (concave) or 20 000
/// (convex) corners, before anything is triangulated.
#[test]
fn polygons_of_many_corners_mesh_or_name_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let light = |n: usize| {
        format!(
            "[[material]]\nname = \"lamp\"\nreflectance = [0.5, 0.5, 0.5]\nemission = [1, 1, 1]\n\
             [[object]]\nname = \"disc\"\ntype = \"polygon\"\nmaterial = \"lamp\"\nvertices = {}\n\
             [mesh]\npatch_size = 10\nelement_size = 10\n",
            disc(n)
        )
    };
    let path = write(dir.path(), "disc.toml", &light(1024));
    let o = run(&["info", path.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    let elements: usize =
        out.lines().find_map(|l| l.strip_prefix("elements")).unwrap().trim().parse().unwrap();
    assert_eq!(elements, 1022, "one element per fan triangle");
    for n in [100_000, 1_000_000] {
        let path = write(dir.path(), "big.toml", &light(n));
        // Quiet: on a loaded machine reading a million corners may outlast the 5 s after
        // which a progress line joins the one error line counted here.
        let o = run(&["-q", "info", path.to_str().unwrap()]);
        assert_input_error(&o, "big.toml", &["big.toml:9:", "object[0].vertices", &n.to_string(), "1024"]);
    }
    write(dir.path(), "m.mtl", "newmtl lamp\nKd 0 0 0\nKe 1 1 1\nnewmtl grey\nKd 0.5 0.5 0.5\n");
    for (n, inner) in [(5_000, 0.5), (20_000, 1.0), (20_000, 0.5)] {
        let mut text =
            String::from("mtllib m.mtl\nv 0 1 0\nv 0 1 1\nv 1 1 1\nv 1 1 0\nusemtl lamp\nf 1 2 3 4\n");
        for k in 0..n {
            let (a, r) = (std::f64::consts::TAU * k as f64 / n as f64, if k % 2 == 0 { 1.0 } else { inner });
            text += &format!("v {:.12} 0 {:.12}\n", r * a.cos(), -r * a.sin());
        }
        text += "usemtl grey\nf";
        for k in 0..n {
            text += &format!(" {}", 5 + k);
        }
        text += "\n";
        let obj = write(dir.path(), "star.obj", &text);
        let o = run(&["-q", "info", obj.to_str().unwrap()]);
        let line = format!("star.obj:{}", n + 9);
        assert_input_error(&o, "star.obj", &[&line, "face 2", &n.to_string(), "1024"]);
    }
}

#[test]
fn output_targets_are_checked_before_the_solve() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = |p: PathBuf| p.to_str().unwrap().to_owned();
    let same = s(d.join("x.png"));
    let missing = s(d.join("no/such/folder/x.png"));
    let folder = s(d.to_path_buf());
    // A long solve, so a check made only after it would show as a timeout here.
    let slow = ["--unshot-threshold", "1e-9", "--max-shots", "100000000"];
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["render", "cornell", "-o", &same, "--exr", &same], "same file"),
        (vec!["render", "cornell", "-o", &missing], "no/such/folder"),
        (vec!["solve", "cornell", "--json", &missing], "no/such/folder"),
        (vec!["solve", "cornell", "--json", &folder], "not a regular file"),
        (vec!["export", "cornell", "-o", &missing], "no/such/folder"),
    ];
    for (mut args, needle) in cases {
        args.extend(slow);
        let o = run(&args);
        assert_input_error(&o, &args.join(" "), &[needle]);
    }
    assert!(!d.join("x.png").exists());
}

/// `/dev/null` (a stream, not a file that could be replaced) takes a report or a picture,
/// with or without `--force`: the common way to discard one.
#[test]
fn outputs_to_dev_null_are_discarded() {
    for args in [
        vec!["solve", "cornell", "--max-shots", "5", "--json", "/dev/null"],
        vec!["solve", "cornell", "--max-shots", "5", "--json", "/dev/null", "--force"],
        vec![
            "render",
            "cornell",
            "--max-shots",
            "5",
            "--width",
            "32",
            "--height",
            "24",
            "--pfm",
            "/dev/null",
        ],
    ] {
        let o = run(&args);
        assert!(o.status.success(), "{}: {}", args.join(" "), String::from_utf8_lossy(&o.stderr));
    }
}

#[cfg(unix)]
#[test]
fn a_read_only_folder_is_refused_before_the_solve() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let ro = dir.path().join("ro");
    std::fs::create_dir(&ro).unwrap();
    std::fs::set_permissions(&ro, std::fs::Permissions::from_mode(0o555)).unwrap();
    // Root writes anywhere: then there is nothing to refuse.
    if tempfile::tempfile_in(&ro).is_ok() {
        return;
    }
    let target = ro.join("r.json");
    let o = run(&["solve", "cornell", "--unshot-threshold", "1e-9", "--json", target.to_str().unwrap()]);
    assert_input_error(&o, "read-only folder", &["cannot write into"]);
}

/// Writes to stdout that fail: a reader that has gone ends the run quietly with the shell's
/// SIGPIPE status; a full disk is an error with exit code 1 and says so.
#[cfg(unix)]
#[test]
fn closed_and_full_standard_streams_end_cleanly() {
    for (args, stream) in [
        (&["info", "cornell"][..], "stdout"),
        (&["solve", "two-plates", "--max-shots", "3", "--json", "-"][..], "stdout"),
        (&["solve", "two-plates", "--max-shots", "3"][..], "stderr"),
    ] {
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let mut cmd = bin();
        cmd.args(args);
        let mut cmd_out = if stream == "stdout" {
            cmd.stdout(writer).stderr(Stdio::piped())
        } else {
            cmd.stderr(writer).stdout(Stdio::null())
        }
        .stdin(Stdio::null())
        .spawn()
        .unwrap();
        let status = cmd_out.wait().unwrap();
        let mut err = String::new();
        if let Some(mut e) = cmd_out.stderr.take() {
            std::io::Read::read_to_string(&mut e, &mut err).unwrap();
        }
        assert_eq!(status.code(), Some(141), "{args:?} with {stream} closed: {err}");
        // Quietly: the summary line may be there, no error and no panic.
        assert!(!err.contains("error") && !err.contains("panicked"), "{args:?}: {err}");
    }
    if Path::new("/dev/full").exists() {
        for args in
            [&["info", "cornell"][..], &["solve", "two-plates", "--max-shots", "3", "--json", "-"][..]]
        {
            let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
            let o =
                bin().args(args).stdin(Stdio::null()).stdout(full).stderr(Stdio::piped()).output().unwrap();
            let err = stderr(&o);
            assert_eq!(o.status.code(), Some(1), "{args:?}: {err}");
            assert!(err.contains("stdout") && err.contains("No space left"), "{args:?}: {err}");
            assert!(!err.contains("panicked"), "{err}");
        }
    }
}

/// Sends `signal` (a name `kill` knows: STOP, KILL) to process `pid`.
#[cfg(unix)]
fn signal(pid: u32, signal: &str) {
    let status = Command::new("kill").arg(format!("-{signal}")).arg(pid.to_string()).status().unwrap();
    assert!(status.success(), "kill -{signal} {pid}");
}

/// Whether `dir` holds a temporary file for `name` (the output module's `.NAME.*`).
fn has_temporary(dir: &Path, name: &str) -> bool {
    let prefix = format!(".{name}.");
    std::fs::read_dir(dir).unwrap().flatten().any(|e| e.file_name().to_string_lossy().starts_with(&prefix))
}

/// `--force` over an existing picture, killed while the new one is being written: the old
/// file stays whole, because the new one goes to a temporary file that is renamed into place
/// only once complete. The run is stopped (SIGSTOP) as soon as the temporary file appears and
/// killed only if that file is still there, i.e. the rename has not happened: so the kill
/// provably lands mid-write. A run whose write slipped between two polls is tried again; none
/// caught in ten tries fails the test.
#[cfg(unix)]
#[test]
fn a_killed_write_leaves_the_old_file_whole() {
    let dir = tempfile::tempdir().unwrap();
    let pfm = dir.path().join("r.pfm");
    let old = b"PF\n1 1\n-1.0\n\0\0\x80?\0\0\x80?\0\0\x80?".to_vec();
    for attempt in 0..10 {
        std::fs::write(&pfm, &old).unwrap();
        let mut child = bin()
            .args(["render", "two-plates", "--max-shots", "1", "--width", "2000", "--height", "2000"])
            .args(["--spp", "1", "--gather", "none", "--force", "--pfm", pfm.to_str().unwrap()])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let start = Instant::now();
        let mut caught = false;
        while child.try_wait().unwrap().is_none() && start.elapsed() < DEADLINE {
            if has_temporary(dir.path(), "r.pfm") {
                signal(child.id(), "STOP");
                caught = has_temporary(dir.path(), "r.pfm");
                break;
            }
            std::thread::sleep(Duration::from_micros(200));
        }
        let _ = child.kill();
        let _ = child.wait();
        let now = std::fs::read(&pfm).unwrap();
        if caught {
            assert_eq!(now, old, "attempt {attempt}: killed mid-write, the old file must be untouched");
            return;
        }
        // Not caught mid-write: the run finished (or was stopped after its rename), and then
        // the file is the whole new picture.
        let img = radiosity_image::decode_pfm(&now, &pfm).expect("a whole PFM");
        assert_eq!((img.width(), img.height()), (2000, 2000));
    }
    panic!("no kill landed during the write in ten runs");
}

/// A full disk, as the file-size limit (RLIMIT_FSIZE, `ulimit -f`) makes it for one process
/// without privileges: the write fails with EFBIG as it would with ENOSPC. The run must say
/// so with exit 1, name the file, keep the old file and leave no temporary file behind.
#[cfg(unix)]
#[test]
fn a_full_disk_is_an_error_and_keeps_the_old_file() {
    let dir = tempfile::tempdir().unwrap();
    let mut cases = vec![];
    for (flag, name) in [("--pfm", "r.pfm"), ("-o", "r.png"), ("--exr", "r.exr")] {
        let path = dir.path().join(name);
        std::fs::write(&path, "old picture").unwrap();
        cases.push((flag, name, path));
    }
    for (flag, name, path) in &cases {
        let mut cmd = Command::new("sh");
        // Signal disposition "ignored" survives exec, so the write returns EFBIG instead of the
        // process dying of SIGXFSZ. 8 blocks (4 or 8 KiB) is far below any of the pictures (the PNG, the smallest, is ~16 KB).
        cmd.args(["-c", "trap '' XFSZ; ulimit -f 8; exec \"$@\"", "sh"])
            .arg(env!("CARGO_BIN_EXE_radiosity"))
            .args(["render", "two-plates", "--max-shots", "1", "--width", "512", "--height", "512"])
            .args(["--spp", "1", "--gather", "none", "--force", flag, path.to_str().unwrap()]);
        let o = finish(cmd, name);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{name}: {err}");
        assert!(!err.contains("panicked") && !err.contains("wrote"), "{name}: {err}");
        assert!(err.contains(name), "{name}: the error names the file: {err}");
        assert_eq!(std::fs::read_to_string(path).unwrap(), "old picture", "{name}");
        assert!(!has_temporary(dir.path(), name), "{name}: a temporary file was left behind");
    }
}

/// A mesh over the element limit is refused before meshing, at the line that asks for it.
#[test]
fn a_mesh_over_the_element_limit_names_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let fine = write(
        dir.path(),
        "fine.toml",
        &format!("{SCENE}[mesh]\npatch_size = 0.001\nelement_size = 0.0001\n"),
    );
    let o = run(&["solve", fine.to_str().unwrap()]);
    assert_input_error(&o, "fine", &["fine.toml:20:", "mesh.element_size", "20000000", "'lamp'", "line 8)"]);
    let moon = format!(
        "{SCENE}[[object]]\nname = \"moon\"\ntype = \"sphere\"\nmaterial = \"grey\"\ncenter = [0, 0, 0]\nradius = 1e5\n\
         [mesh]\npatch_size = 1\nelement_size = 0.1\n"
    );
    let path = write(dir.path(), "moon.toml", &moon);
    let o = run(&["info", path.to_str().unwrap()]);
    assert_input_error(&o, "moon", &["moon.toml:26:", "mesh.element_size", "'moon'", "line 18)"]);
}

#[test]
fn nothing_is_overwritten_that_appeared_during_the_run() {
    // Without --force a target that exists is refused before the solve; one that appears
    // while the solve runs is kept too (the rename does not replace it). The second part
    // is a race with the solve, so it is tested on the output module itself (src/output.rs).
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("a.png");
    std::fs::write(&png, "precious").unwrap();
    let o = run(&[
        "render",
        "two-plates",
        "--max-shots",
        "1",
        "--width",
        "8",
        "--height",
        "8",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert_input_error(&o, "existing png", &["a.png", "--force"]);
    assert_eq!(std::fs::read_to_string(&png).unwrap(), "precious");
}

/// A threshold no solve can reach (1e-300) stops where shooting changes nothing the solution
/// can show (`UNSHOT_FLOOR`, 1e-12), converged, saying so, instead of running until a time
/// limit with its progress at 0.000 %.
#[test]
fn an_unreachable_threshold_stops_at_the_floor() {
    let o = run(&["solve", "cornell", "--unshot-threshold", "1e-300", "--json", "-"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("stops at 1e-12"),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["stop_reason"], "converged", "{report}");
    let unshot = report["unshot_fraction"].as_f64().unwrap();
    assert!(unshot <= 1e-12 && unshot > 0.0, "{unshot}");
}

/// Points beyond ±1e12 (`MAX_COORDINATE`) are refused where they are written: a sphere at
/// 1e308 used to abort on a 25 GB allocation while meshing.
#[test]
fn coordinates_beyond_the_limit_name_their_line() {
    let dir = tempfile::tempdir().unwrap();
    let sphere = |center: &str, radius: &str| {
        format!(
            "{SCENE}[[object]]\nname = \"s\"\ntype = \"sphere\"\nmaterial = \"grey\"\ncenter = {center}\nradius = {radius}\n"
        )
    };
    let cases = [
        ("far_sphere.toml", sphere("[1e308, 0, 0]", "1"), "far_sphere.toml:22:", "object[2].center", "1e308"),
        (
            "wide_sphere.toml",
            sphere("[0, 0, 0]", "1e13"),
            "wide_sphere.toml:23:",
            "object[2].radius",
            "10000000000000",
        ),
        ("reach.toml", sphere("[9.9e11, 0, 0]", "1e11"), "reach.toml:23:", "object[2].radius", "1e12"),
        ("corner.toml", SCENE.replace("[1, 0, 1]", "[1, 0, 1e20]"), "corner.toml:17:", "vertices[2]", "1e20"),
        (
            "camera.toml",
            format!("{SCENE}[camera]\nposition = [0, 0, -1e300]\nlook_at = [0, 0, 0]\n"),
            "camera.toml:19:",
            "camera.position",
            "-1e300",
        ),
    ];
    for (name, text, at, key, value) in cases {
        let path = write(dir.path(), name, &text);
        let o = run(&["info", path.to_str().unwrap()]);
        assert_input_error(&o, name, &[at, key, value]);
    }
    let obj = write(dir.path(), "far.obj", &format!("{OBJ_BODY}v 1e300 0 0\nf 1 2 9\n"));
    let o = run(&["info", obj.to_str().unwrap()]);
    assert_input_error(&o, "far.obj", &["far.obj:15", "vertex 9", "1e300"]);
}

/// Long slivers beside many short edges: the search for T-junctions walked each long edge in
/// steps of the median edge, 27 cells a step (a 5 000-corner concave face's ear-clipped
/// slivers asked for 3 GB). Now its cells are bounded by the edges' total length, so this
/// model (3 000 tiny triangles, 500 slivers 10⁵ times as long: 86 GB of cells before) meshes
/// at once.
#[test]
fn long_slivers_beside_short_edges_mesh_without_a_huge_table() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::from("v 0 1 0\nv 0 1 1\nv 1 1 1\nv 1 1 0\nf 1 2 3 4\n");
    let mut v = 4;
    // Spread over the floor, so that no cell of the mesher's grids holds many of them.
    for k in 0..3_000 {
        let (x, z) = ((k % 60) as f64 * 16.0, (k / 60) as f64 * 20.0);
        let (x1, z1) = (x + 0.01, z + 0.01);
        text += &format!("v {x} 0 {z}\nv {x1} 0 {z}\nv {x} 0 {z1}\nf {} {} {}\n", v + 1, v + 3, v + 2);
        v += 3;
    }
    for k in 0..500 {
        let (x, x1) = (k as f64 * 2.0 + 1.0, k as f64 * 2.0 + 1.01);
        text += &format!("v {x} 0 0\nv {x1} 0 1000\nv {x1} 0 0\nf {} {} {}\n", v + 1, v + 2, v + 3);
        v += 3;
    }
    let obj = write(dir.path(), "slivers.obj", &text);
    let o = run(&["info", obj.to_str().unwrap(), "--patch-size", "100", "--element-size", "100"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// Runs `args` as [`run`] does, failing the test past `limit` instead of [`DEADLINE`]: for
/// inputs whose quadratic paths took minutes, where a linear pass takes a second.
fn run_within(args: &[&str], limit: Duration) -> Output {
    let mut child =
        bin().args(args).stdin(Stdio::null()).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            panic!("{}: still running after {limit:?}", args.join(" "));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

/// Material names are looked up, not searched for: 200 000 unused materials (a search per
/// material: minutes), and 30 000 objects in a row using the last of 30 000 materials (a
/// search per object, and the ray tracer's tree builder merging one pair of equal tiles per
/// pass: minutes) load and mesh in about a second.
#[test]
fn many_materials_and_objects_load_in_linear_time() {
    let dir = tempfile::tempdir().unwrap();
    let materials = |n: usize| {
        (0..n)
            .map(|i| format!("[[material]]\nname = \"m{i}\"\nreflectance = [0.5, 0.5, 0.5]\n"))
            .collect::<String>()
    };
    let unused = write(dir.path(), "unused.toml", &format!("{}{SCENE}", materials(200_000)));
    let n = 30_000;
    let mut row = format!("{}{SCENE}", materials(n));
    for i in 0..n {
        row += &format!(
            "[[object]]\nname = \"o{i}\"\ntype = \"polygon\"\nmaterial = \"m{}\"\nvertices = [[{i}, 0, 2], [{}, 0, 2], [{}, 0, 3], [{i}, 0, 3]]\n",
            n - 1,
            i + 1,
            i + 1
        );
    }
    let row = write(dir.path(), "row.toml", &row);
    for path in [unused, row] {
        let o = run_within(&["info", path.to_str().unwrap()], Duration::from_secs(20));
        assert!(o.status.success(), "{}: {}", path.display(), stderr(&o));
    }
}

/// A disc of 60 000 triangles about one centre vertex (a cylinder's cap as exporters write
/// it): the solver's tables looked at every element around each vertex of each element, and
/// each rim vertex fitted the whole fan (quadratic in the centre's valence: 26 GB at 10⁵).
#[test]
fn a_fan_of_many_triangles_solves() {
    let dir = tempfile::tempdir().unwrap();
    let n = 60_000;
    let mut text =
        String::from("mtllib m.mtl\nv 0 1 0\nv 0 1 1\nv 1 1 1\nv 1 1 0\nusemtl lamp\nf 1 2 3 4\nv 0 0 0\n");
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        text += &format!("v {:.12} 0 {:.12}\n", 2.0 * a.cos(), -2.0 * a.sin());
    }
    text += "usemtl grey\n";
    for k in 0..n {
        text += &format!("f 5 {} {}\n", 6 + k, 6 + (k + 1) % n);
    }
    write(dir.path(), "m.mtl", "newmtl lamp\nKd 0 0 0\nKe 1 1 1\nnewmtl grey\nKd 0.5 0.5 0.5\n");
    let obj = write(dir.path(), "fan.obj", &text);
    let args =
        ["solve", obj.to_str().unwrap(), "--max-shots", "3", "--patch-size", "10", "--element-size", "10"];
    let o = run_within(&args, Duration::from_secs(30));
    assert!(o.status.success(), "{}", stderr(&o));
}

/// `--lightmap a/b/c` makes the missing folders, as `mkdir -p` would (making folders replaces
/// nothing); a folder an earlier run wrote into still needs `--force`, and a file in the way
/// is named.
#[test]
fn lightmaps_go_into_new_nested_folders() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let s = |p: PathBuf| p.to_str().unwrap().to_owned();
    let (ply, nested) = (s(d.join("a.ply")), s(d.join("a/b/c")));
    let o = run(&["export", "two-plates", "--max-shots", "2", "-o", &ply, "--lightmap", &nested]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(d.join("a/b/c/lightmapped.obj").is_file());
    let again = s(d.join("b.ply"));
    let o = run(&["export", "two-plates", "--max-shots", "2", "-o", &again, "--lightmap", &nested]);
    assert_input_error(&o, "again", &["lightmapped.obj", "--force"]);
    std::fs::write(d.join("file"), "in the way").unwrap();
    let blocked = s(d.join("file/x/y"));
    let o = run(&["export", "two-plates", "--max-shots", "2", "-o", &again, "--lightmap", &blocked]);
    assert_input_error(&o, "blocked", &["file", "not a folder"]);
    assert!(!d.join("b.ply").exists());
}
