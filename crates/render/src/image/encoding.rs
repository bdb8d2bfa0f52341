//! Colour encodings of 8-bit pixel values (pbrt-v4 `util/color.h`, `ColorEncoding`;
//! book section 4.6.4 "RGB Color Spaces" and the image-texture discussion in 10.4).
//!
//! An 8-bit image stores encoded values; these functions map them to and from linear
//! floating-point values. The sRGB curves are the exact piecewise definitions (not
//! pbrt-v4's polynomial fits); decoding of 8-bit values goes through a 256-entry table.

use std::sync::OnceLock;

/// How 8-bit pixel values relate to linear values.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum ColorEncoding {
    /// Value / 255.
    Linear,
    /// The sRGB transfer curve (the default).
    #[default]
    SRGB,
    /// (value / 255) ^ gamma.
    Gamma(f32),
}

/// Exact sRGB decoding of a value in [0, 1].
#[inline]
pub fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 {
        v * (1.0 / 12.92)
    } else {
        ((v + 0.055) * (1.0 / 1.055)).powf(2.4)
    }
}

/// Exact sRGB encoding of a linear value in [0, 1].
#[inline]
pub fn linear_to_srgb(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Linear value to an 8-bit sRGB value, clamping to [0, 1] first and rounding to the
/// nearest code (pbrt-v4 `LinearToSRGB8` without dither). NaN maps to 0.
///
/// The same code as [`linear_to_srgb8_exact`] (the formula, with a `powf`),
/// found without one: the code at the value's 1/4096th of [0, 1] from a
/// table, then stepped up past the codes' thresholds (the least values
/// that the formula rounds to each code, found once by bisection). The
/// steepest part of the curve (the linear segment, 3294 codes per unit)
/// makes a 1/4096th span at most one threshold, so it steps at most once.
#[inline]
pub fn linear_to_srgb8(v: f32) -> u8 {
    if v.is_nan() || v <= 0.0 {
        return 0;
    }
    if v >= 1.0 {
        return 255;
    }
    let t = srgb8_thresholds();
    // v·4096 is exact, so the bucket starts at or below v.
    let mut code = t.bucket_code[(v * SRGB8_BUCKETS as f32) as usize];
    while code < 255 && v >= t.at_least[code as usize] {
        code += 1;
    }
    code
}

/// [`linear_to_srgb8`] by the formula (what its tables are built from).
#[inline]
pub fn linear_to_srgb8_exact(v: f32) -> u8 {
    if v.is_nan() || v <= 0.0 {
        return 0;
    }
    if v >= 1.0 {
        return 255;
    }
    (255.0 * linear_to_srgb(v)).round().clamp(0.0, 255.0) as u8
}

/// Buckets of [0, 1) in [`linear_to_srgb8`]'s first guess.
const SRGB8_BUCKETS: usize = 4096;

/// [`linear_to_srgb8`]'s tables.
struct Srgb8Thresholds {
    /// `at_least[k]`: the least value in (0, 1) that the formula encodes as
    /// `k + 1` or more.
    at_least: [f32; 255],
    /// The code of each bucket's first value.
    bucket_code: [u8; SRGB8_BUCKETS],
}

fn srgb8_thresholds() -> &'static Srgb8Thresholds {
    static TABLES: OnceLock<Srgb8Thresholds> = OnceLock::new();
    TABLES.get_or_init(|| {
        // The formula rises with the value, so each threshold is where a
        // bisection over the positive floats' bit patterns (in the
        // floats' order) says the code first reaches k + 1.
        let at_least: [f32; 255] = std::array::from_fn(|k| {
            let want = k as u8 + 1;
            let (mut lo, mut hi) = (0u32, 1.0f32.to_bits());
            // Invariant: code(lo) < want <= code(hi).
            while hi - lo > 1 {
                let mid = lo + (hi - lo) / 2;
                if linear_to_srgb8_exact(f32::from_bits(mid)) >= want {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            f32::from_bits(hi)
        });
        let bucket_code = std::array::from_fn(|i| {
            let start = i as f32 / SRGB8_BUCKETS as f32;
            at_least.iter().take_while(|&&t| t <= start).count() as u8
        });
        Srgb8Thresholds {
            at_least,
            bucket_code,
        }
    })
}

fn srgb8_table() -> &'static [f32; 256] {
    static TABLE: OnceLock<[f32; 256]> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut t = [0.0f32; 256];
        for (i, v) in t.iter_mut().enumerate() {
            // Computed in double precision so each entry is the correctly rounded value.
            let x = i as f64 / 255.0;
            let lin = if x <= 0.04045 {
                x / 12.92
            } else {
                ((x + 0.055) / 1.055).powf(2.4)
            };
            *v = lin as f32;
        }
        t
    })
}

/// 8-bit sRGB value to linear, by table lookup (pbrt-v4 `SRGB8ToLinear`).
#[inline]
pub fn srgb8_to_linear(v: u8) -> f32 {
    srgb8_table()[v as usize]
}

impl ColorEncoding {
    /// Parses pbrt-v4's encoding names: "linear", "sRGB", "gamma <value>".
    pub fn parse(s: &str) -> Option<ColorEncoding> {
        match s {
            "linear" => Some(ColorEncoding::Linear),
            "sRGB" | "srgb" => Some(ColorEncoding::SRGB),
            _ => {
                let rest = s.strip_prefix("gamma ")?;
                let g: f32 = rest.trim().parse().ok()?;
                (g.is_finite() && g > 0.0).then_some(ColorEncoding::Gamma(g))
            }
        }
    }

    /// The name in pbrt-v4's syntax.
    pub fn name(&self) -> String {
        match self {
            ColorEncoding::Linear => "linear".to_string(),
            ColorEncoding::SRGB => "sRGB".to_string(),
            ColorEncoding::Gamma(g) => format!("gamma {g}"),
        }
    }

    /// Decodes one 8-bit value to linear.
    #[inline]
    pub fn to_linear(&self, v: u8) -> f32 {
        match self {
            ColorEncoding::Linear => v as f32 * (1.0 / 255.0),
            ColorEncoding::SRGB => srgb8_to_linear(v),
            ColorEncoding::Gamma(g) => (v as f32 * (1.0 / 255.0)).powf(*g),
        }
    }

    /// Decodes a continuous encoded value in [0, 1] to linear (pbrt-v4 `ToFloatLinear`,
    /// used for 16-bit PNGs).
    #[inline]
    pub fn to_float_linear(&self, v: f32) -> f32 {
        match self {
            ColorEncoding::Linear => v,
            ColorEncoding::SRGB => srgb_to_linear(v),
            ColorEncoding::Gamma(g) => v.powf(*g),
        }
    }

    /// Encodes a linear value to 8 bits, clamping to [0, 1] and rounding.
    #[inline]
    pub fn from_linear(&self, v: f32) -> u8 {
        match self {
            ColorEncoding::Linear => (v * 255.0 + 0.5).clamp(0.0, 255.0) as u8,
            ColorEncoding::SRGB => linear_to_srgb8(v),
            ColorEncoding::Gamma(g) => {
                let v = if v.is_nan() { 0.0 } else { v.clamp(0.0, 1.0) };
                (v.powf(1.0 / g) * 255.0 + 0.5).clamp(0.0, 255.0) as u8
            }
        }
    }

    /// A hashable key (gamma compared by bit pattern), for caches.
    pub fn key(&self) -> (u8, u32) {
        match self {
            ColorEncoding::Linear => (0, 0),
            ColorEncoding::SRGB => (1, 0),
            ColorEncoding::Gamma(g) => (2, g.to_bits()),
        }
    }
}
