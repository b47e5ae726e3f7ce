//! Truncated and mutated model files never panic the importers: every case gives `Ok` or a
//! one-line `Err`. The mutations are deterministic (a fixed xorshift seed and a fixed count),
//! so a failure names a case that can be replayed.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use radiosity_core::Rgb;
use radiosity_export::{VertexColours, glb_bytes};
use radiosity_io::{ModelFormat, Transform, parse_model};
use radiosity_mesh::Mesh;
use radiosity_scenes::cornell_box;
use radiosity_solver::Solution;

use radiosity_core::random::XorShift64;

/// Text fragments that break OBJ and glTF structure and numbers.
const FRAGMENTS: &[&str] = &[
    " ",
    "\n",
    "/",
    "-",
    "-1",
    "0",
    "40",
    "999999999",
    "4294967295",
    "-4294967296",
    "nan",
    "inf",
    "1e999",
    "f 1 2 3\n",
    "f 1\n",
    "v 1 2\n",
    "usemtl x\n",
    "o \n",
    "mtllib ../../Cargo.toml\n",
    "{",
    "}",
    "[",
    "]",
    ",",
    ":",
    "\"",
    "null",
    "true",
    "\"count\":0",
    "\"count\":4000000000",
    "\"byteStride\":1,",
    "\"byteOffset\":-4,",
    "\"componentType\":5126",
    "\"componentType\":5120",
    "\"type\":\"MAT4\"",
    "\"mode\":0,",
    "\"mode\":5,",
    "\"mode\":6,",
    "\"children\":[0],",
    "\"indices\":0,",
    "\"camera\":0,",
    "\"uri\":\"missing.bin\",",
    "\"sparse\":{\"count\":1},",
    "é",
    "\u{0}",
];

fn mutate(rng: &mut XorShift64, original: &[u8]) -> Vec<u8> {
    let mut b = original.to_vec();
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(b.len() + 1);
        match rng.below(6) {
            // Truncate.
            0 => b.truncate(at),
            // Flip one byte.
            1 if at < b.len() => b[at] ^= 1 << rng.below(8),
            // Delete a run.
            2 => {
                let end = (at + 1 + rng.below(32)).min(b.len());
                b.drain(at.min(end)..end);
            }
            // Insert a fragment.
            3 | 4 => {
                let f = FRAGMENTS[rng.below(FRAGMENTS.len())].as_bytes();
                b.splice(at..at, f.iter().copied());
            }
            // Replace a digit with another number.
            _ => {
                if let Some(p) = b[at.min(b.len())..].iter().position(u8::is_ascii_digit) {
                    let p = at + p;
                    let f = ["0", "7", "-3", "65535", "1e30", "300"][rng.below(6)].as_bytes();
                    b.splice(p..p + 1, f.iter().copied());
                }
            }
        }
    }
    b
}

/// Runs `count` mutations of `original` through the importer for `format`.
fn fuzz(name: &str, original: &[u8], format: ModelFormat, base: Option<&Path>, seed: u64, count: usize) {
    let mut rng = XorShift64::new(seed);
    let (mut ok, mut err) = (0, 0);
    for case in 0..count {
        let bytes = if case == 0 { original.to_vec() } else { mutate(&mut rng, original) };
        let result =
            catch_unwind(AssertUnwindSafe(|| parse_model(&bytes, name, base, format, &Transform::default())));
        match result {
            Err(_) => panic!(
                "{name}: case {case} (seed {seed}) panicked; input starts {:?}",
                String::from_utf8_lossy(&bytes[..bytes.len().min(200)])
            ),
            Ok(Ok(_)) => ok += 1,
            Ok(Err(e)) => {
                let s = e.to_string();
                assert!(case > 0, "{name}: the unmutated file must load: {s}");
                assert_eq!(s.lines().count(), 1, "{name}: case {case}: not one line: {s}");
                assert!(s.starts_with(name), "{name}: case {case}: does not name the file: {s}");
                err += 1;
            }
        }
    }
    eprintln!("{name}: {count} cases, {ok} loaded, {err} errors");
    assert!(ok > 0 && err > 0, "the mutations should both keep and break some files");
}

fn scenes() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes")
}

#[test]
fn mutated_obj_files_never_panic() {
    let text = std::fs::read(scenes().join("cornell.obj")).unwrap();
    fuzz("cornell.obj", &text, ModelFormat::Obj, Some(&scenes()), 0x0b1_5eed, 3000);
}

#[test]
fn mutated_gltf_files_never_panic() {
    let text = std::fs::read(scenes().join("cornell.gltf")).unwrap();
    fuzz("cornell.gltf", &text, ModelFormat::Gltf, Some(&scenes()), 0x61f7_5eed, 3000);
}

/// GLB as the exporter writes it (the Cornell box's mesh with made-up colours: the importer
/// reads positions and indices only).
#[test]
fn mutated_glb_files_never_panic() {
    let scene = cornell_box();
    let mesh = Mesh::build(&scene, &scene.mesh_params()).unwrap();
    let solution = Solution {
        vertex_radiosity: (0..mesh.positions.len()).map(|v| Rgb::splat(v as f64 / 1000.0)).collect(),
        ..Solution::default()
    };
    let glb = glb_bytes(&mesh, &solution, VertexColours::Linear { exposure_ev: 0.0 }, &[]);
    // Its triangles have no material: default grey, so as a model it loads (with a warning).
    fuzz("lit.glb", &glb, ModelFormat::Gltf, None, 0x61b_5eed, 1500);
}
