//! The core vocabulary's small parts: colour, the film, one-line errors, sRGB, up axes.

use radiosity_core::glam::DVec3;
use radiosity_core::random::{Rng, XorShift64, four_units};
use radiosity_core::{
    Camera, CameraRays, Rgb, UpAxis, encode_srgb, escape_controls, one_line, srgb_decode, srgb_encode,
};

#[test]
fn luminance_of_white_is_one() {
    assert!((Rgb::ONE.luminance() - 1.0).abs() < 1e-12);
}

#[test]
fn arithmetic_is_channel_wise() {
    let a = Rgb::new(1.0, 2.0, 3.0);
    assert_eq!(a * a, Rgb::new(1.0, 4.0, 9.0));
    assert_eq!(a - a, Rgb::ZERO);
    assert_eq!((a * 2.0).sum(), 12.0);
}

/// The centre of the film looks at `look_at`; the top-left corner is up and to the left
/// by half the field of view.
#[test]
fn the_film_maps_centre_and_corners() {
    let camera = Camera::try_new(DVec3::ZERO, DVec3::Z, DVec3::Y, 90.0).unwrap();
    let rays = CameraRays::new(&camera, 200, 100);
    assert!((rays.direction(100.0, 50.0) - DVec3::Z).length() < 1e-12);
    let corner = rays.direction(0.0, 0.0);
    // tan 45° = 1 up, aspect 2 to the left (+x: right = z × y = −x).
    let expected = DVec3::new(2.0, 1.0, 1.0).normalize();
    assert!((corner - expected).length() < 1e-12, "{corner}");
}

#[derive(Debug)]
struct Outer(std::io::Error);

impl std::fmt::Display for Outer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("cannot load\nthe scene")
    }
}

impl std::error::Error for Outer {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&self.0)
    }
}

#[test]
fn causes_are_joined_and_control_characters_escaped() {
    let e = Outer(std::io::Error::other("no such file"));
    assert_eq!(one_line(&e), "cannot load\\nthe scene: no such file");
}

#[test]
fn plain_text_is_kept() {
    assert_eq!(escape_controls("a\nb\tc"), "a\\nb\\tc");
    assert_eq!(escape_controls("plain"), "plain");
}

#[test]
fn srgb_matches_known_values_and_round_trips() {
    for (linear, encoded) in
        [(0.0, 0.0), (0.003_130_8, 0.040_45), (0.18, 0.461_356), (0.5, 0.735_357), (1.0, 1.0)]
    {
        assert!((srgb_encode(linear) - encoded).abs() < 1e-5, "{linear}");
        assert!((srgb_decode(encoded) - linear).abs() < 1e-5, "{encoded}");
    }
    for i in 0..=1000 {
        let x = f64::from(i) / 1000.0;
        assert!((srgb_decode(srgb_encode(x)) - x).abs() < 1e-12, "{x}");
    }
    // 8-bit round trip: every code value survives decode → encode → round.
    for code in 0..=255u8 {
        let lin = srgb_decode(f64::from(code) / 255.0);
        assert_eq!(encode_srgb(Rgb::splat(lin)), [code; 3]);
    }
}

/// Each turn takes its axis to +y, is a rotation (keeps a right-handed frame) and is
/// undone by its inverse.
#[test]
fn every_turn_takes_its_axis_up_and_back() {
    for up in UpAxis::ALL {
        assert_eq!(up.to_y_up(up.direction()), DVec3::Y, "{up}");
        let (x, y, z) = (up.to_y_up(DVec3::X), up.to_y_up(DVec3::Y), up.to_y_up(DVec3::Z));
        assert_eq!(x.cross(y), z, "{up}: not a rotation");
        let p = DVec3::new(1.5, -2.25, 3.125);
        assert_eq!(up.from_y_up(up.to_y_up(p)), p, "{up}");
        assert_eq!(UpAxis::parse(up.as_str()), Some(up));
    }
    assert_eq!(UpAxis::parse("+Z"), Some(UpAxis::Z));
    assert_eq!(UpAxis::parse("w"), None);
}

/// Keyed streams are reproducible and distinct per key; their numbers are in [0, 1).
#[test]
fn streams_are_keyed_and_in_range() {
    let a: Vec<u64> = (0..4).map(|_| Rng::for_task(1, 2, 3).next_u64()).collect();
    assert!(a.windows(2).all(|w| w[0] == w[1]));
    assert_ne!(Rng::for_task(1, 2, 3).next_u64(), Rng::for_task(1, 2, 4).next_u64());
    assert_ne!(Rng::for_task(1, 2, 3).next_u64(), Rng::for_task(2, 2, 3).next_u64());
    let mut rng = Rng::for_task(0, 0, 0);
    let mut sum = 0.0;
    for _ in 0..100_000 {
        let x = rng.next_f64();
        let (u, v) = rng.next_f32_pair();
        assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&u) && (0.0..1.0).contains(&v));
        sum += x;
    }
    // Mean of 10⁵ uniforms: standard error 1/√(12·10⁵) ≈ 9.1e-4; 5 σ.
    assert!((sum / 100_000.0 - 0.5).abs() < 4.6e-3, "mean {}", sum / 100_000.0);
    assert!(four_units(7, 9).iter().all(|u| (0.0..1.0).contains(u)));
}

/// The xorshift sequence is Marsaglia's: the first value of seed 1 is known by hand.
#[test]
fn xorshift_is_marsaglias() {
    let mut x = XorShift64::new(1);
    // 1 ^ 1<<13 = 0x2001; ^ >>7 = 0x2001 ^ 0x40 = 0x2041; ^ <<17 = 0x2041 ^ 0x4082_0000.
    assert_eq!(x.next_u64(), 0x4082_2041);
    assert!(x.below(0) == 0 && x.below(5) < 5);
}
