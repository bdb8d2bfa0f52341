//! Films (pbrt-v4 book section 5.4, `film.h`/`film.cpp`): the pixel
//! sensor, the RGB, G-buffer and spectral films, and their images.
//!
//! Parallel rendering: a renderer gives each thread its own [`FilmTile`]
//! (from [`Film::make_tile`]), accumulates samples there without locks and
//! merges the tile back with [`Film::merge_tile`]. Pixel sums are plain
//! `f64` additions in sample order within a tile, so when every pixel
//! belongs to exactly one tile the image does not depend on the thread
//! count or on the merge order. Splats ([`Film::add_splat`], for
//! light-tracing integrators) are atomic `f64` additions; integrators
//! record them per unit of work in a [`SplatBuffer`] and apply the
//! buffers in a fixed order through [`OrderedSplats`], so that they too
//! do not depend on the thread count.

use std::sync::Arc;

use rpbrt_geometry::{
    Bounds2f, Bounds2i, Float, Normal3f, Point2f, Point2i, Point3f, Vector2f, Vector3f,
};

pub use partial::{
    merge_sample_ranges, splat_scale, sum_channel_names, tile_bounds, PartialError, SampleRange,
    SAMPLE_RANGE_KEY,
};
pub use splat::{OrderedSplats, SplatBuffer};

use crate::camera::FilmGeometry;
use crate::filter::Filter;
use crate::image::{Image, ImageMetadata};
use crate::spectrum::{ColorMatrix, RgbColorSpace, SampledSpectrum, SampledWavelengths, RGB};

mod create;
mod data;
mod partial;
mod pixels;
mod sensor;
mod splat;
#[cfg(test)]
mod tests;

pub use create::{create_film, FilmOverrides, FILM_NAMES, IMAGE_EXTENSIONS, MAX_RESOLUTION};
pub use pixels::{KindConfig, Pixels, SampleConfig, VarianceEstimator};
pub use sensor::{daylight_illuminant, sensor_names, white_balance, PixelSensor};

/// The surface first seen through a pixel sample, for the G-buffer film
/// (pbrt-v4 `VisibleSurface`). Geometry is in render space; the film
/// converts it to its output space.
#[derive(Clone, Copy, Debug, Default)]
pub struct VisibleSurface {
    /// Position.
    pub p: Point3f,
    /// Geometric normal, facing the viewer.
    pub n: Normal3f,
    /// Shading normal, facing the viewer.
    pub ns: Normal3f,
    /// Surface parameterisation.
    pub uv: Point2f,
    /// Time of the sample.
    pub time: Float,
    /// Change of position per pixel in x (pbrt-v4's newest `VisibleSurface`
    /// stores `dpdx`/`dpdy`; the film writes their output-space z as dz/dx).
    pub dpdx: Vector3f,
    /// Change of position per pixel in y.
    pub dpdy: Vector3f,
    /// Reflectance (albedo) of the surface at the sample's wavelengths.
    pub albedo: SampledSpectrum,
    /// Whether a surface was found.
    pub set: bool,
}

/// What all films share (pbrt-v4 `FilmBase` plus the RGB conversion).
#[derive(Debug)]
pub struct FilmCore {
    full_resolution: Point2i,
    pixel_bounds: Bounds2i,
    /// The pixels a render takes and the image holds: `pixel_bounds`, or
    /// part of it ([`Film::set_active_bounds`]).
    active: Bounds2i,
    diagonal_m: Float,
    filename: String,
    filter: Filter,
    filter_integral: Float,
    color_space: &'static RgbColorSpace,
    write_fp16: bool,
    output_rgb_from_sensor_rgb: ColorMatrix,
    config: Arc<SampleConfig>,
    pixels: Pixels,
    splat_rgb: pixels::AtomicF64s,
    splat_buckets: pixels::AtomicF64s,
}

/// Film parameters besides the sensor and the kind.
#[derive(Clone, Debug)]
pub struct FilmParams {
    /// Full image resolution.
    pub full_resolution: Point2i,
    /// The pixels rendered (non-empty, inside the image).
    pub pixel_bounds: Bounds2i,
    /// Sensor diagonal in mm.
    pub diagonal_mm: Float,
    /// Output file name.
    pub filename: String,
    /// Output colour space.
    pub color_space: &'static RgbColorSpace,
    /// Largest sensor RGB component of a sample.
    pub max_component_value: Float,
    /// Whether to write half floats.
    pub write_fp16: bool,
}

impl FilmCore {
    /// The memory a film over `pixel_bounds` of kind `kind` needs, in
    /// bytes: its sums and splats per pixel, and the float image it writes
    /// with the encoded file (for the memory budget, before the film is made).
    pub fn memory_bytes(pixel_bounds: Bounds2i, kind: &KindConfig) -> u64 {
        let n = pixel_bounds.area().max(0) as u64;
        let f64s = std::mem::size_of::<f64>();
        let (extra, channels) = match kind {
            KindConfig::Rgb => (0, 3),
            KindConfig::GBuffer { .. } => (
                std::mem::size_of::<pixels::GBufferPixel>(),
                3 + GBUFFER_CHANNELS.len(),
            ),
            // Bucket sums, weights and splats.
            KindConfig::Spectral { n_buckets, .. } => (3 * f64s * n_buckets, 3 + n_buckets),
        };
        // RGB and weight sums, RGB splats; the image and its file in floats.
        let per_pixel = 4 * f64s + 3 * f64s + extra + 2 * 4 * channels;
        n.saturating_mul(per_pixel as u64)
    }

    /// A film core; `pixel_bounds` must be non-empty and valid.
    pub fn new(p: FilmParams, filter: Filter, sensor: PixelSensor, kind: KindConfig) -> Self {
        debug_assert!(!p.pixel_bounds.is_empty());
        let n = p.pixel_bounds.area().max(0) as usize;
        let nb = match &kind {
            KindConfig::Spectral { n_buckets, .. } => *n_buckets,
            _ => 0,
        };
        let output_rgb_from_sensor_rgb =
            p.color_space.rgb_from_xyz.mul(&sensor.xyz_from_sensor_rgb);
        let pixels = Pixels::new(p.pixel_bounds, &kind);
        FilmCore {
            full_resolution: p.full_resolution,
            pixel_bounds: p.pixel_bounds,
            active: p.pixel_bounds,
            diagonal_m: p.diagonal_mm * 0.001,
            filename: p.filename,
            filter_integral: filter.integral(),
            filter,
            color_space: p.color_space,
            write_fp16: p.write_fp16,
            output_rgb_from_sensor_rgb,
            config: Arc::new(SampleConfig {
                sensor,
                max_component_value: p.max_component_value,
                kind,
            }),
            pixels,
            splat_rgb: pixels::AtomicF64s::new(3 * n),
            splat_buckets: pixels::AtomicF64s::new(nb * n),
        }
    }

    fn sensor_rgb(&self, l: SampledSpectrum, lambda: &SampledWavelengths) -> RGB {
        let rgb = self.config.sensor.to_sensor_rgb(l, lambda);
        let m = rgb.max_component_value();
        if m > self.config.max_component_value {
            rgb * (self.config.max_component_value / m)
        } else {
            rgb
        }
    }

    fn add_splat(&self, p: Point2f, l: SampledSpectrum, lambda: &SampledWavelengths) {
        let rgb = self.sensor_rgb(l, lambda);
        let r = self.filter.radius();
        let pd = Point2f::new(p.x + 0.5, p.y + 0.5);
        let b = Bounds2i::new(
            Point2i::new((pd.x - r.x).floor() as i32, (pd.y - r.y).floor() as i32),
            Point2i::new(
                (pd.x + r.x).floor() as i32 + 1,
                (pd.y + r.y).floor() as i32 + 1,
            ),
        )
        .intersect(&self.pixel_bounds);
        let spectral = match &self.config.kind {
            KindConfig::Spectral {
                lambda_min,
                lambda_max,
                n_buckets,
            } => {
                let mut ls = l;
                let lm = ls.max_component_value();
                if lm > self.config.max_component_value {
                    ls *= self.config.max_component_value / lm;
                }
                let ls = SampledSpectrum::safe_div(ls, lambda.pdf())
                    * (1.0 / crate::spectrum::N_SPECTRUM_SAMPLES as Float);
                Some((ls, *lambda_min, *lambda_max, *n_buckets))
            }
            _ => None,
        };
        for pi in b.iter() {
            let wt = self.filter.evaluate(Point2f::new(
                p.x - pi.x as Float - 0.5,
                p.y - pi.y as Float - 0.5,
            ));
            if wt == 0.0 {
                continue;
            }
            let i = self.pixels.index(pi);
            for (c, v) in [rgb.r, rgb.g, rgb.b].into_iter().enumerate() {
                self.splat_rgb.add(3 * i + c, (wt * v) as f64);
            }
            if let Some((ls, lo, hi, nb)) = spectral {
                for k in 0..crate::spectrum::N_SPECTRUM_SAMPLES {
                    let bk = KindConfig::bucket(lambda[k], lo, hi, nb);
                    self.splat_buckets.add(nb * i + bk, (wt * ls[k]) as f64);
                }
            }
        }
    }

    fn get_pixel_rgb(&self, p: Point2i, splat_scale: Float) -> RGB {
        if !self.pixel_bounds.inside_exclusive(p) {
            return RGB::new(0.0, 0.0, 0.0);
        }
        let i = self.pixels.index(p);
        self.rgb_from_sums(i, self.pixels.rgb[i], splat_scale)
    }

    /// Output RGB of pixel index `i` whose weighted sensor-RGB sums and
    /// weight sum are `px` (the film's own, or with a tile's added).
    #[inline]
    fn rgb_from_sums(&self, i: usize, px: [f64; 4], splat_scale: Float) -> RGB {
        partial::resolve_rgb(
            px,
            [0, 1, 2].map(|c| self.splat_rgb.get(3 * i + c)),
            splat_scale,
            self.filter_integral,
            &self.output_rgb_from_sensor_rgb,
        )
    }

    fn new_image(&self, channels: &[String]) -> Image {
        let d = self.active.diagonal();
        partial::output_image(self.write_fp16, Point2i::new(d.x, d.y), channels)
    }

    fn clamp16(&self, v: Float) -> Float {
        partial::clamp16(self.write_fp16, v)
    }

    fn get_image(&self, metadata: &mut ImageMetadata, splat_scale: Float) -> Image {
        let mut names: Vec<String> = ["R", "G", "B"].iter().map(|s| s.to_string()).collect();
        match &self.config.kind {
            KindConfig::Rgb => {}
            KindConfig::GBuffer { .. } => {
                names.extend(GBUFFER_CHANNELS.iter().map(|s| s.to_string()))
            }
            KindConfig::Spectral {
                lambda_min,
                lambda_max,
                n_buckets,
            } => names.extend(spectral_channel_names(*lambda_min, *lambda_max, *n_buckets)),
        }
        let mut image = self.new_image(&names);
        let pmin = self.active.p_min;
        for p in self.active.iter() {
            let rgb = self.get_pixel_rgb(p, splat_scale);
            let off = Point2i::new(p.x - pmin.x, p.y - pmin.y);
            image.set_channels(
                off,
                &[
                    self.clamp16(rgb.r),
                    self.clamp16(rgb.g),
                    self.clamp16(rgb.b),
                ],
            );
            let i = self.pixels.index(p);
            match &self.config.kind {
                KindConfig::Rgb => {}
                KindConfig::GBuffer { .. } => {
                    let g = &self.pixels.gbuffer[i];
                    let ws = self.pixels.rgb[i][3];
                    let div = |v: f64, w: f64| if w != 0.0 { v / w } else { v };
                    let a = g.albedo_sum.map(|v| div(v, ws) as Float);
                    let gw = g.weight_sum;
                    let pp = g.p_sum.map(|v| div(v, gw) as Float);
                    let norm = |v: [f64; 3]| {
                        let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                        if l > 0.0 {
                            v.map(|c| (c / l) as Float)
                        } else {
                            [0.0; 3]
                        }
                    };
                    let (n, ns) = (norm(g.n_sum), norm(g.ns_sum));
                    let vals = [
                        a[0],
                        a[1],
                        a[2],
                        pp[0],
                        pp[1],
                        pp[2],
                        div(g.dzdx_sum, gw).abs() as Float,
                        div(g.dzdy_sum, gw).abs() as Float,
                        n[0],
                        n[1],
                        n[2],
                        ns[0],
                        ns[1],
                        ns[2],
                        div(g.uv_sum[0], gw) as Float,
                        div(g.uv_sum[1], gw) as Float,
                        g.variance[0].variance() as Float,
                        g.variance[1].variance() as Float,
                        g.variance[2].variance() as Float,
                        g.variance[0].relative_variance() as Float,
                        g.variance[1].relative_variance() as Float,
                        g.variance[2].relative_variance() as Float,
                    ];
                    for (k, v) in vals.iter().enumerate() {
                        image.set_channel(off, 3 + k, *v);
                    }
                }
                KindConfig::Spectral { n_buckets, .. } => {
                    let nb = *n_buckets;
                    for b in 0..nb {
                        let (s, w) = (
                            self.pixels.buckets[2 * nb * i + b],
                            self.pixels.buckets[2 * nb * i + nb + b],
                        );
                        let mut c = 0.0;
                        if w > 0.0 {
                            c = (s / w
                                + splat_scale as f64 * self.splat_buckets.get(nb * i + b)
                                    / self.filter_integral as f64)
                                as Float;
                            c = self.clamp16(c);
                        }
                        image.set_channel(off, 3 + b, c);
                    }
                }
            }
        }
        metadata.pixel_bounds = Some(self.active);
        metadata.full_resolution = Some(self.full_resolution);
        metadata.color_space = Some(self.color_space.name.clone());
        if let KindConfig::Spectral { .. } = self.config.kind {
            metadata
                .strings
                .insert("spectralLayoutVersion".into(), vec!["1.0".into()]);
            metadata
                .strings
                .insert("emissiveUnits".into(), vec!["W.m^-2.sr^-1".into()]);
        }
        image
    }
}

/// The G-buffer film's channels after R, G, B (pbrt-v4 names).
pub const GBUFFER_CHANNELS: [&str; 22] = [
    "Albedo.R",
    "Albedo.G",
    "Albedo.B",
    "P.X",
    "P.Y",
    "P.Z",
    "dzdx",
    "dzdy",
    "N.X",
    "N.Y",
    "N.Z",
    "Ns.X",
    "Ns.Y",
    "Ns.Z",
    "u",
    "v",
    "Variance.R",
    "Variance.G",
    "Variance.B",
    "RelativeVariance.R",
    "RelativeVariance.G",
    "RelativeVariance.B",
];

/// The spectral film's bucket channels: `S0.<centre>nm` with the centre
/// printed to three decimals and `.` written `,` (OpenEXR spectral layout,
/// as pbrt-v4).
pub fn spectral_channel_names(lambda_min: Float, lambda_max: Float, n: usize) -> Vec<String> {
    (0..n)
        .map(|i| {
            let t = (i as Float + 0.5) / n as Float;
            let c = (1.0 - t) * lambda_min + t * lambda_max;
            format!("S0.{}nm", format!("{c:.3}").replace('.', ","))
        })
        .collect()
}

macro_rules! film_kind {
    ($name:ident, $doc:literal) => {
        #[doc = $doc]
        #[derive(Debug)]
        pub struct $name {
            /// The shared film state.
            pub core: FilmCore,
        }
    };
}
film_kind!(RgbFilm, "Accumulates sensor RGB (pbrt-v4 `RGBFilm`).");
film_kind!(
    GBufferFilm,
    "RGB plus geometric channels (pbrt-v4 `GBufferFilm`)."
);
film_kind!(
    SpectralFilm,
    "RGB plus spectral buckets (pbrt-v4 `SpectralFilm`)."
);

/// A film: one of pbrt-v4's three kinds.
#[derive(Debug)]
pub enum Film {
    /// `rgb`.
    Rgb(RgbFilm),
    /// `gbuffer`.
    GBuffer(GBufferFilm),
    /// `spectral`.
    Spectral(SpectralFilm),
}

impl Film {
    #[inline]
    fn core(&self) -> &FilmCore {
        match self {
            Film::Rgb(f) => &f.core,
            Film::GBuffer(f) => &f.core,
            Film::Spectral(f) => &f.core,
        }
    }
    #[inline]
    fn core_mut(&mut self) -> &mut FilmCore {
        match self {
            Film::Rgb(f) => &mut f.core,
            Film::GBuffer(f) => &mut f.core,
            Film::Spectral(f) => &mut f.core,
        }
    }

    /// Adds a radiance sample at pixel `p_film` with filter weight `weight`.
    #[inline]
    pub fn add_sample(
        &mut self,
        p_film: Point2i,
        l: SampledSpectrum,
        lambda: &SampledWavelengths,
        visible_surface: Option<&VisibleSurface>,
        weight: Float,
    ) {
        let c = self.core_mut();
        c.pixels
            .add_sample(&c.config, p_film, l, lambda, visible_surface, weight);
    }

    /// Adds a splat at continuous raster position `p` (any thread).
    pub fn add_splat(&self, p: Point2f, l: SampledSpectrum, lambda: &SampledWavelengths) {
        self.core().add_splat(p, l, lambda)
    }

    /// Samples the wavelengths a camera ray carries: importance sampling of
    /// the visible range, or uniform over the spectral film's range.
    #[inline]
    pub fn sample_wavelengths(&self, u: Float) -> SampledWavelengths {
        match &self.core().config.kind {
            KindConfig::Spectral {
                lambda_min,
                lambda_max,
                ..
            } => SampledWavelengths::sample_uniform(u, *lambda_min, *lambda_max),
            _ => SampledWavelengths::sample_visible(u),
        }
    }

    /// [`Film::sample_wavelengths`] of each of `us`, into `out` (cleared
    /// first): the same values, the visible range's computed
    /// lane-parallel at `level` (`scratch` holds their buffers).
    pub fn sample_wavelengths_many(
        &self,
        level: crate::simd::SimdLevel,
        us: &[Float],
        scratch: &mut Vec<Float>,
        out: &mut Vec<SampledWavelengths>,
    ) {
        match &self.core().config.kind {
            KindConfig::Spectral { .. } => {
                out.clear();
                out.extend(us.iter().map(|&u| self.sample_wavelengths(u)));
            }
            _ => SampledWavelengths::sample_visible_many(level, us, scratch, out),
        }
    }

    /// The film-plane area to sample: the pixel bounds grown by the filter
    /// radius less half a pixel (pbrt-v4 `FilmBase::SampleBounds`).
    pub fn sample_bounds(&self) -> Bounds2f {
        let c = self.core();
        let r: Vector2f = c.filter.radius();
        let b = c.pixel_bounds;
        Bounds2f::new(
            Point2f::new(
                b.p_min.x as Float - r.x + 0.5,
                b.p_min.y as Float - r.y + 0.5,
            ),
            Point2f::new(
                b.p_max.x as Float + r.x - 0.5,
                b.p_max.y as Float + r.y - 0.5,
            ),
        )
    }

    /// The pixels rendered.
    #[inline]
    pub fn pixel_bounds(&self) -> Bounds2i {
        self.core().pixel_bounds
    }
    /// The pixels a render takes and the image holds: the pixel bounds,
    /// unless [`Film::set_active_bounds`] chose part of them.
    #[inline]
    pub fn active_bounds(&self) -> Bounds2i {
        self.core().active
    }
    /// Renders and writes only `bounds` (non-empty, inside the pixel
    /// bounds) from now on: a tile of a film whose camera and splats still
    /// see the whole pixel bounds. Returns false (changing nothing) for
    /// bounds that do not fit.
    pub fn set_active_bounds(&mut self, bounds: Bounds2i) -> bool {
        let c = self.core_mut();
        let fits = !bounds.is_empty() && bounds.intersect(&c.pixel_bounds) == bounds;
        if fits {
            c.active = bounds;
        }
        fits
    }
    /// Forgets every sample and splat, for another render of the same film.
    pub fn reset(&mut self) {
        let c = self.core_mut();
        c.pixels = Pixels::new(c.pixel_bounds, &c.config.kind);
        c.splat_rgb = pixels::AtomicF64s::new(c.splat_rgb.len());
        c.splat_buckets = pixels::AtomicF64s::new(c.splat_buckets.len());
    }
    /// Expresses G-buffer positions and normals kept in camera space in
    /// the space of a camera placed by `ct` from now on (a camera moved by
    /// an interactive render); other films are unchanged.
    pub fn place_camera(&mut self, ct: &crate::camera::CameraTransform) {
        let c = self.core_mut();
        if let KindConfig::GBuffer {
            apply_inverse: true,
            color_space,
            ..
        } = c.config.kind
        {
            c.config = Arc::new(SampleConfig {
                sensor: c.config.sensor.clone(),
                max_component_value: c.config.max_component_value,
                kind: KindConfig::GBuffer {
                    output_from_render: ct.render_from_camera.clone(),
                    apply_inverse: true,
                    color_space,
                },
            });
        }
    }
    /// Writes to `name` from now on (format by extension).
    pub fn set_filename(&mut self, name: String) {
        self.core_mut().filename = name;
    }
    /// The full image resolution.
    #[inline]
    pub fn full_resolution(&self) -> Point2i {
        self.core().full_resolution
    }
    /// What the camera needs to know about the film.
    pub fn geometry(&self) -> FilmGeometry {
        let c = self.core();
        FilmGeometry {
            full_resolution: c.full_resolution,
            pixel_bounds: c.pixel_bounds,
            diagonal_m: c.diagonal_m,
        }
    }
    /// The output file name.
    pub fn filename(&self) -> &str {
        &self.core().filename
    }
    /// Whether `add_sample` wants a [`VisibleSurface`].
    #[inline]
    pub fn uses_visible_surface(&self) -> bool {
        matches!(self, Film::GBuffer(_))
    }
    /// The pixel sensor.
    pub fn sensor(&self) -> &PixelSensor {
        &self.core().config.sensor
    }
    /// The filter.
    pub fn filter(&self) -> &Filter {
        &self.core().filter
    }
    /// The output colour space.
    pub fn color_space(&self) -> &'static RgbColorSpace {
        self.core().color_space
    }
    /// Pixel `p`'s output RGB (weighted average plus scaled splats).
    pub fn get_pixel_rgb(&self, p: Point2i, splat_scale: Float) -> RGB {
        self.core().get_pixel_rgb(p, splat_scale)
    }
    /// The film's output RGB as it stands, with the sums of `tiles` (not
    /// yet merged) added to their pixels: what [`Film::get_image`] would
    /// give for R, G and B after merging them (unclamped), as
    /// `3 × width × height` values over the active bounds
    /// ([`Film::active_bounds`]), rows from the top. For watching a
    /// render while a wave runs: the film is only read.
    pub fn rgb_snapshot<'t>(
        &self,
        tiles: impl IntoIterator<Item = &'t FilmTile>,
        splat_scale: Float,
    ) -> Vec<f32> {
        let c = self.core();
        let b = c.active;
        let d = b.diagonal();
        let width = d.x.max(0) as usize;
        let mut out = Vec::with_capacity(3 * b.area().max(0) as usize);
        for p in b.iter() {
            let i = c.pixels.index(p);
            let rgb = c.rgb_from_sums(i, c.pixels.rgb[i], splat_scale);
            out.extend_from_slice(&[rgb.r, rgb.g, rgb.b]);
        }
        for t in tiles {
            for p in t.pixels.bounds.intersect(&b).iter() {
                let (i, j) = (c.pixels.index(p), t.pixels.index(p));
                let (a, o) = (c.pixels.rgb[i], t.pixels.rgb[j]);
                let sums = [a[0] + o[0], a[1] + o[1], a[2] + o[2], a[3] + o[3]];
                let rgb = c.rgb_from_sums(i, sums, splat_scale);
                let k = 3 * ((p.y - b.p_min.y) as usize * width + (p.x - b.p_min.x) as usize);
                out[k..k + 3].copy_from_slice(&[rgb.r, rgb.g, rgb.b]);
            }
        }
        out
    }

    /// Output RGB of radiance `l` (pbrt-v4 `ToOutputRGB`, used by SPPM).
    pub fn to_output_rgb(&self, l: SampledSpectrum, lambda: &SampledWavelengths) -> RGB {
        let c = self.core();
        RGB::from_array(
            c.output_rgb_from_sensor_rgb
                .apply(c.config.sensor.to_sensor_rgb(l, lambda).to_array()),
        )
    }
    /// The final image; records pixel bounds, full resolution and colour
    /// space in `metadata`.
    pub fn get_image(&self, metadata: &mut ImageMetadata, splat_scale: Float) -> Image {
        self.core().get_image(metadata, splat_scale)
    }
    /// Writes the final image to [`Film::filename`] (format by extension).
    pub fn write_image(
        &self,
        metadata: &ImageMetadata,
        splat_scale: Float,
    ) -> Result<(), crate::image::ImageError> {
        let mut md = metadata.clone();
        let image = self.get_image(&mut md, splat_scale);
        image.write(self.filename(), &md)
    }

    /// A tile accumulating samples for `bounds` (clipped to the film).
    pub fn make_tile(&self, bounds: Bounds2i) -> FilmTile {
        let c = self.core();
        let b = bounds.intersect(&c.pixel_bounds);
        let b = if b.is_empty() {
            Bounds2i::new(b.p_min, b.p_min)
        } else {
            b
        };
        FilmTile {
            config: c.config.clone(),
            pixels: Pixels::new(b, &c.config.kind),
        }
    }

    /// Adds a tile's sums into the film.
    pub fn merge_tile(&mut self, tile: &FilmTile) {
        self.core_mut().pixels.merge(&tile.pixels);
    }
}

/// A rectangle of a film's pixels owned by one thread.
#[derive(Debug)]
pub struct FilmTile {
    config: Arc<SampleConfig>,
    pixels: Pixels,
}

impl FilmTile {
    /// The pixels this tile covers.
    pub fn bounds(&self) -> Bounds2i {
        self.pixels.bounds
    }
    /// Adds a sample exactly as [`Film::add_sample`] would.
    #[inline]
    pub fn add_sample(
        &mut self,
        p_film: Point2i,
        l: SampledSpectrum,
        lambda: &SampledWavelengths,
        visible_surface: Option<&VisibleSurface>,
        weight: Float,
    ) {
        self.pixels
            .add_sample(&self.config, p_film, l, lambda, visible_surface, weight);
    }
}
