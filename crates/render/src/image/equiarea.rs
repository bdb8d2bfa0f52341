//! Environment maps from pbrt-v3's latitude–longitude (equirectangular)
//! layout to pbrt-v4's equal-area octahedral square (book section 12.5.2;
//! pbrt-v3 `InfiniteAreaLight`, pbrt-v4 `imgtool makeequiarea`).
//!
//! pbrt-v3 reads texel coordinates (u, v) ∈ [0,1]² of an equirectangular
//! map as the light-space direction with polar angle θ = π v and azimuth
//! φ = 2π u (row 0, the top of the file, is +z). pbrt-v4 reads a square
//! image through `EqualAreaSquareToSphere`. [`equirect_to_equal_area`]
//! resamples the first into the second with the same light-space
//! directions, so a light keeps its orientation under the same transform.
//! Each output texel is the average of the source (bilinear) over pbrt-v4's
//! `makeequiarea` filter, a Gaussian of radius 1.5 texels and σ = 2, taken
//! at 6 × 6 points as `makeequiarea` takes it: the map's energy is kept and
//! a one-texel sun stays a small bright spot. pbrt-v4 draws the 36 points
//! by importance-sampling the filter in jittered strata; here they are the
//! strata's midpoints, weighted by the filter. Both estimate the same
//! filtered value (the midpoints without the random draws' noise), and the
//! midpoints of neighbouring texels fall on one grid of half-texel
//! spacing, so each source lookup serves nine texels: a 2048 × 1024 map
//! converts in about a second instead of most of a minute.

use rayon::prelude::*;
use rpbrt_geometry::{
    equal_area_square_to_sphere, spherical_phi, spherical_theta, wrap_equal_area_square_f, Float,
    Point2f, Point2i, Vector2f, Vector3f, PI,
};

use super::{Image, ImageError, WrapMode, WrapMode2D};
use crate::filter::GaussianFilter;

/// How an environment map's resolution reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnvMapLayout {
    /// Square: pbrt-v4's equal-area octahedral map.
    EqualArea,
    /// Twice as wide as high: a latitude–longitude map.
    Equirect,
}

/// The layout a `width` × `height` environment map has, or `None` when it
/// is neither square nor 2:1.
pub fn env_map_layout(resolution: Point2i) -> Option<EnvMapLayout> {
    if resolution.x <= 0 || resolution.y <= 0 {
        None
    } else if resolution.x == resolution.y {
        Some(EnvMapLayout::EqualArea)
    } else if resolution.x == 2 * resolution.y {
        Some(EnvMapLayout::Equirect)
    } else {
        None
    }
}

/// pbrt-v3's light-space direction for equirectangular coordinates `uv`:
/// θ = π v, φ = 2π u.
#[inline]
pub fn equirect_to_direction(uv: Point2f) -> Vector3f {
    let theta = uv.y * PI;
    let phi = uv.x * 2.0 * PI;
    let sin_theta = theta.sin();
    Vector3f::new(sin_theta * phi.cos(), sin_theta * phi.sin(), theta.cos())
}

/// The equirectangular coordinates of a unit light-space direction (the
/// inverse of [`equirect_to_direction`]; pbrt-v3's `Le`).
#[inline]
pub fn direction_to_equirect(w: Vector3f) -> Point2f {
    Point2f::new(spherical_phi(w) / (2.0 * PI), spherical_theta(w) / PI)
}

/// Filter points per texel side (pbrt-v4's `makeequiarea`: 6 × 6).
const SQRT_SAMPLES: usize = 6;

/// Output rows converted together: their filter points share source
/// lookups (a band of `BAND` rows evaluates `2·BAND + 4` grid rows).
const BAND: usize = 16;

/// Resamples an equirectangular map of any channels into an equal-area
/// square of `resolution` × `resolution` float texels with the same
/// channel names (see the module documentation). Texel `(u, v)` weighs the
/// source at the 36 points `(u + 0.5 + oᵢ, v + 0.5 + oⱼ)`, `oₖ = −1.25 +
/// k/2`, by the filter at `(oᵢ, oⱼ)`; those points, for all texels, are
/// the half-texel grid `X(g) = g/2 − 0.75`. A pure function of its input:
/// the same for every thread count. Lookups wrap around in φ and clamp at
/// the poles; negative results are clamped to zero, as pbrt-v4 does.
pub fn equirect_to_equal_area(latlong: &Image, resolution: i32) -> Result<Image, ImageError> {
    let res = latlong.resolution();
    if res.x <= 0 || res.y <= 0 {
        return Err(ImageError::Invalid(
            "an empty image cannot be resampled".into(),
        ));
    }
    if resolution < 1 {
        return Err(ImageError::Invalid(format!(
            "equal-area resolution {resolution} must be at least 1"
        )));
    }
    let nc = latlong.n_channels();
    let n = resolution as usize;
    let filter = GaussianFilter::new(Vector2f::new(1.5, 1.5), 2.0);
    let offset = |k: usize| -1.25 + 0.5 * k as Float;
    let mut weights = [[0.0 as Float; SQRT_SAMPLES]; SQRT_SAMPLES];
    let mut sum_weight = 0.0f64;
    for (j, row) in weights.iter_mut().enumerate() {
        for (i, w) in row.iter_mut().enumerate() {
            *w = filter.evaluate(Point2f::new(offset(i), offset(j)));
            sum_weight += *w as f64;
        }
    }
    let wrap = WrapMode2D::new(WrapMode::Repeat, WrapMode::Clamp);
    // The source at grid point (gx, gy), all channels, into `out`.
    let grid_x = 2 * n + SQRT_SAMPLES - 2;
    let lookup = |gx: usize, gy: usize, out: &mut [f32]| {
        let x = 0.5 * gx as Float - 0.75;
        let y = 0.5 * gy as Float - 0.75;
        let p = wrap_equal_area_square_f(Point2f::new(x / n as Float, y / n as Float));
        let st = direction_to_equirect(equal_area_square_to_sphere(p));
        latlong.bilerp_channels_into(st, wrap, out);
    };
    let mut data = vec![0.0f32; n * n * nc];
    data.par_chunks_mut(BAND * n * nc)
        .enumerate()
        .for_each(|(band, rows)| {
            let v0 = band * BAND;
            let n_rows = rows.len() / (n * nc);
            let grid_rows = 2 * n_rows + SQRT_SAMPLES - 2;
            // The band's grid rows 2·v0 .. 2·v0 + grid_rows.
            let mut grid = vec![0.0f32; grid_rows * grid_x * nc];
            for (r, grow) in grid.chunks_mut(grid_x * nc).enumerate() {
                for (gx, texel) in grow.chunks_mut(nc).enumerate() {
                    lookup(gx, 2 * v0 + r, texel);
                }
            }
            let mut acc = vec![0.0f64; nc];
            for (dv, out_row) in rows.chunks_mut(n * nc).enumerate() {
                for u in 0..n {
                    acc.iter_mut().for_each(|a| *a = 0.0);
                    for (j, wrow) in weights.iter().enumerate() {
                        let g = &grid[(2 * dv + j) * grid_x * nc..][..grid_x * nc];
                        for (i, &w) in wrow.iter().enumerate() {
                            let texel = &g[(2 * u + i) * nc..][..nc];
                            for (a, &t) in acc.iter_mut().zip(texel) {
                                *a += (w * t) as f64;
                            }
                        }
                    }
                    for (c, a) in acc.iter().enumerate() {
                        out_row[u * nc + c] = (a / sum_weight).max(0.0) as f32;
                    }
                }
            }
        });
    Image::from_f32(
        data,
        Point2i::new(resolution, resolution),
        latlong.channel_names(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use rpbrt_geometry::equal_area_sphere_to_square;

    /// An equirectangular RGB image from a function of direction.
    fn latlong_from(w: i32, h: i32, f: impl Fn(Vector3f) -> [f32; 3]) -> Image {
        let mut data = Vec::with_capacity((w * h * 3) as usize);
        for y in 0..h {
            for x in 0..w {
                let uv = Point2f::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
                data.extend_from_slice(&f(equirect_to_direction(uv)));
            }
        }
        Image::from_f32(data, Point2i::new(w, h), &["R", "G", "B"]).unwrap()
    }

    /// ∫ L dω of channel `c` for an equirectangular map (texel solid angles
    /// 2π/W · (cos θ0 − cos θ1)).
    fn equirect_power(im: &Image, c: usize) -> f64 {
        let r = im.resolution();
        let mut sum = 0.0;
        for y in 0..r.y {
            let t0 = PI as f64 * y as f64 / r.y as f64;
            let t1 = PI as f64 * (y + 1) as f64 / r.y as f64;
            let dw = 2.0 * std::f64::consts::PI / r.x as f64 * (t0.cos() - t1.cos());
            for x in 0..r.x {
                sum += im.get_channel(Point2i::new(x, y), c, WrapMode::Clamp.into()) as f64 * dw;
            }
        }
        sum
    }

    /// ∫ L dω of channel `c` for an equal-area map (4π/N² a texel).
    fn equal_area_power(im: &Image, c: usize) -> f64 {
        let r = im.resolution();
        let mut sum = 0.0;
        for y in 0..r.y {
            for x in 0..r.x {
                sum += im.get_channel(Point2i::new(x, y), c, WrapMode::Clamp.into()) as f64;
            }
        }
        sum * 4.0 * std::f64::consts::PI / (r.x as f64 * r.y as f64)
    }

    #[test]
    fn layouts() {
        assert_eq!(
            env_map_layout(Point2i::new(64, 64)),
            Some(EnvMapLayout::EqualArea)
        );
        assert_eq!(
            env_map_layout(Point2i::new(64, 32)),
            Some(EnvMapLayout::Equirect)
        );
        assert_eq!(env_map_layout(Point2i::new(64, 31)), None);
        assert_eq!(env_map_layout(Point2i::new(32, 64)), None);
        assert_eq!(env_map_layout(Point2i::new(0, 0)), None);
    }

    #[test]
    fn equirect_mapping_is_pbrt_v3s() {
        // θ = 0 at the top row: +z; u = 1/4, v = 1/2: +y.
        let z = equirect_to_direction(Point2f::new(0.3, 0.0));
        assert!((z.z - 1.0).abs() < 1e-6);
        let y = equirect_to_direction(Point2f::new(0.25, 0.5));
        assert!((y.y - 1.0).abs() < 1e-6 && y.x.abs() < 1e-6 && y.z.abs() < 1e-6);
        let mut rng = Rng::with_sequence(7);
        for _ in 0..1000 {
            let uv = Point2f::new(rng.uniform_float(), rng.uniform_float() * 0.98 + 0.01);
            let back = direction_to_equirect(equirect_to_direction(uv));
            let du = (back.x - uv.x).abs().min(1.0 - (back.x - uv.x).abs());
            assert!(
                du < 1e-4 && (back.y - uv.y).abs() < 1e-4,
                "{uv:?} -> {back:?}"
            );
        }
    }

    #[test]
    fn smooth_map_keeps_values_and_energy() {
        // A smooth map: each output texel must hold the map's value in its
        // direction, and the integral over the sphere must not change.
        let f = |w: Vector3f| [1.0 + 0.5 * w.z, 1.0 + 0.3 * w.x * w.y, 2.0 - w.x];
        let ll = latlong_from(128, 64, f);
        let ea = equirect_to_equal_area(&ll, 96).unwrap();
        assert_eq!(ea.resolution(), Point2i::new(96, 96));
        assert_eq!(ea.channel_names(), ll.channel_names());
        for y in (0..96).step_by(7) {
            for x in (0..96).step_by(5) {
                let w = equal_area_square_to_sphere(Point2f::new(
                    (x as f32 + 0.5) / 96.0,
                    (y as f32 + 0.5) / 96.0,
                ));
                let want = f(w);
                for (c, want) in want.iter().enumerate() {
                    let got = ea.get_channel(Point2i::new(x, y), c, WrapMode::Clamp.into());
                    assert!(
                        (got - want).abs() < 0.03,
                        "({x}, {y}) c{c}: {got} vs {want}"
                    );
                }
            }
        }
        for c in 0..3 {
            let (a, b) = (equirect_power(&ll, c), equal_area_power(&ea, c));
            assert!((a / b - 1.0).abs() < 0.005, "channel {c}: {a} vs {b}");
        }
    }

    #[test]
    fn sharp_map_keeps_energy() {
        // A checkerboard in (θ, φ) and a bright polar cap: sharp edges,
        // energy still preserved within a percent.
        let f = |w: Vector3f| {
            let st = direction_to_equirect(w);
            let check = ((st.x * 16.0) as i32 + (st.y * 8.0) as i32) % 2 == 0;
            let cap = if w.z > 0.95 { 20.0 } else { 0.0 };
            let v = if check { 1.0 } else { 0.1 } + cap;
            [v, v * 0.5, 0.2]
        };
        let ll = latlong_from(256, 128, f);
        let ea = equirect_to_equal_area(&ll, 160).unwrap();
        for c in 0..3 {
            let (a, b) = (equirect_power(&ll, c), equal_area_power(&ea, c));
            assert!((a / b - 1.0).abs() < 0.01, "channel {c}: {a} vs {b}");
        }
    }

    #[test]
    fn one_bright_texel_lands_where_pbrt_v3_puts_it() {
        let (w, h) = (64, 32);
        let (tx, ty) = (40, 9);
        let mut data = vec![0.0f32; (w * h) as usize];
        data[(ty * w + tx) as usize] = 1000.0;
        let ll = Image::from_f32(data, Point2i::new(w, h), &["Y"]).unwrap();
        let ea = equirect_to_equal_area(&ll, 64).unwrap();
        let mut best = (Point2i::new(0, 0), -1.0);
        for y in 0..64 {
            for x in 0..64 {
                let v = ea.get_channel(Point2i::new(x, y), 0, WrapMode::Clamp.into());
                if v > best.1 {
                    best = (Point2i::new(x, y), v);
                }
            }
        }
        let centre = equirect_to_direction(Point2f::new(
            (tx as f32 + 0.5) / w as f32,
            (ty as f32 + 0.5) / h as f32,
        ));
        let want = equal_area_sphere_to_square(centre);
        let got = Point2f::new(
            (best.0.x as f32 + 0.5) / 64.0,
            (best.0.y as f32 + 0.5) / 64.0,
        );
        assert!(
            (want.x - got.x).abs() <= 2.0 / 64.0 && (want.y - got.y).abs() <= 2.0 / 64.0,
            "brightest texel at {got:?}, pbrt-v3's direction maps to {want:?}"
        );
    }

    #[test]
    fn rejects_bad_sizes() {
        let ll = Image::from_f32(vec![1.0; 8], Point2i::new(4, 2), &["Y"]).unwrap();
        assert!(equirect_to_equal_area(&ll, 0).is_err());
        let empty = Image::from_f32(vec![], Point2i::new(0, 0), &["Y"]).unwrap();
        assert!(equirect_to_equal_area(&empty, 8).is_err());
    }

    #[test]
    fn same_result_on_any_thread_count() {
        let ll = latlong_from(32, 16, |w| [w.x.abs(), w.y.abs(), w.z.abs()]);
        let a = equirect_to_equal_area(&ll, 24).unwrap();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let b = pool.install(|| equirect_to_equal_area(&ll, 24).unwrap());
        assert_eq!(a, b);
    }
}
