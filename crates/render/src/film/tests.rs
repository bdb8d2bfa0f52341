use std::sync::Arc;

use rpbrt_geometry::{Bounds2i, Float, Point2i, Vector2f};
use rpbrt_parser::{FileLoc, ParameterDictionary, ParsedParameter};

use super::*;
use crate::camera::CameraTransform;
use crate::filter::{BoxFilter, Filter};
use crate::params::ParamReader;
use crate::rng::Rng;
use crate::spectrum::{
    cie, named_spectrum, RgbColorSpace, RgbIlluminantSpectrum, Spectrum, CIE_Y_INTEGRAL, RGB, XYZ,
};
use rpbrt_parser::Diagnostic;

fn loc(line: u32) -> FileLoc {
    FileLoc::new(Arc::from("film.pbrt"), line, 3)
}

enum P<'a> {
    F(&'a str, &'a [Float]),
    I(&'a str, &'a [i32]),
    S(&'a str, &'a str),
}

/// A `Film` directive's type and parameters.
struct FilmEntity {
    name: String,
    params: ParameterDictionary,
}

/// The film and its warnings, unused parameters included.
fn create_film(
    e: &FilmEntity,
    filter: &Filter,
    exposure_time: Float,
    ct: &CameraTransform,
    ov: &FilmOverrides,
) -> Result<(Film, Vec<Diagnostic>), Diagnostic> {
    let at = loc(1);
    let r = ParamReader::plain(&e.params, &at);
    let film = super::create_film(&e.name, &r, filter, exposure_time, ct, ov)?;
    Ok((film, r.finish()))
}

fn entity(name: &str, params: &[P]) -> FilmEntity {
    let list = params
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let l = loc(10 + i as u32);
            match p {
                P::F(n, v) => ParsedParameter::with_floats("float", n, l, v.to_vec()),
                P::I(n, v) => {
                    let mut pp = ParsedParameter::with_floats("integer", n, l, vec![]);
                    pp.ints = v.to_vec();
                    pp
                }
                P::S(n, v) => ParsedParameter::with_strings("string", n, l, vec![v.to_string()]),
            }
        })
        .collect();
    FilmEntity {
        name: name.to_string(),
        params: ParameterDictionary::new(list),
    }
}

fn box_filter() -> Filter {
    Filter::Box(BoxFilter::new(Vector2f::new(0.5, 0.5)))
}

fn make(name: &str, params: &[P], ov: &FilmOverrides) -> Result<Film, rpbrt_parser::Diagnostic> {
    create_film(
        &entity(name, params),
        &box_filter(),
        1.0,
        &CameraTransform::default(),
        ov,
    )
    .map(|(f, _)| f)
}

fn film(name: &str, params: &[P]) -> Film {
    match make(name, params, &FilmOverrides::default()) {
        Ok(f) => f,
        Err(e) => panic!("film creation failed: {e:?}"),
    }
}

/// Averages `spectrum` through pixel (0,0) of `film` with `n` samples.
fn render_pixel(film: &mut Film, s: &Spectrum, n: usize) -> RGB {
    let mut rng = Rng::new(7, 0);
    for _ in 0..n {
        let lambda = film.sample_wavelengths(rng.uniform_float());
        film.add_sample(Point2i::new(0, 0), s.sample(&lambda), &lambda, None, 1.0);
    }
    film.get_pixel_rgb(Point2i::new(0, 0), 1.0)
}

fn small(name: &str, extra: &[P]) -> Film {
    let mut p = vec![P::I("xresolution", &[4]), P::I("yresolution", &[4])];
    p.extend(extra.iter().map(|x| match x {
        P::F(a, b) => P::F(a, b),
        P::I(a, b) => P::I(a, b),
        P::S(a, b) => P::S(a, b),
    }));
    film(name, &p)
}

fn close(a: Float, b: Float, rel: Float) -> bool {
    (a - b).abs() <= rel * b.abs().max(1e-3)
}

#[test]
fn equal_energy_white_has_unit_luminance() {
    // Lights are normalised to unit luminance by 1 / CIE_Y_INTEGRAL.
    let mut f = small("rgb", &[]);
    let s = Spectrum::Constant(1.0 / CIE_Y_INTEGRAL);
    let rgb = render_pixel(&mut f, &s, 200_000);
    let cs = RgbColorSpace::srgb();
    let xyz = cs.to_xyz(rgb);
    assert!(close(xyz.y, 1.0, 0.01), "Y = {}", xyz.y);
    let sum = |sp: &Spectrum| {
        (360..=830)
            .map(|l| sp.evaluate(l as Float) as f64)
            .sum::<f64>()
    };
    let e = XYZ::new(
        (sum(cie::x()) / CIE_Y_INTEGRAL as f64) as Float,
        1.0,
        (sum(cie::z()) / CIE_Y_INTEGRAL as f64) as Float,
    );
    let expect = cs.to_rgb(e);
    for c in 0..3 {
        assert!(
            close(rgb.to_array()[c], expect.to_array()[c], 0.015),
            "{rgb:?} vs {expect:?}"
        );
    }
}

#[test]
fn d65_renders_srgb_white() {
    let mut f = small("rgb", &[]);
    let d65 = named_spectrum("stdillum-D65").expect("D65");
    let s = match d65 {
        Spectrum::PiecewiseLinear(p) => {
            let mut p = (*p).clone();
            p.scale(1.0 / CIE_Y_INTEGRAL);
            Spectrum::PiecewiseLinear(Arc::new(p))
        }
        other => other,
    };
    let rgb = render_pixel(&mut f, &s, 200_000);
    for v in rgb.to_array() {
        assert!(close(v, 1.0, 0.01), "{rgb:?}");
    }
}

#[test]
fn rgb_illuminant_round_trips() {
    let cs = RgbColorSpace::srgb();
    let target = RGB::new(0.2, 0.5, 0.8);
    let s = Spectrum::RgbIlluminant(RgbIlluminantSpectrum::new(cs, target));
    // The light's photometric normalisation: 1 / ∫ Y · illuminant.
    let scale = 1.0 / crate::spectrum::spectrum_to_photometric(&s);
    let mut f = small("rgb", &[]);
    let mut rng = Rng::new(3, 0);
    for _ in 0..400_000 {
        let lambda = f.sample_wavelengths(rng.uniform_float());
        f.add_sample(
            Point2i::new(1, 1),
            s.sample(&lambda) * scale,
            &lambda,
            None,
            1.0,
        );
    }
    let rgb = f.get_pixel_rgb(Point2i::new(1, 1), 1.0);
    for c in 0..3 {
        assert!(
            close(rgb.to_array()[c], target.to_array()[c], 0.015),
            "{rgb:?}"
        );
    }
}

#[test]
fn camera_sensors_fit_and_render_white() {
    let cs = RgbColorSpace::srgb();
    for name in sensor_names().skip(1) {
        let s = PixelSensor::camera(name, cs, 6500.0, 1.0)
            .expect("known")
            .expect("solvable");
        let m = s.xyz_from_sensor_rgb.m;
        assert!(m.iter().flatten().all(|v| v.is_finite()), "{name}");
    }
    // A white-balanced camera renders the output white close to white.
    let mut f = small("rgb", &[P::S("sensor", "canon_eos_5d_mkiv")]);
    let d65 = named_spectrum("stdillum-D65").expect("D65");
    let rgb = render_pixel(&mut f, &d65, 100_000);
    let scale = rgb.g;
    for v in rgb.to_array() {
        assert!(close(v / scale, 1.0, 0.05), "{rgb:?}");
    }
}

#[test]
fn white_balance_maps_source_white_to_target() {
    let m = white_balance([0.3457, 0.3585], [0.3127, 0.3290]);
    let out = XYZ::from_array(m.apply(XYZ::from_xyy([0.3457, 0.3585], 1.0).to_array()));
    let xy = out.xy();
    assert!(
        (xy[0] - 0.3127).abs() < 1e-4 && (xy[1] - 0.3290).abs() < 1e-4,
        "{xy:?}"
    );
}

#[test]
fn iso_and_exposure_scale_linearly() {
    let e = entity("rgb", &[P::F("iso", &[200.0])]);
    let (f, _) = create_film(
        &e,
        &box_filter(),
        0.5,
        &CameraTransform::default(),
        &FilmOverrides::default(),
    )
    .expect("film");
    assert!(close(f.sensor().imaging_ratio(), 1.0, 1e-6));
}

#[test]
fn max_component_value_clamps() {
    let mut f = small("rgb", &[P::F("maxcomponentvalue", &[0.5])]);
    let rgb = render_pixel(&mut f, &Spectrum::Constant(10.0 / CIE_Y_INTEGRAL), 1000);
    let xyz = RgbColorSpace::srgb().to_xyz(rgb);
    // Sensor (XYZ) components are clamped to 0.5 per sample.
    assert!(
        xyz.x <= 0.5001 && xyz.y <= 0.5001 && xyz.z <= 0.5001,
        "{xyz:?}"
    );
}

#[test]
fn weights_normalise() {
    let mut f = small("rgb", &[]);
    let lambda = f.sample_wavelengths(0.3);
    let l = Spectrum::Constant(1.0 / CIE_Y_INTEGRAL).sample(&lambda);
    f.add_sample(Point2i::new(2, 2), l, &lambda, None, 0.25);
    let a = f.get_pixel_rgb(Point2i::new(2, 2), 1.0);
    f.add_sample(Point2i::new(2, 2), l, &lambda, None, 3.0);
    let b = f.get_pixel_rgb(Point2i::new(2, 2), 1.0);
    for c in 0..3 {
        assert!(close(a.to_array()[c], b.to_array()[c], 1e-5));
    }
}

fn tiled_image(order: &[usize]) -> Vec<f32> {
    let mut f = film(
        "rgb",
        &[P::I("xresolution", &[8]), P::I("yresolution", &[6])],
    );
    let tiles_b = [
        Bounds2i::new(Point2i::new(0, 0), Point2i::new(4, 3)),
        Bounds2i::new(Point2i::new(4, 0), Point2i::new(8, 3)),
        Bounds2i::new(Point2i::new(0, 3), Point2i::new(4, 6)),
        Bounds2i::new(Point2i::new(4, 3), Point2i::new(8, 6)),
    ];
    let mut tiles: Vec<FilmTile> = tiles_b
        .iter()
        .enumerate()
        .map(|(k, b)| {
            let mut t = f.make_tile(*b);
            let mut rng = Rng::new(k as u64 + 1, 0);
            for p in b.iter() {
                for _ in 0..5 {
                    let lambda = f.sample_wavelengths(rng.uniform_float());
                    let l = Spectrum::Constant(rng.uniform_float()).sample(&lambda);
                    t.add_sample(p, l, &lambda, None, rng.uniform_float());
                }
            }
            t
        })
        .collect();
    for &k in order {
        f.merge_tile(&tiles[k]);
    }
    tiles.clear();
    let mut md = crate::image::ImageMetadata::default();
    f.get_image(&mut md, 1.0).to_f32_vec()
}

#[test]
fn tile_merge_order_does_not_matter() {
    let a = tiled_image(&[0, 1, 2, 3]);
    let b = tiled_image(&[3, 1, 0, 2]);
    assert_eq!(a, b);
    assert!(a.iter().any(|v| *v > 0.0));
}

#[test]
fn crop_window_rounds_like_pbrt() {
    let f = film(
        "rgb",
        &[
            P::I("xresolution", &[100]),
            P::I("yresolution", &[100]),
            P::F("cropwindow", &[0.25, 0.75, 0.25, 0.75]),
        ],
    );
    assert_eq!(
        f.pixel_bounds(),
        Bounds2i::new(Point2i::new(25, 25), Point2i::new(75, 75))
    );
    let b = crate::film::create::crop_to_pixel_bounds(Point2i::new(10, 10), [0.11, 0.5, 0.0, 1.0]);
    assert_eq!(b, Bounds2i::new(Point2i::new(2, 0), Point2i::new(5, 10)));
    let ov = FilmOverrides {
        quick: true,
        ..Default::default()
    };
    let q = make(
        "rgb",
        &[P::I("xresolution", &[100]), P::I("yresolution", &[2])],
        &ov,
    )
    .expect("quick");
    assert_eq!(q.full_resolution(), Point2i::new(25, 1));
}

#[test]
fn bad_parameters_are_located_errors() {
    let ov = FilmOverrides::default();
    let e = make(
        "rgb",
        &[
            P::I("xresolution", &[2_000_000_000]),
            P::I("yresolution", &[2_000_000_000]),
        ],
        &ov,
    )
    .expect_err("huge");
    assert_eq!(e.loc.as_ref().map(|l| l.line), Some(10));
    let e = make("rgb", &[P::I("xresolution", &[0])], &ov).expect_err("zero");
    assert!(e.message.contains("positive"));
    let e = make("rgb", &[P::F("cropwindow", &[0.5, 1.5, 0.0, 1.0])], &ov).expect_err("crop");
    assert_eq!(e.loc.as_ref().map(|l| l.line), Some(10));
    let e = make("rgb", &[P::F("cropwindow", &[0.5, 0.5, 0.0, 1.0])], &ov).expect_err("empty");
    assert!(e.message.contains("degenerate"));
    let e = make("rgb", &[P::I("pixelbounds", &[0, 2000, 0, 10])], &ov).expect_err("pb");
    assert!(e.message.contains("beyond"));
    let e = make("rgb", &[P::S("sensor", "nikon_d1")], &ov).expect_err("sensor");
    assert!(e.message.contains("sony_ilce_9") && e.message.contains("cie1931"));
    let e = make("film35", &[], &ov).expect_err("type");
    assert!(
        e.message
            .contains("unknown film type; expected one of \"gbuffer\", \"rgb\", \"spectral\""),
        "{}",
        e.message
    );
    let o = FilmOverrides {
        outfile: Some("out.jpg".into()),
        ..Default::default()
    };
    let e = make("rgb", &[], &o).expect_err("ext");
    assert!(e.message.contains("jpg"));
    let e = make("gbuffer", &[P::S("filename", "a.png")], &ov).expect_err("gbuffer png");
    assert!(e.message.contains("EXR"));
}

#[test]
fn unused_parameters_warn() {
    let (_, w) = create_film(
        &entity("rgb", &[P::F("isoo", &[100.0])]),
        &box_filter(),
        1.0,
        &CameraTransform::default(),
        &FilmOverrides::default(),
    )
    .expect("film");
    assert!(w.iter().any(|d| d.message.contains("isoo")), "{w:?}");
}

fn tmp(name: &str) -> String {
    let dir = std::env::temp_dir().join(format!("rpbrt-film-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("tmp dir");
    dir.join(name).display().to_string()
}

#[test]
fn exr_round_trip_keeps_values_and_metadata() {
    let path = tmp("rt.exr");
    let mut f = film(
        "rgb",
        &[
            P::I("xresolution", &[6]),
            P::I("yresolution", &[4]),
            P::I("pixelbounds", &[1, 5, 0, 3]),
            P::S("filename", &path),
        ],
    );
    let mut rng = Rng::new(5, 0);
    for p in f.pixel_bounds().iter() {
        let lambda = f.sample_wavelengths(rng.uniform_float());
        f.add_sample(
            p,
            Spectrum::Constant(0.01 * (p.x + p.y) as Float).sample(&lambda),
            &lambda,
            None,
            1.0,
        );
    }
    let md = crate::image::ImageMetadata {
        samples_per_pixel: Some(16),
        render_time_seconds: Some(1.5),
        ..Default::default()
    };
    f.write_image(&md, 1.0).expect("write");
    let read = crate::image::Image::read(&path, None).expect("read");
    assert_eq!(read.metadata.pixel_bounds, Some(f.pixel_bounds()));
    assert_eq!(read.metadata.full_resolution, Some(Point2i::new(6, 4)));
    assert_eq!(read.metadata.samples_per_pixel, Some(16));
    assert_eq!(read.metadata.color_space_name(), "srgb");
    let p = Point2i::new(3, 2);
    let rgb = f.get_pixel_rgb(p, 1.0);
    let wrap =
        crate::image::WrapMode2D::new(crate::image::WrapMode::Clamp, crate::image::WrapMode::Clamp);
    // EXR stores channels by name (sorted), so look R up by name.
    let r = read
        .image
        .channel_names()
        .iter()
        .position(|n| n == "R")
        .expect("R");
    let v = read.image.get_channel(Point2i::new(2, 2), r, wrap);
    assert!(
        (v - rgb.r).abs() <= 1e-3 * rgb.r.abs().max(1.0),
        "{v} vs {rgb:?}"
    );
}

#[test]
fn gbuffer_channels_are_named_as_pbrt() {
    let mut f = small("gbuffer", &[]);
    assert!(f.uses_visible_surface());
    let lambda = f.sample_wavelengths(0.5);
    let vs = VisibleSurface {
        p: rpbrt_geometry::Point3f::new(1.0, 2.0, 3.0),
        n: rpbrt_geometry::Normal3f::new(0.0, 0.0, 2.0),
        ns: rpbrt_geometry::Normal3f::new(0.0, 1.0, 0.0),
        uv: rpbrt_geometry::Point2f::new(0.25, 0.75),
        albedo: crate::spectrum::SampledSpectrum::new(0.5),
        set: true,
        ..Default::default()
    };
    f.add_sample(
        Point2i::new(0, 0),
        Spectrum::Constant(0.01).sample(&lambda),
        &lambda,
        Some(&vs),
        1.0,
    );
    let mut md = crate::image::ImageMetadata::default();
    let img = f.get_image(&mut md, 1.0);
    let names = img.channel_names();
    assert_eq!(&names[..3], &["R", "G", "B"]);
    assert_eq!(
        names[3..].iter().map(|s| s.as_str()).collect::<Vec<_>>(),
        GBUFFER_CHANNELS.to_vec()
    );
    let wrap =
        crate::image::WrapMode2D::new(crate::image::WrapMode::Clamp, crate::image::WrapMode::Clamp);
    let ch = |n: &str| {
        let i = names.iter().position(|x| x == n).expect("channel");
        img.get_channel(Point2i::new(0, 0), i, wrap)
    };
    assert!(
        (ch("P.Z") - 3.0).abs() < 1e-3
            && (ch("N.Z") - 1.0).abs() < 1e-3
            && (ch("v") - 0.75).abs() < 1e-3
    );
}

#[test]
fn spectral_buckets_hold_radiance() {
    let mut f = small("spectral", &[P::I("nbuckets", &[4])]);
    let c = 0.02;
    let mut rng = Rng::new(9, 0);
    for _ in 0..2000 {
        let lambda = f.sample_wavelengths(rng.uniform_float());
        assert!(lambda.lambda.iter().all(|l| (360.0..=830.0).contains(l)));
        f.add_sample(
            Point2i::new(0, 0),
            Spectrum::Constant(c / CIE_Y_INTEGRAL).sample(&lambda),
            &lambda,
            None,
            1.0,
        );
    }
    let mut md = crate::image::ImageMetadata::default();
    let img = f.get_image(&mut md, 1.0);
    let names = img.channel_names();
    assert_eq!(names[3], "S0.418,750nm");
    assert_eq!(names.len(), 7);
    let wrap =
        crate::image::WrapMode2D::new(crate::image::WrapMode::Clamp, crate::image::WrapMode::Clamp);
    let total: Float = (3..7)
        .map(|i| img.get_channel(Point2i::new(0, 0), i, wrap))
        .sum();
    // Every bucket holds the (photometrically un-normalised) radiance c.
    assert!(close(total, 4.0 * c, 1e-3), "{total}");
    assert_eq!(
        md.strings.get("spectralLayoutVersion"),
        Some(&vec!["1.0".to_string()])
    );
}

#[test]
fn sample_bounds_grow_by_filter_radius() {
    let f = small("rgb", &[]);
    let b = f.sample_bounds();
    assert_eq!((b.p_min.x, b.p_max.x), (0.0, 4.0));
}

#[test]
fn denoise_makes_an_rgb_film_a_gbuffer_film() {
    let ov = FilmOverrides {
        aovs: true,
        ..Default::default()
    };
    let params = [P::I("xresolution", &[8]), P::I("yresolution", &[4])];
    let f = make("rgb", &params, &ov).expect("rgb with aovs");
    assert!(f.uses_visible_surface());
    assert_eq!(f.full_resolution(), Point2i::new(8, 4));
    // Without the override, the same film records no surface.
    let plain = make("rgb", &params, &FilmOverrides::default()).expect("rgb");
    assert!(!plain.uses_visible_surface());
    // Other films are kept.
    let s = make("spectral", &params, &ov).expect("spectral");
    assert!(!s.uses_visible_surface());
}
