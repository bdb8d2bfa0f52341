//! Textures computed from their parameters and other textures (book
//! sections 10.3 "Texture Interface and Basic Textures", 10.5 "Solid and
//! Procedural Texturing" and 10.6 "Noise"; pbrt-v4 `textures.h/.cpp`):
//! scale, mix, direction mix, bilerp, checkerboard, dots, FBm, wrinkled,
//! windy and marble.

use super::mapping::{TextureMapping2D, TextureMapping3D};
use super::noise::{fbm, noise, turbulence};
use super::{FloatTextureRef, SpectrumTextureRef, TextureEvalContext};
use crate::spectrum::{
    RgbAlbedoSpectrum, RgbColorSpace, SampledSpectrum, SampledWavelengths, Spectrum, RGB,
};
use rpbrt_geometry::float::{lerp, Float};
use rpbrt_geometry::tuple::*;

/// `(1 − w)·a + w·b`, evaluating neither texture whose weight is zero
/// (pbrt-v4's mix and checkerboard textures skip them the same way).
#[inline]
fn blend<T>(w: Float, a: impl FnOnce() -> T, b: impl FnOnce() -> T) -> T
where
    T: Default + std::ops::Mul<Float, Output = T> + std::ops::Add<Output = T>,
{
    let ta = if w != 1.0 { a() } else { T::default() };
    let tb = if w != 0.0 { b() } else { T::default() };
    ta * (1.0 - w) + tb * w
}

/// `tex * scale` (pbrt-v4 `FloatScaledTexture`).
#[derive(Clone, Debug)]
pub struct FloatScaledTexture {
    /// The texture.
    pub tex: FloatTextureRef,
    /// Its scale.
    pub scale: FloatTextureRef,
}

impl FloatScaledTexture {
    /// The value at a point; `tex` is not evaluated where the scale is 0.
    #[inline]
    pub fn evaluate(&self, ctx: &TextureEvalContext) -> Float {
        let sc = self.scale.evaluate(ctx);
        if sc == 0.0 {
            return 0.0;
        }
        self.tex.evaluate(ctx) * sc
    }
}

/// The product of two spectrum textures: rpbrt's `"tex2"` factor of a
/// `"scale"` texture, which renders pbrt-v3's scale of two textures.
#[derive(Clone, Debug)]
pub struct SpectrumProductTexture {
    /// The first factor.
    pub tex: SpectrumTextureRef,
    /// The second factor.
    pub tex2: SpectrumTextureRef,
}

impl SpectrumProductTexture {
    /// The product at a point; `tex2` is not evaluated where `tex` is 0.
    #[inline]
    pub fn evaluate(
        &self,
        ctx: &TextureEvalContext,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let a = self.tex.evaluate(ctx, lambda);
        if a.is_black() {
            return a;
        }
        a * self.tex2.evaluate(ctx, lambda)
    }
}

/// A spectrum texture times a float texture (pbrt-v4 `SpectrumScaledTexture`).
#[derive(Clone, Debug)]
pub struct SpectrumScaledTexture {
    /// The texture.
    pub tex: SpectrumTextureRef,
    /// Its scale.
    pub scale: FloatTextureRef,
}

impl SpectrumScaledTexture {
    /// The value at a point; `tex` is not evaluated where the scale is 0.
    #[inline]
    pub fn evaluate(
        &self,
        ctx: &TextureEvalContext,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let sc = self.scale.evaluate(ctx);
        if sc == 0.0 {
            return SampledSpectrum::new(0.0);
        }
        self.tex.evaluate(ctx, lambda) * sc
    }
}

/// `(1 - amount) tex1 + amount tex2` (pbrt-v4 `FloatMixTexture`).
#[derive(Clone, Debug)]
pub struct FloatMixTexture {
    /// Weighted by 1 − amount.
    pub tex1: FloatTextureRef,
    /// Weighted by amount.
    pub tex2: FloatTextureRef,
    /// The blend.
    pub amount: FloatTextureRef,
}

impl FloatMixTexture {
    /// The value at a point; a texture with weight 0 is not evaluated.
    #[inline]
    pub fn evaluate(&self, ctx: &TextureEvalContext) -> Float {
        let amt = self.amount.evaluate(ctx);
        blend(amt, || self.tex1.evaluate(ctx), || self.tex2.evaluate(ctx))
    }
}

/// Spectral `(1 - amount) tex1 + amount tex2` (pbrt-v4
/// `SpectrumMixTexture`).
#[derive(Clone, Debug)]
pub struct SpectrumMixTexture {
    /// Weighted by 1 − amount.
    pub tex1: SpectrumTextureRef,
    /// Weighted by amount.
    pub tex2: SpectrumTextureRef,
    /// The blend.
    pub amount: FloatTextureRef,
}

impl SpectrumMixTexture {
    /// The value at a point; a texture with weight 0 is not evaluated.
    #[inline]
    pub fn evaluate(
        &self,
        ctx: &TextureEvalContext,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let amt = self.amount.evaluate(ctx);
        blend(
            amt,
            || self.tex1.evaluate(ctx, lambda),
            || self.tex2.evaluate(ctx, lambda),
        )
    }
}

/// `|n·dir| tex1 + (1 − |n·dir|) tex2` (pbrt-v4 `FloatDirectionMixTexture`).
#[derive(Clone, Debug)]
pub struct FloatDirectionMixTexture {
    /// Weighted by |n·dir|.
    pub tex1: FloatTextureRef,
    /// Weighted by 1 − |n·dir|.
    pub tex2: FloatTextureRef,
    /// Unit direction in render space.
    pub dir: Vector3f,
}

impl FloatDirectionMixTexture {
    /// The value at a point; a texture with weight 0 is not evaluated.
    #[inline]
    pub fn evaluate(&self, ctx: &TextureEvalContext) -> Float {
        let amt = abs_dot(ctx.n, self.dir);
        let t1 = if amt != 0.0 {
            self.tex1.evaluate(ctx)
        } else {
            0.0
        };
        let t2 = if amt != 1.0 {
            self.tex2.evaluate(ctx)
        } else {
            0.0
        };
        amt * t1 + (1.0 - amt) * t2
    }
}

/// Spectral direction mix (pbrt-v4 `SpectrumDirectionMixTexture`).
#[derive(Clone, Debug)]
pub struct SpectrumDirectionMixTexture {
    /// Weighted by |n·dir|.
    pub tex1: SpectrumTextureRef,
    /// Weighted by 1 − |n·dir|.
    pub tex2: SpectrumTextureRef,
    /// Unit direction in render space.
    pub dir: Vector3f,
}

impl SpectrumDirectionMixTexture {
    /// The value at a point; a texture with weight 0 is not evaluated.
    #[inline]
    pub fn evaluate(
        &self,
        ctx: &TextureEvalContext,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let amt = abs_dot(ctx.n, self.dir);
        let zero = SampledSpectrum::new(0.0);
        let t1 = if amt != 0.0 {
            self.tex1.evaluate(ctx, lambda)
        } else {
            zero
        };
        let t2 = if amt != 1.0 {
            self.tex2.evaluate(ctx, lambda)
        } else {
            zero
        };
        t1 * amt + t2 * (1.0 - amt)
    }
}

/// Bilinear interpolation of four corner values over (s, t) (pbrt-v4
/// `FloatBilerpTexture`).
#[derive(Clone, Debug)]
pub struct FloatBilerpTexture {
    /// The (s, t) mapping.
    pub mapping: TextureMapping2D,
    /// Value at (0, 0).
    pub v00: Float,
    /// Value at (0, 1).
    pub v01: Float,
    /// Value at (1, 0).
    pub v10: Float,
    /// Value at (1, 1).
    pub v11: Float,
}

impl FloatBilerpTexture {
    /// The value at a point.
    #[inline]
    pub fn evaluate(&self, ctx: &TextureEvalContext) -> Float {
        let c = self.mapping.map(ctx);
        let (s, t) = (c.st.x, c.st.y);
        (1.0 - s) * (1.0 - t) * self.v00
            + s * (1.0 - t) * self.v10
            + (1.0 - s) * t * self.v01
            + s * t * self.v11
    }
}

/// Bilinear interpolation of four corner spectra (pbrt-v4
/// `SpectrumBilerpTexture`).
#[derive(Clone, Debug)]
pub struct SpectrumBilerpTexture {
    /// The (s, t) mapping.
    pub mapping: TextureMapping2D,
    /// Spectra at (0,0), (0,1), (1,0), (1,1), converted for the spectrum
    /// type the texture was created for (boxed to keep the enum small).
    pub v: Box<[Spectrum; 4]>,
}

impl SpectrumBilerpTexture {
    /// The value at a point.
    #[inline]
    pub fn evaluate(
        &self,
        ctx: &TextureEvalContext,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let c = self.mapping.map(ctx);
        let (s, t) = (c.st.x, c.st.y);
        let [v00, v01, v10, v11] = &*self.v;
        v00.sample(lambda) * ((1.0 - s) * (1.0 - t))
            + v10.sample(lambda) * (s * (1.0 - t))
            + v01.sample(lambda) * ((1.0 - s) * t)
            + v11.sample(lambda) * (s * t)
    }
}

/// The coordinates a checkerboard or dots texture uses.
#[derive(Clone, Debug)]
pub enum CheckerboardMapping {
    /// A 2-D board over (s, t).
    Planar(TextureMapping2D),
    /// A 3-D board of unit cubes in texture space.
    Solid(TextureMapping3D),
}

/// Integral of the 1-D checker function c(x) = ±1 (+1 on even cells) from
/// 0 to `x`, halved and offset: pbrt-v4's closed form for the box-filtered
/// checkerboard.
#[inline]
fn checker_integral(x: Float) -> Float {
    let y = x / 2.0 - (x / 2.0).floor() - 0.5;
    x / 2.0 + y * (1.0 - 2.0 * y.abs())
}

/// The 1-D checker function at `x` filtered by a triangle of half-width
/// `r`: +1 on even cells, −1 on odd ones, smooth across edges.
#[inline]
fn filtered_checker(x: Float, r: Float) -> Float {
    if (x - r).floor() == (x + r).floor() {
        return 1.0 - 2.0 * ((x.floor() as i32) & 1) as Float;
    }
    (checker_integral(x + r) - 2.0 * checker_integral(x) + checker_integral(x - r)) / (r * r)
}

/// The weight of the second texture of a checkerboard at a point: 0 on the
/// first texture's squares, 1 on the second's, in between where the
/// footprint straddles edges (pbrt-v4 `Checkerboard`).
pub fn checkerboard(ctx: &TextureEvalContext, mapping: &CheckerboardMapping) -> Float {
    match mapping {
        CheckerboardMapping::Planar(map) => {
            let c = map.map(ctx);
            let ds = 1.5 * c.dsdx.abs().max(c.dsdy.abs());
            let dt = 1.5 * c.dtdx.abs().max(c.dtdy.abs());
            0.5 - filtered_checker(c.st.x, ds) * filtered_checker(c.st.y, dt) / 2.0
        }
        CheckerboardMapping::Solid(map) => {
            let c = map.map(ctx);
            let dx = 1.5 * c.dpdx.x.abs().max(c.dpdy.x.abs());
            let dy = 1.5 * c.dpdx.y.abs().max(c.dpdy.y.abs());
            let dz = 1.5 * c.dpdx.z.abs().max(c.dpdy.z.abs());
            0.5 - 0.5
                * filtered_checker(c.p.x, dx)
                * filtered_checker(c.p.y, dy)
                * filtered_checker(c.p.z, dz)
        }
    }
}

/// Alternating squares (or cubes) of two textures.
#[derive(Clone, Debug)]
pub struct FloatCheckerboardTexture {
    /// The coordinates.
    pub mapping: CheckerboardMapping,
    /// Texture of the even squares.
    pub tex1: FloatTextureRef,
    /// Texture of the odd squares.
    pub tex2: FloatTextureRef,
}

impl FloatCheckerboardTexture {
    /// The value at a point.
    #[inline]
    pub fn evaluate(&self, ctx: &TextureEvalContext) -> Float {
        let w = checkerboard(ctx, &self.mapping);
        blend(w, || self.tex1.evaluate(ctx), || self.tex2.evaluate(ctx))
    }
}

/// Alternating squares (or cubes) of two spectrum textures.
#[derive(Clone, Debug)]
pub struct SpectrumCheckerboardTexture {
    /// The coordinates.
    pub mapping: CheckerboardMapping,
    /// Texture of the even squares.
    pub tex1: SpectrumTextureRef,
    /// Texture of the odd squares.
    pub tex2: SpectrumTextureRef,
}

impl SpectrumCheckerboardTexture {
    /// The value at a point.
    #[inline]
    pub fn evaluate(
        &self,
        ctx: &TextureEvalContext,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let w = checkerboard(ctx, &self.mapping);
        blend(
            w,
            || self.tex1.evaluate(ctx, lambda),
            || self.tex2.evaluate(ctx, lambda),
        )
    }
}

/// Whether (s, t) is inside the randomly placed dot of its unit cell (cells
/// centred on integers; about half of them have a dot of radius 0.35).
pub fn inside_polka_dot(st: Point2f) -> bool {
    let s_cell = (st.x + 0.5).floor();
    let t_cell = (st.y + 0.5).floor();
    if noise(s_cell + 0.5, t_cell + 0.5, 0.5) > 0.0 {
        let radius = 0.35;
        let max_shift = 0.5 - radius;
        let s_center = s_cell + max_shift * noise(s_cell + 1.5, t_cell + 2.8, 0.5);
        let t_center = t_cell + max_shift * noise(s_cell + 4.5, t_cell + 9.8, 0.5);
        let (ds, dt) = (st.x - s_center, st.y - t_center);
        return ds * ds + dt * dt < radius * radius;
    }
    false
}

/// Random polka dots of one texture over another (pbrt-v4
/// `FloatDotsTexture`).
#[derive(Clone, Debug)]
pub struct FloatDotsTexture {
    /// The (s, t) mapping.
    pub mapping: TextureMapping2D,
    /// Texture outside the dots.
    pub outside: FloatTextureRef,
    /// Texture inside the dots.
    pub inside: FloatTextureRef,
}

impl FloatDotsTexture {
    /// The value at a point.
    #[inline]
    pub fn evaluate(&self, ctx: &TextureEvalContext) -> Float {
        let c = self.mapping.map(ctx);
        if inside_polka_dot(c.st) {
            self.inside.evaluate(ctx)
        } else {
            self.outside.evaluate(ctx)
        }
    }
}

/// Random polka dots of spectrum textures (pbrt-v4 `SpectrumDotsTexture`).
#[derive(Clone, Debug)]
pub struct SpectrumDotsTexture {
    /// The (s, t) mapping.
    pub mapping: TextureMapping2D,
    /// Texture outside the dots.
    pub outside: SpectrumTextureRef,
    /// Texture inside the dots.
    pub inside: SpectrumTextureRef,
}

impl SpectrumDotsTexture {
    /// The value at a point.
    #[inline]
    pub fn evaluate(
        &self,
        ctx: &TextureEvalContext,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        let c = self.mapping.map(ctx);
        if inside_polka_dot(c.st) {
            self.inside.evaluate(ctx, lambda)
        } else {
            self.outside.evaluate(ctx, lambda)
        }
    }
}

/// Fractional Brownian motion of the texture-space point (pbrt-v4
/// `FBmTexture`).
#[derive(Clone, Debug)]
pub struct FBmTexture {
    /// The 3-D mapping.
    pub mapping: TextureMapping3D,
    /// Amplitude falloff per octave (`roughness`).
    pub omega: Float,
    /// Most octaves summed.
    pub octaves: i32,
}

impl FBmTexture {
    /// The value at a point.
    #[inline]
    pub fn evaluate(&self, ctx: &TextureEvalContext) -> Float {
        let c = self.mapping.map(ctx);
        fbm(c.p, c.dpdx, c.dpdy, self.omega, self.octaves)
    }
}

/// Turbulence of the texture-space point (pbrt-v4 `WrinkledTexture`).
#[derive(Clone, Debug)]
pub struct WrinkledTexture {
    /// The 3-D mapping.
    pub mapping: TextureMapping3D,
    /// Amplitude falloff per octave (`roughness`).
    pub omega: Float,
    /// Most octaves summed.
    pub octaves: i32,
}

impl WrinkledTexture {
    /// The value at a point.
    #[inline]
    pub fn evaluate(&self, ctx: &TextureEvalContext) -> Float {
        let c = self.mapping.map(ctx);
        turbulence(c.p, c.dpdx, c.dpdy, self.omega, self.octaves)
    }
}

/// Wind-blown waves: low-frequency FBm modulating wave heights (pbrt-v4
/// `WindyTexture`).
#[derive(Clone, Debug)]
pub struct WindyTexture {
    /// The 3-D mapping.
    pub mapping: TextureMapping3D,
}

impl WindyTexture {
    /// The value at a point.
    #[inline]
    pub fn evaluate(&self, ctx: &TextureEvalContext) -> Float {
        let c = self.mapping.map(ctx);
        let wind_strength = fbm(c.p * 0.1, c.dpdx * 0.1, c.dpdy * 0.1, 0.5, 3);
        let wave_height = fbm(c.p, c.dpdx, c.dpdy, 0.5, 6);
        wind_strength.abs() * wave_height
    }
}

/// Control points of pbrt-v4's marble colour spline.
const MARBLE_COLORS: [[Float; 3]; 9] = [
    [0.58, 0.58, 0.6],
    [0.58, 0.58, 0.6],
    [0.58, 0.58, 0.6],
    [0.5, 0.5, 0.5],
    [0.6, 0.59, 0.58],
    [0.58, 0.58, 0.6],
    [0.58, 0.58, 0.6],
    [0.2, 0.2, 0.33],
    [0.58, 0.58, 0.6],
];

/// A cubic Bézier segment at `u` (de Casteljau), per component.
fn cubic_bezier(cp: &[[Float; 3]], u: Float) -> [Float; 3] {
    let mut out = [0.0; 3];
    for (c, o) in out.iter_mut().enumerate() {
        let a = [
            lerp(u, cp[0][c], cp[1][c]),
            lerp(u, cp[1][c], cp[2][c]),
            lerp(u, cp[2][c], cp[3][c]),
        ];
        let b = [lerp(u, a[0], a[1]), lerp(u, a[1], a[2])];
        *o = lerp(u, b[0], b[1]);
    }
    out
}

/// An sRGB reflectance at the sampled wavelengths: the textures whose
/// colour is an sRGB albedo whatever the consumer (marble, pbrt-v3's uv).
fn srgb_albedo(rgb: RGB, lambda: &SampledWavelengths) -> SampledSpectrum {
    Spectrum::RgbAlbedo(RgbAlbedoSpectrum::new(RgbColorSpace::srgb(), rgb)).sample(lambda)
}

/// Marble: a sine of the height perturbed by FBm, through a colour spline
/// (pbrt-v4 `MarbleTexture`). Always an sRGB albedo, whatever the consumer.
#[derive(Clone, Debug)]
pub struct MarbleTexture {
    /// The 3-D mapping.
    pub mapping: TextureMapping3D,
    /// Most FBm octaves.
    pub octaves: i32,
    /// FBm amplitude falloff (`roughness`).
    pub omega: Float,
    /// Scale of the texture-space point.
    pub scale: Float,
    /// Strength of the FBm perturbation.
    pub variation: Float,
}

impl MarbleTexture {
    /// The RGB reflectance at a point.
    pub fn rgb(&self, ctx: &TextureEvalContext) -> RGB {
        let mut c = self.mapping.map(ctx);
        c.p *= self.scale;
        let marble = c.p.y
            + self.variation
                * fbm(
                    c.p,
                    c.dpdx * self.scale,
                    c.dpdy * self.scale,
                    self.omega,
                    self.octaves,
                );
        let mut t = 0.5 + 0.5 * marble.sin();
        let n_seg = (MARBLE_COLORS.len() - 3) as i32;
        let first = ((t * n_seg as Float).floor() as i32).clamp(0, n_seg - 1);
        t = t * n_seg as Float - first as Float;
        let first = first as usize;
        let v = cubic_bezier(&MARBLE_COLORS[first..first + 4], t);
        RGB::new(1.5 * v[0], 1.5 * v[1], 1.5 * v[2])
    }

    /// The value at a point.
    #[inline]
    pub fn evaluate(
        &self,
        ctx: &TextureEvalContext,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        srgb_albedo(self.rgb(ctx), lambda)
    }
}

/// pbrt-v3's `uv` spectrum texture, which pbrt-v4 dropped: the fractional
/// parts of the mapped (s, t) as red and green.
#[derive(Clone, Debug)]
pub struct UvTexture {
    /// The 2-D mapping.
    pub mapping: TextureMapping2D,
}

impl UvTexture {
    /// The RGB at a point: (s − ⌊s⌋, t − ⌊t⌋, 0).
    pub fn rgb(&self, ctx: &TextureEvalContext) -> RGB {
        let st = self.mapping.map(ctx).st;
        RGB::new(st.x - st.x.floor(), st.y - st.y.floor(), 0.0)
    }

    /// The value at a point.
    #[inline]
    pub fn evaluate(
        &self,
        ctx: &TextureEvalContext,
        lambda: &SampledWavelengths,
    ) -> SampledSpectrum {
        srgb_albedo(self.rgb(ctx), lambda)
    }
}
