//! What the volumetric integrators share (pbrt-v4 `VolPathIntegrator` and
//! `SimpleVolPathIntegrator`; book sections 14.1–14.2): the medium a ray
//! enters when it leaves a surface, the generators delta tracking draws
//! from, and the transmittance of a shadow ray through media and the
//! `interface` surfaces that bound them (ratio tracking).

use super::Scene;
use crate::medium::sample_t_maj;
use crate::primitive::{MediumInterface, PrimitiveIntersection};
use crate::rng::Rng;
use crate::sampler::lowdiscrepancy::murmur_hash64a;
use crate::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::{spawn_ray_to_surface, MediumId, Ray, SHADOW_EPSILON};
use rpbrt_geometry::tuple::*;

/// The medium on the side of a surface that `w` points into (pbrt-v4
/// `Interaction::GetMedium(w)`): the primitive's interface when it
/// separates two media, else the medium the ray arrived in.
#[inline]
pub(crate) fn medium_toward(
    interface: Option<MediumInterface>,
    n: Normal3f,
    ray_medium: Option<MediumId>,
    w: Vector3f,
) -> Option<MediumId> {
    match interface {
        Some(mi) => {
            if dot(w, n) > 0.0 {
                mi.outside
            } else {
                mi.inside
            }
        }
        None => ray_medium,
    }
}

/// [`medium_toward`] for a ray hit.
#[inline]
pub(crate) fn hit_medium_toward(
    hit: &PrimitiveIntersection,
    ray_medium: Option<MediumId>,
    w: Vector3f,
) -> Option<MediumId> {
    medium_toward(hit.medium_interface, hit.si.n, ray_medium, w)
}

/// pbrt-v4's `Hash` of a list of floats (MurmurHash64A of their bytes).
#[inline]
pub(crate) fn hash_floats<const N: usize>(values: [Float; N]) -> u64 {
    let mut bytes = [0u8; 32];
    let n = N.min(8);
    for (i, v) in values.iter().take(n).enumerate() {
        bytes[4 * i..4 * i + 4].copy_from_slice(&v.to_le_bytes());
    }
    murmur_hash64a(&bytes[..4 * n], 0)
}

/// The generator delta tracking along a path segment draws from, seeded
/// by two sampler dimensions (pbrt-v4 `RNG rng(Hash(Get1D()),
/// Hash(Get1D()))`).
#[inline]
pub(crate) fn segment_rng(sampler: &mut Sampler) -> Rng {
    let h0 = hash_floats([sampler.get_1d()]);
    let h1 = hash_floats([sampler.get_1d()]);
    Rng::new(h0, h1)
}

/// A shadow ray's transmittance estimate and its rescaled path
/// probabilities (pbrt-v4 `VolPathIntegrator::SampleLd`'s `T_ray`, `r_u`
/// and `r_l`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct ShadowTransmittance {
    /// The ratio-tracking estimate of the transmittance.
    pub t_ray: SampledSpectrum,
    /// Unidirectional (scattering) path probability, rescaled.
    pub r_u: SampledSpectrum,
    /// Light-sampling path probability, rescaled.
    pub r_l: SampledSpectrum,
}

/// Follows a shadow ray toward a point on a light (`p_light`, its error
/// bounds and normal), through `interface` surfaces and the media between
/// them, estimating the transmittance by ratio tracking with Russian
/// roulette (pbrt-v4 `VolPathIntegrator::SampleLd`'s loop). `None` when an
/// opaque surface blocks it or the estimate is zero.
pub(crate) fn shadow_transmittance(
    scene: &Scene,
    mut ray: Ray,
    p_light: Point3fi,
    n_light: Normal3f,
    lambda: &SampledWavelengths,
) -> Option<ShadowTransmittance> {
    let one = SampledSpectrum::new(1.0);
    if !scene.has_volumes {
        // No media and no interfaces: a plain occlusion test.
        return (!scene.intersect_p(&ray, 1.0 - SHADOW_EPSILON)).then_some(ShadowTransmittance {
            t_ray: one,
            r_u: one,
            r_l: one,
        });
    }
    let mut t_ray = one;
    let mut r_u = one;
    let mut r_l = one;
    let mut rng = Rng::new(
        hash_floats([ray.o.x, ray.o.y, ray.o.z]),
        hash_floats([ray.d.x, ray.d.y, ray.d.z]),
    );
    let p_to = p_light.midpoint();
    loop {
        if ray.d == Vector3f::default() {
            break;
        }
        let hit = scene.intersect(&ray, 1.0 - SHADOW_EPSILON);
        if hit.as_ref().is_some_and(|h| h.material.is_some()) {
            return None;
        }
        if let Some(m) = ray.medium {
            let t_max = hit.as_ref().map_or(1.0 - SHADOW_EPSILON, |h| h.t_hit);
            let u = rng.uniform_float();
            let t_maj = sample_t_maj(
                &scene.media[m as usize],
                &ray,
                t_max,
                u,
                &mut rng,
                lambda,
                |_, mp, sigma_maj, t_maj, rng| {
                    let sigma_n = (sigma_maj - mp.sigma_a - mp.sigma_s).clamp_zero();
                    let pdf = t_maj[0] * sigma_maj[0];
                    t_ray *= t_maj * sigma_n / pdf;
                    r_l *= t_maj * sigma_maj / pdf;
                    r_u *= t_maj * sigma_n / pdf;
                    // Russian roulette once the estimate gets small.
                    let tr = t_ray / (r_l + r_u).average();
                    if tr.max_component_value() < 0.05 {
                        let q = 0.75;
                        if rng.uniform_float() < q {
                            t_ray = SampledSpectrum::new(0.0);
                        } else {
                            t_ray /= 1.0 - q;
                        }
                    }
                    !t_ray.is_black()
                },
            );
            if !(t_maj[0] > 0.0) {
                return None;
            }
            t_ray *= t_maj / t_maj[0];
            r_l *= t_maj / t_maj[0];
            r_u *= t_maj / t_maj[0];
        }
        if t_ray.is_black() || t_ray.has_nan() {
            return None;
        }
        let Some(h) = hit else {
            break;
        };
        let si = &h.si;
        let medium = hit_medium_toward(&h, ray.medium, p_to - si.p());
        ray = spawn_ray_to_surface(
            si.p(),
            si.p_error(),
            si.n,
            si.time,
            p_to,
            p_light.error(),
            n_light,
        );
        ray.medium = medium;
    }
    Some(ShadowTransmittance { t_ray, r_u, r_l })
}
