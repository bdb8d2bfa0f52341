use super::*;
use crate::scene::{build_scene, build_scene_from_str, BuildOptions};
use rpbrt_parser::{parse_string, FormattingTarget, Severity};
use std::path::PathBuf;

fn opts(sys: RenderingCoordinateSystem) -> BuildOptions {
    BuildOptions {
        render_coord_sys: sys,
        ..BuildOptions::default()
    }
}

fn build_with(text: &str, sys: RenderingCoordinateSystem) -> SceneDescription {
    match build_scene_from_str(text, &opts(sys)) {
        Ok((scene, _)) => scene,
        Err(d) => panic!("unexpected errors:\n{d}"),
    }
}

fn build(text: &str) -> SceneDescription {
    build_with(text, RenderingCoordinateSystem::World)
}

/// The errors of a scene that must fail, as `file:line:col: error: message`.
fn errors(text: &str) -> Vec<String> {
    match build_scene_from_str(text, &opts(RenderingCoordinateSystem::World)) {
        Ok(_) => panic!("expected errors in:\n{text}"),
        Err(d) => d
            .iter()
            .filter(|d| d.severity == Severity::Error)
            .map(|d| d.to_string())
            .collect(),
    }
}

fn assert_error(text: &str, prefix: &str, fragment: &str) {
    let errs = errors(text);
    assert!(
        errs.iter()
            .any(|e| e.starts_with(prefix) && e.contains(fragment)),
        "no error at {prefix} containing {fragment:?}: {errs:#?}"
    );
}

fn close(p: Point3f, x: f32, y: f32, z: f32) -> bool {
    (Vector3f::from(p) - Vector3f::new(x, y, z)).length() < 1e-4
}

fn origin() -> Point3f {
    Point3f::new(0.0, 0.0, 0.0)
}

#[test]
fn transforms_compose_in_pbrt_order() {
    let s = build("WorldBegin\nTranslate 1 0 0\nScale 2 2 2\nShape \"sphere\"\n");
    let t = &s.shapes[0].render_from_object;
    // Scale applies first: (1,0,0) -> (2,0,0) -> (3,0,0).
    assert!(close(
        t.apply_point(Point3f::new(1.0, 0.0, 0.0)),
        3.0,
        0.0,
        0.0
    ));
    let back = s.shapes[0]
        .object_from_render
        .apply_point(Point3f::new(3.0, 0.0, 0.0));
    assert!(close(back, 1.0, 0.0, 0.0));
}

#[test]
fn transform_and_concat_read_columns() {
    let s = build(
        "WorldBegin\nTransform [1 0 0 0  0 1 0 0  0 0 1 0  5 6 7 1]\nShape \"sphere\"\n\
         ConcatTransform [2 0 0 0  0 2 0 0  0 0 2 0  0 0 0 1]\nShape \"sphere\"\n",
    );
    assert!(close(
        s.shapes[0].render_from_object.apply_point(origin()),
        5.0,
        6.0,
        7.0
    ));
    let p = s.shapes[1]
        .render_from_object
        .apply_point(Point3f::new(1.0, 0.0, 0.0));
    assert!(close(p, 7.0, 6.0, 7.0));
}

#[test]
fn look_at_and_camera_define_camera_space() {
    let text = "LookAt 0 0 -5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 45\n\
                WorldBegin\nAttributeBegin\nCoordSysTransform \"camera\"\nShape \"sphere\"\nAttributeEnd\n\
                Shape \"sphere\"\n";
    let s = build(text);
    assert_eq!(s.camera.base.name, "perspective");
    let rfc = &s.camera.camera_transform.render_from_camera;
    assert!(close(
        rfc.start_transform().apply_point(origin()),
        0.0,
        0.0,
        -5.0
    ));
    // Camera looks down +z in camera space; towards the world origin here.
    let ahead = rfc
        .start_transform()
        .apply_point(Point3f::new(0.0, 0.0, 1.0));
    assert!(close(ahead, 0.0, 0.0, -4.0));
    // "camera" coordinate system: objects placed at the camera.
    assert!(close(
        s.shapes[0].render_from_object.apply_point(origin()),
        0.0,
        0.0,
        -5.0
    ));
    // WorldBegin reset the CTM.
    assert!(s.shapes[1].render_from_object.is_identity());
}

#[test]
fn rendering_coordinate_systems() {
    let text = "LookAt 1 2 3  1 2 4  0 1 0\nCamera \"perspective\"\nWorldBegin\nShape \"sphere\"\n";
    // cameraworld (default): world translated so that the camera is at the origin.
    let s = build_with(text, RenderingCoordinateSystem::CameraWorld);
    assert_eq!(s.render_coord_sys, RenderingCoordinateSystem::CameraWorld);
    let wfr = &s.camera.camera_transform.world_from_render;
    assert!(close(wfr.apply_point(origin()), 1.0, 2.0, 3.0));
    assert!(close(
        s.shapes[0].render_from_object.apply_point(origin()),
        -1.0,
        -2.0,
        -3.0
    ));
    // camera: render space is camera space.
    let s = build_with(text, RenderingCoordinateSystem::Camera);
    let rfc = s
        .camera
        .camera_transform
        .render_from_camera
        .start_transform();
    assert!(close(
        rfc.apply_point(Point3f::new(0.5, 0.25, 2.0)),
        0.5,
        0.25,
        2.0
    ));
    let p = s.shapes[0]
        .render_from_object
        .apply_point(Point3f::new(1.0, 2.0, 5.0));
    assert!(close(p, 0.0, 0.0, 2.0));
    // world: identity.
    let s = build_with(text, RenderingCoordinateSystem::World);
    assert!(s.camera.camera_transform.world_from_render.is_identity());
    assert!(s.shapes[0].render_from_object.is_identity());
    // The Option overrides the builder option.
    let s = build_with(
        &format!("Option \"string rendercoordsys\" \"world\"\n{text}"),
        RenderingCoordinateSystem::Camera,
    );
    assert_eq!(s.render_coord_sys, RenderingCoordinateSystem::World);
    assert!(s.shapes[0].render_from_object.is_identity());
    assert_eq!(
        s.option("rendercoordsys"),
        Some(&OptionValue::String("world".into()))
    );
    assert_error(
        &format!("{text}Option \"rendercoordsys\" \"camera\"\n"),
        "<string>:5:1:",
        "before Camera",
    );
}

#[test]
fn active_transform_makes_animated_shapes() {
    let s = build(
        "TransformTimes 0 2\nWorldBegin\nActiveTransform EndTime\nTranslate 1 0 0\n\
         ActiveTransform All\nShape \"sphere\"\nTranslate 0 1 0\nShape \"disk\"\n\
         ActiveTransform StartTime\nTranslate 1 0 0\nShape \"cylinder\"\n",
    );
    assert_eq!(s.animated_shapes.len(), 2);
    let a = &s.animated_shapes[0].render_from_object;
    assert_eq!((a.start_time, a.end_time), (0.0, 2.0));
    assert!(close(
        a.start_transform().apply_point(origin()),
        0.0,
        0.0,
        0.0
    ));
    assert!(close(
        a.end_transform().apply_point(origin()),
        1.0,
        0.0,
        0.0
    ));
    assert!(close(a.apply_point(origin(), 1.0), 0.5, 0.0, 0.0));
    let b = &s.animated_shapes[1].render_from_object;
    assert!(close(
        b.end_transform().apply_point(origin()),
        1.0,
        1.0,
        0.0
    ));
    // Only the start moved: both keyframes now agree.
    assert_eq!(s.shapes.len(), 1);
    assert_eq!(s.shapes[0].base.name, "cylinder");
    assert!(close(
        s.shapes[0].render_from_object.apply_point(origin()),
        1.0,
        1.0,
        0.0
    ));
}

#[test]
fn attribute_begin_end_restore_state() {
    let s = build(
        "WorldBegin\nMaterial \"conductor\"\nAttributeBegin\nTranslate 1 0 0\n\
         Material \"dielectric\"\nReverseOrientation\nAreaLightSource \"diffuse\"\n\
         MediumInterface \"fog\" \"\"\nColorSpace \"rec2020\"\nShape \"sphere\"\nAttributeEnd\n\
         Shape \"sphere\"\nMakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n",
    );
    let (inner, outer) = (&s.shapes[0], &s.shapes[1]);
    assert_eq!(s.materials[1].name, "conductor");
    assert_eq!(s.materials[2].name, "dielectric");
    assert_eq!(inner.attributes.material, MaterialRef::Index(2));
    assert!(inner.attributes.reverse_orientation);
    assert_eq!(inner.attributes.light_index, Some(0));
    assert_eq!(inner.attributes.inside_medium, "fog");
    assert_eq!(inner.base.color_space, "rec2020");
    assert_eq!(outer.attributes.material, MaterialRef::Index(1));
    assert!(!outer.attributes.reverse_orientation);
    assert_eq!(outer.attributes.light_index, None);
    assert_eq!(outer.attributes.inside_medium, "");
    assert_eq!(outer.base.color_space, "srgb");
    assert!(outer.render_from_object.is_identity());
    assert_eq!(s.area_lights.len(), 1);
}

#[test]
fn transform_begin_end_restore_only_the_transform() {
    let s = build(
        "WorldBegin\nTransformBegin\nTranslate 0 0 3\nMaterial \"conductor\"\n\
         Shape \"sphere\"\nTransformEnd\nShape \"sphere\"\n",
    );
    assert!(close(
        s.shapes[0].render_from_object.apply_point(origin()),
        0.0,
        0.0,
        3.0
    ));
    assert!(s.shapes[1].render_from_object.is_identity());
    assert_eq!(s.shapes[1].attributes.material, MaterialRef::Index(1));
    // Mismatched nesting is an error.
    assert_error(
        "WorldBegin\nAttributeBegin\nTransformEnd\n",
        "<string>:3:1:",
        "mismatched nesting: open AttributeBegin from <string>:2:1",
    );
}

#[test]
fn named_materials_textures_and_media() {
    let s = build(
        "WorldBegin\nTexture \"checks\" \"spectrum\" \"checkerboard\" \"float uscale\" 4\n\
         Texture \"bump\" \"float\" \"fbm\"\n\
         MakeNamedMaterial \"gold\" \"string type\" \"conductor\" \"spectrum eta\" \"metal-Au-eta\"\n\
         MakeNamedMedium \"smoke\" \"string type\" \"homogeneous\"\n\
         NamedMaterial \"gold\"\nShape \"sphere\"\n",
    );
    let gold = s.named_material("gold").expect("gold");
    assert_eq!(gold.name, "conductor");
    assert_eq!(gold.loc.line, 4);
    assert_eq!(
        s.shapes[0].attributes.material,
        MaterialRef::Named("gold".into())
    );
    assert_eq!(
        s.spectrum_texture("checks").map(|t| t.base.name.as_ref()),
        Some("checkerboard")
    );
    assert_eq!(
        s.float_texture("bump").map(|t| t.kind),
        Some(TextureKind::Float)
    );
    assert!(s.float_texture("checks").is_none());
    assert_eq!(
        s.medium("smoke").map(|m| m.base.name.as_ref()),
        Some("homogeneous")
    );

    assert_error(
        "WorldBegin\nNamedMaterial \"nope\"\nShape \"sphere\"\n",
        "<string>:2:1:",
        "\"nope\": named material not defined",
    );
    assert_error(
        "WorldBegin\nMakeNamedMaterial \"a\" \"string type\" \"diffuse\"\n\
         MakeNamedMaterial \"a\" \"string type\" \"diffuse\"\n",
        "<string>:3:1:",
        "named material redefined",
    );
    assert_error(
        "WorldBegin\nTexture \"t\" \"float\" \"fbm\"\n  Texture \"t\" \"float\" \"fbm\"\n",
        "<string>:3:3:",
        "redefining texture \"t\"",
    );
    assert_error(
        "WorldBegin\nTexture \"t\" \"vector\" \"fbm\"\n",
        "<string>:2:1:",
        "texture type unknown",
    );
    assert_error(
        "MakeNamedMedium \"m\" \"string type\" \"homogeneous\"\n\
         MakeNamedMedium \"m\" \"string type\" \"homogeneous\"\nWorldBegin\n",
        "<string>:2:1:",
        "named medium \"m\" redefined",
    );
    assert_error(
        "WorldBegin\nMediumInterface \"nothere\" \"\"\n",
        "<string>:2:1:",
        "\"nothere\": medium not defined",
    );
    assert_error(
        "WorldBegin\nMakeNamedMaterial \"a\" \"rgb reflectance\" [1 1 1]\n",
        "<string>:2:1:",
        "no parameter \"string type\"",
    );
}

#[test]
fn attribute_defaults_are_inherited() {
    let s = build(
        "WorldBegin\nAttributeBegin\nAttribute \"shape\" \"float radius\" 2\n\
         Shape \"sphere\"\nShape \"sphere\" \"float radius\" 3\nAttributeEnd\nShape \"sphere\"\n\
         Attribute \"light\" \"float scale\" 5\nLightSource \"point\"\n",
    );
    let r = |i: usize| {
        s.shapes[i]
            .base
            .params
            .get_one_float("radius", 1.0)
            .unwrap()
    };
    assert_eq!((r(0), r(1), r(2)), (2.0, 3.0, 1.0));
    let scale = s.lights[0].base.params.get_one_float("scale", 1.0).unwrap();
    assert_eq!(scale, 5.0);
    // Inherited parameters are not the entity's own, so never "unused".
    assert!(s.shapes[0].base.params.report_unused().is_empty());
    assert_error(
        "WorldBegin\nAttribute \"camera\" \"float fov\" 3\n",
        "<string>:2:1:",
        "unknown attribute target \"camera\"",
    );
}

#[test]
fn object_instances() {
    let s = build(
        "WorldBegin\nObjectBegin \"thing\"\nTranslate 1 0 0\nShape \"sphere\"\nObjectEnd\n\
         Shape \"disk\"\nTranslate 0 5 0\nObjectInstance \"thing\"\n",
    );
    let def = s.instance_definition("thing").expect("definition");
    assert_eq!(def.shapes.len(), 1);
    assert_eq!(def.loc.line, 2);
    // Transform directives inside ObjectBegin apply; ObjectEnd restores.
    assert!(close(
        def.shapes[0].render_from_object.apply_point(origin()),
        1.0,
        0.0,
        0.0
    ));
    assert_eq!(s.shapes.len(), 1);
    assert!(s.shapes[0].render_from_object.is_identity());
    match s.instances.get(0).1 {
        InstanceTransform::Fixed(t) => assert!(close(t.apply_point(origin()), 0.0, 5.0, 0.0)),
        InstanceTransform::Animated(_) => panic!("not animated"),
    }

    assert_error(
        "WorldBegin\nObjectInstance \"ghost\"\n",
        "<string>:2:1:",
        "\"ghost\": object instance not defined",
    );
    assert_error(
        "WorldBegin\nObjectBegin \"a\"\nObjectBegin \"b\"\nObjectEnd\nObjectEnd\n",
        "<string>:3:1:",
        "ObjectBegin called inside of instance definition",
    );
    assert_error(
        "WorldBegin\nObjectBegin \"a\"\nObjectEnd\nObjectBegin \"b\"\nObjectInstance \"a\"\nObjectEnd\n",
        "<string>:5:1:",
        "ObjectInstance can't be called inside instance definition",
    );
    assert_error(
        "WorldBegin\nObjectEnd\n",
        "<string>:2:1:",
        "ObjectEnd called outside of instance definition",
    );
}

#[test]
fn pbrt_v3_matte_becomes_diffuse() {
    let (s, diags) = build_scene_from_str(
        "WorldBegin\nMaterial \"matte\" \"color Kd\" [0.5 0.25 0.125]\nShape \"sphere\"\n",
        &BuildOptions::default(),
    )
    .expect("builds");
    let m = &s.materials[1];
    assert_eq!(m.name, "diffuse");
    let p = &m.params.params()[0];
    assert_eq!((&*p.ty, p.name.as_str()), ("rgb", "reflectance"));
    assert_eq!(p.floats, vec![0.5, 0.25, 0.125]);
    assert!(diags.iter().all(|d| !d.is_error()));
}

/// The description of pbrt-v3 `text` that defines texture `t` twice
/// (checked: stored as `t` and `t-renamed-0`, no errors), and its
/// redefinition warnings.
fn built_with_redefinitions(text: &str) -> (SceneDescription, Vec<String>) {
    let (s, diags) = build_scene_from_str(text, &BuildOptions::default()).expect("builds");
    assert!(diags.iter().all(|d| !d.is_error()), "{diags:?}");
    let warned = diags
        .iter()
        .filter(|d| d.severity == Severity::Warning && d.message.contains("defined again"))
        .map(|d| d.to_string())
        .collect();
    let names: Vec<&str> = s
        .spectrum_textures
        .iter()
        .map(|t| t.name.as_str())
        .collect();
    assert_eq!(names, ["t", "t-renamed-0"]);
    (s, warned)
}

/// pbrt-v3 warns about a texture or named material defined again and uses
/// the later definition from there on; what was defined before keeps the
/// earlier one (pbrt-v3 makes each when it reads it). pbrt-v4 refuses both
/// (see `errors_are_located`).
#[test]
fn pbrt_v3_redefinitions_take_effect_from_there_on() {
    let text = "WorldBegin\n\
        Texture \"t\" \"color\" \"constant\" \"color value\" [0.1 0.1 0.1]\n\
        Material \"matte\" \"texture Kd\" \"t\"\n\
        Texture \"t\" \"color\" \"scale\" \"texture tex1\" \"t\" \"rgb tex2\" [2 2 2]\n\
        Material \"matte\" \"texture Kd\" \"t\"\n\
        MakeNamedMaterial \"m\" \"string type\" \"matte\"\n\
        NamedMaterial \"m\"\n\
        MakeNamedMaterial \"m\" \"string type\" \"mirror\"\n\
        MakeNamedMaterial \"both\" \"string type\" \"mix\" \"string namedmaterial1\" \"m\" \"string namedmaterial2\" \"m\"\n\
        NamedMaterial \"m\"\n\
        Shape \"sphere\"\n";
    let (s, warned) = built_with_redefinitions(text);
    assert_eq!(warned.len(), 2, "{warned:#?}");
    assert!(warned[0].starts_with("<string>:4:1:"), "{warned:#?}");
    // The redefinition builds on the texture it replaces.
    let tex1 = s.spectrum_textures[1].base.params.get_texture("tex");
    assert_eq!(tex1.ok().flatten().as_deref(), Some("t"));
    let kd = |i: usize| {
        s.materials[i]
            .params
            .get_texture("reflectance")
            .ok()
            .flatten()
    };
    assert_eq!(kd(1).as_deref(), Some("t"));
    assert_eq!(kd(2).as_deref(), Some("t-renamed-0"));
    let named: Vec<&str> = s.named_materials.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(named, ["m", "m-renamed-0", "both"]);
    let mix = &s.named_materials[2].1.params;
    assert_eq!(
        mix.get_string_array("materials").ok(),
        Some(vec!["m-renamed-0".to_string(), "m-renamed-0".to_string()])
    );
}

/// A redefinition before anything marks the file as pbrt-v3 is pbrt-v3's
/// when a marker comes later (here only the closing `WorldEnd`), and
/// pbrt-v4's error when none does.
#[test]
fn redefinitions_wait_for_a_later_pbrt_v3_marker() {
    let v4 = "WorldBegin\n\
        Texture \"t\" \"spectrum\" \"checkerboard\"\n\
        Texture \"t\" \"spectrum\" \"checkerboard\" \"float uscale\" 4\n\
        Material \"diffuse\" \"texture reflectance\" \"t\"\n\
        MakeNamedMaterial \"m\" \"string type\" \"diffuse\"\n\
        MakeNamedMaterial \"m\" \"string type\" \"conductor\"\n\
        NamedMaterial \"m\"\n\
        Shape \"sphere\"\n";
    let (s, warned) = built_with_redefinitions(&format!("{v4}WorldEnd\n"));
    assert_eq!(warned.len(), 2, "{warned:#?}");
    assert!(warned[0].starts_with("<string>:3:1:"), "{warned:#?}");
    assert!(warned[1].starts_with("<string>:6:1:"), "{warned:#?}");
    let named: Vec<&str> = s.named_materials.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(named, ["m", "m-renamed-0"]);
    assert_error(v4, "<string>:3:1:", "redefining texture \"t\"");
    assert_error(v4, "<string>:6:1:", "named material redefined");
}

#[test]
fn pbrt_v3_only_constructs_mark_the_scene() {
    let first = |text: &str| build(text).pbrt_v3.map(|l| (l.line, l.column));
    // pbrt-v4 text, pbrt-v3 type names included (the mapping runs on
    // every file), is not marked.
    let v4 = "Film \"rgb\"\nWorldBegin\nMaterial \"matte\" \"rgb Kd\" [1 1 1]\nLightSource \"goniometric\" \"rgb I\" [1 1 1]\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\n";
    assert_eq!(first(v4), None);
    assert_eq!(first(&format!("{v4}WorldEnd\n")), Some((6, 1)));
    assert_eq!(
        first("WorldBegin\nAttributeBegin\nLightSource \"point\" \"point from\" [0 0 0]\nAttributeEnd\nWorldEnd\n"),
        Some((3, 21))
    );
    assert_eq!(
        first("Camera \"perspective\"\nWorldBegin\nTexture \"t\" \"spectrum\" \"constant\" \"color value\" [1 1 1]\n"),
        Some((3, 35))
    );
    assert_eq!(
        first("WorldBegin\nAttribute \"shape\" \"vector v\" [0 0 1]\n"),
        Some((2, 19))
    );
}

#[test]
fn pbrt_v3_scenes_take_pbrt_v3_option_defaults() {
    let names = |s: &SceneDescription| {
        [&s.filter, &s.sampler, &s.integrator, &s.film].map(|e| e.name.clone())
    };
    let v4 = build("WorldBegin\nShape \"sphere\"\n");
    assert_eq!(names(&v4), ["gaussian", "zsobol", "volpath", "rgb"]);
    let v3 = build("WorldBegin\nShape \"sphere\"\nWorldEnd\n");
    assert_eq!(names(&v3), ["box", "halton", "path", "rgb"]);
    let int = |e: &SceneEntity, n: &str| {
        e.params
            .params()
            .iter()
            .find(|p| p.name == n)
            .map(|p| p.ints.clone())
    };
    assert_eq!(int(&v3.sampler, "pixelsamples"), Some(vec![16]));
    assert_eq!(int(&v3.integrator, "maxdepth"), Some(vec![5]));
    // What the file gives is kept.
    let given =
        build("Sampler \"sobol\"\nIntegrator \"bdpt\"\nWorldBegin\nShape \"sphere\"\nWorldEnd\n");
    assert_eq!(names(&given), ["box", "sobol", "bdpt", "rgb"]);
}

#[test]
fn located_errors() {
    let cases: &[(&str, &str, &str)] = &[
        ("Shape \"sphere\"\nWorldBegin\n", "<string>:1:1:", "Shape not allowed before WorldBegin"),
        ("WorldBegin\n  Camera \"perspective\"\n", "<string>:2:3:", "Camera not allowed after WorldBegin"),
        ("WorldBegin\nFilm \"rgb\"\n", "<string>:2:1:", "Film not allowed after WorldBegin"),
        ("WorldBegin\nWorldBegin\n", "<string>:2:1:", "WorldBegin not allowed after WorldBegin"),
        ("Material \"diffuse\"\nWorldBegin\n", "<string>:1:1:", "Material not allowed before WorldBegin"),
        ("WorldBegin\nShape \"sphre\"\n", "<string>:2:1:", "\"sphre\": unknown shape type; expected one of \"bilinearmesh\""),
        ("WorldBegin\nMaterial \"plasticky\"\n", "<string>:2:1:", "unknown material type"),
        ("WorldBegin\nLightSource \"sun\"\n", "<string>:2:1:", "unknown light type"),
        ("WorldBegin\nAreaLightSource \"glow\"\n", "<string>:2:1:", "unknown area light type"),
        ("WorldBegin\nTexture \"t\" \"float\" \"noise\"\n", "<string>:2:1:", "unknown texture class type"),
        ("Film \"png\"\nWorldBegin\n", "<string>:1:1:", "unknown film type"),
        ("Sampler \"rnd\"\nWorldBegin\n", "<string>:1:1:", "unknown sampler type"),
        ("PixelFilter \"lanczos\"\nWorldBegin\n", "<string>:1:1:", "unknown pixel filter type"),
        ("Integrator \"whited\"\nWorldBegin\n", "<string>:1:1:", "unknown integrator type"),
        ("Accelerator \"octree\"\nWorldBegin\n", "<string>:1:1:", "unknown accelerator type; expected one of \"bvh\", \"embree\", \"grid\", \"kdtree\""),
        ("Camera \"pinhole\"\nWorldBegin\n", "<string>:1:1:", "unknown camera type"),
        ("MakeNamedMedium \"m\" \"string type\" \"fog\"\nWorldBegin\n", "<string>:1:21:", "unknown medium type"),
        ("ColorSpace \"adobe\"\nWorldBegin\n", "<string>:1:1:", "\"adobe\": unknown color space type; expected one of \"aces2065-1\", \"dci-p3\", \"rec2020\", \"srgb\""),
        ("Option \"bogus\" true\nWorldBegin\n", "<string>:1:1:", "unknown option"),
        ("Option \"seed\" \"x\"\nWorldBegin\n", "<string>:1:1:", "expected an integer"),
        ("WorldBegin\nAttributeEnd\n", "<string>:2:1:", "unmatched AttributeEnd"),
        ("WorldBegin\nAttributeBegin\n", "<string>:2:1:", "missing end to AttributeBegin"),
        ("LookAt 0 0 0  0 1 0  0 1 0\nWorldBegin\n", "<string>:1:1:", "LookAt"),
        ("WorldBegin\nTransform [0 0 0 0  0 0 0 0  0 0 0 0  0 0 0 0]\n", "<string>:2:1:", "singular"),
        ("WorldBegin\nConcatTransform [1 0 0 0  1 0 0 0  0 0 1 0  0 0 0 1]\n", "<string>:2:1:", "singular"),
        ("WorldBegin\nRotate 30 0 0 0\n", "<string>:2:1:", "zero length"),
        ("TransformTimes 2 1\nWorldBegin\n", "<string>:1:1:", "TransformTimes"),
    ];
    for (text, at, what) in cases {
        assert_error(text, at, what);
    }
    let errs = errors("Camera \"perspective\"\n");
    assert!(
        errs.iter()
            .any(|e| e == "error: end of files before \"WorldBegin\""),
        "{errs:?}"
    );
}

#[test]
fn bad_transforms_leave_ctm_unchanged() {
    let text = "WorldBegin\nTranslate 1 0 0\nLookAt 0 0 0  0 1 0  0 1 0\n\
                Transform [0 0 0 0  0 0 0 0  0 0 0 0  0 0 0 0]\nShape \"sphere\"\n";
    let mut b = SceneBuilder::new(RenderingCoordinateSystem::World);
    let r = parse_string(text, &mut b);
    assert!(r.is_err());
    let s = b.finish();
    assert!(close(
        s.shapes[0].render_from_object.apply_point(origin()),
        1.0,
        0.0,
        0.0
    ));
}

#[test]
fn deep_attribute_nesting() {
    const N: usize = 100_000;
    let mut text = String::with_capacity(N * 30);
    text.push_str("WorldBegin\n");
    for _ in 0..N {
        text.push_str("AttributeBegin\n");
    }
    text.push_str("Material \"conductor\"\nShape \"sphere\"\n");
    for _ in 0..N {
        text.push_str("AttributeEnd\n");
    }
    text.push_str("Shape \"sphere\"\n");
    let mut b = SceneBuilder::new(RenderingCoordinateSystem::World);
    parse_string(&text, &mut b).expect("parses");
    assert_eq!(b.nesting_depth(), 0);
    let s = b.finish();
    assert_eq!(s.shapes[0].attributes.material, MaterialRef::Index(1));
    assert_eq!(s.shapes[1].attributes.material, MaterialRef::Index(0));
}

const V3_SCENE: &str = r#"
LookAt 0 5 -10  0 0 0  0 1 0
Camera "perspective" "float fov" [ 40 ]
Film "image" "integer xresolution" [ 64 ] "integer yresolution" [ 48 ] "string filename" "out.exr"
Sampler "lowdiscrepancy" "integer pixelsamples" [ 16 ]
PixelFilter "gaussian" "float xwidth" [ 2 ] "float ywidth" [ 2 ]
Integrator "path" "float rrthreshold" [ 0.5 ]
WorldBegin
LightSource "point" "color I" [ 10 10 10 ] "point from" [ 0 4 0 ]
AttributeBegin
  AreaLightSource "area" "color L" [ 4 4 4 ] "integer nsamples" [ 4 ]
  Translate 0 3 0
  Shape "disk" "float radius" [ 0.5 ]
AttributeEnd
Texture "checks" "color" "checkerboard" "color tex1" [ 1 1 1 ] "color tex2" [ 0 0 0 ]
Material "matte" "texture Kd" "checks"
Shape "trianglemesh" "point P" [ -1 0 -1  1 0 -1  1 0 1  -1 0 1 ] "integer indices" [ 0 1 2  0 2 3 ] "float uv" [ 0 0 1 0 1 1 0 1 ]
MakeNamedMaterial "glassy" "string type" "glass" "float index" [ 1.5 ]
NamedMaterial "glassy"
TransformBegin
  Translate 0 1 0
  Shape "sphere" "float radius" [ 1 ]
TransformEnd
Material "plastic" "color Kd" [ 0.2 0.3 0.4 ] "color Ks" [ 0.5 0.5 0.5 ] "float roughness" [ 0.1 ]
Shape "sphere" "float radius" [ 0.25 ]
WorldEnd
"#;

#[test]
fn pbrt_v3_file_and_its_upgrade_agree() {
    let mut fmt = FormattingTarget::new(true);
    parse_string(V3_SCENE, &mut fmt).expect("formats");
    let v4 = fmt.into_output();
    let (a, _) = build_scene_from_str(V3_SCENE, &BuildOptions::default()).expect("v3 builds");
    let (b, warnings) = build_scene_from_str(&v4, &BuildOptions::default()).expect("v4 builds");
    assert_eq!(
        a.normalized_dump(),
        b.normalized_dump(),
        "upgraded text:\n{v4}"
    );
    assert_eq!(a.film.name, "rgb");
    assert_eq!(a.sampler.name, "paddedsobol");
    assert_eq!(a.integrator.name, "path");
    assert_eq!(
        a.named_material("glassy").map(|m| &*m.name),
        Some("dielectric")
    );
    assert_eq!(a.area_lights[0].name, "diffuse");
    // The pbrt-v4 text passes through without upgrade messages.
    let upgrade_msgs: Vec<_> = warnings
        .iter()
        .filter(|d| !d.message.contains("deprecated"))
        .collect();
    assert!(upgrade_msgs.is_empty(), "{upgrade_msgs:?}");
}

#[test]
fn v4_input_is_unchanged() {
    let text = "WorldBegin\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \
                \"integer indices\" [0 1 2]\nLightSource \"point\" \"rgb I\" [1 1 1]\n";
    let (s, diags) = build_scene_from_str(text, &BuildOptions::default()).expect("builds");
    assert!(diags.is_empty(), "{diags}");
    let names: Vec<&str> = s.shapes[0]
        .base
        .params
        .params()
        .iter()
        .map(|p| p.name.as_str())
        .collect();
    assert_eq!(names, ["P", "indices"]);
}

fn pbrt_files(dir: &std::path::Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.extension().is_some_and(|x| x == "pbrt") {
            out.push(p);
        }
    }
}

/// Needs the third-party scenes in `../shared/scenes` beside the project,
/// which a fresh clone does not have: `.ci/run` runs it with `--ignored`.
#[test]
#[ignore = "needs ../shared/scenes beside the project; .ci/run runs it"]
fn shared_scenes_build_without_errors() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes");
    assert!(
        root.is_dir(),
        "{} is missing: this test needs the shared scenes",
        root.display()
    );
    let mut files = Vec::new();
    if let Ok(dirs) = std::fs::read_dir(&root) {
        for d in dirs.flatten() {
            pbrt_files(&d.path(), &mut files);
        }
    }
    files.sort();
    let mut built = 0;
    for f in &files {
        // Only top-level scene files (those with a WorldBegin) are scenes.
        let text = std::fs::read_to_string(f).unwrap_or_default();
        if !text.contains("WorldBegin") {
            continue;
        }
        if let Err(d) = build_scene(std::slice::from_ref(f), &BuildOptions::default()) {
            panic!("{}:\n{}", f.display(), d);
        }
        built += 1;
    }
    assert!(built > 0, "no scene under {}", root.display());
}

#[test]
fn imports_build_the_scene_a_one_thread_parse_builds() {
    let d = std::env::temp_dir().join(format!("rpbrt-import-scene-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let main = "Camera \"perspective\"\nWorldBegin\nShape \"sphere\"\nImport \"a.pbrt\"\n\
        Translate 0 0 1\nImport \"b.pbrt\"\nShape \"disk\"\n";
    std::fs::write(d.join("main.pbrt"), main).unwrap();
    std::fs::write(
        d.join("a.pbrt"),
        "Translate 5 0 0\nMaterial \"conductor\"\nShape \"sphere\" \"float radius\" 2\n",
    )
    .unwrap();
    std::fs::write(d.join("b.pbrt"), "Shape \"cylinder\"\n").unwrap();
    let run = |parallel: bool| {
        let mut o = opts(RenderingCoordinateSystem::World);
        o.parse.parallel_import = parallel;
        match build_scene(&[d.join("main.pbrt")], &o) {
            Ok((s, _)) => s,
            Err(e) => panic!("{e}"),
        }
    };
    let (par, seq) = (run(true), run(false));
    let describe = |s: &SceneDescription| format!("{:?}", s.shapes);
    assert_eq!(describe(&par), describe(&seq));
    let names: Vec<&str> = par.shapes.iter().map(|s| s.base.name.as_ref()).collect();
    assert_eq!(names, ["sphere", "sphere", "cylinder", "disk"]);
    // The import's Translate and Material stay inside it.
    let at = |i: usize| par.shapes[i].render_from_object.apply_point(origin());
    assert!(close(at(1), 5.0, 0.0, 0.0));
    assert!(close(at(2), 0.0, 0.0, 1.0));
    assert!(close(at(3), 0.0, 0.0, 1.0));
    assert_eq!(
        par.shapes[0].attributes.material,
        par.shapes[3].attributes.material
    );
    // pbrt-v4 allows Import only in the world block.
    std::fs::write(d.join("early.pbrt"), "Import \"b.pbrt\"\nWorldBegin\n").unwrap();
    let o = opts(RenderingCoordinateSystem::World);
    let e = build_scene(&[d.join("early.pbrt")], &o)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("early.pbrt:1:1: error: Import statement only allowed inside world"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&d);
}

/// The integrator a pbrt-v1/v2 options block makes, with its integer
/// parameters, and the build's messages.
fn v2_integrator(opts: &str, world: &str) -> (String, Vec<(String, i32)>, Vec<String>) {
    let text = format!("{opts}\nWorldBegin\n{world}\nShape \"sphere\"\n");
    let (s, diags) = build_scene_from_str(&text, &BuildOptions::default())
        .unwrap_or_else(|d| panic!("unexpected errors in:\n{text}\n{d}"));
    let ints = s
        .integrator
        .params
        .params()
        .iter()
        .filter(|p| p.ty == "integer")
        .map(|p| (p.name.clone(), p.ints[0]))
        .collect();
    let msgs = diags.iter().map(|d| d.to_string()).collect();
    (s.integrator.name.to_string(), ints, msgs)
}

#[test]
fn pbrt_v2_transport_becomes_one_integrator() {
    let depth = |d: i32| vec![("maxdepth".to_string(), d)];
    // The default surface integrator, directlighting (maxdepth 5), is
    // rendered by pbrt-v3's whitted: the same light transport.
    let (name, ints, msgs) = v2_integrator("Renderer \"sampler\"", "");
    assert_eq!((name.as_str(), ints), ("whitted", depth(5)));
    assert!(msgs.is_empty(), "{msgs:?}");
    let (name, ints, _) = v2_integrator("SurfaceIntegrator \"path\" \"integer maxdepth\" 9", "");
    assert_eq!((name.as_str(), ints), ("path", depth(9)));
    let (name, ints, _) = v2_integrator("SurfaceIntegrator \"whitted\"", "");
    assert_eq!((name.as_str(), ints), ("whitted", depth(5)));
    // Approximations warn, located at their directive.
    for (si, what) in [
        ("photonmap", "photon mapping"),
        ("irradiancecache", "irradiance caching"),
        ("igi", "instant global illumination"),
        ("glossyprt", "precomputed radiance transfer"),
    ] {
        let (name, _, msgs) =
            v2_integrator(&format!("Film \"image\"\nSurfaceIntegrator \"{si}\""), "");
        assert_eq!(name, "path", "{si}");
        assert!(
            msgs.iter()
                .any(|m| m.starts_with("<string>:2:1: warning:") && m.contains(what)),
            "{si}: {msgs:?}"
        );
    }
    let (name, _, msgs) = v2_integrator("SurfaceIntegrator \"dipolesubsurface\"", "");
    assert_eq!(name, "volpath");
    assert!(msgs.iter().any(|m| m.contains("dipole")), "{msgs:?}");
    // Metropolis is mlt.
    let (name, ints, _) = v2_integrator(
        "Renderer \"metropolis\" \"integer samplesperpixel\" 16 \"bool dodirectseparately\" \"false\"",
        "",
    );
    assert_eq!(name, "mlt");
    assert!(
        ints.contains(&("mutationsperpixel".to_string(), 16)),
        "{ints:?}"
    );
    assert!(ints.contains(&("maxdepth".to_string(), 7)), "{ints:?}");
    // Regions: volpath, scattering only with a scattering volume
    // integrator.
    let region = "Volume \"homogeneous\" \"color sigma_s\" [ 1 1 1 ]";
    let (name, _, _) = v2_integrator(
        "SurfaceIntegrator \"path\"\nVolumeIntegrator \"single\"",
        region,
    );
    assert_eq!(name, "volpath");
    let s = build("SurfaceIntegrator \"path\"\nWorldBegin\nVolume \"homogeneous\"\n");
    assert!(!s.regions_scatter && s.volume_regions.len() == 1);
    let s = build("VolumeIntegrator \"single\"\nWorldBegin\nVolume \"exponential\"\n");
    assert!(s.regions_scatter);
    assert_eq!(s.integrator.name, "volpath");
    // An Integrator line wins, with a warning at the pbrt-v2 one.
    let (name, _, msgs) = v2_integrator("SurfaceIntegrator \"path\"\nIntegrator \"bdpt\"", "");
    assert_eq!(name, "bdpt");
    assert!(
        msgs.iter()
            .any(|m| m.starts_with("<string>:1:1: warning: ignored")),
        "{msgs:?}"
    );
}

#[test]
fn pbrt_v2_defaults_and_refusals() {
    let s = build(
        "SurfaceIntegrator \"path\"\nFilm \"image\" \"string filename\" \"x.exr\"\nWorldBegin\n",
    );
    assert_eq!(s.film.name, "rgb");
    assert_eq!(s.film.params.get_one_int("xresolution", 0).unwrap(), 640);
    assert_eq!(s.film.params.get_one_int("yresolution", 0).unwrap(), 480);
    assert_eq!(s.sampler.name, "paddedsobol");
    assert_eq!(s.sampler.params.get_one_int("pixelsamples", 0).unwrap(), 4);
    assert_eq!(s.filter.name, "box");
    assert!(s.pbrt_v2.is_some() && s.pbrt_v3.is_some());
    let s = build("SurfaceIntegrator \"path\"\nSampler \"stratified\"\nWorldBegin\n");
    assert_eq!(s.sampler.params.get_one_int("xsamples", 0).unwrap(), 2);
    let s = build("SurfaceIntegrator \"path\"\nSampler \"adaptive\" \"integer maxsamples\" 64\nAccelerator \"grid\"\nWorldBegin\n");
    assert_eq!(s.sampler.name, "paddedsobol");
    assert_eq!(s.sampler.params.get_one_int("pixelsamples", 0).unwrap(), 64);
    assert_eq!(s.accelerator.name, "bvh");
    // pbrt-v1's sampled environment light is pbrt-v4's infinite light.
    let s = build("SurfaceIntegrator \"path\"\nWorldBegin\nLightSource \"infinitesample\" \"color L\" [ 1 1 1 ]\n");
    assert_eq!(s.lights[0].base.name, "infinite");
    // A pbrt-v2 material marks the file too.
    let s = build("WorldBegin\nMaterial \"shinymetal\" \"color Ks\" [ 0.5 0.5 0.5 ]\n");
    assert!(s.pbrt_v2.is_some());
    assert_eq!(s.integrator.name, "whitted");
    // Renderers that make no image, unknown types and misplaced
    // directives are located errors.
    for (text, at, what) in [
        (
            "Renderer \"createprobes\"\nWorldBegin\n",
            "<string>:1:1:",
            "makes no image",
        ),
        (
            "Renderer \"aggregatetest\"\nWorldBegin\n",
            "<string>:1:1:",
            "makes no image",
        ),
        (
            "Renderer \"fast\"\nWorldBegin\n",
            "<string>:1:1:",
            "unknown pbrt-v2 renderer",
        ),
        (
            "SurfaceIntegrator \"foo\"\nWorldBegin\n",
            "<string>:1:1:",
            "unknown pbrt-v2 surface integrator",
        ),
        (
            "VolumeIntegrator \"foo\"\nWorldBegin\nVolume \"homogeneous\"\n",
            "<string>:1:1:",
            "unknown pbrt-v2 volume integrator",
        ),
        (
            "WorldBegin\nSurfaceIntegrator \"path\"\n",
            "<string>:2:1:",
            "SurfaceIntegrator",
        ),
        (
            "Volume \"homogeneous\"\nWorldBegin\n",
            "<string>:1:1:",
            "Volume",
        ),
    ] {
        assert_error(text, at, what);
    }
}

#[test]
fn pbrt_v2_point_light_adds_from_after_the_transformation() {
    // pbrt-v2: Translate(from) · CTM puts the light at CTM(0) + from =
    // (1, 0, 0) + (0, 0, 2); pbrt-v3 would put it at CTM(from).
    let text = "SurfaceIntegrator \"path\"\nWorldBegin\nTranslate 1 0 0\nRotate 90 0 1 0\n\
                LightSource \"point\" \"point from\" [ 0 0 2 ]\n";
    let s = build(text);
    let l = &s.lights[0];
    let from = l.base.params.get_one_point3("from", [0.0; 3]).unwrap();
    let p = l
        .render_from_object
        .start_transform()
        .apply_point(Point3f::new(from[0], from[1], from[2]));
    assert!(close(p, 1.0, 0.0, 2.0), "{p:?}");
    // The same text read as pbrt-v3.
    let s = build(&text.replace("SurfaceIntegrator \"path\"\n", ""));
    let l = &s.lights[0];
    let from = l.base.params.get_one_point3("from", [0.0; 3]).unwrap();
    let p = l
        .render_from_object
        .start_transform()
        .apply_point(Point3f::new(from[0], from[1], from[2]));
    assert!(close(p, 3.0, 0.0, 0.0), "{p:?}");
}

#[test]
fn pbrt_v1_defaults_materials_and_camera() {
    let text = "SearchPath \"/usr/local/pbrt/lib:&\"\nLookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\"\n\
                WorldBegin\nMaterial \"matte\"\nShape \"sphere\"\nMaterial \"clay\"\n";
    let s = build_with(text, RenderingCoordinateSystem::CameraWorld);
    assert!(s.pbrt_v1.is_some() && s.pbrt_v2.is_some() && s.pbrt_v3.is_some());
    assert_eq!(s.filter.name, "mitchell");
    assert_eq!(s.sampler.name, "pmj02bn");
    assert_eq!(s.sampler.params.get_one_int("pixelsamples", 0).unwrap(), 4);
    assert_eq!(s.accelerator.name, "kdtree");
    assert_eq!(s.integrator.name, "whitted");
    // pbrt-v1's matte defaults to Kd 1, and so does its default material.
    let matte = &s.materials[1];
    assert_eq!(matte.name, "diffuse");
    assert_eq!(
        matte.params.get_one_rgb("reflectance").unwrap(),
        Some([1.0, 1.0, 1.0])
    );
    assert_eq!(
        s.materials[0].params.get_one_rgb("reflectance").unwrap(),
        Some([1.0, 1.0, 1.0])
    );
    assert_eq!(s.materials[2].name, "clay");
    // pbrt-v1's LookAt mirrored the camera frame in x: camera +x looks
    // toward world −x.
    let rfc = s
        .camera
        .camera_transform
        .render_from_camera
        .start_transform();
    let x = rfc.apply_vector(Vector3f::new(1.0, 0.0, 0.0));
    assert!((x.x + 1.0).abs() < 1e-5, "{x:?}");
    // Read as pbrt-v2 (no pbrt-v1 construct), the same camera is not
    // mirrored.
    let s = build("SurfaceIntegrator \"path\"\nLookAt 0 0 0  0 0 1  0 1 0\nCamera \"perspective\"\nWorldBegin\n");
    let rfc = s
        .camera
        .camera_transform
        .render_from_camera
        .start_transform();
    let x = rfc.apply_vector(Vector3f::new(1.0, 0.0, 0.0));
    assert!((x.x - 1.0).abs() < 1e-5, "{x:?}");
    assert_error(
        "WorldBegin\nSearchPath \"x\"\n",
        "<string>:2:1:",
        "SearchPath",
    );
}

/// pbrt-v3's colour `scale` on a light with a spectral or blackbody
/// emission multiplies the RGB pbrt-v3 made of that emission (its XYZ in
/// sRGB); a uniform scale stays a float scale.
#[test]
fn pbrt_v3_colour_scale_multiplies_spectral_emission() {
    use crate::spectrum::{
        spectrum_to_xyz, BlackbodySpectrum, PiecewiseLinearSpectrum, RgbColorSpace, Spectrum,
    };
    let text = "WorldBegin\n\
        LightSource \"point\" \"spectrum I\" [400 1 500 2 600 3 700 4] \"color scale\" [1 0.5 0.25]\n\
        LightSource \"distant\" \"blackbody L\" [3000 2] \"rgb scale\" [0.5 1 1]\n\
        LightSource \"spot\" \"spectrum I\" [400 1 700 1] \"color scale\" [2 2 2]\n\
        AttributeBegin\n\
        AreaLightSource \"area\" \"spectrum L\" [400 1 700 3] \"color scale\" [1 0 1]\n\
        Shape \"sphere\"\n\
        AttributeEnd\n\
        WorldEnd\n";
    let (s, diags) = build_scene_from_str(text, &BuildOptions::default()).expect("builds");
    assert!(diags.iter().all(|d| !d.is_error()), "{diags:?}");
    let rgb_of = |sp: Spectrum| {
        let c = RgbColorSpace::srgb().to_rgb(spectrum_to_xyz(&sp));
        [c.r, c.g, c.b]
    };
    let close = |got: [f32; 3], want: [f32; 3]| {
        got.iter()
            .zip(want)
            .all(|(a, b)| (a - b).abs() <= 1e-5 * b.abs().max(1.0))
    };
    let emission = |params: &rpbrt_parser::ParameterDictionary, name: &str| {
        assert_eq!(params.param_type(name), Some("rgb"), "{params:?}");
        params.get_one_rgb(name).unwrap().unwrap()
    };
    let sampled = |v: &[f32]| {
        Spectrum::PiecewiseLinear(std::sync::Arc::new(
            PiecewiseLinearSpectrum::from_interleaved(v, false).unwrap(),
        ))
    };
    let want = rgb_of(sampled(&[400.0, 1.0, 500.0, 2.0, 600.0, 3.0, 700.0, 4.0]));
    let got = emission(&s.lights[0].base.params, "I");
    assert!(
        close(got, [want[0], want[1] * 0.5, want[2] * 0.25]),
        "{got:?} {want:?}"
    );
    let bb = rgb_of(Spectrum::Blackbody(BlackbodySpectrum::new(3000.0)));
    let got = emission(&s.lights[1].base.params, "L");
    assert!(
        close(got, [bb[0], bb[1] * 2.0, bb[2] * 2.0]),
        "{got:?} {bb:?}"
    );
    // A uniform scale folds into the float scale; the spectrum stays.
    let spot = &s.lights[2].base.params;
    assert_eq!(spot.param_type("I"), Some("spectrum"));
    assert_eq!(spot.get_one_float("scale", 1.0).ok(), Some(2.0));
    let area = &s.area_lights[s.shapes[0].attributes.light_index.expect("area light")];
    let want = rgb_of(sampled(&[400.0, 1.0, 700.0, 3.0]));
    let got = emission(&area.params, "L");
    assert!(close(got, [want[0], 0.0, want[2]]), "{got:?} {want:?}");
}
