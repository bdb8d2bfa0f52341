//! pbrt-v3 scenes, one per type pbrt-v3's `core/api.cpp` creates (shapes,
//! materials, textures, lights, area lights, media, cameras, samplers,
//! filters, integrators, accelerators, film), written as pbrt-v3 wrote
//! them. Each must render without error. Where rpbrt maps the type as
//! pbrt-v4's `--upgrade` does, the pbrt-v3 file must give the same pixels
//! as the hand-upgraded pbrt-v4 file (same sampler and seed, one thread);
//! the types pbrt-v4 dropped and rpbrt renders natively (`disney`,
//! `fourier`, `heightfield`, `nurbs`, pbrt-v3's spectrum `uv`/`fbm`/`wrinkled`/
//! `windy` textures, `exinfinite`, the light sample counts) are checked
//! against what pbrt-v3 defines them to be.
//!
//! The README's pbrt-v3 table lists these cases.

use std::path::{Path, PathBuf};

use rpbrt_render::image::{Image, ImageMetadata};
use rpbrt_render::integrator::RenderOptions;
use rpbrt_render::scene::assemble::{create_scene, CreateOptions};
use rpbrt_render::scene::{build_scene_from_bytes, BuildOptions};

fn dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("rpbrt-v3-scenes-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A rendered image and the warnings of building and creating it.
struct Rendered {
    pixels: Vec<f32>,
    warnings: Vec<String>,
}

/// Renders scene text (files it names resolve against [`dir`]) on one
/// thread; errors come back as their rendered messages.
fn render(tag: &str, text: &str) -> Result<Rendered, String> {
    let d = dir();
    // Named by its full path, so that file parameters resolve against `d`.
    let (desc, diags) = build_scene_from_bytes(
        &d.join(format!("{tag}.pbrt")).display().to_string(),
        text.as_bytes(),
        &d,
        &BuildOptions::default(),
    )
    .map_err(|e| e.render())?;
    let mut warnings: Vec<String> = diags.iter().map(|d| d.message.clone()).collect();
    let created = create_scene(&desc, &CreateOptions::default()).map_err(|e| {
        e.iter()
            .map(|d| d.message.clone())
            .collect::<Vec<_>>()
            .join("; ")
    })?;
    warnings.extend(created.warnings.iter().map(|d| d.message.clone()));
    let mut scene = created.scene;
    let opts = RenderOptions {
        nthreads: 1,
        ..Default::default()
    };
    let mut md = ImageMetadata::default();
    created
        .integrator
        .render(&mut scene, &opts, &mut md, &|_| {})
        .map_err(|e| e.to_string())?;
    let path = scene.film.filename().to_string();
    let im = Image::read(Path::new(&path), None)
        .map_err(|e| e.to_string())?
        .image;
    Ok(Rendered {
        pixels: im.to_f32_vec(),
        warnings,
    })
}

/// The scene around `opts` (options block) and `world`: defaults for
/// whatever they leave out, written in pbrt-v3's syntax or pbrt-v4's.
fn scene(v3: bool, tag: &str, opts: &str, world: &str) -> String {
    let out = dir().join(format!("{tag}-{}.pfm", if v3 { "v3" } else { "v4" }));
    let mut s = String::from("LookAt 0 0 5  0 0 0  0 1 0\n");
    if !opts.contains("Camera") {
        s += "Camera \"perspective\" \"float fov\" 40\n";
    }
    if !opts.contains("Sampler") {
        s += "Sampler \"halton\" \"integer pixelsamples\" 4\n";
    }
    if !opts.contains("PixelFilter") {
        s += "PixelFilter \"box\"\n";
    }
    if !opts.contains("Integrator") {
        s += "Integrator \"path\"\n";
    }
    if !opts.contains("Film") {
        let film = if v3 { "image" } else { "rgb" };
        s += &format!("Film \"{film}\" \"integer xresolution\" 8 \"integer yresolution\" 8 \"string filename\" \"{}\"\n", out.display());
    }
    s += opts;
    s += "\nWorldBegin\n";
    if !world.contains("LightSource") {
        let ty = if v3 { "color" } else { "rgb" };
        s += &format!("LightSource \"point\" \"{ty} I\" [ 4 4 4 ] \"point from\" [ 1 2 4 ]\n");
        s += &format!("LightSource \"infinite\" \"{ty} L\" [ 0.2 0.2 0.2 ]\n");
    }
    s += world;
    if v3 {
        s += "\nWorldEnd\n";
    }
    s
}

/// One pbrt-v3 type: its pbrt-v3 scene, and the hand-upgraded pbrt-v4
/// scene when there is one.
struct Case {
    name: &'static str,
    v3: (&'static str, &'static str),
    v4: Option<(&'static str, &'static str)>,
}

const fn case(
    name: &'static str,
    v3: (&'static str, &'static str),
    v4: (&'static str, &'static str),
) -> Case {
    Case {
        name,
        v3,
        v4: Some(v4),
    }
}

const fn native(name: &'static str, v3: (&'static str, &'static str)) -> Case {
    Case { name, v3, v4: None }
}

const SPHERE: &str = "Shape \"sphere\" \"float radius\" 1";

/// Every pbrt-v3 type the test files can exercise without outside files
/// (the file-based ones are in [`file_cases`]).
fn cases() -> Vec<Case> {
    vec![
        // ---- shapes
        case("shape sphere", ("", SPHERE), ("", SPHERE)),
        case("shape cylinder", ("", "Shape \"cylinder\" \"float zmin\" -0.5 \"float zmax\" 0.5"), ("", "Shape \"cylinder\" \"float zmin\" -0.5 \"float zmax\" 0.5")),
        case("shape disk", ("", "Shape \"disk\" \"float innerradius\" 0.3"), ("", "Shape \"disk\" \"float innerradius\" 0.3")),
        case("shape cone", ("", "Shape \"cone\" \"float height\" 1.5"), ("", "Shape \"cone\" \"float height\" 1.5")),
        case("shape paraboloid", ("", "Shape \"paraboloid\" \"float zmin\" 0.1"), ("", "Shape \"paraboloid\" \"float zmin\" 0.1")),
        case("shape hyperboloid", ("", "Shape \"hyperboloid\" \"point p1\" [ 0.5 0 -0.5 ] \"point p2\" [ 0 0.7 0.5 ]"), ("", "Shape \"hyperboloid\" \"point3 p1\" [ 0.5 0 -0.5 ] \"point3 p2\" [ 0 0.7 0.5 ]")),
        case("shape curve", ("", "Shape \"curve\" \"point P\" [ -1 0 0  -0.3 1 0  0.3 -1 0  1 0 0 ] \"float width\" 0.2"), ("", "Shape \"curve\" \"point3 P\" [ -1 0 0  -0.3 1 0  0.3 -1 0  1 0 0 ] \"float width\" 0.2")),
        case("shape trianglemesh", ("", "Shape \"trianglemesh\" \"point P\" [ -1 -1 0  1 -1 0  1 1 0  -1 1 0 ] \"integer indices\" [ 0 1 2 0 2 3 ] \"float uv\" [ 0 0 1 0 1 1 0 1 ]"), ("", "Shape \"trianglemesh\" \"point3 P\" [ -1 -1 0  1 -1 0  1 1 0  -1 1 0 ] \"integer indices\" [ 0 1 2 0 2 3 ] \"point2 uv\" [ 0 0 1 0 1 1 0 1 ]")),
        case("shape loopsubdiv", ("", "Shape \"loopsubdiv\" \"integer nlevels\" 2 \"point P\" [ -1 -1 0  1 -1 0  1 1 0  -1 1 0.5 ] \"integer indices\" [ 0 1 2 0 2 3 ]"), ("", "Shape \"loopsubdiv\" \"integer levels\" 2 \"point3 P\" [ -1 -1 0  1 -1 0  1 1 0  -1 1 0.5 ] \"integer indices\" [ 0 1 2 0 2 3 ]")),
        // pbrt-v3's heightfield is the triangle mesh it built.
        case("shape heightfield", ("", "Translate -1 -1 0 Scale 2 2 1 Shape \"heightfield\" \"integer nu\" 3 \"integer nv\" 2 \"float Pz\" [ 0 0.5 0  0.2 0.7 0.1 ]"), ("", "Translate -1 -1 0 Scale 2 2 1 Shape \"trianglemesh\" \"point3 P\" [ 0 0 0  0.5 0 0.5  1 0 0  0 1 0.2  0.5 1 0.7  1 1 0.1 ] \"point2 uv\" [ 0 0  0.5 0  1 0  0 1  0.5 1  1 1 ] \"integer indices\" [ 0 1 4  0 4 3  1 2 5  1 5 4 ]")),
        // pbrt-v3's nurbs is the 30 × 30 triangle mesh it diced.
        native("shape nurbs", ("", "Shape \"nurbs\" \"integer nu\" 3 \"integer uorder\" 3 \"float uknots\" [ 0 0 0 1 1 1 ] \"integer nv\" 2 \"integer vorder\" 2 \"float vknots\" [ 0 0 1 1 ] \"float Pw\" [ 1 0 -1 1  0.7071 0.7071 -0.7071 0.7071  0 1 -1 1  1 0 1 1  0.7071 0.7071 0.7071 0.7071  0 1 1 1 ]")),
        // ---- materials
        case("material matte", ("", "Material \"matte\" \"color Kd\" [ 0.2 0.5 0.8 ]\nShape \"sphere\""), ("", "Material \"diffuse\" \"rgb reflectance\" [ 0.2 0.5 0.8 ]\nShape \"sphere\"")),
        case("material plastic", ("", "Material \"plastic\" \"color Kd\" [ 0.2 0.5 0.8 ] \"color Ks\" [ 0.3 0.3 0.3 ] \"float roughness\" 0.1\nShape \"sphere\""), ("", "Material \"coateddiffuse\" \"rgb reflectance\" [ 0.2 0.5 0.8 ] \"float roughness\" 0.1\nShape \"sphere\"")),
        case("material substrate", ("", "Material \"substrate\" \"color Kd\" [ 0.2 0.5 0.8 ]\nShape \"sphere\""), ("", "Material \"coateddiffuse\" \"rgb reflectance\" [ 0.2 0.5 0.8 ]\nShape \"sphere\"")),
        case("material uber", ("", "Material \"uber\" \"color Kd\" [ 0.2 0.5 0.8 ] \"float index\" 1.4\nShape \"sphere\""), ("", "Material \"coateddiffuse\" \"float eta\" 1.4 \"rgb reflectance\" [ 0.2 0.5 0.8 ]\nShape \"sphere\"")),
        case("material glass", ("", "Material \"glass\" \"float index\" 1.33\nShape \"sphere\""), ("", "Material \"dielectric\" \"float eta\" 1.33\nShape \"sphere\"")),
        case("material metal", ("", "Material \"metal\" \"float roughness\" 0.2\nShape \"sphere\""), ("", "Material \"conductor\" \"float roughness\" 0.2\nShape \"sphere\"")),
        case("material mirror", ("", "Material \"mirror\" \"color Kr\" [ 0.8 0.8 0.8 ]\nShape \"sphere\""), ("", "Material \"conductor\" \"float roughness\" 0 \"rgb reflectance\" [ 0.8 0.8 0.8 ]\nShape \"sphere\"")),
        case("material translucent", ("", "Material \"translucent\" \"color Kd\" [ 0.4 0.4 0.4 ]\nShape \"sphere\""), ("", "Material \"diffusetransmission\" \"rgb transmittance\" [ 0.4 0.4 0.4 ]\nShape \"sphere\"")),
        case("material subsurface", ("", "Material \"subsurface\" \"string name\" \"Skin1\"\nShape \"sphere\""), ("", "Material \"subsurface\" \"string name\" \"Skin1\"\nShape \"sphere\"")),
        case("material kdsubsurface", ("", "Material \"kdsubsurface\" \"color Kd\" [ 0.6 0.5 0.4 ]\nShape \"sphere\""), ("", "Material \"subsurface\" \"rgb reflectance\" [ 0.6 0.5 0.4 ]\nShape \"sphere\"")),
        case("material hair", ("", "Material \"hair\"\nShape \"curve\" \"point P\" [ -1 0 0  -0.3 1 0  0.3 -1 0  1 0 0 ] \"float width\" 0.2"), ("", "Material \"hair\"\nShape \"curve\" \"point3 P\" [ -1 0 0  -0.3 1 0  0.3 -1 0  1 0 0 ] \"float width\" 0.2")),
        case("material mix", ("", "MakeNamedMaterial \"a\" \"string type\" \"matte\" \"color Kd\" [ 0.8 0.1 0.1 ]\nMakeNamedMaterial \"b\" \"string type\" \"matte\" \"color Kd\" [ 0.1 0.1 0.8 ]\nMaterial \"mix\" \"string namedmaterial1\" \"a\" \"string namedmaterial2\" \"b\" \"color amount\" [ 0.3 0.3 0.3 ]\nShape \"sphere\""), ("", "MakeNamedMaterial \"a\" \"string type\" \"diffuse\" \"rgb reflectance\" [ 0.8 0.1 0.1 ]\nMakeNamedMaterial \"b\" \"string type\" \"diffuse\" \"rgb reflectance\" [ 0.1 0.1 0.8 ]\nMaterial \"mix\" \"string materials\" [ \"b\" \"a\" ] \"float amount\" 0.3\nShape \"sphere\"")),
        case("material none", ("", "Material \"none\"\nShape \"sphere\""), ("", "Material \"interface\"\nShape \"sphere\"")),
        native("material disney", ("", "Material \"disney\" \"color color\" [ 0.8 0.3 0.2 ] \"float metallic\" 0.3 \"float sheen\" 0.5 \"float clearcoat\" 1 \"float spectrans\" 0.2 \"float anisotropic\" 0.4\nShape \"sphere\"")),
        native("material disney thin", ("", "Material \"disney\" \"bool thin\" \"true\" \"float flatness\" 0.5 \"float difftrans\" 1.2 \"float spectrans\" 0.3\nShape \"sphere\"")),
        // ---- textures (float ones drive matte's sigma-free reflectance
        // through a spectrum "scale"; spectrum ones feed Kd directly)
        case("texture constant", ("", "Texture \"t\" \"color\" \"constant\" \"color value\" [ 0.3 0.6 0.2 ]\nMaterial \"matte\" \"texture Kd\" \"t\"\nShape \"sphere\""), ("", "Texture \"t\" \"spectrum\" \"constant\" \"rgb value\" [ 0.3 0.6 0.2 ]\nMaterial \"diffuse\" \"texture reflectance\" \"t\"\nShape \"sphere\"")),
        case("texture scale", ("", "Texture \"f\" \"color\" \"checkerboard\"\nTexture \"t\" \"color\" \"scale\" \"texture tex1\" \"f\" \"color tex2\" [ 0.5 0.5 0.5 ]\nMaterial \"matte\" \"texture Kd\" \"t\"\nShape \"sphere\""), ("", "Texture \"f\" \"spectrum\" \"checkerboard\"\nTexture \"t\" \"spectrum\" \"scale\" \"texture tex\" \"f\" \"float scale\" 0.5\nMaterial \"diffuse\" \"texture reflectance\" \"t\"\nShape \"sphere\"")),
        case("texture float scale", ("", "Texture \"f\" \"float\" \"wrinkled\"\nTexture \"s\" \"float\" \"scale\" \"texture tex1\" \"f\" \"float tex2\" 0.3\nMaterial \"plastic\" \"texture roughness\" \"s\"\nShape \"sphere\""), ("", "Texture \"f\" \"float\" \"wrinkled\"\nTexture \"s\" \"float\" \"scale\" \"texture tex\" \"f\" \"float scale\" 0.3\nMaterial \"coateddiffuse\" \"texture roughness\" \"s\"\nShape \"sphere\"")),
        case("texture mix", ("", "Texture \"t\" \"color\" \"mix\" \"color tex1\" [ 1 0 0 ] \"color tex2\" [ 0 0 1 ] \"float amount\" 0.25\nMaterial \"matte\" \"texture Kd\" \"t\"\nShape \"sphere\""), ("", "Texture \"t\" \"spectrum\" \"mix\" \"rgb tex1\" [ 1 0 0 ] \"rgb tex2\" [ 0 0 1 ] \"float amount\" 0.25\nMaterial \"diffuse\" \"texture reflectance\" \"t\"\nShape \"sphere\"")),
        case("texture bilerp", ("", "Texture \"t\" \"color\" \"bilerp\" \"color v00\" [ 1 0 0 ] \"color v11\" [ 0 1 0 ]\nMaterial \"matte\" \"texture Kd\" \"t\"\nShape \"sphere\""), ("", "Texture \"t\" \"spectrum\" \"bilerp\" \"rgb v00\" [ 1 0 0 ] \"rgb v11\" [ 0 1 0 ]\nMaterial \"diffuse\" \"texture reflectance\" \"t\"\nShape \"sphere\"")),
        case("texture checkerboard", ("", "Texture \"t\" \"color\" \"checkerboard\" \"float uscale\" 8 \"float vscale\" 8\nMaterial \"matte\" \"texture Kd\" \"t\"\nShape \"sphere\""), ("", "Texture \"t\" \"spectrum\" \"checkerboard\" \"float uscale\" 8 \"float vscale\" 8\nMaterial \"diffuse\" \"texture reflectance\" \"t\"\nShape \"sphere\"")),
        case("texture checkerboard 3d", ("", "Texture \"t\" \"color\" \"checkerboard\" \"integer dimension\" 3\nMaterial \"matte\" \"texture Kd\" \"t\"\nShape \"sphere\""), ("", "Texture \"t\" \"spectrum\" \"checkerboard\" \"integer dimension\" 3\nMaterial \"diffuse\" \"texture reflectance\" \"t\"\nShape \"sphere\"")),
        case("texture dots", ("", "Texture \"t\" \"color\" \"dots\" \"float uscale\" 6 \"float vscale\" 6\nMaterial \"matte\" \"texture Kd\" \"t\"\nShape \"sphere\""), ("", "Texture \"t\" \"spectrum\" \"dots\" \"float uscale\" 6 \"float vscale\" 6\nMaterial \"diffuse\" \"texture reflectance\" \"t\"\nShape \"sphere\"")),
        case("texture marble", ("", "Texture \"t\" \"color\" \"marble\" \"float scale\" 3\nMaterial \"matte\" \"texture Kd\" \"t\"\nShape \"sphere\""), ("", "Texture \"t\" \"spectrum\" \"marble\" \"float scale\" 3\nMaterial \"diffuse\" \"texture reflectance\" \"t\"\nShape \"sphere\"")),
        case("texture float fbm wrinkled windy", ("", "Texture \"a\" \"float\" \"fbm\"\nTexture \"b\" \"float\" \"wrinkled\"\nTexture \"w\" \"float\" \"windy\"\nTexture \"m\" \"float\" \"mix\" \"texture tex1\" \"a\" \"texture tex2\" \"b\" \"texture amount\" \"w\"\nMaterial \"plastic\" \"texture roughness\" \"m\"\nShape \"sphere\""), ("", "Texture \"a\" \"float\" \"fbm\"\nTexture \"b\" \"float\" \"wrinkled\"\nTexture \"w\" \"float\" \"windy\"\nTexture \"m\" \"float\" \"mix\" \"texture tex1\" \"a\" \"texture tex2\" \"b\" \"texture amount\" \"w\"\nMaterial \"coateddiffuse\" \"texture roughness\" \"m\"\nShape \"sphere\"")),
        // pbrt-v3's spectrum noise textures are the float value in every
        // channel: in pbrt-v4 terms, white scaled by the float texture.
        case("texture color fbm", ("", "Texture \"t\" \"color\" \"fbm\" \"integer octaves\" 4\nMaterial \"matte\" \"texture Kd\" \"t\"\nShape \"sphere\""), ("", "Texture \"f\" \"float\" \"fbm\" \"integer octaves\" 4\nTexture \"t\" \"spectrum\" \"scale\" \"rgb tex\" [ 1 1 1 ] \"texture scale\" \"f\"\nMaterial \"diffuse\" \"texture reflectance\" \"t\"\nShape \"sphere\"")),
        case("texture color wrinkled", ("", "Texture \"t\" \"color\" \"wrinkled\" \"float roughness\" 0.3\nMaterial \"matte\" \"texture Kd\" \"t\"\nShape \"sphere\""), ("", "Texture \"f\" \"float\" \"wrinkled\" \"float roughness\" 0.3\nTexture \"t\" \"spectrum\" \"scale\" \"rgb tex\" [ 1 1 1 ] \"texture scale\" \"f\"\nMaterial \"diffuse\" \"texture reflectance\" \"t\"\nShape \"sphere\"")),
        case("texture color windy", ("", "Texture \"t\" \"color\" \"windy\"\nMaterial \"matte\" \"texture Kd\" \"t\"\nShape \"sphere\""), ("", "Texture \"f\" \"float\" \"windy\"\nTexture \"t\" \"spectrum\" \"scale\" \"rgb tex\" [ 1 1 1 ] \"texture scale\" \"f\"\nMaterial \"diffuse\" \"texture reflectance\" \"t\"\nShape \"sphere\"")),
        native("texture uv", ("", "Texture \"t\" \"color\" \"uv\"\nMaterial \"matte\" \"texture Kd\" \"t\"\nShape \"sphere\"")),
        // ---- lights and area lights
        case("light point", ("", "LightSource \"point\" \"color I\" [ 3 3 3 ] \"point from\" [ 0 1 3 ]\nShape \"sphere\""), ("", "LightSource \"point\" \"rgb I\" [ 3 3 3 ] \"point3 from\" [ 0 1 3 ]\nShape \"sphere\"")),
        // pbrt-v3 multiplies a colour `scale` into the RGB it made of a
        // spectral emission.
        native("light point spectrum colour scale", ("", "LightSource \"point\" \"spectrum I\" [ 400 1 700 3 ] \"color scale\" [ 3 1.5 1 ] \"point from\" [ 0 1 3 ]\nShape \"sphere\"")),
        case("light spot", ("", "LightSource \"spot\" \"color I\" [ 9 9 9 ] \"point from\" [ 0 0 4 ] \"point to\" [ 0 0 0 ] \"float coneangle\" 20\nShape \"sphere\""), ("", "LightSource \"spot\" \"rgb I\" [ 9 9 9 ] \"point3 from\" [ 0 0 4 ] \"point3 to\" [ 0 0 0 ] \"float coneangle\" 20\nShape \"sphere\"")),
        case("light distant", ("", "LightSource \"distant\" \"blackbody L\" [ 5500 2 ] \"point from\" [ 0 0 5 ]\nShape \"sphere\""), ("", "LightSource \"distant\" \"float scale\" 2 \"blackbody L\" [ 5500 ] \"point3 from\" [ 0 0 5 ]\nShape \"sphere\"")),
        case("light infinite", ("", "LightSource \"infinite\" \"color L\" [ 0.5 0.6 0.7 ] \"integer nsamples\" 8\nShape \"sphere\""), ("", "LightSource \"infinite\" \"rgb L\" [ 0.5 0.6 0.7 ]\nShape \"sphere\"")),
        case("light exinfinite", ("", "LightSource \"exinfinite\" \"color L\" [ 0.5 0.6 0.7 ] \"integer samples\" 4\nShape \"sphere\""), ("", "LightSource \"infinite\" \"rgb L\" [ 0.5 0.6 0.7 ]\nShape \"sphere\"")),
        // pbrt-v4 requires an image; pbrt-v3 renders these without one.
        native("light goniometric no map", ("", "LightSource \"goniometric\" \"color I\" [ 3 3 3 ]\nTranslate 0 0 -2\nShape \"sphere\"")),
        native("light projection no map", ("", "AttributeBegin\nTranslate 0 0 4\nRotate 180 0 1 0\nLightSource \"projection\" \"color I\" [ 9 9 9 ]\nAttributeEnd\nShape \"sphere\"")),
        case("arealight area", ("", "AttributeBegin\nAreaLightSource \"area\" \"color L\" [ 2 2 2 ] \"integer nsamples\" 4 \"bool twosided\" \"true\"\nShape \"disk\"\nAttributeEnd"), ("", "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [ 2 2 2 ] \"bool twosided\" true\nShape \"disk\"\nAttributeEnd")),
        case("arealight diffuse float nsamples", ("", "AttributeBegin\nAreaLightSource \"diffuse\" \"blackbody L\" [ 4000 3 ] \"float nsamples\" 4\nShape \"disk\"\nAttributeEnd"), ("", "AttributeBegin\nAreaLightSource \"diffuse\" \"float scale\" 3 \"blackbody L\" [ 4000 ]\nShape \"disk\"\nAttributeEnd")),
        // ---- media
        case("medium homogeneous", ("", "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"color sigma_a\" [ 0.5 0.5 0.5 ] \"color sigma_s\" [ 1 1 1 ]\nAttributeBegin\nMediumInterface \"m\" \"\"\nMaterial \"\"\nShape \"sphere\"\nAttributeEnd"), ("Integrator \"path\"", "MakeNamedMedium \"m\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [ 0.5 0.5 0.5 ] \"rgb sigma_s\" [ 1 1 1 ]\nAttributeBegin\nMediumInterface \"m\" \"\"\nMaterial \"interface\"\nShape \"sphere\"\nAttributeEnd")),
        case("medium heterogeneous", ("Integrator \"volpath\"", "MakeNamedMedium \"m\" \"string type\" \"heterogeneous\" \"float density\" [ 1 2 3 4 5 6 7 8 ] \"integer nx\" 2 \"integer ny\" 2 \"integer nz\" 2 \"point p0\" [ -1 -1 -1 ] \"point p1\" [ 1 1 1 ]\nAttributeBegin\nMediumInterface \"m\" \"\"\nMaterial \"\"\nShape \"sphere\"\nAttributeEnd"), ("Integrator \"volpath\"", "MakeNamedMedium \"m\" \"string type\" \"uniformgrid\" \"rgb sigma_s\" [ 2.55 3.21 3.77 ] \"rgb sigma_a\" [ 0.0011 0.0024 0.014 ] \"float density\" [ 1 2 3 4 5 6 7 8 ] \"integer nx\" 2 \"integer ny\" 2 \"integer nz\" 2 \"point3 p0\" [ -1 -1 -1 ] \"point3 p1\" [ 1 1 1 ]\nAttributeBegin\nMediumInterface \"m\" \"\"\nMaterial \"interface\"\nShape \"sphere\"\nAttributeEnd")),
        // ---- cameras
        case("camera perspective", ("Camera \"perspective\" \"float fov\" 30 \"float lensradius\" 0.05 \"float focaldistance\" 5", SPHERE), ("Camera \"perspective\" \"float fov\" 30 \"float lensradius\" 0.05 \"float focaldistance\" 5", SPHERE)),
        case("camera orthographic", ("Camera \"orthographic\" \"float screenwindow\" [ -1.5 1.5 -1.5 1.5 ]", SPHERE), ("Camera \"orthographic\" \"float screenwindow\" [ -1.5 1.5 -1.5 1.5 ]", SPHERE)),
        case("camera environment", ("Camera \"environment\"", SPHERE), ("Camera \"spherical\" \"string mapping\" \"equirectangular\"", SPHERE)),
        // ---- samplers
        case("sampler lowdiscrepancy", ("Sampler \"lowdiscrepancy\" \"integer pixelsamples\" 4", SPHERE), ("Sampler \"paddedsobol\" \"integer pixelsamples\" 4", SPHERE)),
        case("sampler 02sequence", ("Sampler \"02sequence\" \"integer pixelsamples\" 4", SPHERE), ("Sampler \"paddedsobol\" \"integer pixelsamples\" 4", SPHERE)),
        case("sampler maxmindist", ("Sampler \"maxmindist\" \"integer pixelsamples\" 4", SPHERE), ("Sampler \"pmj02bn\" \"integer pixelsamples\" 4", SPHERE)),
        case("sampler halton", ("Sampler \"halton\" \"integer pixelsamples\" 4", SPHERE), ("Sampler \"halton\" \"integer pixelsamples\" 4", SPHERE)),
        case("sampler sobol", ("Sampler \"sobol\" \"integer pixelsamples\" 4", SPHERE), ("Sampler \"sobol\" \"integer pixelsamples\" 4", SPHERE)),
        case("sampler random", ("Sampler \"random\" \"integer pixelsamples\" 4", SPHERE), ("Sampler \"independent\" \"integer pixelsamples\" 4", SPHERE)),
        case("sampler stratified", ("Sampler \"stratified\" \"integer xsamples\" 2 \"integer ysamples\" 2", SPHERE), ("Sampler \"stratified\" \"integer xsamples\" 2 \"integer ysamples\" 2", SPHERE)),
        // ---- filters
        case("filter box", ("PixelFilter \"box\" \"float xwidth\" 1 \"float ywidth\" 1", SPHERE), ("PixelFilter \"box\" \"float xradius\" 1 \"float yradius\" 1", SPHERE)),
        case("filter gaussian", ("PixelFilter \"gaussian\" \"float alpha\" 2", SPHERE), ("PixelFilter \"gaussian\" \"float sigma\" 0.5", SPHERE)),
        case("filter mitchell", ("PixelFilter \"mitchell\" \"float xwidth\" 2 \"float ywidth\" 2", SPHERE), ("PixelFilter \"mitchell\" \"float xradius\" 2 \"float yradius\" 2", SPHERE)),
        case("filter sinc", ("PixelFilter \"sinc\" \"float tau\" 3 \"float xwidth\" 1 \"float ywidth\" 1", SPHERE), ("PixelFilter \"sinc\" \"float tau\" 3 \"float xradius\" 1 \"float yradius\" 1", SPHERE)),
        case("filter triangle", ("PixelFilter \"triangle\"", SPHERE), ("PixelFilter \"triangle\"", SPHERE)),
        // ---- integrators
        native("integrator whitted", ("Integrator \"whitted\" \"integer maxdepth\" 3", "Material \"mirror\"\nShape \"sphere\"")),
        // pbrt-v3's directlighting is the light transport of its whitted.
        case("integrator directlighting", ("Integrator \"directlighting\" \"string strategy\" \"all\"", "Material \"mirror\"\nShape \"sphere\""), ("Integrator \"whitted\" \"integer maxdepth\" 5", "Material \"conductor\" \"float roughness\" 0 \"rgb reflectance\" [ 0.9 0.9 0.9 ]\nShape \"sphere\"")),
        case("integrator path", ("Integrator \"path\" \"integer maxdepth\" 3 \"float rrthreshold\" 0.5 \"string lightsamplestrategy\" \"spatial\"", SPHERE), ("Integrator \"path\" \"integer maxdepth\" 3 \"string lightsamplestrategy\" \"bvh\"", SPHERE)),
        case("integrator volpath", ("Integrator \"volpath\" \"integer maxdepth\" 3", SPHERE), ("Integrator \"volpath\" \"integer maxdepth\" 3", SPHERE)),
        case("integrator bdpt", ("Integrator \"bdpt\" \"integer maxdepth\" 3", SPHERE), ("Integrator \"bdpt\" \"integer maxdepth\" 3", SPHERE)),
        case("integrator mlt", ("Integrator \"mlt\" \"integer maxdepth\" 3 \"integer mutationsperpixel\" 4", SPHERE), ("Integrator \"mlt\" \"integer maxdepth\" 3 \"integer mutationsperpixel\" 4", SPHERE)),
        case("integrator ambientocclusion", ("Integrator \"ambientocclusion\"", SPHERE), ("Integrator \"ambientocclusion\"", SPHERE)),
        case("integrator sppm", ("Integrator \"sppm\" \"integer numiterations\" 2 \"integer photonsperiteration\" 1000 \"integer imagewritefrequency\" 100", SPHERE), ("Integrator \"sppm\" \"integer photonsperiteration\" 1000", SPHERE)),
        // ---- accelerators and film
        case("accelerator bvh", ("Accelerator \"bvh\" \"string splitmethod\" \"sah\"", SPHERE), ("Accelerator \"bvh\" \"string splitmethod\" \"sah\"", SPHERE)),
        case("accelerator kdtree", ("Accelerator \"kdtree\"", SPHERE), ("Accelerator \"kdtree\"", SPHERE)),
        case("film image", ("", SPHERE), ("", SPHERE)),
    ]
}

/// Renders a case; the failure message if it fails.
/// A 2 × 2 RGB image, a one-triangle PLY mesh, a two-surface lens and a
/// Fourier BSDF table, written next to the scenes.
fn write_files() {
    let d = dir();
    let mut pfm = b"PF\n2 2\n-1\n".to_vec();
    for v in [
        1.0f32, 0.5, 0.2, 0.2, 0.5, 1.0, 0.5, 0.5, 0.5, 1.0, 1.0, 1.0,
    ] {
        pfm.extend_from_slice(&v.to_le_bytes());
    }
    std::fs::write(d.join("img.pfm"), pfm).unwrap();
    std::fs::write(
        d.join("mesh.ply"),
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n-1 -1 0\n1 -1 0\n0 1 0\n3 0 1 2\n",
    )
    .unwrap();
    std::fs::write(
        d.join("lens.dat"),
        "# radius thickness eta aperture\n20 4 1.5 10\n0 30 1 8\n",
    )
    .unwrap();
    let table = fourier_table();
    std::fs::write(d.join("smooth.bsdf"), &table).unwrap();
    std::fs::write(d.join("truncated.bsdf"), &table[..table.len() / 2]).unwrap();
}

/// A Fourier BSDF file (pbrt-v3's `SCATFUN` format): f = c |μi| |μo|
/// (1 + ½ cos φ) on both sides, albedo 0.8 |cos θo|, one channel.
fn fourier_table() -> Vec<u8> {
    let n: i32 = 21;
    let mu: Vec<f32> = (0..n)
        .map(|i| -1.0 + 2.0 * i as f32 / (n - 1) as f32)
        .collect();
    let c = 0.8 * 3.0 / (4.0 * std::f32::consts::PI);
    let (mut a, mut pairs, mut cdf) = (Vec::new(), Vec::new(), Vec::new());
    for &mo in &mu {
        // Running integral of a0 = c μi² |μo| over μi (exact for this
        // quadratic, as the Catmull–Rom integral is).
        for &mi in &mu {
            pairs.push((a.len() as i32, 2i32));
            let y = c * mi * mi * mo.abs();
            a.extend([y, 0.5 * y]);
            cdf.push(c * mo.abs() * (mi.powi(3) + 1.0) / 3.0);
        }
    }
    let mut out = b"SCATFUN\x01".to_vec();
    for v in [1, n, a.len() as i32, 2, 1, 1, 0, 0, 0] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend_from_slice(&1.0f32.to_le_bytes());
    out.extend_from_slice(&[0; 16]);
    for v in mu.iter().chain(&cdf) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for (o, l) in pairs {
        out.extend_from_slice(&o.to_le_bytes());
        out.extend_from_slice(&l.to_le_bytes());
    }
    for v in &a {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

/// The pbrt-v3 types that read files.
fn file_cases() -> Vec<Case> {
    vec![
        case("shape plymesh", ("", "Shape \"plymesh\" \"string filename\" \"mesh.ply\""), ("", "Shape \"plymesh\" \"string filename\" \"mesh.ply\"")),
        case("texture imagemap", ("", "Texture \"t\" \"color\" \"imagemap\" \"string filename\" \"img.pfm\" \"bool trilinear\" \"true\" \"float gamma\" 2.2\nMaterial \"matte\" \"texture Kd\" \"t\"\nShape \"sphere\""), ("", "Texture \"t\" \"spectrum\" \"imagemap\" \"string encoding\" \"gamma 2.2\" \"string filter\" \"trilinear\" \"string filename\" \"img.pfm\"\nMaterial \"diffuse\" \"texture reflectance\" \"t\"\nShape \"sphere\"")),
        // pbrt-v3's goniometric map is a latitude–longitude image of any
        // size, resampled on load (pbrt-v4's `filename` is equal-area).
        native("light goniometric", ("", "LightSource \"goniometric\" \"color I\" [ 2 2 2 ] \"string mapname\" \"img.pfm\"\nTranslate 0 0 -2\nShape \"sphere\"")),
        case("light projection", ("", "AttributeBegin\nRotate 180 0 1 0\nLightSource \"projection\" \"string mapname\" \"img.pfm\" \"float fov\" 60\nAttributeEnd\nTranslate 0 0 -2\nShape \"sphere\""), ("", "AttributeBegin\nRotate 180 0 1 0\nLightSource \"projection\" \"string filename\" \"img.pfm\" \"float fov\" 60\nAttributeEnd\nTranslate 0 0 -2\nShape \"sphere\"")),
        // pbrt-v3's `mapname` is a latitude–longitude map, resampled to
        // pbrt-v4's equal-area square on load (not pbrt-v4's `filename`).
        native("light infinite map", ("", "LightSource \"infinite\" \"string mapname\" \"img.pfm\" \"color L\" [ 0.5 0.5 0.5 ]\nShape \"sphere\"")),
        // pbrt-v3 multiplies its map by a colour `L` or `scale`.
        native("light infinite map colour scale", ("", "LightSource \"infinite\" \"string mapname\" \"img.pfm\" \"color scale\" [ 1 0.5 0.25 ]\nShape \"sphere\"")),
        native("light infinite map spectrum L", ("", "LightSource \"infinite\" \"string mapname\" \"img.pfm\" \"blackbody L\" [ 5000 1 ]\nShape \"sphere\"")),
        native("light infinite map colour L", ("", "LightSource \"infinite\" \"string mapname\" \"img.pfm\" \"color L\" [ 0.2 0.5 1 ]\nShape \"sphere\"")),
        case("camera realistic", ("Camera \"realistic\" \"string lensfile\" \"lens.dat\" \"float aperturediameter\" 5 \"float focusdistance\" 5 \"bool simpleweighting\" \"true\"", SPHERE), ("Camera \"realistic\" \"string lensfile\" \"lens.dat\" \"float aperturediameter\" 5 \"float focusdistance\" 5", SPHERE)),
        native("material fourier", ("", "Material \"fourier\" \"string bsdffile\" \"smooth.bsdf\"\nShape \"sphere\"")),
    ]
}

fn check_case(c: &Case) -> Result<Rendered, String> {
    let tag = c.name.replace(' ', "-");
    let v3 = render(&tag, &scene(true, &tag, c.v3.0, c.v3.1))
        .map_err(|e| format!("{}: the pbrt-v3 scene fails: {e}", c.name))?;
    // (Saturated colours and the sinc filter's lobes may give negative
    // RGB values.)
    if !v3.pixels.iter().all(|v| v.is_finite()) {
        return Err(format!("{}: bad pixels", c.name));
    }
    if v3.pixels.iter().all(|&v| v == 0.0) {
        return Err(format!("{}: a black image", c.name));
    }
    if let Some((o, w)) = c.v4 {
        let v4 = render(&tag, &scene(false, &tag, o, w))
            .map_err(|e| format!("{}: the pbrt-v4 scene fails: {e}", c.name))?;
        if v3.pixels != v4.pixels {
            return Err(format!(
                "{}: the pbrt-v3 file and its pbrt-v4 upgrade differ",
                c.name
            ));
        }
    }
    Ok(v3)
}

#[test]
fn every_pbrt_v3_type_renders_as_its_upgrade() {
    write_files();
    let failures: Vec<String> = cases()
        .iter()
        .chain(&file_cases())
        .filter_map(|c| check_case(c).err())
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn native_pbrt_v3_types_behave_as_pbrt_v3_defines_them() {
    write_files();
    let mean = |c: &Case| {
        let r = check_case(c).unwrap_or_else(|e| panic!("{e}"));
        r.pixels.iter().map(|&v| v as f64).sum::<f64>() / r.pixels.len() as f64
    };
    // Disney: not the diffuse material pbrt-v4's --upgrade substitutes,
    // and no approximation warning.
    let disney = "Material \"disney\" \"color color\" [ 0.5 0.5 0.5 ] \"float metallic\" 1 \"float roughness\" 0.2\nShape \"sphere\"";
    let d = render("disney", &scene(true, "disney", "", disney)).unwrap();
    let m = render(
        "disney",
        &scene(
            true,
            "disney",
            "",
            "Material \"matte\" \"color Kd\" [ 0.5 0.5 0.5 ]\nShape \"sphere\"",
        ),
    )
    .unwrap();
    assert_ne!(d.pixels, m.pixels);
    assert!(
        d.warnings.iter().all(|w| !w.contains("approximated")),
        "{:?}",
        d.warnings
    );
    // Fourier: the table's sphere is lit; a truncated table is a located
    // error naming the file.
    let f = mean(&native(
        "fourier",
        (
            "",
            "Material \"fourier\" \"string bsdffile\" \"smooth.bsdf\"\nShape \"sphere\"",
        ),
    ));
    assert!(f > 0.0);
    let e = render(
        "bad",
        &scene(
            true,
            "bad",
            "",
            "Material \"fourier\" \"string bsdffile\" \"truncated.bsdf\"\nShape \"sphere\"",
        ),
    )
    .err()
    .expect("truncated table");
    assert!(
        e.contains("truncated.bsdf") && e.contains("truncated Fourier BSDF file"),
        "{e}"
    );
    let e = render(
        "bad",
        &scene(true, "bad", "", "Material \"fourier\"\nShape \"sphere\""),
    )
    .err()
    .expect("no file");
    assert!(e.contains("bsdffile"), "{e}");
    // The uv texture is (u, v, 0): on a quad with uv over [0,1]², the
    // same colours as pbrt-v4's bilerp from black through red and green
    // to yellow, up to the RGB-to-spectrum curves of the blends (close).
    let quad = "Shape \"trianglemesh\" \"point P\" [ -1 -1 0  1 -1 0  1 1 0  -1 1 0 ] \"integer indices\" [ 0 1 2 0 2 3 ] \"float uv\" [ 0 0 1 0 1 1 0 1 ]";
    let uv = mean(&native("uv", ("", Box::leak(format!("Texture \"t\" \"color\" \"uv\"\nMaterial \"matte\" \"texture Kd\" \"t\"\n{quad}").into_boxed_str()))));
    let bilerp = mean(&native("bilerp", ("", Box::leak(format!("Texture \"t\" \"color\" \"bilerp\" \"color v00\" [ 0 0 0 ] \"color v10\" [ 1 0 0 ] \"color v01\" [ 0 1 0 ] \"color v11\" [ 1 1 0 ]\nMaterial \"matte\" \"texture Kd\" \"t\"\n{quad}").into_boxed_str()))));
    assert!(
        (uv - bilerp).abs() < 0.1 * bilerp,
        "uv {uv} vs bilerp {bilerp}"
    );
    // A bilinear NURBS patch is the quad (diced into 30 × 30 vertices
    // with the same uvs), up to rounding.
    let patch = "Shape \"nurbs\" \"integer nu\" 2 \"integer uorder\" 2 \"float uknots\" [ 0 0 1 1 ] \"integer nv\" 2 \"integer vorder\" 2 \"float vknots\" [ 0 0 1 1 ] \"point P\" [ -1 -1 0  1 -1 0  -1 1 0  1 1 0 ]";
    let nurbs = mean(&native("nurbs", ("", Box::leak(format!("Texture \"t\" \"color\" \"uv\"\nMaterial \"matte\" \"texture Kd\" \"t\"\n{patch}").into_boxed_str()))));
    assert!((nurbs - uv).abs() < 1e-3 * uv, "nurbs {nurbs} vs quad {uv}");
    let e = render(
        "bad",
        &scene(true, "bad", "", "Shape \"nurbs\" \"integer nu\" 2 \"integer uorder\" 2 \"float uknots\" [ 0 0 1 ] \"integer nv\" 2 \"integer vorder\" 2 \"float vknots\" [ 0 0 1 1 ] \"point P\" [ -1 -1 0  1 -1 0  -1 1 0  1 1 0 ]"),
    )
    .err()
    .expect("short knot vector");
    assert!(e.contains("bad.pbrt:") && e.contains("\"uknots\""), "{e}");
}

/// pbrt-v3's `goniometric` and `projection` lights without `mapname`: a
/// uniform point light, and a constant `I` over the square frustum of
/// pbrt-v3's default 45° field of view, against the analytic radiance of
/// a diffuse plane under them; a pbrt-v4 file keeps pbrt-v4's error.
#[test]
fn v3_lights_without_maps_match_analytic_radiance() {
    let plane = "Material \"matte\" \"color Kd\" [ 0.5 0.5 0.5 ]\nShape \"trianglemesh\" \"point P\" [ -10 -10 0  10 -10 0  10 10 0  -10 10 0 ] \"integer indices\" [ 0 1 2 0 2 3 ]";
    let opts = "Camera \"orthographic\" \"float screenwindow\" [ -1.6 1.6 -1.6 1.6 ]\nSampler \"halton\" \"integer pixelsamples\" 64\nIntegrator \"path\" \"integer maxdepth\" 1";
    let light_at = |light: &str| {
        format!("AttributeBegin\nTranslate 0 0 2\nRotate 180 0 1 0\n{light}\nAttributeEnd\n{plane}")
    };
    let grey = |r: &Rendered| -> Vec<f64> {
        r.pixels
            .chunks(3)
            .map(|c| c.iter().map(|&v| v as f64).sum::<f64>() / 3.0)
            .collect()
    };
    // The radiance of the plane at (x, y): ρ/π · I cos θ / r², I = 1, d = 2,
    // averaged over each of the 8 × 8 pixels (0.4 wide) by the midpoint
    // rule; `half` is the lit half-width (∞: everywhere).
    let analytic = |half: f64| -> Vec<f64> {
        let (d, n) = (2.0f64, 40);
        let mut out = Vec::new();
        for py in 0..8 {
            for px in 0..8 {
                let mut sum = 0.0;
                for j in 0..n {
                    for i in 0..n {
                        let x = -1.6 + 0.4 * (px as f64 + (i as f64 + 0.5) / n as f64);
                        let y = -1.6 + 0.4 * (py as f64 + (j as f64 + 0.5) / n as f64);
                        if x.abs() <= half && y.abs() <= half {
                            let r2 = d * d + x * x + y * y;
                            sum += 0.5 / std::f64::consts::PI * d / (r2 * r2.sqrt());
                        }
                    }
                }
                out.push(sum / (n * n) as f64);
            }
        }
        out
    };
    let check = |tag: &str, got: &[f64], want: &[f64]| {
        let (sg, sw) = (got.iter().sum::<f64>(), want.iter().sum::<f64>());
        assert!((sg / sw - 1.0).abs() < 0.02, "{tag}: total {sg} vs {sw}");
        for (k, (g, w)) in got.iter().zip(want).enumerate() {
            if *w == 0.0 {
                assert_eq!(*g, 0.0, "{tag}: pixel {k} lit outside the frustum");
            } else {
                assert!(
                    (g - w).abs() < 0.05 * w + 2e-3,
                    "{tag}: pixel {k}: {g} vs {w}"
                );
            }
        }
    };
    let gonio = render(
        "gonio",
        &scene(
            true,
            "gonio",
            opts,
            &light_at("LightSource \"goniometric\" \"color I\" [ 1 1 1 ]"),
        ),
    )
    .unwrap();
    check("goniometric", &grey(&gonio), &analytic(f64::INFINITY));
    let point = render(
        "gonio",
        &scene(
            true,
            "gonio",
            opts,
            &light_at("LightSource \"point\" \"color I\" [ 1 1 1 ]"),
        ),
    )
    .unwrap();
    assert_eq!(gonio.pixels, point.pixels);
    let proj = render(
        "proj",
        &scene(
            true,
            "proj",
            opts,
            &light_at("LightSource \"projection\" \"color I\" [ 1 1 1 ]"),
        ),
    )
    .unwrap();
    check(
        "projection",
        &grey(&proj),
        &analytic(2.0 * (22.5f64).to_radians().tan()),
    );
    let proj90 = render(
        "proj",
        &scene(
            true,
            "proj",
            opts,
            &light_at("LightSource \"projection\" \"color I\" [ 1 1 1 ] \"float fov\" 90"),
        ),
    )
    .unwrap();
    check("projection fov 90", &grey(&proj90), &analytic(2.0));
    for ty in ["goniometric", "projection"] {
        let light = format!("LightSource \"{ty}\" \"rgb I\" [ 1 1 1 ]");
        let v4 = light_at(&light)
            .replace("\"point P\"", "\"point3 P\"")
            .replace("\"matte\" \"color Kd\"", "\"diffuse\" \"rgb reflectance\"");
        let e = render("v4", &scene(false, "v4", "", &v4))
            .err()
            .expect("pbrt-v4 needs the image");
        assert!(e.contains("must provide \"filename\""), "{e}");
    }
}

/// pbrt-v3's Disney BSSRDF (`disney` with `scatterdistance`), rendered by
/// the v3 file's `path` integrator, against the separable model worked by
/// hand: a flat white slab with zero roughness (no retro-reflection, a
/// near-mirror specular lobe the camera does not see) under a distant
/// light whose shadow edge crosses the middle of the view. Light enters
/// with (1 − Fr(θl)) cos θl E, spreads by Burley's profile, and leaves with
/// (1 − Fr(θo)) / (cπ), c = 1 − 2 ∫ Fr μ dμ. Seen from above, a point at
/// signed distance x from the edge (x > 0 lit) gets the fraction G(x) of
/// the profile that lies in the light.
#[test]
fn v3_disney_bssrdf_spreads_light_by_burleys_profile() {
    let eta = 1.5f64;
    // Exact dielectric Fresnel reflectance from outside.
    let fr = |cos_i: f64| {
        let sin_t = (1.0 - cos_i * cos_i).max(0.0).sqrt() / eta;
        let cos_t = (1.0 - sin_t * sin_t).sqrt();
        let par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
        let perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
        (par * par + perp * perp) / 2.0
    };
    let n = 100_000;
    let moment: f64 = (0..n)
        .map(|k| {
            let mu = (k as f64 + 0.5) / n as f64;
            fr(mu) * mu / n as f64
        })
        .sum();
    let c = 1.0 - 2.0 * moment;
    let cos_l = 0.8f64;
    let scale = (1.0 - fr(1.0)) * (1.0 - fr(cos_l)) * cos_l / (c * std::f64::consts::PI);
    // G(x) = ∫ p(r) P(r cos φ > −x) dr, p the radial density
    // (e^(−r/d) + e^(−r/3d)) / 4d.
    let g = |x: f64, d: f64| {
        let (m, r_max) = (20_000, 40.0 * d);
        (0..m)
            .map(|k| {
                let r = (k as f64 + 0.5) * r_max / m as f64;
                let p = ((-r / d).exp() + (-r / (3.0 * d)).exp()) / (4.0 * d);
                let lit = if x >= r {
                    1.0
                } else if x <= -r {
                    0.0
                } else {
                    (-x / r).acos() / std::f64::consts::PI
                };
                p * lit * r_max / m as f64
            })
            .sum::<f64>()
    };
    let opts = "Camera \"orthographic\" \"float screenwindow\" [ -0.8 0.8 -0.1 0.1 ]\nSampler \"halton\" \"integer pixelsamples\" 4096";
    // The light comes from +x, 36.87° off the normal; the occluder above
    // the camera stops it for x < 4.5 at z = 6, so the shadow edge is x = 0.
    let world = |d: f64| {
        format!(
            "LightSource \"distant\" \"color L\" [ 1 1 1 ] \"point from\" [ 0.6 0 0.8 ] \"point to\" [ 0 0 0 ]\n\
             AttributeBegin\nMaterial \"matte\" \"color Kd\" [ 0 0 0 ]\n\
             Shape \"trianglemesh\" \"point P\" [ -20 -20 6  4.5 -20 6  4.5 20 6  -20 20 6 ] \"integer indices\" [ 0 1 2 0 2 3 ]\nAttributeEnd\n\
             Material \"disney\" \"color color\" [ 1 1 1 ] \"float roughness\" 0 \"color scatterdistance\" [ {d} {d} {d} ]\n\
             Shape \"trianglemesh\" \"point P\" [ -10 -10 0  10 -10 0  10 10 0  -10 10 0 ] \"integer indices\" [ 0 1 2 0 2 3 ]"
        )
    };
    let film = |tag: &str| {
        format!(
            "Film \"image\" \"integer xresolution\" 16 \"integer yresolution\" 2 \"string filename\" \"{}\"",
            dir().join(format!("{tag}.pfm")).display()
        )
    };
    let d = 0.2;
    let r = render(
        "sss",
        &scene(true, "sss", &format!("{opts}\n{}", film("sss")), &world(d)),
    )
    .unwrap();
    assert!(
        r.warnings.iter().all(|w| !w.contains("subsurface")),
        "{:?}",
        r.warnings
    );
    // Column means (grey), and the analytic value over each column: camera
    // x runs along world −x, so column i is centred on x = 0.75 − 0.1 i.
    let cols: Vec<f64> = (0..16)
        .map(|i| {
            (0..2)
                .flat_map(|row| r.pixels[(row * 16 + i) * 3..(row * 16 + i) * 3 + 3].to_vec())
                .map(|v| v as f64)
                .sum::<f64>()
                / 6.0
        })
        .collect();
    let want = |d: f64| -> Vec<f64> {
        (0..16)
            .map(|i| {
                let x0 = 0.8 - 0.1 * (i as f64 + 0.5);
                (0..4)
                    .map(|j| scale * g(x0 + 0.1 * (j as f64 - 1.5) / 4.0, d) / 4.0)
                    .sum()
            })
            .collect()
    };
    let w = want(d);
    let sums = |v: &[f64]| (v[..8].iter().sum::<f64>(), v[8..].iter().sum::<f64>());
    let ((lit, shade), (lit_w, shade_w)) = (sums(&cols), sums(&w));
    assert!(
        (lit / lit_w - 1.0).abs() < 0.03,
        "lit half: {lit} vs {lit_w}"
    );
    assert!(
        (shade / shade_w - 1.0).abs() < 0.06,
        "shadowed half: {shade} vs {shade_w} (d 0.1: {}, d 0.3: {})",
        sums(&want(0.1)).1,
        sums(&want(0.3)).1
    );
    for (i, (got, w)) in cols.iter().zip(&w).enumerate() {
        assert!(
            (got - w).abs() < 0.15 * w + 2e-3,
            "column {i}: {got} vs {w}\n{cols:?}\n{w:?}"
        );
    }
}

/// Odd scatter distances (zero in some channels, huge, tiny) and a
/// textured one render finite pixels without panicking; a negative one is
/// pbrt-v4's located RGB error; a constant black one is the diffuse lobe,
/// the same image as leaving it out.
#[test]
fn v3_disney_bssrdf_takes_odd_scatter_distances() {
    let sphere = "Shape \"sphere\" \"float radius\" 1";
    for sd in [
        "\"color scatterdistance\" [ 0 0.1 0 ]",
        "\"color scatterdistance\" [ 1e30 1e-30 0.5 ]",
        "\"color scatterdistance\" [ 0 0 1e-9 ]",
        "\"texture scatterdistance\" \"c\"",
    ] {
        let world = format!(
            "Texture \"c\" \"color\" \"checkerboard\" \"color tex1\" [ 0 0 0 ] \"color tex2\" [ 0.2 0.1 0.05 ]\nMaterial \"disney\" {sd}\n{sphere}"
        );
        let r =
            render("odd", &scene(true, "odd", "", &world)).unwrap_or_else(|e| panic!("{sd}: {e}"));
        assert!(r.pixels.iter().all(|v| v.is_finite()), "{sd}");
    }
    let e = render(
        "neg",
        &scene(
            true,
            "neg",
            "",
            &format!("Material \"disney\" \"color scatterdistance\" [ -1 0.1 0 ]\n{sphere}"),
        ),
    )
    .err()
    .expect("negative RGB");
    assert!(
        e.contains("scatterdistance") && e.contains("negative"),
        "{e}"
    );
    let black = render(
        "black",
        &scene(
            true,
            "black",
            "",
            &format!("Material \"disney\" \"color scatterdistance\" [ 0 0 0 ]\n{sphere}"),
        ),
    )
    .unwrap();
    let none = render(
        "black",
        &scene(true, "black", "", &format!("Material \"disney\"\n{sphere}")),
    )
    .unwrap();
    assert_eq!(black.pixels, none.pixels);
}
