//! Creation from scene text, and bump mapping with a non-constant
//! displacement.

use std::collections::HashMap;
use std::sync::Arc;

use rpbrt_geometry::float::*;
use rpbrt_geometry::interaction::SurfaceInteraction;
use rpbrt_geometry::tuple::*;
use rpbrt_parser::{Diagnostic, FileLoc, ParameterDictionary, ParsedParameter};

use super::{build, create_materials, create_textures_of};
use crate::bxdf::{BxDF, TransportMode};
use crate::image::{Image, ImageMetadata};
use crate::material::*;
use crate::scene::entities::SceneEntity;
use crate::scene::{build_scene_from_str, BuildOptions};
use crate::spectrum::SampledWavelengths;
use crate::texture::{FloatBilerpTexture, FloatTexture, FloatTextureRef, TextureMapping2D};

type Created = (MaterialSet, HashMap<String, u32>, Vec<Diagnostic>);

fn create(text: &str) -> Result<Created, Vec<Diagnostic>> {
    let s = build(text);
    let (named, _) = create_textures_of(&s).unwrap_or_else(|d| panic!("{d:?}"));
    create_materials(&s.materials, &s.named_materials, &named)
}

fn create_ok(text: &str) -> Created {
    create(text).unwrap_or_else(|d| panic!("{d:?}"))
}

/// The single error of a failed creation, as `line:col: message`.
fn create_err(text: &str) -> String {
    let diags = match create(text) {
        Ok(_) => panic!("expected an error"),
        Err(d) => d,
    };
    let errors: Vec<&Diagnostic> = diags.iter().filter(|d| d.is_error()).collect();
    assert_eq!(errors.len(), 1, "{diags:?}");
    let e = errors[0];
    let loc = e.loc.as_ref().expect("a located error");
    assert_eq!(&*loc.file, "<string>");
    format!("{}:{}: {}", loc.line, loc.column, e.message)
}

fn si() -> SurfaceInteraction {
    SurfaceInteraction::new(
        Point3fi::from(Point3f::new(0.1, 0.2, 0.0)),
        Point2f::new(0.25, 0.5),
        Vector3f::new(0.0, 0.0, 1.0),
        Vector3f::new(1.0, 0.0, 0.0),
        Vector3f::new(0.0, 1.0, 0.0),
        Normal3f::default(),
        Normal3f::default(),
        0.0,
        false,
    )
}

fn lambda() -> SampledWavelengths {
    SampledWavelengths::sample_visible(0.61)
}

fn diffuse_value(set: &MaterialSet, index: u32) -> Float {
    let b = set.get_bsdf(index, &mut si(), &mut lambda()).unwrap();
    assert!(matches!(b.bxdf, BxDF::Diffuse(_)), "{:?}", b.bxdf);
    let wi = Vector3f::new(0.2, 0.1, 0.9).normalize();
    b.f(Vector3f::new(0.0, 0.0, 1.0), wi, TransportMode::Radiance)[0] * PI
}

#[test]
fn default_material_and_indices() {
    let (set, named, warnings) = create_ok(
        "MakeNamedMaterial \"a\" \"string type\" \"diffuse\" \"spectrum reflectance\" [300 0.2 800 0.2]\n\
         Material \"conductor\"\n\
         MakeNamedMaterial \"b\" \"string type\" \"interface\"\n\
         Material \"dielectric\"\n",
    );
    assert!(warnings.is_empty(), "{warnings:?}");
    // Index 0 is the builder's default diffuse material, then the
    // anonymous ones, then the named ones in order.
    assert_eq!(set.len(), 5);
    assert!(matches!(set.get(0), Some(Material::Diffuse(_))));
    assert!(close(diffuse_value(&set, 0), 0.5));
    assert!(matches!(set.get(1), Some(Material::Conductor(_))));
    assert!(matches!(set.get(2), Some(Material::Dielectric(_))));
    assert_eq!(named["a"], 3);
    assert_eq!(named["b"], 4);
    assert!(close(diffuse_value(&set, 3), 0.2));
    assert!(set.get_bsdf(4, &mut si(), &mut lambda()).is_none());
}

fn close(a: Float, b: Float) -> bool {
    (a - b).abs() < 1e-3 * (1.0 + b.abs())
}

#[test]
fn textures_and_spectra_reach_the_material() {
    let (set, _, _) = create_ok(
        "Texture \"r\" \"spectrum\" \"constant\" \"spectrum value\" [300 0.3 800 0.3]\n\
         Texture \"half\" \"float\" \"constant\" \"float value\" 0.5\n\
         Material \"diffuse\" \"texture reflectance\" \"r\"\n\
         Material \"dielectric\" \"spectrum eta\" \"glass-BK7\"\n\
         Material \"dielectric\" \"float eta\" 1.2 \"texture roughness\" \"half\" \"bool remaproughness\" false\n\
         Material \"conductor\" \"rgb reflectance\" [0.5 0.5 0.5]\n",
    );
    assert!(close(diffuse_value(&set, 1), 0.3));

    let mut l = lambda();
    let b = set.get_bsdf(2, &mut si(), &mut l).unwrap();
    assert!(l.secondary_terminated());
    let BxDF::Dielectric(d) = b.bxdf else {
        panic!()
    };
    assert!(d.eta() > 1.49 && d.eta() < 1.54, "{}", d.eta());

    let mut l = lambda();
    let b = set.get_bsdf(3, &mut si(), &mut l).unwrap();
    assert!(!l.secondary_terminated());
    let BxDF::Dielectric(d) = b.bxdf else {
        panic!()
    };
    assert_eq!(d.eta(), 1.2);
    assert!(b.flags().is_glossy());

    let Some(Material::Conductor(c)) = set.get(4) else {
        panic!()
    };
    assert!(matches!(c.spectra, ConductorSpectra::Reflectance(_)));
}

#[test]
fn every_type_is_created_with_defaults() {
    let (set, _, warnings) = create_ok(
        "Material \"diffusetransmission\"\n\
         Material \"thindielectric\"\n\
         Material \"coateddiffuse\"\n\
         Material \"coatedconductor\"\n\
         Material \"hair\"\n\
         Material \"subsurface\"\n\
         Material \"subsurface\" \"string name\" \"Skin1\"\n\
         Material \"subsurface\" \"rgb reflectance\" [0.5 0.5 0.5]\n\
         Material \"interface\"\n\
         Material \"none\"\n",
    );
    assert!(warnings.is_empty(), "{warnings:?}");
    let names: Vec<&str> = set.materials().iter().map(Material::type_name).collect();
    assert_eq!(
        names,
        [
            "diffuse",
            "diffusetransmission",
            "thindielectric",
            "coateddiffuse",
            "coatedconductor",
            "hair",
            "subsurface",
            "subsurface",
            "subsurface",
            "interface",
            "interface"
        ]
    );
    let Some(Material::Hair(h)) = set.get(5) else {
        panic!()
    };
    assert!(matches!(h.absorption, HairAbsorption::SigmaA(_)));
    let Some(Material::Subsurface(s)) = set.get(8) else {
        panic!()
    };
    assert!(matches!(
        s.coefficients,
        SubsurfaceCoefficients::Reflectance { .. }
    ));
    assert_eq!(s.eta, 1.33);
    for i in 1..9 {
        let b = set.get_bsdf(i, &mut si(), &mut lambda());
        assert!(b.is_some(), "{i}");
    }
    assert!(set.has_subsurface(6, &si()));
    let (i, loc) = set.first_subsurface().unwrap();
    assert_eq!(i, 6);
    assert_eq!(loc.unwrap().line, 7);
    assert_eq!(set.loc(1).unwrap().line, 2);
}

fn loc(line: u32, column: u32) -> FileLoc {
    FileLoc::new(Arc::from("m.pbrt"), line, column)
}

/// A material entity with pbrt-v4's `"string materials"` (built by hand:
/// the scene builder currently runs the pbrt-v3 upgrade on every `mix`).
fn mix_entity(names: &[&str], amount: Float, line: u32) -> SceneEntity {
    let params = vec![
        ParsedParameter::with_strings(
            "string",
            "materials",
            loc(line, 10),
            names.iter().map(|s| s.to_string()).collect(),
        ),
        ParsedParameter::with_floats("float", "amount", loc(line, 40), vec![amount]),
    ];
    SceneEntity::new(
        "mix",
        ParameterDictionary::new(params),
        loc(line, 1),
        "srgb",
    )
}

fn diffuse_entity(r: Float, line: u32) -> SceneEntity {
    let params = vec![ParsedParameter::with_floats(
        "rgb",
        "reflectance",
        loc(line, 10),
        vec![r, r, r],
    )];
    SceneEntity::new(
        "diffuse",
        ParameterDictionary::new(params),
        loc(line, 1),
        "srgb",
    )
}

#[test]
fn mix_references_named_materials() {
    let named_in = vec![
        ("dark".to_string(), diffuse_entity(0.1, 1)),
        ("light".to_string(), diffuse_entity(0.9, 2)),
        ("m0".to_string(), mix_entity(&["dark", "light"], 0.0, 3)),
    ];
    let anon = vec![
        mix_entity(&["m0", "light"], 0.0, 4),
        mix_entity(&["dark", "light"], 1.0, 5),
    ];
    let (set, named, w) =
        create_materials(&anon, &named_in, &Default::default()).unwrap_or_else(|d| panic!("{d:?}"));
    assert!(w.is_empty(), "{w:?}");
    assert_eq!(named["m0"], 4);
    assert!(diffuse_value(&set, named["m0"]) < 0.2);
    assert!(diffuse_value(&set, 0) < 0.2);
    assert!(diffuse_value(&set, 1) > 0.8);
}

#[test]
fn undefined_mix_material_is_a_located_error() {
    let named_in = vec![("a".to_string(), diffuse_entity(0.5, 1))];
    let d = create_materials(
        &[mix_entity(&["a", "nope"], 0.5, 7)],
        &named_in,
        &Default::default(),
    )
    .unwrap_err();
    assert_eq!(d.len(), 1, "{d:?}");
    assert_eq!(
        d[0].to_string(),
        "m.pbrt:7:10: error: \"nope\": named material not defined"
    );
    // Through the scene builder (pbrt-v3 syntax, which it upgrades; the
    // upgraded parameter carries the directive's location).
    let e = create_err(
        "MakeNamedMaterial \"a\" \"string type\" \"diffuse\"\n\
         Material \"mix\" \"string namedmaterial1\" \"a\" \"string namedmaterial2\" \"nope\"\n",
    );
    assert_eq!(e, "3:1: \"nope\": named material not defined");
}

#[test]
fn named_mix_may_not_use_later_materials() {
    let named_in = vec![
        ("m".to_string(), mix_entity(&["a", "m"], 0.5, 1)),
        ("a".to_string(), diffuse_entity(0.5, 2)),
    ];
    let d = create_materials(&[], &named_in, &Default::default()).unwrap_err();
    assert_eq!(d.len(), 1, "{d:?}");
    assert!(d[0].to_string().starts_with("m.pbrt:1:10: error"), "{d:?}");
    assert!(d[0].message.contains("before it is defined"), "{d:?}");
    let d = create_materials(&[mix_entity(&["x"], 0.5, 3)], &[], &Default::default()).unwrap_err();
    assert!(d[0].message.contains("exactly two"), "{d:?}");
}

#[test]
fn negative_roughness_is_a_located_error() {
    let e = create_err("Material \"conductor\" \"float roughness\" -0.1\n");
    assert!(e.starts_with("2:22: "), "{e}");
    assert!(e.contains("roughness must not be negative"), "{e}");
    let e = create_err("Material \"coatedconductor\"\n  \"float conductor.vroughness\" -1\n");
    assert!(e.starts_with("3:3: "), "{e}");
    let e = create_err("Material \"dielectric\" \"float eta\" 0\n");
    assert!(e.starts_with("2:23: ") && e.contains("positive"), "{e}");
    let e = create_err("Material \"coateddiffuse\" \"integer nsamples\" 0\n");
    assert!(e.contains("nsamples"), "{e}");
}

#[test]
fn unknown_type_lists_known_names() {
    // The builder already rejects unknown types while parsing.
    let r = build_scene_from_str(
        "WorldBegin\nMaterial \"velvet\"\n",
        &BuildOptions::default(),
    );
    assert!(r.is_err());
    // Entities made elsewhere are checked again.
    let mut e = SceneEntity::default_named("velvet");
    e.loc = FileLoc::new(Arc::from("x.pbrt"), 4, 9);
    let diags = create_materials(&[e], &[], &Default::default()).unwrap_err();
    assert_eq!(diags.len(), 1);
    let d = diags[0].to_string();
    assert!(d.starts_with("x.pbrt:4:9: error"), "{d}");
    assert!(d.contains("coateddiffuse") && d.contains("velvet"), "{d}");
}

#[test]
fn measured_and_conflicting_parameters_are_errors() {
    let e = create_err("Material \"measured\" \"string filename\" \"/nonexistent/x.bsdf\"\n");
    assert!(
        e.starts_with("2:21: ") && e.contains("x.bsdf") && e.contains("unable to open"),
        "{e}"
    );
    let e = create_err("Material \"measured\"\n");
    assert!(e.starts_with("2:1: ") && e.contains("\"filename\""), "{e}");
    let e = create_err("Material \"conductor\" \"rgb reflectance\" [0.5 0.5 0.5] \"spectrum eta\" \"metal-Ag-eta\"\n");
    assert!(e.contains("can't both be given"), "{e}");
    let e = create_err("Material \"subsurface\" \"string name\" \"Jelly\"\n");
    assert!(
        e.contains("named medium not found") && e.contains("Ketchup"),
        "{e}"
    );
    let e = create_err("Material \"subsurface\" \"rgb sigma_a\" [1 1 1]\n");
    assert!(e.contains("without \"sigma_s\""), "{e}");
    let e = create_err("Material \"diffuse\" \"string normalmap\" \"/nonexistent/n.png\"\n");
    assert!(e.starts_with("2:"), "{e}");
    // Several bad materials: every error is reported.
    let d = create("Material \"conductor\" \"float roughness\" -1\nMaterial \"measured\"\n")
        .unwrap_err();
    assert_eq!(d.iter().filter(|d| d.is_error()).count(), 2);
}

#[test]
fn unused_parameters_are_warned_about() {
    let (_, _, w) = create_ok(
        "Material \"diffuse\" \"float roughnes\" 0.3\n\
         Material \"hair\" \"rgb sigma_a\" [0.5 0.5 0.5] \"float eumelanin\" 2\n",
    );
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(w[0].message.contains("roughnes") && !w[0].is_error());
    assert_eq!(w[0].loc.as_ref().unwrap().line, 2);
    assert!(w[1].message.contains("eumelanin"), "{w:?}");
}

#[test]
fn normal_map_from_scene_file() {
    let dir = std::env::temp_dir().join(format!("rpbrt-material-scene-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("tilt.pfm");
    let data: Vec<f32> = (0..4).flat_map(|_| [0.8f32, 0.5, 0.9]).collect();
    let im = Image::from_f32(data, Point2i::new(2, 2), &["R", "G", "B"]).unwrap();
    im.write(&path, &ImageMetadata::default()).unwrap();
    let text = format!(
        "Material \"diffuse\" \"string normalmap\" \"{p}\"\n\
         Material \"conductor\" \"string normalmap\" \"{p}\"\n",
        p = path.display()
    );
    let (set, _, w) = create_ok(&text);
    let _ = std::fs::remove_dir_all(&dir);
    assert!(w.is_empty(), "{w:?}");
    // Both share one image.
    let (Some(Material::Diffuse(a)), Some(Material::Conductor(b))) = (set.get(1), set.get(2))
    else {
        panic!()
    };
    assert!(Arc::ptr_eq(
        a.perturbation.normal_map.as_ref().unwrap(),
        b.perturbation.normal_map.as_ref().unwrap()
    ));
    let mut s = si();
    set.get_bsdf(1, &mut s, &mut lambda()).unwrap();
    assert!((Vector3f::from(s.shading.n) - Vector3f::new(0.6, 0.0, 0.8)).length() < 1e-4);
}

/// Displacement a·u + b·v through a bilinear texture over (u, v).
fn ramp(a: Float, b: Float) -> FloatTextureRef {
    Arc::new(FloatTexture::Bilerp(FloatBilerpTexture {
        mapping: TextureMapping2D::UV {
            su: 1.0,
            sv: 1.0,
            du: 0.0,
            dv: 0.0,
        },
        v00: 0.0,
        v10: a,
        v01: b,
        v11: a + b,
    }))
}

#[test]
fn linear_displacement_tilts_the_normal_by_the_gradient() {
    for (a, b, dudx) in [(0.5, 0.0, 0.0), (0.0, -2.0, 0.01), (1.0, 1.0, 0.003)] {
        let set = MaterialSet::new(vec![Material::Diffuse(DiffuseMaterial {
            reflectance: Arc::new(crate::texture::SpectrumTexture::Constant(
                crate::spectrum::Spectrum::constant(0.5),
            )),
            perturbation: ShadingPerturbation {
                displacement: Some(ramp(a, b)),
                normal_map: None,
            },
        })]);
        let mut s = si();
        s.dudx = dudx;
        s.dvdy = dudx * 0.5;
        set.get_bsdf(0, &mut s, &mut lambda()).unwrap();
        // Surface z = a u + b v over (u, v) = (x, y): normal ∝ (−a, −b, 1).
        let expect = Vector3f::new(-a, -b, 1.0).normalize();
        let got = Vector3f::from(s.shading.n);
        assert!(
            (got - expect).length() < 2e-3,
            "{a} {b}: {got:?} vs {expect:?}"
        );
        let angle = safe_acos(got.z);
        let analytic = (a * a + b * b).sqrt().atan();
        assert!((angle - analytic).abs() < 2e-3, "{angle} vs {analytic}");
        assert!(dot(s.shading.n, s.n) > 0.0);
    }
}

/// A minimal consistent RGL tensor file: flat tables on 2×2 grids.
fn tiny_bsdf(spectra: f32) -> Vec<u8> {
    use crate::bxdf::measured::{write_tensor_bytes, TensorField, TensorType};
    let f = |shape: &[usize], v: f32| TensorField {
        dtype: TensorType::Float32,
        shape: shape.to_vec(),
        data: (0..shape.iter().product::<usize>())
            .flat_map(|_| v.to_le_bytes())
            .collect(),
    };
    let theta = TensorField {
        data: [0.0f32, PI / 2.0]
            .iter()
            .flat_map(|x| x.to_le_bytes())
            .collect(),
        ..f(&[2], 0.0)
    };
    let u8f = |v: &[u8]| TensorField {
        dtype: TensorType::UInt8,
        shape: vec![v.len()],
        data: v.to_vec(),
    };
    let fields = [
        ("description", u8f(b"tiny")),
        ("jacobian", u8f(&[1])),
        ("theta_i", theta),
        ("phi_i", f(&[1], 0.0)),
        ("wavelengths", f(&[1], 550.0)),
        ("ndf", f(&[2, 2], 1.0)),
        ("sigma", f(&[2, 2], 1.0)),
        ("vndf", f(&[1, 2, 2, 2], 1.0)),
        ("luminance", f(&[1, 2, 2, 2], 1.0)),
        ("spectra", f(&[1, 2, 1, 2, 2], spectra)),
    ];
    let refs: Vec<(&str, &TensorField)> = fields.iter().map(|(n, x)| (*n, x)).collect();
    write_tensor_bytes(&refs)
}

#[test]
fn measured_material_from_scene_file() {
    let dir = std::env::temp_dir().join(format!("rpbrt-material-measured-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let good = dir.join("tiny.bsdf");
    std::fs::write(&good, tiny_bsdf(0.5)).unwrap();
    let bad = dir.join("bad.bsdf");
    std::fs::write(&bad, &tiny_bsdf(0.5)[..40]).unwrap();
    let text = format!(
        "Material \"measured\" \"string filename\" \"{p}\"\n\
         Material \"measured\" \"string filename\" \"{p}\"\n",
        p = good.display()
    );
    let (set, _, w) = create_ok(&text);
    assert!(w.is_empty(), "{w:?}");
    let (Some(Material::Measured(a)), Some(Material::Measured(b))) = (set.get(1), set.get(2))
    else {
        panic!()
    };
    assert!(std::ptr::eq(a.data, b.data), "data are shared per file");
    let mut s = si();
    let bsdf = set.get_bsdf(1, &mut s, &mut lambda()).unwrap();
    assert!(matches!(bsdf.bxdf, BxDF::Measured(_)));
    let wo = Vector3f::from(s.shading.n);
    let f = bsdf.f(wo, wo, TransportMode::Radiance);
    assert!(f[0] > 0.0 && f[0].is_finite(), "{f:?}");
    let e = create_err(&format!(
        "Material \"measured\" \"string filename\" \"{}\"\n",
        bad.display()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    assert!(e.starts_with("2:21: ") && e.contains("truncated"), "{e}");
}
