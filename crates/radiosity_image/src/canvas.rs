//! An 8-bit RGB drawing surface for annotated pictures (false colour, legends, labels):
//! filled rectangles, lines, and text in the built-in bitmap font ([`crate::font`]).

use crate::SrgbImage;
use crate::font::{ADVANCE, DESCENT, GLYPH_WIDTH, descends, glyph};

/// White.
pub const WHITE: [u8; 3] = [255, 255, 255];
/// Black.
pub const BLACK: [u8; 3] = [0, 0, 0];

/// A picture being drawn, top row first; drawing outside it is clipped.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Canvas {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Pixels, top row first.
    pub pixels: Vec<[u8; 3]>,
}

impl Canvas {
    /// A canvas of `width` × `height` filled with `background`.
    pub fn new(width: u32, height: u32, background: [u8; 3]) -> Self {
        Self { width, height, pixels: vec![background; width as usize * height as usize] }
    }

    /// The colour at (`x`, `y`), `None` outside.
    pub fn get(&self, x: i64, y: i64) -> Option<[u8; 3]> {
        self.index(x, y).map(|i| self.pixels[i])
    }

    fn index(&self, x: i64, y: i64) -> Option<usize> {
        (x >= 0 && y >= 0 && x < i64::from(self.width) && y < i64::from(self.height))
            .then(|| y as usize * self.width as usize + x as usize)
    }

    /// Sets one pixel (nothing outside the canvas).
    pub fn set(&mut self, x: i64, y: i64, colour: [u8; 3]) {
        if let Some(i) = self.index(x, y) {
            self.pixels[i] = colour;
        }
    }

    /// Fills the rectangle of `w` × `h` pixels whose top-left corner is (`x`, `y`).
    pub fn fill_rect(&mut self, x: i64, y: i64, w: u32, h: u32, colour: [u8; 3]) {
        for yy in y..y + i64::from(h) {
            for xx in x..x + i64::from(w) {
                self.set(xx, yy, colour);
            }
        }
    }

    /// Draws the one-pixel outline of the rectangle of `w` × `h` pixels at (`x`, `y`).
    pub fn outline_rect(&mut self, x: i64, y: i64, w: u32, h: u32, colour: [u8; 3]) {
        let (w, h) = (i64::from(w), i64::from(h));
        for xx in x..x + w {
            self.set(xx, y, colour);
            self.set(xx, y + h - 1, colour);
        }
        for yy in y..y + h {
            self.set(x, yy, colour);
            self.set(x + w - 1, yy, colour);
        }
    }

    /// Draws `text` with its top-left corner at (`x`, `y`), each font pixel `scale` × `scale`.
    pub fn text(&mut self, x: i64, y: i64, text: &str, scale: u32, colour: [u8; 3]) {
        let s = i64::from(scale.max(1));
        for (k, c) in text.chars().enumerate() {
            let left = x + k as i64 * i64::from(ADVANCE) * s;
            let top = if descends(c) { y + i64::from(DESCENT) * s } else { y };
            for (row, bits) in glyph(c).iter().enumerate() {
                for col in 0..GLYPH_WIDTH {
                    if bits >> (GLYPH_WIDTH - 1 - col) & 1 == 1 {
                        let (px, py) = (left + i64::from(col) * s, top + row as i64 * s);
                        self.fill_rect(px, py, s as u32, s as u32, colour);
                    }
                }
            }
        }
    }

    /// Copies `other` with its top-left corner at (`x`, `y`).
    pub fn blit(&mut self, other: &SrgbImage, x: i64, y: i64) {
        for yy in 0..other.height {
            for xx in 0..other.width {
                let c = other.pixels[(yy * other.width + xx) as usize];
                self.set(x + i64::from(xx), y + i64::from(yy), c);
            }
        }
    }

    /// The finished picture.
    pub fn into_image(self) -> SrgbImage {
        SrgbImage { width: self.width, height: self.height, pixels: self.pixels }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_lands_where_asked_and_is_clipped_at_the_edges() {
        let mut c = Canvas::new(20, 10, WHITE);
        c.text(1, 1, "1", 1, BLACK);
        // '1': the top row's middle pixel, and the bottom row of three.
        assert_eq!(c.get(3, 1), Some(BLACK));
        assert_eq!(c.get(1, 1), Some(WHITE));
        assert_eq!((2..5).map(|x| c.get(x, 7)).collect::<Vec<_>>(), vec![Some(BLACK); 3]);
        // Half outside: no panic.
        c.text(17, 8, "88", 2, BLACK);
        c.fill_rect(-5, -5, 8, 8, BLACK);
        assert_eq!(c.get(2, 2), Some(BLACK));
        assert_eq!(c.get(-1, 0), None);
        let img = c.into_image();
        assert_eq!(img.pixels.len(), 200);
    }
}
