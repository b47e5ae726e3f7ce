//! The crate graph keeps its shape: the solver never depends, directly or through another
//! crate, on a window, picture, command-line or file-format crate (it returns data and never
//! draws, reads files or parses arguments), the scene loader needs neither the solver nor
//! the picture files, and the scene vocabulary and the mesher need neither rays nor threads.
//!
//! Asked of `cargo tree` over the lock file (`--offline`, `--locked`: no network, no change
//! to `Cargo.lock`), for the host platform (other platforms' crates need not be downloaded)
//! and normal dependencies only (tests and benches may use what they like).

use std::collections::BTreeSet;
use std::process::Command;

/// Every crate that `package` needs to build, itself included, by name.
fn normal_dependencies(package: &str) -> BTreeSet<String> {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let out = Command::new(cargo)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(["tree", "--offline", "--locked", "-e", "normal", "--prefix", "none"])
        .args(["--format", "{p}", "-p", package])
        .output()
        .expect("cargo runs");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "cargo tree -p {package} failed: {stderr}");
    let names: BTreeSet<String> = String::from_utf8(out.stdout)
        .expect("UTF-8 output")
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .map(str::to_owned)
        .collect();
    assert!(names.contains(package), "{package} is not in its own tree: {names:?}");
    names
}

/// Fails naming each crate of `forbidden` that `package` depends on.
fn assert_free_of(package: &str, forbidden: &[&str]) {
    let deps = normal_dependencies(package);
    let found: Vec<&&str> = forbidden.iter().filter(|f| deps.contains(**f)).collect();
    assert!(found.is_empty(), "{package} depends on {found:?}; its dependencies: {deps:?}");
}

#[test]
fn the_solver_needs_no_window_picture_cli_or_file_format_crate() {
    let forbidden = [
        // Windows and GPU.
        "eframe",
        "egui",
        "wgpu",
        "winit",
        // Pictures.
        "image",
        "exr",
        "png",
        // Command line.
        "clap",
        "indicatif",
        // File formats.
        "serde_json",
        "toml",
        "tobj",
        "gltf",
        // The workspace's own crates that draw, read or write.
        "radiosity_image",
        "radiosity_io",
        "radiosity_export",
        "radiosity_viewer",
    ];
    assert_free_of("radiosity_solver", &forbidden);
}

#[test]
fn the_scene_loader_needs_no_solver_or_picture_files() {
    assert_free_of(
        "radiosity_io",
        &["radiosity_solver", "radiosity_accel", "radiosity_image", "exr", "rayon"],
    );
}

#[test]
fn the_scene_vocabulary_and_the_mesher_stand_alone() {
    let workspace = [
        "radiosity_scenes",
        "radiosity_accel",
        "radiosity_solver",
        "radiosity_image",
        "radiosity_io",
        "radiosity_export",
        "radiosity_viewer",
        "radiosity_reference",
    ];
    // Every crate depends on the vocabulary: a meshing change must not rebuild it.
    let mut core_forbidden = workspace.to_vec();
    core_forbidden.extend(["radiosity_mesh", "rayon", "obvhs"]);
    assert_free_of("radiosity_core", &core_forbidden);
    let mut mesh_forbidden = workspace.to_vec();
    mesh_forbidden.extend(["rayon", "obvhs", "serde_json", "toml"]);
    assert_free_of("radiosity_mesh", &mesh_forbidden);
}

/// The check itself can fail: the viewer does depend on the window crates.
#[test]
fn the_check_sees_transitive_dependencies() {
    let viewer = normal_dependencies("radiosity_viewer");
    for name in ["eframe", "wgpu", "radiosity_solver", "radiosity_accel"] {
        assert!(viewer.contains(name), "{name} missing from the viewer's tree");
    }
}
