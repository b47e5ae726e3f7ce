//! Scene files in: the TOML scene format (see the README), loaded in two stages — plain serde
//! data (`SceneDesc`, unknown keys rejected) then validation into a core [`Scene`] — with
//! every error naming the file, line, column and key; and the built-in scenes.
#![warn(missing_docs)]
#![forbid(unsafe_code)]

mod builtin;
mod error;
mod scene_file;

pub use builtin::{BUILTIN_SCENES, builtin_scene, resolve_scene};
pub use error::LoadError;
pub use scene_file::{load_scene, parse_scene};

use radiosity_core::Scene;
