//! Models written with another axis up (building models: +z) read with `--up` or a scene
//! file's `up` key: the same room written y-up and z-up gives the same picture and the same
//! per-object results, and a z-up room read without the flag gets a note naming it.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use radiosity_core::UpAxis;
use radiosity_core::glam::DVec3;

fn radiosity(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_radiosity")).args(args).output().expect("run radiosity")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A small room, +y up, 4 × 2.5 × 3 (lower than it is wide and deep, as rooms are): floor,
/// ceiling, four walls facing in, a block on the floor and a ceiling lamp facing down.
const ROOM_Y_UP: &str = "mtllib room.mtl
v 0 0 0
v 4 0 0
v 4 0 3
v 0 0 3
v 0 2.5 0
v 4 2.5 0
v 4 2.5 3
v 0 2.5 3
v 1.5 2.49 1
v 2.5 2.49 1
v 2.5 2.49 2
v 1.5 2.49 2
v 0.5 0 0.5
v 1.3 0 0.5
v 1.3 0 1.3
v 0.5 0 1.3
v 0.5 0.8 0.5
v 1.3 0.8 0.5
v 1.3 0.8 1.3
v 0.5 0.8 1.3
o floor
usemtl white
f 1 4 3 2
o ceiling
usemtl white
f 5 6 7 8
o walls
usemtl red
f 1 2 6 5
f 2 3 7 6
f 3 4 8 7
f 4 1 5 8
o lamp
usemtl lamp
f 9 10 11 12
o block
usemtl white
f 17 20 19 18
f 13 14 18 17
f 14 15 19 18
f 15 16 20 19
f 16 13 17 20
";

const MTL: &str =
    "newmtl white\nKd 0.7 0.7 0.7\nnewmtl red\nKd 0.6 0.3 0.2\nnewmtl lamp\nKd 0 0 0\nKe 5 5 5\n";

/// `ROOM_Y_UP` as a z-up tool writes it: every vertex turned from +y up to +z up.
fn room_z_up() -> String {
    ROOM_Y_UP
        .lines()
        .map(|l| match l.strip_prefix("v ") {
            Some(v) => {
                let c: Vec<f64> = v.split_whitespace().map(|x| x.parse().unwrap()).collect();
                let p = UpAxis::Z.from_y_up(DVec3::new(c[0], c[1], c[2]));
                format!("v {} {} {}\n", p.x, p.y, p.z)
            }
            None => format!("{l}\n"),
        })
        .collect()
}

/// Writes the two rooms and their MTL into `dir`: `(y-up OBJ, z-up OBJ)`.
fn rooms(dir: &Path) -> (PathBuf, PathBuf) {
    let (y, z) = (dir.join("room_y.obj"), dir.join("room_z.obj"));
    std::fs::write(&y, ROOM_Y_UP).unwrap();
    std::fs::write(&z, room_z_up()).unwrap();
    std::fs::write(dir.join("room.mtl"), MTL).unwrap();
    (y, z)
}

/// Coarse and quick: the comparison is between two readings of one room, not of accuracy.
const QUICK: [&str; 6] = ["--patch-size", "1", "--element-size", "0.5", "--max-shots", "60"];

fn solve_objects(scene: &Path, extra: &[&str]) -> (serde_json::Value, String) {
    let mut args = vec!["solve", scene.to_str().unwrap(), "--json", "-"];
    args.extend_from_slice(&QUICK);
    args.extend_from_slice(extra);
    let o = radiosity(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    (v["objects"].clone(), stderr(&o))
}

/// Every object's area and radiosity agree to round-off (the turn only swaps and negates
/// coordinates, but a normal's length sums its squares in another order: 1e-12).
fn assert_same_objects(a: &serde_json::Value, b: &serde_json::Value) {
    let (a, b) = (a.as_array().unwrap(), b.as_array().unwrap());
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        assert_eq!(x["name"], y["name"]);
        for key in ["area", "radiosity"] {
            let flat = |v: &serde_json::Value| -> Vec<f64> {
                match v.as_array() {
                    Some(c) => c.iter().map(|c| c.as_f64().unwrap()).collect(),
                    None => vec![v.as_f64().unwrap()],
                }
            };
            for (p, q) in flat(&x[key]).iter().zip(flat(&y[key])) {
                assert!(
                    (p - q).abs() <= 1e-9 * p.abs().max(q.abs()).max(1e-12),
                    "{key} of {}: {p} vs {q}",
                    x["name"]
                );
            }
        }
    }
}

/// The linear pixels of a PFM file (`PF`, size, scale, then little-endian f32 RGB rows).
fn pfm_pixels(path: &Path) -> Vec<f32> {
    let bytes = std::fs::read(path).unwrap();
    // Three header lines, each ended by a newline.
    let mut newlines = 0;
    let start = bytes
        .iter()
        .position(|&b| {
            newlines += usize::from(b == b'\n');
            newlines == 3
        })
        .unwrap()
        + 1;
    bytes[start..].chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect()
}

/// Per object and per pixel, the z-up file read with `--up z` (and through a scene file's
/// `up = "z"`) is the y-up file; the z-up file alone gets the note, the y-up one does not.
#[test]
fn a_room_written_z_up_reads_as_the_same_room_y_up() {
    let dir = tempfile::tempdir().unwrap();
    let (y, z) = rooms(dir.path());
    let (y_objects, y_err) = solve_objects(&y, &[]);
    let (z_objects, z_err) = solve_objects(&z, &["--up", "z"]);
    assert_same_objects(&y_objects, &z_objects);
    assert!(!y_err.contains("--up"), "a y-up room got a note: {y_err}");
    assert!(!z_err.contains("--up z"), "the note is for scenes read without --up: {z_err}");
    let (_, hinted) = solve_objects(&z, &[]);
    let note = hinted.lines().find(|l| l.contains("--up z")).unwrap_or_else(|| panic!("no note: {hinted}"));
    assert!(note.contains("looks z up") && note.contains("lights face −z"), "{note}");

    // A scene file in the same frame: its `up` key, a camera without `up`, a mesh object.
    let toml = dir.path().join("room_z.toml");
    std::fs::write(
        &toml,
        "up = \"z\"\n[[object]]\nname = \"room\"\ntype = \"mesh\"\nfile = \"room_z.obj\"\n",
    )
    .unwrap();
    let (from_file, file_err) = solve_objects(&toml, &[]);
    assert!(!file_err.contains("--up"), "{file_err}");
    let named = |v: &serde_json::Value| {
        let mut v = v.clone();
        for o in v.as_array_mut().unwrap() {
            o["name"] = format!("room/{}", o["name"].as_str().unwrap()).into();
        }
        v
    };
    assert_same_objects(&named(&y_objects), &from_file);

    // The picture from the automatic camera: the same pixels.
    let render = |scene: &Path, out: &Path, extra: &[&str]| {
        let mut args = vec!["render", scene.to_str().unwrap(), "--pfm", out.to_str().unwrap()];
        args.extend_from_slice(&["--width", "32", "--height", "24", "--spp", "1", "--gather", "none"]);
        args.extend_from_slice(&QUICK);
        args.extend_from_slice(extra);
        let o = radiosity(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        pfm_pixels(out)
    };
    let (y_png, z_png) = (dir.path().join("y.pfm"), dir.path().join("z.pfm"));
    let (a, b) = (render(&y, &y_png, &[]), render(&z, &z_png, &["--up", "z"]));
    assert_eq!(a.len(), 32 * 24 * 3);
    assert!(a.iter().any(|&v| v > 0.0), "a black picture");
    let worst = a.iter().zip(&b).map(|(p, q)| (p - q).abs() / p.abs().max(1e-6)).fold(0.0, f32::max);
    assert!(worst < 1e-4, "pixels differ by up to {worst}");
}

/// A point given on the command line is in the file's frame: the eye placed in the z-up
/// file's coordinates sees what it sees from the same place in the y-up file.
#[test]
fn camera_points_are_in_the_files_frame() {
    let dir = tempfile::tempdir().unwrap();
    let (y, z) = rooms(dir.path());
    let render = |scene: &Path, out: &Path, eye: DVec3, at: DVec3, extra: &[&str]| {
        let (eye, at) = (format!("{},{},{}", eye.x, eye.y, eye.z), format!("{},{},{}", at.x, at.y, at.z));
        let mut args = vec!["render", scene.to_str().unwrap(), "--pfm", out.to_str().unwrap()];
        args.extend_from_slice(&["--width", "16", "--height", "12", "--spp", "1", "--gather", "none"]);
        args.extend_from_slice(&["--camera-position", &eye, "--look-at", &at]);
        args.extend_from_slice(&QUICK);
        args.extend_from_slice(extra);
        let o = radiosity(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        pfm_pixels(out)
    };
    let (eye, at) = (DVec3::new(3.5, 1.2, 2.8), DVec3::new(1.0, 0.5, 1.0));
    let a = render(&y, &dir.path().join("y.pfm"), eye, at, &[]);
    let b = render(
        &z,
        &dir.path().join("z.pfm"),
        UpAxis::Z.from_y_up(eye),
        UpAxis::Z.from_y_up(at),
        &["--up", "z"],
    );
    let worst = a.iter().zip(&b).map(|(p, q)| (p - q).abs() / p.abs().max(1e-6)).fold(0.0, f32::max);
    assert!(worst < 1e-4, "pixels differ by up to {worst}");
}

/// A camera placed by hand in a scene whose automatic view looks straight down (a wide lit
/// floor under a low lamp, seen from above with +z up in the picture) stands upright: the
/// floor it looks along fills the bottom of the picture, not one side of it.
#[test]
fn a_camera_placed_by_hand_stands_upright() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("floor.obj");
    std::fs::write(dir.path().join("room.mtl"), MTL).unwrap();
    std::fs::write(
        &obj,
        "mtllib room.mtl\nv -10 0 -10\nv 10 0 -10\nv 10 0 10\nv -10 0 10\nv -0.5 1 -0.5\nv 0.5 1 -0.5\n\
         v 0.5 1 0.5\nv -0.5 1 0.5\no floor\nusemtl white\nf 1 4 3 2\no lamp\nusemtl lamp\nf 5 6 7 8\n",
    )
    .unwrap();
    let out = dir.path().join("level.pfm");
    let (w, h) = (16usize, 12usize);
    let mut args = vec!["render", obj.to_str().unwrap(), "--pfm", out.to_str().unwrap(), "--sides", "1"];
    args.extend_from_slice(&["--width", "16", "--height", "12", "--spp", "1", "--gather", "none"]);
    args.extend_from_slice(&["--camera-position", "-8,0.5,0", "--look-at", "0,0.5,0", "--fov", "40"]);
    args.extend_from_slice(&QUICK);
    let o = radiosity(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let px = pfm_pixels(&out);
    assert_eq!(px.len(), w * h * 3);
    // Pixels that see something lit, counted (the lamp is brighter than the whole floor).
    let lit = |ys: std::ops::Range<usize>, xs: std::ops::Range<usize>| -> usize {
        ys.flat_map(|y| xs.clone().map(move |x| (y * w + x) * 3))
            .filter(|&i| px[i] + px[i + 1] + px[i + 2] > 0.0)
            .count()
    };
    // PFM rows run from the bottom of the picture up.
    let (bottom, top) = (lit(0..h / 2, 0..w), lit(h / 2..h, 0..w));
    let (left, right) = (lit(0..h, 0..w / 2), lit(0..h, w / 2..w));
    assert!(bottom > 3 * top, "the floor below the horizon: lit pixels below {bottom}, above {top}");
    assert!(left.abs_diff(right) <= (left + right) / 8, "level: lit pixels left {left}, right {right}");
}

/// An up axis that is not one: one line, exit code 2, from the option and from the key.
#[test]
fn a_bad_up_axis_is_one_line_with_exit_code_2() {
    let dir = tempfile::tempdir().unwrap();
    let (y, _) = rooms(dir.path());
    let o = radiosity(&["solve", y.to_str().unwrap(), "--up", "w"]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("--up") && err.contains("'w'") && err.contains("-z"), "{err}");
    let toml = dir.path().join("bad.toml");
    std::fs::write(
        &toml,
        "up = \"w\"\n[[object]]\nname = \"room\"\ntype = \"mesh\"\nfile = \"room_y.obj\"\n",
    )
    .unwrap();
    let o = radiosity(&["info", toml.to_str().unwrap()]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("bad.toml:1:") && err.contains("up:"), "{err}");
}

/// PLY output lies in the file's frame, glTF is +y up: exported from the z-up file, the PLY's
/// highest vertex is the highest in z, and the same export of the y-up file matches it turned.
#[test]
fn ply_goes_back_to_the_files_frame() {
    let dir = tempfile::tempdir().unwrap();
    let (_, z) = rooms(dir.path());
    let ply = dir.path().join("lit.ply");
    let mut args = vec!["export", z.to_str().unwrap(), "-o", ply.to_str().unwrap(), "--up", "z"];
    args.extend_from_slice(&QUICK);
    let o = radiosity(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let bytes = std::fs::read(&ply).unwrap();
    let header_end = bytes.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let count: usize = String::from_utf8_lossy(&bytes[..header_end])
        .lines()
        .find_map(|l| l.strip_prefix("element vertex "))
        .unwrap()
        .parse()
        .unwrap();
    // x y z float, r g b uchar, three float radiosities: 27 bytes a vertex.
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for v in 0..count {
        let at = header_end + v * 27;
        let c: Vec<f64> = (0..3)
            .map(|k| f64::from(f32::from_le_bytes(bytes[at + 4 * k..at + 4 * k + 4].try_into().unwrap())))
            .collect();
        lo = lo.min(DVec3::new(c[0], c[1], c[2]));
        hi = hi.max(DVec3::new(c[0], c[1], c[2]));
    }
    // The z-up file spans x 0–4, y −3–0, z 0–2.5.
    assert!((hi.z - 2.5).abs() < 1e-5 && lo.z.abs() < 1e-5, "{lo} {hi}");
    assert!((lo.y + 3.0).abs() < 1e-5 && hi.y.abs() < 1e-5, "{lo} {hi}");
}
