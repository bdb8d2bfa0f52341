//! The simpler integrators of pbrt-v4 (`SimplePathIntegrator`,
//! `AOIntegrator`, `RandomWalkIntegrator`; book sections 13.1–13.3): useful
//! as references for the path tracer and for debugging scenes.

use super::{skip_intersection, RayIntegrator, Scene};
use crate::bxdf::{BxDFReflTransFlags, TransportMode};
use crate::film::VisibleSurface;
use crate::light::LightSampleContext;
use crate::sampler::Sampler;
use crate::sampling::*;
use crate::spectrum::{SampledSpectrum, SampledWavelengths, Spectrum};
use rpbrt_geometry::float::*;
use rpbrt_geometry::frame::Frame;
use rpbrt_geometry::ray::RayDifferential;
use rpbrt_geometry::tuple::*;

/// pbrt-v4's `simplepath`: uniform light sampling and BSDF (or uniform)
/// direction sampling, without MIS.
#[derive(Clone, Debug)]
pub struct SimplePathIntegrator {
    /// Maximum path depth.
    pub max_depth: i32,
    /// Sample lights directly at each hit.
    pub sample_lights: bool,
    /// Sample the BSDF for the next direction (else uniform directions).
    pub sample_bsdf: bool,
}

impl RayIntegrator for SimplePathIntegrator {
    /// The radiance arriving along `ray`.
    fn li(
        &self,
        scene: &Scene,
        ray: RayDifferential,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        _visible: Option<&mut VisibleSurface>,
    ) -> SampledSpectrum {
        let mut ray = ray;
        let mut l = SampledSpectrum::new(0.0);
        let mut beta = SampledSpectrum::new(1.0);
        let mut specular_bounce = true;
        let mut depth = 0;
        while !beta.is_black() {
            let Some(mut hit) = scene.intersect(&ray.ray, Float::INFINITY) else {
                if !self.sample_lights || specular_bounce {
                    for &li in &scene.infinite_lights {
                        l += beta * scene.lights[li as usize].le(&ray.ray, lambda);
                    }
                }
                break;
            };
            if !self.sample_lights || specular_bounce {
                l += beta * scene.le(&hit, -ray.ray.d, lambda);
            }
            if depth == self.max_depth {
                break;
            }
            depth += 1;
            let Some(bsdf) = scene.get_bsdf(&mut hit, &ray, lambda, sampler) else {
                specular_bounce = true;
                ray = skip_intersection(&ray, &hit);
                continue;
            };
            let si = &hit.si;
            let wo = -ray.ray.d;
            if self.sample_lights {
                let u = sampler.get_1d();
                let n = scene.lights.len();
                if n > 0 {
                    let idx = ((u * n as Float) as usize).min(n - 1);
                    let p_light = 1.0 / n as Float;
                    let u_light = sampler.get_2d();
                    let ctx = LightSampleContext::from_si(si);
                    if let Some(ls) = scene.lights[idx].sample_li(&ctx, u_light, lambda, false) {
                        if !ls.l.is_black() && ls.pdf > 0.0 {
                            let f = bsdf.f(wo, ls.wi, TransportMode::Radiance)
                                * abs_dot(ls.wi, si.shading.n);
                            if !f.is_black() && scene.unoccluded(si, ls.p_light, ls.n_light) {
                                l += beta * f * ls.l / (p_light * ls.pdf);
                            }
                        }
                    }
                }
            }
            if self.sample_bsdf {
                let u = sampler.get_1d();
                let u2 = sampler.get_2d();
                let Some(bs) =
                    bsdf.sample_f(wo, u, u2, TransportMode::Radiance, BxDFReflTransFlags::ALL)
                else {
                    break;
                };
                beta *= bs.f * (abs_dot(bs.wi, si.shading.n) / bs.pdf);
                specular_bounce = bs.is_specular();
                ray = RayDifferential::new(si.spawn_ray(bs.wi));
            } else {
                let flags = bsdf.flags();
                let u = sampler.get_2d();
                let (mut wi, pdf) = if flags.is_reflective() && flags.is_transmissive() {
                    (sample_uniform_sphere(u), UNIFORM_SPHERE_PDF)
                } else {
                    (sample_uniform_hemisphere(u), UNIFORM_HEMISPHERE_PDF)
                };
                if !(flags.is_reflective() && flags.is_transmissive()) {
                    // Put wi in the hemisphere the BSDF scatters into.
                    wi = Frame::from_normal(si.n).from_local(wi);
                    if flags.is_reflective() && dot(wo, si.n) * dot(wi, si.n) < 0.0 {
                        wi = -wi;
                    } else if flags.is_transmissive() && dot(wo, si.n) * dot(wi, si.n) > 0.0 {
                        wi = -wi;
                    }
                }
                beta *= bsdf.f(wo, wi, TransportMode::Radiance) * (abs_dot(wi, si.shading.n) / pdf);
                specular_bounce = false;
                ray = RayDifferential::new(si.spawn_ray(wi));
            }
        }
        l
    }
}

/// pbrt-v4's `ambientocclusion`: the fraction of the hemisphere around each
/// hit that is unoccluded within `max_distance`, lit by the colour space's
/// illuminant normalised to luminance 1.
#[derive(Clone, Debug)]
pub struct AmbientOcclusionIntegrator {
    /// Sample directions with a cosine distribution (else uniformly).
    pub cos_sample: bool,
    /// How far occluders count.
    pub max_distance: Float,
}

impl RayIntegrator for AmbientOcclusionIntegrator {
    /// The AO estimate along `ray`.
    fn li(
        &self,
        scene: &Scene,
        ray: RayDifferential,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        _visible: Option<&mut VisibleSurface>,
    ) -> SampledSpectrum {
        let mut ray = ray;
        // Interfaces are skipped; bound the number of them.
        for _ in 0..1024 {
            let Some(mut hit) = scene.intersect(&ray.ray, Float::INFINITY) else {
                return SampledSpectrum::new(0.0);
            };
            if scene.get_bsdf(&mut hit, &ray, lambda, sampler).is_none() {
                ray = skip_intersection(&ray, &hit);
                continue;
            }
            let si = &hit.si;
            let n = si.n.face_forward(-ray.ray.d);
            let u = sampler.get_2d();
            let (wi_local, pdf) = if self.cos_sample {
                let w = sample_cosine_hemisphere(u);
                (w, cosine_hemisphere_pdf(w.z.abs()))
            } else {
                (sample_uniform_hemisphere(u), UNIFORM_HEMISPHERE_PDF)
            };
            if pdf == 0.0 {
                return SampledSpectrum::new(0.0);
            }
            let wi = Frame::from_normal(n).from_local(wi_local);
            let r = si.spawn_ray(wi);
            if !scene.intersect_p(&r, self.max_distance) {
                let (illum, scale) = illuminant();
                return illum.sample(lambda) * (scale * dot(wi, n) / (PI * pdf));
            }
            return SampledSpectrum::new(0.0);
        }
        SampledSpectrum::new(0.0)
    }
}

/// The sRGB illuminant (D65) and the scale that gives it luminance 1.
fn illuminant() -> (Spectrum, Float) {
    let cs = crate::spectrum::RgbColorSpace::srgb();
    let s = Spectrum::DenselySampled(cs.illuminant.clone());
    let scale = 1.0 / crate::spectrum::spectrum_to_photometric(&s);
    (s, scale)
}

/// pbrt-v4's `randomwalk`: uniform spherical directions at every hit and no
/// light sampling — unbiased and very noisy.
#[derive(Clone, Debug)]
pub struct RandomWalkIntegrator {
    /// Maximum path depth.
    pub max_depth: i32,
}

impl RayIntegrator for RandomWalkIntegrator {
    /// The radiance arriving along `ray`.
    fn li(
        &self,
        scene: &Scene,
        ray: RayDifferential,
        lambda: &mut SampledWavelengths,
        sampler: &mut Sampler,
        _visible: Option<&mut VisibleSurface>,
    ) -> SampledSpectrum {
        let mut ray = ray;
        let mut l = SampledSpectrum::new(0.0);
        let mut beta = SampledSpectrum::new(1.0);
        let mut depth = 0;
        loop {
            let Some(mut hit) = scene.intersect(&ray.ray, Float::INFINITY) else {
                for &li in &scene.infinite_lights {
                    l += beta * scene.lights[li as usize].le(&ray.ray, lambda);
                }
                return l;
            };
            let wo = -ray.ray.d;
            l += beta * scene.le(&hit, wo, lambda);
            if depth == self.max_depth {
                return l;
            }
            let Some(bsdf) = scene.get_bsdf(&mut hit, &ray, lambda, sampler) else {
                return l;
            };
            let u = sampler.get_2d();
            let wp = sample_uniform_sphere(u);
            let fcos = bsdf.f(wo, wp, TransportMode::Radiance) * abs_dot(wp, hit.si.shading.n);
            if fcos.is_black() {
                return l;
            }
            beta *= fcos * (4.0 * PI);
            ray = RayDifferential::new(hit.si.spawn_ray(wp));
            depth += 1;
        }
    }
}
