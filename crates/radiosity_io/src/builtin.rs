//! Built-in scenes: the TOML files of `scenes/`, embedded so the binary needs no data files
//! and a built-in name loads exactly what the file holds.

use std::path::Path;

use crate::{LoadError, Scene, load_scene, parse_scene};

/// Built-in scene names and their embedded files.
const FILES: &[(&str, &str, &str)] = &[
    ("cornell", "scenes/cornell.toml", include_str!("../../../scenes/cornell.toml")),
    ("furnace", "scenes/furnace.toml", include_str!("../../../scenes/furnace.toml")),
    ("seed-room", "scenes/seed-room.toml", include_str!("../../../scenes/seed-room.toml")),
    ("two-plates", "scenes/two-plates.toml", include_str!("../../../scenes/two-plates.toml")),
];

/// Names accepted by [`builtin_scene`].
pub const BUILTIN_SCENES: &[&str] = &["cornell", "furnace", "seed-room", "two-plates"];

/// A built-in scene by name, or `None`.
///
/// # Panics
/// Never for the shipped files: a test parses every one.
pub fn builtin_scene(name: &str) -> Option<Scene> {
    FILES
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|(_, origin, text)| parse_scene(text, origin).expect("built-in scenes are valid"))
}

/// A scene from a command-line argument: a file path when that file exists or the argument
/// ends in `.toml`, otherwise a built-in name.
///
/// # Errors
/// The file's [`LoadError`], or [`LoadError::UnknownScene`].
pub fn resolve_scene(arg: &str) -> Result<Scene, LoadError> {
    let path = Path::new(arg);
    if path.exists() || arg.ends_with(".toml") {
        return load_scene(path);
    }
    builtin_scene(arg)
        .ok_or_else(|| LoadError::UnknownScene { name: arg.to_owned(), known: BUILTIN_SCENES.join(", ") })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_builtin_parses_and_is_listed() {
        assert_eq!(FILES.len(), BUILTIN_SCENES.len());
        for (name, _, _) in FILES {
            assert!(BUILTIN_SCENES.contains(name));
            assert!(builtin_scene(name).is_some());
        }
    }

    #[test]
    fn files_equal_the_canonical_functions() {
        assert_eq!(builtin_scene("furnace").unwrap(), radiosity_core::furnace_box(0.5, 1.0));
        assert_eq!(builtin_scene("two-plates").unwrap(), radiosity_core::two_plates(1.0, 1.0, 0.5, 1.0));
    }

    #[test]
    fn unknown_names_list_the_builtins() {
        let e = resolve_scene("nope").unwrap_err();
        assert!(e.to_string().contains("cornell, furnace"));
    }
}
