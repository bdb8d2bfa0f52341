//! Helpers the integration tests share: renders from scene text under
//! both designs (scalar and `--wavefront`), compared bit for bit.
#![allow(dead_code)]

use rpbrt_render::image::{Image, ImageMetadata};
use rpbrt_render::integrator::RenderOptions;
use rpbrt_render::scene::assemble::{create_scene, CreateOptions};
use rpbrt_render::scene::{build_scene_from_str, BuildOptions};

/// Renders scene text and returns the image. Integrators with a wavefront
/// form render twice, scalar and `--wavefront`, which must give the same
/// pixels bit for bit: every test here runs under both designs.
pub fn render_scene(text: &str, threads: usize) -> Image {
    let (scalar, has_wavefront) = render_with(text, threads, false);
    if has_wavefront {
        let (wavefront, _) = render_with(text, threads, true);
        assert_same_pixels(&scalar, &wavefront, text);
    }
    scalar
}

/// Renders scene text with or without `--wavefront`; also says whether
/// the integrator has a wavefront form.
pub fn render_with(text: &str, threads: usize, wavefront: bool) -> (Image, bool) {
    let created = created(text);
    let has = created.integrator.has_wavefront();
    (render_created(created, threads, wavefront, None), has)
}

/// The scene of `text`, created (a panic with its diagnostics where it
/// fails).
pub fn created(text: &str) -> rpbrt_render::scene::assemble::CreatedScene {
    let (desc, _) = build_scene_from_str(text, &BuildOptions::default())
        .unwrap_or_else(|d| panic!("{}", d.render()));
    match create_scene(&desc, &CreateOptions::default()) {
        Ok(c) => c,
        Err(e) => panic!(
            "{:?}",
            e.iter().map(|d| d.message.clone()).collect::<Vec<_>>()
        ),
    }
}

/// Renders scene text with or without `--wavefront`, its kernels at
/// `simd` (`None`: the process's level).
pub fn render_opts(
    text: &str,
    threads: usize,
    wavefront: bool,
    simd: Option<rpbrt_render::simd::SimdLevel>,
) -> Image {
    render_created(created(text), threads, wavefront, simd)
}

/// Renders a created scene (see [`render_opts`]).
fn render_created(
    created: rpbrt_render::scene::assemble::CreatedScene,
    threads: usize,
    wavefront: bool,
    simd: Option<rpbrt_render::simd::SimdLevel>,
) -> Image {
    let mut scene = created.scene;
    let opts = RenderOptions {
        nthreads: threads,
        wavefront,
        simd,
        ..Default::default()
    };
    let mut md = ImageMetadata::default();
    created
        .integrator
        .render(&mut scene, &opts, &mut md, &|_| {})
        .unwrap();
    let path = scene.film.filename().to_string();
    Image::read(std::path::Path::new(&path), None)
        .unwrap()
        .image
}

/// The two images have the same channels and bit-identical values.
pub fn assert_same_pixels(a: &Image, b: &Image, what: &str) {
    assert_eq!(a.channel_names(), b.channel_names());
    let (va, vb) = (a.to_f32_vec(), b.to_f32_vec());
    assert_eq!(va.len(), vb.len());
    let differing = va
        .iter()
        .zip(&vb)
        .filter(|(x, y)| x.to_bits() != y.to_bits())
        .count();
    assert_eq!(
        differing, 0,
        "wavefront and scalar differ in {differing} values:\n{what}"
    );
}
