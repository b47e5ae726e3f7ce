//! The scene model's checks: polygons, materials, light scaling and box faces.

use radiosity_core::glam::DVec3;
use radiosity_core::{
    Facing, IntensityTable, Luminaire, MAX_POLYGON_VERTICES, Material, Object, Polygon, Rgb, Scene,
    SceneError, Shape, box_faces,
};

/// A [`MAX_POLYGON_VERTICES`]-gon (a disc) is valid, and one corner more is refused before
/// any other work (a 10⁶-gon as fast as a 1025-gon).
#[test]
fn many_cornered_polygons_are_linear_or_refused() {
    let n = MAX_POLYGON_VERTICES;
    let disc: Vec<DVec3> = (0..n)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            DVec3::new(a.cos(), a.sin(), 0.0)
        })
        .collect();
    let p = Polygon::try_new(disc).unwrap();
    assert!((p.area() - std::f64::consts::PI).abs() < 1e-4, "{}", p.area());
    for count in [MAX_POLYGON_VERTICES + 1, 1_000_000] {
        let e = Polygon::try_new(vec![DVec3::ZERO; count]).unwrap_err();
        assert_eq!(e, SceneError::TooManyVertices { count, limit: MAX_POLYGON_VERTICES });
    }
}

#[test]
fn polygon_normal_follows_counter_clockwise_order() {
    let p = Polygon::try_new(vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y]).unwrap();
    assert!((p.normal() - DVec3::Z).length() < 1e-12);
    assert!((p.area() - 1.0).abs() < 1e-12);
}

#[test]
fn bad_polygons_are_rejected() {
    let col = vec![DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
    assert!(matches!(Polygon::try_new(col), Err(SceneError::DegeneratePolygon { .. })));
    let bent = vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.3), DVec3::Y];
    assert!(matches!(Polygon::try_new(bent), Err(SceneError::NonPlanarPolygon { .. })));
    let dart =
        vec![DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0), DVec3::new(1.0, 0.3, 0.0), DVec3::new(1.0, 2.0, 0.0)];
    assert!(matches!(Polygon::try_new(dart), Err(SceneError::NonConvexPolygon { .. })));
    let nan = vec![DVec3::ZERO, DVec3::X, DVec3::new(f64::NAN, 0.0, 0.0)];
    assert!(matches!(Polygon::try_new(nan), Err(SceneError::NonFiniteCoordinate { .. })));
}

#[test]
fn reflectance_one_is_rejected() {
    let e = Material::try_new("w", Rgb::new(0.5, 1.0, 0.5), Rgb::ZERO).unwrap_err();
    assert!(matches!(e, SceneError::ReflectanceOutOfRange { .. }));
    assert!(e.to_string().contains("[0, 1)"));
    assert!(Material::try_new("w", Rgb::splat(f64::NAN), Rgb::ZERO).is_err());
}

#[test]
fn light_scale_scales_emitters_and_luminaires() {
    let materials = vec![
        Material::try_new("lamp", Rgb::ZERO, Rgb::splat(2.0)).unwrap(),
        Material::try_new("grey", Rgb::splat(0.5), Rgb::ZERO).unwrap(),
    ];
    let quad = Polygon::try_new(vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 0.0, 1.0), DVec3::Z]);
    let objects = vec![Object::new("floor", 1, Shape::Polygons(vec![quad.unwrap()]))];
    let mut scene = Scene::try_new_unlit("lit by a luminaire", None, materials, objects).unwrap();
    let table = std::sync::Arc::new(IntensityTable::isotropic(100.0));
    let luminaire = Luminaire::aimed("l", DVec3::Y, -DVec3::Y, 0.0, table, 1.5, Rgb::ONE);
    let flux = luminaire.flux();
    scene.lighting.luminaires.push(luminaire);
    scene.scale_emission(3.0);
    assert_eq!(scene.materials[0].emission, Rgb::splat(6.0));
    assert_eq!(scene.lighting.luminaires[0].scale, 4.5);
    assert!((scene.lighting.luminaire_flux() / (3.0 * flux) - 1.0).abs() < 1e-12);
}

#[test]
fn inward_box_faces_point_inside() {
    let faces = box_faces(DVec3::ZERO, DVec3::ONE, Facing::Inward, 0.0).unwrap();
    let centre = DVec3::splat(0.5);
    for f in &faces {
        assert!((centre - f.vertices()[0]).dot(f.normal()) > 0.0);
    }
    let out = box_faces(DVec3::ZERO, DVec3::ONE, Facing::Outward, 30.0).unwrap();
    for f in &out {
        assert!((centre - f.vertices()[0]).dot(f.normal()) < 0.0);
    }
}
