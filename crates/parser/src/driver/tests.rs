//! Tests of the driver: directive dispatch, error locations and recovery,
//! includes, limits and robustness against hostile input.
use super::*;
use crate::target::{DirectiveResult, ParamList};

/// Records each call as "Name args @line:col".
#[derive(Default)]
struct Rec {
    calls: Vec<String>,
    params: Vec<ParsedParameter>,
    depth: usize,
    max_depth: usize,
}

impl Rec {
    fn push(&mut self, what: String, loc: &FileLoc) -> DirectiveResult {
        let file = loc.file.rsplit('/').next().unwrap_or("").to_string();
        self.calls
            .push(format!("{what} @{file}:{}:{}", loc.line, loc.column));
        Ok(())
    }
    fn with_params(&mut self, what: String, p: ParamList, loc: &FileLoc) -> DirectiveResult {
        let desc: Vec<String> = p
            .iter()
            .map(|p| format!("{} {}={}", p.ty, p.name, p.value_count()))
            .collect();
        self.params.extend(p);
        self.push(format!("{what} [{}]", desc.join(", ")), loc)
    }
}

impl ParserTarget for Rec {
    fn identity(&mut self, loc: FileLoc) -> DirectiveResult {
        self.push("Identity".into(), &loc)
    }
    fn translate(&mut self, d: [f32; 3], loc: FileLoc) -> DirectiveResult {
        self.push(format!("Translate {d:?}"), &loc)
    }
    fn scale(&mut self, s: [f32; 3], loc: FileLoc) -> DirectiveResult {
        self.push(format!("Scale {s:?}"), &loc)
    }
    fn rotate(&mut self, a: f32, x: [f32; 3], loc: FileLoc) -> DirectiveResult {
        self.push(format!("Rotate {a} {x:?}"), &loc)
    }
    fn look_at(&mut self, e: [f32; 3], l: [f32; 3], u: [f32; 3], loc: FileLoc) -> DirectiveResult {
        self.push(format!("LookAt {e:?} {l:?} {u:?}"), &loc)
    }
    fn concat_transform(&mut self, m: [f32; 16], loc: FileLoc) -> DirectiveResult {
        self.push(format!("ConcatTransform {}", m[15]), &loc)
    }
    fn transform(&mut self, m: [f32; 16], loc: FileLoc) -> DirectiveResult {
        self.push(format!("Transform {}", m[0]), &loc)
    }
    fn coordinate_system(&mut self, n: &str, loc: FileLoc) -> DirectiveResult {
        self.push(format!("CoordinateSystem {n}"), &loc)
    }
    fn coord_sys_transform(&mut self, n: &str, loc: FileLoc) -> DirectiveResult {
        self.push(format!("CoordSysTransform {n}"), &loc)
    }
    fn search_path(&mut self, n: &str, loc: FileLoc) -> DirectiveResult {
        self.push(format!("SearchPath {n}"), &loc)
    }
    fn active_transform_all(&mut self, loc: FileLoc) -> DirectiveResult {
        self.push("ActiveTransform All".into(), &loc)
    }
    fn active_transform_end_time(&mut self, loc: FileLoc) -> DirectiveResult {
        self.push("ActiveTransform EndTime".into(), &loc)
    }
    fn active_transform_start_time(&mut self, loc: FileLoc) -> DirectiveResult {
        self.push("ActiveTransform StartTime".into(), &loc)
    }
    fn transform_times(&mut self, s: f32, e: f32, loc: FileLoc) -> DirectiveResult {
        self.push(format!("TransformTimes {s} {e}"), &loc)
    }
    fn reverse_orientation(&mut self, loc: FileLoc) -> DirectiveResult {
        self.push("ReverseOrientation".into(), &loc)
    }
    fn color_space(&mut self, n: &str, loc: FileLoc) -> DirectiveResult {
        self.push(format!("ColorSpace {n}"), &loc)
    }
    fn pixel_filter(&mut self, n: &str, p: ParamList, loc: FileLoc) -> DirectiveResult {
        self.with_params(format!("PixelFilter {n}"), p, &loc)
    }
    fn film(&mut self, n: &str, p: ParamList, loc: FileLoc) -> DirectiveResult {
        self.with_params(format!("Film {n}"), p, &loc)
    }
    fn sampler(&mut self, n: &str, p: ParamList, loc: FileLoc) -> DirectiveResult {
        self.with_params(format!("Sampler {n}"), p, &loc)
    }
    fn accelerator(&mut self, n: &str, p: ParamList, loc: FileLoc) -> DirectiveResult {
        self.with_params(format!("Accelerator {n}"), p, &loc)
    }
    fn integrator(&mut self, n: &str, p: ParamList, loc: FileLoc) -> DirectiveResult {
        self.with_params(format!("Integrator {n}"), p, &loc)
    }
    fn renderer(&mut self, n: &str, p: ParamList, loc: FileLoc) -> DirectiveResult {
        self.with_params(format!("Renderer {n}"), p, &loc)
    }
    fn surface_integrator(&mut self, n: &str, p: ParamList, loc: FileLoc) -> DirectiveResult {
        self.with_params(format!("SurfaceIntegrator {n}"), p, &loc)
    }
    fn volume_integrator(&mut self, n: &str, p: ParamList, loc: FileLoc) -> DirectiveResult {
        self.with_params(format!("VolumeIntegrator {n}"), p, &loc)
    }
    fn volume(&mut self, n: &str, p: ParamList, loc: FileLoc) -> DirectiveResult {
        self.with_params(format!("Volume {n}"), p, &loc)
    }
    fn camera(&mut self, n: &str, p: ParamList, loc: FileLoc) -> DirectiveResult {
        self.with_params(format!("Camera {n}"), p, &loc)
    }
    fn make_named_medium(&mut self, n: &str, p: ParamList, loc: FileLoc) -> DirectiveResult {
        self.with_params(format!("MakeNamedMedium {n}"), p, &loc)
    }
    fn medium_interface(&mut self, i: &str, o: &str, loc: FileLoc) -> DirectiveResult {
        self.push(format!("MediumInterface {i} {o}"), &loc)
    }
    fn option(&mut self, n: &str, v: &str, loc: FileLoc) -> DirectiveResult {
        self.push(format!("Option {n} {v}"), &loc)
    }
    fn world_begin(&mut self, loc: FileLoc) -> DirectiveResult {
        self.push("WorldBegin".into(), &loc)
    }
    fn attribute_begin(&mut self, loc: FileLoc) -> DirectiveResult {
        self.depth += 1;
        self.max_depth = self.max_depth.max(self.depth);
        if self.calls.len() < 1000 {
            self.push("AttributeBegin".into(), &loc)
        } else {
            Ok(())
        }
    }
    fn attribute_end(&mut self, loc: FileLoc) -> DirectiveResult {
        if self.depth == 0 {
            return Err(Diagnostic::error(loc, "unmatched AttributeEnd"));
        }
        self.depth -= 1;
        if self.calls.len() < 1000 {
            self.push("AttributeEnd".into(), &loc)
        } else {
            Ok(())
        }
    }
    fn attribute(&mut self, t: &str, p: ParamList, loc: FileLoc) -> DirectiveResult {
        self.with_params(format!("Attribute {t}"), p, &loc)
    }
    fn texture(
        &mut self,
        n: &str,
        t: &str,
        c: &str,
        p: ParamList,
        loc: FileLoc,
    ) -> DirectiveResult {
        self.with_params(format!("Texture {n} {t} {c}"), p, &loc)
    }
    fn material(&mut self, n: &str, p: ParamList, loc: FileLoc) -> DirectiveResult {
        self.with_params(format!("Material {n}"), p, &loc)
    }
    fn make_named_material(&mut self, n: &str, p: ParamList, loc: FileLoc) -> DirectiveResult {
        self.with_params(format!("MakeNamedMaterial {n}"), p, &loc)
    }
    fn named_material(&mut self, n: &str, loc: FileLoc) -> DirectiveResult {
        self.push(format!("NamedMaterial {n}"), &loc)
    }
    fn light_source(&mut self, n: &str, p: ParamList, loc: FileLoc) -> DirectiveResult {
        self.with_params(format!("LightSource {n}"), p, &loc)
    }
    fn area_light_source(&mut self, n: &str, p: ParamList, loc: FileLoc) -> DirectiveResult {
        self.with_params(format!("AreaLightSource {n}"), p, &loc)
    }
    fn shape(&mut self, n: &str, p: ParamList, loc: FileLoc) -> DirectiveResult {
        if n == "refused" {
            return Err(Diagnostic::error(loc, "the target refuses this shape"));
        }
        self.with_params(format!("Shape {n}"), p, &loc)
    }
    fn object_begin(&mut self, n: &str, loc: FileLoc) -> DirectiveResult {
        self.push(format!("ObjectBegin {n}"), &loc)
    }
    fn object_end(&mut self, loc: FileLoc) -> DirectiveResult {
        self.push("ObjectEnd".into(), &loc)
    }
    fn object_instance(&mut self, n: &str, loc: FileLoc) -> DirectiveResult {
        self.push(format!("ObjectInstance {n}"), &loc)
    }
    fn end_of_files(&mut self) -> DirectiveResult {
        self.calls.push("EndOfFiles".into());
        Ok(())
    }
}

fn parse(text: &str) -> (Rec, Result<Diagnostics, Diagnostics>) {
    let mut r = Rec::default();
    let res = parse_string(text, &mut r);
    (r, res)
}

fn errors(text: &str) -> Vec<String> {
    let (_, res) = parse(text);
    match res {
        Ok(d) => panic!("expected errors, got {d}"),
        Err(d) => d
            .iter()
            .filter(|d| d.is_error())
            .map(|d| d.to_string())
            .collect(),
    }
}

#[test]
fn dispatches_every_directive() {
    let text = r#"Option "bool disablepixeljitter" true
Option "string seed" "a b"
ColorSpace "srgb"
LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" 45
Film "rgb" "integer xresolution" [ 64 ] "string filename" "out.exr"
Sampler "halton" "integer pixelsamples" 16
PixelFilter "gaussian"
Accelerator "bvh"
Integrator "path" "integer maxdepth" 5
TransformTimes 0 1
ActiveTransform EndTime
Translate 1 2 3
ActiveTransform StartTime
Scale 2 2 2
ActiveTransform All
Rotate 90 0 0 1
Identity
ConcatTransform [ 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1 ]
Transform [ 2 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1 ]
CoordinateSystem "cam"
CoordSysTransform "cam"
MakeNamedMedium "fog" "string type" "homogeneous"
WorldBegin
MediumInterface "fog"
MediumInterface "" "fog"
Attribute "shape" "float radius" 2
Texture "checks" "spectrum" "checkerboard" "rgb tex1" [1 1 1]
MakeNamedMaterial "red" "string type" "diffuse" "rgb reflectance" [ 1 0 0 ]
NamedMaterial "red"
Material "conductor" "spectrum eta" "metal-Cu-eta"
AttributeBegin
  ReverseOrientation
  AreaLightSource "diffuse" "blackbody L" 6500
  Shape "sphere"
AttributeEnd
TransformBegin
TransformEnd
LightSource "point" "point3 from" [0 1 0] "bool b" "true"
ObjectBegin "thing"
  Shape "trianglemesh" "point P" [0 0 0 1 0 0 0 1 0] "integer indices" [0 1 2] "normal N" [0 0 1 0 0 1 0 0 1]
ObjectEnd
ObjectInstance "thing"
WorldEnd
"#;
    let (r, res) = parse(text);
    let warnings = res.unwrap();
    // TransformBegin's deprecation warning, once.
    assert_eq!(warnings.len(), 1, "{warnings}");
    assert!(warnings.items[0].message.contains("deprecated"));
    assert_eq!(warnings.items[0].loc.as_ref().map(|l| l.line), Some(37));
    let expect = [
        "Option bool disablepixeljitter true @<string>:1:1",
        "Option string seed \"a b\" @<string>:2:1",
        "ColorSpace srgb @<string>:3:1",
        "LookAt [0.0, 0.0, 5.0] [0.0, 0.0, 0.0] [0.0, 1.0, 0.0] @<string>:4:1",
        "Camera perspective [float fov=1] @<string>:5:1",
        "Film rgb [integer xresolution=1, string filename=1] @<string>:6:1",
        "Sampler halton [integer pixelsamples=1] @<string>:7:1",
        "PixelFilter gaussian [] @<string>:8:1",
        "Accelerator bvh [] @<string>:9:1",
        "Integrator path [integer maxdepth=1] @<string>:10:1",
        "TransformTimes 0 1 @<string>:11:1",
        "ActiveTransform EndTime @<string>:12:1",
        "Translate [1.0, 2.0, 3.0] @<string>:13:1",
        "ActiveTransform StartTime @<string>:14:1",
        "Scale [2.0, 2.0, 2.0] @<string>:15:1",
        "ActiveTransform All @<string>:16:1",
        "Rotate 90 [0.0, 0.0, 1.0] @<string>:17:1",
        "Identity @<string>:18:1",
        "ConcatTransform 1 @<string>:19:1",
        "Transform 2 @<string>:20:1",
        "CoordinateSystem cam @<string>:21:1",
        "CoordSysTransform cam @<string>:22:1",
        "MakeNamedMedium fog [string type=1] @<string>:23:1",
        "WorldBegin @<string>:24:1",
        "MediumInterface fog fog @<string>:25:1",
        "MediumInterface  fog @<string>:26:1",
        "Attribute shape [float radius=1] @<string>:27:1",
        "Texture checks spectrum checkerboard [rgb tex1=3] @<string>:28:1",
        "MakeNamedMaterial red [string type=1, rgb reflectance=3] @<string>:29:1",
        "NamedMaterial red @<string>:30:1",
        "Material conductor [spectrum eta=1] @<string>:31:1",
        "AttributeBegin @<string>:32:1",
        "ReverseOrientation @<string>:33:3",
        "AreaLightSource diffuse [blackbody L=1] @<string>:34:3",
        "Shape sphere [] @<string>:35:3",
        "AttributeEnd @<string>:36:1",
        "AttributeBegin @<string>:37:1",
        "AttributeEnd @<string>:38:1",
        "LightSource point [point3 from=3, bool b=1] @<string>:39:1",
        "ObjectBegin thing @<string>:40:1",
        "Shape trianglemesh [point P=9, integer indices=3, normal N=9] @<string>:41:3",
        "ObjectEnd @<string>:42:1",
        "ObjectInstance thing @<string>:43:1",
        "EndOfFiles",
    ];
    assert_eq!(r.calls, expect);
    let b = r.params.iter().find(|p| p.name == "b").unwrap();
    assert_eq!(b.bools, [true]);
    let p = r.params.iter().find(|p| p.name == "from").unwrap();
    assert_eq!((p.loc.line, p.loc.column), (39, 21));
}

#[test]
fn unknown_directive_is_located_with_suggestion_and_parsing_continues() {
    let (r, res) = parse("Shape \"sphere\"\n  Shpae \"disk\" \"float radius\" 1\nShape \"disk\"\n");
    let d = res.unwrap_err();
    assert_eq!(d.error_count(), 1);
    assert_eq!(
        d.items[0].to_string(),
        "<string>:2:3: error: unknown directive \"Shpae\"; did you mean \"Shape\"?"
    );
    assert_eq!(r.calls.len(), 3, "{:?}", r.calls); // two shapes and EndOfFiles
    assert!(errors("Frobnicate 1 2\n")[0].ends_with("unknown directive \"Frobnicate\""));
}

#[test]
fn unterminated_string_error_location() {
    let e = errors("Shape \"sphere\"\nShape \"disk\n\"float radius\" 2\n");
    assert_eq!(
        e[0],
        "<string>:2:7: error: unterminated string: newline before the closing '\"'"
    );
}

#[test]
fn bad_number_error_location() {
    let e = errors("WorldBegin\nTranslate 1 x2 3\nShape \"sphere\" \"float radius\" [ 1 2z ]\n");
    assert_eq!(e[0], "<string>:2:13: error: x2: expected a number");
    assert_eq!(e[1], "<string>:3:35: error: 2z: expected a number");
    assert_eq!(e.len(), 2);
}

#[test]
fn parameter_syntax_errors() {
    let e = errors("Shape \"sphere\" \"float\" 1\n");
    assert!(
        e[0].starts_with("<string>:1:16: error:") && e[0].contains("no name"),
        "{e:?}"
    );
    let e = errors("Shape \"sphere\" \"float radius extra\" 1\n");
    assert!(e[0].contains("more than two words"), "{e:?}");
    let e = errors("Shape \"sphere\" \"float radius\" \"big\"\n");
    assert!(e[0].contains("expected a number"), "{e:?}");
    let e = errors("Shape \"sphere\" \"string name\" 3\n");
    assert!(e[0].contains("expected a quoted string"), "{e:?}");
    let e = errors("Shape \"sphere\" \"integer n\" 1.5\n");
    assert!(e[0].contains("expected an integer"), "{e:?}");
    let e = errors("Shape \"sphere\" \"bool b\" 1\n");
    assert!(e[0].contains("expected true or false"), "{e:?}");
    let e = errors("Shape \"sphere\" \"quaternion q\" [1 2 3 4]\nShape \"disk\"");
    assert_eq!(
        e,
        ["<string>:1:16: error: unknown parameter type \"quaternion\" in \"quaternion q\""]
    );
    let e = errors("Shape \"sphere\" \"spectrum s\" [ 300 1 \"x\" ]\n");
    assert!(e[0].contains("mixes numbers"), "{e:?}");
    let e = errors("Shape \"sphere\" \"float r\" ]\n");
    assert!(e[0].contains("unexpected ']'"), "{e:?}");
    let e = errors("Shape \"sphere\" \"float r\"");
    assert!(e[0].contains("premature end of file"), "{e:?}");
    let e = errors("Shape sphere\n");
    assert!(e[0].contains("expected a name (a quoted string)"), "{e:?}");
}

#[test]
fn missing_bracket_points_at_the_bracket_and_recovers() {
    let (r, res) = parse("Shape \"sphere\" \"float radius\" [ 1\nWorldBegin\nShape \"disk\"\n");
    let d = res.unwrap_err();
    assert_eq!(
        d.items[0].to_string(),
        "<string>:1:31: error: missing ']' to close the values of \"float radius\""
    );
    assert!(r.calls.iter().any(|c| c.starts_with("WorldBegin")));
    assert!(r.calls.iter().any(|c| c.starts_with("Shape disk")));
    let e = errors("Shape \"sphere\" \"float radius\" [ 1 2");
    assert_eq!(
        e[0],
        "<string>:1:31: error: unterminated '[' in the values of \"float radius\""
    );
}

#[test]
fn target_errors_are_collected_and_parsing_continues() {
    let (r, res) = parse("AttributeEnd\nAttributeBegin\nAttributeEnd\nAttributeEnd\n");
    let d = res.unwrap_err();
    let lines: Vec<u32> = d
        .iter()
        .filter_map(|d| d.loc.as_ref().map(|l| l.line))
        .collect();
    assert_eq!(lines, [1, 4]);
    assert_eq!(r.calls.last().map(String::as_str), Some("EndOfFiles"));
}

#[test]
fn stops_after_max_errors() {
    let text = "Translate x 0 0\n".repeat(100);
    let d = parse(&text).1.unwrap_err();
    assert_eq!(d.error_count(), 21); // 20 plus "too many errors"
    assert!(d.items.last().unwrap().message.contains("too many errors"));
}

#[test]
fn option_and_active_transform_errors() {
    let e = errors("ActiveTransform Sometimes\nShape \"sphere\"");
    assert!(
        e[0].starts_with("<string>:1:17: error: ActiveTransform: expected"),
        "{e:?}"
    );
    let e = errors("ConcatTransform [ 1 2 3 ]\n");
    assert!(e[0].contains("expected a number"), "{e:?}");
    // Matrices without brackets (pbrt-v3 leniency) parse.
    let (r, res) = parse("Transform 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\n");
    res.unwrap();
    assert_eq!(r.calls[0], "Transform 1 @<string>:1:1");
}

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("rpbrt-parser-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(d.join("sub/deeper")).unwrap();
    d
}

#[test]
fn includes_resolve_relative_to_the_including_file() {
    let d = temp_dir("inc");
    std::fs::write(
        d.join("main.pbrt"),
        "WorldBegin\nInclude \"sub/a.pbrt\"\nShape \"disk\"\n",
    )
    .unwrap();
    std::fs::write(
        d.join("sub/a.pbrt"),
        "Shape \"sphere\"\nImport \"deeper/b.pbrt\"\n",
    )
    .unwrap();
    std::fs::write(
        d.join("sub/deeper/b.pbrt"),
        "Shape \"cylinder\" \"float bad\" [ 1 x ]\n",
    )
    .unwrap();
    let mut r = Rec::default();
    let res = parse_files(&[d.join("main.pbrt")], &mut r);
    let diags = res.unwrap_err();
    assert_eq!(
        r.calls,
        [
            "WorldBegin @main.pbrt:1:1",
            "Shape sphere [] @a.pbrt:1:1",
            // The Import, isolated, with nothing left in it.
            "AttributeBegin @a.pbrt:2:1",
            "AttributeEnd @a.pbrt:2:1",
            "Shape disk [] @main.pbrt:3:1",
            "EndOfFiles"
        ]
    );
    let e = &diags.items[0];
    assert!(e.loc.as_ref().unwrap().file.ends_with("sub/deeper/b.pbrt"));
    assert_eq!(e.loc.as_ref().map(|l| (l.line, l.column)), Some((1, 34)));
    // The included file's text is kept for rendering.
    assert!(
        diags.render().contains("1 | Shape \"cylinder\""),
        "{}",
        diags.render()
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// Parses `main` under `d` with imports in parallel or in place.
fn parse_with(d: &Path, parallel: bool) -> (Vec<String>, Diagnostics) {
    let mut r = Rec::default();
    let opts = ParseOptions {
        parallel_import: parallel,
        ..ParseOptions::default()
    };
    let res = Parser::new(opts).parse_files(&[d.join("main.pbrt")], &mut r);
    let diags = match res {
        Ok(d) | Err(d) => d,
    };
    (r.calls, diags)
}

#[test]
fn imports_are_delivered_in_place_isolated_whatever_the_threads_do() {
    let d = temp_dir("import");
    std::fs::write(
        d.join("main.pbrt"),
        "WorldBegin\nShape \"disk\"\nImport \"sub/a.pbrt\"\nTranslate 1 0 0\n\
         Import \"sub/b.pbrt\"\nShape \"sphere\"\n",
    )
    .unwrap();
    // a changes the transform (which stays inside it), includes a file and
    // imports another.
    std::fs::write(
        d.join("sub/a.pbrt"),
        "Translate 0 5 0\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n\
         Include \"deeper/c.pbrt\"\nImport \"deeper/d.pbrt\"\nShape \"cylinder\"\n",
    )
    .unwrap();
    std::fs::write(d.join("sub/b.pbrt"), "MakeNamedMaterial \"m\"\n").unwrap();
    std::fs::write(d.join("sub/deeper/c.pbrt"), "Material \"diffuse\"\n").unwrap();
    std::fs::write(d.join("sub/deeper/d.pbrt"), "Shape \"curve\"\n").unwrap();
    let (par, pd) = parse_with(&d, true);
    let (seq, sd) = parse_with(&d, false);
    assert!(!pd.has_errors() && !sd.has_errors(), "{pd} {sd}");
    assert_eq!(
        par,
        [
            "WorldBegin @main.pbrt:1:1",
            "Shape disk [] @main.pbrt:2:1",
            "AttributeBegin @main.pbrt:3:1",
            "Translate [0.0, 5.0, 0.0] @a.pbrt:1:1",
            "Shape trianglemesh [point3 P=9] @a.pbrt:2:1",
            "Material diffuse [] @c.pbrt:1:1",
            "AttributeBegin @a.pbrt:4:1",
            "Shape curve [] @d.pbrt:1:1",
            "AttributeEnd @a.pbrt:4:1",
            "Shape cylinder [] @a.pbrt:5:1",
            "AttributeEnd @main.pbrt:3:1",
            "Translate [1.0, 0.0, 0.0] @main.pbrt:4:1",
            "AttributeBegin @main.pbrt:5:1",
            "MakeNamedMaterial m [] @b.pbrt:1:1",
            "AttributeEnd @main.pbrt:5:1",
            "Shape sphere [] @main.pbrt:6:1",
            "EndOfFiles",
        ]
    );
    assert_eq!(par, seq);
    // Many runs, same stream.
    for _ in 0..10 {
        assert_eq!(parse_with(&d, true).0, seq);
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn many_imports_share_a_bounded_set_of_threads() {
    // 300 imports, each importing one more file: far more than the import
    // thread limit, so most are parsed in place; the stream is still the
    // one-thread parse's, and every slot is given back.
    let d = temp_dir("many-imports");
    let mut main = String::from("WorldBegin\n");
    for i in 0..300 {
        main.push_str(&format!("Import \"sub/i{i}.pbrt\"\n"));
        std::fs::write(
            d.join(format!("sub/i{i}.pbrt")),
            format!("Translate {i} 0 0\nImport \"deeper/j{i}.pbrt\"\n"),
        )
        .unwrap();
        std::fs::write(
            d.join(format!("sub/deeper/j{i}.pbrt")),
            "Shape \"sphere\"\n",
        )
        .unwrap();
    }
    std::fs::write(d.join("main.pbrt"), main).unwrap();
    let (par, pd) = parse_with(&d, true);
    let (seq, sd) = parse_with(&d, false);
    assert!(!pd.has_errors() && !sd.has_errors(), "{pd} {sd}");
    assert_eq!(
        par.iter().filter(|c| c.starts_with("Shape sphere")).count(),
        300
    );
    assert_eq!(par, seq);
    assert!(super::import::import_threads_running() <= super::import::max_import_threads());
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn errors_in_imported_files_keep_their_locations() {
    let d = temp_dir("import-err");
    std::fs::write(
        d.join("main.pbrt"),
        "WorldBegin\nImport \"sub/a.pbrt\"\nImport \"sub/missing.pbrt\"\n\
         Shape \"refused\"\nImport \"sub/open.pbrt\"\nImport \"main.pbrt\"\n",
    )
    .unwrap();
    std::fs::write(
        d.join("sub/a.pbrt"),
        "Shape \"sphere\"\n  Shape \"refused\"\nShape \"disk\" \"float r\" [ 1 x ]\n",
    )
    .unwrap();
    std::fs::write(
        d.join("sub/open.pbrt"),
        "AttributeBegin\nShape \"sphere\"\n",
    )
    .unwrap();
    for parallel in [true, false] {
        let (calls, diags) = parse_with(&d, parallel);
        let e: Vec<String> = diags.iter().map(|d| d.to_string()).collect();
        let has = |s: &str| e.iter().any(|m| m.contains(s));
        // The parse error and the target's error inside the import, the
        // missing file at its Import, the target's error in the main file,
        // the unclosed block and the cycle, all located.
        assert!(has("a.pbrt:3:28: error: x: expected a number"), "{e:?}");
        assert!(
            has("a.pbrt:2:3: error: the target refuses this shape"),
            "{e:?}"
        );
        assert!(has("main.pbrt:3:1: error: cannot read"), "{e:?}");
        assert!(
            has("main.pbrt:4:1: error: the target refuses this shape"),
            "{e:?}"
        );
        assert!(has("open.pbrt:1:1: error: missing end"), "{e:?}");
        assert!(has("main.pbrt:6:1: error: include cycle"), "{e:?}");
        // The imported file's text is kept to show the line.
        let shown = diags.render();
        assert!(shown.contains("2 |   Shape \"refused\""), "{shown}");
        assert!(shown.contains("4 | Shape \"refused\""), "{shown}");
        assert!(calls.contains(&"Shape sphere [] @a.pbrt:1:1".to_string()));
        assert!(!calls.iter().any(|c| c.contains("open.pbrt")), "{calls:?}");
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn gzip_files_are_read_transparently() {
    use std::io::Write;
    let d = temp_dir("gz");
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    enc.write_all(b"Shape \"sphere\" \"float radius\" 3\n")
        .unwrap();
    std::fs::write(d.join("scene.pbrt.gz"), enc.finish().unwrap()).unwrap();
    std::fs::write(d.join("main.pbrt"), "Include \"scene.pbrt.gz\"\n").unwrap();
    let mut r = Rec::default();
    parse_files(&[d.join("main.pbrt")], &mut r).unwrap();
    assert_eq!(
        r.calls[0],
        "Shape sphere [float radius=1] @scene.pbrt.gz:1:1"
    );
    // A corrupt gzip file is an error, not a panic.
    std::fs::write(d.join("bad.gz"), [0x1f, 0x8b, 8, 0, 1, 2, 3]).unwrap();
    let res = parse_files(&[d.join("bad.gz")], &mut Rec::default());
    assert!(res.is_err());
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn include_cycles_and_missing_files_are_located_errors() {
    let d = temp_dir("cycle");
    std::fs::write(d.join("a.pbrt"), "Shape \"sphere\"\nInclude \"b.pbrt\"\n").unwrap();
    std::fs::write(
        d.join("b.pbrt"),
        "\n  Include \"a.pbrt\"\nInclude \"missing.pbrt\"\n",
    )
    .unwrap();
    let mut r = Rec::default();
    let diags = parse_files(&[d.join("a.pbrt")], &mut r).unwrap_err();
    let e: Vec<String> = diags.iter().map(|d| d.to_string()).collect();
    assert_eq!(e.len(), 2, "{e:?}");
    assert!(e[0].contains("b.pbrt:2:3: error: include cycle"), "{e:?}");
    assert!(e[1].contains("b.pbrt:3:1: error: cannot read"), "{e:?}");
    assert_eq!(r.calls, ["Shape sphere [] @a.pbrt:1:1", "EndOfFiles"]);
    // Self-inclusion too.
    std::fs::write(d.join("self.pbrt"), "Include \"self.pbrt\"\n").unwrap();
    assert!(parse_files(&[d.join("self.pbrt")], &mut Rec::default()).is_err());
    let e = parse_files(&[d.join("nope.pbrt")], &mut Rec::default()).unwrap_err();
    assert!(e.items[0].loc.is_none() && e.items[0].message.contains("nope.pbrt"));
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn include_depth_is_limited() {
    let d = temp_dir("depth");
    // A chain of 100 distinct files, each including the next.
    for i in 0..100 {
        std::fs::write(
            d.join(format!("f{i}.pbrt")),
            format!("Include \"f{}.pbrt\"\n", i + 1),
        )
        .unwrap();
    }
    std::fs::write(d.join("f100.pbrt"), "Shape \"sphere\"\n").unwrap();
    let e = parse_files(&[d.join("f0.pbrt")], &mut Rec::default()).unwrap_err();
    assert!(e.items[0].message.contains("nested more than 64"), "{e}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn deep_nesting_does_not_recurse() {
    let n = 100_000;
    let mut text = "AttributeBegin\n".repeat(n);
    text.push_str(&"AttributeEnd\n".repeat(n));
    let (r, res) = parse(&text);
    res.unwrap();
    assert_eq!((r.max_depth, r.depth), (n, 0));
}

#[test]
fn absurd_numbers_are_errors() {
    let e = errors("Translate 1e400 0 0\nTranslate -nan 0 0\nTranslate inf 0 0\nShape \"x\" \"integer n\" 99999999999\n");
    assert_eq!(e.len(), 4, "{e:?}");
    assert!(e[0].contains("out of range"));
    assert!(e[1].contains("-nan: expected a number"));
    assert!(e[3].contains("too large"));
    let (r, res) = parse("Translate 1e-400 -0 +.5\n");
    res.unwrap();
    assert_eq!(r.calls[0], "Translate [0.0, -0.0, 0.5] @<string>:1:1");
}

#[test]
fn binary_garbage_and_truncation_never_panic() {
    for len in [0usize, 1, 7, 100, 5000] {
        let bytes = crate::input::noise_bytes(0x1234_5678_9abc_def1 + len as u64, len);
        let p = Parser::default();
        let _ = p.parse_bytes("g", Arc::from(bytes), Path::new("."), &mut Rec::default());
    }
    let valid = "LookAt 0 0 5 0 0 0 0 1 0\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0 1 0 0 0 1 0 ] \"string s\" \"a\\\"b\"\n";
    for cut in 0..valid.len() {
        let _ = parse(&valid[..cut]);
    }
}

const MUTATION_SEED_SCENE: &str = r#"Film "rgb" "integer xresolution" [ 64 ] "string filename" "a\tb.exr"
LookAt 0 0 5 0 0 0 0 1 0
Camera "perspective" "float fov" [ 45 ]
WorldBegin
AttributeBegin
  Material "diffuse" "rgb reflectance" [ .5 .5 .5 ] "bool x" true
  Shape "trianglemesh" "point3 P" [ 0 0 0 1 0 0 0 1 0 ] "integer indices" [ 0 1 2 ]
    "spectrum s" [ 300 1 800 2 ] "texture t" "tex" # comment
AttributeEnd
Include "does-not-exist.pbrt"
"#;

#[test]
fn seeded_mutations_never_panic() {
    let base = MUTATION_SEED_SCENE.as_bytes();
    let alphabet = b"\"[]#\\\n \t0123456789.e-+aZ\xff\x00";
    let mut x: u64 = 0x2545_f491_4f6c_dd1d;
    let mut rnd = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    for _ in 0..3000 {
        let mut v = base.to_vec();
        for _ in 0..(1 + rnd() % 6) {
            let i = (rnd() as usize) % (v.len() + 1);
            match rnd() % 4 {
                0 if i < v.len() => v[i] = alphabet[(rnd() as usize) % alphabet.len()],
                1 if i < v.len() => {
                    v.remove(i);
                }
                2 => v.insert(i, alphabet[(rnd() as usize) % alphabet.len()]),
                _ => v.truncate(i),
            }
        }
        let p = Parser::default();
        let mut fmt = crate::format::FormattingTarget::new(true);
        let _ = p.parse_bytes(
            "m",
            Arc::from(v.clone()),
            Path::new("/nonexistent"),
            &mut fmt,
        );
        let _ = p.parse_bytes(
            "m",
            Arc::from(v),
            Path::new("/nonexistent"),
            &mut Rec::default(),
        );
    }
}

#[test]
fn suggestions() {
    assert_eq!(suggest("attributebegin"), Some("AttributeBegin"));
    assert_eq!(suggest("LightSorce"), Some("LightSource"));
    assert_eq!(suggest("xyz"), None);
    assert_eq!(edit_distance("kitten", "sitting"), 3);
}

#[cfg(unix)]
#[test]
fn included_device_is_a_located_error_not_an_endless_read() {
    let d = temp_dir("devzero");
    std::fs::write(
        d.join("main.pbrt"),
        "Shape \"sphere\"\nInclude \"/dev/zero\"\nImport \"/dev/urandom\"\n",
    )
    .unwrap();
    let t = std::time::Instant::now();
    let res = parse_files(&[d.join("main.pbrt")], &mut Rec::default());
    let e: Vec<String> = res.unwrap_err().iter().map(|d| d.to_string()).collect();
    assert!(
        e.iter()
            .any(|m| m.contains("main.pbrt:2:1: error:")
                && m.contains("/dev/zero: not a regular file")),
        "{e:?}"
    );
    assert!(
        e.iter()
            .any(|m| m.contains("main.pbrt:3:1: error:") && m.contains("not a regular file")),
        "{e:?}"
    );
    assert!(t.elapsed() < std::time::Duration::from_secs(5));
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn gzip_bomb_scene_stops_at_the_size_limit() {
    use std::io::Write;
    let d = temp_dir("bomb");
    // 4 MiB of blank lines compress to a few KiB.
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
    let blank = vec![b'\n'; 1 << 20];
    for _ in 0..4 {
        enc.write_all(&blank).unwrap();
    }
    let gz = enc.finish().unwrap();
    assert!(gz.len() < 64 << 10);
    std::fs::write(d.join("bomb.pbrt.gz"), gz).unwrap();
    std::fs::write(
        d.join("main.pbrt"),
        "WorldBegin\nInclude \"bomb.pbrt.gz\"\n",
    )
    .unwrap();
    // The limit lowered to 1 MiB keeps the test small; the default (1 GiB)
    // works the same way.
    let opts = ParseOptions {
        max_file_bytes: 1 << 20,
        ..ParseOptions::default()
    };
    let res = Parser::new(opts.clone()).parse_files(&[d.join("main.pbrt")], &mut Rec::default());
    let e: Vec<String> = res.unwrap_err().iter().map(|d| d.to_string()).collect();
    assert!(
        e.iter().any(|m| m.contains("main.pbrt:2:1: error:")
            && m.contains("decompressed size exceeds the limit of 1048576 bytes")),
        "{e:?}"
    );
    // Within the limit, the same file reads.
    let roomy = ParseOptions {
        max_file_bytes: 8 << 20,
        ..opts
    };
    Parser::new(roomy)
        .parse_files(&[d.join("main.pbrt")], &mut Rec::default())
        .unwrap();
    assert_eq!(
        ParseOptions::default().max_file_bytes,
        crate::input::DEFAULT_MAX_SCENE_FILE_BYTES
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// The lookup by first letter needs the table sorted (so that names with
/// one first letter are together); every name is found, and words that
/// differ from a name in length or a letter are not.
#[test]
fn every_directive_is_looked_up() {
    let names: Vec<&str> = directive_names().collect();
    let mut sorted = names.clone();
    sorted.sort_unstable();
    assert_eq!(names, sorted);
    for &(name, d) in DIRECTIVES {
        assert_eq!(lookup_directive(name.as_bytes()), Some(d), "{name}");
        let longer = format!("{name}s");
        assert_eq!(lookup_directive(longer.as_bytes()), None, "{longer}");
        let mut changed = name.as_bytes().to_vec();
        let last = changed.len() - 1;
        changed[last] ^= 0x20;
        assert_eq!(lookup_directive(&changed), None, "{name}");
    }
    for word in ["", "A", "Z", "1", "attributeBegin", "Zebra", "Transforms"] {
        assert_eq!(lookup_directive(word.as_bytes()), None, "{word}");
    }
}
