//! Scene files in, for the `radiosity` renderer: the TOML scene format (described in
//! `docs/ARCHITECTURE.md` and `DESIGN.md`, "Scene file"), model files (OBJ + MTL, glTF / GLB:
//! [`load_model`], or `type = "mesh"` objects of a scene file), and the built-in scenes. Every
//! scene loader ([`load_scene`], [`parse_scene`], [`resolve_scene`]) returns a [`LoadedScene`]:
//! the scene and the loader's warnings. A model that does not say which way is up gets a
//! guess ([`likely_up`]) for a note to the user. Lit meshes go out through `radiosity_export`.
//!
//! Loading has two stages. First the text becomes plain serde data (`SceneDesc`, private)
//! with unknown keys rejected; then that data becomes a core [`Scene`] through the core's
//! validating constructors. Every error is a [`LoadError`] whose message is one line:
//! `<file>:<line>:<column>: <key path>: <what is wrong and what was expected>` for scene
//! files, `<file>[:<line>]: <element>: <what is wrong>` for model files.
//!
//! ```
//! let loaded = radiosity_io::parse_scene(
//!     "[[material]]\nname = \"lamp\"\nreflectance = [0, 0, 0]\nemission = [1, 1, 1]\n\
//!      [[object]]\nname = \"tile\"\ntype = \"polygon\"\nmaterial = \"lamp\"\n\
//!      vertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0]]\n",
//!     "tile.toml",
//! )
//! .unwrap();
//! assert_eq!(loaded.scene.name, "tile");
//! assert!(loaded.warnings.is_empty());
//! let e = radiosity_io::parse_scene("[mesh]\npatch_size = -1\nelement_size = 1\n", "bad.toml").unwrap_err();
//! assert_eq!(e.to_string(), "bad.toml:2:14: mesh.patch_size: patch_size must be a finite number > 0, got -1");
//! ```
#![warn(missing_docs)]
#![forbid(unsafe_code)]

mod builtin;
mod desc;
mod error;
mod gltf_in;
mod lighting_file;
mod load_model;
mod locate;
mod model;
mod obj;
mod photometric;
mod scene_file;
mod scene_settings;
mod sun_position;
mod texture_map;
mod up_guess;

pub use builtin::{BUILTIN_SCENES, builtin_scene, resolve_scene, resolve_scene_with};
pub use error::LoadError;
pub use lighting_file::{MAX_GRID_POINTS, MAX_LUMINAIRES};
pub use load_model::{load_model, parse_model};
pub use model::{CLAMPED_REFLECTANCE, DEFAULT_GREY, Model, ModelFormat, ModelPart, Transform};
pub use photometric::{
    MAX_ANGLES, MAX_PHOTOMETRIC_BYTES, PhotometricFormat, Photometry, load_photometry, parse_photometry,
};
pub use scene_file::{LoadOptions, LoadedScene, load_scene, load_scene_with, parse_scene, parse_scene_with};
pub use up_guess::{UpGuess, likely_up};

use radiosity_core::Scene;
