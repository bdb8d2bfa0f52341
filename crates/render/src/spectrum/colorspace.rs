//! RGB colour spaces: primaries, white illuminant, conversion matrices and
//! the RGB to spectrum tables (pbrt-v4 book sections 4.6.3 and 4.6.6;
//! pbrt-v4 `util/colorspace.h`).

use std::borrow::Cow;
use std::sync::{Arc, OnceLock};

use rpbrt_geometry::Float;

use super::color::{ColorMatrix, RgbSigmoidPolynomial, RGB, XYZ};
use super::named::named_spectrum;
use super::spectra::{spectrum_to_xyz, DenselySampledSpectrum, Spectrum};

/// Resolution of the RGB to spectrum tables along each axis.
pub const RGB_TO_SPECTRUM_RES: usize = 64;

/// Sigmoid-polynomial coefficients over a grid of RGB colours: indexed by
/// the largest component, that component's value (on the nonuniform z
/// nodes) and the other two divided by it (Jakob and Hanika 2019).
///
/// The coefficients are read where they lie: in the bytes embedded in the
/// program for the built-in colour spaces (9.4 MB each, of which a scene
/// touches the few pages its colours need), not decoded into a copy.
#[derive(Clone, Debug)]
pub struct RgbToSpectrumTable {
    z_nodes: Vec<f32>,
    /// `[largest component][z][y][x][3]`, little-endian `f32`s.
    coeffs: Cow<'static, [u8]>,
}

impl RgbToSpectrumTable {
    /// A table from z nodes and `[3][res][res][res][3]` coefficients.
    pub fn new(z_nodes: Vec<f32>, coeffs: Vec<f32>) -> Result<Self, String> {
        let bytes = coeffs.iter().flat_map(|c| c.to_le_bytes()).collect();
        Self::with_coefficient_bytes(z_nodes, Cow::Owned(bytes))
    }

    fn with_coefficient_bytes(
        z_nodes: Vec<f32>,
        coeffs: Cow<'static, [u8]>,
    ) -> Result<Self, String> {
        let res = z_nodes.len();
        if res < 2 || coeffs.len() != 4 * 9 * res * res * res {
            return Err(format!(
                "RGB to spectrum table: {} z nodes and {} coefficients do not match",
                res,
                coeffs.len() / 4
            ));
        }
        Ok(RgbToSpectrumTable { z_nodes, coeffs })
    }

    /// A table written by `build.rs`: `res` z nodes, then the
    /// coefficients, all little-endian `f32`s; the coefficients are read
    /// from `bytes` in place.
    pub fn from_le_bytes(bytes: &'static [u8], res: usize) -> Result<Self, String> {
        let Some((z, coeffs)) = bytes.split_at_checked(4 * res) else {
            return Err("RGB to spectrum table is truncated".into());
        };
        let z_nodes = z
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        Self::with_coefficient_bytes(z_nodes, Cow::Borrowed(coeffs))
    }

    /// Coefficient `i` of `coeffs` (the table's bytes).
    #[inline(always)]
    fn coeff(coeffs: &[u8], i: usize) -> f32 {
        let b = &coeffs[4 * i..4 * i + 4];
        f32::from_le_bytes([b[0], b[1], b[2], b[3]])
    }

    /// The table's resolution along each axis.
    pub fn resolution(&self) -> usize {
        self.z_nodes.len()
    }

    /// The coefficients for `rgb`, each component in `[0, 1]` (clamped),
    /// trilinearly interpolated as pbrt-v4's `RGBToSpectrumTable` does.
    pub fn lookup(&self, rgb: RGB) -> RgbSigmoidPolynomial {
        let rgb = RGB::new(
            rgb.r.clamp(0.0, 1.0),
            rgb.g.clamp(0.0, 1.0),
            rgb.b.clamp(0.0, 1.0),
        );
        // Grey: an exact constant spectrum.
        if rgb.r == rgb.g && rgb.g == rgb.b {
            let v = rgb.r;
            return RgbSigmoidPolynomial::new(0.0, 0.0, (v - 0.5) / (v * (1.0 - v)).sqrt());
        }
        let res = self.z_nodes.len();
        let maxc = if rgb.r > rgb.g {
            if rgb.r > rgb.b {
                0
            } else {
                2
            }
        } else if rgb.g > rgb.b {
            1
        } else {
            2
        };
        let z = rgb[maxc];
        let scale = (res - 1) as Float / z;
        let x = rgb[(maxc + 1) % 3] * scale;
        let y = rgb[(maxc + 2) % 3] * scale;
        let xi = (x as usize).min(res - 2);
        let yi = (y as usize).min(res - 2);
        // The last z node at or below z, kept one short of the end.
        let zi = self
            .z_nodes
            .partition_point(|&n| n < z)
            .saturating_sub(1)
            .min(res - 2);
        let dx = x - xi as Float;
        let dy = y - yi as Float;
        let dz = (z - self.z_nodes[zi]) / (self.z_nodes[zi + 1] - self.z_nodes[zi]);
        let lerp = |t: Float, a: Float, b: Float| (1.0 - t) * a + t * b;
        let coeffs: &[u8] = &self.coeffs;
        let mut c = [0.0; 3];
        for (i, ci) in c.iter_mut().enumerate() {
            let co = |ox: usize, oy: usize, oz: usize| {
                let idx = (((maxc * res + zi + oz) * res + yi + oy) * res + xi + ox) * 3 + i;
                Self::coeff(coeffs, idx)
            };
            *ci = lerp(
                dz,
                lerp(
                    dy,
                    lerp(dx, co(0, 0, 0), co(1, 0, 0)),
                    lerp(dx, co(0, 1, 0), co(1, 1, 0)),
                ),
                lerp(
                    dy,
                    lerp(dx, co(0, 0, 1), co(1, 0, 1)),
                    lerp(dx, co(0, 1, 1), co(1, 1, 1)),
                ),
            );
        }
        RgbSigmoidPolynomial::new(c[0], c[1], c[2])
    }
}

/// An RGB colour space: its primaries and white, the matrices to and from
/// XYZ, and the table turning its colours into spectra.
#[derive(Clone, Debug)]
pub struct RgbColorSpace {
    /// The name pbrt-v4 gives it (`srgb`, `rec2020`, `aces2065-1`, `dci-p3`).
    pub name: String,
    /// Red primary chromaticity.
    pub r: [Float; 2],
    /// Green primary chromaticity.
    pub g: [Float; 2],
    /// Blue primary chromaticity.
    pub b: [Float; 2],
    /// White point chromaticity (of the illuminant).
    pub w: [Float; 2],
    /// The standard illuminant RGB (1, 1, 1) emits.
    pub illuminant: Arc<DenselySampledSpectrum>,
    /// RGB to XYZ.
    pub xyz_from_rgb: ColorMatrix,
    /// XYZ to RGB.
    pub rgb_from_xyz: ColorMatrix,
    table: Arc<RgbToSpectrumTable>,
}

impl RgbColorSpace {
    /// A colour space from primaries `r`, `g`, `b`, its illuminant and its
    /// RGB to spectrum table; the matrices map RGB (1, 1, 1) to the
    /// illuminant's XYZ.
    pub fn new(
        name: &str,
        r: [Float; 2],
        g: [Float; 2],
        b: [Float; 2],
        illuminant: &Spectrum,
        table: Arc<RgbToSpectrumTable>,
    ) -> Result<Self, String> {
        let white = spectrum_to_xyz(illuminant);
        let w = white.xy();
        let (rx, gx, bx) = (
            XYZ::from_xyy(r, 1.0),
            XYZ::from_xyy(g, 1.0),
            XYZ::from_xyy(b, 1.0),
        );
        let prim = ColorMatrix::new([[rx.x, gx.x, bx.x], [rx.y, gx.y, bx.y], [rx.z, gx.z, bx.z]]);
        let inv = prim
            .inverse()
            .ok_or_else(|| format!("colour space \"{name}\": degenerate primaries"))?;
        let c = inv.apply(white.to_array());
        let xyz_from_rgb = prim.mul(&ColorMatrix::diag(c[0], c[1], c[2]));
        let rgb_from_xyz = xyz_from_rgb
            .inverse()
            .ok_or_else(|| format!("colour space \"{name}\": singular RGB to XYZ matrix"))?;
        Ok(RgbColorSpace {
            name: name.to_string(),
            r,
            g,
            b,
            w,
            illuminant: Arc::new(DenselySampledSpectrum::new(illuminant)),
            xyz_from_rgb,
            rgb_from_xyz,
            table,
        })
    }

    /// XYZ to this space's RGB.
    #[inline]
    pub fn to_rgb(&self, xyz: XYZ) -> RGB {
        RGB::from_array(self.rgb_from_xyz.apply(xyz.to_array()))
    }

    /// This space's RGB to XYZ.
    #[inline]
    pub fn to_xyz(&self, rgb: RGB) -> XYZ {
        XYZ::from_array(self.xyz_from_rgb.apply(rgb.to_array()))
    }

    /// The sigmoid polynomial whose spectrum has colour `rgb` (components
    /// in `[0, 1]`) under this space's illuminant.
    #[inline]
    pub fn rgb_to_spectrum_coeffs(&self, rgb: RGB) -> RgbSigmoidPolynomial {
        self.table.lookup(rgb)
    }

    /// The illuminant as a spectrum.
    pub fn illuminant_spectrum(&self) -> Spectrum {
        Spectrum::DenselySampled(self.illuminant.clone())
    }

    /// The names of the built-in colour spaces (pbrt-v4
    /// `RGBColorSpace::GetNamed`), as `ColorSpace` accepts them.
    pub const NAMES: &'static [&'static str] = &["aces2065-1", "dci-p3", "rec2020", "srgb"];

    /// One of the built-in colour spaces by pbrt-v4's name: `srgb`,
    /// `rec2020`, `aces2065-1` or `dci-p3`.
    pub fn get(name: &str) -> Option<&'static RgbColorSpace> {
        static SRGB: OnceLock<RgbColorSpace> = OnceLock::new();
        static REC2020: OnceLock<RgbColorSpace> = OnceLock::new();
        static ACES: OnceLock<RgbColorSpace> = OnceLock::new();
        static DCI_P3: OnceLock<RgbColorSpace> = OnceLock::new();
        let (cell, r, g, b, illum, bytes): (_, _, _, _, _, &'static [u8]) = match name {
            "srgb" => (
                &SRGB,
                [0.64, 0.33],
                [0.3, 0.6],
                [0.15, 0.06],
                "stdillum-D65",
                include_bytes!(concat!(env!("OUT_DIR"), "/rgbspec_srgb.bin")),
            ),
            "rec2020" => (
                &REC2020,
                [0.708, 0.292],
                [0.170, 0.797],
                [0.131, 0.046],
                "stdillum-D65",
                include_bytes!(concat!(env!("OUT_DIR"), "/rgbspec_rec2020.bin")),
            ),
            "aces2065-1" => (
                &ACES,
                [0.7347, 0.2653],
                [0.0, 1.0],
                [0.0001, -0.077],
                "illum-acesD60",
                include_bytes!(concat!(env!("OUT_DIR"), "/rgbspec_aces2065_1.bin")),
            ),
            "dci-p3" => (
                &DCI_P3,
                [0.680, 0.320],
                [0.265, 0.690],
                [0.150, 0.060],
                "stdillum-D65",
                include_bytes!(concat!(env!("OUT_DIR"), "/rgbspec_dci_p3.bin")),
            ),
            _ => return None,
        };
        Some(cell.get_or_init(|| {
            // The embedded data and named illuminants are generated with
            // the crate; failure here is a build defect, not user error.
            let table = RgbToSpectrumTable::from_le_bytes(bytes, RGB_TO_SPECTRUM_RES)
                .expect("embedded RGB to spectrum table is well formed");
            let illum = named_spectrum(illum).expect("built-in illuminant exists");
            RgbColorSpace::new(name, r, g, b, &illum, Arc::new(table))
                .expect("built-in colour space is valid")
        }))
    }

    /// sRGB, the default colour space.
    pub fn srgb() -> &'static RgbColorSpace {
        Self::get("srgb").expect("srgb is built in")
    }
}

/// The matrix taking RGB in `from` to RGB in `to` (through XYZ).
pub fn convert_rgb_color_space(from: &RgbColorSpace, to: &RgbColorSpace) -> ColorMatrix {
    if std::ptr::eq(from, to) {
        return ColorMatrix::IDENTITY;
    }
    to.rgb_from_xyz.mul(&from.xyz_from_rgb)
}
