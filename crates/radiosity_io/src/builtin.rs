//! Built-in scenes: the TOML files of `scenes/`, embedded so the binary needs no data files
//! and a built-in name loads exactly what the file holds (one format, one loader, one set of
//! rules for both).

use std::path::Path;

use crate::{
    LoadError, LoadOptions, LoadedScene, ModelFormat, Scene, load_scene_with, parse_scene, parse_scene_with,
};

/// Built-in scene names with the origin shown in messages and the embedded text.
const FILES: &[(&str, &str, &str)] = &[
    ("cornell", "scenes/cornell.toml", include_str!("../../../scenes/cornell.toml")),
    ("furnace", "scenes/furnace.toml", include_str!("../../../scenes/furnace.toml")),
    ("seed-room", "scenes/seed-room.toml", include_str!("../../../scenes/seed-room.toml")),
    ("two-plates", "scenes/two-plates.toml", include_str!("../../../scenes/two-plates.toml")),
];

/// Names accepted by [`builtin_scene`] and [`resolve_scene`], in a stable order.
pub const BUILTIN_SCENES: &[&str] = &["cornell", "furnace", "seed-room", "two-plates"];

/// A built-in scene by name, or `None` for a name not in [`BUILTIN_SCENES`].
///
/// # Panics
/// Never for the shipped files: a test parses every one.
pub fn builtin_scene(name: &str) -> Option<Scene> {
    FILES
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|(_, origin, text)| parse_scene(text, origin).expect("built-in scenes are valid (tested)").scene)
}

/// A scene and its loader's warnings from a command-line argument: the file at `arg` when that is an existing file or
/// `arg` ends in `.toml`, `.obj`, `.gltf` or `.glb` (so a mistyped path says "cannot read",
/// not "unknown scene"), otherwise the built-in scene of that name.
///
/// # Errors
/// As [`load_scene`](crate::load_scene) for a path; [`LoadError::UnknownScene`], listing the built-ins, for any
/// other name.
pub fn resolve_scene(arg: &str) -> Result<LoadedScene, LoadError> {
    resolve_scene_with(arg, &LoadOptions::default())
}

/// [`resolve_scene`] with [`LoadOptions`] (a built-in scene has a light and no model file, so
/// the options change nothing there).
///
/// # Errors
/// As [`resolve_scene`].
pub fn resolve_scene_with(arg: &str, opts: &LoadOptions) -> Result<LoadedScene, LoadError> {
    let path = Path::new(arg);
    // Anything there but a folder is read as a file, so a FIFO or a device is refused by
    // the loader rather than taken for an unknown built-in name.
    let present = std::fs::metadata(path).is_ok_and(|m| !m.is_dir());
    if present || arg.ends_with(".toml") || ModelFormat::from_path(path).is_some() {
        return load_scene_with(path, opts);
    }
    // Parsed with the options, so that an up axis given for a built-in scene turns it too.
    FILES
        .iter()
        .find(|(n, _, _)| *n == arg)
        .map(|(_, origin, text)| {
            parse_scene_with(text, origin, opts).expect("built-in scenes are valid (tested)")
        })
        .ok_or_else(|| LoadError::UnknownScene { name: arg.to_owned(), known: BUILTIN_SCENES.join(", ") })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_name_list_matches_the_embedded_files() {
        let names: Vec<&str> = FILES.iter().map(|(n, _, _)| *n).collect();
        assert_eq!(names, BUILTIN_SCENES);
    }
}
