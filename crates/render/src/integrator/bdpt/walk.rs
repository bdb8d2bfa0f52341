//! Subpath generation for bidirectional methods (pbrt-v4
//! `GenerateCameraSubpath`, `GenerateLightSubpath` and `RandomWalk` in
//! `cpu/integrators.cpp`): random walks from the camera and from a light
//! that record each scattering vertex with its forward and reverse area
//! densities, through surfaces and participating media.

use super::vertex::{infinite_light_density, Vertex, VertexKind};
use crate::bxdf::{BxDFReflTransFlags, TransportMode};
use crate::integrator::volpath::sample_event;
use crate::integrator::volume::{hash_floats, hit_medium_toward};
use crate::integrator::{skip_intersection, Scene};
use crate::medium::sample_t_maj;
use crate::rng::Rng;
use crate::sampler::SampleSource;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::{Ray, RayDifferential};
use rpbrt_geometry::tuple::*;

/// What a random walk needs besides the scene.
#[derive(Clone, Copy, Debug)]
pub(crate) struct WalkOptions {
    /// Regularize near-specular BSDFs after the first non-specular bounce.
    pub regularize: bool,
}

/// Traces a camera subpath of at most `max_depth` vertices starting with
/// `ray` into `path` (cleared first); returns the number of vertices.
pub(crate) fn generate_camera_subpath<S: SampleSource>(
    scene: &Scene,
    ray: RayDifferential,
    lambda: &mut SampledWavelengths,
    sampler: &mut S,
    max_depth: usize,
    opts: WalkOptions,
    path: &mut Vec<Vertex>,
) -> usize {
    path.clear();
    if max_depth == 0 {
        return 0;
    }
    let beta = SampledSpectrum::new(1.0);
    let mut camera = Vertex::new(
        VertexKind::Camera,
        Point3fi::from(ray.ray.o),
        ray.ray.time,
        beta,
    );
    camera.medium = ray.ray.medium;
    path.push(camera);
    let (_, pdf_dir) = scene.camera.pdf_we(&ray.ray);
    random_walk(
        scene,
        lambda,
        ray,
        sampler,
        beta,
        pdf_dir,
        max_depth - 1,
        TransportMode::Radiance,
        opts,
        path,
    );
    path.len()
}

/// Traces a light subpath of at most `max_depth` vertices into `path`
/// (cleared first), starting on a light chosen by the scene's (power)
/// light sampler at `time`; returns the number of vertices.
pub(crate) fn generate_light_subpath<S: SampleSource>(
    scene: &Scene,
    lambda: &mut SampledWavelengths,
    sampler: &mut S,
    max_depth: usize,
    time: Float,
    opts: WalkOptions,
    path: &mut Vec<Vertex>,
) -> usize {
    path.clear();
    if max_depth == 0 {
        return 0;
    }
    let Some(sampled) = scene.light_sampler.sample_no_ctx(sampler.get_1d()) else {
        return 0;
    };
    let light = &scene.lights[sampled.light as usize];
    let ul0 = sampler.get_2d();
    let ul1 = sampler.get_2d();
    let Some(les) = light.sample_le(ul0, ul1, lambda, time) else {
        return 0;
    };
    if les.pdf_pos == 0.0 || les.pdf_dir == 0.0 || les.l.is_black() {
        return 0;
    }
    let light_pdf = sampled.p * les.pdf_pos;
    let mut v = match les.surface {
        Some(s) => {
            let mut v = Vertex::new(VertexKind::Light, s.pi, time, les.l);
            v.n = s.n;
            v.ns = s.n;
            v.uv = s.uv;
            v
        }
        None => Vertex::new(
            VertexKind::Light,
            Point3fi::from(les.ray.o),
            les.ray.time,
            les.l,
        ),
    };
    v.medium = les.ray.medium;
    v.light = Some(sampled.light);
    v.pdf_fwd = light_pdf;
    path.push(v);
    let ray = les.ray;
    let abs_cos = match les.surface {
        Some(s) => abs_dot(Vector3f::from(s.n), ray.d),
        None => 1.0,
    };
    let beta = les.l * (abs_cos / (light_pdf * les.pdf_dir));
    random_walk(
        scene,
        lambda,
        RayDifferential::new(ray),
        sampler,
        beta,
        les.pdf_dir,
        max_depth - 1,
        TransportMode::Importance,
        opts,
        path,
    );
    // Rays from infinite lights: the first hit's density is the disk's
    // (spatial), and the light's own is that of the direction.
    if path[0].is_infinite_light(scene) {
        if path.len() > 1 {
            let mut pdf = les.pdf_pos;
            if path[1].is_on_surface() {
                pdf *= abs_dot(ray.d, Vector3f::from(path[1].n));
            }
            path[1].pdf_fwd = pdf;
        }
        path[0].pdf_fwd = infinite_light_density(scene, ray.d);
    }
    path.len()
}

/// Extends `path` (whose last vertex is where `ray` starts) by at most
/// `max_depth` scattering vertices (pbrt-v4 `RandomWalk`).
#[allow(clippy::too_many_arguments)]
fn random_walk<S: SampleSource>(
    scene: &Scene,
    lambda: &mut SampledWavelengths,
    mut ray: RayDifferential,
    sampler: &mut S,
    mut beta: SampledSpectrum,
    pdf: Float,
    max_depth: usize,
    mode: TransportMode,
    opts: WalkOptions,
    path: &mut Vec<Vertex>,
) {
    if max_depth == 0 {
        return;
    }
    let mut bounces = 0usize;
    let mut any_non_specular = false;
    let mut pdf_fwd = pdf;
    loop {
        if beta.is_black() {
            break;
        }
        let mut closest = scene.intersect(&ray.ray, Float::INFINITY);
        if let Some(m) = ray.ray.medium {
            // Delta tracking to the surface (or to infinity).
            let t_max = closest.as_ref().map_or(Float::INFINITY, |h| h.t_hit);
            let r = ray.ray;
            let mut rng = Rng::new(
                hash_floats([r.o.x, r.o.y, r.o.z, t_max]),
                hash_floats([r.d.x, r.d.y, r.d.z]),
            );
            let u = sampler.get_1d();
            let mut scattered = false;
            let mut terminated = false;
            let lambda_ref: &SampledWavelengths = lambda;
            let t_maj = sample_t_maj(
                &scene.media[m as usize],
                &r,
                t_max,
                u,
                &mut rng,
                lambda_ref,
                |p, mp, sigma_maj, t_maj, _| {
                    let um = sampler.get_1d();
                    match sample_event(mp.sigma_a[0], mp.sigma_s[0], sigma_maj[0], um) {
                        0 => {
                            terminated = true;
                            false
                        }
                        1 => {
                            beta *= t_maj * mp.sigma_s / (t_maj[0] * mp.sigma_s[0]);
                            let wo = -r.d.normalize();
                            let mut v =
                                Vertex::new(VertexKind::Medium, Point3fi::from(p), r.time, beta);
                            v.wo = wo;
                            v.medium = Some(m);
                            v.phase = mp.phase;
                            let prev = path.len() - 1;
                            v.pdf_fwd = path[prev].convert_density(pdf_fwd, &v, scene);
                            path.push(v);
                            bounces += 1;
                            if bounces >= max_depth {
                                terminated = true;
                                return false;
                            }
                            match mp.phase.sample_p(wo, sampler.get_2d()) {
                                Some(ps) if ps.pdf > 0.0 => {
                                    pdf_fwd = ps.pdf;
                                    beta *= ps.p / ps.pdf;
                                    ray = RayDifferential::new(Ray::with_time(
                                        p,
                                        ps.wi,
                                        r.time,
                                        Some(m),
                                    ));
                                    any_non_specular = true;
                                    let (before, cur) = path.split_at(prev + 1);
                                    let rev = cur[0].convert_density(ps.pdf, &before[prev], scene);
                                    path[prev].pdf_rev = rev;
                                    scattered = true;
                                }
                                _ => terminated = true,
                            }
                            false
                        }
                        _ => {
                            let sigma_n = (sigma_maj - mp.sigma_a - mp.sigma_s).clamp_zero();
                            let pdf = t_maj[0] * sigma_n[0];
                            if pdf == 0.0 {
                                beta = SampledSpectrum::new(0.0);
                            } else {
                                beta *= t_maj * sigma_n / pdf;
                            }
                            !beta.is_black()
                        }
                    }
                },
            );
            if terminated {
                return;
            }
            if scattered {
                continue;
            }
            if t_maj[0].is_nan() || t_maj[0] <= 0.0 {
                return;
            }
            beta *= t_maj / t_maj[0];
        }
        let Some(hit) = closest.as_mut() else {
            // Escaped: camera paths end on the infinite lights.
            if mode == TransportMode::Radiance {
                let r = ray.ray;
                let mut v = Vertex::new(VertexKind::Light, Point3fi::from(r.o + r.d), r.time, beta);
                v.n = Normal3f::from(-r.d);
                v.ns = v.n;
                v.medium = r.medium;
                v.pdf_fwd = pdf_fwd;
                path.push(v);
            }
            break;
        };
        let Some(mut bsdf) = scene.get_bsdf(hit, &ray, lambda, sampler) else {
            ray = skip_intersection(&ray, hit);
            continue;
        };
        if opts.regularize && any_non_specular {
            bsdf.regularize();
        }
        let si = &hit.si;
        let mut v = Vertex::new(VertexKind::Surface, si.pi, si.time, beta);
        v.n = si.n;
        v.ns = si.shading.n;
        v.uv = si.uv;
        v.wo = si.wo;
        v.interface = hit.medium_interface;
        v.medium = ray.ray.medium;
        v.bsdf = Some(bsdf);
        v.light = hit.area_light;
        let prev = path.len() - 1;
        v.pdf_fwd = path[prev].convert_density(pdf_fwd, &v, scene);
        path.push(v);
        bounces += 1;
        if bounces >= max_depth {
            break;
        }
        let wo = si.wo;
        let u = sampler.get_1d();
        let Some(bs) = bsdf.sample_f(wo, u, sampler.get_2d(), mode, BxDFReflTransFlags::ALL) else {
            break;
        };
        pdf_fwd = if bs.pdf_is_proportional {
            bsdf.pdf(wo, bs.wi, mode, BxDFReflTransFlags::ALL)
        } else {
            bs.pdf
        };
        any_non_specular |= !bs.is_specular();
        beta *= bs.f * (abs_dot(bs.wi, si.shading.n) / bs.pdf);
        let mut next = RayDifferential::new(si.spawn_ray(bs.wi));
        next.ray.medium = hit_medium_toward(hit, ray.ray.medium, bs.wi);
        ray = next;
        let mut pdf_rev = bsdf.pdf(bs.wi, wo, !mode, BxDFReflTransFlags::ALL);
        let cur = path.len() - 1;
        if bs.is_specular() {
            path[cur].delta = true;
            pdf_rev = 0.0;
            pdf_fwd = 0.0;
        }
        let (before, rest) = path.split_at(cur);
        let rev = rest[0].convert_density(pdf_rev, &before[prev], scene);
        path[prev].pdf_rev = rev;
    }
}
