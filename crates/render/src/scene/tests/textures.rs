//! Textures created from scene text: image textures read from files next
//! to the scene, references between textures, located errors, and the
//! texture-or-value lookups materials make.

use std::path::PathBuf;
use std::sync::Arc;

use rpbrt_geometry::float::Float;
use rpbrt_geometry::tuple::*;
use rpbrt_parser::{Diagnostic, FileLoc, ParameterDictionary, ParsedParameter};

use super::{build, create_textures_of};
use crate::image::{ColorEncoding, Image, ImageMetadata};
use crate::params::ParamReader;
use crate::spectrum::{
    cie, RgbColorSpace, SampledSpectrum, SampledWavelengths, Spectrum, SpectrumType, RGB, XYZ,
};
use crate::texture::*;

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rpbrt-texture-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn create(text: &str) -> Result<(NamedTextures, Vec<Diagnostic>), Vec<Diagnostic>> {
    create_textures_of(&build(text))
}

fn create_ok(text: &str) -> NamedTextures {
    match create(text) {
        Ok((n, _)) => n,
        Err(d) => panic!("{d:?}"),
    }
}

/// The single error of a failed creation.
fn create_err(text: &str) -> Diagnostic {
    let errs: Vec<Diagnostic> = create(text)
        .expect_err("creation should fail")
        .into_iter()
        .filter(|d| d.is_error())
        .collect();
    assert_eq!(errs.len(), 1, "{errs:?}");
    errs.into_iter().next().unwrap()
}

/// 1-based line and column of the first occurrence of `needle`, in the
/// scene [`scene`] builds (one `WorldBegin` line first).
fn pos_of(text: &str, needle: &str) -> (u32, u32) {
    let at = text.find(needle).expect("needle");
    let line = text[..at].matches('\n').count() as u32 + 2;
    let col = (at - text[..at].rfind('\n').map_or(0, |i| i + 1)) as u32 + 1;
    (line, col)
}

fn assert_at(d: &Diagnostic, text: &str, needle: &str) {
    let loc = d.loc.as_ref().expect("located");
    assert_eq!((loc.line, loc.column), pos_of(text, needle), "{d:?}");
}

/// A one-channel 4x2 image: pixel (x, y) has value 10y + x + 2/3.
fn write_pfm(dir: &std::path::Path) -> PathBuf {
    let (w, h) = (4, 2);
    let mut data = Vec::new();
    for y in 0..h {
        for x in 0..w {
            data.push((10 * y + x) as f32 + 2.0 / 3.0);
        }
    }
    let img = Image::from_f32(data, Point2i { x: w, y: h }, &["Y"]).unwrap();
    let path = dir.join("grid.pfm");
    img.write(&path, &ImageMetadata::default()).unwrap();
    path
}

#[test]
fn float_imagemap_texel_centres_orientation_wrap_scale_invert() {
    let dir = temp_dir("float");
    let path = write_pfm(&dir);
    let p = path.display();
    let text = format!(
        r#"Texture "rep" "float" "imagemap" "string filename" "{p}"
Texture "pt" "float" "imagemap" "string filename" "{p}" "string filter" "point" "string wrap" "clamp"
Texture "blk" "float" "imagemap" "string filename" "{p}" "string wrap" "black"
Texture "sc" "float" "imagemap" "string filename" "{p}" "float scale" 0.5
Texture "inv" "float" "imagemap" "string filename" "{p}" "bool invert" true
Texture "sc2" "float" "scale" "texture tex" "rep" "float scale" 2
"#
    );
    let named = create_ok(&text);
    let get = |n: &str, u: Float, v: Float| named.float[n].evaluate(&uv_ctx(u, v, 0.0));
    let value = |x: i32, y: i32| (10 * y + x) as Float + 2.0 / 3.0;
    for y in 0..2 {
        for x in 0..4 {
            let u = (x as Float + 0.5) / 4.0;
            // v = 0 is the bottom row of the image (its last row).
            let v = 1.0 - (y as Float + 0.5) / 2.0;
            for n in ["rep", "pt", "blk"] {
                assert!(
                    (get(n, u, v) - value(x, y)).abs() < 1e-4,
                    "{n} ({x},{y}): {}",
                    get(n, u, v)
                );
            }
            assert!((get("sc", u, v) - 0.5 * value(x, y)).abs() < 1e-4);
            assert!((get("sc2", u, v) - 2.0 * value(x, y)).abs() < 1e-4);
            assert_eq!(get("inv", u, v), (1.0 - value(x, y)).max(0.0));
        }
    }
    assert!((get("inv", 0.125, 0.75) - (1.0 - value(0, 0))).abs() < 1e-6);
    // The bottom-left corner of texture space is the image's bottom row.
    assert!((get("pt", 0.125, 0.25) - value(0, 1)).abs() < 1e-4);
    // Wrap modes outside [0, 1].
    assert!((get("rep", 1.125, 0.75) - value(0, 0)).abs() < 1e-4);
    assert!((get("pt", 1.875, 0.75) - value(3, 0)).abs() < 1e-4);
    assert!((get("pt", -3.0, 0.75) - value(0, 0)).abs() < 1e-4);
    assert_eq!(get("blk", 1.625, 0.75), 0.0);
    // A constant scale folds into the image texture.
    assert!(matches!(&*named.float["sc2"], FloatTexture::Image(_)));
}

#[test]
fn png_encodings() {
    let dir = temp_dir("png");
    let img = Image::from_u8(
        vec![128u8; 4],
        Point2i { x: 2, y: 2 },
        &["Y"],
        ColorEncoding::Linear,
    )
    .unwrap();
    let path = dir.join("grey.png");
    img.write(&path, &ImageMetadata::default()).unwrap();
    let p = path.display();
    let text = format!(
        r#"Texture "def" "float" "imagemap" "string filename" "{p}"
Texture "lin" "float" "imagemap" "string filename" "{p}" "string encoding" "linear"
Texture "gam" "float" "imagemap" "string filename" "{p}" "string encoding" "gamma 2.2"
"#
    );
    let named = create_ok(&text);
    let get = |n: &str| named.float[n].evaluate(&uv_ctx(0.25, 0.25, 0.0));
    let x: Float = 128.0 / 255.0;
    let srgb = ((x + 0.055) / 1.055).powf(2.4);
    assert!((get("def") - srgb).abs() < 2e-3, "{}", get("def"));
    assert!((get("lin") - x).abs() < 2e-3, "{}", get("lin"));
    assert!((get("gam") - x.powf(2.2)).abs() < 2e-3, "{}", get("gam"));
}

fn reflected_rgb(cs: &RgbColorSpace, s: &Spectrum) -> RGB {
    let illum = cs.illuminant_spectrum();
    let (mut xyz, mut y_illum) = ([0.0f64; 3], 0.0f64);
    for l in 360..=830 {
        let lf = l as Float;
        let m = cie::xyz_matching(lf);
        let e = illum.evaluate(lf) as f64;
        let v = s.evaluate(lf) as f64;
        for c in 0..3 {
            xyz[c] += m[c] as f64 * e * v;
        }
        y_illum += m[1] as f64 * e;
    }
    cs.to_rgb(XYZ::new(
        (xyz[0] / y_illum) as Float,
        (xyz[1] / y_illum) as Float,
        (xyz[2] / y_illum) as Float,
    ))
}

#[test]
fn spectrum_imagemap_round_trips_rgb() {
    let dir = temp_dir("spec");
    let img = Image::from_f32(
        vec![0.2, 0.5, 0.7, 2.0, 0.5, 0.25],
        Point2i { x: 2, y: 1 },
        &["R", "G", "B"],
    )
    .unwrap();
    let path = dir.join("two.pfm");
    img.write(&path, &ImageMetadata::default()).unwrap();
    let text = format!(
        "Texture \"im\" \"spectrum\" \"imagemap\" \"string filename\" \"{}\"\n",
        path.display()
    );
    let named = create_ok(&text);
    let cs = RgbColorSpace::srgb();
    let spec = |ty: SpectrumType, u: Float| match &*named.spectrum(ty)["im"] {
        SpectrumTexture::Image(t) => {
            assert_eq!(t.spectrum_type, ty);
            t.spectrum(&uv_ctx(u, 0.5, 0.0))
        }
        other => panic!("{other:?}"),
    };
    let rgb = reflected_rgb(cs, &spec(SpectrumType::Albedo, 0.25));
    for (a, b) in rgb.to_array().iter().zip([0.2, 0.5, 0.7]) {
        assert!((a - b).abs() < 1e-2, "{rgb:?}");
    }
    // Albedo clamps to 1; unbounded keeps the value.
    let clamped = reflected_rgb(cs, &spec(SpectrumType::Albedo, 0.75));
    assert!((clamped.r - 1.0).abs() < 3e-2, "{clamped:?}");
    let unb = reflected_rgb(cs, &spec(SpectrumType::Unbounded, 0.75));
    for (a, b) in unb.to_array().iter().zip([2.0, 0.5, 0.25]) {
        assert!((a - b).abs() < 2e-2, "{unb:?}");
    }
    // Sampled evaluation agrees with the spectrum.
    let lambda = SampledWavelengths::sample_visible(0.3);
    let s = named.albedo["im"].evaluate(&uv_ctx(0.25, 0.5, 0.0), &lambda);
    let direct = spec(SpectrumType::Albedo, 0.25).sample(&lambda);
    assert_eq!(s, direct);
}

#[test]
fn spectrum_textures_reference_float_and_spectrum_textures() {
    let text = r#"Texture "amt" "float" "constant" "float value" 0.25
Texture "red" "spectrum" "constant" "rgb value" [0.8 0.1 0.1]
Texture "mixed" "spectrum" "mix" "texture tex1" "red" "rgb tex2" [0.1 0.1 0.8] "texture amount" "amt"
Texture "chk" "spectrum" "checkerboard" "texture tex1" "mixed" "float uscale" 4 "float bogus" 1
"#;
    let (named, warnings) = create(text).unwrap();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].message.contains("bogus"));
    assert_at(&warnings[0], text, "\"float bogus\"");
    for ty in [
        SpectrumType::Albedo,
        SpectrumType::Unbounded,
        SpectrumType::Illuminant,
    ] {
        assert!(named.spectrum(ty).contains_key("chk"));
    }
    let lambda = SampledWavelengths::sample_visible(0.5);
    let ctx = uv_ctx(0.1, 0.1, 0.0);
    let v = named.albedo["mixed"].evaluate(&ctx, &lambda);
    let red = named.albedo["red"].evaluate(&ctx, &lambda);
    let blue = Spectrum::RgbAlbedo(crate::spectrum::RgbAlbedoSpectrum::new(
        RgbColorSpace::srgb(),
        RGB::new(0.1, 0.1, 0.8),
    ))
    .sample(&lambda);
    let expect = red * 0.75 + blue * 0.25;
    for i in 0..4 {
        assert!((v[i] - expect[i]).abs() < 1e-5);
    }
    assert_eq!(named.albedo["chk"].evaluate(&ctx, &lambda), v);
    // Illuminant versions are different spectra.
    assert_ne!(named.illuminant["red"].evaluate(&ctx, &lambda), red);
}

#[test]
fn creation_errors_are_located() {
    let text = "Texture \"a\" \"float\" \"scale\" \"texture tex\" \"nope\"\n";
    let e = create_err(text);
    assert!(
        e.message.contains("\"nope\"") && e.message.contains("float texture"),
        "{e:?}"
    );
    assert_at(&e, text, "\"texture tex\"");

    let text = "Texture \"s\" \"spectrum\" \"constant\"\nTexture \"a\" \"float\" \"mix\" \"texture amount\" \"s\"\n";
    let e = create_err(text);
    assert!(e.message.contains("is a spectrum texture"), "{e:?}");
    assert_at(&e, text, "\"texture amount\"");

    let text = "Texture \"f\" \"float\" \"constant\"\nTexture \"s\" \"spectrum\" \"scale\" \"texture tex\" \"f\"\n";
    let e = create_err(text);
    assert!(e.message.contains("is a float texture"), "{e:?}");
    assert_at(&e, text, "\"texture tex\"");

    let text = "Texture \"i\" \"spectrum\" \"imagemap\"\n  \"string filename\" \"/nonexistent/dir/missing.png\"\n";
    let e = create_err(text);
    assert!(
        e.message.contains("missing.png") && e.message.contains("\"i\""),
        "{e:?}"
    );
    assert_at(&e, text, "\"string filename\"");

    let text = "Texture \"b\" \"float\" \"bilerp\" \"string mapping\" \"spherica\"\n";
    let e = create_err(text);
    assert!(
        e.message.contains("spherica") && e.message.contains("cylindrical"),
        "{e:?}"
    );
    assert_at(&e, text, "\"string mapping\"");

    let text = "Texture \"p\" \"float\" \"ptex\" \"string filename\" \"/nonexistent/dir/x.ptx\"\n";
    let e = create_err(text);
    assert!(
        e.message.contains("x.ptx") && e.message.contains("\"p\""),
        "{e:?}"
    );
    assert_at(&e, text, "\"string filename\"");

    let dir = temp_dir("errs");
    let path = write_pfm(&dir);
    let text = format!(
        "Texture \"w\" \"float\" \"imagemap\" \"string filename\" \"{}\" \"string wrap\" \"mirror\"\n",
        path.display()
    );
    let e = create_err(&text);
    assert!(
        e.message.contains("mirror") && e.message.contains("octahedralsphere"),
        "{e:?}"
    );
    assert_at(&e, &text, "\"string wrap\"");

    let text = "Texture \"c\" \"float\" \"checkerboard\" \"integer dimension\" 4\n";
    let e = create_err(text);
    assert_at(&e, text, "\"integer dimension\"");
}

#[test]
fn material_facing_lookups() {
    let text = "Texture \"f\" \"float\" \"constant\" \"float value\" 0.3\nTexture \"s\" \"spectrum\" \"constant\" \"rgb value\" [0.5 0.5 0.5]\n";
    let named = create_ok(text);
    let loc = FileLoc::new(Arc::from("m.pbrt"), 3, 5);
    let dict = ParameterDictionary::new(vec![
        ParsedParameter::with_strings("texture", "roughness", loc.clone(), vec!["f".into()]),
        ParsedParameter::with_floats("float", "eta", loc.clone(), vec![1.5]),
        ParsedParameter::with_strings("texture", "reflectance", loc.clone(), vec!["s".into()]),
        ParsedParameter::with_floats("rgb", "tint", loc.clone(), vec![0.2, 0.4, 0.6]),
        ParsedParameter::with_strings("texture", "bad", loc.clone(), vec!["zzz".into()]),
    ]);
    let ctx = TextureEvalContext::default();
    let tp = TextureParams::new(ParamReader::plain(&dict, &loc), &named);
    let r = tp.float_texture("roughness", 0.0).unwrap();
    assert_eq!(r.evaluate(&ctx), 0.3);
    let eta = tp.float_texture("eta", 1.0).unwrap();
    assert_eq!(eta.evaluate(&ctx), 1.5);
    assert_eq!(tp.float_texture("absent", 7.0).unwrap().evaluate(&ctx), 7.0);
    assert!(tp.float_texture_opt("absent").unwrap().is_none());
    let e = tp.float_texture("bad", 0.0).unwrap_err();
    assert_eq!(e.loc.as_ref().map(|l| (l.line, l.column)), Some((3, 5)));
    let lambda = SampledWavelengths::sample_visible(0.5);
    let s = tp
        .spectrum_texture_opt("reflectance", SpectrumType::Albedo)
        .unwrap()
        .unwrap();
    assert!(Arc::ptr_eq(&s, &named.albedo["s"]));
    let tint = tp
        .spectrum_texture_opt("tint", SpectrumType::Unbounded)
        .unwrap()
        .unwrap();
    let v = tint.evaluate(&ctx, &lambda);
    assert!(v.min_component_value() > 0.0);
    assert!(tp
        .spectrum_texture_opt("none", SpectrumType::Albedo)
        .unwrap()
        .is_none());
    let d = tp
        .spectrum_texture("none", Spectrum::constant(0.5), SpectrumType::Albedo)
        .unwrap();
    assert_eq!(d.evaluate(&ctx, &lambda), SampledSpectrum::new(0.5));
    // A float parameter where a spectrum is wanted is a located error.
    assert!(tp
        .spectrum_texture_opt("eta", SpectrumType::Albedo)
        .is_err());
}

fn uv_ctx(u: Float, v: Float, d: Float) -> TextureEvalContext {
    TextureEvalContext {
        uv: Point2f::new(u, v),
        dudx: d,
        dvdy: d,
        ..Default::default()
    }
}

/// pbrt-v3's `"scale"` of two colour textures renders their product (rpbrt's
/// `"tex2"` factor; pbrt-v4 cannot express it and `--upgrade` refuses it).
#[test]
fn pbrt_v3_scale_of_two_textures_is_their_product() {
    let n = create_ok(
        "Texture \"a\" \"color\" \"constant\" \"color value\" [0.5 0.25 1]\n\
         Texture \"b\" \"color\" \"checkerboard\" \"color tex1\" [0.2 0.4 0.6] \"color tex2\" [1 0.5 0]\n\
         Texture \"p\" \"color\" \"scale\" \"texture tex1\" \"a\" \"texture tex2\" \"b\"\n",
    );
    let tex = |name: &str| n.albedo.get(name).cloned().expect(name);
    let (a, b, p) = (tex("a"), tex("b"), tex("p"));
    assert!(matches!(&*p, SpectrumTexture::Product(_)), "{p:?}");
    let lambda = SampledWavelengths::sample_visible(0.5);
    let mut differs = false;
    for (u, v) in [(0.1, 0.1), (0.6, 0.1), (0.1, 0.6), (0.7, 0.8)] {
        let ctx = uv_ctx(u, v, 0.0);
        let (va, vb) = (a.evaluate(&ctx, &lambda), b.evaluate(&ctx, &lambda));
        let want = va * vb;
        let got = p.evaluate(&ctx, &lambda);
        assert_eq!(got.values, want.values, "({u}, {v})");
        differs |= want.values != va.values;
    }
    assert!(differs, "the second factor changes nothing: test too weak");
}
