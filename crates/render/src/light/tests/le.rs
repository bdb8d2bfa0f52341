//! Emission sampling (`sample_le`, `pdf_le`, `pdf_le_surface`) for every
//! light, in the manner of pbrt-v4's `lights_test.cpp`: the densities
//! `sample_le` reports are the ones `pdf_le` gives back for the same ray,
//! and the Monte Carlo estimate of ∫∫ L cos dA dω through `sample_le`
//! equals the light's power.

use std::sync::Arc;

use rpbrt_geometry::{
    abs_dot, dot, Bounds3f, Float, MediumId, Point2f, Point2i, Point3f, Ray, Transform, Vector3f,
    PI,
};

use super::{disk_light, floats, make, rel_eq, test_envmap};
use crate::camera::CameraTransform;
use crate::image::Image;
use crate::light::*;
use crate::rng::Rng;
use crate::sampling::sample_uniform_sphere;
use crate::shape::{BilinearPatch, BilinearPatchMesh, Cylinder, Shape, ShapeMethods, Sphere};
use crate::spectrum::{RgbColorSpace, SampledSpectrum, SampledWavelengths};
use crate::texture::FloatTexture;

fn scene_bounds() -> Bounds3f {
    Bounds3f::new(Point3f::new(-2.0, -1.0, -3.0), Point3f::new(4.0, 2.0, 1.0))
}

fn u2(rng: &mut Rng) -> Point2f {
    Point2f::new(rng.uniform_float(), rng.uniform_float())
}

/// What [`estimate`] found.
struct Estimate {
    /// Mean of L |cos θ| / (pdf_pos pdf_dir) over all `n` samples (failed
    /// samples count as zero).
    power: SampledSpectrum,
    /// The samples `sample_le` returned.
    samples: Vec<LightLeSample>,
    /// Samples whose densities `pdf_le`/`pdf_le_surface` did not give back
    /// (to 10⁻³): only a sample on a cell boundary of a tabulated
    /// distribution may land in the neighbouring cell.
    pdf_mismatches: usize,
}

/// Samples `n` rays from `light` with a fixed seed and wavelengths,
/// checks each ray (unit direction, time, densities against `pdf_le` or
/// `pdf_le_surface` according to the light's type) and estimates the
/// emitted power.
fn estimate(light: &Light, lambda: &SampledWavelengths, n: usize, seed: u64) -> Estimate {
    let mut rng = Rng::with_sequence(seed);
    let time = 0.375;
    let mut sum = [0.0f64; 4];
    let mut samples = Vec::new();
    let mut pdf_mismatches = 0;
    for _ in 0..n {
        let (a, b) = (u2(&mut rng), u2(&mut rng));
        let Some(s) = light.sample_le(a, b, lambda, time) else {
            continue;
        };
        assert!((s.ray.d.length() - 1.0).abs() < 1e-4, "{:?}", s.ray.d);
        assert_eq!(s.ray.time, time);
        assert!(s.pdf_pos > 0.0 && s.pdf_dir > 0.0, "{s:?}");
        let close = |a: Float, b: Float| rel_eq(a, b, 1e-3);
        let mut cos = 1.0;
        let ok = match light.light_type() {
            LightType::Area => {
                let sp = s.surface.expect("area lights return their surface point");
                cos = abs_dot(sp.n, s.ray.d);
                assert_eq!(light.pdf_le(&s.ray), (0.0, 0.0));
                let (pp, pd) = light.pdf_le_surface(sp.pi.midpoint(), sp.n, s.ray.d);
                close(pp, s.pdf_pos) && close(pd, s.pdf_dir)
            }
            LightType::DeltaPosition => {
                assert!(s.surface.is_none());
                assert_eq!(s.pdf_pos, 1.0);
                let (pp, pd) = light.pdf_le(&s.ray);
                // pbrt-v4: no positional density for a delta position.
                assert_eq!(pp, 0.0);
                close(pd, s.pdf_dir)
            }
            LightType::DeltaDirection => {
                assert!(s.surface.is_none());
                assert_eq!(s.pdf_dir, 1.0);
                let (pp, pd) = light.pdf_le(&s.ray);
                assert_eq!(pd, 0.0);
                close(pp, s.pdf_pos)
            }
            LightType::Infinite => {
                assert!(s.surface.is_none());
                let (pp, pd) = light.pdf_le(&s.ray);
                close(pp, s.pdf_pos) && close(pd, s.pdf_dir)
            }
        };
        if !ok {
            pdf_mismatches += 1;
        }
        for (k, v) in sum.iter_mut().enumerate() {
            *v += (s.l[k] * cos / (s.pdf_pos * s.pdf_dir)) as f64;
        }
        samples.push(s);
    }
    assert!(
        pdf_mismatches * 1000 <= n,
        "{pdf_mismatches} of {n} samples' densities differ from pdf_le's"
    );
    let mut power = SampledSpectrum::new(0.0);
    for k in 0..4 {
        power[k] = (sum[k] / n as f64) as Float;
    }
    Estimate {
        power,
        samples,
        pdf_mismatches,
    }
}

fn assert_power(est: &Estimate, want: SampledSpectrum, eps: Float, what: &str) {
    for k in 0..4 {
        assert!(
            rel_eq(est.power[k], want[k], eps),
            "{what}: estimated power {:?}, expected {:?}",
            est.power,
            want
        );
    }
}

/// ∫ pdf_dir(ω) dω over the sphere of directions from `o`, by jittered
/// stratified uniform sampling on `k` × `k` strata: 1 for a normalised
/// directional density.
fn integrate_pdf_dir(light: &Light, o: Point3f, k: usize, seed: u64) -> Float {
    let mut rng = Rng::with_sequence(seed);
    let mut sum = 0.0f64;
    for i in 0..k {
        for j in 0..k {
            let u = Point2f::new(
                (i as Float + rng.uniform_float()) / k as Float,
                (j as Float + rng.uniform_float()) / k as Float,
            );
            let w = sample_uniform_sphere(u);
            sum += (light.pdf_le(&Ray::new(o, w)).1 * 4.0 * PI) as f64;
        }
    }
    (sum / (k * k) as f64) as Float
}

#[test]
fn point_light_le() {
    let e = super::entity(
        "point",
        vec![floats("power", &[30.0]), floats("from", &[1.0, -2.0, 0.5])],
    );
    let (l, _) = super::create_light(&e, Some(3), &CameraTransform::default()).unwrap();
    let lambda = SampledWavelengths::sample_visible(0.3);
    let est = estimate(&l, &lambda, 4000, 1);
    assert_eq!(est.samples.len(), 4000);
    for s in &est.samples {
        assert_eq!(s.ray.o, Point3f::new(1.0, -2.0, 0.5));
        assert_eq!(s.ray.medium, Some(3));
    }
    assert_power(&est, l.phi(&lambda), 1e-4, "point");
    // Directions cover the sphere uniformly.
    let mean_d = est
        .samples
        .iter()
        .fold(Vector3f::default(), |a, s| a + s.ray.d)
        / est.samples.len() as Float;
    assert!(mean_d.length() < 0.05, "{mean_d:?}");
}

#[test]
fn spot_light_le_follows_the_falloff() {
    let lambda = SampledWavelengths::sample_visible(0.6);
    // A cone with a falloff band, one that is all falloff and one with
    // none.
    for (cone, delta) in [(40.0, 10.0), (30.0, 30.0), (25.0, 0.0)] {
        let l = make(
            "spot",
            vec![
                floats("coneangle", &[cone]),
                floats("conedelta", &[delta]),
                floats("from", &[0.5, 0.0, 1.0]),
                floats("to", &[1.5, 1.0, 1.0]),
            ],
        );
        let Light::Spot(s) = &l else { panic!() };
        let (cs, ce) = (s.cos_falloff_start, s.cos_falloff_end);
        let axis = Vector3f::new(1.0, 1.0, 0.0).normalize();
        let est = estimate(&l, &lambda, 40_000, 2);
        let mut in_band = 0;
        for smp in &est.samples {
            let c = dot(smp.ray.d, axis);
            assert!(c >= ce - 1e-4, "cone {cone}: cos {c} outside {ce}");
            if c < cs - 1e-4 {
                in_band += 1;
                // In the band the intensity falls off.
                assert!(smp.l[0] < s.i.sample(&lambda)[0] * s.scale * (1.0 + 1e-4));
            }
        }
        // The band gets its share of the power.
        let band_share = ((cs - ce) / 2.0) / ((1.0 - cs) + (cs - ce) / 2.0);
        let got = in_band as Float / est.samples.len() as Float;
        assert!((got - band_share).abs() < 0.01, "{got} vs {band_share}");
        assert_power(&est, l.phi(&lambda), 1e-3, "spot");
        let int = integrate_pdf_dir(&l, Point3f::new(0.5, 0.0, 1.0), 640, 3);
        assert!((int - 1.0).abs() < 5e-3, "cone {cone}: ∫pdf_dir = {int}");
    }
}

#[test]
fn goniometric_light_le() {
    let res = 16;
    let mut data = Vec::new();
    for y in 0..res {
        for x in 0..res {
            data.push(if (x, y) == (4, 9) {
                20.0
            } else {
                0.1 + ((x * 3 + y) % 5) as f32 * 0.2
            });
        }
    }
    let image = Image::from_f32(data, Point2i::new(res, res), &["Y"]).unwrap();
    let cs = RgbColorSpace::srgb();
    let xf = Transform::translate(Vector3f::new(0.0, 1.0, 0.0))
        * Transform::rotate(35.0, Vector3f::new(1.0, 1.0, 0.0).normalize());
    let l = Light::Goniometric(Box::new(GoniometricLight::new(
        xf,
        dense(&cs.illuminant_spectrum()),
        0.02,
        image,
        Some(1),
    )));
    let lambda = SampledWavelengths::sample_visible(0.45);
    let est = estimate(&l, &lambda, 20_000, 4);
    for s in &est.samples {
        assert!((s.ray.o - Point3f::new(0.0, 1.0, 0.0)).length() < 1e-6);
        assert_eq!(s.ray.medium, Some(1));
        // Sampling follows the image: intensity / density is the power.
        for k in 0..4 {
            assert!(rel_eq(s.l[k] / s.pdf_dir, l.phi(&lambda)[k], 2e-3));
        }
    }
    assert_power(&est, l.phi(&lambda), 2e-3, "goniometric");
    let int = integrate_pdf_dir(&l, Point3f::new(0.0, 1.0, 0.0), 640, 5);
    assert!((int - 1.0).abs() < 5e-3, "∫pdf_dir = {int}");
}

#[test]
fn projection_light_le() {
    let mut data = Vec::new();
    for y in 0..8 {
        for x in 0..12 {
            let v = 0.1 + ((x * y) % 5) as f32 * 0.2;
            data.extend_from_slice(&[v, 0.5 * v, 0.2]);
        }
    }
    let image = Image::from_f32(data, Point2i::new(12, 8), &["R", "G", "B"]).unwrap();
    let xf = Transform::translate(Vector3f::new(1.0, 0.0, 2.0)) * Transform::rotate_y(30.0);
    let l = Light::Projection(Box::new(ProjectionLight::new(
        xf,
        image,
        RgbColorSpace::srgb(),
        0.01,
        60.0,
        None,
    )));
    let lambda = SampledWavelengths::sample_visible(0.7);
    let est = estimate(&l, &lambda, 100_000, 6);
    // Each sample's radiance is what the light projects that way.
    let Light::Projection(p) = &l else { panic!() };
    for s in est.samples.iter().take(2000) {
        let wl = xf.apply_inverse_vector(s.ray.d);
        assert_eq!(p.projection(wl, &lambda), s.l);
    }
    assert_power(&est, l.phi(&lambda), 1e-2, "projection");
    let int = integrate_pdf_dir(&l, Point3f::new(1.0, 0.0, 2.0), 640, 7);
    assert!((int - 1.0).abs() < 5e-3, "∫pdf_dir = {int}");
    // Behind the light and outside the frustum: no density.
    let o = Point3f::new(1.0, 0.0, 2.0);
    assert_eq!(
        l.pdf_le(&Ray::new(o, xf.apply_vector(-Vector3f::new(0.0, 0.0, 1.0))))
            .1,
        0.0
    );
    assert_eq!(
        l.pdf_le(&Ray::new(
            o,
            xf.apply_vector(Vector3f::new(1.0, 0.0, 0.1)).normalize()
        ))
        .1,
        0.0
    );
}

#[test]
fn distant_light_le() {
    let mut l = make(
        "distant",
        vec![
            floats("L", &[0.3, 0.6, 0.9]),
            floats("from", &[1.0, 2.0, 0.5]),
            floats("to", &[0.0, 0.0, 0.0]),
        ],
    );
    l.preprocess(&scene_bounds());
    let (c, r) = scene_bounds().bounding_sphere();
    let lambda = SampledWavelengths::sample_visible(0.1);
    let est = estimate(&l, &lambda, 20_000, 8);
    let toward = Vector3f::new(1.0, 2.0, 0.5).normalize();
    let mut mean_offset = Vector3f::default();
    for s in &est.samples {
        assert!((s.ray.d + toward).length() < 1e-5);
        assert_eq!(s.ray.medium, None);
        // The ray starts a radius before the scene's bounding disk and
        // crosses the disk inside it.
        let v = c - s.ray.o;
        assert!(rel_eq(dot(v, s.ray.d), r, 1e-4));
        let off = v - s.ray.d * dot(v, s.ray.d);
        assert!(off.length() <= r * (1.0 + 1e-4));
        mean_offset += off;
        assert!(rel_eq(s.pdf_pos, 1.0 / (PI * r * r), 1e-5));
    }
    assert!((mean_offset / est.samples.len() as Float).length() < 0.02 * r);
    assert_power(&est, l.phi(&lambda), 1e-4, "distant");
}

#[test]
fn uniform_infinite_light_le() {
    let mut l = make("infinite", vec![floats("L", &[0.2, 0.5, 0.9])]);
    l.preprocess(&scene_bounds());
    let (c, r) = scene_bounds().bounding_sphere();
    let lambda = SampledWavelengths::sample_visible(0.8);
    let est = estimate(&l, &lambda, 20_000, 9);
    for s in &est.samples {
        let v = c - s.ray.o;
        assert!(rel_eq(dot(v, s.ray.d), r, 1e-4));
        assert!((v - s.ray.d * dot(v, s.ray.d)).length() <= r * (1.0 + 1e-4));
        // The radiance is what a ray escaping toward the light sees.
        assert_eq!(s.l, l.le(&Ray::new(c, -s.ray.d), &lambda));
    }
    assert_power(&est, l.phi(&lambda), 1e-4, "uniform infinite");
}

#[test]
fn image_infinite_light_le() {
    let xf = Transform::rotate(40.0, Vector3f::new(0.3, 1.0, 0.2).normalize());
    let mut l = Light::ImageInfinite(Box::new(ImageInfiniteLight::new(
        xf,
        test_envmap(16, Point2i::new(3, 11)),
        RgbColorSpace::srgb(),
        1.5,
    )));
    l.preprocess(&scene_bounds());
    let (c, _) = scene_bounds().bounding_sphere();
    let lambda = SampledWavelengths::sample_visible(0.25);
    let est = estimate(&l, &lambda, 100_000, 10);
    for s in est.samples.iter().take(2000) {
        // The ray carries the radiance arriving from where it came from.
        assert_eq!(s.l, l.le(&Ray::new(c, -s.ray.d), &lambda));
    }
    assert_power(&est, l.phi(&lambda), 1e-3, "image infinite");
    let int = integrate_pdf_dir(&l, c, 640, 11);
    assert!((int - 1.0).abs() < 5e-3, "∫pdf_dir = {int}");
}

/// A portal light in the plane z = 1, the environment above it.
fn portal_light(image: &Image) -> Light {
    let corners = [
        Point3f::new(-0.5, -0.4, 1.0),
        Point3f::new(-0.5, 0.4, 1.0),
        Point3f::new(0.7, 0.4, 1.0),
        Point3f::new(0.7, -0.4, 1.0),
    ];
    let xf = Transform::rotate_z(20.0);
    let mut l = Light::PortalImageInfinite(Box::new(
        PortalImageInfiniteLight::new(xf, image, RgbColorSpace::srgb(), 0.8, corners).unwrap(),
    ));
    l.preprocess(&scene_bounds());
    l
}

#[test]
fn portal_light_le() {
    let (_, r) = scene_bounds().bounding_sphere();
    let lambda = SampledWavelengths::sample_visible(0.55);
    // A constant environment: every direction from above the portal's
    // plane carries the same radiance, so the estimate is π r² · 2π L
    // (the rays' directions cover the hemisphere, not only the portal's
    // solid angle, as pbrt-v4's). pbrt-v4's `Phi` for this light is a
    // different estimate (it divides by dω/d(u,v)), so it is not the
    // reference here.
    let constant =
        Image::from_f32(vec![0.6; 8 * 8 * 3], Point2i::new(8, 8), &["R", "G", "B"]).unwrap();
    let l = portal_light(&constant);
    let est = estimate(&l, &lambda, 20_000, 12);
    let l0 = est.samples[0].l;
    for s in &est.samples {
        assert!(s.ray.d.z < 0.0, "rays travel away from the environment");
        // (The resampled constant map is constant up to rounding.)
        assert!((0..4).all(|k| rel_eq(s.l[k], l0[k], 1e-5)));
    }
    assert_power(
        &est,
        l0 * (PI * r * r * 2.0 * PI),
        5e-3,
        "portal, constant map",
    );
    // A varying environment: against the midpoint rule over the rectified
    // image, ∫ L dω = ∫∫ L(u,v) dω/d(u,v) du dv.
    let l = portal_light(&test_envmap(32, Point2i::new(20, 7)));
    let Light::PortalImageInfinite(p) = &l else {
        panic!()
    };
    let res = p.image.resolution();
    let mut quad = SampledSpectrum::new(0.0);
    for y in 0..res.y {
        for x in 0..res.x {
            let uv = Point2f::new(
                (x as Float + 0.5) / res.x as Float,
                (y as Float + 0.5) / res.y as Float,
            );
            let (_, dw_duv) = p.render_from_image(uv);
            quad += p.image_lookup(uv, &lambda) * dw_duv;
        }
    }
    let quad = quad * (PI * r * r / (res.x * res.y) as Float);
    let est = estimate(&l, &lambda, 100_000, 13);
    assert_power(&est, quad, 2e-2, "portal, varying map");
    // Rays from the environment's side of the portal plane have no
    // density.
    assert_eq!(
        l.pdf_le(&Ray::new(
            Point3f::new(0.0, 0.0, 0.0),
            Vector3f::new(0.0, 0.0, 1.0)
        )),
        (0.0, 0.0)
    );
}

#[test]
fn area_light_le_one_and_two_sided() {
    let xf = Transform::translate(Vector3f::new(0.0, 0.5, 1.0)) * Transform::rotate_x(30.0);
    let lambda = SampledWavelengths::sample_visible(0.35);
    for two_sided in [false, true] {
        let mut l = disk_light(two_sided, None, xf);
        if let Light::DiffuseArea(a) = &mut l {
            a.medium_inside = Some(7);
            a.medium_outside = Some(8);
        }
        let est = estimate(&l, &lambda, 100_000, 14);
        assert_eq!(est.samples.len(), 100_000);
        let mut back = 0;
        for s in &est.samples {
            let sp = s.surface.unwrap();
            let facing = dot(sp.n, s.ray.d);
            if facing < 0.0 {
                back += 1;
            }
            // Leaves from (just off) the sampled point, in the medium on
            // the side it leaves by.
            assert!((s.ray.o - sp.pi.midpoint()).length() < 1e-4);
            assert_eq!(s.ray.medium, Some(if facing > 0.0 { 8 } else { 7 }));
            assert_eq!(s.l, l.l(sp.pi.midpoint(), sp.n, sp.uv, s.ray.d, &lambda));
        }
        let back = back as Float / est.samples.len() as Float;
        if two_sided {
            assert!((back - 0.5).abs() < 0.01, "{back}");
        } else {
            assert_eq!(back, 0.0);
        }
        assert_power(&est, l.phi(&lambda), 1e-3, "disk");
        // One-sided lights have no density behind.
        let s = est.samples[0].surface.unwrap();
        let behind = -Vector3f::from(s.n);
        let (_, pd) = l.pdf_le_surface(s.pi.midpoint(), s.n, behind);
        assert_eq!(pd, if two_sided { 1.0 / (2.0 * PI) } else { 0.0 });
    }
}

/// A diffuse area light with spectrum emission on `shape`.
fn area_light_on(shape: Shape, two_sided: bool) -> Light {
    let cs = RgbColorSpace::srgb();
    Light::DiffuseArea(Box::new(
        DiffuseAreaLight {
            area: shape.area(),
            shape,
            emission: AreaEmission::Spectrum(dense(&cs.illuminant_spectrum())),
            scale: 0.3,
            two_sided,
            alpha: None,
            medium_inside: None,
            medium_outside: None,
            sampled_triangle: None,
        }
        .with_cache(),
    ))
}

#[test]
fn area_light_le_on_curved_shapes() {
    let lambda = SampledWavelengths::sample_visible(0.9);
    let sphere = Sphere::new(
        Transform::translate(Vector3f::new(1.0, 0.0, 0.0)),
        false,
        0.7,
        -0.7,
        0.7,
        360.0,
    )
    .unwrap();
    let l = area_light_on(Shape::Sphere(Box::new(sphere)), false);
    assert_power(
        &estimate(&l, &lambda, 50_000, 15),
        l.phi(&lambda),
        1e-3,
        "sphere",
    );
    // A twisted bilinear patch: not sampled uniformly by area, so its
    // density at a point comes from inverting the patch's parameters.
    let (mesh, _) = BilinearPatchMesh::new(
        &Transform::identity(),
        false,
        vec![],
        vec![
            Point3f::new(0.0, 0.0, 0.0),
            Point3f::new(2.0, 0.0, 0.5),
            Point3f::new(0.0, 1.0, 0.6),
            Point3f::new(1.5, 1.5, -0.4),
        ],
        vec![],
        vec![],
        vec![],
    )
    .unwrap();
    let patch = BilinearPatch::new(mesh, 0);
    assert!(!patch.is_rectangle());
    let l = area_light_on(Shape::BilinearPatch(patch), true);
    let est = estimate(&l, &lambda, 50_000, 16);
    assert_eq!(est.pdf_mismatches, 0);
    assert_power(&est, l.phi(&lambda), 2e-3, "bilinear patch");
}

#[test]
fn image_area_light_le() {
    // The cylinder's (u, v) are uniform in area, and the image varies
    // only in brightness, so its mean is the mean emitted radiance.
    let (nx, ny) = (6, 5);
    let mut data = Vec::new();
    for y in 0..ny {
        for x in 0..nx {
            let v = 0.2 + ((x * 2 + y * 3) % 7) as f32 * 0.3;
            data.extend_from_slice(&[0.9 * v, 0.5 * v, 0.3 * v]);
        }
    }
    let image = Image::from_f32(data, Point2i::new(nx, ny), &["R", "G", "B"]).unwrap();
    let cyl = Cylinder::new(Transform::rotate_x(70.0), false, 0.8, -0.5, 1.0, 360.0).unwrap();
    let shape = Shape::Cylinder(Box::new(cyl));
    let l = Light::DiffuseArea(Box::new(DiffuseAreaLight {
        area: shape.area(),
        shape,
        emission: AreaEmission::Image(image, RgbColorSpace::srgb()),
        scale: 2.0,
        two_sided: false,
        alpha: None,
        medium_inside: None,
        medium_outside: None,
        sampled_triangle: None,
    }));
    let lambda = SampledWavelengths::sample_visible(0.15);
    let est = estimate(&l, &lambda, 100_000, 17);
    assert_power(&est, l.phi(&lambda), 5e-3, "image area light");
}

#[test]
fn alpha_masked_area_light_le() {
    let lambda = SampledWavelengths::sample_visible(0.5);
    let with_alpha = |a: Float| {
        let mut l = disk_light(false, None, Transform::identity());
        if let Light::DiffuseArea(d) = &mut l {
            d.alpha = Some(Arc::new(FloatTexture::Constant(a)));
        }
        l
    };
    let mut rng = Rng::with_sequence(18);
    let l = with_alpha(0.0);
    for _ in 0..1000 {
        assert!(l
            .sample_le(u2(&mut rng), u2(&mut rng), &lambda, 0.0)
            .is_none());
    }
    // Stochastic alpha: about half of the points are cut out; those kept
    // emit.
    let l = with_alpha(0.5);
    let n = 20_000;
    let mut kept = 0;
    for _ in 0..n {
        if let Some(s) = l.sample_le(u2(&mut rng), u2(&mut rng), &lambda, 0.0) {
            assert!(!s.l.is_black());
            kept += 1;
        }
    }
    let kept = kept as Float / n as Float;
    assert!((kept - 0.5).abs() < 0.03, "{kept}");
}

#[test]
fn non_matching_pdf_queries_are_zero() {
    let lambda = SampledWavelengths::sample_visible(0.5);
    let area = disk_light(true, None, Transform::identity());
    let point = make("point", vec![]);
    let ray = Ray::new(Point3f::new(0.0, 0.0, 0.0), Vector3f::new(0.0, 0.0, 1.0));
    assert_eq!(area.pdf_le(&ray), (0.0, 0.0));
    let n = rpbrt_geometry::Normal3f::new(0.0, 0.0, 1.0);
    assert_eq!(point.pdf_le_surface(ray.o, n, ray.d), (0.0, 0.0));
    assert!(point
        .sample_le(Point2f::new(0.5, 0.5), Point2f::new(0.5, 0.5), &lambda, 0.0)
        .is_some());
    let _: Option<MediumId> = point.medium();
}
