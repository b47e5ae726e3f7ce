//! Photometry's closed forms: luminaire intensity tables (flux, interpolation, frames), light
//! colours, the EN 12464-1 grid spacing and the sky models' horizontal factors.

use std::f64::consts::PI;
use std::sync::Arc;

use radiosity_core::glam::DVec3;
use radiosity_core::{Grid, IntensityTable, Luminaire, Rgb, Sky, SkyMap, SkyModel, colour_of_cct};

/// Each sky model's horizontal factor is ∫ g(θ) cos θ dω / π over the upper hemisphere,
/// here by the midpoint rule over 20 000 rings of μ = cos θ (dω = 2π dμ).
#[test]
fn sky_horizontal_factors_are_the_integrals_of_their_radiance() {
    for model in [SkyModel::Uniform, SkyModel::CieOvercast] {
        let n = 20_000;
        let integral: f64 = (0..n)
            .map(|i| {
                let mu = (f64::from(i) + 0.5) / f64::from(n);
                let towards = DVec3::new((1.0 - mu * mu).sqrt(), mu, 0.0);
                model.relative_radiance(towards, DVec3::Y) * mu * 2.0 * PI / f64::from(n)
            })
            .sum();
        assert!((integral / PI - model.horizontal_factor(DVec3::Y)).abs() < 1e-8, "{model:?}");
    }
    let sky = Sky::from_horizontal(SkyModel::CieOvercast, DVec3::Y, Rgb::splat(10.0), 64);
    assert!((sky.horizontal_irradiance().g - 10.0).abs() < 1e-12);
    assert_eq!(sky.radiosity_towards(-DVec3::Y), Rgb::ZERO, "no sky below the horizon");
    // Three times brighter at the zenith than at the horizon.
    let (zenith, horizon) =
        (sky.radiosity_towards(DVec3::Y).g, sky.radiosity_towards(DVec3::new(1.0, 1e-9, 0.0)).g);
    assert!((zenith / horizon - 3.0).abs() < 1e-6);
}

#[test]
fn isotropic_flux_is_four_pi_i() {
    let t = IntensityTable::isotropic(100.0);
    assert!((t.flux() - 400.0 * PI).abs() < 1e-6 * t.flux());
}

#[test]
fn cosine_flux_is_pi_i0() {
    let gammas: Vec<f64> = (0..=90).map(f64::from).collect();
    let cd: Vec<f64> = gammas.iter().map(|g| 1000.0 * g.to_radians().cos()).collect();
    let t = IntensityTable::symmetric(gammas, cd).unwrap();
    // Linear interpolation of cos between 1° samples: 1e-4 relative at most.
    assert!((t.flux() / (1000.0 * PI) - 1.0).abs() < 2e-4, "{}", t.flux());
}

#[test]
fn interpolation_is_periodic_and_bilinear() {
    let t = IntensityTable::try_new(
        vec![0.0, 180.0, 360.0],
        vec![0.0, 90.0],
        vec![100.0, 0.0, 200.0, 100.0, 100.0, 0.0],
    )
    .unwrap();
    assert!((t.candela(90.0, 0.0) - 150.0).abs() < 1e-9);
    assert!((t.candela(270.0, 45.0) - 100.0).abs() < 1e-9);
    assert!((t.candela(-90.0, 45.0) - 100.0).abs() < 1e-9);
    assert_eq!(t.candela(0.0, 120.0), 0.0);
}

#[test]
fn luminaire_frame_measures_gamma_from_the_nadir() {
    let t = Arc::new(
        IntensityTable::try_new(
            vec![0.0, 90.0, 180.0, 270.0, 360.0],
            vec![0.0, 90.0],
            vec![10.0, 1.0, 10.0, 2.0, 10.0, 3.0, 10.0, 4.0, 10.0, 1.0],
        )
        .unwrap(),
    );
    let l = Luminaire::aimed("l", DVec3::ZERO, -DVec3::Y, 0.0, t, 1.0, Rgb::ONE);
    assert!((l.candela_towards(-DVec3::Y) - 10.0).abs() < 1e-9);
    assert!((l.candela_towards(DVec3::X) - 1.0).abs() < 1e-9);
    assert!((l.candela_towards(l.c90) - 2.0).abs() < 1e-9);
    assert!((l.candela_towards(-DVec3::X) - 3.0).abs() < 1e-9);
}

/// A cosine downlight's light goes down on the whole, 2/3 of the way (∫cos²γ sin γ /
/// ∫cos γ sin γ over the lower hemisphere); an isotropic lamp's nowhere, so it lights from
/// its centre.
#[test]
fn mean_light_direction_follows_the_distribution() {
    let gammas: Vec<f64> = (0..=90).map(f64::from).collect();
    let cd: Vec<f64> = gammas.iter().map(|g| g.to_radians().cos()).collect();
    let table = Arc::new(IntensityTable::symmetric(gammas, cd).unwrap());
    let down = Luminaire::aimed("l", DVec3::Y, -DVec3::Y, 0.0, table, 1.0, Rgb::ONE);
    let mean = down.mean_light_direction();
    // The 5° midpoint rule errs by well under 1 %.
    assert!((mean - DVec3::NEG_Y * (2.0 / 3.0)).length() < 0.01, "{mean}");
    assert!((down.light_point(0.01) - DVec3::new(0.0, 0.99, 0.0)).length() < 1e-12);
    let iso = Luminaire::aimed(
        "i",
        DVec3::Y,
        -DVec3::Y,
        0.0,
        Arc::new(IntensityTable::isotropic(5.0)),
        1.0,
        Rgb::ONE,
    );
    assert!(iso.mean_light_direction().length() < 1e-9);
    assert_eq!(iso.light_point(0.01), DVec3::Y);
}

#[test]
fn cct_white_points_are_plausible() {
    let warm = colour_of_cct(3000.0);
    let d65 = colour_of_cct(6504.0);
    assert!((warm.luminance() - 1.0).abs() < 1e-9);
    assert!(warm.r > warm.g && warm.g > warm.b);
    // 6504 K is near the sRGB white point: channels within a few per cent.
    assert!((d65.r / d65.b - 1.0).abs() < 0.06, "{d65:?}");
}

#[test]
fn standard_spacing_follows_en_12464() {
    assert!((Grid::standard_spacing(1.0) - 0.2).abs() < 1e-12);
    assert!((Grid::standard_spacing(10.0) - 1.0).abs() < 1e-12);
}

/// The CIE clear sky (type 12) with the sun 40° up: 1 at the zenith, brightest towards the
/// sun, darker 90° from it than near the sun or at the horizon opposite; its horizontal factor
/// by the ring rule agrees with an independent estimate, the mean of its radiance over
/// 400 000 cosine-distributed random directions (E_h / π L_z = E[g], standard error ≈ 0.1 %),
/// within 4 standard errors.
#[test]
fn the_clear_sky_peaks_at_the_sun_and_integrates_the_same_two_ways() {
    let el = 40f64.to_radians();
    let sun = DVec3::new(el.cos(), el.sin(), 0.0);
    let clear = SkyModel::CieClear { sun };
    let g = |d: DVec3| clear.relative_radiance(d.normalize(), DVec3::Y);
    assert!((g(DVec3::Y) - 1.0).abs() < 1e-12);
    let near_sun = g(sun + DVec3::new(0.0, 0.0, 0.05));
    let (side, behind) = (g(DVec3::new(0.0, 1.0, 1.0)), g(DVec3::new(-1.0, 0.2, 0.0)));
    assert!(g(sun) > near_sun && near_sun > 3.0 * side, "sun {} near {near_sun} side {side}", g(sun));
    assert!(behind > side, "the horizon opposite the sun is brighter than 90° from it");

    let factor = clear.horizontal_factor(DVec3::Y);
    let mut rng = radiosity_core::random::Rng::for_task(7, 0, 0);
    let n = 400_000;
    let (mut sum, mut sum2) = (0.0, 0.0);
    for _ in 0..n {
        let (u, v) = (rng.next_f64(), rng.next_f64());
        let (r, phi) = (u.sqrt(), 2.0 * PI * v);
        let value = g(DVec3::new(r * phi.cos(), (1.0 - u).sqrt(), r * phi.sin()));
        sum += value;
        sum2 += value * value;
    }
    let mean = sum / f64::from(n);
    let se = ((sum2 / f64::from(n) - mean * mean) / f64::from(n)).sqrt();
    assert!((mean - factor).abs() < 4.0 * se, "rings {factor}, random {mean} ± {se}");
    assert!(se < 2e-3 * mean);
}

/// A map of radiance 1 everywhere gives an open plane π (∫ cos θ dω over a hemisphere), at
/// any resolution; the middle column looks along `forward`, the top row at the zenith,
/// and a texel's value comes back at its centre; bad sizes and texels are refused.
#[test]
fn a_map_is_looked_up_and_integrated_where_its_texels_are() {
    for (w, h) in [(4, 2), (64, 32), (100, 51)] {
        let map = SkyMap::try_new(w, h, vec![Rgb::splat(1.0); (w * h) as usize]).unwrap();
        assert!((map.horizontal_irradiance().g / PI - 1.0).abs() < 1e-12, "{w} × {h}");
    }
    let (w, h) = (8u32, 4u32);
    let texels = (0..w * h).map(|k| Rgb::new(f64::from(k % w), f64::from(k / w), 0.0)).collect::<Vec<_>>();
    let map = SkyMap::try_new(w, h, texels).unwrap();
    let (zenith, forward) = (DVec3::Y, DVec3::NEG_Z);
    // Forward, just above the horizon: between columns 3 and 4 (u = ½), row 1.5 → 1.5.
    let l = map.radiance(DVec3::new(0.0, 1e-9, -1.0), zenith, forward);
    assert!((l.r - 3.5).abs() < 1e-6 && (l.g - 1.5).abs() < 1e-6, "{l:?}");
    // To the right of forward (+x here): a quarter turn on, u = ¾, column 5.5.
    let l = map.radiance(DVec3::new(1.0, 0.0, 0.0), zenith, forward);
    assert!((l.r - 5.5).abs() < 1e-6, "{l:?}");
    assert!(map.radiance(DVec3::Y, zenith, forward).g.abs() < 1e-9, "the zenith is the top row");
    assert!(SkyMap::try_new(2, 2, vec![Rgb::ZERO; 3]).is_err());
    assert!(SkyMap::try_new(2, 2, vec![Rgb::splat(-1.0); 4]).is_err());
}
