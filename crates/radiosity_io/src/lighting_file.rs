//! The photometric keys of a scene file: `units`, `lumens` / `luminance` / `colour` / `cct`
//! on materials, `[[luminaire]]` and `[[grid]]`, validated into [`Lighting`] and material
//! emission (the RGB ↔ lumen rule is [`radiosity_core::photometric_y`]'s: 683 lm/W of
//! Rec. 709 Y).

use std::ops::Range;
use std::path::Path;
use std::sync::Arc;

use radiosity_core::glam::DVec3;
use radiosity_core::{
    Grid, IntensityTable, LUMENS_PER_WATT, LengthUnit, Lighting, Luminaire, Material, Object, Opening, Rgb,
    Shape, Sides, Sky, SkyMap, SkyModel, Sun, UpAxis, colour_of_cct, unit_luminance,
};
use toml::Spanned;

use crate::LoadError;
use crate::desc::{MaterialDesc, SceneDesc, SkyDesc, SunDesc};
use crate::locate::Locator;
use crate::photometric::load_photometry;

/// Most luminaires one scene may place.
pub const MAX_LUMINAIRES: usize = 100_000;

/// Most points in all the grids of a scene.
pub const MAX_GRID_POINTS: u64 = 4_000_000;

/// The scene's unit: `opts_units` (a command-line `--units`) over the file's `units` key.
pub(crate) fn units(
    loc: &Locator,
    desc: &SceneDesc,
    opts_units: Option<LengthUnit>,
) -> Result<Option<LengthUnit>, LoadError> {
    if opts_units.is_some() {
        return Ok(opts_units);
    }
    desc.units
        .as_ref()
        .map(|u| {
            LengthUnit::parse(u.get_ref()).ok_or_else(|| {
                let names: Vec<String> = LengthUnit::ALL.iter().map(|(n, _)| format!("\"{n}\"")).collect();
                loc.at(
                    u.span(),
                    "units",
                    format!("expected one of {}, got {:?}", names.join(", "), u.get_ref()),
                )
            })
        })
        .transpose()
}

/// The Y = 1 colour of `colour` or `cct` (white without either), or an error at the key.
fn light_colour(
    loc: &Locator,
    key: &str,
    colour: Option<&Spanned<[f64; 3]>>,
    cct: Option<&Spanned<f64>>,
) -> Result<Rgb, LoadError> {
    match (colour, cct) {
        (Some(c), Some(_)) => Err(loc.at(c.span(), format!("{key}.colour"), "give colour or cct, not both")),
        (Some(c), None) => unit_luminance(Rgb::from_array(*c.get_ref())).ok_or_else(|| {
            loc.at(c.span(), format!("{key}.colour"), "colour must be finite, ≥ 0 and not black")
        }),
        (None, Some(t)) => {
            let k = *t.get_ref();
            if (1000.0..=40000.0).contains(&k) {
                Ok(colour_of_cct(k))
            } else {
                Err(loc.at(t.span(), format!("{key}.cct"), format!("cct must be in 1000–40000 K, got {k}")))
            }
        }
        (None, None) => Ok(Rgb::ONE),
    }
}

fn positive(loc: &Locator, key: String, v: &Spanned<f64>) -> Result<f64, LoadError> {
    let x = *v.get_ref();
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(loc.at(v.span(), key, format!("expected a finite number > 0, got {x}")))
    }
}

/// Area of `object` that emits: its area, twice for a two-sided object whose back emits.
fn emitting_area(object: &Object) -> f64 {
    let area = match &object.shape {
        Shape::Polygons(ps) => ps.iter().map(|p| p.area()).sum(),
        Shape::Sphere(s) => 4.0 * std::f64::consts::PI * s.radius * s.radius,
        Shape::Mesh(m) => m.area(),
    };
    if matches!(object.sides, Sides::Two { emits_back: true }) { 2.0 * area } else { area }
}

/// Emission from the materials' `luminance` and `lumens` keys: luminance L cd/m² is an
/// exitance π·L lm/m², π·L/683 · s² W/unit²; `lumens` Φ over an object's emitting area A
/// (unit²) is Φ / 683 / A W/unit². A material giving `lumens` used by objects of different
/// areas is copied per object (`NAME (OBJECT)`), so each whole object emits Φ.
pub(crate) fn photometric_emission(
    loc: &Locator,
    descs: &[Spanned<MaterialDesc>],
    materials: &mut Vec<Material>,
    objects: &mut [Object],
    unit: LengthUnit,
) -> Result<(), LoadError> {
    for (i, m) in descs.iter().enumerate() {
        let m = m.get_ref();
        let key = format!("material[{i}]");
        let given = [m.lumens.as_ref(), m.luminance.as_ref()];
        if given.iter().all(Option::is_none) {
            for (k, span) in
                [("colour", m.colour.as_ref().map(Spanned::span)), ("cct", m.cct.as_ref().map(Spanned::span))]
            {
                if let Some(span) = span {
                    return Err(loc.at(
                        span,
                        format!("{key}.{k}"),
                        format!("{k} colours `lumens` or `luminance` light; give one of those"),
                    ));
                }
            }
            continue;
        }
        if let (Some(a), Some(_)) = (m.lumens.as_ref(), m.luminance.as_ref()) {
            return Err(loc.at(a.span(), format!("{key}.lumens"), "give lumens or luminance, not both"));
        }
        if let (Some(e), Some(_)) = (m.emission.as_ref(), given.iter().flatten().next()) {
            return Err(loc.at(
                e.span(),
                format!("{key}.emission"),
                "give emission (W) or lumens/luminance, not both",
            ));
        }
        let colour = light_colour(loc, &key, m.colour.as_ref(), m.cct.as_ref())?;
        if let Some(l) = &m.luminance {
            let l = positive(loc, format!("{key}.luminance"), l)?;
            let s = unit.metres();
            materials[i].emission = colour * (std::f64::consts::PI * l / LUMENS_PER_WATT * s * s);
        }
        if let Some(f) = &m.lumens {
            let flux = positive(loc, format!("{key}.lumens"), f)?;
            let mut first_area: Option<f64> = None;
            for o in objects.iter_mut().filter(|o| o.material == i) {
                let area = emitting_area(o);
                let emission = colour * (flux / LUMENS_PER_WATT / area);
                match first_area {
                    None => {
                        first_area = Some(area);
                        materials[i].emission = emission;
                    }
                    Some(a) if a == area => {}
                    Some(_) => {
                        let mut copy = materials[i].clone();
                        copy.name = format!("{} ({})", copy.name, o.name);
                        copy.emission = emission;
                        materials.push(copy);
                        o.material = materials.len() - 1;
                    }
                }
            }
        }
    }
    Ok(())
}

fn finite3(loc: &Locator, key: String, v: &Spanned<[f64; 3]>) -> Result<DVec3, LoadError> {
    let a = *v.get_ref();
    if radiosity_core::coordinate_in_range(a) {
        Ok(DVec3::from_array(a))
    } else {
        Err(loc.at(
            v.span(),
            key,
            format!("expected finite coordinates within ±{:e}, got {a:?}", radiosity_core::MAX_COORDINATE),
        ))
    }
}

fn direction(loc: &Locator, key: String, v: &Spanned<[f64; 3]>) -> Result<DVec3, LoadError> {
    let d = finite3(loc, key.clone(), v)?;
    if d.length() > 0.0 {
        Ok(d.normalize())
    } else {
        Err(loc.at(v.span(), key, "a direction must not be zero"))
    }
}

/// The `[sun]` table: a direction, or a place and a time, and either lux (with a colour) or
/// W/unit². `up` is the file's up axis.
fn sun(loc: &Locator, d: &Spanned<SunDesc>, unit: LengthUnit, up: UpAxis) -> Result<Sun, LoadError> {
    let (span, d) = (d.span(), d.get_ref());
    let towards = match (&d.direction, &d.time) {
        (Some(towards), None) => direction(loc, "sun.direction".into(), towards)?,
        (None, Some(time)) => sun_at(loc, d, time, up)?,
        (Some(towards), Some(_)) => {
            return Err(loc.at(
                towards.span(),
                "sun.direction",
                "give direction or latitude, longitude and time, not both",
            ));
        }
        (None, None) => {
            return Err(loc.at(
                span,
                "sun.direction",
                "the sun needs direction = [x, y, z] (towards the sun), or latitude, longitude and time",
            ));
        }
    };
    let amount =
        Amount { illuminance: &d.illuminance, irradiance: &d.irradiance, colour: &d.colour, cct: &d.cct };
    let irradiance = amount.irradiance(loc, span, "sun", "on a plane facing it", unit)?;
    Ok(Sun { towards, irradiance })
}

/// The direction towards the sun from the `[sun]` table's place and `time`, in the file's
/// frame: east is north × up.
fn sun_at(
    loc: &Locator,
    d: &SunDesc,
    time: &Spanned<toml::value::Datetime>,
    up: UpAxis,
) -> Result<DVec3, LoadError> {
    let degrees = |key: &str, v: &Option<Spanned<f64>>, limit: f64| -> Result<f64, LoadError> {
        let Some(v) = v else {
            return Err(loc.at(
                time.span(),
                format!("sun.{key}"),
                format!("a sun placed by time needs {key}"),
            ));
        };
        let x = *v.get_ref();
        if x.is_finite() && x.abs() <= limit {
            Ok(x)
        } else {
            Err(loc.at(v.span(), format!("sun.{key}"), format!("expected degrees from −{limit} to {limit}")))
        }
    };
    let latitude = degrees("latitude", &d.latitude, 90.0)?;
    let longitude = degrees("longitude", &d.longitude, 180.0)?;
    let position = crate::sun_position::solar_position(latitude, longitude, time.get_ref()).map_err(|e| {
        let why = match e {
            crate::sun_position::TimeError::Incomplete => {
                "expected a date and a time, such as 2026-06-21T12:00:00+02:00"
            }
            crate::sun_position::TimeError::NoOffset => {
                "the time needs its offset from UTC, such as 2026-06-21T12:00:00+02:00 or …Z"
            }
        };
        loc.at(time.span(), "sun.time", why)
    })?;
    if position.elevation <= 0.0 {
        return Err(loc.at(
            time.span(),
            "sun.time",
            format!("the sun is {:.1}° below the horizon at that place and time", -position.elevation),
        ));
    }
    let file_up = up.from_y_up(DVec3::Y);
    let north = match &d.north {
        Some(n) => direction(loc, "sun.north".into(), n)?,
        None => up.from_y_up(DVec3::NEG_Z),
    };
    // North as given may lean: only its horizontal part counts.
    let north = north - file_up * north.dot(file_up);
    if north.length() < 1e-9 {
        let span = d.north.as_ref().map_or(time.span(), |n| n.span());
        return Err(loc.at(span, "sun.north", "north must not point straight up or down"));
    }
    let north = north.normalize();
    let east = north.cross(file_up);
    let (el, az) = (position.elevation.to_radians(), position.azimuth.to_radians());
    Ok((east * az.sin() + north * az.cos()) * el.cos() + file_up * el.sin())
}

/// The `[sky]` table: a model and its unobstructed horizontal light, lux (with a colour) or
/// W/unit²; the zenith is the file's up axis; the clear sky takes the `[sun]`'s position.
fn sky(
    loc: &Locator,
    d: &Spanned<SkyDesc>,
    unit: LengthUnit,
    (up, folder): (UpAxis, &Path),
    sun: Option<&Sun>,
) -> Result<Sky, LoadError> {
    let zenith = up.from_y_up(DVec3::Y);
    let (span, d) = (d.span(), d.get_ref());
    if let Some(file) = &d.map {
        return sky_of_map(loc, (span, d), unit, (up, folder), file);
    }
    for (key, given) in
        [("scale", d.scale.as_ref().map(|s| s.span())), ("rotation", d.rotation.as_ref().map(|r| r.span()))]
    {
        if let Some(at) = given {
            return Err(loc.at(at, format!("sky.{key}"), "turns or scales a map: give sky.map too"));
        }
    }
    let model = match d.model.as_ref().map(|m| (m.span(), m.get_ref().as_str())) {
        None | Some((_, "cie-overcast")) => SkyModel::CieOvercast,
        Some((_, "uniform")) => SkyModel::Uniform,
        Some((span, "cie-clear")) => match sun {
            Some(sun) if sun.towards.dot(zenith) > 0.0 => SkyModel::CieClear { sun: sun.towards },
            Some(_) => {
                return Err(loc.at(span, "sky.model", "a clear sky needs the [sun] above the horizon"));
            }
            None => {
                return Err(loc.at(
                    span,
                    "sky.model",
                    "a clear sky is brightest around the sun: give a [sun] (direction or place and time)",
                ));
            }
        },
        Some((span, other)) => {
            let other = radiosity_core::escape_controls(other);
            return Err(loc.at(
                span,
                "sky.model",
                format!("unknown sky model '{other}' (cie-overcast, cie-clear or uniform)"),
            ));
        }
    };
    let rays = sky_rays(loc, d)?;
    let amount =
        Amount { illuminance: &d.illuminance, irradiance: &d.irradiance, colour: &d.colour, cct: &d.cct };
    let horizontal = amount.irradiance(loc, span, "sky", "on an open horizontal plane", unit)?;
    Ok(Sky::from_horizontal(model, zenith, horizontal, rays))
}

/// The most shadow rays per element a `[sky]` may ask for.
const MAX_SKY_RAYS: i64 = 4096;

/// Shadow rays per element from `[sky]`'s `rays`, or the default.
fn sky_rays(loc: &Locator, d: &SkyDesc) -> Result<u32, LoadError> {
    match &d.rays {
        None => Ok(Sky::DEFAULT_RAYS),
        Some(r) if (1..=MAX_SKY_RAYS).contains(r.get_ref()) => Ok(*r.get_ref() as u32),
        Some(r) => {
            Err(loc.at(r.span(), "sky.rays", format!("expected a whole number from 1 to {MAX_SKY_RAYS}")))
        }
    }
}

/// The most texels along a sky map's width.
const MAX_SKY_MAP_WIDTH: u32 = 16_384;

/// A `[sky]` given by an environment map `file` (relative to `folder`): its middle column
/// faces north (the `[sun]`'s default north, the file's −z, or +y for a z-up file) turned by
/// `rotation` degrees towards east; its texels times `scale`, or scaled so that the open
/// horizontal plane receives the illuminance or irradiance given.
fn sky_of_map(
    loc: &Locator,
    (span, d): (Range<usize>, &SkyDesc),
    unit: LengthUnit,
    (up, folder): (UpAxis, &Path),
    file: &Spanned<String>,
) -> Result<Sky, LoadError> {
    if let Some(m) = d.model.as_ref().filter(|m| m.get_ref() != "map") {
        return Err(loc.at(
            m.span(),
            "sky.model",
            "a sky is a model or a map: give one of sky.model and sky.map",
        ));
    }
    let path = folder.join(file.get_ref());
    let map = read_sky_map(&path)
        .map_err(|m| loc.at(file.span(), "sky.map", format!("{}: {m}", path.display())))?;
    let number = |v: &Option<Spanned<f64>>, key: &str, default: f64, ok: fn(f64) -> bool| match v {
        None => Ok(default),
        Some(x) if x.get_ref().is_finite() && ok(*x.get_ref()) => Ok(*x.get_ref()),
        Some(x) => Err(loc.at(x.span(), format!("sky.{key}"), "expected a finite number (a scale above 0)")),
    };
    let scale = number(&d.scale, "scale", 1.0, |s| s > 0.0)?;
    let rotation = number(&d.rotation, "rotation", 0.0, |_| true)?;
    let zenith = up.from_y_up(DVec3::Y);
    let north = up.from_y_up(DVec3::NEG_Z);
    let east = north.cross(zenith);
    let turn = rotation.to_radians();
    let forward = north * turn.cos() + east * turn.sin();
    let rays = sky_rays(loc, d)?;
    let map = Arc::new(map);
    if d.illuminance.is_some() || d.irradiance.is_some() {
        if let Some(s) = &d.scale {
            return Err(loc.at(s.span(), "sky.scale", "give a scale or an amount of light, not both"));
        }
        let amount =
            Amount { illuminance: &d.illuminance, irradiance: &d.irradiance, colour: &d.colour, cct: &d.cct };
        let horizontal = amount.irradiance(loc, span, "sky", "on an open horizontal plane", unit)?;
        if map.horizontal_irradiance().luminance() <= 0.0 {
            return Err(loc.at(
                file.span(),
                "sky.map",
                "the map's upper half is black: it cannot be scaled to an amount of light",
            ));
        }
        return Ok(Sky::from_horizontal(SkyModel::Map { map, forward }, zenith, horizontal, rays));
    }
    Ok(Sky::from_map(map, zenith, forward, Rgb::splat(scale), rays))
}

/// An equirectangular map of linear radiance from a Radiance `.hdr` file (the loader reads no
/// OpenEXR: that codec belongs to the picture crates; an `.exr` map converts losslessly).
fn read_sky_map(path: &Path) -> Result<SkyMap, String> {
    let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
    if ext.as_deref() != Some("hdr") {
        return Err("expected a linear HDR image in Radiance's .hdr format".into());
    }
    let (w, h) = image::image_dimensions(path).map_err(|e| e.to_string())?;
    if w > MAX_SKY_MAP_WIDTH || h > MAX_SKY_MAP_WIDTH / 2 + 1 {
        return Err(format!("{w} × {h} texels: at most {MAX_SKY_MAP_WIDTH} × {}", MAX_SKY_MAP_WIDTH / 2));
    }
    let image = image::open(path).map_err(|e| e.to_string())?.to_rgb32f();
    let texels = image.pixels().map(|p| Rgb::new(p[0].into(), p[1].into(), p[2].into())).collect();
    SkyMap::try_new(w, h, texels)
}

/// How much light a sun or a sky gives, as written: lux with a colour, or W/unit².
struct Amount<'a> {
    illuminance: &'a Option<Spanned<f64>>,
    irradiance: &'a Option<Spanned<[f64; 3]>>,
    colour: &'a Option<Spanned<[f64; 3]>>,
    cct: &'a Option<Spanned<f64>>,
}

impl Amount<'_> {
    /// The irradiance per channel, W/unit²; errors name `table`'s keys (`span` is the
    /// table's, for a missing amount; `plane` says where the amount is measured).
    fn irradiance(
        &self,
        loc: &Locator,
        span: Range<usize>,
        table: &str,
        plane: &str,
        unit: LengthUnit,
    ) -> Result<Rgb, LoadError> {
        match (self.illuminance, self.irradiance) {
            (Some(lx), None) => {
                let colour = light_colour(loc, table, self.colour.as_ref(), self.cct.as_ref())?;
                Ok(colour * (positive(loc, format!("{table}.illuminance"), lx)? / unit.lux_per_irradiance()))
            }
            (None, Some(w)) => {
                if let Some(c) = self.colour {
                    return Err(loc.at(
                        c.span(),
                        format!("{table}.colour"),
                        "irradiance has its own colour; colour goes with illuminance",
                    ));
                }
                let e = Rgb::from_array(*w.get_ref());
                if !(e.is_finite() && e.min_channel() >= 0.0 && e.max_channel() > 0.0) {
                    return Err(loc.at(
                        w.span(),
                        format!("{table}.irradiance"),
                        "irradiance must be finite, ≥ 0 and not black",
                    ));
                }
                Ok(e)
            }
            (Some(lx), Some(_)) => Err(loc.at(
                lx.span(),
                format!("{table}.illuminance"),
                "give illuminance (lx) or irradiance (W/unit²), not both",
            )),
            (None, None) => Err(loc.at(
                span,
                table,
                format!("the {table} needs illuminance = <lx> or irradiance = [r, g, b] (W/unit²), {plane}"),
            )),
        }
    }
}

/// The `[[luminaire]]` and `[[grid]]` entries, in the file's frame (`up`: the file's up axis,
/// for the default aim and grid normal).
pub(crate) fn lighting(
    loc: &Locator,
    desc: &SceneDesc,
    units: Option<LengthUnit>,
    up: UpAxis,
) -> Result<Lighting, LoadError> {
    let file_up = up.from_y_up(DVec3::Y);
    let unit = units.unwrap_or_default();
    let folder = Path::new(loc.origin).parent().unwrap_or(Path::new(""));
    let mut luminaires = Vec::new();
    let mut tables: Vec<(String, Arc<IntensityTable>, f64, Opening)> = Vec::new();
    for (i, l) in desc.luminaire.iter().enumerate() {
        let key = format!("luminaire[{i}]");
        let l = l.get_ref();
        let path = folder.join(l.file.get_ref());
        let stem = Path::new(l.file.get_ref())
            .file_stem()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
        let (table, file_flux, opening) = match tables.iter().find(|t| t.0 == *l.file.get_ref()) {
            Some(t) => (t.1.clone(), t.2, t.3),
            None => {
                let p = load_photometry(&path)?;
                let table = Arc::new(p.table);
                let flux = table.flux();
                tables.push((l.file.get_ref().clone(), table.clone(), flux, p.opening));
                (table, flux, p.opening)
            }
        };
        // The file's opening is in metres; a point when asked for.
        let opening = if l.near_field == Some(false) {
            Opening::default()
        } else {
            let s = unit.metres();
            Opening { length: opening.length / s, width: opening.width / s, ..opening }
        };
        let mut scale = l
            .multiplier
            .as_ref()
            .map(|m| positive(loc, format!("{key}.multiplier"), m))
            .transpose()?
            .unwrap_or(1.0);
        if let Some(f) = &l.lumens {
            let want = positive(loc, format!("{key}.lumens"), f)?;
            if file_flux <= 0.0 {
                return Err(loc.at(f.span(), format!("{key}.lumens"), "the file's intensities are all zero"));
            }
            scale *= want / file_flux;
        }
        let aim =
            l.aim.as_ref().map(|a| direction(loc, format!("{key}.aim"), a)).transpose()?.unwrap_or(-file_up);
        let rotation = match &l.rotation_deg {
            Some(r) if r.get_ref().is_finite() => *r.get_ref(),
            Some(r) => {
                return Err(loc.at(
                    r.span(),
                    format!("{key}.rotation_deg"),
                    "expected a finite number of degrees",
                ));
            }
            None => 0.0,
        };
        let colour = light_colour(loc, &key, l.colour.as_ref(), l.cct.as_ref())?;
        let positions: Vec<DVec3> = match (&l.position, &l.positions) {
            (Some(p), None) => vec![finite3(loc, format!("{key}.position"), p)?],
            (None, Some(ps)) => {
                if ps.get_ref().is_empty() {
                    return Err(loc.at(
                        ps.span(),
                        format!("{key}.positions"),
                        "expected at least one [x, y, z]",
                    ));
                }
                let at =
                    |p: &[f64; 3]| finite3(loc, format!("{key}.positions"), &Spanned::new(ps.span(), *p));
                ps.get_ref().iter().map(at).collect::<Result<_, _>>()?
            }
            (Some(p), Some(_)) => {
                return Err(loc.at(
                    p.span(),
                    format!("{key}.position"),
                    "give position or positions, not both",
                ));
            }
            (None, None) => {
                return Err(loc.at(
                    l.file.span(),
                    key.clone(),
                    "a luminaire needs position = [x, y, z] or positions = [[x, y, z], …]",
                ));
            }
        };
        let name = l.name.clone().unwrap_or(stem);
        let many = positions.len() > 1;
        for (k, p) in positions.into_iter().enumerate() {
            if luminaires.len() >= MAX_LUMINAIRES {
                return Err(loc.at(l.file.span(), key, format!("more than {MAX_LUMINAIRES} luminaires")));
            }
            let name = if many { format!("{name} #{}", k + 1) } else { name.clone() };
            let luminaire = Luminaire::aimed(name, p, aim, rotation, table.clone(), scale, colour);
            luminaires.push(Luminaire { opening, ..luminaire });
        }
    }
    let mut grids = Vec::new();
    let mut total_points = 0u64;
    for (i, spanned) in desc.grid.iter().enumerate() {
        let key = format!("grid[{i}]");
        let g = spanned.get_ref();
        let ((origin, u, v), on_surface) = match (&g.surface, &g.origin, &g.u, &g.v) {
            (Some(name), None, None, None) => (surface_frame(loc, desc, &key, name)?, true),
            (Some(name), ..) => {
                return Err(loc.at(
                    name.span(),
                    format!("{key}.surface"),
                    "give surface or origin, u and v, not both",
                ));
            }
            (None, Some(o), Some(u), Some(v)) => {
                let origin = finite3(loc, format!("{key}.origin"), o)?;
                let (a, b) = (finite3(loc, format!("{key}.u"), u)?, finite3(loc, format!("{key}.v"), v)?);
                if a.cross(b).length() <= 1e-12 * a.length() * b.length() || a.length() == 0.0 {
                    return Err(loc.at(
                        v.span(),
                        format!("{key}.v"),
                        "u and v must span a rectangle (non-zero, not parallel)",
                    ));
                }
                ((origin, a, b), false)
            }
            (None, ..) => {
                return Err(loc.at(
                    spanned.span(),
                    key,
                    "a grid needs origin, u and v (a rectangle), or surface (an object's name)",
                ));
            }
        };
        let divisions = match (&g.divisions, &g.spacing) {
            (Some(_), Some(s)) => {
                return Err(loc.at(
                    s.span(),
                    format!("{key}.spacing"),
                    "give spacing or divisions, not both",
                ));
            }
            (Some(d), None) => {
                let [a, b] = *d.get_ref();
                if !(1..=100_000).contains(&a) || !(1..=100_000).contains(&b) {
                    return Err(loc.at(
                        d.span(),
                        format!("{key}.divisions"),
                        format!("expected two whole numbers in 1..=100000, got [{a}, {b}]"),
                    ));
                }
                [a as u32, b as u32]
            }
            (None, spacing) => {
                let p = match spacing {
                    Some(s) => positive(loc, format!("{key}.spacing"), s)?,
                    // EN 12464-1: p = 0.2 · 5^log10(d), d the longer side in metres.
                    None => {
                        Grid::standard_spacing(u.length().max(v.length()) * unit.metres()) / unit.metres()
                    }
                };
                let cells = |len: f64| (len / p).ceil().clamp(1.0, 100_000.0) as u32;
                [cells(u.length()), cells(v.length())]
            }
        };
        total_points += u64::from(divisions[0]) * u64::from(divisions[1]);
        if total_points > MAX_GRID_POINTS {
            return Err(loc.at(
                spanned.span(),
                key,
                format!("the grids have more than {MAX_GRID_POINTS} points"),
            ));
        }
        // A surface's grid faces out of its front, as the polygon's corners turn.
        let default_normal = if on_surface { u.cross(v).normalize() } else { file_up };
        let normal = g
            .normal
            .as_ref()
            .map(|n| direction(loc, format!("{key}.normal"), n))
            .transpose()?
            .unwrap_or(default_normal);
        let height = match &g.height {
            Some(h) if h.get_ref().is_finite() => *h.get_ref(),
            Some(h) => return Err(loc.at(h.span(), format!("{key}.height"), "expected a finite number")),
            // On a surface the points stand 1 mm off it, so that it cannot shadow them.
            None if on_surface => SURFACE_LIFT_METRES / unit.metres(),
            None => 0.0,
        };
        let name = g.name.clone().unwrap_or_else(|| match &g.surface {
            Some(s) => s.get_ref().clone(),
            None => format!("grid {}", i + 1),
        });
        grids.push(Grid { name, origin, u, v, divisions, normal, height });
    }
    let sun = desc.sun.as_ref().map(|d| sun(loc, d, unit, up)).transpose()?;
    let sky = desc.sky.as_ref().map(|d| sky(loc, d, unit, (up, folder), sun.as_ref())).transpose()?;
    Ok(Lighting { units, luminaires, grids, sun, sky })
}

/// How far a surface's grid points stand off it, metres.
pub const SURFACE_LIFT_METRES: f64 = 1e-3;

/// The rectangle (corner, first edge, second edge) of the object `name` names, for a grid on
/// its front: a `polygon` of four corners that make a parallelogram; corners 0, 1 and 3 give
/// the corner and the edges, so u × v is the polygon's front normal.
fn surface_frame(
    loc: &Locator,
    desc: &SceneDesc,
    key: &str,
    name: &Spanned<String>,
) -> Result<(DVec3, DVec3, DVec3), LoadError> {
    let err = |msg: String| loc.at(name.span(), format!("{key}.surface"), msg);
    let object = desc
        .object
        .iter()
        .map(Spanned::get_ref)
        .find(|o| o.name.get_ref() == name.get_ref())
        .ok_or_else(|| err(format!("no object is named '{}'", name.get_ref())))?;
    let corners: Vec<DVec3> = match (object.kind.get_ref().as_str(), &object.vertices) {
        ("polygon", Some(face)) => face.get_ref().iter().map(|p| DVec3::from_array(*p.get_ref())).collect(),
        _ => Vec::new(),
    };
    let parallelogram = corners.len() == 4 && {
        let d = corners[0] + corners[2] - corners[1] - corners[3];
        d.length() <= 1e-9 * (corners[2] - corners[0]).length().max(f64::MIN_POSITIVE)
    };
    if !parallelogram {
        return Err(err(format!(
            "'{}' is not a polygon of four corners making a rectangle or parallelogram; a grid covers only such a surface (give origin, u and v for any other)",
            name.get_ref()
        )));
    }
    let (u, v) = (corners[1] - corners[0], corners[3] - corners[0]);
    if u.cross(v).length() <= 1e-12 * u.length() * v.length() || u.length() == 0.0 {
        return Err(err(format!("'{}' has no area", name.get_ref())));
    }
    Ok((corners[0], u, v))
}
