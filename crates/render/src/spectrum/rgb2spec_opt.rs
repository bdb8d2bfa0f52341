//! The RGB to spectrum coefficient optimiser of Jakob and Hanika (2019), as
//! pbrt-v4's `rgb2spec_opt` runs it: for each colour of a 3-D grid, fit
//! `sigmoid(A λ'² + B λ' + C)` (λ' mapped to `[0, 1]`) whose colour under the
//! gamut's illuminant matches the grid colour, by Gauss–Newton on the
//! CIELAB difference. Grid points are visited along the largest component
//! outwards from one fifth of the way up, each fit starting from its
//! neighbour's solution.
//!
//! This file stands alone (no crate imports) so `build.rs` can compile it
//! with `#[path]` to generate the tables at build time.

#![allow(
    dead_code,
    clippy::needless_range_loop,
    clippy::excessive_precision,
    clippy::neg_cmp_op_on_partial_ord
)]

/// The CIE tables' range and the 5 nm grid the optimiser integrates over.
const LAMBDA_MIN: f64 = 360.0;
const LAMBDA_MAX: f64 = 830.0;
/// Samples of the 5 nm grid over 360..=830 nm.
pub const CIE_SAMPLES: usize = 95;
/// Simpson 3/8 quadrature points: three per 5 nm segment.
const FINE_SAMPLES: usize = (CIE_SAMPLES - 1) * 3 + 1;
/// Finite-difference step for the Jacobian.
const EPSILON: f64 = 1e-4;

/// An RGB gamut as the optimiser needs it.
#[derive(Clone, Debug)]
pub struct Gamut {
    /// Converts XYZ to the gamut's RGB.
    pub xyz_to_rgb: [[f64; 3]; 3],
    /// Converts the gamut's RGB to XYZ.
    pub rgb_to_xyz: [[f64; 3]; 3],
    /// The illuminant at 5 nm steps over 360..=830 nm, normalised to
    /// roughly unit luminance.
    pub illuminant: [f64; CIE_SAMPLES],
}

/// CIE D65 at 5 nm over 360..=830 nm (relative to 100 at 560 nm).
#[rustfmt::skip]
const D65: [f64; CIE_SAMPLES] = [
    46.6383, 49.3637, 52.0891, 51.0323, 49.9755, 52.3118, 54.6482, 68.7015, 82.7549, 87.1204,
    91.486, 92.4589, 93.4318, 90.057, 86.6823, 95.7736, 104.865, 110.936, 117.008, 117.41,
    117.812, 116.336, 114.861, 115.392, 115.923, 112.367, 108.811, 109.082, 109.354, 108.578,
    107.802, 106.296, 104.79, 106.239, 107.689, 106.047, 104.405, 104.225, 104.046, 102.023,
    100.0, 98.1671, 96.3342, 96.0611, 95.788, 92.2368, 88.6856, 89.3459, 90.0062, 89.8026,
    89.5991, 88.6489, 87.6987, 85.4936, 83.2886, 83.4939, 83.6992, 81.863, 80.0268, 80.1207,
    80.2146, 81.2462, 82.2778, 80.281, 78.2842, 74.0027, 69.7213, 70.6652, 71.6091, 72.979,
    74.349, 67.9765, 61.604, 65.7448, 69.8856, 72.4863, 75.087, 69.3398, 63.5927, 55.0054,
    46.4182, 56.6118, 66.8054, 65.0941, 63.3828, 63.8434, 64.304, 61.8779, 59.4519, 55.7054,
    51.959, 54.6998, 57.4406, 58.8765, 60.3125,
];
const D65_NORM: f64 = 10566.864005283874576;

/// The ACES white (about D60) at 5 nm over 360..=830 nm; the last sample is
/// zero, as in pbrt-v4's table.
#[rustfmt::skip]
const D60: [f64; CIE_SAMPLES] = [
    38.683115, 41.014457, 42.717548, 42.264182, 41.454941, 41.763698, 46.605319, 59.226938,
    72.278594, 78.231500, 80.440600, 82.739580, 82.915027, 79.009168, 77.676264, 85.163609,
    95.681274, 103.267764, 107.954821, 109.777964, 109.559187, 108.418402, 107.758141,
    109.071548, 109.671404, 106.734741, 103.707873, 103.981942, 105.232199, 105.235867,
    104.427667, 103.052881, 102.522934, 104.371416, 106.052671, 104.948900, 103.315154,
    103.416286, 103.538599, 102.099304, 100.000000, 97.992725, 96.751421, 97.102402,
    96.712823, 93.174457, 89.921479, 90.351933, 91.999793, 92.384009, 92.098710, 91.722859,
    90.646003, 88.327552, 86.526483, 87.034239, 87.579186, 85.884584, 83.976140, 83.743140,
    84.724074, 86.450818, 87.493491, 86.546330, 83.483070, 78.268785, 74.172451, 74.275184,
    76.620385, 79.423856, 79.051849, 71.763360, 65.471371, 67.984085, 74.106079, 78.556612,
    79.527120, 75.584935, 67.307163, 55.275106, 49.273538, 59.008629, 70.892412, 70.950115,
    67.163996, 67.445480, 68.171371, 66.466636, 62.989809, 58.067786, 54.990892, 56.915942,
    60.825601, 62.987850, 0.0,
];
const D60_NORM: f64 = 10536.3;

fn normalized(table: &[f64; CIE_SAMPLES], norm: f64) -> [f64; CIE_SAMPLES] {
    table.map(|v| v / norm)
}

/// The gamut for one of pbrt-v4's colour space names (`srgb`, `rec2020`,
/// `aces2065-1`, `dci-p3`), with the matrices `rgb2spec_opt` uses.
pub fn gamut(name: &str) -> Option<Gamut> {
    let d65 = normalized(&D65, D65_NORM);
    Some(match name {
        "srgb" => Gamut {
            xyz_to_rgb: [
                [3.240479, -1.537150, -0.498535],
                [-0.969256, 1.875991, 0.041556],
                [0.055648, -0.204043, 1.057311],
            ],
            rgb_to_xyz: [
                [0.412453, 0.357580, 0.180423],
                [0.212671, 0.715160, 0.072169],
                [0.019334, 0.119193, 0.950227],
            ],
            illuminant: d65,
        },
        "rec2020" => Gamut {
            xyz_to_rgb: [
                [1.7166511880, -0.3556707838, -0.2533662814],
                [-0.6666843518, 1.6164812366, 0.0157685458],
                [0.0176398574, -0.0427706133, 0.9421031212],
            ],
            rgb_to_xyz: [
                [0.6369580483, 0.1446169036, 0.1688809752],
                [0.2627002120, 0.6779980715, 0.0593017165],
                [0.0000000000, 0.0280726930, 1.0609850577],
            ],
            illuminant: d65,
        },
        "aces2065-1" => Gamut {
            xyz_to_rgb: [
                [1.0498110175, 0.0000000000, -0.0000974845],
                [-0.4959030231, 1.3733130458, 0.0982400361],
                [0.0000000000, 0.0000000000, 0.9912520182],
            ],
            rgb_to_xyz: [
                [0.9525523959, 0.0000000000, 0.0000936786],
                [0.3439664498, 0.7281660966, -0.0721325464],
                [0.0000000000, 0.0000000000, 1.0088251844],
            ],
            illuminant: normalized(&D60, D60_NORM),
        },
        "dci-p3" => Gamut {
            xyz_to_rgb: [
                [2.4931748, -0.93126315, -0.40265882],
                [-0.82950425, 1.7626965, 0.023625137],
                [0.035853732, -0.07618918, 0.9570952],
            ],
            rgb_to_xyz: [
                [0.48663378, 0.26566276, 0.19817366],
                [0.22900413, 0.69172573, 0.079269454],
                [0.0, 0.04511256, 1.0437145],
            ],
            illuminant: d65,
        },
        _ => return None,
    })
}

/// Linear interpolation in a 5 nm table, clamped at the ends.
fn interp(data: &[f64; CIE_SAMPLES], lambda: f64) -> f64 {
    let x = (lambda - LAMBDA_MIN) * ((CIE_SAMPLES - 1) as f64 / (LAMBDA_MAX - LAMBDA_MIN));
    let offset = (x as i64).clamp(0, CIE_SAMPLES as i64 - 2) as usize;
    let w = x - offset as f64;
    (1.0 - w) * data[offset] + w * data[offset + 1]
}

/// Precomputed quadrature: per fine sample, the normalised wavelength and
/// the weighted RGB response of the matching functions under the
/// illuminant.
struct Setup {
    lambda: [f64; FINE_SAMPLES],
    rgb_tbl: [[f64; 3]; FINE_SAMPLES],
    rgb_to_xyz: [[f64; 3]; 3],
    white: [f64; 3],
}

impl Setup {
    fn new(g: &Gamut, cie_1nm: [&[f32]; 3]) -> Setup {
        // The optimiser works from the 5 nm CIE tables: every fifth entry
        // of the 1 nm ones.
        let mut cie = [[0.0f64; CIE_SAMPLES]; 3];
        for (c, t) in cie.iter_mut().zip(cie_1nm) {
            for (i, v) in c.iter_mut().enumerate() {
                *v = t[5 * i] as f64;
            }
        }
        let h = (LAMBDA_MAX - LAMBDA_MIN) / (FINE_SAMPLES - 1) as f64;
        let mut s = Setup {
            lambda: [0.0; FINE_SAMPLES],
            rgb_tbl: [[0.0; 3]; FINE_SAMPLES],
            rgb_to_xyz: g.rgb_to_xyz,
            white: [0.0; 3],
        };
        for i in 0..FINE_SAMPLES {
            let lambda = LAMBDA_MIN + i as f64 * h;
            let xyz = [
                interp(&cie[0], lambda),
                interp(&cie[1], lambda),
                interp(&cie[2], lambda),
            ];
            let illum = interp(&g.illuminant, lambda);
            let mut weight = 3.0 / 8.0 * h;
            if i == 0 || i == FINE_SAMPLES - 1 {
            } else if (i - 1) % 3 == 2 {
                weight *= 2.0;
            } else {
                weight *= 3.0;
            }
            s.lambda[i] = (lambda - LAMBDA_MIN) / (LAMBDA_MAX - LAMBDA_MIN);
            for k in 0..3 {
                for j in 0..3 {
                    s.rgb_tbl[i][k] += g.xyz_to_rgb[k][j] * xyz[j] * illum * weight;
                }
            }
            for k in 0..3 {
                s.white[k] += xyz[k] * illum * weight;
            }
        }
        s
    }

    /// CIELAB of an RGB value, relative to the illuminant's white.
    fn lab(&self, p: [f64; 3]) -> [f64; 3] {
        let m = &self.rgb_to_xyz;
        let xyz = [0, 1, 2].map(|r| m[r][0] * p[0] + m[r][1] * p[1] + m[r][2] * p[2]);
        let f = |t: f64| {
            let delta = 6.0 / 29.0;
            if t > delta * delta * delta {
                t.cbrt()
            } else {
                t / (delta * delta * 3.0) + 4.0 / 29.0
            }
        };
        let fx = f(xyz[0] / self.white[0]);
        let fy = f(xyz[1] / self.white[1]);
        let fz = f(xyz[2] / self.white[2]);
        [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
    }

    /// The RGB values of the sigmoid spectra of seven coefficient sets at
    /// once: the current one and its ± finite-difference neighbours.
    fn integrate7(&self, sets: &[[f64; 3]; 7]) -> [[f64; 3]; 7] {
        let mut out = [[0.0; 3]; 7];
        for i in 0..FINE_SAMPLES {
            let l = self.lambda[i];
            let t = &self.rgb_tbl[i];
            for (o, c) in out.iter_mut().zip(sets) {
                let x = (c[0] * l + c[1]) * l + c[2];
                let s = 0.5 * x / (1.0 + x * x).sqrt() + 0.5;
                o[0] += t[0] * s;
                o[1] += t[1] * s;
                o[2] += t[2] * s;
            }
        }
        out
    }

    /// Fits `coeffs` to `rgb`, starting from their current value.
    fn gauss_newton(&self, rgb: [f64; 3], coeffs: &mut [f64; 3]) {
        let target = self.lab(rgb);
        for _ in 0..15 {
            let mut sets = [*coeffs; 7];
            for i in 0..3 {
                sets[1 + 2 * i][i] -= EPSILON;
                sets[2 + 2 * i][i] += EPSILON;
            }
            let outs = self.integrate7(&sets);
            let labs = outs.map(|o| self.lab(o));
            let residual = [0, 1, 2].map(|j| target[j] - labs[0][j]);
            let mut jac = [[0.0; 3]; 3];
            for i in 0..3 {
                for j in 0..3 {
                    let r0 = target[j] - labs[1 + 2 * i][j];
                    let r1 = target[j] - labs[2 + 2 * i][j];
                    jac[j][i] = (r1 - r0) / (2.0 * EPSILON);
                }
            }
            let Some(x) = solve3(jac, residual) else {
                // A singular Jacobian (pbrt-v4 aborts here; it does not
                // happen for the supported gamuts): keep the current fit.
                break;
            };
            let mut r = 0.0;
            for j in 0..3 {
                coeffs[j] -= x[j];
                r += residual[j] * residual[j];
            }
            let max = coeffs[0].max(coeffs[1]).max(coeffs[2]);
            if max > 200.0 {
                for c in coeffs.iter_mut() {
                    *c *= 200.0 / max;
                }
            }
            if r < 1e-6 {
                break;
            }
        }
    }
}

/// Solves `a x = b` by Gaussian elimination with partial pivoting; `None`
/// when a pivot falls below 1e-15.
fn solve3(mut a: [[f64; 3]; 3], mut b: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let piv = (col..3).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if !(a[piv][col].abs() >= 1e-15) {
            return None;
        }
        a.swap(col, piv);
        b.swap(col, piv);
        for row in col + 1..3 {
            let f = a[row][col] / a[col][col];
            for k in col..3 {
                a[row][k] -= f * a[col][k];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 3];
    for i in (0..3).rev() {
        let mut s = b[i];
        for k in i + 1..3 {
            s -= a[i][k] * x[k];
        }
        x[i] = s / a[i][i];
    }
    Some(x)
}

/// `smoothstep(smoothstep(k / (res - 1)))`: the brightness levels of the
/// table, denser near black and white.
pub fn z_nodes(res: usize) -> Vec<f32> {
    let smoothstep = |x: f64| x * x * (3.0 - 2.0 * x);
    (0..res)
        .map(|k| smoothstep(smoothstep(k as f64 / (res - 1) as f64)) as f32)
        .collect()
}

/// Runs the optimisation on `threads` threads. Returns the z nodes and the
/// coefficients laid out `[largest component][z][y][x][3]`, already
/// converted to polynomials in λ (nm).
pub fn optimize(
    g: &Gamut,
    cie_1nm: [&[f32]; 3],
    res: usize,
    threads: usize,
) -> (Vec<f32>, Vec<f32>) {
    let setup = Setup::new(g, cie_1nm);
    let scale = z_nodes(res);
    let mut out = vec![0.0f32; 3 * 3 * res * res * res];
    // Work items: one (component, y) row each; each owns res*res*3 floats
    // per z, so split the output by (component, z) slabs after the fact.
    let rows: Vec<(usize, usize)> = (0..3).flat_map(|l| (0..res).map(move |j| (l, j))).collect();
    let threads = threads.max(1);
    let results: Vec<Vec<(usize, usize, Vec<f32>)>> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                let rows = &rows;
                let setup = &setup;
                let scale = &scale;
                s.spawn(move || {
                    rows.iter()
                        .skip(t)
                        .step_by(threads)
                        .map(|&(l, j)| (l, j, optimize_row(setup, scale, res, l, j)))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_default())
            .collect()
    });
    for (l, j, row) in results.into_iter().flatten() {
        // row is [z][x][3]
        for k in 0..res {
            let dst = (((l * res + k) * res + j) * res) * 3;
            let src = k * res * 3;
            out[dst..dst + res * 3].copy_from_slice(&row[src..src + res * 3]);
        }
    }
    (scale, out)
}

/// Fits one row of fixed largest component `l` and second-other ratio `j`:
/// every x and z. Returns `[z][x][3]`.
fn optimize_row(setup: &Setup, scale: &[f32], res: usize, l: usize, j: usize) -> Vec<f32> {
    let mut row = vec![0.0f32; res * res * 3];
    let y = j as f64 / (res - 1) as f64;
    let start = res / 5;
    for i in 0..res {
        let x = i as f64 / (res - 1) as f64;
        let mut fit = |k: usize, coeffs: &mut [f64; 3]| {
            let b = scale[k] as f64;
            let mut rgb = [0.0; 3];
            rgb[l] = b;
            rgb[(l + 1) % 3] = x * b;
            rgb[(l + 2) % 3] = y * b;
            setup.gauss_newton(rgb, coeffs);
            // From the polynomial in (λ - 360) / 470 to one in λ.
            let c0 = 360.0;
            let c1 = 1.0 / (830.0 - 360.0);
            let [a, b, c] = *coeffs;
            let idx = (k * res + i) * 3;
            row[idx] = (a * c1 * c1) as f32;
            row[idx + 1] = (b * c1 - 2.0 * a * c0 * c1 * c1) as f32;
            row[idx + 2] = (c - b * c0 * c1 + a * (c0 * c1) * (c0 * c1)) as f32;
        };
        let mut coeffs = [0.0; 3];
        for k in start..res {
            fit(k, &mut coeffs);
        }
        let mut coeffs = [0.0; 3];
        for k in (0..=start).rev() {
            fit(k, &mut coeffs);
        }
    }
    row
}
