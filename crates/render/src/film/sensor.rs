//! The pixel sensor (pbrt-v4 book section 5.4.2, `PixelSensor` in
//! `film.h`): spectral response curves turning radiance into sensor RGB,
//! the imaging ratio, the XYZ-from-sensor-RGB matrix fitted against the
//! ColorChecker swatches, and white balancing (`WhiteBalance` in
//! `util/color.cpp`).

use rpbrt_geometry::Float;

use super::data::cie_d::{CIE_S0, CIE_S1, CIE_S2, CIE_S_LAMBDA_START, CIE_S_LAMBDA_STEP};
use super::data::sensors::{SENSORS, SENSOR_LAMBDA_START};
use super::data::swatches::{SWATCHES, SWATCH_LAMBDA_START};
use crate::spectrum::{
    cie, round_nm, ColorMatrix, DenselySampledSpectrum, RgbColorSpace, SampledSpectrum,
    SampledWavelengths, Spectrum, N_SPECTRUM_SAMPLES, RGB, XYZ,
};

/// Linear interpolation in a table sampled every `step` nm from `start`;
/// zero outside the table (as pbrt-v4's `PiecewiseLinearSpectrum`).
fn tabulated(values: &[f32], start: f32, step: f32, lambda: Float) -> Float {
    let n = values.len();
    let end = start + step * (n - 1) as f32;
    if n == 0 || lambda < start || lambda > end {
        return 0.0;
    }
    let x = (lambda - start) / step;
    let i = (x.floor() as usize).min(n.saturating_sub(2));
    let t = x - i as Float;
    if n == 1 {
        return values[0];
    }
    values[i] * (1.0 - t) + values[i + 1] * t
}

/// Sums `f(λ)` over the integer wavelengths of [360, 830] nm, as pbrt-v4's
/// `InnerProduct` and `ProjectReflectance` do.
fn sum_visible(f: impl Fn(Float) -> f64) -> f64 {
    (360..=830).map(|l| f(l as Float)).sum()
}

/// pbrt-v4's `Spectra::D`: the CIE daylight illuminant of temperature
/// `t` K (a normalised blackbody below 4000 K, where CIE D is undefined).
pub fn daylight_illuminant(t: Float) -> DenselySampledSpectrum {
    let cct = t * 1.4388 / 1.4380;
    if cct < 4000.0 {
        let bb = Spectrum::blackbody(cct);
        return DenselySampledSpectrum::from_fn(360, 830, |l| bb.evaluate(l));
    }
    let x = if cct <= 7000.0 {
        -4.607e9 / (cct * cct * cct) + 2.9678e6 / (cct * cct) + 0.09911e3 / cct + 0.244063
    } else {
        -2.0064e9 / (cct * cct * cct) + 1.9018e6 / (cct * cct) + 0.24748e3 / cct + 0.23704
    };
    let y = -3.0 * x * x + 2.870 * x - 0.275;
    let m = 0.0241 + 0.2562 * x - 0.7341 * y;
    let m1 = (-1.3515 - 1.7703 * x + 5.9114 * y) / m;
    let m2 = (0.0300 - 31.4424 * x + 30.0717 * y) / m;
    let values: Vec<f32> = (0..CIE_S0.len())
        .map(|i| (CIE_S0[i] + CIE_S1[i] * m1 + CIE_S2[i] * m2) * 0.01)
        .collect();
    DenselySampledSpectrum::from_fn(360, 830, |l| {
        tabulated(&values, CIE_S_LAMBDA_START, CIE_S_LAMBDA_STEP, l)
    })
}

/// Bradford cone response matrix (XYZ to LMS), as pbrt-v4.
const LMS_FROM_XYZ: ColorMatrix = ColorMatrix::new([
    [0.8951, 0.2664, -0.1614],
    [-0.7502, 1.7135, 0.0367],
    [0.0389, -0.0685, 1.0296],
]);
/// Its inverse, with pbrt-v4's rounding.
const XYZ_FROM_LMS: ColorMatrix = ColorMatrix::new([
    [0.986993, -0.147054, 0.159963],
    [0.432305, 0.51836, 0.0492912],
    [-0.00852866, 0.0400428, 0.968487],
]);

/// The von Kries chromatic adaptation (in Bradford LMS space) taking
/// colours seen under white `src_white` (xy) to white `target_white`.
pub fn white_balance(src_white: [Float; 2], target_white: [Float; 2]) -> ColorMatrix {
    let src = LMS_FROM_XYZ.apply(XYZ::from_xyy(src_white, 1.0).to_array());
    let dst = LMS_FROM_XYZ.apply(XYZ::from_xyy(target_white, 1.0).to_array());
    let correct = ColorMatrix::diag(dst[0] / src[0], dst[1] / src[1], dst[2] / src[2]);
    XYZ_FROM_LMS.mul(&correct).mul(&LMS_FROM_XYZ)
}

/// The 3×3 `M` minimising `Σ |M a_r − b_r|²` over the rows (pbrt-v4's
/// `LinearLeastSquares`); `None` when the normal equations are singular.
fn linear_least_squares(a: &[[f64; 3]], b: &[[f64; 3]]) -> Option<ColorMatrix> {
    let mut ata = [[0.0f64; 3]; 3];
    let mut atb = [[0.0f64; 3]; 3];
    for (ar, br) in a.iter().zip(b) {
        for i in 0..3 {
            for j in 0..3 {
                ata[i][j] += ar[i] * ar[j];
                atb[i][j] += ar[i] * br[j];
            }
        }
    }
    let inv = invert3(&ata)?;
    // X = (AᵀA)⁻¹ AᵀB solves A X ≈ B row by row; M = Xᵀ acts on columns.
    let mut m = [[0.0 as Float; 3]; 3];
    for (i, row) in m.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..3).map(|k| inv[j][k] * atb[k][i]).sum::<f64>() as Float;
        }
    }
    Some(ColorMatrix::new(m))
}

fn invert3(a: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let c =
        |r0: usize, r1: usize, c0: usize, c1: usize| a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0];
    let det = a[0][0] * c(1, 2, 1, 2) - a[0][1] * c(1, 2, 0, 2) + a[0][2] * c(1, 2, 0, 1);
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    let adj = [
        [c(1, 2, 1, 2), -c(0, 2, 1, 2), c(0, 1, 1, 2)],
        [-c(1, 2, 0, 2), c(0, 2, 0, 2), -c(0, 1, 0, 2)],
        [c(1, 2, 0, 1), -c(0, 2, 0, 1), c(0, 1, 0, 1)],
    ];
    Some(adj.map(|r| r.map(|v| v / det)))
}

/// The names of pbrt-v4's sensors: `cie1931` and the measured cameras.
pub fn sensor_names() -> impl Iterator<Item = &'static str> {
    std::iter::once("cie1931").chain(SENSORS.iter().map(|(n, _)| *n))
}

/// A pixel sensor: response curves, imaging ratio and the matrix from its
/// RGB to XYZ.
#[derive(Clone, Debug)]
pub struct PixelSensor {
    r_bar: DenselySampledSpectrum,
    g_bar: DenselySampledSpectrum,
    b_bar: DenselySampledSpectrum,
    /// The three responses side by side, per nanometre from `table_min`
    /// (the three tables cover the same range), so that a sample looks up
    /// each wavelength's index once.
    table: Vec<[Float; 3]>,
    table_min: i32,
    imaging_ratio: Float,
    /// Sensor RGB to XYZ (white balance included).
    pub xyz_from_sensor_rgb: ColorMatrix,
}

/// The responses interleaved per wavelength; empty when the tables do not
/// cover the same range (then each is looked up on its own).
fn interleave(
    r: &DenselySampledSpectrum,
    g: &DenselySampledSpectrum,
    b: &DenselySampledSpectrum,
) -> Vec<[Float; 3]> {
    let same = |s: &DenselySampledSpectrum| {
        s.lambda_min() == r.lambda_min() && s.values().len() == r.values().len()
    };
    if !(same(g) && same(b)) {
        return Vec::new();
    }
    (0..r.values().len())
        .map(|i| [r.values()[i], g.values()[i], b.values()[i]])
        .collect()
}

impl PixelSensor {
    fn with_responses(
        r_bar: DenselySampledSpectrum,
        g_bar: DenselySampledSpectrum,
        b_bar: DenselySampledSpectrum,
        imaging_ratio: Float,
        xyz_from_sensor_rgb: ColorMatrix,
    ) -> Self {
        PixelSensor {
            table: interleave(&r_bar, &g_bar, &b_bar),
            table_min: r_bar.lambda_min(),
            r_bar,
            g_bar,
            b_bar,
            imaging_ratio,
            xyz_from_sensor_rgb,
        }
    }

    /// The `cie1931` sensor: the XYZ matching functions as responses;
    /// white balanced from daylight of `wb_temp` K to the output colour
    /// space's white unless `wb_temp` is zero.
    pub fn cie1931(output: &RgbColorSpace, wb_temp: Float, imaging_ratio: Float) -> Self {
        let xyz_from_sensor_rgb = if wb_temp != 0.0 {
            let d = daylight_illuminant(wb_temp);
            let xyz = XYZ::new(
                sum_visible(|l| (cie::x().evaluate(l) * d.evaluate(l)) as f64) as Float,
                sum_visible(|l| (cie::y().evaluate(l) * d.evaluate(l)) as f64) as Float,
                sum_visible(|l| (cie::z().evaluate(l) * d.evaluate(l)) as f64) as Float,
            );
            white_balance(xyz.xy(), output.w)
        } else {
            ColorMatrix::IDENTITY
        };
        PixelSensor::with_responses(
            DenselySampledSpectrum::new(cie::x()),
            DenselySampledSpectrum::new(cie::y()),
            DenselySampledSpectrum::new(cie::z()),
            imaging_ratio,
            xyz_from_sensor_rgb,
        )
    }

    /// A measured camera sensor by pbrt-v4's name (`canon_eos_5d`...),
    /// white balanced for daylight of `wb_temp` K (pbrt-v4 uses 6500 K when
    /// the scene gives none), or `None` for an unknown name. The matrix to
    /// XYZ is the least-squares fit over the 24 ColorChecker swatches.
    pub fn camera(
        name: &str,
        output: &RgbColorSpace,
        wb_temp: Float,
        imaging_ratio: Float,
    ) -> Option<Result<Self, String>> {
        let (_, curves) = SENSORS.iter().find(|(n, _)| *n == name)?;
        let dense = |c: &[f32]| {
            DenselySampledSpectrum::from_fn(360, 830, |l| {
                tabulated(c, SENSOR_LAMBDA_START, 10.0, l)
            })
        };
        let (r_bar, g_bar, b_bar) = (dense(&curves[0]), dense(&curves[1]), dense(&curves[2]));
        let illum = daylight_illuminant(wb_temp);
        let out_illum = &output.illuminant;
        let swatch = |s: &[f32], l: Float| tabulated(s, SWATCH_LAMBDA_START, 10.0, l);
        // Normalised by the middle curve's response to the illuminant, as
        // pbrt-v4's ProjectReflectance.
        let project = |s: &[f32], ill: &dyn Fn(Float) -> Float, b: [&dyn Fn(Float) -> Float; 3]| {
            let g: f64 = sum_visible(|l| (b[1](l) * ill(l)) as f64);
            let mut r = [0.0f64; 3];
            for (c, bc) in b.iter().enumerate() {
                r[c] = sum_visible(|l| (bc(l) * swatch(s, l) * ill(l)) as f64) / g;
            }
            r
        };
        let ill = |l: Float| illum.evaluate(l);
        let oill = |l: Float| out_illum.evaluate(l);
        let (rf, gf, bf) = (
            |l: Float| r_bar.evaluate(l),
            |l: Float| g_bar.evaluate(l),
            |l: Float| b_bar.evaluate(l),
        );
        let (xf, yf, zf) = (
            |l: Float| cie::x().evaluate(l),
            |l: Float| cie::y().evaluate(l),
            |l: Float| cie::z().evaluate(l),
        );
        let sensor_white_g = sum_visible(|l| (ill(l) * gf(l)) as f64);
        let sensor_white_y = sum_visible(|l| (ill(l) * yf(l)) as f64);
        let mut rgb_camera = Vec::with_capacity(SWATCHES.len());
        let mut xyz_output = Vec::with_capacity(SWATCHES.len());
        for s in SWATCHES.iter() {
            rgb_camera.push(project(s, &ill, [&rf, &gf, &bf]));
            let xyz = project(s, &oill, [&xf, &yf, &zf]);
            xyz_output.push(xyz.map(|v| v * sensor_white_y / sensor_white_g));
        }
        let m = match linear_least_squares(&rgb_camera, &xyz_output) {
            Some(m) => m,
            None => {
                return Some(Err(format!(
                    "sensor \"{name}\": the XYZ from sensor RGB matrix could not be solved"
                )))
            }
        };
        Some(Ok(PixelSensor::with_responses(
            r_bar,
            g_bar,
            b_bar,
            imaging_ratio,
            m,
        )))
    }

    /// The imaging ratio (exposure time × ISO / 100).
    #[inline]
    pub fn imaging_ratio(&self) -> Float {
        self.imaging_ratio
    }

    /// Sensor RGB of radiance `l` carried at wavelengths `lambda`: each
    /// response's Monte Carlo estimate (values divided by the wavelength
    /// densities, averaged) times the imaging ratio. As in pbrt-v4 there is
    /// no division by `CIE_Y_INTEGRAL` here: lights are normalised to unit
    /// luminance when they are created (`scale /= SpectrumToPhotometric`).
    #[inline]
    pub fn to_sensor_rgb(&self, l: SampledSpectrum, lambda: &SampledWavelengths) -> RGB {
        let l = SampledSpectrum::safe_div(l, lambda.pdf());
        if !self.table.is_empty() {
            // The same values as the three `sample` calls below.
            let (mut r, mut g, mut b) = (
                SampledSpectrum::new(0.0),
                SampledSpectrum::new(0.0),
                SampledSpectrum::new(0.0),
            );
            for i in 0..N_SPECTRUM_SAMPLES {
                let offset = round_nm(lambda[i]) - self.table_min as i64;
                if let Some(v) = usize::try_from(offset).ok().and_then(|o| self.table.get(o)) {
                    (r[i], g[i], b[i]) = (v[0], v[1], v[2]);
                }
            }
            return RGB::new((r * l).average(), (g * l).average(), (b * l).average())
                * self.imaging_ratio;
        }
        RGB::new(
            (self.r_bar.sample(lambda) * l).average(),
            (self.g_bar.sample(lambda) * l).average(),
            (self.b_bar.sample(lambda) * l).average(),
        ) * self.imaging_ratio
    }
}
