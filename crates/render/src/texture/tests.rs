use super::noise::*;
use super::*;
use crate::rng::Rng;

use rpbrt_geometry::float::{Float, PI};
use rpbrt_geometry::transform::Transform;

fn ctx_at(p: Point3f, dpdx: Vector3f, dpdy: Vector3f) -> TextureEvalContext {
    TextureEvalContext {
        p,
        dpdx,
        dpdy,
        n: Normal3f::new(0.0, 0.0, 1.0),
        uv: Point2f::new(0.3, 0.6),
        dudx: 0.01,
        dudy: -0.02,
        dvdx: 0.03,
        dvdy: 0.015,
        face_index: 0,
    }
}

/// The context moved by `h` pixels along x (`axis` 0) or y (1).
fn shifted(c: &TextureEvalContext, h: Float, axis: usize) -> TextureEvalContext {
    let mut o = *c;
    let (dp, du, dv) = if axis == 0 {
        (c.dpdx, c.dudx, c.dvdx)
    } else {
        (c.dpdy, c.dudy, c.dvdy)
    };
    o.p = c.p + dp * h;
    o.uv = Point2f::new(c.uv.x + du * h, c.uv.y + dv * h);
    o
}

fn check_derivatives(m: &TextureMapping2D, c: &TextureEvalContext) {
    let tc = m.map(c);
    let h = 1e-2;
    for axis in 0..2 {
        let a = m.map(&shifted(c, h, axis)).st;
        let b = m.map(&shifted(c, -h, axis)).st;
        let ds = (a.x - b.x) / (2.0 * h);
        let dt = (a.y - b.y) / (2.0 * h);
        let (es, et) = if axis == 0 {
            (tc.dsdx, tc.dtdx)
        } else {
            (tc.dsdy, tc.dtdy)
        };
        let tol = |e: Float| 2e-3 + 1e-2 * e.abs();
        assert!(
            (ds - es).abs() < tol(es),
            "{m:?} axis {axis}: ds {ds} vs {es}"
        );
        assert!(
            (dt - et).abs() < tol(et),
            "{m:?} axis {axis}: dt {dt} vs {et}"
        );
    }
}

fn some_transform() -> Transform {
    Transform::translate(Vector3f::new(0.2, -0.1, 0.3))
        * Transform::rotate(30.0, Vector3f::new(1.0, 1.0, 0.0))
        * Transform::scale(1.5, 0.8, 1.2)
}

#[test]
fn uv_mapping_coordinates_and_derivatives() {
    let m = TextureMapping2D::UV {
        su: 2.0,
        sv: 3.0,
        du: 0.5,
        dv: -0.25,
    };
    let c = ctx_at(
        Point3f::new(0.0, 0.0, 0.0),
        Vector3f::default(),
        Vector3f::default(),
    );
    let tc = m.map(&c);
    assert!((tc.st.x - (2.0 * 0.3 + 0.5)).abs() < 1e-6);
    assert!((tc.st.y - (3.0 * 0.6 - 0.25)).abs() < 1e-6);
    assert_eq!(tc.dsdx, 2.0 * 0.01);
    assert_eq!(tc.dtdy, 3.0 * 0.015);
    check_derivatives(&m, &c);
}

#[test]
fn spherical_cylindrical_planar_derivatives_match_finite_differences() {
    let render_from_texture = some_transform();
    let tfr = render_from_texture.inverse();
    let mut rng = Rng::with_sequence(7);
    let maps = [
        TextureMapping2D::Spherical {
            texture_from_render: tfr,
        },
        TextureMapping2D::Cylindrical {
            texture_from_render: tfr,
        },
        TextureMapping2D::Planar {
            texture_from_render: tfr,
            vs: Vector3f::new(1.0, 0.5, 0.0),
            vt: Vector3f::new(0.0, 0.3, 2.0),
            ds: 0.1,
            dt: 0.7,
        },
    ];
    for m in &maps {
        let mut tested = 0;
        while tested < 40 {
            let mut r = || 2.0 * rng.uniform_float() - 1.0;
            let pt = Point3f::new(r(), r(), r());
            let dpdx = Vector3f::new(r(), r(), r()) * 0.01;
            let dpdy = Vector3f::new(r(), r(), r()) * 0.01;
            // Stay away from the poles and the φ seam, where the angles
            // are not differentiable.
            let (x2y2, rho) = (pt.x * pt.x + pt.y * pt.y, Vector3f::from(pt).length());
            if x2y2 < 0.09 || rho < 0.3 || (pt.y.abs() < 0.2 && pt.x < 0.0) {
                continue;
            }
            let c = ctx_at(
                render_from_texture.apply_point(pt),
                render_from_texture.apply_vector(dpdx),
                render_from_texture.apply_vector(dpdy),
            );
            check_derivatives(m, &c);
            tested += 1;
        }
    }
}

#[test]
fn mapping_values_follow_pbrt_conventions() {
    let id = Transform::identity();
    let c = ctx_at(
        Point3f::new(0.0, 1.0, 0.0),
        Vector3f::default(),
        Vector3f::default(),
    );
    let s = TextureMapping2D::Spherical {
        texture_from_render: id,
    }
    .map(&c);
    // θ = π/2, φ = π/2.
    assert!(
        (s.st.x - 0.5).abs() < 1e-6 && (s.st.y - 0.25).abs() < 1e-6,
        "{s:?}"
    );
    let cy = TextureMapping2D::Cylindrical {
        texture_from_render: id,
    }
    .map(&ctx_at(
        Point3f::new(1.0, 0.0, 0.7),
        Vector3f::default(),
        Vector3f::default(),
    ));
    assert!(
        (cy.st.x - 0.5).abs() < 1e-6 && (cy.st.y - 0.7).abs() < 1e-6,
        "{cy:?}"
    );
    let m3 = TextureMapping3D::new(&Transform::translate(Vector3f::new(1.0, 2.0, 3.0)));
    let t3 = m3.map(&ctx_at(
        Point3f::new(1.0, 2.0, 3.0),
        Vector3f::new(1.0, 0.0, 0.0),
        Vector3f::default(),
    ));
    assert_eq!(t3.p, Point3f::new(0.0, 0.0, 0.0));
    assert_eq!(t3.dpdx, Vector3f::new(1.0, 0.0, 0.0));
}

fn uv_ctx(u: Float, v: Float, d: Float) -> TextureEvalContext {
    TextureEvalContext {
        uv: Point2f::new(u, v),
        dudx: d,
        dvdy: d,
        ..Default::default()
    }
}

fn checker(mapping: CheckerboardMapping) -> FloatTexture {
    FloatTexture::Checkerboard(FloatCheckerboardTexture {
        mapping,
        tex1: Arc::new(FloatTexture::Constant(3.0)),
        tex2: Arc::new(FloatTexture::Constant(1.0)),
    })
}

#[test]
fn checkerboard_point_lookups_and_wide_footprints() {
    let t = checker(CheckerboardMapping::Planar(TextureMapping2D::default()));
    // (0,0) cell is even: tex1; neighbours along one axis: tex2.
    assert_eq!(t.evaluate(&uv_ctx(0.5, 0.5, 0.0)), 3.0);
    assert_eq!(t.evaluate(&uv_ctx(1.5, 0.5, 0.0)), 1.0);
    assert_eq!(t.evaluate(&uv_ctx(0.5, 1.5, 0.0)), 1.0);
    assert_eq!(t.evaluate(&uv_ctx(1.5, 1.5, 0.0)), 3.0);
    assert_eq!(t.evaluate(&uv_ctx(-0.5, 0.5, 0.0)), 1.0);
    // A small footprint well inside a square changes nothing.
    assert_eq!(t.evaluate(&uv_ctx(0.5, 0.5, 0.1)), 3.0);
    // Wide footprints tend to the mean, 2.
    let mut prev = Float::INFINITY;
    for d in [2.0, 8.0, 64.0] {
        let mut worst: Float = 0.0;
        for i in 0..50 {
            let u = 0.137 * i as Float;
            let v = 0.291 * i as Float;
            let x = t.evaluate(&uv_ctx(u, v, d));
            assert!((1.0..=3.0).contains(&x));
            worst = worst.max((x - 2.0).abs());
        }
        assert!(worst < prev.max(1e-3) + 1e-6, "footprint {d}: {worst}");
        prev = worst;
    }
    assert!(prev < 0.02, "{prev}");
    // The filtered value agrees with a brute-force box-triangle average at
    // a medium footprint.
    let d: Float = 0.4;
    for (u, v) in [(0.9, 0.3), (1.05, 2.95), (0.2, 0.8)] {
        let got = t.evaluate(&uv_ctx(u, v, d));
        let r = 1.5 * d;
        let (mut sum, mut wsum) = (0.0, 0.0);
        let n = 400;
        for i in 0..n {
            for j in 0..n {
                let x = -r + 2.0 * r * (i as Float + 0.5) / n as Float;
                let y = -r + 2.0 * r * (j as Float + 0.5) / n as Float;
                let w = (1.0 - x.abs() / r) * (1.0 - y.abs() / r);
                sum += w * t.evaluate(&uv_ctx(u + x, v + y, 0.0));
                wsum += w;
            }
        }
        assert!(
            (got - sum / wsum).abs() < 0.02,
            "({u},{v}): {got} vs {}",
            sum / wsum
        );
    }
}

#[test]
fn solid_checkerboard() {
    let t = checker(CheckerboardMapping::Solid(TextureMapping3D::new(
        &Transform::identity(),
    )));
    let at = |x: Float, y: Float, z: Float, d: Float| {
        t.evaluate(&ctx_at(
            Point3f::new(x, y, z),
            Vector3f::new(d, d, d),
            Vector3f::default(),
        ))
    };
    assert_eq!(at(0.5, 0.5, 0.5, 0.0), 3.0);
    assert_eq!(at(1.5, 0.5, 0.5, 0.0), 1.0);
    assert_eq!(at(1.5, 1.5, 0.5, 0.0), 3.0);
    assert_eq!(at(1.5, 1.5, -0.5, 0.0), 1.0);
    assert!((at(0.3, 0.7, 0.2, 100.0) - 2.0).abs() < 0.01);
}

#[test]
fn noise_is_bounded_deterministic_and_continuous() {
    let mut rng = Rng::with_sequence(11);
    let mut lo: Float = 0.0;
    let mut hi: Float = 0.0;
    for _ in 0..20000 {
        let p = Point3f::new(
            200.0 * rng.uniform_float() - 100.0,
            200.0 * rng.uniform_float() - 100.0,
            200.0 * rng.uniform_float() - 100.0,
        );
        let n = noise_p(p);
        assert_eq!(n, noise_p(p));
        lo = lo.min(n);
        hi = hi.max(n);
        // Lipschitz: the gradient is bounded (by well under 4).
        let q = p + Vector3f::new(1e-3, -1e-3, 1e-3);
        assert!((noise_p(q) - n).abs() < 4.0 * 1.8e-3, "{p:?}");
    }
    assert!(lo >= -1.0 && hi <= 1.0, "[{lo}, {hi}]");
    assert!(
        lo < -0.5 && hi > 0.5,
        "noise should use its range: [{lo}, {hi}]"
    );
    // Zero at lattice points, and continuous across cell faces.
    assert_eq!(noise(3.0, -7.0, 12.0), 0.0);
    let e = 1e-4;
    assert!((noise(2.0 - e, 0.3, 0.6) - noise(2.0 + e, 0.3, 0.6)).abs() < 1e-3);
    // Known values of pbrt's table (the dots texture depends on these).
    assert!(noise(0.5, 0.5, 0.5).abs() > 0.0);
    assert_eq!(noise(0.5, 0.5, 0.5), noise(256.5, 0.5, 0.5));
}

#[test]
fn fbm_and_turbulence_drop_octaves_for_wide_footprints() {
    let zero = Vector3f::default();
    assert_eq!(octave_count(zero, zero, 8), 8.0);
    // |dp| = 2^-k allows k − 1 octaves.
    let d = |k: i32| Vector3f::new((2.0 as Float).powi(-k), 0.0, 0.0);
    assert!((octave_count(d(4), zero, 8) - 3.0).abs() < 1e-5);
    assert!((octave_count(zero, d(6), 8) - 5.0).abs() < 1e-5);
    assert_eq!(octave_count(d(-3), zero, 8), 0.0);
    let p = Point3f::new(0.31, 1.7, -2.2);
    // Huge footprint: FBm vanishes, turbulence is the clamped average.
    assert_eq!(fbm(p, d(-3), zero, 0.5, 8), 0.0);
    let t = turbulence(p, d(-3), zero, 0.5, 8);
    let expect: Float = 0.2 + (0..8).map(|i| 0.2 * (0.5 as Float).powi(i)).sum::<Float>();
    assert!((t - expect).abs() < 1e-5, "{t} vs {expect}");
    // Exactly 3 octaves (partial part 0) equal the explicit sum.
    let manual: Float = (0..3)
        .map(|i| (0.5 as Float).powi(i) * noise_p(p * (1.99 as Float).powi(i)))
        .sum();
    assert!((fbm(p, d(4), zero, 0.5, 8) - manual).abs() < 1e-5);
    // Tiny footprints use every octave; results stay bounded.
    let full = fbm(p, zero, zero, 0.5, 8);
    assert!(full.abs() < 2.0);
    assert!(turbulence(p, zero, zero, 0.5, 8) >= 0.0);
}

#[test]
fn marble_wrinkled_windy_dots_are_finite() {
    let m3 = TextureMapping3D::new(&Transform::identity());
    let marble = MarbleTexture {
        mapping: m3.clone(),
        octaves: 8,
        omega: 0.5,
        scale: 3.0,
        variation: 0.2,
    };
    let wrinkled = WrinkledTexture {
        mapping: m3.clone(),
        omega: 0.5,
        octaves: 8,
    };
    let windy = WindyTexture { mapping: m3 };
    let dots = FloatDotsTexture {
        mapping: TextureMapping2D::default(),
        outside: Arc::new(FloatTexture::Constant(0.0)),
        inside: Arc::new(FloatTexture::Constant(1.0)),
    };
    let lambda = SampledWavelengths::sample_visible(0.4);
    let (mut inside, mut outside) = (0, 0);
    for i in 0..2000 {
        let f = i as Float * 0.0137;
        let c = ctx_at(
            Point3f::new(f.sin() * 5.0, f * 0.7, (3.0 * f).cos()),
            Vector3f::new(1e-3, 0.0, 0.0) * (1.0 + f),
            Vector3f::new(0.0, 1e-3, 0.0),
        );
        let rgb = marble.rgb(&c);
        for v in [rgb.r, rgb.g, rgb.b] {
            assert!(v.is_finite() && (0.0..=1.0).contains(&v), "{rgb:?}");
        }
        let s = marble.evaluate(&c, &lambda);
        assert!(!s.has_nan() && s.min_component_value() >= 0.0);
        let w = wrinkled.evaluate(&c);
        assert!(w.is_finite() && w >= 0.0);
        assert!(windy.evaluate(&c).is_finite());
        let mut uvc = c;
        uvc.uv = Point2f::new(f * 3.0, f * 1.3);
        if dots.evaluate(&uvc) == 1.0 {
            inside += 1;
        } else {
            outside += 1;
        }
    }
    assert!(inside > 100 && outside > 100, "{inside} / {outside}");
}

#[test]
fn mix_scale_bilerp_directionmix() {
    let c = |v| Arc::new(FloatTexture::Constant(v));
    let ctx = uv_ctx(0.25, 0.75, 0.0);
    let mix = FloatTexture::Mix(FloatMixTexture {
        tex1: c(2.0),
        tex2: c(4.0),
        amount: c(0.25),
    });
    assert_eq!(mix.evaluate(&ctx), 2.5);
    let scaled = FloatTexture::Scaled(FloatScaledTexture {
        tex: c(2.0),
        scale: c(3.0),
    });
    assert_eq!(scaled.evaluate(&ctx), 6.0);
    let bilerp = FloatTexture::Bilerp(FloatBilerpTexture {
        mapping: TextureMapping2D::default(),
        v00: 0.0,
        v01: 1.0,
        v10: 2.0,
        v11: 4.0,
    });
    // (1-s)(1-t)*0 + s(1-t)*2 + (1-s)t*1 + st*4 at s = 0.25, t = 0.75.
    let expect = 0.25 * 0.25 * 2.0 + 0.75 * 0.75 * 1.0 + 0.25 * 0.75 * 4.0;
    assert!((bilerp.evaluate(&ctx) - expect).abs() < 1e-6);
    let dm = FloatTexture::DirectionMix(FloatDirectionMixTexture {
        tex1: c(1.0),
        tex2: c(0.0),
        dir: Vector3f::new(0.0, 0.6, 0.8),
    });
    let mut nctx = ctx;
    nctx.n = Normal3f::new(0.0, 0.0, -1.0);
    assert!((dm.evaluate(&nctx) - 0.8).abs() < 1e-6);
}

#[test]
fn texture_enum_sizes() {
    // Textures live behind Arc; keep the enums from growing without notice.
    assert!(
        std::mem::size_of::<FloatTexture>() <= 256,
        "{}",
        std::mem::size_of::<FloatTexture>()
    );
    assert!(
        std::mem::size_of::<SpectrumTexture>() <= 256,
        "{}",
        std::mem::size_of::<SpectrumTexture>()
    );
}

#[test]
fn spherical_mapping_at_the_equator() {
    // Spherical mapping of the +x axis at the equator: s = 1/2, t = 0.
    let tc = TextureMapping2D::Spherical {
        texture_from_render: Transform::identity(),
    }
    .map(&ctx_at(
        Point3f::new(2.0, 0.0, 0.0),
        Vector3f::default(),
        Vector3f::default(),
    ));
    assert!((tc.st.x * PI - PI / 2.0).abs() < 1e-6 && tc.st.y.abs() < 1e-6);
}
