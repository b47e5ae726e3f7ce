//! Scene files in, for the `radiosity` renderer: the TOML scene format (described in
//! `docs/ARCHITECTURE.md` and `DESIGN.md`, "Scene file"), model files (OBJ + MTL, glTF / GLB:
//! [`load_model`], or `type = "mesh"` objects of a scene file), and the built-in scenes; lit
//! meshes out ([`glb_bytes`], [`gltf_text`], [`ply_bytes`], [`write_lightmaps`]).
//!
//! Loading has two stages. First the text becomes plain serde data (`SceneDesc`, private)
//! with unknown keys rejected; then that data becomes a core [`Scene`] through the core's
//! validating constructors. Every error is a [`LoadError`] whose message is one line:
//! `<file>:<line>:<column>: <key path>: <what is wrong and what was expected>` for scene
//! files, `<file>[:<line>]: <element>: <what is wrong>` for model files.
//!
//! ```
//! let scene = radiosity_io::parse_scene(
//!     "[[material]]\nname = \"lamp\"\nreflectance = [0, 0, 0]\nemission = [1, 1, 1]\n\
//!      [[object]]\nname = \"tile\"\ntype = \"polygon\"\nmaterial = \"lamp\"\n\
//!      vertices = [[0, 0, 0], [1, 0, 0], [1, 1, 0]]\n",
//!     "tile.toml",
//! )
//! .unwrap();
//! assert_eq!(scene.name, "tile");
//! let e = radiosity_io::parse_scene("[mesh]\npatch_size = -1\nelement_size = 1\n", "bad.toml").unwrap_err();
//! assert_eq!(e.to_string(), "bad.toml:2:14: mesh.patch_size: patch_size must be a finite number > 0, got -1");
//! ```
#![warn(missing_docs)]
#![forbid(unsafe_code)]

mod builtin;
mod desc;
mod error;
mod export;
mod gltf_in;
mod locate;
mod model;
mod obj;
mod scene_file;

pub use builtin::{BUILTIN_SCENES, builtin_scene, resolve_scene, resolve_scene_warned};
pub use error::LoadError;
pub use export::{
    ExportFormat, LIGHTMAP_CELL_TEXELS, Lightmap, VertexColours, file_stem_for, glb_bytes, gltf_text,
    lightmaps, ply_bytes, vertex_colours, write_lightmaps,
};
pub use model::{DEFAULT_GREY, Model, ModelFormat, ModelPart, Transform, load_model, parse_model};
pub use scene_file::{LoadedScene, load_scene, load_scene_warned, parse_scene, parse_scene_warned};

use radiosity_core::Scene;
