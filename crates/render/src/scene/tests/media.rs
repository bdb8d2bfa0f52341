//! Media created from scene text: `MakeNamedMedium` directives through
//! the builder to `create_medium`, pbrt-v3's `heterogeneous`, and located
//! errors for bad grids.

use crate::medium::*;
use crate::params::ParamReader;
use crate::scene::{build_scene_from_str, BuildOptions};
use crate::spectrum::{RgbColorSpace, RgbUnboundedSpectrum, SampledWavelengths, Spectrum, RGB};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::tuple::*;
use rpbrt_parser::Diagnostic;

fn lambda(u: Float) -> SampledWavelengths {
    SampledWavelengths::sample_visible(u)
}

/// The first medium of scene text (placed after `WorldBegin`, so line 1
/// is the text's first line), created.
fn create(text: &str) -> Result<(Medium, Vec<Diagnostic>), Diagnostic> {
    let full = format!("WorldBegin\n{text}");
    let (desc, _) = match build_scene_from_str(&full, &BuildOptions::default()) {
        Ok(d) => d,
        Err(d) => return Err(d.items.into_iter().next().expect("a diagnostic")),
    };
    let e = &desc.media[0];
    let cs = RgbColorSpace::get(e.base.color_space).unwrap();
    let r = ParamReader::with_color_space(&e.base.params, &e.base.loc, cs);
    let m = create_medium(&e.base.name, &r, &e.render_from_object.start_transform())?;
    // The scene's medium loop reads the type the builder put back.
    let _ = r.string("type", "");
    Ok((m, r.finish()))
}

#[test]
fn media_are_created_from_scene_text() {
    let l = lambda(0.4);
    let (m, w) = create(
        "MakeNamedMedium \"smoke\" \"string type\" \"uniformgrid\"\n\
         \"float density\" [0 1 2 3 4 5 6 7] \"integer nx\" 2 \"integer ny\" 2 \"integer nz\" 2\n\
         \"rgb sigma_a\" [1 1 1] \"spectrum sigma_s\" [300 2 800 2] \"float scale\" 0.5\n\
         \"float g\" 0.2 \"point3 p0\" [-1 -1 -1] \"point3 p1\" [1 1 1] \"float Lescale\" [2]\n",
    )
    .unwrap();
    assert!(w.is_empty(), "{w:?}");
    let Medium::UniformGrid(g) = &m else {
        panic!("{m:?}")
    };
    assert!(!g.is_emissive());
    // The centre of sample (1, 1, 1) has density 7.
    let mp = m.sample_point(Point3f::new(0.5, 0.5, 0.5), &l);
    assert!(
        (mp.sigma_s[0] - 0.5 * 2.0 * 7.0).abs() < 1e-4,
        "{:?}",
        mp.sigma_s
    );
    assert_eq!(mp.phase.g, 0.2);

    let (m, w) = create(
        "ColorSpace \"rec2020\"\nMakeNamedMedium \"c\" \"string type\" \"rgbgrid\"\n\
         \"rgb sigma_a\" [1 0 0  0 1 0] \"rgb Le\" [0 0 1  1 1 1] \"integer nx\" 2\n",
    )
    .unwrap();
    assert!(w.is_empty(), "{w:?}");
    assert!(matches!(m, Medium::RgbGrid(_)) && m.is_emissive());
    let cs = RgbColorSpace::get("rec2020").unwrap();
    let mp = m.sample_point(Point3f::new(0.25, 0.5, 0.5), &l);
    let expected =
        Spectrum::RgbUnbounded(RgbUnboundedSpectrum::new(cs, RGB::new(1.0, 0.0, 0.0))).sample(&l);
    assert!((mp.sigma_a[0] - expected[0]).abs() < 1e-4);

    let (m, _) = create("MakeNamedMedium \"sky\" \"string type\" \"cloud\" \"float density\" 0.5 \"float frequency\" 2\n").unwrap();
    assert!(matches!(m, Medium::Cloud(_)) && !m.is_emissive());
}

#[test]
fn pbrt_v3_heterogeneous_media_read_as_uniform_grids() {
    let l = lambda(0.1);
    let (m, w) = create(
        "MakeNamedMedium \"smoke\" \"string type\" \"heterogeneous\"\n\
         \"integer nx\" 1 \"integer ny\" 1 \"integer nz\" 1 \"float density\" [ 2 ]\n\
         \"point p0\" [ 0 0 0 ] \"point p1\" [ 2 2 2 ] \"float scale\" 3\n",
    )
    .unwrap();
    assert!(w.is_empty(), "{w:?}");
    let Medium::UniformGrid(_) = &m else {
        panic!("{m:?}")
    };
    // pbrt-v3's default σs, (2.55, 3.21, 3.77), times scale and density.
    let s = Spectrum::RgbUnbounded(RgbUnboundedSpectrum::new(
        RgbColorSpace::srgb(),
        RGB::new(2.55, 3.21, 3.77),
    ));
    let mp = m.sample_point(Point3f::new(1.0, 1.0, 1.0), &l);
    let expected = s.sample(&l) * (3.0 * 2.0);
    assert!(
        (mp.sigma_s[0] - expected[0]).abs() < 1e-3 * expected[0],
        "{:?} vs {expected:?}",
        mp.sigma_s
    );
}

#[test]
fn bad_grid_media_are_located_errors() {
    let grid = |extra: &str| {
        format!("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\"\n\"float density\" [1 2]\n\"integer nx\" 2\n{extra}\n")
    };
    let rgb = |extra: &str| format!("MakeNamedMedium \"m\" \"string type\" \"rgbgrid\"\n{extra}\n");
    // (text, line of the error, part of its message)
    let cases: Vec<(String, u32, &str)> = vec![
        (grid("\"integer ny\" 2"), 2, "expected nx*ny*nz"),
        ("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\"\n\"integer nx\" 2\n".into(), 1, "no \"density\""),
        (grid("\"integer ny\" 0"), 4, "\"ny\" must be positive"),
        (grid("\"integer nz\" -3"), 4, "\"nz\" must be positive"),
        (grid("\"integer ny\" 65536\n\"integer nz\" 65536"), 5, "too large"),
        (grid("\"integer ny\" 2147483647\n\"integer nz\" 2147483647"), 5, "too large"),
        (grid("\"float temperature\" [1 2 3]"), 4, "different number of samples"),
        (grid("\"float temperature\" [1000 1200]\n\"rgb Le\" [1 1 1]"), 5, "both \"Le\" and \"temperature\""),
        ("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\"\n\"float density\" [1 -2]\n\"integer nx\" 2\n".into(), 2, "non-negative"),
        ("MakeNamedMedium \"m\" \"string type\" \"uniformgrid\"\n\"float density\" [1 1e39]\n\"integer nx\" 2\n".into(), 2, ""),
        (grid("\"float temperature\" [1000 -5]"), 4, "non-negative"),
        (grid("\"float Lescale\" [1 2 3]"), 4, "\"Lescale\""),
        (grid("\"rgb sigma_a\" [1 -1 1]"), 4, "negative"),
        (grid("\"float scale\" -1"), 4, "\"scale\""),
        (grid("\"float g\" 1e39"), 4, ""),
        (grid("\"point3 p1\" [1 0 1]"), 4, "grid with zero-size bounds"),
        (grid("\"point3 p0\" [2 2 2]\n\"point3 p1\" [2 3 3]"), 5, "grid with zero-size bounds"),
        (grid("\"point3 p0\" [0 2 0]"), 4, "inverted"),
        (grid("\"point3 p0\" [0 1e39 0]"), 4, ""),
        (grid("\"float temperaturescale\" 1e39"), 4, ""),
        (rgb("\"integer nx\" 2"), 1, "requires \"sigma_a\" and/or \"sigma_s\""),
        (rgb("\"rgb sigma_a\" [1 1 1  2 2 2]\n\"rgb sigma_s\" [1 1 1]"), 3, "different number of samples"),
        (rgb("\"rgb sigma_s\" [1 1 1]\n\"rgb Le\" [1 1 1]"), 3, "requires \"sigma_a\" if \"Le\""),
        (rgb("\"rgb sigma_a\" [1 1 1  2 2 2]\n\"rgb Le\" [1 1 1]\n\"integer nx\" 2"), 3, "expected 2 values for \"Le\""),
        (rgb("\"rgb sigma_a\" [1 1 1  2 2 2]"), 2, "expected nx*ny*nz"),
        (rgb("\"rgb sigma_a\" [1 1 1  2 2]"), 2, "multiple of 3"),
        (rgb("\"rgb sigma_s\" [1 1 1]\n\"integer ny\" 0"), 3, "must be positive"),
        (rgb("\"rgb sigma_s\" [1 1 1]\n\"point3 p1\" [0 1 1]"), 3, "grid with zero-size bounds"),
        ("MakeNamedMedium \"m\" \"string type\" \"cloud\"\n\"float density\" 1e39\n".into(), 2, ""),
        ("MakeNamedMedium \"m\" \"string type\" \"cloud\"\n\"point3 p1\" [1 1 0]\n".into(), 2, "grid with zero-size bounds"),
    ];
    for (text, line, message) in cases {
        let e = match create(&text) {
            Ok((m, _)) => panic!("no error for\n{text}\ngot {m:?}"),
            Err(e) => e,
        };
        assert!(e.is_error(), "{text}: {e:?}");
        let at = e.loc.as_ref().map(|l| l.line);
        assert_eq!(at, Some(line + 1), "{text}: {}", e.message);
        assert!(e.message.contains(message), "{text}: {}", e.message);
    }
}
