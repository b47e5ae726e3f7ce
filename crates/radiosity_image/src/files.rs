//! Picture files: PNG (8-bit sRGB, for display), and OpenEXR and PFM (32-bit float linear
//! radiance, for anything that measures).
//!
//! PFM follows Paul Debevec's definition (the `hdrview`/Netpbm convention): a text header
//! `PF\n<width> <height>\n<scale>\n`, then `width × height` RGB triples of 32-bit floats, rows
//! from the **bottom** of the picture to the top; a negative scale means little-endian.
//!
//! These live here rather than in `radiosity_io` (a deviation from `DESIGN.md`) so that the
//! scene loader and the picture writers could be built side by side.

use std::fs;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use radiosity_core::Rgb;
use thiserror::Error;

use crate::{HdrImage, SrgbImage};

/// Why a picture file could not be written or read.
#[derive(Debug, Error)]
pub enum ImageFileError {
    /// The operating system refused (missing folder, permissions, full disk, …).
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The PNG encoder or decoder failed.
    #[error("{path}: PNG: {source}")]
    Png {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: image::ImageError,
    },
    /// The OpenEXR encoder or decoder failed.
    #[error("{path}: OpenEXR: {source}")]
    Exr {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: exr::error::Error,
    },
    /// A PFM file is malformed.
    #[error("{path}: not a valid PFM file: {reason}")]
    BadPfm {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// The file name's extension is not one of the picture formats.
    #[error("{path}: unknown picture format; expected a name ending in {expected}")]
    UnknownFormat {
        /// The file.
        path: PathBuf,
        /// The extensions accepted.
        expected: &'static str,
    },
    /// A picture with no pixels cannot be saved.
    #[error("{path}: the picture is empty ({width}×{height})")]
    Empty {
        /// The file.
        path: PathBuf,
        /// Width.
        width: u32,
        /// Height.
        height: u32,
    },
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> ImageFileError + '_ {
    move |source| ImageFileError::Io { path: path.to_owned(), source }
}

fn check_not_empty(path: &Path, width: u32, height: u32) -> Result<(), ImageFileError> {
    if width == 0 || height == 0 {
        return Err(ImageFileError::Empty { path: path.to_owned(), width, height });
    }
    Ok(())
}

/// Writes an 8-bit sRGB picture as PNG.
///
/// # Errors
/// [`ImageFileError::Png`] / [`ImageFileError::Io`] when the file cannot be written,
/// [`ImageFileError::Empty`] for a picture without pixels.
pub fn write_png(path: &Path, image: &SrgbImage) -> Result<(), ImageFileError> {
    check_not_empty(path, image.width, image.height)?;
    image::save_buffer_with_format(
        path,
        &image.as_bytes(),
        image.width,
        image.height,
        image::ExtendedColorType::Rgb8,
        image::ImageFormat::Png,
    )
    .map_err(|source| ImageFileError::Png { path: path.to_owned(), source })
}

/// Reads a PNG as an 8-bit sRGB picture (grey or alpha channels are converted to RGB).
///
/// # Errors
/// [`ImageFileError::Png`] when the file is missing or not a PNG.
pub fn read_png(path: &Path) -> Result<SrgbImage, ImageFileError> {
    let img =
        image::open(path).map_err(|source| ImageFileError::Png { path: path.to_owned(), source })?.to_rgb8();
    Ok(SrgbImage { width: img.width(), height: img.height(), pixels: img.pixels().map(|p| p.0).collect() })
}

/// Writes linear radiance as a 32-bit float RGB OpenEXR file.
///
/// # Errors
/// [`ImageFileError::Exr`] when the file cannot be written, [`ImageFileError::Empty`] for a
/// picture without pixels.
pub fn write_exr(path: &Path, image: &HdrImage) -> Result<(), ImageFileError> {
    check_not_empty(path, image.width(), image.height())?;
    let w = image.width() as usize;
    exr::prelude::write_rgb_file(path, w, image.height() as usize, |x, y| {
        let p = image.pixels()[y * w + x];
        (p.r as f32, p.g as f32, p.b as f32)
    })
    .map_err(|source| ImageFileError::Exr { path: path.to_owned(), source })
}

/// Reads the first RGB(A) layer of an OpenEXR file as linear radiance (alpha is dropped).
///
/// # Errors
/// [`ImageFileError::Exr`] when the file is missing, malformed or has no RGB layer.
pub fn read_exr(path: &Path) -> Result<HdrImage, ImageFileError> {
    let img = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |size, _| HdrImage::new(size.width() as u32, size.height() as u32),
        |img: &mut HdrImage, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            img.set_pixel(pos.x() as u32, pos.y() as u32, Rgb::new(f64::from(r), f64::from(g), f64::from(b)));
        },
    )
    .map_err(|source| ImageFileError::Exr { path: path.to_owned(), source })?;
    Ok(img.layer_data.channel_data.pixels)
}

/// Encodes linear radiance as PFM bytes: bottom row first, little-endian (scale −1).
pub fn encode_pfm(image: &HdrImage) -> Vec<u8> {
    let (w, h) = (image.width() as usize, image.height() as usize);
    let mut out = format!("PF\n{w} {h}\n-1.0\n").into_bytes();
    out.reserve(w * h * 12);
    for y in (0..h).rev() {
        for p in &image.pixels()[y * w..(y + 1) * w] {
            for c in p.to_array() {
                out.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
    }
    out
}

/// Decodes PFM bytes (`PF` colour or `Pf` grey, either byte order) into linear radiance, top
/// row first. `path` only names the file in errors.
///
/// # Errors
/// [`ImageFileError::BadPfm`] naming what is malformed.
pub fn decode_pfm(bytes: &[u8], path: &Path) -> Result<HdrImage, ImageFileError> {
    let bad = |reason: &str| ImageFileError::BadPfm { path: path.to_owned(), reason: reason.to_owned() };
    // The header is three whitespace-separated tokens after the magic, then exactly one
    // whitespace byte before the binary data.
    let mut pos = 0;
    let mut token = || -> Result<String, ImageFileError> {
        while pos < bytes.len() && bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        let start = pos;
        while pos < bytes.len() && !bytes[pos].is_ascii_whitespace() {
            pos += 1;
        }
        if start == pos {
            return Err(bad("the header is cut short"));
        }
        let t = String::from_utf8_lossy(&bytes[start..pos]).into_owned();
        Ok(t)
    };
    let magic = token()?;
    let channels = match magic.as_str() {
        "PF" => 3,
        "Pf" => 1,
        _ => return Err(bad(&format!("it starts with '{magic}', not 'PF' or 'Pf'"))),
    };
    let width: u32 = token()?.parse().map_err(|_| bad("the width is not a whole number"))?;
    let height: u32 = token()?.parse().map_err(|_| bad("the height is not a whole number"))?;
    let scale: f64 = token()?.parse().map_err(|_| bad("the scale is not a number"))?;
    if !(scale.is_finite() && scale != 0.0) {
        return Err(bad("the scale must be a finite non-zero number"));
    }
    let little_endian = scale < 0.0;
    let data = bytes.get(pos + 1..).ok_or_else(|| bad("no pixel data"))?;
    let count = width as usize * height as usize * channels;
    if data.len() < count * 4 {
        return Err(bad(&format!(
            "{width}×{height} needs {} bytes of pixel data, found {}",
            count * 4,
            data.len()
        )));
    }
    let value = |i: usize| {
        let b = [data[4 * i], data[4 * i + 1], data[4 * i + 2], data[4 * i + 3]];
        f64::from(if little_endian { f32::from_le_bytes(b) } else { f32::from_be_bytes(b) })
    };
    let (w, h) = (width as usize, height as usize);
    Ok(HdrImage::from_fn(width, height, |x, y| {
        // Stored bottom row first.
        let i = ((h - 1 - y as usize) * w + x as usize) * channels;
        if channels == 3 { Rgb::new(value(i), value(i + 1), value(i + 2)) } else { Rgb::splat(value(i)) }
    }))
}

/// Writes linear radiance as a PFM file (bottom row first, little-endian).
///
/// # Errors
/// [`ImageFileError::Io`] when the file cannot be written, [`ImageFileError::Empty`] for a
/// picture without pixels.
pub fn write_pfm(path: &Path, image: &HdrImage) -> Result<(), ImageFileError> {
    check_not_empty(path, image.width(), image.height())?;
    let file = fs::File::create(path).map_err(io_err(path))?;
    let mut out = BufWriter::new(file);
    out.write_all(&encode_pfm(image)).map_err(io_err(path))?;
    out.flush().map_err(io_err(path))
}

/// Reads a PFM file as linear radiance.
///
/// # Errors
/// [`ImageFileError::Io`] when it cannot be read, [`ImageFileError::BadPfm`] when malformed.
pub fn read_pfm(path: &Path) -> Result<HdrImage, ImageFileError> {
    decode_pfm(&fs::read(path).map_err(io_err(path))?, path)
}

/// Which linear picture format a file name asks for, from its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HdrFormat {
    /// OpenEXR (`.exr`).
    Exr,
    /// Portable float map (`.pfm`).
    Pfm,
}

impl HdrFormat {
    /// The format named by `path`'s extension (case-insensitive).
    ///
    /// # Errors
    /// [`ImageFileError::UnknownFormat`] for any other extension.
    pub fn from_path(path: &Path) -> Result<Self, ImageFileError> {
        match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("exr") => Ok(HdrFormat::Exr),
            Some("pfm") => Ok(HdrFormat::Pfm),
            _ => Err(ImageFileError::UnknownFormat { path: path.to_owned(), expected: ".exr or .pfm" }),
        }
    }
}

/// Reads linear radiance from an `.exr` or `.pfm` file, chosen by extension.
///
/// # Errors
/// [`ImageFileError::UnknownFormat`], or the reader's error.
pub fn read_hdr(path: &Path) -> Result<HdrImage, ImageFileError> {
    match HdrFormat::from_path(path)? {
        HdrFormat::Exr => read_exr(path),
        HdrFormat::Pfm => read_pfm(path),
    }
}

/// Writes linear radiance to an `.exr` or `.pfm` file, chosen by extension.
///
/// # Errors
/// [`ImageFileError::UnknownFormat`], or the writer's error.
pub fn write_hdr(path: &Path, image: &HdrImage) -> Result<(), ImageFileError> {
    match HdrFormat::from_path(path)? {
        HdrFormat::Exr => write_exr(path, image),
        HdrFormat::Pfm => write_pfm(path, image),
    }
}
