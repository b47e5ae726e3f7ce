//! Pictures of a radiosity solution: a CPU ray-cast renderer ([`Renderer`]) that turns a lit
//! mesh into linear radiance ([`HdrImage`]), tone mapping ([`tone_map`], [`ToneParams`]) shared
//! by every display path, and picture files — PNG for display, OpenEXR and PFM for linear
//! radiance.
//!
//! ```
//! use std::sync::Arc;
//! use radiosity_core::{Camera, Mesh, furnace_box, glam::DVec3};
//! use radiosity_image::{Exposure, RenderParams, Renderer, ToneParams, ToneOperator, tone_map_image};
//! use radiosity_solver::{Solver, SolverParams, occluder_triangles};
//!
//! let scene = furnace_box(0.5, 1.0);
//! let mesh = Arc::new(Mesh::build(&scene, &scene.mesh_params()).unwrap());
//! let accel = Arc::new(radiosity_accel::Bvh::new(&occluder_triangles(&mesh)));
//! let mut solver = Solver::new(mesh.clone(), accel, SolverParams::preview()).unwrap();
//! solver.solve();
//!
//! let camera = Camera::try_new(DVec3::splat(0.5), DVec3::new(0.5, 0.5, 1.0), DVec3::Y, 60.0).unwrap();
//! let picture = Renderer::new(mesh).render(&solver.solution(), &camera, &RenderParams::preview()).unwrap();
//! let ev = Exposure::Auto.ev_for(&picture.radiance);
//! let png = tone_map_image(&picture.radiance, &ToneParams::new(ev, ToneOperator::Aces));
//! assert_eq!(png.pixels.len(), 160 * 120);
//! ```
#![warn(missing_docs)]
#![forbid(unsafe_code)]

mod files;
mod hdr;
mod metrics;
mod render;
mod tonemap;

pub use files::{
    HdrFormat, ImageFileError, MAX_PICTURE_PIXELS, decode_pfm, encode_exr, encode_pfm, encode_png, read_exr,
    read_hdr, read_pfm, read_png, write_exr, write_file_atomic, write_hdr, write_pfm, write_png,
};
pub use hdr::HdrImage;
pub use metrics::{ObjectPixels, difference_image, object_mean_radiance};
pub use render::{RenderError, RenderParams, Renderer, Rendering, Shading, SurfaceHit};
pub use tonemap::{
    AUTO_EXPOSURE_KEY, Exposure, SrgbImage, ToneOperator, ToneParams, ToneParseError, auto_exposure_ev,
    encode_srgb, srgb_decode, srgb_encode, tone_map, tone_map_image,
};
