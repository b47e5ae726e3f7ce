//! Picture files: PNG (8-bit sRGB, for display), and OpenEXR and PFM (32-bit float linear
//! radiance, for anything that measures).
//!
//! PFM follows Paul Debevec's definition (the `hdrview`/Netpbm convention): a text header
//! `PF\n<width> <height>\n<scale>\n`, then `width × height` RGB triples of 32-bit floats, rows
//! from the **bottom** of the picture to the top; a negative scale means little-endian.
//!
//! Every writer here encodes into memory first and then writes the bytes to a temporary file
//! beside the target, synced, and renamed into place ([`write_file_atomic`]): a crash or a
//! full disk leaves any older file whole, and a failed write never removes the target.
//! Every reader takes regular files only (a FIFO would block, a device never ends) and checks
//! the sizes a header declares against [`MAX_PICTURE_PIXELS`] before it allocates.
//!
//! These live here rather than in `radiosity_io` (a deviation from `DESIGN.md`) so that the
//! scene loader and the picture writers could be built side by side.

use std::fs;
use std::io::{Cursor, Read, Write};
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
    /// The PNG (or JPEG) encoder or decoder failed.
    #[error("{path}: {source}")]
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
    /// A header declares more pixels than [`MAX_PICTURE_PIXELS`].
    #[error(
        "{path}: a {width}×{height} picture is larger than this program reads (at most {} pixels)",
        MAX_PICTURE_PIXELS
    )]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// Declared width.
        width: u64,
        /// Declared height.
        height: u64,
    },
    /// A header declares more pixels than the file's bytes could hold at any compression.
    #[error(
        "{path}: the header declares a {width}×{height} picture, more than its {bytes} bytes can hold \
         (at least one byte per {} pixels)",
        EXR_MOST_PIXELS_PER_BYTE
    )]
    Truncated {
        /// The file.
        path: PathBuf,
        /// Declared width.
        width: u64,
        /// Declared height.
        height: u64,
        /// The file's size.
        bytes: u64,
    },
    /// A tiled header declares tiles of more pixels than the file's bytes could hold.
    #[error(
        "{path}: the header declares tiles of {width}×{height} pixels, more than its {bytes} bytes can \
         hold (at least one byte per {} pixels)",
        EXR_MOST_PIXELS_PER_BYTE
    )]
    TilesTooLarge {
        /// The file.
        path: PathBuf,
        /// Declared tile width.
        width: u64,
        /// Declared tile height.
        height: u64,
        /// The file's size.
        bytes: u64,
    },
    /// The path is a folder, a FIFO or a device, not a regular file.
    #[error("{path}: not a regular file")]
    NotAFile {
        /// The path.
        path: PathBuf,
    },
    /// The file is larger than any picture read.
    #[error("{path}: {bytes} bytes is larger than any picture read (at most {limit})")]
    FileTooLarge {
        /// The file.
        path: PathBuf,
        /// Its size.
        bytes: u64,
        /// The limit.
        limit: u64,
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

/// Most pixels in a picture read or rendered: 2²⁶ (8192 × 8192). As linear RGB in `f64` that
/// is 1.5 GiB, and the renderer and encoders need about as much again; a larger header is
/// more likely a broken or hostile file than a picture this machine can hold.
pub const MAX_PICTURE_PIXELS: u64 = 1 << 26;

/// Bytes of the largest picture file read: the largest PFM (12 bytes per pixel) and a header.
const MAX_PICTURE_FILE_BYTES: u64 = MAX_PICTURE_PIXELS * 12 + 4096;

/// Most pixels an OpenEXR file's byte may stand for. Deflate compresses at most about
/// 1 032 : 1 and the leanest pixel is one half-float channel (2 bytes), so even a flat picture
/// needs a byte per 516 pixels; RLE, PIZ and B44 compress less. A header declaring more than
/// this many per byte of the file cannot be read whole: refused before its pixels are
/// allocated (a 567-byte file declared a picture of 1.5 GB, which was allocated before the
/// missing data was found).
pub const EXR_MOST_PIXELS_PER_BYTE: u64 = 4096;

fn check_size(path: &Path, width: u64, height: u64) -> Result<(), ImageFileError> {
    if width.saturating_mul(height) > MAX_PICTURE_PIXELS {
        return Err(ImageFileError::TooLarge { path: path.to_owned(), width, height });
    }
    Ok(())
}

/// Reads a whole regular file of at most `limit` bytes; anything else (a FIFO, a device, a
/// folder, a larger file) is refused before a byte is read.
fn read_regular(path: &Path, limit: u64) -> Result<Vec<u8>, ImageFileError> {
    let meta = fs::metadata(path).map_err(io_err(path))?;
    if !meta.is_file() {
        return Err(ImageFileError::NotAFile { path: path.to_owned() });
    }
    if meta.len() > limit {
        return Err(ImageFileError::FileTooLarge { path: path.to_owned(), bytes: meta.len(), limit });
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    // `take`: the file may have grown since it was measured.
    fs::File::open(path).and_then(|f| f.take(limit + 1).read_to_end(&mut bytes)).map_err(io_err(path))?;
    if bytes.len() as u64 > limit {
        return Err(ImageFileError::FileTooLarge { path: path.to_owned(), bytes: bytes.len() as u64, limit });
    }
    Ok(bytes)
}

/// Writes `bytes` to `path` through a temporary file in the same folder: written, flushed,
/// synced, then renamed over `path`. A failure at any step leaves `path` as it was.
///
/// # Errors
/// [`ImageFileError::Io`] naming `path`.
pub fn write_file_atomic(path: &Path, bytes: &[u8]) -> Result<(), ImageFileError> {
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut prefix = std::ffi::OsString::from(".");
    prefix.push(path.file_name().unwrap_or_default());
    prefix.push(".");
    let mut tmp =
        tempfile::Builder::new().prefix(&prefix).suffix(".tmp").tempfile_in(folder).map_err(io_err(path))?;
    tmp.write_all(bytes).and_then(|()| tmp.as_file().sync_all()).map_err(io_err(path))?;
    tmp.persist(path).map_err(|e| ImageFileError::Io { path: path.to_owned(), source: e.error })?;
    Ok(())
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
    write_file_atomic(path, &encode_png(image, path)?)
}

/// Encodes an 8-bit sRGB picture as PNG bytes. `path` only names the file in errors.
///
/// # Errors
/// [`ImageFileError::Png`] from the encoder, [`ImageFileError::Empty`] for a picture without
/// pixels.
pub fn encode_png(image: &SrgbImage, path: &Path) -> Result<Vec<u8>, ImageFileError> {
    check_not_empty(path, image.width, image.height)?;
    let mut out = Cursor::new(Vec::new());
    image::write_buffer_with_format(
        &mut out,
        &image.as_bytes(),
        image.width,
        image.height,
        image::ExtendedColorType::Rgb8,
        image::ImageFormat::Png,
    )
    .map_err(|source| ImageFileError::Png { path: path.to_owned(), source })?;
    Ok(out.into_inner())
}

/// An 8-bit picture file format, chosen by the file name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PictureFormat {
    /// Lossless, `.png`.
    Png,
    /// Lossy (quality 95), `.jpg` or `.jpeg`.
    Jpeg,
}

impl PictureFormat {
    /// The format `path`'s extension names (case-insensitive).
    ///
    /// # Errors
    /// [`ImageFileError::UnknownFormat`] for any other name: a `.jpg` must not quietly hold
    /// PNG bytes, nor a `.exr` an 8-bit picture.
    pub fn of(path: &Path) -> Result<Self, ImageFileError> {
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("png") => Ok(Self::Png),
            Some("jpg" | "jpeg") => Ok(Self::Jpeg),
            _ => {
                Err(ImageFileError::UnknownFormat { path: path.to_owned(), expected: ".png, .jpg or .jpeg" })
            }
        }
    }
}

/// Encodes an 8-bit sRGB picture in the format its file name asks for ([`PictureFormat::of`]).
///
/// # Errors
/// [`ImageFileError::UnknownFormat`] for another extension; the encoder's errors.
pub fn encode_picture(image: &SrgbImage, path: &Path) -> Result<Vec<u8>, ImageFileError> {
    match PictureFormat::of(path)? {
        PictureFormat::Png => encode_png(image, path),
        PictureFormat::Jpeg => {
            check_not_empty(path, image.width, image.height)?;
            let mut out = Cursor::new(Vec::new());
            image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, 95)
                .encode(&image.as_bytes(), image.width, image.height, image::ExtendedColorType::Rgb8)
                .map_err(|source| ImageFileError::Png { path: path.to_owned(), source })?;
            Ok(out.into_inner())
        }
    }
}

/// Reads a PNG as an 8-bit sRGB picture (grey or alpha channels are converted to RGB).
///
/// # Errors
/// [`ImageFileError::Png`] when the file is missing or not a PNG.
pub fn read_png(path: &Path) -> Result<SrgbImage, ImageFileError> {
    let bytes = read_regular(path, MAX_PICTURE_FILE_BYTES)?;
    let png = |source| ImageFileError::Png { path: path.to_owned(), source };
    let decoder = image::ImageReader::with_format(Cursor::new(&bytes), image::ImageFormat::Png);
    let (w, h) = decoder.into_dimensions().map_err(png)?;
    check_size(path, u64::from(w), u64::from(h))?;
    let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png).map_err(png)?.to_rgb8();
    Ok(SrgbImage { width: img.width(), height: img.height(), pixels: img.pixels().map(|p| p.0).collect() })
}

/// Writes linear radiance as a 32-bit float RGB OpenEXR file.
///
/// # Errors
/// [`ImageFileError::Exr`] when the file cannot be written, [`ImageFileError::Empty`] for a
/// picture without pixels.
pub fn write_exr(path: &Path, image: &HdrImage) -> Result<(), ImageFileError> {
    write_file_atomic(path, &encode_exr(image, path)?)
}

/// Encodes linear radiance as 32-bit float RGB OpenEXR bytes. `path` only names the file in
/// errors.
///
/// # Errors
/// [`ImageFileError::Exr`] from the encoder, [`ImageFileError::Empty`] for a picture without
/// pixels.
pub fn encode_exr(image: &HdrImage, path: &Path) -> Result<Vec<u8>, ImageFileError> {
    use exr::prelude::WritableImage;
    check_not_empty(path, image.width(), image.height())?;
    let w = image.width() as usize;
    let channels = exr::prelude::SpecificChannels::rgb(|pos: exr::prelude::Vec2<usize>| {
        let p = image.pixels()[pos.y() * w + pos.x()];
        (p.r as f32, p.g as f32, p.b as f32)
    });
    let picture = exr::prelude::Image::from_channels((w, image.height() as usize), channels);
    let mut out = Cursor::new(Vec::new());
    picture
        .write()
        .to_buffered(&mut out)
        .map_err(|source| ImageFileError::Exr { path: path.to_owned(), source })?;
    Ok(out.into_inner())
}

/// Reads the first RGB(A) layer of an OpenEXR file as linear radiance (alpha is dropped).
///
/// # Errors
/// [`ImageFileError::Exr`] when the file is missing, malformed or has no RGB layer.
pub fn read_exr(path: &Path) -> Result<HdrImage, ImageFileError> {
    use exr::prelude::{ReadChannels, ReadLayers};
    let bytes = read_regular(path, MAX_PICTURE_FILE_BYTES)?;
    let exr_err = |source| ImageFileError::Exr { path: path.to_owned(), source };
    // The header first: every layer's declared size is checked before a pixel is allocated.
    let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(&bytes), false).map_err(exr_err)?;
    for header in &meta.headers {
        let size = header.layer_size;
        let (width, height) = (size.width() as u64, size.height() as u64);
        check_size(path, width, height)?;
        let bytes = bytes.len() as u64;
        if width.saturating_mul(height) > bytes.saturating_mul(EXR_MOST_PIXELS_PER_BYTE) {
            return Err(ImageFileError::Truncated { path: path.to_owned(), width, height, bytes });
        }
        // A tile is decoded into a buffer of its declared size, however small the picture:
        // a 487-byte file of a 4 × 3 picture in tiles of 16 777 280 × 3 604 480 took 1.9 GB.
        if let exr::meta::BlockDescription::Tiles(tiles) = header.blocks {
            let (tw, th) = (tiles.tile_size.width() as u64, tiles.tile_size.height() as u64);
            if tw.saturating_mul(th) > bytes.saturating_mul(EXR_MOST_PIXELS_PER_BYTE) {
                return Err(ImageFileError::TilesTooLarge {
                    path: path.to_owned(),
                    width: tw,
                    height: th,
                    bytes,
                });
            }
        }
    }
    let img = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |size, _| HdrImage::new(size.width() as u32, size.height() as u32),
            |img: &mut HdrImage, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                img.set_pixel(
                    pos.x() as u32,
                    pos.y() as u32,
                    Rgb::new(f64::from(r), f64::from(g), f64::from(b)),
                );
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(Cursor::new(&bytes))
        .map_err(exr_err)?;
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
    check_size(path, u64::from(width), u64::from(height))?;
    let data = bytes.get(pos + 1..).ok_or_else(|| bad("no pixel data"))?;
    // In u64, and after the size check: 2³¹ × 2³¹ must not wrap around to a small count.
    let count = u64::from(width) * u64::from(height) * channels as u64;
    if (data.len() as u64) < count * 4 {
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
    write_file_atomic(path, &encode_pfm(image))
}

/// Reads a PFM file as linear radiance.
///
/// # Errors
/// [`ImageFileError::Io`] when it cannot be read, [`ImageFileError::BadPfm`] when malformed.
pub fn read_pfm(path: &Path) -> Result<HdrImage, ImageFileError> {
    decode_pfm(&read_regular(path, MAX_PICTURE_FILE_BYTES)?, path)
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
