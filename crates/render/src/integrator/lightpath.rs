//! The light tracer (pbrt-v4 `LightPathIntegrator`, `cpu/integrators.cpp`):
//! each pixel sample traces a path from a light and, at every vertex,
//! connects it to the camera, splatting the contribution wherever it
//! lands on the film. It renders what the camera sees of light after at
//! least one scattering event and of emitters seen directly; specular
//! surfaces seen by the camera stay black (no path reaches them).

use super::bdpt::vertex::{Vertex, VertexKind};
use super::render::RenderOptions;
use super::tile::TileIntegrator;
use super::volume::hit_medium_toward;
use super::{skip_intersection, Scene};
use crate::bxdf::{BxDFReflTransFlags, TransportMode};
use crate::film::{FilmTile, SplatBuffer};
use crate::sampler::Sampler;
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::RayDifferential;
use rpbrt_geometry::tuple::*;

/// pbrt-v4's `lightpath` integrator.
#[derive(Clone, Debug)]
pub struct LightPathIntegrator {
    /// Maximum number of scattering events.
    pub max_depth: i32,
}

impl TileIntegrator for LightPathIntegrator {
    type Buffers = ();

    fn evaluate_pixel_sample(
        &self,
        scene: &Scene,
        opts: &RenderOptions,
        _p_pixel: Point2i,
        sampler: &mut Sampler,
        _tile: &mut FilmTile,
        splats: &mut SplatBuffer,
        _differentials: bool,
    ) {
        let mut lu = sampler.get_1d();
        if opts.disable_wavelength_jitter {
            lu = 0.5;
        }
        let mut lambda = scene.film.sample_wavelengths(lu);
        let Some(sampled) = scene.light_sampler.sample_no_ctx(sampler.get_1d()) else {
            return;
        };
        let light = &scene.lights[sampled.light as usize];
        let light_pdf = sampled.p;
        let time = scene.camera.sample_time(sampler.get_1d());
        let ul0 = sampler.get_2d();
        let ul1 = sampler.get_2d();
        let Some(les) = light.sample_le(ul0, ul1, &lambda, time) else {
            return;
        };
        if les.pdf_pos == 0.0 || les.pdf_dir == 0.0 || les.l.is_black() {
            return;
        }
        // An emitter the camera sees directly.
        if let Some(surf) = les.surface {
            let u = sampler.get_2d();
            if let Some(cs) = scene.camera.sample_wi(surf.pi.midpoint(), time, u, &lambda) {
                if cs.pdf != 0.0 {
                    let le = light.l(surf.pi.midpoint(), surf.n, surf.uv, cs.wi, &lambda);
                    if !le.is_black() {
                        // The measurement over the area density of the
                        // point on the light (pbrt-v4 divides by the light's
                        // solid-angle density seen from the lens instead,
                        // which drops directly visible emitters; this is the
                        // estimator that converges to the path tracer's).
                        let abs_cos = abs_dot(Vector3f::from(surf.n), cs.wi);
                        let l =
                            le * cs.wi_importance * (abs_cos / (light_pdf * les.pdf_pos * cs.pdf));
                        let mut from = Vertex::new(VertexKind::Light, surf.pi, time, le);
                        from.n = surf.n;
                        from.medium = les.ray.medium;
                        let mut to =
                            Vertex::new(VertexKind::Camera, Point3fi::from(cs.p_lens), time, le);
                        to.n = cs.n_lens;
                        let tr = super::bdpt::transmittance(scene, &from, &to, &lambda);
                        if !tr.is_black() {
                            splats.add(cs.p_raster, l * tr, &lambda);
                        }
                    }
                }
            }
        }
        // Follow the light's path, connecting each vertex to the camera.
        let mut depth = 0;
        let mut ray = RayDifferential::new(les.ray);
        let abs_cos = les
            .surface
            .map_or(1.0, |s| abs_dot(Vector3f::from(s.n), ray.ray.d));
        let mut beta = les.l * (abs_cos / (light_pdf * les.pdf_pos * les.pdf_dir));
        loop {
            let mut closest = scene.intersect(&ray.ray, Float::INFINITY);
            let Some(hit) = closest.as_mut() else {
                break;
            };
            let Some(bsdf) = scene.get_bsdf(hit, &ray, &mut lambda, sampler) else {
                ray = skip_intersection(&ray, hit);
                continue;
            };
            if depth == self.max_depth {
                break;
            }
            depth += 1;
            let si = &hit.si;
            let u = sampler.get_2d();
            if let Some(cs) = scene.camera.sample_wi(si.p(), si.time, u, &lambda) {
                if cs.pdf != 0.0 {
                    let l = beta
                        * bsdf.f(si.wo, cs.wi, TransportMode::Importance)
                        * (abs_dot(cs.wi, si.shading.n) / cs.pdf)
                        * cs.wi_importance;
                    if !l.is_black() && scene.unoccluded(si, Point3fi::from(cs.p_lens), cs.n_lens) {
                        splats.add(cs.p_raster, l, &lambda);
                    }
                }
            }
            let uc = sampler.get_1d();
            let Some(bs) = bsdf.sample_f(
                si.wo,
                uc,
                sampler.get_2d(),
                TransportMode::Importance,
                BxDFReflTransFlags::ALL,
            ) else {
                break;
            };
            beta *= bs.f * (abs_dot(bs.wi, si.shading.n) / bs.pdf);
            let mut next = RayDifferential::new(si.spawn_ray(bs.wi));
            next.ray.medium = hit_medium_toward(hit, ray.ray.medium, bs.wi);
            ray = next;
        }
    }
}
