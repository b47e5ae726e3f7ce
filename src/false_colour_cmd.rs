//! `render --false-colour lux`: the rendered picture's pixels coloured by the illuminance of
//! the surface each one sees, with the legend, instead of tone mapped.

use std::path::Path;

use anyhow::Result;
use clap::ValueEnum;
use radiosity_image::{Rendering, SurfaceLight, encode_picture, false_colour_picture, pixel_illuminance};

use crate::errors::InputError;
use crate::output;
use crate::prepare::Prepared;

/// What a false-colour picture shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FalseColourArg {
    /// Illuminance on the surface seen, lx.
    Lux,
}

/// Refuses a false-colour picture of a scene that is not photometric (no `units`, no
/// luminaire, no grid): its lux would be a guess at what its watts and lengths mean.
///
/// # Errors
/// An [`InputError`] naming the scene.
pub fn check_photometric(prepared: &Prepared, scene_arg: &str) -> Result<()> {
    if prepared.scene.lighting.is_photometric() {
        return Ok(());
    }
    Err(InputError(format!(
        "--false-colour lux: {scene_arg} is not a photometric scene; give its file `units = \"m\"` (or luminaires) so that its light has lux"
    ))
    .into())
}

/// The surfaces of the rendering's objects: reflectance and emission of the scene object of
/// the same index and name, `None` for any other.
fn surfaces(prepared: &Prepared) -> Vec<Option<SurfaceLight>> {
    let scene = &prepared.scene;
    prepared
        .problem
        .mesh()
        .object_names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let object = scene.objects.get(i).filter(|o| &o.name == name)?;
            let m = &scene.materials[object.material];
            Some(SurfaceLight { reflectance: m.reflectance, emission: m.emission })
        })
        .collect()
}

/// Writes the false-colour picture of `rendering` to `path` (PNG or JPEG by its name).
///
/// # Errors
/// As [`output::write_file`].
pub fn write_false_colour(
    prepared: &Prepared,
    rendering: &Rendering,
    path: &Path,
    force: bool,
) -> Result<()> {
    let to_lux = prepared.scene.lighting.unit().lux_per_irradiance();
    let lux = pixel_illuminance(rendering, &surfaces(prepared), to_lux);
    let (w, h) = (rendering.radiance.width(), rendering.radiance.height());
    let picture = false_colour_picture(&lux, w, h);
    output::write_file(path, force, &encode_picture(&picture, path)?)?;
    output::note(format_args!("wrote {} (false colour, lx)", path.display()))
}
