//! The one-page HTML report of `radiosity grid`: what a lighting designer hands to a client.
//! One self-contained file (styles inline, pictures as base64 PNG data), so it can be mailed
//! or printed as it is.

use radiosity_image::{GridIlluminance, format_lux};

use crate::prepare::Prepared;

/// `bytes` in base64 (RFC 4648, with padding).
pub fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(char::from(ALPHABET[(n >> (18 - 6 * k) & 63) as usize]));
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// `text` with HTML's special characters escaped.
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// A luminaire's type: its name without the number of its place in a row (`downlight #3`).
fn luminaire_type(name: &str) -> &str {
    name.rsplit_once(" #").map_or(name, |(base, n)| if n.parse::<u32>().is_ok() { base } else { name })
}

/// The luminaire schedule (each type with its count, flux each and in all, and the total),
/// then every luminaire's position in a folded table.
fn luminaire_tables(prepared: &Prepared) -> String {
    let lighting = &prepared.scene.lighting;
    let unit = lighting.unit().as_str();
    // Types in the order they first appear; one row per type and flux.
    let mut rows: Vec<(&str, f64, usize)> = Vec::new();
    for l in &lighting.luminaires {
        let (kind, flux) = (luminaire_type(&l.name), l.flux());
        match rows.iter_mut().find(|r| r.0 == kind && (r.1 - flux).abs() <= 1e-9 * flux.abs()) {
            Some(r) => r.2 += 1,
            None => rows.push((kind, flux, 1)),
        }
    }
    let mut h = String::from(
        "<table><tr><th>luminaire</th><th>count</th><th>flux each (lm)</th><th>flux (lm)</th></tr>\n",
    );
    for (kind, flux, count) in &rows {
        h += &format!(
            "<tr><td>{}</td><td class=\"n\">{count}</td><td class=\"n\">{flux:.0}</td><td class=\"n\">{:.0}</td></tr>\n",
            escape(kind),
            flux * *count as f64
        );
    }
    let total: f64 = lighting.luminaires.iter().map(|l| l.flux()).sum();
    h += &format!(
        "<tr><th>total</th><th class=\"n\">{}</th><th></th><th class=\"n\">{total:.0}</th></tr></table>\n",
        lighting.luminaires.len()
    );
    h += &format!(
        "<details><summary>Positions</summary><table><tr><th>luminaire</th><th>x, y, z ({unit})</th></tr>\n"
    );
    for l in &lighting.luminaires {
        let p = prepared.up.from_y_up(l.position);
        h += &format!(
            "<tr><td>{}</td><td class=\"n\">{:.2}, {:.2}, {:.2}</td></tr>\n",
            escape(&l.name),
            p.x,
            p.y,
            p.z
        );
    }
    h + "</table></details>\n"
}

const STYLE: &str = "body{font-family:Helvetica,Arial,sans-serif;max-width:60em;margin:2em auto;color:#222}\
h1{font-size:1.6em;margin-bottom:0.2em}h2{font-size:1.2em;margin-top:1.6em;border-bottom:1px solid #999}\
table{border-collapse:collapse;margin:0.6em 0}th,td{border:1px solid #bbb;padding:0.25em 0.7em}\
th{background:#eee;text-align:left}td.n{text-align:right;font-variant-numeric:tabular-nums}\
img{max-width:100%;margin:0.5em 0}.note{color:#555;font-size:0.9em}";

/// The report of `prepared`'s grids: the scene, its luminaires with their flux, a table of
/// each grid's statistics and each grid's picture (`pictures`: PNG bytes, one per grid).
pub fn grid_report(prepared: &Prepared, grids: &[GridIlluminance], pictures: &[&[u8]]) -> String {
    let scene = &prepared.scene;
    let lighting = &scene.lighting;
    let unit = lighting.unit().as_str();
    let mut h = String::new();
    h += "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n";
    h += &format!(
        "<title>{} — lighting report</title>\n<style>{STYLE}</style></head><body>\n",
        escape(&scene.name)
    );
    h += &format!(
        "<h1>{}</h1>\n<p>Lighting report: illuminance on the calculation grids.</p>\n",
        escape(&scene.name)
    );

    h += "<h2>Luminaires</h2>\n";
    if lighting.luminaires.is_empty() {
        h += "<p>No photometric luminaires: the light comes from the scene's emitting surfaces.</p>\n";
    } else {
        h += &luminaire_tables(prepared);
    }

    h += "<h2>Results</h2>\n<table><tr><th>grid</th><th>points</th><th>E<sub>m</sub> (lx)</th>\
<th>E<sub>min</sub> (lx)</th><th>E<sub>max</sub> (lx)</th><th>U<sub>0</sub> = E<sub>min</sub>/E<sub>m</sub></th>\
<th>E<sub>min</sub>/E<sub>max</sub></th></tr>\n";
    for g in grids {
        let g2 = if g.max > 0.0 { g.min / g.max } else { 0.0 };
        h += &format!(
            "<tr><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td>\
<td class=\"n\">{}</td><td class=\"n\">{:.2}</td><td class=\"n\">{:.2}</td></tr>\n",
            escape(&g.name),
            g.lux.len(),
            format_lux(g.avg),
            format_lux(g.min),
            format_lux(g.max),
            g.uniformity,
            g2
        );
    }
    h += "</table>\n";
    for (g, png) in grids.iter().zip(pictures) {
        h += &format!(
            "<h2>{}</h2>\n<img alt=\"illuminance on {}\" src=\"data:image/png;base64,{}\">\n",
            escape(&g.name),
            escape(&g.name),
            base64(png)
        );
    }
    h += &format!(
        "<p class=\"note\">Illuminance at the grid points (cell centres, EN 12464-1): the luminaires' \
direct light by shadow rays, the light reflected by the room's surfaces gathered from a radiosity \
solution of {} elements. Lengths in {unit}.</p>\n</body></html>\n",
        prepared.problem.mesh().elements.len()
    );
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc_4648() {
        for (raw, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(raw.as_bytes()), coded);
        }
        assert_eq!(base64(&[0xff, 0xfe, 0xfd]), "//79");
    }

    #[test]
    fn a_row_of_one_fitting_is_one_type() {
        assert_eq!(luminaire_type("downlight #12"), "downlight");
        assert_eq!(luminaire_type("panel"), "panel");
        assert_eq!(luminaire_type("spot #A"), "spot #A");
    }

    #[test]
    fn names_are_escaped() {
        assert_eq!(escape("<a & \"b\">"), "&lt;a &amp; &quot;b&quot;&gt;");
    }
}
