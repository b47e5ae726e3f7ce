//! The false-colour scale of illuminance pictures: level boundaries in lux chosen from the
//! values shown, one colour per band between them (blue for the least light, red for the
//! most, as lighting-design programs draw them), and the legend that names the levels.
//!
//! Levels: where the values span less than a factor of 10, equal steps of 1, 2, 2.5 or 5 ×
//! 10ᵏ lx, about six inside the range (an office's work plane of 515 to 650 lx: every 25 lx);
//! over a wider span, the series of illuminances EN 12464-1 speaks in (1, 1.5, 2, 3, 5, 7.5
//! × 10ᵏ lx), so a room with a bright window wall still reads in steps a designer knows.
//! Every band's colour is an equal step along the ramp, whatever the levels' spacing.

use crate::canvas::{BLACK, Canvas};
use crate::font::{text_height, text_width};

/// Colours along the ramp, from the lowest band to the highest.
const RAMP: [[f64; 3]; 7] = [
    [40.0, 50.0, 190.0],
    [20.0, 130.0, 240.0],
    [0.0, 200.0, 200.0],
    [90.0, 205.0, 70.0],
    [245.0, 230.0, 50.0],
    [250.0, 150.0, 30.0],
    [215.0, 35.0, 35.0],
];

/// Level boundaries of a false-colour scale, lx, ascending.
#[derive(Clone, Debug, PartialEq)]
pub struct LuxScale {
    /// Boundaries between the bands; `levels.len() + 1` bands.
    pub levels: Vec<f64>,
}

/// The number of the EN 12464-1 series (1, 1.5, 2, 3, 5, 7.5 × 10ᵏ) at position `i`.
fn series(i: i32) -> f64 {
    const MANTISSA: [f64; 6] = [1.0, 1.5, 2.0, 3.0, 5.0, 7.5];
    MANTISSA[i.rem_euclid(6) as usize] * 10f64.powi(i.div_euclid(6))
}

/// The step from 1, 2, 2.5, 5 × 10ᵏ nearest above `rough`.
fn nice_step(rough: f64) -> f64 {
    let k = rough.log10().floor();
    let base = 10f64.powf(k);
    [1.0, 2.0, 2.5, 5.0, 10.0]
        .iter()
        .map(|m| m * base)
        .find(|s| *s >= rough * (1.0 - 1e-9))
        .unwrap_or(10.0 * base)
}

impl LuxScale {
    /// A scale for values from `lo` to `hi` lx (any order; non-finite values are ignored).
    pub fn for_range(lo: f64, hi: f64) -> Self {
        let (lo, hi) = match (lo.is_finite(), hi.is_finite()) {
            (true, true) => (lo.min(hi).max(0.0), hi.max(lo).max(0.0)),
            _ => (0.0, 0.0),
        };
        if lo > 0.0 && hi / lo > 10.0 {
            let mut levels: Vec<f64> = (-60..120).map(series).filter(|v| *v > lo && *v < hi).collect();
            while levels.len() > 10 {
                levels = levels.into_iter().step_by(2).collect();
            }
            return Self { levels };
        }
        // A flat field still gets a scale around its value.
        let span = if hi - lo > 1e-9 * hi.max(1e-9) { hi - lo } else { (hi * 0.2).max(1e-3) };
        let (lo, hi) =
            if hi - lo > 1e-9 * hi.max(1e-9) { (lo, hi) } else { (hi - span / 2.0, hi + span / 2.0) };
        let mut step = nice_step(span / 6.0);
        loop {
            let first = (lo / step).floor() as i64 + 1;
            let levels: Vec<f64> = (first..)
                .map(|k| k as f64 * step)
                .take_while(|v| *v < hi - 1e-9 * step)
                .filter(|v| *v > 0.0)
                .collect();
            if levels.len() >= 3 || step < 1e-6 {
                return Self { levels };
            }
            step = nice_step(step / 2.0 * (1.0 - 1e-6));
        }
    }

    /// The band of `lux`: 0 below the first level, `levels.len()` at or above the last.
    pub fn band(&self, lux: f64) -> usize {
        self.levels.partition_point(|l| *l <= lux)
    }

    /// The colour of band `band`.
    pub fn band_colour(&self, band: usize) -> [u8; 3] {
        let n = self.levels.len().max(1) as f64;
        let t = (band as f64 / n).clamp(0.0, 1.0) * (RAMP.len() - 1) as f64;
        let i = (t.floor() as usize).min(RAMP.len() - 2);
        let f = t - i as f64;
        let mix = |c: usize| (RAMP[i][c] * (1.0 - f) + RAMP[i + 1][c] * f).round() as u8;
        [mix(0), mix(1), mix(2)]
    }

    /// The colour of `lux`.
    pub fn colour(&self, lux: f64) -> [u8; 3] {
        self.band_colour(self.band(lux))
    }

    /// Draws the legend with its top-left corner at (`x`, `y`), `height` pixels tall: the
    /// bands stacked from the lowest (bottom) to the highest, each level's value beside the
    /// boundary it names, and "lx" above. Returns the legend's width.
    pub fn draw_legend(&self, canvas: &mut Canvas, x: i64, y: i64, height: u32, scale: u32) -> u32 {
        let bands = self.levels.len() + 1;
        let bar_w = 14 * scale;
        let title_h = text_height(scale) + 4 * scale;
        canvas.text(x, y, "lx", scale, BLACK);
        let top = y + i64::from(title_h);
        let bar_h = i64::from(height.saturating_sub(title_h)).max(bands as i64);
        let edge = |b: usize| top + bar_h - (bar_h * b as i64) / bands as i64;
        for b in 0..bands {
            let (y1, y0) = (edge(b), edge(b + 1));
            canvas.fill_rect(x, y0, bar_w, (y1 - y0) as u32, self.band_colour(b));
        }
        canvas.outline_rect(x, top, bar_w, bar_h as u32, BLACK);
        let mut widest = 0;
        let gap = i64::from(text_height(scale)) + 2;
        let mut last_label = i64::MAX;
        for (i, level) in self.levels.iter().enumerate() {
            let yb = edge(i + 1);
            canvas.fill_rect(x + i64::from(bar_w), yb, 4 * scale, 1, BLACK);
            // Labels that would overlap the one below are left out.
            let ty = yb - i64::from(text_height(scale)) / 2;
            if last_label - ty < gap {
                continue;
            }
            last_label = ty;
            let label = format_lux(*level);
            canvas.text(x + i64::from(bar_w + 6 * scale), ty, &label, scale, BLACK);
            widest = widest.max(text_width(&label, scale));
        }
        bar_w + 6 * scale + widest.max(text_width("10000", scale))
    }
}

/// A lux value as a legend writes it: whole numbers from 10 up, otherwise up to two
/// significant decimals, no trailing zeros.
pub fn format_lux(v: f64) -> String {
    let s = if v.abs() >= 10.0 {
        format!("{v:.0}")
    } else if v.abs() >= 1.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    };
    if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_owned() } else { s }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_narrow_range_takes_equal_nice_steps_inside_it() {
        let s = LuxScale::for_range(515.0, 650.0);
        assert_eq!(s.levels, vec![525.0, 550.0, 575.0, 600.0, 625.0]);
        assert_eq!(s.band(500.0), 0);
        assert_eq!(s.band(525.0), 1);
        assert_eq!(s.band(640.0), 5);
        // Lowest band blue, highest red.
        let (low, high) = (s.band_colour(0), s.band_colour(5));
        assert!(low[2] > low[0] && high[0] > high[2], "{low:?} {high:?}");
    }

    #[test]
    fn a_wide_range_takes_the_standard_series() {
        let s = LuxScale::for_range(40.0, 2500.0);
        assert!(
            s.levels
                .iter()
                .all(|l| [50.0, 75.0, 100.0, 150.0, 200.0, 300.0, 500.0, 750.0, 1000.0, 1500.0, 2000.0]
                    .contains(l)),
            "{:?}",
            s.levels
        );
        assert!(s.levels.len() <= 10 && s.levels.len() >= 5);
        assert!(s.levels.windows(2).all(|w| w[0] < w[1]));
    }

    #[test]
    fn flat_empty_and_broken_ranges_still_give_levels() {
        for (lo, hi) in [(300.0, 300.0), (0.0, 0.0), (f64::NAN, 5.0), (0.0, 1e-4)] {
            let s = LuxScale::for_range(lo, hi);
            assert!(!s.levels.is_empty(), "{lo} {hi}: {:?}", s.levels);
            assert!(s.levels.iter().all(|l| l.is_finite() && *l > 0.0));
        }
    }

    #[test]
    fn lux_values_read_as_a_designer_writes_them() {
        assert_eq!(format_lux(525.0), "525");
        assert_eq!(format_lux(7.5), "7.5");
        assert_eq!(format_lux(2.0), "2");
        assert_eq!(format_lux(0.25), "0.25");
        assert_eq!(format_lux(1500.4), "1500");
    }
}
