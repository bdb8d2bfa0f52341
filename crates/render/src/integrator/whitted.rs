//! pbrt-v3's Whitted-style ray tracer (`WhittedIntegrator`, pbrt-v3
//! `integrators/whitted.cpp`; third edition section 1.3.6), which pbrt-v4
//! dropped: at each hit, emission plus one sample of every light (not a
//! light sampler's choice), then perfectly specular reflection and
//! transmission followed recursively up to `maxdepth`. Glossy and diffuse
//! interreflection is not rendered, as in pbrt-v3. Files written for
//! pbrt-v3 render with it directly.

use super::{skip_intersection, RayIntegrator, Scene};
use crate::bxdf::{BxDFReflTransFlags, TransportMode, BSDF};
use crate::film::VisibleSurface;
use crate::light::LightSampleContext;
use crate::primitive::PrimitiveIntersection;
use crate::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::RayDifferential;
use rpbrt_geometry::tuple::*;

/// pbrt-v3's `whitted` integrator.
#[derive(Clone, Debug)]
pub struct WhittedIntegrator {
    /// Maximum recursion depth of specular rays.
    pub max_depth: i32,
}

impl WhittedIntegrator {
    /// pbrt-v3 `WhittedIntegrator::Li` at recursion `depth`.
    fn li_depth(
        &self,
        scene: &Scene,
        mut ray: RayDifferential,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        depth: i32,
    ) -> SampledSpectrum {
        let mut l = SampledSpectrum::new(0.0);
        // Surfaces without a BSDF (media interfaces) are passed through at
        // the same depth.
        let (mut hit, bsdf) = loop {
            let Some(mut hit) = scene.intersect(&ray.ray, Float::INFINITY) else {
                for &li in &scene.infinite_lights {
                    l += scene.lights[li as usize].le(&ray.ray, lambda);
                }
                return l;
            };
            match scene.get_bsdf(&mut hit, &ray, lambda, sampler) {
                Some(b) => break (hit, b),
                None => ray = skip_intersection(&ray, &hit),
            }
        };
        let si = hit.si;
        let wo = si.wo;
        l += scene.le(&hit, wo, lambda);
        // One sample of every light.
        let ctx = LightSampleContext::from_si(&si);
        for light in &scene.lights {
            let u = sampler.get_2d();
            let Some(ls) = light.sample_li(&ctx, u, lambda, false) else {
                continue;
            };
            if ls.l.is_black() || ls.pdf == 0.0 {
                continue;
            }
            let f = bsdf.f(wo, ls.wi, TransportMode::Radiance);
            if !f.is_black() && scene.unoccluded(&si, ls.p_light, ls.n_light) {
                l += f * ls.l * (abs_dot(ls.wi, si.shading.n) / ls.pdf);
            }
        }
        if depth + 1 < self.max_depth {
            for flags in [
                BxDFReflTransFlags::REFLECTION,
                BxDFReflTransFlags::TRANSMISSION,
            ] {
                l += self.specular(scene, &mut hit, &bsdf, flags, lambda, sampler, depth);
            }
        }
        l
    }

    /// pbrt-v3 `SpecularReflect` / `SpecularTransmit`: the radiance along
    /// the perfectly specular direction of the given kind, if the BSDF
    /// has one.
    #[allow(clippy::too_many_arguments)]
    fn specular(
        &self,
        scene: &Scene,
        hit: &mut PrimitiveIntersection,
        bsdf: &BSDF,
        flags: BxDFReflTransFlags,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        depth: i32,
    ) -> SampledSpectrum {
        let zero = SampledSpectrum::new(0.0);
        let si = &hit.si;
        let uc = sampler.get_1d();
        let u = sampler.get_2d();
        let Some(bs) = bsdf.sample_f(si.wo, uc, u, TransportMode::Radiance, flags) else {
            return zero;
        };
        let cos = abs_dot(bs.wi, si.shading.n);
        if !bs.is_specular() || bs.f.is_black() || bs.pdf <= 0.0 || cos == 0.0 {
            return zero;
        }
        let mut next = RayDifferential::new(si.spawn_ray(bs.wi));
        next.ray.medium = super::volume::hit_medium_toward(hit, None, bs.wi);
        let li = self.li_depth(scene, next, lambda, sampler, depth + 1);
        bs.f * li * (cos / bs.pdf)
    }
}

impl RayIntegrator for WhittedIntegrator {
    fn li(
        &self,
        scene: &Scene,
        ray: RayDifferential,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        _visible: Option<&mut VisibleSurface>,
    ) -> SampledSpectrum {
        self.li_depth(scene, ray, lambda, sampler, 0)
    }
}
