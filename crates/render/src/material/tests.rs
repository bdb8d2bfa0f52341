use std::sync::Arc;

use rpbrt_geometry::float::*;
use rpbrt_geometry::interaction::SurfaceInteraction;
use rpbrt_geometry::tuple::*;

use super::*;
use crate::bxdf::{BxDF, BxDFMethods, BxDFReflTransFlags, TransportMode};
use crate::image::{Image, ImageMetadata};
use crate::spectrum::{named_spectrum, SampledWavelengths, Spectrum};
use crate::texture::{FloatTexture, FloatTextureRef, SpectrumTexture, SpectrumTextureRef};

fn ftex(v: Float) -> FloatTextureRef {
    Arc::new(FloatTexture::Constant(v))
}

fn stex(v: Float) -> SpectrumTextureRef {
    Arc::new(SpectrumTexture::Constant(Spectrum::constant(v)))
}

fn smooth() -> Roughness {
    Roughness {
        u: ftex(0.0),
        v: ftex(0.0),
        remap: true,
    }
}

/// A hit on the z = 0 plane at `p` seen from `wo`, with u along x and v
/// along y; `flip` turns the geometric normal to −z.
fn si_at(p: Point3f, wo: Vector3f, flip: bool) -> SurfaceInteraction {
    SurfaceInteraction::new(
        Point3fi::from(p),
        Point2f::new(0.25, 0.5),
        wo,
        Vector3f::new(1.0, 0.0, 0.0),
        Vector3f::new(0.0, 1.0, 0.0),
        Normal3f::default(),
        Normal3f::default(),
        0.0,
        flip,
    )
}

fn si() -> SurfaceInteraction {
    si_at(
        Point3f::new(0.0, 0.0, 0.0),
        Vector3f::new(0.0, 0.0, 1.0),
        false,
    )
}

fn lambda() -> SampledWavelengths {
    SampledWavelengths::sample_visible(0.37)
}

fn diffuse(r: Float) -> Material {
    Material::Diffuse(DiffuseMaterial {
        reflectance: stex(r),
        perturbation: ShadingPerturbation::default(),
    })
}

fn bsdf_of(m: Material) -> (Option<crate::bxdf::BSDF>, SampledWavelengths) {
    let set = MaterialSet::new(vec![m]);
    let mut l = lambda();
    let b = set.get_bsdf(0, &mut si(), &mut l);
    (b, l)
}

fn up() -> Vector3f {
    Vector3f::new(0.0, 0.0, 1.0)
}

fn tilted() -> Vector3f {
    Vector3f::new(0.3, -0.2, 0.9).normalize()
}

fn close(a: Float, b: Float, eps: Float) -> bool {
    (a - b).abs() <= eps * (1.0 + b.abs())
}

#[test]
fn diffuse_reflectance_gives_r_over_pi() {
    let (b, l) = bsdf_of(diffuse(0.3));
    let b = b.expect("diffuse has a BSDF");
    assert!(matches!(b.bxdf, BxDF::Diffuse(_)));
    let f = b.f(up(), tilted(), TransportMode::Radiance);
    for i in 0..4 {
        assert!(close(f[i], 0.3 * INV_PI, 1e-5), "{f:?}");
    }
    assert!(!l.secondary_terminated());
}

#[test]
fn diffuse_reflectance_is_clamped() {
    let (b, _) = bsdf_of(diffuse(1.7));
    let f = b.unwrap().f(up(), tilted(), TransportMode::Radiance);
    assert!(close(f[0], INV_PI, 1e-5));
}

#[test]
fn diffuse_transmission_scales_and_transmits() {
    let m = Material::DiffuseTransmission(DiffuseTransmissionMaterial {
        reflectance: stex(0.25),
        transmittance: stex(0.1),
        scale: 2.0,
        perturbation: ShadingPerturbation::default(),
    });
    let b = bsdf_of(m).0.unwrap();
    assert!(matches!(b.bxdf, BxDF::DiffuseTransmission(_)));
    let fr = b.f(up(), tilted(), TransportMode::Radiance);
    let ft = b.f(up(), -tilted(), TransportMode::Radiance);
    assert!(close(fr[0], 0.5 * INV_PI, 1e-5), "{fr:?}");
    assert!(close(ft[0], 0.2 * INV_PI, 1e-5), "{ft:?}");
}

/// Reflectance at normal incidence of a smooth specular BSDF: f cos / pdf
/// of its (only) reflection sample.
fn normal_incidence_reflectance(b: &crate::bxdf::BSDF) -> SampledSpectrum {
    let s = b
        .sample_f(
            up(),
            0.0,
            Point2f::new(0.5, 0.5),
            TransportMode::Radiance,
            BxDFReflTransFlags::REFLECTION,
        )
        .expect("a reflection sample");
    assert!(s.is_specular() && s.is_reflection());
    s.f * s.wi.z.abs() / s.pdf
}

use crate::spectrum::SampledSpectrum;

#[test]
fn conductor_from_reflectance_reflects_r_at_normal_incidence() {
    for r in [0.05, 0.4, 0.9] {
        let m = Material::Conductor(ConductorMaterial {
            spectra: ConductorSpectra::Reflectance(stex(r)),
            roughness: smooth(),
            perturbation: ShadingPerturbation::default(),
        });
        let b = bsdf_of(m).0.unwrap();
        assert!(matches!(b.bxdf, BxDF::Conductor(_)));
        let refl = normal_incidence_reflectance(&b);
        for i in 0..4 {
            assert!(close(refl[i], r, 1e-4), "r {r}: {refl:?}");
        }
    }
}

#[test]
fn conductor_eta_k_matches_fresnel() {
    let eta = named_spectrum("metal-Cu-eta").unwrap();
    let k = named_spectrum("metal-Cu-k").unwrap();
    let m = Material::Conductor(ConductorMaterial {
        spectra: ConductorSpectra::EtaK {
            eta: Arc::new(SpectrumTexture::Constant(eta.clone())),
            k: Arc::new(SpectrumTexture::Constant(k.clone())),
        },
        roughness: smooth(),
        perturbation: ShadingPerturbation::default(),
    });
    let (b, l) = bsdf_of(m);
    let refl = normal_incidence_reflectance(&b.unwrap());
    for i in 0..4 {
        let (n, kk) = (eta.evaluate(l[i]), k.evaluate(l[i]));
        let expect = ((n - 1.0) * (n - 1.0) + kk * kk) / ((n + 1.0) * (n + 1.0) + kk * kk);
        assert!(close(refl[i], expect, 1e-3), "{i}: {} vs {expect}", refl[i]);
    }
}

#[test]
fn rough_conductor_is_glossy() {
    let m = Material::Conductor(ConductorMaterial {
        spectra: ConductorSpectra::Reflectance(stex(0.5)),
        roughness: Roughness {
            u: ftex(0.3),
            v: ftex(0.3),
            remap: false,
        },
        perturbation: ShadingPerturbation::default(),
    });
    let b = bsdf_of(m).0.unwrap();
    let BxDF::Conductor(c) = b.bxdf else {
        panic!("not a conductor")
    };
    assert_eq!(c.distribution().alpha_x(), 0.3);
    assert!(b.flags().is_glossy());
}

fn dielectric(eta: Spectrum) -> Material {
    Material::Dielectric(DielectricMaterial {
        eta,
        roughness: smooth(),
        perturbation: ShadingPerturbation::default(),
    })
}

#[test]
fn dielectric_constant_eta_keeps_wavelengths() {
    let (b, l) = bsdf_of(dielectric(Spectrum::constant(1.33)));
    let BxDF::Dielectric(d) = b.unwrap().bxdf else {
        panic!("not a dielectric")
    };
    assert_eq!(d.eta(), 1.33);
    assert!(!l.secondary_terminated());
}

#[test]
fn dielectric_spectral_eta_terminates_secondary() {
    let bk7 = named_spectrum("glass-BK7").unwrap();
    let (b, l) = bsdf_of(dielectric(bk7.clone()));
    let BxDF::Dielectric(d) = b.unwrap().bxdf else {
        panic!("not a dielectric")
    };
    assert!(l.secondary_terminated());
    assert!(close(d.eta(), bk7.evaluate(l[0]), 1e-6));
    assert!(d.eta() > 1.4 && d.eta() < 1.6);
}

#[test]
fn zero_eta_is_taken_as_one() {
    let (b, _) = bsdf_of(dielectric(Spectrum::constant(0.0)));
    let BxDF::Dielectric(d) = b.unwrap().bxdf else {
        panic!("not a dielectric")
    };
    assert_eq!(d.eta(), 1.0);
}

#[test]
fn thin_dielectric_kind_and_dispersion() {
    let m = Material::ThinDielectric(ThinDielectricMaterial {
        eta: named_spectrum("glass-F11").unwrap(),
        perturbation: ShadingPerturbation::default(),
    });
    let (b, l) = bsdf_of(m);
    assert!(matches!(b.unwrap().bxdf, BxDF::ThinDielectric(_)));
    assert!(l.secondary_terminated());
}

fn layer() -> coated::LayerSettings {
    coated::LayerSettings {
        thickness: ftex(0.01),
        albedo: stex(0.0),
        g: ftex(0.0),
        max_depth: 10,
        n_samples: 1,
    }
}

#[test]
fn coated_materials_build_layered_bxdfs() {
    let cd = Material::CoatedDiffuse(Box::new(CoatedDiffuseMaterial {
        reflectance: stex(0.5),
        roughness: smooth(),
        eta: Spectrum::constant(1.5),
        layer: layer(),
        perturbation: ShadingPerturbation::default(),
    }));
    let (b, l) = bsdf_of(cd);
    let b = b.unwrap();
    assert!(matches!(b.bxdf, BxDF::CoatedDiffuse(_)));
    assert!(!l.secondary_terminated());
    // Energy: the coated Lambertian reflects less than its base but not
    // nothing.
    let uc: Vec<Float> = (0..256).map(|i| (i as Float + 0.5) / 256.0).collect();
    let u2: Vec<Point2f> = (0..256)
        .map(|i| {
            Point2f::new(
                ((i * 37) % 256) as Float / 256.0,
                (i as Float + 0.5) / 256.0,
            )
        })
        .collect();
    let rho = b.rho_hd(up(), &uc, &u2);
    assert!(rho[0] > 0.2 && rho[0] < 0.55, "{rho:?}");

    let cc = Material::CoatedConductor(Box::new(CoatedConductorMaterial {
        interface_roughness: smooth(),
        interface_eta: named_spectrum("glass-BK7").unwrap(),
        conductor: ConductorSpectra::Reflectance(stex(0.8)),
        conductor_roughness: smooth(),
        layer: layer(),
        perturbation: ShadingPerturbation::default(),
    }));
    let (b, l) = bsdf_of(cc);
    assert!(matches!(b.unwrap().bxdf, BxDF::CoatedConductor(_)));
    assert!(l.secondary_terminated());
}

#[test]
fn hair_material_builds_hair_bxdf() {
    for absorption in [
        HairAbsorption::Melanin {
            eumelanin: ftex(1.3),
            pheomelanin: ftex(0.0),
        },
        HairAbsorption::SigmaA(stex(0.5)),
        HairAbsorption::Reflectance(stex(0.4)),
    ] {
        let m = Material::Hair(HairMaterial {
            absorption,
            eta: ftex(1.55),
            beta_m: ftex(0.3),
            beta_n: ftex(0.3),
            alpha: ftex(2.0),
        });
        let b = bsdf_of(m).0.unwrap();
        let BxDF::Hair(h) = b.bxdf else {
            panic!("not hair")
        };
        assert!(close(h.beta_m(), 0.3, 1e-6));
        let f = b.f(up(), tilted(), TransportMode::Radiance);
        assert!(f[0] > 0.0 && f[0].is_finite());
    }
}

#[test]
fn subsurface_has_dielectric_boundary_and_bssrdf_flag() {
    let (sa, ss) = get_medium_scattering_properties("Skin1").unwrap();
    let m = Material::Subsurface(Box::new(SubsurfaceMaterial {
        scale: 1.0,
        coefficients: SubsurfaceCoefficients::Coefficients {
            sigma_a: Arc::new(SpectrumTexture::Constant(sa)),
            sigma_s: Arc::new(SpectrumTexture::Constant(ss)),
        },
        g: 0.0,
        eta: 1.33,
        roughness: smooth(),
        perturbation: ShadingPerturbation::default(),
    }));
    assert!(m.has_subsurface_scattering());
    let set = MaterialSet::new(vec![m, diffuse(0.5)]);
    assert!(set.has_subsurface(0, &si()));
    assert!(!set.has_subsurface(1, &si()));
    assert!(set.any_subsurface());
    let b = set.get_bsdf(0, &mut si(), &mut lambda()).unwrap();
    let BxDF::Dielectric(d) = b.bxdf else {
        panic!("not a dielectric")
    };
    assert_eq!(d.eta(), 1.33);
}

#[test]
fn measured_media_table_lookups() {
    assert_eq!(crate::medium::measured::MEASURED_MEDIA.len(), 47);
    assert!(get_medium_scattering_properties("Ketchup").is_some());
    assert!(get_medium_scattering_properties("Pacific Ocean Surface Water").is_some());
    assert!(get_medium_scattering_properties("ketchup").is_none());
    let (sa, ss) = get_medium_scattering_properties("Wholemilk").unwrap();
    // Unbounded RGB spectra reproduce the table's magnitude.
    assert!(ss.evaluate(550.0) > 2.5 && ss.evaluate(550.0) < 4.0);
    assert!(sa.evaluate(550.0) < 0.01);
}

#[test]
fn interface_has_no_bsdf() {
    let set = MaterialSet::new(vec![Material::Interface]);
    let mut s = si();
    let before = s.shading;
    assert!(set.get_bsdf(0, &mut s, &mut lambda()).is_none());
    assert_eq!(s.shading, before);
    assert!(set.get_bsdf(7, &mut si(), &mut lambda()).is_none());
}

fn mix(amount: Float, a: u32, b: u32) -> Material {
    Material::Mix(MixMaterial {
        materials: [a, b],
        amount: ftex(amount),
    })
}

fn diffuse_value(b: &crate::bxdf::BSDF) -> Float {
    b.f(up(), tilted(), TransportMode::Radiance)[0] * PI
}

#[test]
fn mix_extremes_pick_one_material() {
    let set = MaterialSet::new(vec![
        diffuse(0.2),
        diffuse(0.7),
        mix(0.0, 0, 1),
        mix(1.0, 0, 1),
        mix(-3.0, 0, 1),
        mix(5.0, 0, 1),
    ]);
    let v = |i| diffuse_value(&set.get_bsdf(i, &mut si(), &mut lambda()).unwrap());
    assert!(close(v(2), 0.2, 1e-5));
    assert!(close(v(3), 0.7, 1e-5));
    assert!(close(v(4), 0.2, 1e-5));
    assert!(close(v(5), 0.7, 1e-5));
}

#[test]
fn mix_half_picks_each_about_half_the_time_deterministically() {
    let set = MaterialSet::new(vec![diffuse(0.2), diffuse(0.7), mix(0.5, 0, 1)]);
    let mut rng = crate::rng::Rng::new(7, 0);
    let n = 4000;
    let mut second = 0;
    for _ in 0..n {
        let p = Point3f::new(
            rng.uniform_float(),
            rng.uniform_float(),
            rng.uniform_float(),
        );
        let wo =
            Vector3f::new(rng.uniform_float() - 0.5, rng.uniform_float() - 0.5, 1.0).normalize();
        let s = si_at(p, wo, false);
        let (a, _) = set.resolve(2, &s).unwrap();
        let (b, _) = set.resolve(2, &s).unwrap();
        assert_eq!(a, b, "the choice must be deterministic per point");
        if a == 1 {
            second += 1;
        }
    }
    let frac = second as f64 / n as f64;
    assert!((frac - 0.5).abs() < 0.04, "{frac}");
}

#[test]
fn mix_amount_is_the_probability_of_the_second() {
    let set = MaterialSet::new(vec![diffuse(0.2), diffuse(0.7), mix(0.2, 0, 1)]);
    let n = 4000;
    let mut second = 0;
    for i in 0..n {
        let p = Point3f::new(i as Float * 0.013, (i % 17) as Float * 0.1, 0.0);
        if set.resolve(2, &si_at(p, up(), false)).unwrap().0 == 1 {
            second += 1;
        }
    }
    let frac = second as f64 / n as f64;
    assert!((frac - 0.2).abs() < 0.03, "{frac}");
}

#[test]
fn mix_of_interface_and_nested_mix() {
    let set = MaterialSet::new(vec![
        Material::Interface,
        diffuse(0.7),
        mix(0.0, 0, 1),
        mix(1.0, 2, 1),
        mix(0.0, 2, 1),
    ]);
    assert!(set.get_bsdf(2, &mut si(), &mut lambda()).is_none());
    assert!(set.get_bsdf(3, &mut si(), &mut lambda()).is_some());
    assert!(set.get_bsdf(4, &mut si(), &mut lambda()).is_none());
}

fn with_perturbation(perturbation: ShadingPerturbation) -> Material {
    Material::Diffuse(DiffuseMaterial {
        reflectance: stex(0.5),
        perturbation,
    })
}

#[test]
fn constant_displacement_leaves_the_normal_unchanged() {
    for flip in [false, true] {
        let set = MaterialSet::new(vec![with_perturbation(ShadingPerturbation {
            displacement: Some(ftex(0.3)),
            normal_map: None,
        })]);
        let mut s = si_at(Point3f::new(0.1, 0.2, 0.0), up(), flip);
        let n_before = s.shading.n;
        let b = set.get_bsdf(0, &mut s, &mut lambda()).unwrap();
        assert!(
            (s.shading.n - n_before).length() < 1e-6,
            "{:?}",
            s.shading.n
        );
        assert!(dot(s.shading.n, s.n) > 0.0);
        assert!((b.local_to_render(up()) - Vector3f::from(s.shading.n)).length() < 1e-5);
    }
}

/// A 4×4 RGB float image of one colour, written as PFM to a temp file and
/// read back as a normal map.
fn flat_normal_map(rgb: [f32; 3], tag: &str) -> Arc<Image> {
    let data: Vec<f32> = (0..16).flat_map(|_| rgb).collect();
    let im = Image::from_f32(data, Point2i::new(4, 4), &["R", "G", "B"]).unwrap();
    let dir = std::env::temp_dir().join(format!("rpbrt-material-{}-{tag}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("n.pfm");
    im.write(&path, &ImageMetadata::default()).unwrap();
    let read = read_normal_map(&path, &Default::default()).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    Arc::new(read)
}

#[test]
fn flat_normal_map_leaves_the_normal_unchanged() {
    let nm = flat_normal_map([0.5, 0.5, 1.0], "flat");
    let set = MaterialSet::new(vec![with_perturbation(ShadingPerturbation {
        displacement: Some(ftex(1.0)),
        normal_map: Some(nm),
    })]);
    for flip in [false, true] {
        let mut s = si_at(Point3f::new(0.1, 0.2, 0.0), up(), flip);
        let n_before = s.shading.n;
        set.get_bsdf(0, &mut s, &mut lambda()).unwrap();
        assert!(
            (s.shading.n - n_before).length() < 1e-5,
            "{:?}",
            s.shading.n
        );
        assert!((s.shading.dpdu - Vector3f::new(1.0, 0.0, 0.0)).length() < 1e-5);
    }
}

#[test]
fn tilted_normal_map_tilts_towards_u() {
    // Tangent-space normal (0.6, 0, 0.8): RGB = (n + 1) / 2.
    let nm = flat_normal_map([0.8, 0.5, 0.9], "tilted");
    let set = MaterialSet::new(vec![with_perturbation(ShadingPerturbation {
        displacement: None,
        normal_map: Some(nm),
    })]);
    let mut s = si();
    let b = set.get_bsdf(0, &mut s, &mut lambda()).unwrap();
    let expect = Vector3f::new(0.6, 0.0, 0.8);
    assert!(
        (Vector3f::from(s.shading.n) - expect).length() < 1e-4,
        "{:?}",
        s.shading.n
    );
    assert!(dot(s.shading.dpdu, Vector3f::from(s.shading.n)).abs() < 1e-5);
    assert!(close(s.shading.dpdu.length(), 1.0, 1e-5));
    assert!(close(s.shading.dpdv.length(), 1.0, 1e-5));
    assert!((b.local_to_render(up()) - expect).length() < 1e-4);
    // The geometric normal is untouched.
    assert_eq!(s.n, Normal3f::new(0.0, 0.0, 1.0));

    // On a surface whose geometric normal faces −z the shading normal stays
    // on that side.
    let mut s = si_at(Point3f::new(0.0, 0.0, 0.0), up(), true);
    set.get_bsdf(0, &mut s, &mut lambda()).unwrap();
    assert!(dot(s.shading.n, s.n) > 0.0);
    assert!(
        (Vector3f::from(s.shading.n) - Vector3f::new(0.6, 0.0, -0.8)).length() < 1e-4,
        "{:?}",
        s.shading.n
    );
}

#[test]
fn normal_map_needs_rgb_channels() {
    let im = Image::from_f32(vec![0.5; 4], Point2i::new(2, 2), &["Y"]).unwrap();
    let dir = std::env::temp_dir().join(format!("rpbrt-material-{}-gray", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("g.pfm");
    im.write(&path, &ImageMetadata::default()).unwrap();
    let r = read_normal_map(&path, &Default::default());
    let _ = std::fs::remove_dir_all(&dir);
    // A one-channel PFM comes back as a single channel: no R, G, B.
    let err = r.unwrap_err();
    assert!(err.contains("R, G and B"), "{err}");
    assert!(read_normal_map(
        std::path::Path::new("/nonexistent/n.png"),
        &Default::default()
    )
    .is_err());
}

#[test]
fn force_diffuse_gives_lambertian_with_the_albedo() {
    let set = MaterialSet::new(vec![
        diffuse(0.3),
        Material::Conductor(ConductorMaterial {
            spectra: ConductorSpectra::Reflectance(stex(0.6)),
            roughness: smooth(),
            perturbation: ShadingPerturbation::default(),
        }),
    ]);
    let s = si();
    let mut s0 = s;
    let b = set.get_bsdf(0, &mut s0, &mut lambda()).unwrap();
    let d = MaterialSet::force_diffuse(&b, &s0, 0.5, Point2f::new(0.3, 0.6));
    assert!(matches!(d.bxdf, BxDF::Diffuse(_)));
    assert!(close(diffuse_value(&d), 0.3, 1e-4));

    let mut s1 = s;
    let b = set.get_bsdf(1, &mut s1, &mut lambda()).unwrap();
    let d = MaterialSet::force_diffuse(&b, &s1, 0.5, Point2f::new(0.3, 0.6));
    assert!(matches!(d.bxdf, BxDF::Diffuse(_)));
    assert!(d.flags().is_diffuse() && !d.flags().is_specular());
    assert!(close(diffuse_value(&d), 0.6, 1e-3), "{}", diffuse_value(&d));
}

#[test]
fn material_enum_stays_small() {
    eprintln!(
        "Material: {} bytes, Dielectric: {}, Diffuse: {}",
        std::mem::size_of::<Material>(),
        std::mem::size_of::<DielectricMaterial>(),
        std::mem::size_of::<DiffuseMaterial>()
    );
    assert!(
        std::mem::size_of::<Material>() <= 80,
        "{}",
        std::mem::size_of::<Material>()
    );
    let _ = BxDF::Diffuse(crate::bxdf::DiffuseBxDF::new(SampledSpectrum::new(0.0))).flags();
}
