//! False-colour pictures of calculation grids, as lighting-design programs print them: the
//! grid seen from the side its normal points to, coloured by illuminance in the bands of a
//! [`LuxScale`], iso-lux lines at the scale's levels labelled with their value, the
//! calculation points marked, the luminaires above or beside the grid drawn where they
//! project onto it (a ring with a cross), the grid's size along its edges, a legend in lux, and the
//! statistics EN 12464-1 asks for (Em, Emin, Emax, U0 = Emin / Em) printed under it.
//!
//! The field between the points (which sit at the cells' centres) is interpolated
//! bilinearly, and held at the outer points' values out to the grid's edges.

use radiosity_core::Grid;
use radiosity_core::glam::DVec3;

use crate::canvas::{BLACK, Canvas, WHITE};
use crate::font::{text_height, text_width};
use crate::lux_scale::{LuxScale, format_lux};
use crate::{GridIlluminance, SrgbImage};

/// The longer side of a grid's plot, pixels.
const PLOT_SIDE: f64 = 640.0;
/// The shorter side of a plot is at least this many pixels.
const MIN_SIDE: f64 = 160.0;
/// Margin around everything, pixels.
const MARGIN: u32 = 16;
/// Font scale of the title and the statistics.
const BIG: u32 = 2;

/// The illuminance at continuous point (`s`, `t`) ∈ [0, 1]² of a grid of `nu` × `nv` cell
/// centres (row by row along u), bilinear between the centres, held flat beyond the outer
/// ones.
fn field(lux: &[f64], nu: usize, nv: usize, s: f64, t: f64) -> f64 {
    let a = (s * nu as f64 - 0.5).clamp(0.0, (nu - 1) as f64);
    let b = (t * nv as f64 - 0.5).clamp(0.0, (nv - 1) as f64);
    let (i, j) =
        ((a.floor() as usize).min(nu.saturating_sub(2)), (b.floor() as usize).min(nv.saturating_sub(2)));
    let (fa, fb) = (a - i as f64, b - j as f64);
    let at = |i: usize, j: usize| lux[j.min(nv - 1) * nu + i.min(nu - 1)];
    let top = at(i, j) * (1.0 - fa) + at(i + 1, j) * fa;
    let bottom = at(i, j + 1) * (1.0 - fa) + at(i + 1, j + 1) * fa;
    top * (1.0 - fb) + bottom * fb
}

/// How a grid's parameters (s along u, t along v, both 0..1) lie on its plot: the plot is
/// the grid seen from the side its normal points to; a plan (a grid facing up or down) has u
/// to the right, a vertical grid the world's up (+y) up the page.
#[derive(Clone, Copy, Debug, PartialEq)]
struct View {
    /// u runs down the page and v across.
    transpose: bool,
    /// The parameter across runs right to left.
    flip_across: bool,
    /// The parameter down runs bottom to top.
    flip_down: bool,
}

impl View {
    fn of(grid: &Grid) -> Self {
        let (u, v, n) = (grid.u, grid.v, grid.normal);
        let plan = n.normalize().y.abs() >= 0.5;
        // The edge down the page, and the one across.
        let transpose = !plan && u.y.abs() > v.y.abs();
        let (down, across) = if transpose { (u, v) } else { (v, u) };
        let flip_down = if plan { u.cross(v).dot(n) > 0.0 } else { down.y > 0.0 };
        let down = if flip_down { -down } else { down };
        // Right × down points away from the viewer, who looks along −n.
        let flip_across = across.cross(down).dot(n) > 0.0;
        Self { transpose, flip_across, flip_down }
    }

    /// (s, t) at plot fractions `a` (left to right) and `b` (top to bottom).
    fn st(self, a: f64, b: f64) -> (f64, f64) {
        let a = if self.flip_across { 1.0 - a } else { a };
        let b = if self.flip_down { 1.0 - b } else { b };
        if self.transpose { (b, a) } else { (a, b) }
    }

    /// Plot fractions (a, b) of (s, t): the inverse of [`View::st`].
    fn ab(self, s: f64, t: f64) -> (f64, f64) {
        let (a, b) = if self.transpose { (t, s) } else { (s, t) };
        (if self.flip_across { 1.0 - a } else { a }, if self.flip_down { 1.0 - b } else { b })
    }

    /// Lengths of the edges across and down the page.
    fn sides(self, grid: &Grid) -> (f64, f64) {
        let (lu, lv) = (grid.u.length(), grid.v.length());
        if self.transpose { (lv, lu) } else { (lu, lv) }
    }
}

/// A rectangle taken by a label: x, y, w, h.
type Rect = (i64, i64, i64, i64);

fn overlaps(a: Rect, b: Rect) -> bool {
    a.0 < b.0 + b.2 && b.0 < a.0 + a.2 && a.1 < b.1 + b.3 && b.1 < a.1 + a.3
}

/// Draws a luminaire's mark centred on (`x`, `y`): a ring with a cross, black on a white rim.
fn luminaire_mark(c: &mut Canvas, x: i64, y: i64) {
    for (r, colour) in [(7.5, WHITE), (6.0, BLACK)] {
        for k in 0..96 {
            let a = f64::from(k) / 96.0 * std::f64::consts::TAU;
            for dr in [0.0, -0.8] {
                let (px, py) = (x as f64 + (r + dr) * a.cos(), y as f64 + (r + dr) * a.sin());
                c.set(px.round() as i64, py.round() as i64, colour);
            }
        }
    }
    for d in -4..=4 {
        c.set(x + d, y + d, BLACK);
        c.set(x + d, y - d, BLACK);
    }
}

/// The false-colour picture of one grid's result (`unit`: the scene's length unit, for the
/// edge lengths). `scale` gives the levels; `None` chooses them from the grid's own range.
/// On a plan (a grid facing up or down), `luminaires` (positions in the grid's frame) are
/// marked where they project onto it along its normal.
///
/// # Panics
/// When `result` does not hold `grid`'s points (a bug in the caller).
pub fn grid_picture(
    grid: &Grid,
    result: &GridIlluminance,
    unit: &str,
    scale: Option<&LuxScale>,
    luminaires: &[DVec3],
) -> SrgbImage {
    let [nu, nv] = grid.divisions.map(|d| d.max(1) as usize);
    assert_eq!(result.lux.len(), nu * nv, "a grid result of another grid");
    let own;
    let scale = match scale {
        Some(s) => s,
        None => {
            own = LuxScale::for_range(result.min, result.max);
            &own
        }
    };
    let (lu, lv) = (grid.u.length(), grid.v.length());
    let view = View::of(grid);
    let (l_across, l_down) = view.sides(grid);
    let ppu = PLOT_SIDE / lu.max(lv).max(1e-12);
    let pw = (l_across * ppu).max(MIN_SIDE).round() as u32;
    let ph = (l_down * ppu).max(MIN_SIDE).round() as u32;

    let small = 1;
    let title_h = text_height(BIG) + 10;
    let axis_w = text_width("00.00", small) + 8;
    let plot_x = i64::from(MARGIN + axis_w);
    let plot_y = i64::from(MARGIN + title_h);
    let legend_w = 14 + 6 + text_width("100000", BIG) + 8;
    let stats_h = 2 * (text_height(BIG) + 8) + text_height(small) + 16;
    let width = MARGIN + axis_w + pw + 24 + legend_w + MARGIN;
    let height = MARGIN + title_h + ph + text_height(small) + 10 + stats_h + MARGIN;
    let mut c = Canvas::new(width, height, WHITE);
    c.text(i64::from(MARGIN), i64::from(MARGIN), &format!("{}: illuminance (lx)", result.name), BIG, BLACK);

    // The field and its bands, pixel by pixel.
    let (w, h) = (pw as usize, ph as usize);
    let mut bands = vec![0usize; w * h];
    for py in 0..h {
        for px in 0..w {
            let (s, t) = view.st((px as f64 + 0.5) / w as f64, (py as f64 + 0.5) / h as f64);
            let e = field(&result.lux, nu, nv, s, t);
            let b = scale.band(e);
            bands[py * w + px] = b;
            c.set(plot_x + px as i64, plot_y + py as i64, scale.band_colour(b));
        }
    }
    // Iso-lux lines where the band changes; each level's pixels kept for its label.
    let line = [40, 40, 40];
    let mut on_level: Vec<Vec<(i64, i64)>> = vec![Vec::new(); scale.levels.len()];
    for py in 0..h {
        for px in 0..w {
            let b = bands[py * w + px];
            let right = (px + 1 < w).then(|| bands[py * w + px + 1]);
            let below = (py + 1 < h).then(|| bands[(py + 1) * w + px]);
            for other in [right, below].into_iter().flatten() {
                if other != b {
                    c.set(plot_x + px as i64, plot_y + py as i64, line);
                    on_level[b.min(other)].push((px as i64, py as i64));
                }
            }
        }
    }
    // The calculation points.
    for j in 0..nv {
        for i in 0..nu {
            let (a, b) = view.ab((i as f64 + 0.5) / nu as f64, (j as f64 + 0.5) / nv as f64);
            let (px, py) = ((a * w as f64) as i64, (b * h as f64) as i64);
            c.fill_rect(plot_x + px - 1, plot_y + py - 1, 2, 2, [70, 70, 70]);
        }
    }
    // The luminaires over the grid: (s, t) from the plane's own axes, u and v need not be
    // perpendicular.
    let mut taken: Vec<Rect> = Vec::new();
    let (uu, uv, vv) = (grid.u.dot(grid.u), grid.u.dot(grid.v), grid.v.dot(grid.v));
    let det = uu * vv - uv * uv;
    let plan = grid.normal.normalize().y.abs() >= 0.5;
    for &p in luminaires {
        if !plan || det.abs() <= 1e-18 * uu * vv {
            break;
        }
        let d = p - grid.origin;
        let (du, dv) = (d.dot(grid.u), d.dot(grid.v));
        let (s, t) = ((du * vv - dv * uv) / det, (dv * uu - du * uv) / det);
        if !(0.0..=1.0).contains(&s) || !(0.0..=1.0).contains(&t) {
            continue;
        }
        let (a, b) = view.ab(s, t);
        let (x, y) = ((a * w as f64) as i64, (b * h as f64) as i64);
        luminaire_mark(&mut c, plot_x + x, plot_y + y);
        taken.push((x - 10, y - 10, 20, 20));
    }
    // Each line's value on a white tag, where it overlaps no other tag.
    for (level, pixels) in on_level.iter().enumerate() {
        let label = format_lux(scale.levels[level]);
        let (tw, th) = (i64::from(text_width(&label, small)) + 4, i64::from(text_height(small)) + 4);
        let n = pixels.len();
        let order = (0..n).map(|k| (n / 2 + k * 7919) % n.max(1));
        for k in order.take(200) {
            let (px, py) = pixels[k];
            let r = (px - tw / 2, py - th / 2, tw, th);
            if r.0 < 0 || r.1 < 0 || r.0 + tw > w as i64 || r.1 + th > h as i64 {
                continue;
            }
            if taken.iter().any(|t| overlaps(*t, r)) {
                continue;
            }
            taken.push((r.0 - 6, r.1 - 6, tw + 12, th + 12));
            c.fill_rect(plot_x + r.0, plot_y + r.1, tw as u32, th as u32, WHITE);
            c.text(plot_x + r.0 + 2, plot_y + r.1 + 2, &label, small, BLACK);
            break;
        }
    }
    c.outline_rect(plot_x - 1, plot_y - 1, pw + 2, ph + 2, BLACK);

    // Edge lengths from the plot's bottom-left corner, in the scene's unit.
    let fmt = |x: f64| {
        let s = format!("{x:.2}");
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    };
    let below = plot_y + i64::from(ph) + 5;
    c.text(plot_x, below, "0", small, BLACK);
    let across_label = format!("{} {unit}", fmt(l_across));
    let right = plot_x + i64::from(pw) - i64::from(text_width(&across_label, small));
    c.text(right, below, &across_label, small, BLACK);
    let down_label = format!("{} {unit}", fmt(l_down));
    let (v_top, v_bottom) = (down_label.as_str(), "0");
    let right_align = |c: &mut Canvas, y: i64, s: &str| {
        c.text(plot_x - 6 - i64::from(text_width(s, small)), y, s, small, BLACK);
    };
    right_align(&mut c, plot_y, v_top);
    right_align(&mut c, plot_y + i64::from(ph) - i64::from(text_height(small)), v_bottom);

    scale.draw_legend(&mut c, plot_x + i64::from(pw) + 24, plot_y, ph, BIG);

    // The statistics.
    let mut y = below + i64::from(text_height(small)) + 12;
    let g2 = if result.max > 0.0 { result.min / result.max } else { 0.0 };
    let line1 = format!(
        "Em {} lx   Emin {} lx   Emax {} lx",
        format_lux(result.avg),
        format_lux(result.min),
        format_lux(result.max)
    );
    let line2 = format!("U0 = Emin/Em {:.2}   Emin/Emax {:.2}", result.uniformity, g2);
    for text in [line1, line2] {
        c.text(i64::from(MARGIN), y, &text, BIG, BLACK);
        y += i64::from(text_height(BIG)) + 8;
    }
    let size = format!(
        "{} x {} points, cells {} x {} {unit}, at cell centres",
        nu,
        nv,
        fmt(lu / nu as f64),
        fmt(lv / nv as f64)
    );
    c.text(i64::from(MARGIN), y + 4, &size, small, [60, 60, 60]);
    c.into_image()
}

/// Pictures stacked top to bottom on one sheet, left-aligned, a white gap between them.
pub fn picture_sheet(pictures: &[SrgbImage]) -> SrgbImage {
    let width = pictures.iter().map(|p| p.width).max().unwrap_or(1);
    let height = pictures.iter().map(|p| p.height).sum::<u32>().max(1);
    let mut c = Canvas::new(width, height, WHITE);
    let mut y = 0;
    for p in pictures {
        c.blit(p, 0, y);
        y += i64::from(p.height);
    }
    c.into_image()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid_statistics;

    fn grid(v: DVec3) -> (Grid, GridIlluminance) {
        let g = Grid {
            name: "desk".into(),
            origin: DVec3::ZERO,
            u: DVec3::new(3.0, 0.0, 0.0),
            v,
            divisions: [3, 2],
            normal: DVec3::Y,
            height: 0.0,
        };
        let lux = vec![100.0, 200.0, 300.0, 400.0, 500.0, 600.0];
        let (min, avg, max, uniformity) = grid_statistics(&lux);
        let points = g.points();
        let r = GridIlluminance {
            name: "desk".into(),
            points,
            direct_lux: lux.clone(),
            lux,
            min,
            avg,
            max,
            uniformity,
        };
        (g, r)
    }

    /// The plot's top-left pixel, a few pixels in from the frame.
    fn top_left(image: &SrgbImage) -> [u8; 3] {
        let x = MARGIN + text_width("00.00", 1) + 8 + 3;
        let y = MARGIN + text_height(BIG) + 10 + 3;
        image.pixels[(y * image.width + x) as usize]
    }

    #[test]
    fn a_work_plane_is_seen_from_above_and_a_flipped_one_too() {
        let scale = LuxScale::for_range(100.0, 600.0);
        // u = +x, v = +z, seen from +y: v runs down the page, the first point top left.
        let (g, r) = grid(DVec3::new(0.0, 0.0, 2.0));
        let image = grid_picture(&g, &r, "m", Some(&scale), &[]);
        assert_eq!(top_left(&image), scale.colour(100.0));
        // v = −z: seen from +y the second row of points is at the top.
        let (g, r) = grid(DVec3::new(0.0, 0.0, -2.0));
        let image = grid_picture(&g, &r, "m", Some(&scale), &[]);
        assert_eq!(top_left(&image), scale.colour(400.0));
        // The plot keeps the grid's proportions: 640 px for 3 m, about 427 px for 2 m.
        assert!(image.height > 427 && image.width > 640);
        for band in 0..=scale.levels.len() {
            assert!(image.pixels.contains(&scale.band_colour(band)), "band {band}");
        }
    }

    #[test]
    fn luminaires_over_the_grid_are_marked_and_others_not() {
        let (g, r) = grid(DVec3::new(0.0, 0.0, 2.0));
        let plain = grid_picture(&g, &r, "m", None, &[]);
        let away = grid_picture(&g, &r, "m", None, &[DVec3::new(10.0, 2.8, 1.0)]);
        assert_eq!(plain, away, "a luminaire beside the grid is not drawn");
        let over = grid_picture(&g, &r, "m", None, &[DVec3::new(1.5, 2.8, 1.0)]);
        let changed = plain.pixels.iter().zip(&over.pixels).filter(|(a, b)| a != b).count();
        assert!((20..400).contains(&changed), "{changed} pixels of a mark");
    }

    #[test]
    fn a_wall_stands_upright_seen_from_the_room() {
        let wall = |u: DVec3, v: DVec3, normal: DVec3| Grid {
            name: "wall".into(),
            origin: DVec3::ZERO,
            u,
            v,
            divisions: [2, 2],
            normal,
            height: 0.0,
        };
        let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
        // A north wall at z = 4 seen from the room (normal −z), its corners in either order.
        for g in [wall(2.8 * y, 6.0 * x, -z), wall(6.0 * x, 2.8 * y, -z), wall(-2.8 * y, -6.0 * x, -z)] {
            let view = View::of(&g);
            let at = |a: f64, b: f64| {
                let (s, t) = view.st(a, b);
                g.origin + g.u * s + g.v * t
            };
            // Up the page is up in the room; seen from −z, +x runs right to left.
            assert!(at(0.5, 0.0).y > at(0.5, 1.0).y, "{g:?}");
            assert!(at(0.0, 0.5).x > at(1.0, 0.5).x, "{g:?}");
            assert_eq!(view.sides(&g), (6.0, 2.8));
            for (s, t) in [(0.1, 0.7), (0.9, 0.2)] {
                let (a, b) = view.ab(s, t);
                let back = view.st(a, b);
                assert!((back.0 - s).abs() < 1e-12 && (back.1 - t).abs() < 1e-12);
            }
        }
    }
}
