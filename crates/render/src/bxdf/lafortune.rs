//! pbrt-v1's measured Lafortune materials (`bluepaint`, `brushedmetal`,
//! `clay`, `felt`, `primer`, `skin`; pbrt-v1 `materials/*.cpp` and the
//! `Lafortune` BxDF of `core/reflection.cpp`), which pbrt-v2 dropped.
//!
//! Lafortune et al.'s generalized cosine lobes fitted to measured
//! reflectance, one fit per RGB channel: `f = ρd/π + Σ max(0, x·wo.x·wi.x +
//! y·wo.y·wi.y + z·wo.z·wi.z)^e`, with `x = y` (isotropic) and three
//! lobes. The RGB value is turned into a spectrum at the path's
//! wavelengths (as pbrt-v4 turns an RGB it cannot bound). pbrt-v1's last
//! version sampled it like any diffuse BxDF: cosine-weighted.

use rpbrt_geometry::float::*;
use rpbrt_geometry::same_hemisphere;
use rpbrt_geometry::tuple::*;

use super::diffuse::{cosine_reflection_pdf, sample_cosine_reflection};
use super::{BSDFSample, BxDFFlags, BxDFMethods, BxDFReflTransFlags, TransportMode};
use crate::spectrum::{
    RgbColorSpace, RgbUnboundedSpectrum, SampledSpectrum, SampledWavelengths, RGB,
};

/// One lobe's coefficients, per RGB channel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LafortuneLobe {
    /// The x and y coefficient.
    pub xy: [Float; 3],
    /// The z coefficient.
    pub z: [Float; 3],
    /// The exponent.
    pub e: [Float; 3],
}

/// A fitted material: its diffuse reflectance and three lobes, per RGB
/// channel, and whether pbrt-v1 called it glossy.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LafortuneFit {
    /// The material's name in pbrt-v1.
    pub name: &'static str,
    /// The diffuse reflectance.
    pub diffuse: [Float; 3],
    /// The lobes.
    pub lobes: [LafortuneLobe; 3],
    /// pbrt-v1's `BSDF_GLOSSY` (else `BSDF_DIFFUSE`).
    pub glossy: bool,
}

const fn lobe(xy: [Float; 3], z: [Float; 3], e: [Float; 3]) -> LafortuneLobe {
    LafortuneLobe { xy, z, e }
}

const fn grey(v: Float) -> [Float; 3] {
    [v, v, v]
}

/// pbrt-v1's six fits (its `materials/<name>.cpp`), the values as it
/// wrote them.
#[allow(clippy::excessive_precision)]
pub const LAFORTUNE_FITS: [LafortuneFit; 6] = [
    LafortuneFit {
        name: "bluepaint",
        diffuse: [0.3094, 0.39667, 0.70837],
        lobes: [
            lobe(
                [0.870567, 0.857255, 0.670982],
                [0.803624, 0.774290, 0.586674],
                [21.820103, 18.597755, 7.472717],
            ),
            lobe(
                [-0.451218, -0.406681, -0.477976],
                [0.023123, 0.017625, 0.227295],
                [2.774499, 2.581499, 3.677653],
            ),
            lobe(
                [-1.031545, -1.029426, -1.026588],
                [0.706734, 0.696530, 0.687715],
                [66.899060, 63.767912, 57.489181],
            ),
        ],
        glossy: false,
    },
    LafortuneFit {
        name: "brushedmetal",
        diffuse: [0.0; 3],
        lobes: [
            lobe(
                [-1.11854, -1.11845, -1.11999],
                [1.01272, 1.01469, 1.01942],
                [15.8708, 15.6489, 15.4571],
            ),
            lobe(
                [-1.05334, -1.06409, -1.08378],
                [0.69541, 0.662178, 0.626672],
                [111.267, 88.9222, 65.2179],
            ),
            lobe(
                [-1.01684, -1.01635, -1.01529],
                [1.00132, 1.00112, 1.00108],
                [180.181, 184.152, 195.773],
            ),
        ],
        glossy: true,
    },
    LafortuneFit {
        name: "clay",
        diffuse: [0.383626, 0.260749, 0.274207],
        lobes: [
            lobe(
                [-1.089701, -1.102701, -1.107603],
                [-1.354682, -2.714801, -1.569866],
                [17.968505, 11.024489, 21.270282],
            ),
            lobe(
                [-0.733381, -0.793320, -0.848206],
                [0.676108, 0.679314, 0.726031],
                [8.219745, 9.055139, 11.261951],
            ),
            lobe(
                [-1.010548, -1.012378, -1.011263],
                [0.910783, 0.885239, 0.892451],
                [152.912795, 141.937171, 201.046802],
            ),
        ],
        glossy: false,
    },
    LafortuneFit {
        name: "felt",
        diffuse: grey(0.025865),
        lobes: [
            lobe(grey(-0.304075), grey(-0.065992), grey(3.047892)),
            lobe(grey(-0.749561), grey(-1.167929), grey(6.931827)),
            lobe(grey(1.004921), grey(-0.205529), grey(94.117332)),
        ],
        glossy: false,
    },
    LafortuneFit {
        name: "primer",
        diffuse: [0.118230, 0.121218, 0.133209],
        lobes: [
            lobe(
                [-0.399286, -1.033473, -1.058104],
                [0.167504, 0.009545, -0.068002],
                [2.466633, 7.637253, 8.117645],
            ),
            lobe(
                [-1.041861, -1.100108, -1.087779],
                [0.014375, -0.198147, -0.053605],
                [7.993722, 29.446268, 41.988990],
            ),
            lobe(
                [-1.098605, -0.379883, -0.449038],
                [-0.145110, 0.159127, 0.173224],
                [31.899719, 2.372852, 2.636161],
            ),
        ],
        glossy: false,
    },
    LafortuneFit {
        name: "skin",
        diffuse: [0.428425, 0.301341, 0.331054],
        lobes: [
            lobe(
                [-1.131747, -1.016939, -0.966018],
                [-1.209182, -1.462488, -1.222419],
                [6.421658, 3.699932, 3.524889],
            ),
            lobe(
                [-0.546570, -0.643533, -0.638934],
                [0.380123, 0.410559, 0.437367],
                [3.685044, 4.266495, 4.539742],
            ),
            lobe(
                [-0.998888, -1.020153, -1.027479],
                [0.857998, 0.703913, 0.573625],
                [64.208486, 63.919687, 43.809866],
            ),
        ],
        glossy: false,
    },
];

/// The names of [`LAFORTUNE_FITS`].
pub const LAFORTUNE_MATERIALS: [&str; 6] = [
    "bluepaint",
    "brushedmetal",
    "clay",
    "felt",
    "primer",
    "skin",
];

/// A Lafortune fit at a path's wavelengths.
#[derive(Clone, Copy, Debug)]
pub struct LafortuneBxDF {
    fit: &'static LafortuneFit,
    cs: &'static RgbColorSpace,
    lambda: SampledWavelengths,
}

impl PartialEq for LafortuneBxDF {
    fn eq(&self, o: &Self) -> bool {
        std::ptr::eq(self.fit, o.fit) && std::ptr::eq(self.cs, o.cs) && self.lambda == o.lambda
    }
}

impl LafortuneBxDF {
    /// `fit`'s BxDF, its RGB values read in `cs`, at `lambda`.
    pub fn new(
        fit: &'static LafortuneFit,
        cs: &'static RgbColorSpace,
        lambda: &SampledWavelengths,
    ) -> Self {
        LafortuneBxDF {
            fit,
            cs,
            lambda: *lambda,
        }
    }

    /// The fit's RGB value for the pair of directions.
    pub fn rgb(&self, wo: Vector3f, wi: Vector3f) -> [Float; 3] {
        let (xy, z) = (wo.x * wi.x + wo.y * wi.y, wo.z * wi.z);
        std::array::from_fn(|c| {
            let lobes: Float = self
                .fit
                .lobes
                .iter()
                .map(|l| {
                    let base = l.xy[c] * xy + l.z[c] * z;
                    if base > 0.0 {
                        base.powf(l.e[c])
                    } else {
                        0.0
                    }
                })
                .sum();
            self.fit.diffuse[c] * INV_PI + lobes
        })
    }
}

impl BxDFMethods for LafortuneBxDF {
    fn f(&self, wo: Vector3f, wi: Vector3f, _mode: TransportMode) -> SampledSpectrum {
        if !same_hemisphere(wo, wi) {
            return SampledSpectrum::new(0.0);
        }
        let [r, g, b] = self.rgb(wo, wi);
        RgbUnboundedSpectrum::new(self.cs, RGB::new(r, g, b)).sample(&self.lambda)
    }

    fn sample_f(
        &self,
        wo: Vector3f,
        _uc: Float,
        u: Point2f,
        mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Option<BSDFSample> {
        sample_cosine_reflection(wo, u, sample_flags, self.flags(), |wi| self.f(wo, wi, mode))
    }

    fn pdf(
        &self,
        wo: Vector3f,
        wi: Vector3f,
        _mode: TransportMode,
        sample_flags: BxDFReflTransFlags,
    ) -> Float {
        cosine_reflection_pdf(wo, wi, sample_flags)
    }

    fn flags(&self) -> BxDFFlags {
        if self.fit.glossy {
            BxDFFlags::GLOSSY_REFLECTION
        } else {
            BxDFFlags::DIFFUSE_REFLECTION
        }
    }

    fn regularize(&mut self) {}
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fits_evaluate_their_coefficients() {
        let fit = &LAFORTUNE_FITS[0];
        let b = LafortuneBxDF::new(
            fit,
            RgbColorSpace::srgb(),
            &SampledWavelengths::sample_visible(0.5),
        );
        // Along the normal only the z terms count.
        let n = Vector3f::new(0.0, 0.0, 1.0);
        let rgb = b.rgb(n, n);
        for (c, &got) in rgb.iter().enumerate() {
            let want = fit.diffuse[c] * INV_PI
                + fit
                    .lobes
                    .iter()
                    .map(|l| {
                        if l.z[c] > 0.0 {
                            l.z[c].powf(l.e[c])
                        } else {
                            0.0
                        }
                    })
                    .sum::<Float>();
            assert!((got - want).abs() <= 1e-5 * want, "{c}: {got} {want}");
        }
        // The names table matches the fits.
        for (f, n) in LAFORTUNE_FITS.iter().zip(LAFORTUNE_MATERIALS) {
            assert_eq!(f.name, n);
        }
    }

    #[test]
    fn fits_reflect_about_what_real_materials_do() {
        // pbrt-v1's fits are of real materials: the directional albedo of
        // every channel is positive and about 1 at most for a range of
        // view angles (midpoint rule over the hemisphere). The fits are
        // not constrained to conserve energy: brushedmetal's blue
        // reflects 1.11 at cos θ = 0.3.
        for fit in &LAFORTUNE_FITS {
            let b = LafortuneBxDF::new(
                fit,
                RgbColorSpace::srgb(),
                &SampledWavelengths::sample_visible(0.5),
            );
            for cos_o in [0.3, 0.6, 0.95] {
                let wo = Vector3f::new((1.0 - cos_o * cos_o as Float).sqrt(), 0.0, cos_o);
                let (nt, np) = (64, 128);
                let mut albedo = [0.0f64; 3];
                for i in 0..nt {
                    let ct = (i as Float + 0.5) / nt as Float;
                    let st = (1.0 - ct * ct).sqrt();
                    for j in 0..np {
                        let phi = 2.0 * PI * (j as Float + 0.5) / np as Float;
                        let wi = Vector3f::new(st * phi.cos(), st * phi.sin(), ct);
                        let f = b.rgb(wo, wi);
                        for c in 0..3 {
                            // dω = d(cos θ) dφ.
                            albedo[c] += (f[c] * ct) as f64
                                * (2.0 * std::f64::consts::PI / (nt * np) as f64);
                        }
                    }
                }
                for (c, a) in albedo.iter().enumerate() {
                    assert!(
                        *a > 0.0 && *a < 1.15,
                        "{} channel {c} at cos {cos_o}: {a}",
                        fit.name
                    );
                }
            }
        }
    }
}
