//! Pictures of a radiosity solution: a CPU ray-cast renderer ([`Renderer`]) that turns a lit
//! mesh into linear radiance ([`HdrImage`]), tone mapping ([`tone_map`], [`ToneParams`]) shared
//! by every display path, and picture files — PNG for display, OpenEXR and PFM for linear
//! radiance.
//!
//! ```
//! use radiosity_core::{Camera, glam::DVec3};
//! use radiosity_scenes::furnace_box;
//! use radiosity_image::{Exposure, RenderParams, Renderer, ToneParams, ToneOperator, tone_map_image};
//! use radiosity_solver::{Problem, SolverParams};
//!
//! let scene = furnace_box(0.5, 1.0);
//! let problem = Problem::new(&scene, &scene.mesh_params()).unwrap();
//! let mut solver = problem.solver(SolverParams::preview()).unwrap();
//! solver.solve();
//!
//! let camera = Camera::try_new(DVec3::splat(0.5), DVec3::new(0.5, 0.5, 1.0), DVec3::Y, 60.0).unwrap();
//! let picture = Renderer::new(problem.mesh().clone()).render(&solver.solution(), &camera, &RenderParams::preview()).unwrap();
//! let ev = Exposure::Auto.ev_for(&picture.radiance);
//! let png = tone_map_image(&picture.radiance, &ToneParams::new(ev, ToneOperator::Aces));
//! assert_eq!(png.pixels.len(), 160 * 120);
//! ```
#![warn(missing_docs)]
#![forbid(unsafe_code)]

mod cache;
mod canvas;
mod false_colour;
mod files;
mod font;
mod framing;
mod gather;
mod grid_picture;
mod hdr;
mod illuminance;
mod lux_scale;
mod metrics;
mod render;
mod tonemap;

pub use canvas::Canvas;
pub use false_colour::{NO_DATA, SurfaceLight, false_colour_picture, picture_scale, pixel_illuminance};
pub use files::{
    HdrFormat, ImageFileError, MAX_PICTURE_PIXELS, PictureFormat, decode_pfm, encode_exr, encode_pfm,
    encode_picture, encode_png, read_exr, read_hdr, read_pfm, read_png, write_exr, write_file_atomic,
    write_hdr, write_pfm, write_png,
};
pub use framing::{camera_or_framing, lit_share_seen_by};
pub use gather::Gather;
pub use grid_picture::{grid_picture, picture_sheet};
pub use hdr::HdrImage;
pub use illuminance::{GridIlluminance, GridParams, grid_illuminance, grid_statistics, luminaire_irradiance};
pub use lux_scale::{LuxScale, format_lux};
pub use metrics::{ObjectPixels, difference_image, object_mean_radiance};
pub use render::{
    ElementUvs, RECORD_RAYS_PER_GATHER_RAY, RenderError, RenderParams, Renderer, Rendering, Shading,
    SurfaceHit, element_uvs,
};
pub use tonemap::{
    AUTO_EXPOSURE_HIGHLIGHTS, AUTO_EXPOSURE_KEY, AUTO_EXPOSURE_WHITE, Exposure, MeterSample, SrgbImage,
    ToneOperator, ToneParams, ToneParseError, auto_exposure_ev, metered_exposure_ev, tone_map,
    tone_map_image,
};
