//! Tests of the grid media (`uniformgrid`, `rgbgrid`, `cloud`): the
//! sampled grid's reconstruction, majorants that bound the extinction,
//! transmittance against quadrature and against the homogeneous medium,
//! transformed media, emission, and the collision guard (creation from
//! scene text is tested in `scene/tests/media.rs`).

use super::*;
use crate::spectrum::{
    spectrum_to_photometric, BlackbodySpectrum, RgbColorSpace, RgbIlluminantSpectrum,
    RgbUnboundedSpectrum, Spectrum, RGB,
};
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::Bounds3f;

fn lambda(u: Float) -> SampledWavelengths {
    SampledWavelengths::sample_visible(u)
}

fn rand_point(rng: &mut Rng, lo: Float, hi: Float) -> Point3f {
    let mut c = || lo + (hi - lo) * rng.uniform_float();
    Point3f::new(c(), c(), c())
}

fn rand_dir(rng: &mut Rng) -> Vector3f {
    crate::sampling::sample_uniform_sphere(Point2f::new(rng.uniform_float(), rng.uniform_float()))
}

fn unit_box() -> Bounds3f {
    Bounds3f::new(Point3f::new(0.0, 0.0, 0.0), Point3f::new(1.0, 1.0, 1.0))
}

/// A density grid of random values in `[0, 1)`, with a few spikes of 5.
fn random_density(rng: &mut Rng, n: [i32; 3]) -> SampledGrid<Float> {
    let count = (n[0] * n[1] * n[2]) as usize;
    let values = (0..count)
        .map(|i| {
            if i % 17 == 3 {
                5.0
            } else {
                rng.uniform_float()
            }
        })
        .collect();
    SampledGrid::new(values, n[0], n[1], n[2]).unwrap()
}

fn grid_parts(density: SampledGrid<Float>, bounds: Bounds3f, xf: Transform) -> GridMediumParts {
    GridMediumParts {
        bounds,
        render_from_medium: xf,
        sigma_a: Spectrum::constant(0.4),
        sigma_s: Spectrum::constant(1.1),
        sigma_scale: 2.0,
        g: 0.3,
        density,
        temperature: None,
        temperature_scale: 1.0,
        temperature_offset: 0.0,
        le: Spectrum::constant(0.0),
        le_scale: SampledGrid::new(vec![1.0], 1, 1, 1).unwrap(),
    }
}

fn random_rgb_grid(rng: &mut Rng, n: [i32; 3], max: Float) -> SampledGrid<RgbUnboundedSpectrum> {
    let cs = RgbColorSpace::srgb();
    let count = (n[0] * n[1] * n[2]) as usize;
    let values = (0..count)
        .map(|_| {
            let mut c = || max * rng.uniform_float();
            RgbUnboundedSpectrum::new(cs, RGB::new(c(), c(), c()))
        })
        .collect();
    SampledGrid::new(values, n[0], n[1], n[2]).unwrap()
}

fn rgb_medium(rng: &mut Rng, xf: Transform) -> RgbGridMedium {
    let n = [5, 3, 6];
    RgbGridMedium::new(RgbGridMediumParts {
        bounds: Bounds3f::new(Point3f::new(-1.0, 0.0, 2.0), Point3f::new(1.0, 0.5, 3.0)),
        render_from_medium: xf,
        g: 0.0,
        sigma_a: Some(random_rgb_grid(rng, n, 2.0)),
        sigma_s: Some(random_rgb_grid(rng, n, 4.0)),
        sigma_scale: 1.5,
        le: None,
        le_scale: 1.0,
    })
}

fn cloud_parts(xf: Transform) -> CloudMediumParts {
    CloudMediumParts {
        bounds: Bounds3f::new(Point3f::new(-1.0, -0.5, -1.0), Point3f::new(1.0, 1.5, 1.0)),
        render_from_medium: xf,
        sigma_a: Spectrum::constant(0.5),
        sigma_s: Spectrum::constant(3.0),
        sigma_scale: 1.0,
        g: 0.0,
        density: 2.0,
        wispiness: 1.0,
        frequency: 3.0,
    }
}

fn cloud_medium(xf: Transform) -> CloudMedium {
    CloudMedium::new(cloud_parts(xf))
}

fn some_transform() -> Transform {
    Transform::translate(Vector3f::new(0.5, -2.0, 1.0))
        * Transform::rotate(37.0, Vector3f::new(1.0, 2.0, -0.5))
        * Transform::scale(2.0, 0.5, 3.0)
}

#[test]
fn sampled_grid_is_exact_at_sample_centres_and_linear_between() {
    let mut rng = Rng::new(1, 0);
    let (nx, ny, nz) = (3, 4, 2);
    let grid = random_density(&mut rng, [nx, ny, nz]);
    let centre = |x: i32, y: i32, z: i32| {
        Point3f::new(
            (x as Float + 0.5) / nx as Float,
            (y as Float + 0.5) / ny as Float,
            (z as Float + 0.5) / nz as Float,
        )
    };
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let v = grid.sample(x, y, z);
                assert!((grid.lookup(centre(x, y, z)) - v).abs() <= 1e-6 * v.max(1.0));
            }
        }
    }
    // Linear along each axis between neighbouring centres.
    for _ in 0..200 {
        let (x, y, z) = (
            (rng.uniform_float() * (nx - 1) as Float) as i32,
            (rng.uniform_float() * (ny - 1) as Float) as i32,
            (rng.uniform_float() * (nz - 1) as Float) as i32,
        );
        let t = rng.uniform_float();
        let a = centre(x, y, z);
        for (axis, b) in [
            centre(x + 1, y, z),
            centre(x, y + 1, z),
            centre(x, y, z + 1),
        ]
        .into_iter()
        .enumerate()
        {
            let p = a + (b - a) * t;
            let (va, vb) = (grid.lookup(a), grid.lookup(b));
            let expected = va * (1.0 - t) + vb * t;
            assert!((grid.lookup(p) - expected).abs() < 1e-5, "axis {axis}");
        }
    }
    // Trilinear inside a cell: the product of the axis weights.
    let p = Point3f::new(0.5, 0.45, 0.6);
    let ps = [p.x * 3.0 - 0.5, p.y * 4.0 - 0.5, p.z * 2.0 - 0.5];
    let (i, j, k) = (
        ps[0].floor() as i32,
        ps[1].floor() as i32,
        ps[2].floor() as i32,
    );
    let d = [ps[0] - i as Float, ps[1] - j as Float, ps[2] - k as Float];
    let mut expected = 0.0;
    for c in 0..8 {
        let (a, b, e) = (c & 1, (c >> 1) & 1, (c >> 2) & 1);
        let w = [(a, 0), (b, 1), (e, 2)]
            .iter()
            .map(|&(bit, ax)| if bit == 1 { d[ax] } else { 1.0 - d[ax] })
            .product::<Float>();
        expected += w * grid.sample(i + a, j + b, k + e);
    }
    assert!((grid.lookup(p) - expected).abs() < 1e-5);
    // Outside the lattice the samples are zero: half the edge value on a
    // face, nothing far away or at a NaN.
    let on_face = Point3f::new(0.0, centre(0, 1, 1).y, centre(0, 1, 1).z);
    assert!((grid.lookup(on_face) - 0.5 * grid.sample(0, 1, 1)).abs() < 1e-6);
    assert_eq!(grid.lookup(Point3f::new(1.5, 0.5, 0.5)), 0.0);
    assert_eq!(grid.lookup(Point3f::new(-1e30, 1e30, 0.5)), 0.0);
    assert_eq!(grid.lookup(Point3f::new(Float::NAN, 0.5, 0.5)), 0.0);
    assert!(SampledGrid::new(vec![1.0; 5], 2, 2, 1).is_none());
    assert!(SampledGrid::new(vec![1.0; 4], 2, 2, 0).is_none());
}

#[test]
fn max_value_bounds_every_lookup_in_its_region() {
    let mut rng = Rng::new(2, 0);
    let grid = random_density(&mut rng, [7, 5, 4]);
    for _ in 0..300 {
        let (a, b) = (
            rand_point(&mut rng, 0.0, 1.0),
            rand_point(&mut rng, 0.0, 1.0),
        );
        let region = Bounds3f::new(a, b);
        let max = grid.max_value(&region);
        for _ in 0..20 {
            let t = rand_point(&mut rng, 0.0, 1.0);
            let v = grid.lookup(region.lerp(t));
            assert!(v <= max * (1.0 + 1e-5), "{v} > {max} in {region:?}");
        }
    }
}

/// Points in voxel `(x, y, z)` of a `res³` grid over `[0, 1]³`: random ones,
/// its corners, and points on and just inside its faces.
fn voxel_points(rng: &mut Rng, res: i32, v: [i32; 3]) -> Vec<Point3f> {
    let r = res as Float;
    let lo = v.map(|i| i as Float / r);
    let at = |f: [Float; 3]| Point3f::new(lo[0] + f[0] / r, lo[1] + f[1] / r, lo[2] + f[2] / r);
    let mut pts: Vec<Point3f> = (0..8)
        .map(|c| {
            at([
                (c & 1) as Float,
                ((c >> 1) & 1) as Float,
                ((c >> 2) & 1) as Float,
            ])
        })
        .collect();
    for _ in 0..12 {
        let mut f = [
            rng.uniform_float(),
            rng.uniform_float(),
            rng.uniform_float(),
        ];
        pts.push(at(f));
        // The same point pushed onto a face, and just inside it.
        let axis = (rng.uniform_float() * 3.0) as usize % 3;
        f[axis] = if rng.uniform_float() < 0.5 { 0.0 } else { 1.0 };
        pts.push(at(f));
        f[axis] = (f[axis] - 1e-4).abs();
        pts.push(at(f));
    }
    pts
}

#[test]
fn grid_majorants_bound_the_density_in_every_voxel() {
    let mut rng = Rng::new(3, 0);
    let bounds = Bounds3f::new(Point3f::new(-2.0, 0.0, 1.0), Point3f::new(3.0, 1.0, 1.5));
    for n in [[1, 1, 1], [10, 7, 5], [33, 16, 40]] {
        let m = GridMedium::new(grid_parts(
            random_density(&mut rng, n),
            bounds,
            Transform::identity(),
        ));
        let maj = m.majorant_grid();
        assert_eq!(maj.res, [GRID_MAJORANT_RES; 3]);
        for z in 0..GRID_MAJORANT_RES {
            for y in 0..GRID_MAJORANT_RES {
                for x in 0..GRID_MAJORANT_RES {
                    let bound = maj.lookup(x, y, z);
                    for p in voxel_points(&mut rng, GRID_MAJORANT_RES, [x, y, z]) {
                        let d = m.density(p);
                        assert!(
                            d <= bound * (1.0 + 1e-5),
                            "{n:?} voxel ({x},{y},{z}): {d} > {bound}"
                        );
                    }
                }
            }
        }
    }
    // The RGB grid's majorant bounds σt at any wavelength.
    let m = rgb_medium(&mut rng, Transform::identity());
    let maj = m.majorant_grid();
    let b = m.bounds();
    for z in 0..RGB_GRID_MAJORANT_RES {
        for y in 0..RGB_GRID_MAJORANT_RES {
            for x in 0..RGB_GRID_MAJORANT_RES {
                let bound = maj.lookup(x, y, z);
                for p in voxel_points(&mut rng, RGB_GRID_MAJORANT_RES, [x, y, z]) {
                    let l = lambda(rng.uniform_float());
                    let mp = m.sample_point(b.lerp(p), &l);
                    let st = mp.sigma_a + mp.sigma_s;
                    assert!(st.max_component_value() <= bound * (1.0 + 1e-5) + 1e-6);
                }
            }
        }
    }
}

/// Runs delta tracking along many random rays through `medium` (origins
/// inside and outside `region`, a render-space box around it) and checks at
/// every tentative collision that σt ≤ σmaj at every wavelength. Returns
/// the number of collisions seen.
fn check_majorant_along_rays(medium: &Medium, region: (Point3f, Point3f), seed: u64) -> usize {
    let mut rng = Rng::new(seed, 0);
    let mut collisions = 0;
    for i in 0..2000 {
        let o = Point3f::new(
            region.0.x + (region.1.x - region.0.x) * rng.uniform_float(),
            region.0.y + (region.1.y - region.0.y) * rng.uniform_float(),
            region.0.z + (region.1.z - region.0.z) * rng.uniform_float(),
        );
        // Directions of assorted lengths; every fourth ray unbounded.
        let d = rand_dir(&mut rng) * (0.5 + 2.0 * rng.uniform_float());
        let t_max = if i % 4 == 0 {
            Float::INFINITY
        } else {
            10.0 * rng.uniform_float()
        };
        let ray = Ray::new(o, d);
        let l = lambda(rng.uniform_float());
        let u = rng.uniform_float();
        sample_t_maj(
            medium,
            &ray,
            t_max,
            u,
            &mut rng,
            &l,
            |p, mp, sigma_maj, _, _| {
                collisions += 1;
                let st = mp.sigma_a + mp.sigma_s;
                for k in 0..crate::spectrum::N_SPECTRUM_SAMPLES {
                    assert!(
                        st[k] <= sigma_maj[k] * (1.0 + 1e-4) + 1e-5,
                        "σt {} > σmaj {} at {p:?}",
                        st[k],
                        sigma_maj[k]
                    );
                }
                true
            },
        );
    }
    collisions
}

#[test]
fn majorants_hold_along_rays_for_every_grid_medium() {
    let mut rng = Rng::new(4, 0);
    let bounds = Bounds3f::new(Point3f::new(-1.0, -1.0, -1.0), Point3f::new(1.0, 2.0, 0.5));
    for xf in [Transform::identity(), some_transform()] {
        let grid = Medium::UniformGrid(Box::new(GridMedium::new(grid_parts(
            random_density(&mut rng, [9, 13, 6]),
            bounds,
            xf,
        ))));
        let rb = xf.apply_bounds(&bounds);
        let region = (
            rb.p_min - Vector3f::new(1.0, 1.0, 1.0),
            rb.p_max + Vector3f::new(1.0, 1.0, 1.0),
        );
        let n = check_majorant_along_rays(&grid, region, 5);
        assert!(n > 1000, "{n} collisions");

        let rgb = Medium::RgbGrid(Box::new(rgb_medium(&mut rng, xf)));
        let Medium::RgbGrid(m) = &rgb else {
            unreachable!()
        };
        let rb = xf.apply_bounds(&m.bounds());
        let region = (
            rb.p_min - Vector3f::new(0.5, 0.5, 0.5),
            rb.p_max + Vector3f::new(0.5, 0.5, 0.5),
        );
        let n = check_majorant_along_rays(&rgb, region, 6);
        assert!(n > 1000, "{n} collisions");

        let cloud = Medium::Cloud(Box::new(cloud_medium(xf)));
        let Medium::Cloud(m) = &cloud else {
            unreachable!()
        };
        let rb = xf.apply_bounds(&m.bounds());
        let n = check_majorant_along_rays(&cloud, (rb.p_min, rb.p_max), 7);
        assert!(n > 1000, "{n} collisions");
    }
}

/// exp(−∫σt) along `ray` over `[0, t_max]` (unit direction) at the first
/// wavelength, by the midpoint rule, for a medium in `bounds` (render
/// space). Only the stretch inside the bounds counts: a grid's
/// interpolated density also reaches half a cell beyond its faces, where
/// tracking never looks.
fn quadrature_transmittance(
    m: &Medium,
    bounds: &Bounds3f,
    ray: &Ray,
    t_max: Float,
    l: &SampledWavelengths,
) -> f64 {
    let Some((t0, t1)) = bounds.intersect_p(ray.o, ray.d, t_max) else {
        return 1.0;
    };
    let steps = 4000;
    let dt = (t1 - t0) as f64 / steps as f64;
    let mut tau = 0.0f64;
    for i in 0..steps {
        let p = ray.at((t0 as f64 + (i as f64 + 0.5) * dt) as Float);
        let mp = m.sample_point(p, l);
        tau += (mp.sigma_a[0] + mp.sigma_s[0]) as f64 * dt;
    }
    (-tau).exp()
}

/// The ratio-tracking estimate of the transmittance at the first
/// wavelength, averaged over `n` walks; the estimate also reports whether
/// any collision was sampled.
fn ratio_tracking(
    m: &Medium,
    ray: &Ray,
    t_max: Float,
    l: &SampledWavelengths,
    n: usize,
    seed: u64,
) -> (f64, f64, bool) {
    let mut rng = Rng::new(seed, 0);
    let (mut sum, mut sum2, mut any) = (0.0f64, 0.0f64, false);
    for _ in 0..n {
        let mut tr = 1.0f64;
        let u = rng.uniform_float();
        sample_t_maj(m, ray, t_max, u, &mut rng, l, |_, mp, sigma_maj, _, _| {
            any = true;
            let sigma_n = sigma_maj[0] - (mp.sigma_a[0] + mp.sigma_s[0]);
            tr *= (sigma_n / sigma_maj[0]) as f64;
            true
        });
        sum += tr;
        sum2 += tr * tr;
    }
    let mean = sum / n as f64;
    let std_err = ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
    (mean, std_err, any)
}

#[test]
fn transmittance_matches_quadrature_and_the_homogeneous_medium() {
    let l = lambda(0.3);
    let bounds = Bounds3f::new(Point3f::new(-1.0, -1.0, -1.0), Point3f::new(1.0, 1.0, 1.0));
    // A constant 8³ grid equals a homogeneous medium more than half a cell
    // (0.125) away from the faces, where its samples fade towards zero.
    let constant = SampledGrid::new(vec![0.5; 512], 8, 8, 8).unwrap();
    let parts = grid_parts(constant, bounds, Transform::identity());
    // σt = density × scale × (σa + σs), the homogeneous medium's 0.4 + 1.1.
    let sigma_t: f64 = 0.5 * 2.0 * (0.4 + 1.1);
    let grid = Medium::UniformGrid(Box::new(GridMedium::new(parts)));
    let homogeneous = Medium::Homogeneous(HomogeneousMedium::new(
        &Spectrum::constant(0.4),
        &Spectrum::constant(1.1),
        1.0,
        &Spectrum::constant(0.0),
        1.0,
        0.0,
    ));
    let inner = Ray::new(Point3f::new(-0.8, 0.1, -0.2), Vector3f::new(1.0, 0.3, 0.2));
    let t_inner = 1.4;
    let expected = (-sigma_t * t_inner as f64 * inner.d.length() as f64).exp();
    let (est, se, _) = ratio_tracking(&grid, &inner, t_inner, &l, 20000, 8);
    assert!(
        (est - expected).abs() < 4.0 * se + 1e-3,
        "grid {est} ± {se} vs {expected}"
    );
    let (hom, hse, _) = ratio_tracking(&homogeneous, &inner, t_inner, &l, 20000, 9);
    assert!(
        (hom - expected).abs() < 4.0 * hse + 1e-3,
        "homogeneous {hom} vs {expected}"
    );
    let unit_inner = Ray::new(inner.o, inner.d / inner.d.length());
    let q = quadrature_transmittance(&grid, &bounds, &unit_inner, t_inner * inner.d.length(), &l);
    assert!((q - expected).abs() < 1e-4, "quadrature {q} vs {expected}");

    // Rays through the whole box, from inside it, and unbounded, in a
    // random grid, against quadrature.
    let mut rng = Rng::new(10, 0);
    let mut parts = grid_parts(
        random_density(&mut rng, [6, 5, 7]),
        bounds,
        Transform::identity(),
    );
    parts.sigma_scale = 0.5;
    let random = Medium::UniformGrid(Box::new(GridMedium::new(parts)));
    let rays = [
        (
            Point3f::new(-3.0, 0.2, 0.1),
            Vector3f::new(1.0, 0.05, -0.1),
            6.0,
        ),
        (
            Point3f::new(0.2, -0.3, 0.4),
            Vector3f::new(-0.3, 0.8, 0.5),
            5.0,
        ),
        (
            Point3f::new(0.9, 0.9, -2.5),
            Vector3f::new(-0.2, -0.3, 1.0),
            Float::INFINITY,
        ),
    ];
    for (k, (o, d, t_max)) in rays.into_iter().enumerate() {
        let ray = Ray::new(o, d.normalize());
        let (est, se, any) = ratio_tracking(&random, &ray, t_max, &l, 20000, 11 + k as u64);
        assert!(any);
        let q = quadrature_transmittance(&random, &bounds, &ray, t_max, &l);
        assert!(q > 0.01 && q < 0.99, "ray {k}: {q}");
        assert!(
            (est - q).abs() < 4.0 * se + 2e-3,
            "ray {k}: {est} ± {se} vs {q}"
        );
    }
    // A ray that misses the box sees no collision and no attenuation.
    let miss = Ray::new(Point3f::new(-3.0, 2.0, 0.0), Vector3f::new(1.0, 0.0, 0.0));
    assert!(random.majorant_segments(&miss, 10.0, &l).is_empty());
    let mut rng = Rng::new(12, 0);
    let t = sample_t_maj(&random, &miss, 10.0, 0.5, &mut rng, &l, |_, _, _, _, _| {
        panic!("collision")
    });
    assert_eq!(t, SampledSpectrum::new(1.0));
}

#[test]
fn transformed_media_find_their_bounds() {
    let xf = some_transform();
    let bounds = Bounds3f::new(Point3f::new(0.0, -1.0, 0.5), Point3f::new(1.0, 1.0, 2.0));
    let mut rng = Rng::new(13, 0);
    let m = GridMedium::new(grid_parts(random_density(&mut rng, [4, 4, 4]), bounds, xf));
    let medium = Medium::UniformGrid(Box::new(m.clone()));
    let l = lambda(0.5);
    for _ in 0..200 {
        // A chord of the medium-space box, extended, mapped to render space.
        let a = bounds.lerp(rand_point(&mut rng, 0.0, 1.0));
        let b = bounds.lerp(rand_point(&mut rng, 0.0, 1.0));
        if a.distance(b) < 0.1 {
            continue;
        }
        // From far outside (the box is at most 20 across in render
        // space), with a direction of length 2.
        let (ra, rb) = (xf.apply_point(a), xf.apply_point(b));
        let dir = (rb - ra).normalize();
        let o = ra - dir * 30.0;
        let ray = Ray::new(o, dir * 2.0);
        let segs = medium.majorant_segments(&ray, 40.0, &l);
        assert!(!segs.is_empty());
        let unit = Ray::new(o, dir);
        let to_medium = |t: Float| xf.apply_inverse_point(unit.at(t));
        let (entry, exit) = (
            to_medium(segs[0].t_min),
            to_medium(segs.last().unwrap().t_max),
        );
        // Entry and exit lie on the box's surface.
        for p in [entry, exit] {
            let off = bounds.offset(p);
            let on_face = (0..3).any(|i| off[i].abs() < 1e-3 || (off[i] - 1.0).abs() < 1e-3);
            let inside = (0..3).all(|i| off[i] > -1e-3 && off[i] < 1.0 + 1e-3);
            assert!(on_face && inside, "{p:?} off {off:?}");
        }
        // Properties at a render-space point are those of its medium point.
        let pm = bounds.lerp(rand_point(&mut rng, 0.0, 1.0));
        let mp = medium.sample_point(xf.apply_point(pm), &l);
        let d = m.density(Point3f::from(bounds.offset(pm)));
        let expected = 2.0 * 0.4 * d;
        assert!((mp.sigma_a[0] - expected).abs() <= 1e-4 * expected.max(1.0));
    }
    // Moved away, the box is no longer where it was in medium space, and
    // is where it went.
    let moved =
        Transform::translate(Vector3f::new(10.0, 0.0, 0.0)) * Transform::scale(2.0, 2.0, 2.0);
    let m = Medium::UniformGrid(Box::new(GridMedium::new(grid_parts(
        random_density(&mut rng, [4, 4, 4]),
        bounds,
        moved,
    ))));
    let old_place = Ray::new(Point3f::new(0.5, 0.0, -5.0), Vector3f::new(0.0, 0.0, 1.0));
    assert!(bounds
        .intersect_p(old_place.o, old_place.d, 100.0)
        .is_some());
    assert!(m.majorant_segments(&old_place, 100.0, &l).is_empty());
    let new_place = Ray::new(Point3f::new(11.0, 0.0, -5.0), Vector3f::new(0.0, 0.0, 1.0));
    let segs = m.majorant_segments(&new_place, 100.0, &l);
    // z from 2·0.5 = 1 to 2·2 = 4.
    assert!((segs[0].t_min - 6.0).abs() < 1e-4 && (segs.last().unwrap().t_max - 9.0).abs() < 1e-3);
}

#[test]
fn cloud_density_stays_in_the_unit_interval() {
    let mut rng = Rng::new(14, 0);
    for (density, wispiness, frequency) in [
        (1.0, 1.0, 5.0),
        (40.0, 3.0, 11.0),
        (-2.0, 0.0, 1.0),
        (0.3, 0.0, 5.0),
    ] {
        let m = CloudMedium::new(CloudMediumParts {
            density,
            wispiness,
            frequency,
            ..cloud_parts(Transform::identity())
        });
        let (mut between, n) = (0, 2000);
        for _ in 0..n {
            let d = m.density(rand_point(&mut rng, -1.5, 2.0));
            assert!((0.0..=1.0).contains(&d), "{d}");
            between += (d > 0.0 && d < 1.0) as usize;
        }
        // Below y = 0 the cloud is solid.
        assert_eq!(m.density(Point3f::new(0.3, -0.6, 0.2)), 1.0);
        if density > 0.0 {
            assert!(
                between > 50,
                "({density}, {wispiness}, {frequency}): {between} of {n}"
            );
        }
        assert_eq!(m.density(Point3f::new(Float::NAN, 0.5, 0.5)), 0.0);
    }
}

#[test]
fn grid_emission_from_spectrum_scale_grid_and_temperature() {
    let l = lambda(0.2);
    let le = Spectrum::constant(3.0);
    let norm = 1.0 / spectrum_to_photometric(&le);
    let mut parts = grid_parts(
        SampledGrid::new(vec![0.0, 1.0], 2, 1, 1).unwrap(),
        unit_box(),
        Transform::identity(),
    );
    parts.le = le.clone();
    parts.le_scale = SampledGrid::new(vec![2.0 * norm, 4.0 * norm], 2, 1, 1).unwrap();
    let m = GridMedium::new(parts.clone());
    assert!(m.is_emissive());
    // At the first sample's centre: zero density, yet emission (pbrt-v4
    // evaluates Le regardless of density).
    let mp = m.sample_point(Point3f::new(0.25, 0.5, 0.5), &l);
    assert_eq!(mp.sigma_a[0], 0.0);
    assert!((mp.le[0] - 3.0 * 2.0 * norm).abs() < 1e-4 * mp.le[0]);
    let mp = m.sample_point(Point3f::new(0.5, 0.5, 0.5), &l);
    assert!((mp.le[0] - 3.0 * 3.0 * norm).abs() < 1e-4 * mp.le[0]);

    // A temperature grid glows as a normalised blackbody above 100 K.
    parts.le = Spectrum::constant(0.0);
    parts.le_scale = SampledGrid::new(vec![1.5], 1, 1, 1).unwrap();
    parts.temperature = Some(SampledGrid::new(vec![1200.0, 80.0], 2, 1, 1).unwrap());
    parts.temperature_offset = 200.0;
    parts.temperature_scale = 2.0;
    let m = GridMedium::new(parts);
    assert!(m.is_emissive());
    // The 1×1×1 scale grid is 1.5 at the centre only: 0.75 on a face.
    let mp = m.sample_point(Point3f::new(0.25, 0.5, 0.5), &l);
    let scale = SampledGrid::new(vec![1.5], 1, 1, 1)
        .unwrap()
        .lookup(Point3f::new(0.25, 0.5, 0.5));
    assert!((scale - 1.5 * 0.75).abs() < 1e-5, "{scale}");
    let bb = BlackbodySpectrum::new((1200.0 - 200.0) * 2.0);
    for k in 0..4 {
        let e = scale * bb.evaluate(l.lambda[k]);
        assert!(
            (mp.le[k] - e).abs() <= 1e-4 * e.max(1e-3),
            "{} vs {e}",
            mp.le[k]
        );
    }
    // (80 − 200)·2 < 100 K: dark.
    assert!(m
        .sample_point(Point3f::new(0.75, 0.5, 0.5), &l)
        .le
        .is_black());
}

#[test]
fn rgb_grid_samples_equal_their_rgb_spectra() {
    let cs = RgbColorSpace::get("aces2065-1").unwrap();
    let l = lambda(0.6);
    let rgb_a = RGB::new(0.2, 1.5, 0.7);
    let rgb_s = RGB::new(3.0, 0.1, 0.0);
    let rgb_le = RGB::new(0.5, 0.25, 2.0);
    let one = |c: RGB| SampledGrid::new(vec![RgbUnboundedSpectrum::new(cs, c)], 1, 1, 1).unwrap();
    let m = RgbGridMedium::new(RgbGridMediumParts {
        bounds: unit_box(),
        render_from_medium: Transform::identity(),
        g: 0.0,
        sigma_a: Some(one(rgb_a)),
        sigma_s: Some(one(rgb_s)),
        sigma_scale: 2.0,
        le: Some(RgbEmissionGrid {
            grid: one(rgb_le),
            illuminant: cs.illuminant.clone(),
        }),
        le_scale: 3.0,
    });
    assert!(m.is_emissive());
    let mp = m.sample_point(Point3f::new(0.5, 0.5, 0.5), &l);
    let a = Spectrum::RgbUnbounded(RgbUnboundedSpectrum::new(cs, rgb_a)).sample(&l) * 2.0;
    let s = Spectrum::RgbUnbounded(RgbUnboundedSpectrum::new(cs, rgb_s)).sample(&l) * 2.0;
    let le = RgbIlluminantSpectrum::new(cs, rgb_le).sample(&l) * 3.0;
    for k in 0..4 {
        assert!((mp.sigma_a[k] - a[k]).abs() <= 1e-5 * a[k].max(1.0));
        assert!((mp.sigma_s[k] - s[k]).abs() <= 1e-5 * s[k].max(1.0));
        assert!(
            (mp.le[k] - le[k]).abs() <= 1e-4 * le[k].max(1.0),
            "{} vs {}",
            mp.le[k],
            le[k]
        );
    }
    // An absent coefficient grid is 1 everywhere (times the scale).
    let m = RgbGridMedium::new(RgbGridMediumParts {
        bounds: unit_box(),
        render_from_medium: Transform::identity(),
        g: 0.0,
        sigma_a: None,
        sigma_s: Some(one(rgb_s)),
        sigma_scale: 2.0,
        le: None,
        le_scale: 1.0,
    });
    assert!(!m.is_emissive());
    let mp = m.sample_point(Point3f::new(0.9, 0.1, 0.5), &l);
    assert_eq!(mp.sigma_a, SampledSpectrum::new(2.0));
    assert!(mp.le.is_black());
    // Its majorant: 2 × (1 + max of the σs spectrum).
    let max_s = RgbUnboundedSpectrum::new(cs, rgb_s).max_value();
    assert!((m.majorant_grid().lookup(3, 4, 5) - 2.0 * (1.0 + max_s)).abs() < 1e-5);
}

#[test]
fn medium_enum_stays_small() {
    assert!(
        std::mem::size_of::<Medium>() <= 112,
        "{}",
        std::mem::size_of::<Medium>()
    );
}

#[test]
fn a_majorant_far_above_the_density_cannot_make_tracking_hang() {
    // A spike of 1e30 two cells away from empty space: the majorant of the
    // voxels beside it is 1e30 while the density there is tiny, so a ray
    // through them meets about 1e30 null collisions per unit length.
    let mut values = vec![0.0; 8];
    values[7] = 1e30;
    let density = SampledGrid::new(values, 8, 1, 1).unwrap();
    let bounds = Bounds3f::new(Point3f::new(0.0, 0.0, 0.0), Point3f::new(8.0, 1.0, 1.0));
    let m = Medium::UniformGrid(Box::new(GridMedium::new(grid_parts(
        density,
        bounds,
        Transform::identity(),
    ))));
    // Along y = z = 0.5 near x = 6: between the empty cells and the spike.
    let ray = Ray::new(Point3f::new(6.4, 0.5, -1.0), Vector3f::new(0.0, 0.0, 1.0));
    let mut rng = Rng::new(1, 0);
    let mut nulls = 0u64;
    let t = sample_t_maj(
        &m,
        &ray,
        3.0,
        0.5,
        &mut rng,
        &lambda(0.3),
        |_, _, _, _, _| {
            nulls += 1;
            true
        },
    );
    assert!(nulls <= MAX_COLLISIONS as u64, "{nulls}");
    assert!(t.is_black(), "the walk ends as an absorption: {t:?}");
}
