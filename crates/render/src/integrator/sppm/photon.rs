//! SPPM's photon pass (pbrt-v4 `SPPMIntegrator::Render`, "Trace photons
//! and accumulate contributions"; pbrt-v3 book section 16.2.6): paths
//! traced from lights chosen by emitted power, leaving a contribution at
//! every visible point within its search radius of each vertex after the
//! first.
//!
//! Each photon's sample values come from the scrambled Halton sequence at
//! index `iteration × photons per iteration + photon index`, one dimension
//! after another, as in pbrt-v4: a photon's path depends on its index
//! alone. The contributions are returned as a list per photon range rather
//! than added to the pixels in place (pbrt-v4 adds them with atomics, in
//! whatever order threads run): the caller adds the lists in photon order,
//! so sums never depend on the thread count.

use super::grid::VisiblePointGrid;
use super::SppmPixel;
use crate::bxdf::{BxDFReflTransFlags, TransportMode};
use crate::integrator::{skip_intersection, Scene};
use crate::lightsampler::PowerLightSampler;
use crate::sampler::lowdiscrepancy::{scrambled_radical_inverse, DigitPermutation};
use crate::sampler::Sampler;
use crate::spectrum::{SampledSpectrum, SampledWavelengths, RGB};
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::RayDifferential;
use rpbrt_geometry::tuple::*;

/// One photon's contribution to one pixel's visible point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Deposit {
    /// The pixel's index.
    pub pixel: u32,
    /// The flux reflected toward the camera, in output RGB (pbrt-v4's
    /// `Phi_i` term).
    pub phi: RGB,
}

/// Sample dimensions a photon path of `max_depth` vertices can draw: the
/// light choice, two 2-D values and the time to leave the light, then a
/// BSDF sample (3) and a Russian roulette value per bounce.
pub(super) fn photon_dimensions(max_depth: i32) -> usize {
    6 + 4 * max_depth.max(0) as usize
}

/// The scrambled Halton values of one photon (pbrt-v4's `Sample1D` and
/// `Sample2D` lambdas).
struct HaltonStream<'a> {
    permutations: &'a [DigitPermutation],
    index: u64,
    dimension: usize,
}

impl HaltonStream<'_> {
    #[inline]
    fn get_1d(&mut self) -> Float {
        // Paths long enough to run past the prime table (pbrt-v4 reads past
        // its end there) start over at its first dimension.
        let d = self.dimension % self.permutations.len();
        self.dimension += 1;
        scrambled_radical_inverse(d, self.index, &self.permutations[d])
    }

    #[inline]
    fn get_2d(&mut self) -> Point2f {
        let x = self.get_1d();
        let y = self.get_1d();
        Point2f::new(x, y)
    }
}

/// What every photon of one iteration shares.
pub(super) struct PhotonPass<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// This iteration's visible points.
    pub grid: &'a VisiblePointGrid,
    /// The pixels, with their visible points.
    pub pixels: &'a [SppmPixel],
    /// Chooses the light each photon leaves.
    pub shoot: &'a PowerLightSampler,
    /// The Halton sequence's digit permutations, one per dimension.
    pub permutations: &'a [DigitPermutation],
    /// The wavelengths of this iteration (camera paths carry the same).
    pub lambda: SampledWavelengths,
    /// Maximum number of photon path vertices.
    pub max_depth: i32,
    /// Halton index of this iteration's first photon.
    pub first_index: u64,
}

impl PhotonPass<'_> {
    /// Follows photon `photon_index` of the iteration, appending its
    /// contributions to `out`. `sampler` serves only `--force-diffuse`'s
    /// draws in `get_bsdf`.
    pub fn trace(&self, photon_index: u64, sampler: &mut Sampler, out: &mut Vec<Deposit>) {
        let scene = self.scene;
        let halton_index = self.first_index + photon_index;
        let mut u = HaltonStream {
            permutations: self.permutations,
            index: halton_index,
            dimension: 0,
        };
        if scene.force_diffuse {
            // A sampler state keyed by the photon alone.
            sampler.start_pixel_sample(
                Point2i::new(
                    (halton_index & 0x7fff_ffff) as i32,
                    (halton_index >> 31) as i32,
                ),
                0,
                0,
            );
        }

        // The light and the ray leaving it.
        let Some(sampled) = self.shoot.sample_no_ctx(u.get_1d()) else {
            return;
        };
        let light = &scene.lights[sampled.light as usize];
        let u_light0 = u.get_2d();
        let u_light1 = u.get_2d();
        let time = scene.camera.sample_time(u.get_1d());
        let mut lambda = self.lambda;
        let Some(les) = light.sample_le(u_light0, u_light1, &lambda, time) else {
            return;
        };
        if les.pdf_pos == 0.0 || les.pdf_dir == 0.0 || les.l.is_black() {
            return;
        }
        let mut ray = RayDifferential::new(les.ray);
        let abs_cos = les.surface.map_or(1.0, |s| abs_dot(ray.ray.d, s.n));
        let mut beta = les.l * abs_cos / (sampled.p * les.pdf_pos * les.pdf_dir);
        if beta.is_black() {
            return;
        }

        let mut depth = 0;
        while depth < self.max_depth {
            let mut closest = scene.intersect(&ray.ray, Float::INFINITY);
            let Some(hit) = closest.as_mut() else {
                break;
            };
            if depth > 0 {
                self.deposit(hit.si.p(), -ray.ray.d, beta, &lambda, out);
            }
            let Some(bsdf) = scene.get_bsdf(hit, &ray, &mut lambda, sampler) else {
                // An interface between media: the same vertex count on the
                // far side.
                ray = skip_intersection(&ray, hit);
                continue;
            };
            let si = &hit.si;
            let wo = -ray.ray.d;
            let uc = u.get_1d();
            let u2 = u.get_2d();
            let Some(bs) = bsdf.sample_f(
                wo,
                uc,
                u2,
                TransportMode::Importance,
                BxDFReflTransFlags::ALL,
            ) else {
                break;
            };
            let beta_new = beta * bs.f * abs_dot(bs.wi, si.shading.n) / bs.pdf;
            // Russian roulette by how much the bounce changed the weight.
            let beta_ratio = beta_new.max_component_value() / beta.max_component_value();
            let q = (1.0 - beta_ratio).max(0.0);
            if u.get_1d() < q {
                break;
            }
            beta = beta_new / (1.0 - q);
            ray = RayDifferential::new(si.spawn_ray(bs.wi));
            depth += 1;
        }
    }

    /// The photon arriving at `p` from direction `wi` with weight `beta`
    /// at wavelengths `lambda`, reflected by every visible point within its
    /// pixel's search radius.
    #[inline]
    fn deposit(
        &self,
        p: Point3f,
        wi: Vector3f,
        beta: SampledSpectrum,
        lambda: &SampledWavelengths,
        out: &mut Vec<Deposit>,
    ) {
        for e in self.grid.candidates(p) {
            if e.p.distance_squared(p) > e.r2 {
                continue;
            }
            let Some(vp) = self.pixels[e.pixel as usize].vp.as_ref() else {
                continue;
            };
            let phi = beta * vp.bsdf.f(vp.wo, wi, TransportMode::Radiance);
            let mut photon_lambda = *lambda;
            if vp.secondary_terminated {
                photon_lambda.terminate_secondary();
            }
            out.push(Deposit {
                pixel: e.pixel,
                phi: self.scene.film.to_output_rgb(vp.beta * phi, &photon_lambda),
            });
        }
    }
}
