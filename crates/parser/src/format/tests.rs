//! Tests of the formatter: canonical layout, float round trips, idempotence
//! and the pbrt-v3 upgrade of a small scene.
use super::*;
use crate::driver::parse_string;
use crate::tokenizer::parse_f32;

fn format(text: &str, upgrade: bool) -> (String, crate::diag::Diagnostics) {
    let mut f = FormattingTarget::new(upgrade);
    let d = match parse_string(text, &mut f) {
        Ok(d) | Err(d) => d,
    };
    (f.into_output(), d)
}

const EVERY_DIRECTIVE: &str = r#"# a comment
Option "bool disablepixeljitter" true
Option "string seed" "x \"y\""
ColorSpace "srgb"
LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" 45.000
Film "rgb" "integer xresolution" [ 64 ] "string filename" "out\t.exr"
Sampler "halton" "integer pixelsamples" 16
PixelFilter "gaussian" "float sigma" 0.1
Accelerator "bvh"
Integrator "volpath" "integer maxdepth" 5 "bool regularize" "false"
TransformTimes 0 1
ActiveTransform EndTime Translate 1 2 3 ActiveTransform StartTime Scale 2 2 2
ActiveTransform All
Rotate 90 0 0 1
Identity
ConcatTransform [ 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1 ]
Transform [ 2 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1 ]
CoordinateSystem "cam"
CoordSysTransform "cam"
MakeNamedMedium "fog" "string type" "homogeneous" "spectrum sigma_a" [ 300 .1 800 .2 ]
WorldBegin
MediumInterface "fog"
Attribute "shape" "float radius" 2
Texture "checks" "spectrum" "checkerboard" "rgb tex1" [1 1 1] "float uscale" 1e-7
MakeNamedMaterial "red" "string type" "diffuse" "rgb reflectance" [ 1 0 0 ]
NamedMaterial "red"
Material "conductor" "spectrum eta" "metal-Cu-eta" "spectrum k" "metal-Cu-k"
AttributeBegin
  ReverseOrientation
  AreaLightSource "diffuse" "blackbody L" 6500 "float scale" 3.4028235e38
  Shape "sphere" "float radius" 0.30000001192092896
  AttributeBegin
    Shape "disk" "normal N" [0 0 1] "normal3 M" [0 1 0]
  AttributeEnd
AttributeEnd
TransformBegin
  Translate 0 0 1
TransformEnd
LightSource "point" "point3 from" [0 1 0]
ObjectBegin "thing"
  Shape "trianglemesh" "point3 P" [0 0 0 1 0 0 0 1 0 1 1 0 2 2 2]
    "integer indices" [0 1 2 2 1 3 0 1 2 3 3 3 1 1 1]
    "string names" ["a" "b" "c" "d" "e"]
ObjectEnd
ObjectInstance "thing"
Include "other.pbrt"
Import "geometry.pbrt"
WorldEnd
"#;

#[test]
fn format_is_canonical_and_idempotent() {
    let (f1, d1) = format(EVERY_DIRECTIVE, false);
    assert!(!d1.has_errors(), "{d1}");
    let (f2, d2) = format(&f1, false);
    assert!(!d2.has_errors(), "{d2}");
    assert_eq!(f1, f2);
    let expected_fragments = [
        "Option \"bool disablepixeljitter\" true\n",
        "Option \"string seed\" \"x \\\"y\\\"\"\n",
        "LookAt 0 0 5\n       0 0 0\n       0 1 0\n",
        "Camera \"perspective\"\n    \"float fov\" [ 45 ]\n",
        "    \"string filename\" [ \"out\\t.exr\" ]\n",
        "    \"bool regularize\" [ false ]\n",
        "ActiveTransform EndTime\nTranslate 1 2 3\n",
        "\nWorldBegin\n\n",
        "    \"float uscale\" [ 1e-7 ]\n",
        "AttributeBegin\n    ReverseOrientation\n",
        "        \"float scale\" [ 3.4028235e38 ]\n",
        "        \"float radius\" [ 0.3 ]\n",
        "    AttributeBegin\n        Shape \"disk\"\n            \"normal N\" [ 0 0 1 ]\n            \"normal3 M\" [ 0 1 0 ]\n    AttributeEnd\nAttributeEnd\n",
        "TransformBegin\n    Translate 0 0 1\nTransformEnd\n",
        "ObjectBegin \"thing\"\n    Shape \"trianglemesh\"\n        \"point3 P\" [\n            0 0 0 1 0 0 0 1 0 1 1 0\n            2 2 2\n        ]\n",
        "        \"string names\" [\n            \"a\" \"b\" \"c\" \"d\"\n            \"e\"\n        ]\nObjectEnd\n",
        "Include \"other.pbrt\"\nImport \"geometry.pbrt\"\n",
    ];
    for frag in expected_fragments {
        assert!(f1.contains(frag), "missing {frag:?} in\n{f1}");
    }
    assert!(!f1.contains("WorldEnd"));
}

#[test]
fn floats_print_shortest_and_round_trip() {
    assert_eq!(format_float(1.0), "1");
    assert_eq!(format_float(-0.0), "-0");
    assert_eq!(format_float(0.1), "0.1");
    assert_eq!(format_float(1e-7), "1e-7");
    assert_eq!(format_float(1e30), "1e30");
    let mut x: u32 = 0x1234_5679;
    for _ in 0..100_000 {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        let v = f32::from_bits(x);
        if !v.is_finite() {
            continue;
        }
        let s = format_float(v);
        assert_eq!(
            parse_f32(s.as_bytes()).map(f32::to_bits),
            Some(v.to_bits()),
            "{s}"
        );
    }
}

const V3_SCENE: &str = r#"Film "image" "string filename" "v3.exr" "float scale" 2
Sampler "lowdiscrepancy" "integer pixelsamples" 8
Integrator "directlighting"
PixelFilter "gaussian" "float xwidth" 2 "float alpha" 2
Camera "environment"
MakeNamedMedium "smoke" "string type" "heterogeneous" "integer nx" 2 "float density" [0.5 1] "color sigma_s" [1 1 1]
WorldBegin
LightSource "infinite" "string mapname" "sky.exr" "color L" [2 2 2] "color scale" [0.5 0.5 0.5]
TransformBegin
  Translate 0 1 0
  LightSource "point" "blackbody I" [5500 10]
TransformEnd
Texture "grid" "color" "imagemap" "string filename" "g.png" "bool trilinear" "true" "float gamma" 2.2
Material "matte" "color Kd" [0.5 0.5 0.5] "texture bumpmap" "bumps"
Material "plastic" "color Kd" [0.5 0.5 0.5] "color Ks" [0 0 0] "float roughness" 0.1
Material "mirror"
Material "glass" "float index" 1.5
MakeNamedMaterial "a" "string type" "metal"
MakeNamedMaterial "m" "string type" "mix" "string namedmaterial1" "a" "string namedmaterial2" "b" "color amount" [0.2 0.4 0.6]
AttributeBegin
  AreaLightSource "area" "color L" [4 4 4] "integer nsamples" 4
  Shape "trianglemesh" "point P" [0 0 0 1 0 0 0 1 0] "integer indices" [0 1 2] "float uv" [0 0 1 0 0 1] "vector S" [1 0 0 1 0 0 1 0 0]
AttributeEnd
WorldEnd
"#;

#[test]
fn upgrades_a_small_v3_scene() {
    let (out, diags) = format(V3_SCENE, true);
    assert!(!diags.has_errors(), "{diags}");
    for frag in [
        "Film \"rgb\"\n    \"float iso\" [ 200 ]\n    \"string filename\" [ \"v3.exr\" ]\n",
        "Sampler \"paddedsobol\"\n",
        "Integrator \"path\"\n    \"integer maxdepth\" [ 1 ]\n",
        "PixelFilter \"gaussian\"\n    \"float xradius\" [ 2 ]\n    \"float sigma\" [ 0.5 ]\n",
        "Camera \"spherical\"\n    \"string mapping\" [ \"equirectangular\" ]\n",
        "MakeNamedMedium \"smoke\"\n    \"string type\" [ \"uniformgrid\" ]\n    \"rgb sigma_a\" [ 0.0011 0.0024 0.014 ]\n    \"integer nx\" [ 2 ]\n",
        "LightSource \"infinite\"\n    \"string filename\" [ \"sky.exr\" ]\n",
        "AttributeBegin\n    Translate 0 1 0\n    LightSource \"point\"\n        \"float scale\" [ 10 ]\n        \"blackbody I\" [ 5500 ]\nAttributeEnd\n",
        "Texture \"grid\" \"spectrum\" \"imagemap\"\n    \"string filter\" [ \"trilinear\" ]\n    \"string encoding\" [ \"gamma 2.2\" ]\n",
        "Material \"diffuse\"\n    \"rgb reflectance\" [ 0.5 0.5 0.5 ]\n    \"texture displacement\" [ \"bumps\" ]\n",
        "Material \"diffuse\"\n    \"rgb reflectance\" [ 0.5 0.5 0.5 ]\n",
        "Material \"conductor\"\n    \"float roughness\" [ 0 ]\n    \"rgb reflectance\" [ 0.9 0.9 0.9 ]\n",
        "Material \"dielectric\"\n    \"float eta\" [ 1.5 ]\n",
        "MakeNamedMaterial \"a\"\n    \"string type\" [ \"conductor\" ]\n",
        "    \"string type\" [ \"mix\" ]\n    \"float amount\" [ 0.4 ]\n    \"string materials\" [ \"b\" \"a\" ]\n",
        "AreaLightSource \"diffuse\"\n        \"rgb L\" [ 4 4 4 ]\n    Shape",
        "        \"point2 uv\" [ 0 0 1 0 0 1 ]\n        \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ]\n        \"vector3 S\"",
    ] {
        assert!(out.contains(frag), "missing {frag:?} in\n{out}");
    }
    assert!(
        !out.contains("TransformBegin") && !out.contains("nsamples") && !out.contains("indices")
    );
    assert!(!out.contains("\"color") && !out.contains("\"point P"));
    // Approximations are reported, located.
    let msgs: Vec<String> = diags.iter().map(|d| d.to_string()).collect();
    assert!(
        msgs.iter()
            .any(|m| m.contains(":4:1: warning:") || m.contains("directlighting")),
        "{msgs:?}"
    );
    assert!(msgs.iter().any(|m| m.contains("average 0.4")), "{msgs:?}");
    // The upgraded text is valid pbrt-v4 and formats stably.
    let (again, d) = format(&out, false);
    assert!(!d.has_errors(), "{d}");
    let (again2, _) = format(&again, false);
    assert_eq!(again, again2);
}

#[test]
fn toply_writes_large_meshes_and_references_them() {
    let dir = std::env::temp_dir().join(format!("rpbrt-toply-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // A grid of 20x20 quads = 800 triangles = 2400 indices.
    let n = 21;
    let mut p = String::new();
    for y in 0..n {
        for x in 0..n {
            p.push_str(&format!("{x} {y} 0 "));
        }
    }
    let mut idx = String::new();
    for y in 0..n - 1 {
        for x in 0..n - 1 {
            let v = y * n + x;
            idx.push_str(&format!(
                "{} {} {} {} {} {} ",
                v,
                v + 1,
                v + n,
                v + 1,
                v + n + 1,
                v + n
            ));
        }
    }
    let scene = format!(
        "WorldBegin\nShape \"trianglemesh\" \"point3 P\" [ {p} ] \"integer indices\" [ {idx} ] \"float alpha\" 0.5\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"integer indices\" [ 0 1 2 ]\n"
    );
    let mut t = FormattingTarget::new(false).with_toply(&dir, "mesh");
    crate::parse_string(&scene, &mut t).unwrap();
    let out = t.into_output();
    assert!(out.contains("Shape \"plymesh\""), "{out}");
    assert!(out.contains("\"mesh_00001.ply\""), "{out}");
    assert!(out.contains("\"float alpha\" [ 0.5 ]"), "{out}");
    // The small mesh stays inline.
    assert!(out.contains("Shape \"trianglemesh\""), "{out}");
    let mesh = crate::ply::read_ply(&dir.join("mesh_00001.ply")).unwrap();
    assert_eq!(mesh.positions.len(), n * n);
    assert_eq!(mesh.tri_indices.len(), 2400);
    assert_eq!(mesh.positions[n + 2], [2.0, 1.0, 0.0]);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn comments_are_kept_in_place_and_formatting_them_is_idempotent() {
    let text = "# header line 1\n#header line 2   \n\
LookAt 0 0 5  0 0 0  0 1 0 # eye, look, up\n\
Camera \"perspective\" \"float fov\" 45\n\
  # after the camera's parameters\n\
WorldBegin\n\
AttributeBegin # a block\n\
  # inside the block\n\
  Shape \"trianglemesh\" \"point3 P\" [ 0 0 0 # first vertex\n 1 0 0 0 1 0 ]\n\
  \"integer indices\" [ 0 1 2 ]\n\
  # before the end\n\
AttributeEnd\n\
# trailing comment\n";
    let (f1, d1) = format(text, false);
    assert!(!d1.has_errors(), "{d1}");
    let expected = [
        "# header line 1",
        "#header line 2",
        "LookAt 0 0 5",
        "       0 0 0",
        "       0 1 0",
        "# eye, look, up",
        "Camera \"perspective\"",
        "    \"float fov\" [ 45 ]",
        "# after the camera's parameters",
        "",
        "WorldBegin",
        "",
        "AttributeBegin",
        "    # a block",
        "    # inside the block",
        "    Shape \"trianglemesh\"",
        "        \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ]",
        "        \"integer indices\" [ 0 1 2 ]",
        "    # first vertex",
        "    # before the end",
        "AttributeEnd",
        "# trailing comment",
        "",
    ]
    .join("\n");
    assert_eq!(f1, expected);
    let (f2, d2) = format(&f1, false);
    assert!(!d2.has_errors(), "{d2}");
    assert_eq!(f1, f2);
    // The upgrade keeps them too.
    let (u, _) = format(text, true);
    assert!(u.contains("# after the camera's parameters\n") && u.contains("# trailing comment\n"));
}

#[test]
fn a_comment_ends_at_the_end_of_its_line() {
    // What follows a `#` on its line is comment, the next line is not.
    let (f, d) = format(
        "Shape \"sphere\" # r \"float radius\" 2\n\"float radius\" 3\n",
        false,
    );
    assert!(!d.has_errors(), "{d}");
    assert_eq!(
        f,
        "Shape \"sphere\"\n    \"float radius\" [ 3 ]\n# r \"float radius\" 2\n"
    );
}

#[test]
fn upgrade_renames_multiply_defined_names_and_their_references() {
    let text = r#"WorldBegin
Texture "t" "float" "constant" "float value" 0.5
Texture "t" "float" "scale" "texture tex1" "t" "float tex2" 2
Texture "t" "float" "constant" "float value" 0.25
Material "matte" "texture sigma" "t" "texture bumpmap" "t"
MakeNamedMaterial "m" "string type" "matte"
NamedMaterial "m"
MakeNamedMaterial "m" "string type" "matte" "texture bumpmap" "t"
MakeNamedMaterial "mixed" "string type" "mix" "string namedmaterial1" "m" "string namedmaterial2" "other"
NamedMaterial "m"
Shape "sphere" "texture alpha" "t"
ObjectBegin "o"
ObjectEnd
ObjectInstance "o"
ObjectBegin "o"
ObjectEnd
ObjectInstance "o"
ObjectInstance "never-defined"
"#;
    let (out, diags) = format(text, true);
    assert!(!diags.has_errors(), "{diags}");
    for frag in [
        "Texture \"t\" \"float\" \"constant\"\n    \"float value\" [ 0.5 ]\n",
        // The scale builds on the texture it replaces: the first "t".
        "Texture \"t-renamed-0\" \"float\" \"scale\"\n    \"texture tex\" [ \"t\" ]\n    \"float scale\" [ 2 ]\n",
        "Texture \"t-renamed-1\" \"float\" \"constant\"\n",
        "    \"texture displacement\" [ \"t-renamed-1\" ]\n",
        "MakeNamedMaterial \"m\"\n    \"string type\" [ \"diffuse\" ]\nNamedMaterial \"m\"\n",
        "MakeNamedMaterial \"m-renamed-0\"\n    \"string type\" [ \"diffuse\" ]\n    \"texture displacement\" [ \"t-renamed-1\" ]\n",
        "\"string materials\" [ \"other\" \"m-renamed-0\" ]\n",
        "NamedMaterial \"m-renamed-0\"\nShape \"sphere\"\n    \"texture alpha\" [ \"t-renamed-1\" ]\n",
        "ObjectBegin \"o\"\nObjectEnd\nObjectInstance \"o\"\nObjectBegin \"o-renamed-0\"\nObjectEnd\nObjectInstance \"o-renamed-0\"\n",
        "ObjectInstance \"never-defined\"\n",
    ] {
        assert!(out.contains(frag), "missing {frag:?} in\n{out}");
    }
    let warnings: Vec<String> = diags.iter().map(|d| d.to_string()).collect();
    for (line, w) in [
        (3, "t: renaming multiply-defined texture"),
        (4, "t: renaming multiply-defined texture"),
        (8, "m: renaming multiply-defined named material"),
        (15, "o: renaming multiply-defined object instance"),
    ] {
        assert!(
            warnings
                .iter()
                .any(|m| m.contains(&format!("<string>:{line}:1: warning: {w}"))),
            "{line} {w}: {warnings:?}"
        );
    }
    // Without --upgrade nothing is renamed.
    let (plain, d) = format(text, false);
    assert!(!plain.contains("renamed"), "{plain}");
    assert!(!d.iter().any(|m| m.to_string().contains("renaming")));
}

/// pbrt-v3's colour light `scale` multiplies an RGB emission channel by
/// channel (or becomes the emission where the light has none); it cannot
/// scale a blackbody or an environment map's texels, which stay errors.
#[test]
fn colour_light_scales_fold_into_rgb_emission() {
    let (out, diags) = format(
        "WorldBegin\n\
         LightSource \"point\" \"color I\" [2 2 4] \"color scale\" [1 0.5 0.25]\n\
         LightSource \"distant\" \"color scale\" [0.5 1 2]\n\
         AttributeBegin\n\
         AreaLightSource \"area\" \"color L\" [4 4 4] \"color scale\" [1 2 3]\n\
         Shape \"sphere\"\n\
         AttributeEnd\n",
        true,
    );
    assert!(!diags.has_errors(), "{diags}");
    for frag in [
        "LightSource \"point\"\n    \"rgb I\" [ 2 1 1 ]\n",
        "LightSource \"distant\"\n    \"rgb L\" [ 0.5 1 2 ]\n",
        "AreaLightSource \"diffuse\"\n        \"rgb L\" [ 4 8 12 ]\n",
    ] {
        assert!(out.contains(frag), "missing {frag:?} in\n{out}");
    }
    assert!(!out.contains("scale"), "{out}");
    for bad in [
        "LightSource \"point\" \"blackbody I\" [5500] \"color scale\" [1 0.5 0.25]\n",
        "LightSource \"infinite\" \"string mapname\" \"sky.exr\" \"color scale\" [1 0.5 0.25]\n",
    ] {
        let (_, diags) = format(&format!("WorldBegin\n{bad}"), true);
        assert!(
            diags
                .iter()
                .any(|d| d.is_error() && d.message.contains("non-uniform spectrum")),
            "{bad}: {diags}"
        );
    }
}

const V2_SCENE: &str = r#"Film "image" "string filename" "v2.exr" "integer xresolution" 64
Sampler "bestcandidate" "integer pixelsamples" 8
Accelerator "grid" "bool refineimmediately" "true"
Renderer "sampler"
VolumeIntegrator "single" "float stepsize" 0.1
SurfaceIntegrator "directlighting" "integer maxdepth" 3 "string strategy" "one"
WorldBegin
Volume "homogeneous" "color sigma_a" [0.1 0.1 0.1] "point p0" [0 0 0] "point p1" [1 1 1]
Shape "sphere"
WorldEnd
"#;

#[test]
fn formats_pbrt_v2_directives_as_they_are() {
    let (out, diags) = format(V2_SCENE, false);
    assert!(!diags.has_errors(), "{diags}");
    for frag in [
        "Renderer \"sampler\"\n",
        "VolumeIntegrator \"single\"\n    \"float stepsize\" [ 0.1 ]\n",
        "SurfaceIntegrator \"directlighting\"\n    \"integer maxdepth\" [ 3 ]\n",
        "Volume \"homogeneous\"\n    \"color sigma_a\" [ 0.1 0.1 0.1 ]\n",
    ] {
        assert!(out.contains(frag), "missing {frag:?} in\n{out}");
    }
    let (again, _) = format(&out, false);
    assert_eq!(out, again);
}

#[test]
fn upgrades_pbrt_v2_transport_to_one_integrator() {
    let (out, diags) = format(V2_SCENE, true);
    for frag in [
        "Sampler \"pmj02bn\"\n    \"integer pixelsamples\" [ 8 ]\n",
        "Accelerator \"bvh\"\n",
        "Integrator \"path\"\n    \"integer maxdepth\" [ 1 ]\n\nWorldBegin",
    ] {
        assert!(out.contains(frag), "missing {frag:?} in\n{out}");
    }
    assert!(!out.contains("Renderer") && !out.contains("SurfaceIntegrator"));
    assert!(!out.contains("refineimmediately") && !out.contains("Volume"));
    // The region cannot be written: a located error.
    let msgs: Vec<String> = diags.iter().map(|d| d.to_string()).collect();
    assert!(
        msgs.iter()
            .any(|m| m.contains(":8:1: error:") && m.contains("no \"Volume\" regions")),
        "{msgs:?}"
    );
    // Metropolis becomes mlt with pbrt-v2's defaults spelled out.
    let (out, diags) = format(
        "Renderer \"metropolis\" \"integer samplesperpixel\" 64 \"bool bidirectional\" \"false\"\nWorldBegin\n",
        true,
    );
    assert!(!diags.has_errors(), "{diags}");
    assert!(
        out.contains("Integrator \"mlt\"\n    \"integer maxdepth\" [ 7 ]\n    \"integer mutationsperpixel\" [ 64 ]\n    \"float largestepprobability\" [ 0.25 ]\n"),
        "{out}"
    );
    assert!(!out.contains("bidirectional"), "{out}");
    // A renderer that makes no image is a located error.
    let (_, diags) = format("Renderer \"createprobes\"\nWorldBegin\n", true);
    let msgs: Vec<String> = diags.iter().map(|d| d.to_string()).collect();
    assert!(
        msgs.iter()
            .any(|m| m.contains(":1:1: error:") && m.contains("makes no image")),
        "{msgs:?}"
    );
}
