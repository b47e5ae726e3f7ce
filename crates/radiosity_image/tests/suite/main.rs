//! The renderer, the gather and the picture files, as one test binary (one link on a cold
//! `cargo test`; the files' tests run side by side).

mod common;
mod files;
mod gather;
mod golden;
mod render;
