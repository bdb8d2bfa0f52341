//! Layered BxDFs (pbrt-v4 book section 14.3; pbrt-v4 `bxdfs.h`): two
//! interfaces separated by a slab that may hold a homogeneous scattering
//! medium, evaluated and sampled by stochastic random walks between the
//! interfaces. The walks are seeded from a hash of the query, so `f` and
//! `pdf` are deterministic for given arguments.

use rpbrt_geometry::float::*;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::{abs_cos_theta, same_hemisphere};

use super::conductor::ConductorBxDF;
use super::dielectric::DielectricBxDF;
use super::diffuse::DiffuseBxDF;
use super::lanes::{self, gather_f, source, LayeredLanes, ToLanes, MAX_LANES};
use super::scattering::{henyey_greenstein, sample_henyey_greenstein};
use super::{BSDFSample, BxDFFlags, BxDFMethods, BxDFReflTransFlags, TransportMode};
use crate::rng::Rng;
use crate::sampling::power_heuristic;
use crate::simd::{F32Lanes, Scalar1};
use crate::spectrum::SampledSpectrum;

/// A dielectric coating over a Lambertian base (two-sided).
pub type CoatedDiffuseBxDF = LayeredBxDF<DielectricBxDF, DiffuseBxDF, true>;
/// A dielectric coating over a conductor (two-sided).
pub type CoatedConductorBxDF = LayeredBxDF<DielectricBxDF, ConductorBxDF, true>;

/// MurmurHash64A (seed 0) of a byte string: pbrt-v4's `Hash` of packed
/// arguments.
fn murmur_hash64a(key: &[u8]) -> u64 {
    const M: u64 = 0xc6a4_a793_5bd1_e995;
    const R: u32 = 47;
    let mut h: u64 = (key.len() as u64).wrapping_mul(M);
    let mut chunks = key.chunks_exact(8);
    for c in &mut chunks {
        let mut k = u64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]);
        k = k.wrapping_mul(M);
        k ^= k >> R;
        k = k.wrapping_mul(M);
        h ^= k;
        h = h.wrapping_mul(M);
    }
    let rest = chunks.remainder();
    if !rest.is_empty() {
        for (i, &b) in rest.iter().enumerate() {
            h ^= (b as u64) << (8 * i);
        }
        h = h.wrapping_mul(M);
    }
    h ^= h >> R;
    h = h.wrapping_mul(M);
    h ^= h >> R;
    h
}

/// Hash of the little-endian bytes of an optional integer seed followed by
/// floats, as pbrt-v4 packs `Hash(seed, v)` and `Hash(v)`.
pub(crate) fn hash_floats(seed: Option<i32>, fs: &[Float]) -> u64 {
    let mut buf = [0u8; 32];
    let mut n = 0;
    if let Some(s) = seed {
        buf[..4].copy_from_slice(&s.to_le_bytes());
        n = 4;
    }
    for f in fs {
        buf[n..n + 4].copy_from_slice(&f.to_le_bytes());
        n += 4;
    }
    murmur_hash64a(&buf[..n])
}

/// Transmittance through the slab along `w` over height difference `dz`
/// (unit extinction).
#[inline]
fn tr(dz: Float, w: Vector3f) -> Float {
    if dz.abs() <= Float::MIN_POSITIVE {
        return 1.0;
    }
    (-(dz / w.z).abs()).exp()
}

/// Exponential sample with rate `a`.
#[inline]
fn sample_exponential(u: Float, a: Float) -> Float {
    -(1.0 - u).ln() / a
}

#[cfg(test)]
thread_local! {
    /// Tests compare the lane walk with the scalar one, which otherwise
    /// runs only for models with a medium.
    pub(crate) static FORCE_SCALAR_WALK: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

#[inline(always)]
fn scalar_walk_forced() -> bool {
    #[cfg(test)]
    {
        FORCE_SCALAR_WALK.with(|c| c.get())
    }
    #[cfg(not(test))]
    {
        false
    }
}

/// One of the two interfaces of a layered BxDF.
enum Layer<'a, T, B> {
    Top(&'a T),
    Bottom(&'a B),
}

impl<T, B> Clone for Layer<'_, T, B> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<T, B> Copy for Layer<'_, T, B> {}

impl<T: BxDFMethods, B: BxDFMethods> Layer<'_, T, B> {
    #[inline]
    fn f(&self, wo: Vector3f, wi: Vector3f, mode: TransportMode) -> SampledSpectrum {
        match self {
            Layer::Top(t) => t.f(wo, wi, mode),
            Layer::Bottom(b) => b.f(wo, wi, mode),
        }
    }
    #[inline]
    fn sample_f(
        &self,
        wo: Vector3f,
        uc: Float,
        u: Point2f,
        mode: TransportMode,
        flags: BxDFReflTransFlags,
    ) -> Option<BSDFSample> {
        match self {
            Layer::Top(t) => t.sample_f(wo, uc, u, mode, flags),
            Layer::Bottom(b) => b.sample_f(wo, uc, u, mode, flags),
        }
    }
    #[inline]
    fn pdf(
        &self,
        wo: Vector3f,
        wi: Vector3f,
        mode: TransportMode,
        fl: BxDFReflTransFlags,
    ) -> Float {
        match self {
            Layer::Top(t) => t.pdf(wo, wi, mode, fl),
            Layer::Bottom(b) => b.pdf(wo, wi, mode, fl),
        }
    }
    #[inline]
    fn flags(&self) -> BxDFFlags {
        match self {
            Layer::Top(t) => t.flags(),
            Layer::Bottom(b) => b.flags(),
        }
    }
}

/// True when a sample is usable for continuing a walk.
#[inline]
fn usable(bs: &Option<BSDFSample>) -> Option<BSDFSample> {
    match bs {
        Some(s) if !s.f.is_black() && s.pdf != 0.0 && s.wi.z != 0.0 => Some(*s),
        _ => None,
    }
}

/// Two interfaces `top` (at height `thickness`) and `bottom` (at 0) with a
/// medium of the given single-scattering `albedo` and Henyey–Greenstein
/// asymmetry `g` between them (unit extinction; no medium when the albedo
/// is zero). `TWO_SIDED` makes the model symmetric about the surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LayeredBxDF<Top, Bottom, const TWO_SIDED: bool> {
    top: Top,
    bottom: Bottom,
    thickness: Float,
    g: Float,
    albedo: SampledSpectrum,
    max_depth: u32,
    n_samples: u32,
    seed: i32,
}

impl<Top: BxDFMethods, Bottom: BxDFMethods, const TWO_SIDED: bool>
    LayeredBxDF<Top, Bottom, TWO_SIDED>
{
    /// A layered model. `max_depth` bounds the random walk, `n_samples`
    /// walks are averaged per evaluation.
    pub fn new(
        top: Top,
        bottom: Bottom,
        thickness: Float,
        albedo: SampledSpectrum,
        g: Float,
        max_depth: u32,
        n_samples: u32,
    ) -> Self {
        LayeredBxDF {
            top,
            bottom,
            thickness: thickness.max(Float::MIN_POSITIVE),
            g,
            albedo,
            max_depth,
            n_samples: n_samples.max(1),
            seed: 0,
        }
    }

    /// Sets the global seed mixed into the walks' random streams (pbrt-v4's
    /// `--seed` option; 0 by default).
    pub fn with_seed(mut self, seed: i32) -> Self {
        self.seed = seed;
        self
    }

    fn rng(&self, a: &[Float], b: &[Float]) -> Rng {
        Rng::new(hash_floats(Some(self.seed), a), hash_floats(None, b))
    }
}

#[inline]
fn r(rng: &mut Rng) -> Float {
    rng.uniform_float().min(ONE_MINUS_EPSILON)
}

#[inline]
fn r2(rng: &mut Rng) -> Point2f {
    let x = r(rng);
    let y = r(rng);
    Point2f::new(x, y)
}

#[inline]
fn v3(v: Vector3f) -> [Float; 3] {
    [v.x, v.y, v.z]
}

// The lane forms are the crate's business: the methods below are
// crate-private, but the bound names a crate-private trait.
#[allow(private_bounds)]
impl<Bottom: BxDFMethods + ToLanes, const TWO_SIDED: bool>
    LayeredBxDF<DielectricBxDF, Bottom, TWO_SIDED>
{
    /// True when the lane walk (`lanes/layered.rs`) computes this model:
    /// two-sided, with no medium between the interfaces.
    #[inline(always)]
    pub(crate) fn has_lane_walk(&self) -> bool {
        TWO_SIDED && self.albedo.is_black() && !scalar_walk_forced()
    }

    /// The lane form of `items[..L::N]`, which must agree in depth,
    /// sample count and seed (and have [`Self::has_lane_walk`]).
    #[inline(always)]
    pub(crate) fn gather_walk<L: F32Lanes>(items: &[&Self]) -> LayeredLanes<L, Bottom::Lanes<L>> {
        let n = items.len();
        let tops: [&DielectricBxDF; MAX_LANES] = std::array::from_fn(|i| &items[source(i, n)].top);
        let bottoms: [&Bottom; MAX_LANES] = std::array::from_fn(|i| &items[source(i, n)].bottom);
        let m = n.min(L::N);
        LayeredLanes {
            top: DielectricBxDF::gather::<L>(&tops[..m]),
            bottom: Bottom::gather::<L>(&bottoms[..m]),
            thickness: gather_f(n, |i| items[i].thickness),
            max_depth: items[0].max_depth,
            n_samples: items[0].n_samples,
            seed: items[0].seed,
        }
    }

    /// The lane walk at width one (for the scalar methods).
    #[inline(always)]
    fn walk1(&self) -> LayeredLanes<Scalar1, Bottom::Lanes<Scalar1>> {
        LayeredLanes {
            top: self.top.one(),
            bottom: self.bottom.one(),
            thickness: Scalar1(self.thickness),
            max_depth: self.max_depth,
            n_samples: self.n_samples,
            seed: self.seed,
        }
    }

    /// What a batch of these models must agree on.
    #[inline(always)]
    pub(crate) fn walk_key(&self) -> (u32, u32, i32) {
        (self.max_depth, self.n_samples, self.seed)
    }
}

/// The coated models' lane form: their walk (for models that have one,
/// [`LayeredBxDF::has_lane_walk`]).
#[allow(private_bounds)]
impl<Bottom: BxDFMethods + ToLanes> ToLanes for LayeredBxDF<DielectricBxDF, Bottom, true> {
    type Lanes<L: F32Lanes> = LayeredLanes<L, Bottom::Lanes<L>>;
    #[inline(always)]
    fn gather<L: F32Lanes>(items: &[&Self]) -> Self::Lanes<L> {
        Self::gather_walk::<L>(items)
    }
}

#[allow(private_bounds)]
impl<Bottom: BxDFMethods + ToLanes, const TWO_SIDED: bool> BxDFMethods
    for LayeredBxDF<DielectricBxDF, Bottom, TWO_SIDED>
{
    fn f(&self, wo: Vector3f, wi: Vector3f, mode: TransportMode) -> SampledSpectrum {
        if self.has_lane_walk() {
            return lanes::f1(&self.walk1(), wo, wi, mode);
        }
        let (mut wo, mut wi) = (wo, wi);
        if TWO_SIDED && wo.z < 0.0 {
            wo = -wo;
            wi = -wi;
        }
        let entered_top = TWO_SIDED || wo.z > 0.0;
        let enter: Layer<DielectricBxDF, Bottom> = if entered_top {
            Layer::Top(&self.top)
        } else {
            Layer::Bottom(&self.bottom)
        };
        let exits_bottom = same_hemisphere(wo, wi) ^ entered_top;
        let (exit, non_exit): (Layer<DielectricBxDF, Bottom>, Layer<DielectricBxDF, Bottom>) =
            if exits_bottom {
                (Layer::Bottom(&self.bottom), Layer::Top(&self.top))
            } else {
                (Layer::Top(&self.top), Layer::Bottom(&self.bottom))
            };
        let exit_z = if exits_bottom { 0.0 } else { self.thickness };
        let n_samples = self.n_samples as Float;

        let mut f = SampledSpectrum::new(0.0);
        if same_hemisphere(wo, wi) {
            f = enter.f(wo, wi, mode) * n_samples;
        }

        let mut rng = self.rng(&v3(wo), &v3(wi));
        let has_medium = !self.albedo.is_black();
        let exit_specular = exit.flags().is_specular();
        let non_exit_specular = non_exit.flags().is_specular();

        for _ in 0..self.n_samples {
            // Enter the slab from wo, and presample the exit towards wi.
            let uc = r(&mut rng);
            let u = r2(&mut rng);
            let Some(wos) =
                usable(&enter.sample_f(wo, uc, u, mode, BxDFReflTransFlags::TRANSMISSION))
            else {
                continue;
            };
            let uc = r(&mut rng);
            let u = r2(&mut rng);
            let Some(wis) =
                usable(&exit.sample_f(wi, uc, u, !mode, BxDFReflTransFlags::TRANSMISSION))
            else {
                continue;
            };

            let mut beta = wos.f * abs_cos_theta(wos.wi) / wos.pdf;
            let mut z = if entered_top { self.thickness } else { 0.0 };
            let mut w = wos.wi;

            for depth in 0..self.max_depth {
                // Russian roulette on low-throughput walks.
                if depth > 3 && beta.max_component_value() < 0.25 {
                    let q = (1.0 - beta.max_component_value()).max(0.0);
                    if r(&mut rng) < q {
                        break;
                    }
                    beta /= 1.0 - q;
                }

                if !has_medium {
                    z = if z == self.thickness {
                        0.0
                    } else {
                        self.thickness
                    };
                    beta *= tr(self.thickness, w);
                } else {
                    let sigma_t = 1.0;
                    let dz = sample_exponential(r(&mut rng), sigma_t / w.z.abs());
                    let zp = if w.z > 0.0 { z + dz } else { z - dz };
                    if zp == z {
                        continue;
                    }
                    if 0.0 < zp && zp < self.thickness {
                        // Scattering in the medium: next-event estimate through
                        // the exit interface along the presampled wis.
                        let mut wt = 1.0;
                        if !exit_specular {
                            wt = power_heuristic(
                                1.0,
                                wis.pdf,
                                1.0,
                                henyey_greenstein(dot(-w, -wis.wi), self.g),
                            );
                        }
                        f += beta
                            * self.albedo
                            * (henyey_greenstein(dot(-w, -wis.wi), self.g)
                                * wt
                                * tr(zp - exit_z, wis.wi))
                            * wis.f
                            / wis.pdf;
                        // Continue the walk with a phase-function sample.
                        let u = r2(&mut rng);
                        let (ps_wi, ps_pdf) = sample_henyey_greenstein(-w, self.g, u);
                        if ps_pdf == 0.0 || ps_wi.z == 0.0 {
                            continue;
                        }
                        // The phase value equals its density, so the weight
                        // p / pdf is one.
                        beta *= self.albedo;
                        w = ps_wi;
                        z = zp;
                        // MIS companion: the phase sample may leave through
                        // the exit interface towards wi.
                        if ((z < exit_z && w.z > 0.0) || (z > exit_z && w.z < 0.0))
                            && !exit_specular
                        {
                            let f_exit = exit.f(-w, wi, mode);
                            if !f_exit.is_black() {
                                let exit_pdf =
                                    exit.pdf(-w, wi, mode, BxDFReflTransFlags::TRANSMISSION);
                                let wt = power_heuristic(1.0, ps_pdf, 1.0, exit_pdf);
                                f += beta * tr(zp - exit_z, ps_wi) * f_exit * wt;
                            }
                        }
                        continue;
                    }
                    z = clamp(zp, 0.0, self.thickness);
                }

                if z == exit_z {
                    // Reflect off the exit interface back into the slab.
                    let uc = r(&mut rng);
                    let u = r2(&mut rng);
                    let Some(bs) =
                        usable(&exit.sample_f(-w, uc, u, mode, BxDFReflTransFlags::REFLECTION))
                    else {
                        break;
                    };
                    beta *= bs.f * abs_cos_theta(bs.wi) / bs.pdf;
                    w = bs.wi;
                } else {
                    // At the non-exit interface: next-event estimate along
                    // wis, then continue by sampling its reflection.
                    if !non_exit_specular {
                        let mut wt = 1.0;
                        if !exit_specular {
                            wt = power_heuristic(
                                1.0,
                                wis.pdf,
                                1.0,
                                non_exit.pdf(-w, -wis.wi, mode, BxDFReflTransFlags::ALL),
                            );
                        }
                        f += beta
                            * non_exit.f(-w, -wis.wi, mode)
                            * (abs_cos_theta(wis.wi) * wt * tr(self.thickness, wis.wi))
                            * wis.f
                            / wis.pdf;
                    }
                    let uc = r(&mut rng);
                    let u = r2(&mut rng);
                    let Some(bs) =
                        usable(&non_exit.sample_f(-w, uc, u, mode, BxDFReflTransFlags::REFLECTION))
                    else {
                        break;
                    };
                    beta *= bs.f * abs_cos_theta(bs.wi) / bs.pdf;
                    w = bs.wi;

                    if !exit_specular {
                        let f_exit = exit.f(-w, wi, mode);
                        if !f_exit.is_black() {
                            let mut wt = 1.0;
                            if !non_exit_specular {
                                let exit_pdf =
                                    exit.pdf(-w, wi, mode, BxDFReflTransFlags::TRANSMISSION);
                                wt = power_heuristic(1.0, bs.pdf, 1.0, exit_pdf);
                            }
                            f += beta * tr(self.thickness, bs.wi) * f_exit * wt;
                        }
                    }
                }
            }
        }
        f / n_samples
    }

    fn sample_f(
        &self,
        wo: Vector3f,
        uc: Float,
        u: Point2f,
        mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Option<BSDFSample> {
        // pbrt-v4 supports only unrestricted sampling of layered models.
        debug_assert!(sample_flags == BxDFReflTransFlags::ALL);
        if self.has_lane_walk() {
            let w = self.walk1();
            return lanes::sample_f1(&w, wo, uc, u, mode, sample_flags);
        }
        let mut wo = wo;
        let mut flip_wi = false;
        if TWO_SIDED && wo.z < 0.0 {
            wo = -wo;
            flip_wi = true;
        }

        let entered_top = TWO_SIDED || wo.z > 0.0;
        let first = if entered_top {
            self.top.sample_f(wo, uc, u, mode, BxDFReflTransFlags::ALL)
        } else {
            self.bottom
                .sample_f(wo, uc, u, mode, BxDFReflTransFlags::ALL)
        };
        let mut bs = usable(&first)?;
        if bs.is_reflection() {
            if flip_wi {
                bs.wi = -bs.wi;
            }
            bs.pdf_is_proportional = true;
            return Some(bs);
        }
        let mut w = bs.wi;
        let mut specular_path = bs.is_specular();

        let mut rng = self.rng(&v3(wo), &[uc, u.x, u.y]);

        let mut f = bs.f * abs_cos_theta(bs.wi);
        let mut pdf = bs.pdf;
        let mut z = if entered_top { self.thickness } else { 0.0 };
        let has_medium = !self.albedo.is_black();

        for depth in 0..self.max_depth {
            let rr_beta = f.max_component_value() / pdf;
            if depth > 3 && rr_beta < 0.25 {
                let q = (1.0 - rr_beta).max(0.0);
                if r(&mut rng) < q {
                    return None;
                }
                pdf *= 1.0 - q;
            }
            if w.z == 0.0 {
                return None;
            }

            if has_medium {
                let sigma_t = 1.0;
                let dz = sample_exponential(r(&mut rng), sigma_t / abs_cos_theta(w));
                let zp = if w.z > 0.0 { z + dz } else { z - dz };
                if zp == z {
                    return None;
                }
                if 0.0 < zp && zp < self.thickness {
                    let u = r2(&mut rng);
                    let (ps_wi, ps_pdf) = sample_henyey_greenstein(-w, self.g, u);
                    if ps_pdf == 0.0 || ps_wi.z == 0.0 {
                        return None;
                    }
                    f *= self.albedo * ps_pdf;
                    pdf *= ps_pdf;
                    specular_path = false;
                    w = ps_wi;
                    z = zp;
                    continue;
                }
                z = clamp(zp, 0.0, self.thickness);
            } else {
                z = if z == self.thickness {
                    0.0
                } else {
                    self.thickness
                };
                f *= tr(self.thickness, w);
            }

            let uc = r(&mut rng);
            let u = r2(&mut rng);
            let s = if z == 0.0 {
                self.bottom
                    .sample_f(-w, uc, u, mode, BxDFReflTransFlags::ALL)
            } else {
                self.top.sample_f(-w, uc, u, mode, BxDFReflTransFlags::ALL)
            };
            let bs = usable(&s)?;
            f *= bs.f;
            pdf *= bs.pdf;
            specular_path &= bs.is_specular();
            w = bs.wi;

            if bs.is_transmission() {
                // The walk left the slab.
                let mut flags = if same_hemisphere(wo, w) {
                    BxDFFlags::REFLECTION
                } else {
                    BxDFFlags::TRANSMISSION
                };
                flags |= if specular_path {
                    BxDFFlags::SPECULAR
                } else {
                    BxDFFlags::GLOSSY
                };
                if flip_wi {
                    w = -w;
                }
                return Some(BSDFSample {
                    f,
                    wi: w,
                    pdf,
                    flags,
                    eta: 1.0,
                    pdf_is_proportional: true,
                });
            }
            f *= abs_cos_theta(bs.wi);
        }
        None
    }

    fn pdf(
        &self,
        wo: Vector3f,
        wi: Vector3f,
        mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Float {
        debug_assert!(sample_flags == BxDFReflTransFlags::ALL);
        if self.has_lane_walk() {
            let w = self.walk1();
            return lanes::pdf1(&w, wo, wi, mode, sample_flags);
        }
        let (mut wo, mut wi) = (wo, wi);
        if TWO_SIDED && wo.z < 0.0 {
            wo = -wo;
            wi = -wi;
        }
        let mut rng = self.rng(&v3(wi), &v3(wo));

        let entered_top = TWO_SIDED || wo.z > 0.0;
        let n_samples = self.n_samples as Float;
        let all = BxDFReflTransFlags::ALL;
        let trans = BxDFReflTransFlags::TRANSMISSION;
        let mut pdf_sum = 0.0;
        if same_hemisphere(wo, wi) {
            let refl = BxDFReflTransFlags::REFLECTION;
            pdf_sum += n_samples
                * if entered_top {
                    self.top.pdf(wo, wi, mode, refl)
                } else {
                    self.bottom.pdf(wo, wi, mode, refl)
                };
        }

        for _ in 0..self.n_samples {
            if same_hemisphere(wo, wi) {
                // Transmission, reflection inside, transmission (TRT).
                let (r_if, t_if): (Layer<DielectricBxDF, Bottom>, Layer<DielectricBxDF, Bottom>) =
                    if entered_top {
                        (Layer::Bottom(&self.bottom), Layer::Top(&self.top))
                    } else {
                        (Layer::Top(&self.top), Layer::Bottom(&self.bottom))
                    };
                let (uc, u) = (r(&mut rng), r2(&mut rng));
                let wos = t_if.sample_f(wo, uc, u, mode, trans);
                let (uc, u) = (r(&mut rng), r2(&mut rng));
                let wis = t_if.sample_f(wi, uc, u, !mode, trans);
                let (Some(wos), Some(wis)) = (wos, wis) else {
                    continue;
                };
                if wos.f.is_black() || wos.pdf <= 0.0 || wis.f.is_black() || wis.pdf <= 0.0 {
                    continue;
                }
                if !t_if.flags().is_non_specular() {
                    pdf_sum += r_if.pdf(-wos.wi, -wis.wi, mode, all);
                } else {
                    // MIS estimate of the product of the densities.
                    let (uc, u) = (r(&mut rng), r2(&mut rng));
                    let Some(rs) = r_if.sample_f(-wos.wi, uc, u, mode, all) else {
                        continue;
                    };
                    if rs.f.is_black() || rs.pdf <= 0.0 {
                        continue;
                    }
                    if !r_if.flags().is_non_specular() {
                        pdf_sum += t_if.pdf(-rs.wi, wi, mode, all);
                    } else {
                        let r_pdf = r_if.pdf(-wos.wi, -wis.wi, mode, all);
                        pdf_sum += power_heuristic(1.0, wis.pdf, 1.0, r_pdf) * r_pdf;
                        let t_pdf = t_if.pdf(-rs.wi, wi, mode, all);
                        pdf_sum += power_heuristic(1.0, rs.pdf, 1.0, t_pdf) * t_pdf;
                    }
                }
            } else {
                // Transmission through both interfaces (TT).
                let (to_if, ti_if): (Layer<DielectricBxDF, Bottom>, Layer<DielectricBxDF, Bottom>) =
                    if entered_top {
                        (Layer::Top(&self.top), Layer::Bottom(&self.bottom))
                    } else {
                        (Layer::Bottom(&self.bottom), Layer::Top(&self.top))
                    };
                let (uc, u) = (r(&mut rng), r2(&mut rng));
                let Some(wos) = usable(&to_if.sample_f(wo, uc, u, mode, all)) else {
                    continue;
                };
                if wos.is_reflection() {
                    continue;
                }
                let (uc, u) = (r(&mut rng), r2(&mut rng));
                let Some(wis) = usable(&ti_if.sample_f(wi, uc, u, !mode, all)) else {
                    continue;
                };
                if wis.is_reflection() {
                    continue;
                }
                if to_if.flags().is_specular() {
                    pdf_sum += ti_if.pdf(-wos.wi, wi, mode, all);
                } else if ti_if.flags().is_specular() {
                    pdf_sum += to_if.pdf(wo, -wis.wi, mode, all);
                } else {
                    pdf_sum += (to_if.pdf(wo, -wis.wi, mode, all)
                        + ti_if.pdf(-wos.wi, wi, mode, all))
                        / 2.0;
                }
            }
        }
        // Mix with a uniform density to cover what the estimate misses.
        lerp(0.9, 1.0 / (4.0 * PI), pdf_sum / n_samples)
    }

    fn flags(&self) -> BxDFFlags {
        let top = self.top.flags();
        let bottom = self.bottom.flags();
        debug_assert!(top.is_transmissive() || bottom.is_transmissive());
        let mut flags = BxDFFlags::REFLECTION;
        if top.is_specular() {
            flags |= BxDFFlags::SPECULAR;
        }
        if top.is_diffuse() || bottom.is_diffuse() || !self.albedo.is_black() {
            flags |= BxDFFlags::DIFFUSE;
        } else if top.is_glossy() || bottom.is_glossy() {
            flags |= BxDFFlags::GLOSSY;
        }
        if top.is_transmissive() && bottom.is_transmissive() {
            flags |= BxDFFlags::TRANSMISSION;
        }
        flags
    }

    fn regularize(&mut self) {
        self.top.regularize();
        self.bottom.regularize();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn murmur_matches_reference_values() {
        // The empty key hashes to 0 with seed 0.
        assert_eq!(murmur_hash64a(&[]), 0);
        // Deterministic, and sensitive to every byte including the tail.
        let a = hash_floats(Some(0), &[0.1, 0.2, 0.3]);
        let b = hash_floats(Some(0), &[0.1, 0.2, 0.30001]);
        let c = hash_floats(Some(1), &[0.1, 0.2, 0.3]);
        assert_ne!(a, b);
        assert_ne!(a, c);
        assert_eq!(a, hash_floats(Some(0), &[0.1, 0.2, 0.3]));
        let d = murmur_hash64a(&[1, 2, 3, 4, 5, 6, 7, 8, 9]);
        let e = murmur_hash64a(&[1, 2, 3, 4, 5, 6, 7, 8, 10]);
        assert_ne!(d, e);
    }
}
