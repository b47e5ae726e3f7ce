//! The command and the crates end to end, as one test binary: one link instead of a dozen on
//! a cold `cargo test`, and the files' tests run side by side instead of one binary after
//! another. Each file is a module of its own.

mod alpha_masks;
mod bad_input;
mod bench_real;
mod cli;
mod dependencies;
mod discretisation;
mod export;
mod fast_paths;
mod grid_outputs;
mod luminaire_shadows;
mod lux_closed_forms;
mod model_fuzz;
mod models;
mod modules;
mod photometry;
mod progress;
mod public_models;
mod readme;
mod rooms;
mod sky;
mod sun;
mod surface_grids;
mod textures;
mod up_axis;
mod verify;
mod viewer;
