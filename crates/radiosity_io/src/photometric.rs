//! Photometric files in: IES LM-63 (1986, 1991, 1995, 2002) and EULUMDAT (`.ldt`), type C
//! only, into an [`IntensityTable`] of absolute candela over the full circle of C planes.
//!
//! Our own reader, not a crate: the `eulumdat` crate is AGPL-3.0, which this MIT / Apache-2.0
//! project cannot take in, and both formats are short and fully specified (ANSI/IES
//! LM-63-02; the EULUMDAT description of Stockmar 1990).
//!
//! Symmetry is expanded as each format says:
//!
//! * IES: the last horizontal angle 0° (rotationally symmetric), 90° (each quadrant mirrors
//!   the first), 180° (the 0–180° plane is a mirror), 360° (none); first 90° and last 270°
//!   (the 1995 form mirrored about the 90–270° plane).
//! * EULUMDAT `Isym`: 0 none, 1 about the vertical axis, 2 about C0–C180, 3 about C90–C270,
//!   4 about both.
//!
//! Every error is one line naming the file and the line (the last line read, for a file that
//! ends too soon), and no partial table is returned. TILT=INCLUDE data is read and checked,
//! but the tilt factors are not applied (the lamp is taken as tested upright).

use std::path::Path;

use radiosity_core::{IntensityTable, Opening};

use crate::LoadError;

/// Photometric files larger than this are refused before they are read: the largest real
/// ones (1° × 1° full-sphere tables) are under 1 MiB.
pub const MAX_PHOTOMETRIC_BYTES: u64 = 16 << 20;

/// Angle counts above this are refused (the finest tables have 361 × 181).
pub const MAX_ANGLES: usize = 10_000;

/// A photometric file read and expanded.
#[derive(Clone, Debug, PartialEq)]
pub struct Photometry {
    /// Absolute intensities (cd) over every C plane: the file's values times its multipliers
    /// (IES: the candela multiplier and ballast factor; EULUMDAT: cd/klm times the lamps'
    /// flux / 1000 times the conversion factor).
    pub table: IntensityTable,
    /// The rated lamp flux the file was measured for, lm; `None` for absolute photometry
    /// (IES lumens per lamp = −1).
    pub lamp_lumens: Option<f64>,
    /// Luminaire name or catalogue number as the file gives it, possibly empty.
    pub label: String,
    /// The luminous opening, metres (IES: width and length, negative for a round one;
    /// EULUMDAT: the luminous area's length and width, width 0 for a round one). Its height
    /// (a luminous box or cylinder) is not read: the opening is taken flat.
    pub opening: Opening,
}

/// Openings wider than this (metres) are refused: no luminaire is a hundred metres across, and
/// a file that says so has its units wrong.
pub const MAX_OPENING_METRES: f64 = 100.0;

/// Which format a file is in, by its extension (`.ies`, `.ldt`; any case).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PhotometricFormat {
    /// IES LM-63.
    Ies,
    /// EULUMDAT.
    Eulumdat,
}

impl PhotometricFormat {
    /// The format of `path` by its extension.
    pub fn from_path(path: &Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "ies" => Some(Self::Ies),
            "ldt" | "eul" => Some(Self::Eulumdat),
            _ => None,
        }
    }
}

/// Reads the photometric file at `path` (format by extension).
///
/// # Errors
/// [`LoadError::Model`] naming the file (and line) for an unreadable, oversized, non-text or
/// malformed file, or an unknown extension.
pub fn load_photometry(path: &Path) -> Result<Photometry, LoadError> {
    let origin = path.display().to_string();
    let err = |line, message: String| LoadError::Model { origin: origin.clone(), line, message };
    let format = PhotometricFormat::from_path(path)
        .ok_or_else(|| err(None, "not a photometric file: expected the extension .ies or .ldt".to_owned()))?;
    let bytes = crate::model::read_input_file(path, MAX_PHOTOMETRIC_BYTES)
        .map_err(|reason| err(None, format!("cannot read the photometric file: {reason}")))?;
    // Files from older tools are often Latin-1: keep every byte as a character.
    let text: String = match String::from_utf8(bytes) {
        Ok(t) => t,
        Err(e) => e.into_bytes().iter().map(|&b| char::from(b)).collect(),
    };
    parse_photometry(&text, &origin, format)
}

/// Parses the text of a photometric file; `origin` starts every error message.
///
/// # Errors
/// [`LoadError::Model`] with the line for anything malformed: a truncated file, a count
/// that does not match, angles out of order or range, a negative or non-numeric value,
/// photometric type A or B, TILT=INCLUDE without its data.
pub fn parse_photometry(
    text: &str,
    origin: &str,
    format: PhotometricFormat,
) -> Result<Photometry, LoadError> {
    let r = match format {
        PhotometricFormat::Ies => parse_ies(text),
        PhotometricFormat::Eulumdat => parse_ldt(text),
    };
    r.map_err(|(line, message)| LoadError::Model {
        origin: origin.to_owned(),
        line: Some(line),
        message: radiosity_core::escape_controls(&message),
    })
}

type Failed = (usize, String);

/// A luminous opening's size `metres` (any sign) checked against [`MAX_OPENING_METRES`].
fn opening_size(line: usize, metres: f64, what: &str) -> Result<f64, Failed> {
    if metres.abs() > MAX_OPENING_METRES {
        return Err((line, format!("{what} is {metres} m across, more than {MAX_OPENING_METRES} m")));
    }
    Ok(metres.abs())
}

/// Numbers of the IES data section, each with its 1-based line.
struct Tokens<'a> {
    items: Vec<(usize, &'a str)>,
    next: usize,
    last_line: usize,
}

impl<'a> Tokens<'a> {
    fn new(lines: &[(usize, &'a str)]) -> Self {
        let items = lines
            .iter()
            .flat_map(|&(n, l)| {
                l.split(|c: char| c.is_whitespace() || c == ',')
                    .filter(|t| !t.is_empty())
                    .map(move |t| (n, t))
            })
            .collect();
        Self { items, next: 0, last_line: lines.last().map_or(1, |l| l.0) }
    }

    fn number(&mut self, what: &str) -> Result<(usize, f64), Failed> {
        let Some(&(line, t)) = self.items.get(self.next) else {
            return Err((self.last_line, format!("the file ends before {what}")));
        };
        self.next += 1;
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok((line, v)),
            _ => Err((line, format!("{what}: expected a number, got '{}'", truncate(t)))),
        }
    }

    fn count(&mut self, what: &str, min: usize) -> Result<(usize, usize), Failed> {
        let (line, v) = self.number(what)?;
        if v.fract() != 0.0 || v < min as f64 || v > MAX_ANGLES as f64 {
            return Err((line, format!("{what} must be a whole number in {min}..={MAX_ANGLES}, got {v}")));
        }
        Ok((line, v as usize))
    }

    fn list(&mut self, what: &str, n: usize) -> Result<Vec<(usize, f64)>, Failed> {
        (0..n).map(|i| self.number(&format!("{what} {} of {n}", i + 1))).collect()
    }
}

fn truncate(t: &str) -> String {
    t.chars().take(24).collect()
}

/// Checks that `angles` increase strictly, naming the line of the first that does not.
fn increasing(angles: &[(usize, f64)], what: &str) -> Result<(), Failed> {
    for w in angles.windows(2) {
        if w[1].1 <= w[0].1 {
            return Err((w[1].0, format!("{what} out of order: {} after {}", w[1].1, w[0].1)));
        }
    }
    Ok(())
}

fn parse_ies(text: &str) -> Result<Photometry, Failed> {
    let lines: Vec<(usize, &str)> = text.lines().enumerate().map(|(i, l)| (i + 1, l.trim())).collect();
    let mut label = String::new();
    let tilt_at = lines
        .iter()
        .position(|(_, l)| l.to_ascii_uppercase().starts_with("TILT"))
        .ok_or_else(|| (lines.len().max(1), "no TILT= line: not an IES LM-63 file".to_owned()))?;
    for (_, l) in &lines[..tilt_at] {
        let upper = l.to_ascii_uppercase();
        if let Some(rest) = upper.strip_prefix("[LUMINAIRE]").or_else(|| upper.strip_prefix("[LUMCAT]"))
            && label.is_empty()
        {
            label = l[l.len() - rest.len()..].trim().to_owned();
        }
    }
    let (tilt_line, tilt) = lines[tilt_at];
    let tilt_value = tilt.split_once('=').map_or("", |(_, v)| v.trim()).to_ascii_uppercase();
    let mut tokens = Tokens::new(&lines[tilt_at + 1..]);
    tokens.last_line = tokens.last_line.max(tilt_line);
    if tilt_value == "INCLUDE" {
        tokens.number("the TILT=INCLUDE lamp-to-luminaire geometry")?;
        let (_, n) = tokens.count("the TILT=INCLUDE angle count", 1)?;
        let angles = tokens.list("TILT angle", n)?;
        increasing(&angles, "TILT angles")?;
        for (line, f) in tokens.list("TILT multiplying factor", n)? {
            if f < 0.0 {
                return Err((line, format!("TILT multiplying factor {f} is negative")));
            }
        }
    } else if tilt_value.is_empty() {
        return Err((tilt_line, "TILT= needs NONE, INCLUDE or a file name".to_owned()));
    }
    let (_, lamps) = tokens.number("the number of lamps")?;
    let (lumens_line, lumens) = tokens.number("the lumens per lamp")?;
    let (mult_line, multiplier) = tokens.number("the candela multiplier")?;
    let (_, n_vertical) = tokens.count("the number of vertical angles", 1)?;
    let (_, n_horizontal) = tokens.count("the number of horizontal angles", 1)?;
    let (type_line, kind) = tokens.number("the photometric type")?;
    let (units_line, units) = tokens.number("the units type")?;
    let width = tokens.number("the luminous opening's width")?;
    let length = tokens.number("the luminous opening's length")?;
    tokens.number("the luminous opening's height")?;
    let (ballast_line, ballast) = tokens.number("the ballast factor")?;
    tokens.number("the ballast-lamp photometric factor (future use)")?;
    tokens.number("the input watts")?;
    match kind as i64 {
        1 if kind == 1.0 => {}
        2 | 3 if kind.fract() == 0.0 => {
            let name = if kind == 2.0 { "B" } else { "A" };
            return Err((
                type_line,
                format!("photometric type {name} is not supported; only type C (1) files are read"),
            ));
        }
        _ => return Err((type_line, format!("photometric type must be 1 (C), 2 (B) or 3 (A), got {kind}"))),
    }
    if units != 1.0 && units != 2.0 {
        return Err((units_line, format!("units type must be 1 (feet) or 2 (metres), got {units}")));
    }
    let metres = if units == 1.0 { 0.3048 } else { 1.0 };
    for (line, v) in [width, length] {
        opening_size(line, v * metres, "the luminous opening")?;
    }
    // LM-63-2002 §5.10: negative dimensions are a round opening (a disc when only the width
    // is given).
    let (w, l) = (width.1.abs() * metres, length.1.abs() * metres);
    let round = width.1 < 0.0 || length.1 < 0.0;
    let opening = if round {
        Opening { length: if l > 0.0 { l } else { w }, width: if w > 0.0 { w } else { l }, round }
    } else {
        Opening { length: l, width: w, round }
    };
    if multiplier <= 0.0 {
        return Err((mult_line, format!("candela multiplier must be > 0, got {multiplier}")));
    }
    if ballast <= 0.0 {
        return Err((ballast_line, format!("ballast factor must be > 0, got {ballast}")));
    }
    if lumens <= 0.0 && lumens != -1.0 {
        return Err((
            lumens_line,
            format!("lumens per lamp must be > 0, or −1 for absolute photometry, got {lumens}"),
        ));
    }
    if n_vertical.checked_mul(n_horizontal).is_none_or(|n| n > 4_000_000) {
        return Err((tokens.last_line, "too many angles".to_owned()));
    }
    let vertical = tokens.list("vertical angle", n_vertical)?;
    increasing(&vertical, "vertical angles")?;
    let (first, last) = (vertical[0], vertical[n_vertical - 1]);
    if !(first.1 == 0.0 || first.1 == 90.0) || !(last.1 == 90.0 || last.1 == 180.0) {
        return Err((
            first.0,
            format!(
                "type C vertical angles must run from 0° or 90° to 90° or 180°, got {}° to {}°",
                first.1, last.1
            ),
        ));
    }
    let horizontal = tokens.list("horizontal angle", n_horizontal)?;
    increasing(&horizontal, "horizontal angles")?;
    let mut values = Vec::with_capacity(n_vertical * n_horizontal);
    for (line, v) in tokens.list("candela value", n_vertical * n_horizontal)? {
        if v < 0.0 {
            return Err((line, format!("candela value {v} is negative")));
        }
        values.push(v * multiplier * ballast);
    }
    if let Some(&(line, t)) = tokens.items.get(tokens.next) {
        return Err((
            line,
            format!("unexpected '{}' after the last candela value (counts wrong?)", truncate(t)),
        ));
    }
    let h: Vec<f64> = horizontal.iter().map(|a| a.1).collect();
    let (h_first, h_last) = (h[0], h[n_horizontal - 1]);
    let gammas: Vec<f64> = vertical.iter().map(|a| a.1).collect();
    let planes: Vec<&[f64]> = values.chunks(n_vertical).collect();
    let full = match (h_first, h_last) {
        (0.0, 0.0) if n_horizontal == 1 => vec![(0.0, planes[0].to_vec()), (360.0, planes[0].to_vec())],
        (0.0, 90.0) => mirrored_quadrant(&h, &planes),
        (0.0, 180.0) => mirrored_half(&h, &planes),
        (0.0, 360.0) => h.iter().zip(&planes).map(|(&c, p)| (c, p.to_vec())).collect(),
        (90.0, 270.0) => {
            // Mirror about the 90–270° plane: I(C) = I(180° − C).
            let mut out: Vec<(f64, Vec<f64>)> =
                h.iter().zip(&planes).map(|(&c, p)| (c, p.to_vec())).collect();
            for (&c, p) in h.iter().zip(&planes).rev() {
                let m = (540.0 - c) % 360.0; // 180 − C, in (270, 360] ∪ [0, 90)
                if c != 90.0 && c != 270.0 {
                    out.push((m, p.to_vec()));
                }
            }
            normalise_circle(out)
        }
        _ => {
            return Err((
                horizontal[n_horizontal - 1].0,
                format!(
                    "horizontal angles must run 0–0, 0–90, 0–180, 0–360 or 90–270°, got {h_first}–{h_last}°"
                ),
            ));
        }
    };
    let table = table_of(full, gammas).map_err(|e| (tokens.last_line, e))?;
    let lamp_lumens = (lumens > 0.0).then_some(lumens * lamps.max(1.0));
    Ok(Photometry { table, lamp_lumens, label, opening })
}

/// 0–90° planes to the full circle: I(180 − C) = I(C), I(360 − C) = I(C).
fn mirrored_quadrant(h: &[f64], planes: &[&[f64]]) -> Vec<(f64, Vec<f64>)> {
    let half: Vec<(f64, Vec<f64>)> = h
        .iter()
        .zip(planes)
        .map(|(&c, p)| (c, p.to_vec()))
        .chain(h.iter().zip(planes).rev().filter(|(c, _)| **c != 90.0).map(|(&c, p)| (180.0 - c, p.to_vec())))
        .collect();
    let hh: Vec<f64> = half.iter().map(|p| p.0).collect();
    let hp: Vec<&[f64]> = half.iter().map(|p| p.1.as_slice()).collect();
    mirrored_half(&hh, &hp)
}

/// 0–180° planes to the full circle: I(360 − C) = I(C).
fn mirrored_half(h: &[f64], planes: &[&[f64]]) -> Vec<(f64, Vec<f64>)> {
    h.iter()
        .zip(planes)
        .map(|(&c, p)| (c, p.to_vec()))
        .chain(
            h.iter().zip(planes).rev().filter(|(c, _)| **c != 180.0).map(|(&c, p)| (360.0 - c, p.to_vec())),
        )
        .collect()
}

/// Planes in any order over the circle, to sorted 0 … 360 with 360 a copy of 0.
fn normalise_circle(mut planes: Vec<(f64, Vec<f64>)>) -> Vec<(f64, Vec<f64>)> {
    for p in &mut planes {
        p.0 = p.0.rem_euclid(360.0);
    }
    planes.sort_by(|a, b| a.0.total_cmp(&b.0));
    planes.dedup_by(|a, b| a.0 == b.0);
    planes
}

/// The table of `planes` (C, values per γ), closing the circle: C0 is added from the
/// nearest planes (interpolated across the gap) when missing, and C360 copies C0.
fn table_of(planes: Vec<(f64, Vec<f64>)>, gammas: Vec<f64>) -> Result<IntensityTable, String> {
    let mut planes = normalise_circle(planes);
    if planes.last().is_some_and(|p| p.0 == 360.0) {
        planes.pop();
    }
    let Some(first) = planes.first().cloned() else { return Err("no C planes".to_owned()) };
    if first.0 != 0.0 {
        let last = planes.last().cloned().unwrap_or_else(|| first.clone());
        let gap = first.0 + 360.0 - last.0;
        let t = if gap > 0.0 { (360.0 - last.0) / gap } else { 0.0 };
        let values = last.1.iter().zip(&first.1).map(|(a, b)| a * (1.0 - t) + b * t).collect();
        planes.insert(0, (0.0, values));
    }
    let zero = planes[0].1.clone();
    planes.push((360.0, zero));
    let c: Vec<f64> = planes.iter().map(|p| p.0).collect();
    let values: Vec<f64> = planes.into_iter().flat_map(|p| p.1).collect();
    IntensityTable::try_new(c, gammas, values).map_err(|e| e.to_string())
}

/// The lines of a EULUMDAT file, read one value per line.
struct Lines<'a> {
    lines: Vec<&'a str>,
    /// Lines read so far (the 1-based number of the last one read).
    at: usize,
}

impl<'a> Lines<'a> {
    fn next(&mut self, what: &str) -> Result<(usize, &'a str), Failed> {
        let last = self.lines.len().max(1);
        let l =
            self.lines.get(self.at).copied().ok_or_else(|| (last, format!("the file ends before {what}")))?;
        self.at += 1;
        Ok((self.at, l))
    }
}

fn parse_ldt(text: &str) -> Result<Photometry, Failed> {
    let mut reader = Lines { lines: text.lines().map(str::trim).collect(), at: 0 };
    let last_line = reader.lines.len().max(1);
    let mut next = |what: &str| reader.next(what);
    fn num(l: (usize, &str), what: &str) -> Result<(usize, f64), Failed> {
        // EULUMDAT from some tools writes decimal commas.
        let t = l.1.replace(',', ".");
        match t.trim().parse::<f64>() {
            Ok(v) if v.is_finite() => Ok((l.0, v)),
            _ => Err((l.0, format!("{what}: expected a number, got '{}'", truncate(l.1)))),
        }
    }
    fn whole(l: (usize, f64), what: &str, range: std::ops::RangeInclusive<usize>) -> Result<usize, Failed> {
        if l.1.fract() != 0.0 || l.1 < *range.start() as f64 || l.1 > *range.end() as f64 {
            return Err((
                l.0,
                format!("{what} must be a whole number in {}..={}, got {}", range.start(), range.end(), l.1),
            ));
        }
        Ok(l.1 as usize)
    }
    next("the company line")?;
    let ityp = num(next("Ityp")?, "Ityp (type indicator)")?;
    whole(ityp, "Ityp (type indicator)", 0..=3)?;
    let isym_l = num(next("Isym")?, "Isym (symmetry indicator)")?;
    let isym = whole(isym_l, "Isym (symmetry indicator)", 0..=4)?;
    let mc_l = num(next("Mc")?, "Mc (number of C planes)")?;
    let mc = whole(mc_l, "Mc (number of C planes)", 1..=MAX_ANGLES)?;
    let dc = num(next("Dc")?, "Dc (distance between C planes)")?;
    let ng_l = num(next("Ng")?, "Ng (number of γ angles)")?;
    let ng = whole(ng_l, "Ng (number of γ angles)", 1..=MAX_ANGLES)?;
    let _dg = num(next("Dg")?, "Dg (distance between γ angles)")?;
    next("the measurement report number")?;
    let label = next("the luminaire name")?.1.to_owned();
    for what in ["the luminaire number", "the file name", "the date/user"] {
        next(what)?;
    }
    for what in ["the luminaire length", "the luminaire width", "the luminaire height"] {
        num(next(what)?, what)?;
    }
    // Millimetres; a width of 0 is a round area of that diameter.
    let mut area = [0.0; 2];
    for (k, what) in ["the luminous area's length", "the luminous area's width"].into_iter().enumerate() {
        let (line, v) = num(next(what)?, what)?;
        if v < 0.0 {
            return Err((line, format!("{what} must be ≥ 0 mm, got {v}")));
        }
        area[k] = opening_size(line, v / 1000.0, what)?;
    }
    let opening = match area {
        [l, 0.0] => Opening { length: l, width: l, round: true },
        [l, w] => Opening { length: l, width: w, round: false },
    };
    for what in [
        "the luminous area's height at C0",
        "the luminous area's height at C90",
        "the luminous area's height at C180",
        "the luminous area's height at C270",
        "the downward flux fraction",
        "the light output ratio",
    ] {
        num(next(what)?, what)?;
    }
    let conversion = num(next("the intensity conversion factor")?, "the intensity conversion factor")?;
    num(next("the tilt of the luminaire")?, "the tilt of the luminaire")?;
    let sets_l = num(next("the number of lamp sets")?, "the number of lamp sets")?;
    let sets = whole(sets_l, "the number of lamp sets", 1..=20)?;
    let mut flux = 0.0;
    let mut flux_line = sets_l.0;
    for s in 0..sets {
        num(next("the number of lamps")?, "the number of lamps")?;
        next("the lamp type")?;
        let f = num(next("the lamps' total flux")?, "the lamps' total flux")?;
        if s == 0 {
            flux = f.1;
            flux_line = f.0;
        }
        next("the colour temperature")?;
        next("the colour rendering")?;
        num(next("the wattage")?, "the wattage")?;
    }
    for i in 0..10 {
        num(next("the direct ratios")?, &format!("direct ratio {} of 10", i + 1))?;
    }
    if dc.1 < 0.0 {
        return Err((dc.0, format!("Dc must be ≥ 0, got {}", dc.1)));
    }
    if flux <= 0.0 {
        return Err((flux_line, format!("the lamps' total flux must be > 0 lm, got {flux}")));
    }
    if conversion.1 <= 0.0 {
        return Err((
            conversion.0,
            format!("the intensity conversion factor must be > 0, got {}", conversion.1),
        ));
    }
    let mut c_all = Vec::with_capacity(mc);
    for i in 0..mc {
        let what = format!("C angle {} of {mc}", i + 1);
        c_all.push(num(next(&what)?, &what)?);
    }
    increasing(&c_all, "C angles")?;
    if c_all[0].1 != 0.0 || c_all[mc - 1].1 >= 360.0 {
        return Err((c_all[0].0, "C angles must start at 0° and stay below 360°".to_owned()));
    }
    let mut g = Vec::with_capacity(ng);
    for i in 0..ng {
        let what = format!("γ angle {} of {ng}", i + 1);
        g.push(num(next(&what)?, &what)?);
    }
    increasing(&g, "γ angles")?;
    if g[0].1 < 0.0 || g[ng - 1].1 > 180.0 {
        return Err((g[0].0, format!("γ angles must lie in 0–180°, got {}–{}°", g[0].1, g[ng - 1].1)));
    }
    // Which of the C planes the file holds (Mc1 … Mc2 of the description, 0-based here).
    let (first, count) = match isym {
        0 => (0, mc),
        1 => (0, 1),
        2 => (0, mc / 2 + 1),
        3 => (3 * mc / 4, mc / 2 + 1),
        _ => (0, mc / 4 + 1),
    };
    if isym >= 2 && mc % 4 != 0 && isym != 2 || isym == 2 && mc % 2 != 0 {
        return Err((mc_l.0, format!("Mc = {mc} does not divide into the planes Isym = {isym} needs")));
    }
    let scale = conversion.1 * flux / 1000.0;
    let mut planes: Vec<(f64, Vec<f64>)> = Vec::with_capacity(count);
    for k in 0..count {
        let c = c_all[(first + k) % mc].1;
        let mut values = Vec::with_capacity(ng);
        for i in 0..ng {
            let what = format!("intensity {} of {} (cd/klm)", k * ng + i + 1, count * ng);
            let (line, v) = num(next(&what)?, &what)?;
            if v < 0.0 {
                return Err((line, format!("intensity {v} cd/klm is negative")));
            }
            values.push(v * scale);
        }
        planes.push((c, values));
    }
    if let Some(extra) =
        reader.lines.get(reader.at..).and_then(|rest| rest.iter().position(|l| !l.is_empty()))
    {
        return Err((
            reader.at + extra + 1,
            "more values after the last intensity (counts wrong?)".to_owned(),
        ));
    }
    let gammas: Vec<f64> = g.iter().map(|a| a.1).collect();
    let mirror = |planes: &[(f64, Vec<f64>)], m: fn(f64) -> f64| -> Vec<(f64, Vec<f64>)> {
        planes.iter().map(|(c, v)| (m(*c).rem_euclid(360.0), v.clone())).collect()
    };
    let full = match isym {
        0 => planes,
        1 => vec![(0.0, planes[0].1.clone())],
        2 => [mirror(&planes, |c| 360.0 - c), planes].concat(),
        3 => [mirror(&planes, |c| 180.0 - c), planes].concat(),
        _ => {
            let half = [mirror(&planes, |c| 180.0 - c), planes].concat();
            [mirror(&half, |c| 360.0 - c), half].concat()
        }
    };
    let table = table_of(full, gammas).map_err(|e| (last_line, e))?;
    Ok(Photometry { table, lamp_lumens: Some(flux), label, opening })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ies(body: &str) -> String {
        format!("IESNA:LM-63-2002\n[TEST] unit\n[LUMINAIRE] test downlight\nTILT=NONE\n{body}")
    }

    const LAMBERT: &str = "1 1000 1 4 1 1 2 0.2 0.2 0\n1 1 20\n0 30 60 90\n0\n100 86.6025 50 0\n";

    #[test]
    fn rotationally_symmetric_ies_reads() {
        let p = parse_photometry(&ies(LAMBERT), "t.ies", PhotometricFormat::Ies).unwrap();
        assert_eq!(p.label, "test downlight");
        assert!((p.table.candela(123.0, 30.0) - 86.6025).abs() < 1e-9);
        assert!((p.table.candela(0.0, 45.0) - 68.30125).abs() < 1e-9);
        assert_eq!(p.lamp_lumens, Some(1000.0));
    }

    #[test]
    fn quadrant_symmetry_mirrors() {
        let body = "1 -1 2 2 3 1 2 0 0 0\n1 1 10\n0 90\n0 45 90\n10 1 20 2 30 3\n";
        let p = parse_photometry(&ies(body), "t.ies", PhotometricFormat::Ies).unwrap();
        assert_eq!(p.lamp_lumens, None);
        // Multiplier 2: C90 γ90 = 2·3, C135 = C45, C270 = C90, C315 = C45.
        assert!((p.table.candela(90.0, 90.0) - 6.0).abs() < 1e-9);
        assert!((p.table.candela(135.0, 90.0) - 4.0).abs() < 1e-9);
        assert!((p.table.candela(270.0, 90.0) - 6.0).abs() < 1e-9);
        assert!((p.table.candela(315.0, 0.0) - 40.0).abs() < 1e-9);
        assert!((p.table.candela(180.0, 0.0) - 20.0).abs() < 1e-9);
    }

    fn error(text: &str) -> String {
        parse_photometry(text, "bad.ies", PhotometricFormat::Ies).unwrap_err().to_string()
    }

    #[test]
    fn bad_ies_files_name_their_line() {
        let e = error(&ies("1 1000 1 4 1 1 2 0.2 0.2 0\n1 1 20\n0 30 60 90\n0\n100 86 50\n"));
        assert!(e.starts_with("bad.ies:9:") && e.contains("ends before candela value 4 of 4"), "{e}");
        let e = error(&ies("1 1000 1 4 1 1 2 0.2 0.2 0\n1 1 20\n0 30 60 90\n0\n100 -86 50 0\n"));
        assert!(e.starts_with("bad.ies:9:") && e.contains("negative"), "{e}");
        let e = error(&ies("1 1000 1 4 1 1 2 0.2 0.2 0\n1 1 20\n0 60 30 90\n0\n100 86 50 0\n"));
        assert!(e.starts_with("bad.ies:7:") && e.contains("out of order"), "{e}");
        let e = error(&ies("1 1000 1 4 1 3 2 0.2 0.2 0\n1 1 20\n0 30 60 90\n0\n100 86 50 0\n"));
        assert!(e.contains("type A is not supported"), "{e}");
        let e = error(&ies("1 1000 1 4 1 1 2 0.2 0.2 0\n1 1 20\n0 30 60 90\n0\n100 86 50 0 7\n"));
        assert!(e.contains("after the last candela"), "{e}");
        let e = error("IESNA:LM-63-2002\nTILT=INCLUDE\n1\n3\n0 45\n");
        assert!(e.starts_with("bad.ies:5:") && e.contains("TILT"), "{e}");
        let e = error("IESNA:LM-63-2002\n[TEST] x\n");
        assert!(e.contains("no TILT"), "{e}");
    }

    fn ldt(isym: u32, mc: u32, dc: f64, c_planes: &[f64], gammas: &[f64], values: &[f64]) -> String {
        let mut s = format!(
            "Company\n1\n{isym}\n{mc}\n{dc}\n{}\n10\nreport\nname\nnumber\nfile.ldt\ndate\n",
            gammas.len()
        );
        for _ in 0..11 {
            s += "100\n";
        }
        s += "1\n0\n1\n1\nLED\n2000\n3000\n80\n20\n";
        for _ in 0..10 {
            s += "0.5\n";
        }
        for c in c_planes {
            s += &format!("{c}\n");
        }
        for g in gammas {
            s += &format!("{g}\n");
        }
        for v in values {
            s += &format!("{v}\n");
        }
        s
    }

    #[test]
    fn eulumdat_symmetries_expand() {
        let c: Vec<f64> = (0..4).map(|i| f64::from(i) * 90.0).collect();
        // Isym 4: planes C0 and C90 given; cd/klm × 2000 lm / 1000.
        let text = ldt(4, 4, 90.0, &c, &[0.0, 90.0], &[100.0, 10.0, 200.0, 20.0]);
        let p = parse_photometry(&text, "t.ldt", PhotometricFormat::Eulumdat).unwrap();
        assert!((p.table.candela(0.0, 0.0) - 200.0).abs() < 1e-9);
        assert!((p.table.candela(90.0, 90.0) - 40.0).abs() < 1e-9);
        assert!((p.table.candela(180.0, 90.0) - 20.0).abs() < 1e-9);
        assert!((p.table.candela(270.0, 90.0) - 40.0).abs() < 1e-9);
        // Isym 1: one plane.
        let text = ldt(1, 4, 90.0, &c, &[0.0, 90.0], &[100.0, 10.0]);
        let p = parse_photometry(&text, "t.ldt", PhotometricFormat::Eulumdat).unwrap();
        assert!((p.table.candela(200.0, 90.0) - 20.0).abs() < 1e-9);
        // Truncated.
        let text = ldt(1, 4, 90.0, &c, &[0.0, 90.0], &[100.0]);
        let e = parse_photometry(&text, "t.ldt", PhotometricFormat::Eulumdat).unwrap_err().to_string();
        assert!(e.contains("ends before intensity 2 of 2"), "{e}");
    }

    /// The luminous opening: IES in feet or metres, negative for round (a disc from the
    /// width alone); EULUMDAT in millimetres, width 0 for round; sizes out of range refused
    /// on their line.
    #[test]
    fn luminous_openings_read_in_metres() {
        let opening =
            |body: &str| parse_photometry(&ies(body), "t.ies", PhotometricFormat::Ies).map(|p| p.opening);
        let o = opening(LAMBERT).unwrap();
        assert_eq!((o.length, o.width, o.round), (0.2, 0.2, false));
        let o = opening(&LAMBERT.replace("1 1 2 0.2 0.2 0", "1 1 1 1.5 4 0")).unwrap();
        assert!((o.width - 0.4572).abs() < 1e-12 && (o.length - 1.2192).abs() < 1e-12 && !o.round, "{o:?}");
        let o = opening(&LAMBERT.replace("1 1 2 0.2 0.2 0", "1 1 2 -0.3 0 0")).unwrap();
        assert_eq!((o.length, o.width, o.round), (0.3, 0.3, true));
        let o = opening(&LAMBERT.replace("1 1 2 0.2 0.2 0", "1 1 2 0 0 0")).unwrap();
        assert_eq!(o, Opening::default(), "a point");
        let e = error(&ies(&LAMBERT.replace("1 1 2 0.2 0.2 0", "1 1 2 0.2 1e9 0")));
        assert!(e.starts_with("bad.ies:5:") && e.contains("more than 100 m"), "{e}");

        let c: Vec<f64> = (0..4).map(|i| f64::from(i) * 90.0).collect();
        let text = ldt(1, 4, 90.0, &c, &[0.0, 90.0], &[100.0, 10.0]);
        let o = parse_photometry(&text, "t.ldt", PhotometricFormat::Eulumdat).unwrap().opening;
        assert_eq!((o.length, o.width, o.round), (0.1, 0.1, false));
        // Lines 16 and 17: the luminous area's length and width.
        let lines = |f: &dyn Fn(usize, &str) -> String| {
            text.lines().enumerate().map(|(i, l)| f(i, l) + "\n").collect::<String>()
        };
        let round = lines(&|i, l| if i == 16 { "0".to_owned() } else { l.to_owned() });
        let o = parse_photometry(&round, "t.ldt", PhotometricFormat::Eulumdat).unwrap().opening;
        assert_eq!((o.length, o.width, o.round), (0.1, 0.1, true));
        let negative = lines(&|i, l| if i == 15 { "-5".to_owned() } else { l.to_owned() });
        let e = parse_photometry(&negative, "t.ldt", PhotometricFormat::Eulumdat).unwrap_err().to_string();
        assert!(e.starts_with("t.ldt:16:") && e.contains("≥ 0 mm"), "{e}");
    }
}
