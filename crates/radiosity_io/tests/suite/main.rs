//! Scene and model loading, as one test binary (one link on a cold `cargo test`; the files'
//! tests run side by side).

mod builtins;
mod fuzz;
mod malformed;
mod sides_and_materials;
