//! The sky model against values of the reference implementation's
//! formulas, evaluated by hand (a separate transcription of
//! `ArHosekSkyModel.c` 1.4a, with pbrt's zero off the solar disc, over the
//! published arrays in their original layout), and `make_sky`'s image.

use super::*;
use crate::image::WrapMode;
use rpbrt_geometry::{equal_area_sphere_to_square, Vector3f};

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-12)
}

#[test]
fn sky_and_sun_match_the_reference_formulas() {
    let deg = |d: f64| d.to_radians();
    // Sun 10° up, turbidity 3, albedo 0.5 (makesky's defaults).
    let m = SkyModel::new(deg(10.0), 3.0, 0.5);
    let cases = [
        (deg(30.0), deg(50.0), 560.0, 0.024181013544653008),
        (
            deg(80.0),
            deg(100.0),
            320.0 + 400.0 / 12.0,
            0.019489669678521608,
        ),
        (deg(45.0), deg(120.0), 700.0, 0.010883725726045089),
    ];
    for (theta, gamma, l, want) in cases {
        let got = m.sky_radiance(theta, gamma, l);
        assert!(
            rel(got, want) < 1e-9,
            "θ {theta} γ {gamma} λ {l}: {got} vs {want}"
        );
    }
    // On the solar disc (γ = 1 mrad of its 4.45 mrad radius), and off it.
    let sun = m.solar_disc_radiance(600.0, deg(10.0), 0.001);
    assert!(rel(sun, 12944.07753953461) < 1e-9, "{sun}");
    assert_eq!(m.solar_disc_radiance(600.0, deg(10.0), 0.01), 0.0);
    // A fractional turbidity blends the tables on both sides.
    let m = SkyModel::new(deg(60.0), 7.25, 0.1);
    let got = m.sky_radiance(deg(20.0), deg(45.0), 450.0);
    assert!(rel(got, 0.12081683250823957) < 1e-9, "{got}");
    let got = m.sky_radiance(deg(70.0), deg(130.0), 720.0);
    assert!(rel(got, 0.030957841924777713) < 1e-9, "{got}");
    let got = m.solar_disc_radiance(450.0, deg(60.0), 0.002);
    assert!(rel(got, 15479.663535838756) < 1e-9, "{got}");
    // The total is the two added.
    let total = m.radiance(deg(30.0), 0.002, 450.0);
    let parts =
        m.solar_disc_radiance(450.0, deg(60.0), 0.002) + m.sky_radiance(deg(30.0), 0.002, 450.0);
    assert!(rel(total, parts) < 1e-12);
}

#[test]
fn makesky_wavelengths_are_pbrt_v4s() {
    let l = makesky_wavelengths();
    assert_eq!(l.len(), 13);
    assert_eq!(l[0], 320.0);
    assert_eq!(l[12], 720.0);
    assert!((l[1] - 353.333333).abs() < 1e-5);
}

#[test]
fn make_sky_image() {
    let res = 48;
    let (im, md) = make_sky(0.5, 30.0, 3.0, res).unwrap();
    assert_eq!(im.resolution(), Point2i::new(res, res));
    assert_eq!(md.color_space.as_deref(), Some("aces2065-1"));
    assert_eq!(
        md.strings["makesky.turbidity"],
        vec!["3.000000".to_string()]
    );
    let px =
        |x: i32, y: i32, c: usize| im.get_channel(Point2i::new(x, y), c, WrapMode::Clamp.into());
    let model = SkyModel::new(30f64.to_radians(), 3.0, 0.5);
    let sun = [0.0, 30f64.to_radians().cos(), 30f64.to_radians().sin()];
    for y in 0..res {
        for x in 0..res {
            let v = equal_area_square_to_sphere(Point2f::new(
                (x as Float + 0.5) / res as Float,
                (y as Float + 0.5) / res as Float,
            ));
            if v.z <= 0.0 {
                // The lower hemisphere is black.
                assert!((0..3).all(|c| px(x, y, c) == 0.0), "({x}, {y})");
            } else {
                // Each pixel is the model at its centre's direction; the sky
                // is positive and bluish.
                let want = sky_rgb(&model, [v.x as f64, v.y as f64, v.z as f64], sun);
                for (c, w) in want.iter().enumerate() {
                    assert_eq!(px(x, y, c), *w);
                }
                assert!(px(x, y, 2) > 0.0);
            }
        }
    }
    // Mirror symmetric across the sun's vertical plane (x → −x).
    for (x, y) in [(30, 20), (26, 33), (40, 10)] {
        let v = equal_area_square_to_sphere(Point2f::new(
            (x as Float + 0.5) / res as Float,
            (y as Float + 0.5) / res as Float,
        ));
        let m = equal_area_sphere_to_square(Vector3f::new(-v.x, v.y, v.z));
        let (mx, my) = ((m.x * res as Float) as i32, (m.y * res as Float) as i32);
        for c in 0..3 {
            let (a, b) = (px(x, y, c), px(mx, my, c));
            assert!(
                (a - b).abs() <= 1e-4 * a.abs().max(b.abs()),
                "({x},{y}) vs ({mx},{my})"
            );
        }
    }
    // Sky toward the sun is brighter than away from it.
    let toward = sky_rgb(&model, [0.0, 0.8, 0.6], sun);
    let away = sky_rgb(&model, [0.0, -0.8, 0.6], sun);
    assert!(toward[1] > away[1], "{toward:?} {away:?}");
}

#[test]
fn make_sky_rejects_what_pbrt_v4_rejects() {
    assert_eq!(
        make_sky(1.5, 10.0, 3.0, 8).unwrap_err(),
        SkyError::Albedo(1.5)
    );
    assert_eq!(
        make_sky(0.5, 10.0, 1.5, 8).unwrap_err(),
        SkyError::Turbidity(1.5)
    );
    assert_eq!(
        make_sky(0.5, 91.0, 3.0, 8).unwrap_err(),
        SkyError::Elevation(91.0)
    );
    assert_eq!(
        make_sky(0.5, 10.0, 3.0, 0).unwrap_err(),
        SkyError::Resolution(0)
    );
    assert!(matches!(
        make_sky(f32::NAN, 10.0, 3.0, 8),
        Err(SkyError::Albedo(_))
    ));
}
