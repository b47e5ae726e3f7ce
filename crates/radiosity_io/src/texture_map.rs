//! Where a texture lies on a model's faces: the texture-coordinate transforms of MTL's
//! `map_Kd` options (`-o`, `-s`, `-clamp`) and of glTF's `KHR_texture_transform`, applied to
//! the coordinates once at load, so the renderer samples the image with them as they are.
//!
//! MTL's options follow the Wavefront MTL specification's list; `-o` and `-s` are read as
//! three.js's `MTLLoader` reads them (u′ = u·s + o, the texture matrix's repeat and offset),
//! the common reading in the tools that write them.

use radiosity_core::Wrap;

/// An affine map of texture coordinates: scale, then rotate, then offset (the order of
/// `KHR_texture_transform`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct UvTransform {
    /// Added last.
    pub(crate) offset: [f64; 2],
    /// Multiplies u and v first.
    pub(crate) scale: [f64; 2],
    /// Radians, counter-clockwise in glTF's (u right, v down) image space.
    pub(crate) rotation: f64,
}

impl Default for UvTransform {
    fn default() -> Self {
        Self { offset: [0.0; 2], scale: [1.0; 2], rotation: 0.0 }
    }
}

impl UvTransform {
    /// `uv` mapped: `KHR_texture_transform`'s T · R · S, R = [[cos, sin], [−sin, cos]].
    pub(crate) fn apply(&self, uv: [f64; 2]) -> [f64; 2] {
        let (u, v) = (uv[0] * self.scale[0], uv[1] * self.scale[1]);
        let (sin, cos) = self.rotation.sin_cos();
        [cos * u + sin * v + self.offset[0], -sin * u + cos * v + self.offset[1]]
    }
}

/// A `map_Kd` line's value taken apart: the file and the options that place it.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct MapKd {
    /// The image file, relative to the MTL's folder (the rest of the line after the options:
    /// names may hold spaces).
    pub(crate) file: String,
    /// `-s u v` then `-o u v`, in OBJ's (v up) texture space.
    pub(crate) transform: UvTransform,
    /// `-clamp on`: the edge texels stretch outwards instead of the image repeating.
    pub(crate) wrap: Wrap,
}

/// Reads the value of a `map_Kd` line: options first (each with its own count of arguments;
/// `-o`, `-s` and `-t` take one to three numbers), then the file name. Options that do not
/// move the texture on the surface (`-bm`, `-mm`, `-imfchan`, …) are skipped.
pub(crate) fn parse_map_kd(value: &str) -> MapKd {
    let words: Vec<&str> = value.split_whitespace().collect();
    let mut transform = UvTransform::default();
    let mut wrap = Wrap::Repeat;
    let mut at = 0;
    // Up to `most` numbers after an option.
    let numbers = |at: usize, most: usize| -> Vec<f64> {
        words[at..].iter().take(most).map_while(|w| w.parse::<f64>().ok()).collect()
    };
    while at < words.len() && words[at].starts_with('-') {
        let option = words[at];
        at += 1;
        match option {
            "-o" | "-s" | "-t" => {
                let n = numbers(at, 3);
                at += n.len();
                let uv = [n.first().copied(), n.get(1).copied()];
                match option {
                    "-o" => transform.offset = [uv[0].unwrap_or(0.0), uv[1].unwrap_or(0.0)],
                    "-s" => transform.scale = [uv[0].unwrap_or(1.0), uv[1].unwrap_or(1.0)],
                    _ => {}
                }
            }
            "-clamp" => {
                if words.get(at) == Some(&"on") {
                    wrap = Wrap::ClampToEdge;
                }
                at += 1;
            }
            "-mm" => at += numbers(at, 2).len(),
            "-blendu" | "-blendv" | "-cc" | "-bm" | "-boost" | "-texres" | "-imfchan" | "-type" => at += 1,
            // An unknown option: taken as the start of a file name.
            _ => {
                at -= 1;
                break;
            }
        }
    }
    MapKd { file: words[at.min(words.len())..].join(" "), transform, wrap }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn map_kd_offset_and_scale_are_read_before_the_file() {
        let m = parse_map_kd("-o 0.25 0.5 0 -s 2 3 1 -clamp on -bm 1 checker board.png");
        assert_eq!(m.file, "checker board.png");
        assert_eq!(m.transform.offset, [0.25, 0.5]);
        assert_eq!(m.transform.scale, [2.0, 3.0]);
        assert_eq!(m.wrap, Wrap::ClampToEdge);
        // u′ = u·s + o.
        assert_eq!(m.transform.apply([0.5, 0.5]), [1.25, 2.0]);
        let plain = parse_map_kd("wood.jpg");
        assert_eq!(
            (plain.file.as_str(), plain.transform, plain.wrap),
            ("wood.jpg", UvTransform::default(), Wrap::Repeat)
        );
        // One number scales u alone.
        assert_eq!(parse_map_kd("-s 4 a.png").transform.scale, [4.0, 1.0]);
    }

    #[test]
    fn a_quarter_turn_takes_u_to_minus_v() {
        let t = UvTransform { rotation: std::f64::consts::FRAC_PI_2, ..UvTransform::default() };
        let [u, v] = t.apply([1.0, 0.0]);
        assert!(u.abs() < 1e-12 && (v + 1.0).abs() < 1e-12, "{u} {v}");
    }
}
