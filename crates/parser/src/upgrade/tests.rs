//! Tests of the pbrt-v3 → pbrt-v4 mappings.
use super::*;
use std::sync::Arc;

fn loc(line: u32) -> FileLoc {
    FileLoc::new(Arc::from("v3.pbrt"), line, 1)
}

fn f(ty: &str, name: &str, v: &[f32]) -> ParsedParameter {
    ParsedParameter::with_floats(ty, name, loc(2), v.to_vec())
}

fn s(ty: &str, name: &str, v: &[&str]) -> ParsedParameter {
    ParsedParameter::with_strings(ty, name, loc(3), v.iter().map(|x| x.to_string()).collect())
}

fn names(u: &Upgraded) -> Vec<String> {
    u.params
        .iter()
        .map(|p| format!("{} {}", p.ty, p.name))
        .collect()
}

#[test]
fn param_types() {
    let mut p = vec![
        f("point", "P", &[0.; 3]),
        f("vector", "v", &[0.; 3]),
        f("color", "c", &[0.; 3]),
        f("normal3", "N", &[0.; 3]),
    ];
    upgrade_param_types(&mut p);
    let t: Vec<&str> = p.iter().map(|p| &*p.ty).collect();
    assert_eq!(t, ["point3", "vector3", "rgb", "normal"]);
}

#[test]
fn materials() {
    let u = upgrade_material("matte", vec![f("color", "Kd", &[0.5; 3])], &loc(1));
    assert_eq!(
        (u.name.as_str(), names(&u)),
        ("diffuse", vec!["rgb reflectance".to_string()])
    );
    let u = upgrade_material(
        "plastic",
        vec![f("rgb", "Ks", &[0.2; 3]), f("float", "roughness", &[0.1])],
        &loc(1),
    );
    assert_eq!(u.name, "coateddiffuse");
    // The model differs (a warning at the directive) and Ks is dropped
    // (a warning at the parameter).
    assert_eq!(u.diagnostics.len(), 2);
    assert!(u.diagnostics[0].message.contains("approximated"));
    assert_eq!(u.diagnostics[1].loc.as_ref().map(|l| l.line), Some(2));
    let u = upgrade_material(
        "substrate",
        vec![f("rgb", "Ks", &[1.; 3]), f("rgb", "Kd", &[0.3; 3])],
        &loc(1),
    );
    assert_eq!((u.name.as_str(), u.diagnostics.len()), ("coateddiffuse", 1));
    assert_eq!(names(&u), ["rgb reflectance"]);
    let u = upgrade_material(
        "uber",
        vec![f("rgb", "Ks", &[0.; 3]), f("float", "eta", &[1.5])],
        &loc(1),
    );
    assert_eq!((u.name.as_str(), u.params.len()), ("diffuse", 0));
    let u = upgrade_material("uber", vec![f("rgb", "opacity", &[0.5; 3])], &loc(1));
    assert!(u.diagnostics.iter().any(|d| d.is_error()));
    let u = upgrade_material(
        "metal",
        vec![s("spectrum", "eta", &["metal-Au-eta"])],
        &loc(1),
    );
    assert_eq!((u.name.as_str(), u.params.len()), ("conductor", 1));
    let u = upgrade_material("mirror", vec![f("rgb", "Kr", &[0.8; 3])], &loc(1));
    assert_eq!(u.name, "conductor");
    assert_eq!(names(&u), ["float roughness", "rgb reflectance"]);
    let u = upgrade_material("glass", vec![s("texture", "index", &["ior"])], &loc(1));
    assert_eq!(
        (u.name.as_str(), names(&u)),
        ("dielectric", vec!["texture eta".to_string()])
    );
    let u = upgrade_material(
        "glass",
        vec![f("float", "index", &[1.5]), f("float", "eta", &[1.3])],
        &loc(1),
    );
    assert!(u.diagnostics[0].is_error());
    let u = upgrade_material(
        "translucent",
        vec![f("rgb", "Kd", &[0.5; 3]), f("rgb", "transmit", &[1.; 3])],
        &loc(1),
    );
    assert_eq!(
        (u.name.as_str(), names(&u)),
        ("diffusetransmission", vec!["rgb transmittance".to_string()])
    );
    let u = upgrade_material("mix", vec![s("string", "namedmaterial1", &["x"])], &loc(1));
    assert!(u.diagnostics[0].is_error());
    let u = upgrade_material("fourier", vec![], &loc(1));
    assert_eq!(u.diagnostics[0].severity, crate::diag::Severity::Warning);
    assert_eq!(upgrade_material("none", vec![], &loc(1)).name, "interface");
    assert_eq!(
        upgrade_material("kdsubsurface", vec![], &loc(1)).name,
        "subsurface"
    );
}

#[test]
fn lights() {
    // A colour scale becomes the RGB emission pbrt-v3 multiplied it into
    // (1 by default); it cannot scale a blackbody.
    let u = upgrade_light("point", vec![f("rgb", "scale", &[1., 2., 3.])], &loc(1));
    assert!(u.diagnostics.is_empty(), "{:?}", u.diagnostics);
    assert_eq!(u.params.len(), 1);
    assert_eq!(
        (u.params[0].name.as_str(), &u.params[0].floats[..]),
        ("I", &[1., 2., 3.][..])
    );
    let u = upgrade_light(
        "point",
        vec![
            f("rgb", "scale", &[1., 2., 3.]),
            f("blackbody", "I", &[3000.]),
        ],
        &loc(1),
    );
    assert!(u.diagnostics[0].is_error());
    let u = upgrade_light(
        "spot",
        vec![
            f("color", "scale", &[2.; 3]),
            f("float", "scale", &[3.]),
            f("blackbody", "I", &[3000., 2.]),
        ],
        &loc(1),
    );
    let sc = u.params.iter().find(|p| p.name == "scale").unwrap();
    assert_eq!(sc.floats, [12.]);
    assert_eq!(
        u.params.iter().find(|p| p.name == "I").unwrap().floats,
        [3000.]
    );
    let u = upgrade_light(
        "infinite",
        vec![
            s("string", "mapname", &["a.exr"]),
            f("rgb", "L", &[1., 2., 3.]),
        ],
        &loc(1),
    );
    assert!(u.diagnostics.iter().any(|d| d.is_error()));
    let u = upgrade_light(
        "projection",
        vec![s("string", "mapname", &["a.exr"])],
        &loc(1),
    );
    assert_eq!(names(&u), ["string filename"]);
    // pbrt-v3's infinite light takes "nsamples"; pbrt-v4 has no use for it.
    let u = upgrade_light(
        "infinite",
        vec![
            s("string", "mapname", &["a.exr"]),
            ParsedParameter::new("integer", "nsamples", loc(1)),
        ],
        &loc(1),
    );
    assert_eq!(names(&u), ["string filename"]);
    let u = upgrade_area_light(
        "area",
        vec![
            f("blackbody", "L", &[6500., 5.]),
            ParsedParameter::new("integer", "nsamples", loc(1)),
        ],
        &loc(1),
    );
    assert_eq!(u.name, "diffuse");
    assert_eq!(names(&u), ["float scale", "blackbody L"]);
}

#[test]
fn cameras_films_samplers_integrators_filters() {
    assert_eq!(
        upgrade_sampler("02sequence", vec![], &loc(1)).name,
        "paddedsobol"
    );
    assert_eq!(
        upgrade_sampler("maxmindist", vec![], &loc(1)).name,
        "pmj02bn"
    );
    assert_eq!(
        upgrade_sampler("random", vec![], &loc(1)).name,
        "independent"
    );
    assert_eq!(upgrade_sampler("halton", vec![], &loc(1)).name, "halton");
    let u = upgrade_film(
        "image",
        vec![f("float", "maxsampleluminance", &[10.])],
        &loc(1),
    );
    assert_eq!(
        (u.name.as_str(), names(&u)),
        ("rgb", vec!["float maxcomponentvalue".to_string()])
    );
    let mut n = ParsedParameter::new("integer", "numiterations", loc(4));
    n.ints = vec![64];
    let u = upgrade_integrator(
        "sppm",
        vec![
            n,
            f("float", "rrthreshold", &[1.]),
            s("string", "lightsamplestrategy", &["spatial"]),
        ],
        &loc(1),
    );
    assert_eq!(names(&u), ["string lightsamplestrategy"]);
    assert_eq!(u.params[0].strings, ["bvh"]);
    assert_eq!(u.diagnostics[0].loc.as_ref().map(|l| l.line), Some(4));
    let mut b = ParsedParameter::new("bool", "simpleweighting", loc(1));
    b.bools = vec![true];
    assert!(upgrade_camera("realistic", vec![b], &loc(1))
        .params
        .is_empty());
    let u = upgrade_pixel_filter("box", vec![f("float", "ywidth", &[0.5])], &loc(1));
    assert_eq!(names(&u), ["float yradius"]);
    assert_eq!(
        upgrade_medium("heterogeneous", vec![], &loc(1)).name,
        "uniformgrid"
    );
}

#[test]
fn heterogeneous_medium_becomes_uniformgrid_with_v3_defaults() {
    let mut nx = ParsedParameter::new("integer", "nx", loc(4));
    nx.ints = vec![2];
    let u = upgrade_medium(
        "heterogeneous",
        vec![
            f("float", "density", &[0.5, 1.0]),
            nx,
            f("point", "p1", &[2., 1., 1.]),
            f("color", "sigma_s", &[1., 2., 3.]),
        ],
        &loc(1),
    );
    assert_eq!(u.name, "uniformgrid");
    assert!(u.diagnostics.is_empty(), "{:?}", u.diagnostics);
    // Only the absent coefficient gets pbrt-v3's default; v3 types are renamed.
    assert_eq!(
        names(&u),
        [
            "rgb sigma_a",
            "float density",
            "integer nx",
            "point3 p1",
            "rgb sigma_s"
        ]
    );
    assert_eq!(u.params[0].floats, [0.0011, 0.0024, 0.014]);
    assert_eq!(u.params[0].loc.line, 1);
    assert_eq!(u.params[4].floats, [1., 2., 3.]);

    let u = upgrade_medium(
        "heterogeneous",
        vec![
            f("float", "density", &[1.0]),
            s("string", "preset", &["Wholemilk"]),
        ],
        &loc(1),
    );
    assert_eq!(names(&u), ["rgb sigma_a", "rgb sigma_s", "float density"]);
    assert_eq!(u.params[1].floats, [2.55, 3.21, 3.77]);
    assert_eq!(u.diagnostics.len(), 1);
    assert!(!u.diagnostics[0].is_error());
    assert_eq!(u.diagnostics[0].loc.as_ref().map(|l| l.line), Some(3));
    assert!(u.diagnostics[0].message.contains("preset"));

    // pbrt-v4 media are left alone.
    let u = upgrade_medium("homogeneous", vec![f("float", "scale", &[2.])], &loc(1));
    assert_eq!(u.name, "homogeneous");
    assert_eq!(names(&u), ["float scale"]);
}

#[test]
fn textures() {
    let (ty, u) = upgrade_texture(
        "float",
        "scale",
        vec![s("texture", "tex1", &["a"]), f("float", "tex2", &[2.])],
        &loc(1),
    );
    assert_eq!(ty, "float");
    assert_eq!(names(&u), ["texture tex", "float scale"]);
    let (ty, u) = upgrade_texture(
        "color",
        "scale",
        vec![s("texture", "tex1", &["a"]), f("color", "tex2", &[2.; 3])],
        &loc(1),
    );
    assert_eq!(ty, "spectrum");
    assert_eq!(names(&u), ["texture tex", "float scale"]);
    assert_eq!(u.params[1].floats, [2.]);
    let (_, u) = upgrade_texture(
        "spectrum",
        "scale",
        vec![f("rgb", "tex1", &[1., 2., 3.])],
        &loc(1),
    );
    assert!(u.diagnostics[0].is_error());
    let mut g = ParsedParameter::new("bool", "gamma", loc(1));
    g.bools = vec![false];
    let (_, u) = upgrade_texture("float", "ptex", vec![g], &loc(1));
    assert_eq!(u.params[0].strings, ["linear"]);
}

#[test]
fn shapes() {
    let mut idx = ParsedParameter::new("integer", "indices", loc(1));
    idx.ints = vec![0, 1, 2];
    let u = upgrade_shape(
        "trianglemesh",
        vec![
            f("point", "P", &[0.; 9]),
            idx.clone(),
            f("point2", "st", &[0.; 6]),
            f("color", "Kd", &[1.; 3]),
        ],
        &loc(1),
    );
    assert_eq!(names(&u), ["point2 uv", "point3 P", "rgb reflectance"]);
    idx.ints = vec![0, 2, 1];
    let u = upgrade_shape(
        "trianglemesh",
        vec![f("point", "P", &[0.; 9]), idx],
        &loc(1),
    );
    assert_eq!(u.params.len(), 2);
    let mut n = ParsedParameter::new("integer", "nlevels", loc(1));
    n.ints = vec![3];
    assert_eq!(
        names(&upgrade_shape("loopsubdiv", vec![n], &loc(1))),
        ["integer levels"]
    );
    let u = upgrade_shape("trianglemesh", vec![f("float", "uv", &[0.; 3])], &loc(1));
    assert!(u.diagnostics[0].is_error());
}

#[test]
fn pbrt_v4_mix_is_left_alone() {
    let loc = crate::FileLoc::new("t.pbrt".into(), 1, 1);
    let params = vec![
        crate::ParsedParameter::with_strings(
            "string",
            "materials",
            loc.clone(),
            vec!["a".into(), "b".into()],
        ),
        crate::ParsedParameter::with_floats("float", "amount", loc.clone(), vec![0.3]),
    ];
    let u = upgrade_material("mix", params, &loc);
    assert_eq!(u.name, "mix");
    assert!(
        u.diagnostics.iter().all(|d| !d.is_error()),
        "{:?}",
        u.diagnostics
    );
    assert!(u
        .params
        .iter()
        .any(|p| p.name == "materials" && p.strings == ["a", "b"]));
    assert!(u
        .params
        .iter()
        .any(|p| p.name == "amount" && p.floats == [0.3]));
}

#[test]
fn approximate_material_mappings_warn_exact_ones_do_not() {
    let warns = |name: &str, params: Vec<ParsedParameter>| {
        upgrade_material(name, params, &loc(1))
            .diagnostics
            .iter()
            .any(|d| d.message.contains("approximated"))
    };
    assert!(!warns("matte", vec![f("rgb", "Kd", &[0.5; 3])]));
    assert!(warns("matte", vec![f("float", "sigma", &[20.])]));
    assert!(!warns("glass", vec![f("float", "index", &[1.4])]));
    assert!(warns("glass", vec![f("float", "roughness", &[0.1])]));
    assert!(!warns("plastic", vec![f("rgb", "Ks", &[0.; 3])]));
    assert!(!warns("uber", vec![f("rgb", "Ks", &[0.; 3])]));
    for m in [
        "plastic",
        "substrate",
        "uber",
        "translucent",
        "metal",
        "mirror",
        "kdsubsurface",
    ] {
        assert!(warns(m, vec![]), "{m}");
    }
    assert!(!warns("mix", vec![]));
}

/// A pbrt-v3 `projection` light's non-uniform `I` with its map: pbrt-v4
/// cannot express it (`--upgrade` refuses), rpbrt's renderer keeps the RGB
/// `I` to multiply the map by.
#[test]
fn projection_colour_with_a_map() {
    let params = || {
        vec![
            ParsedParameter::with_strings("string", "mapname", loc(1), vec!["m.exr".into()]),
            f("color", "I", &[2., 1., 0.5]),
        ]
    };
    let u = upgrade_light("projection", params(), &loc(1));
    assert!(u.diagnostics.iter().any(|d| d.is_error()));
    let u = upgrade_light_for_render("projection", params(), &loc(1));
    assert!(u.diagnostics.is_empty(), "{:?}", u.diagnostics);
    let i = u.params.iter().find(|p| p.name == "I").expect("keeps I");
    assert_eq!(i.floats, vec![2., 1., 0.5]);
}

#[test]
fn pbrt_v1_random_sampler_takes_a_grid_of_samples() {
    let loc = FileLoc::new(std::sync::Arc::from("f"), 1, 1);
    let mut x = ParsedParameter::new("integer", "xsamples", loc.clone());
    x.ints = vec![3];
    let mut y = ParsedParameter::new("integer", "ysamples", loc.clone());
    y.ints = vec![4];
    let u = upgrade_sampler("random", vec![x, y], &loc);
    assert_eq!(u.name, "independent");
    assert_eq!(u.params.len(), 1);
    assert_eq!(
        (u.params[0].name.as_str(), u.params[0].ints[0]),
        ("pixelsamples", 12)
    );
}
