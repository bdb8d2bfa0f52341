//! Majorants for delta tracking (pbrt-v4 `MajorantGrid`,
//! `HomogeneousMajorantIterator` and `DDAMajorantIterator`; book section
//! 11.4): bounds on a medium's extinction along a ray, as segments of
//! constant majorant. A coarse grid of per-voxel maximum densities, walked
//! with a 3-D DDA, keeps the majorant close to the true density so that
//! delta tracking takes few null collisions.

use crate::spectrum::SampledSpectrum;
use rpbrt_geometry::float::Float;
use rpbrt_geometry::ray::Ray;
use rpbrt_geometry::transform::Transform;
use rpbrt_geometry::tuple::*;
use rpbrt_geometry::Bounds3f;

/// A stretch `[t_min, t_max]` of a ray over which the extinction is at
/// most `sigma_maj` (pbrt-v4 `RayMajorantSegment`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayMajorantSegment {
    /// Where the segment starts (ray parameter).
    pub t_min: Float,
    /// Where it ends.
    pub t_max: Float,
    /// The majorant extinction over the segment.
    pub sigma_maj: SampledSpectrum,
}

/// A grid of maximum densities over a medium's bounds, for the DDA
/// iterator (pbrt-v4 `MajorantGrid`). Voxel `(x, y, z)` covers
/// `[x/res.x, (x+1)/res.x] × …` of the bounds in their `[0, 1]³`
/// parametrisation.
#[derive(Clone, Debug)]
pub struct MajorantGrid {
    /// The region the grid covers, in medium space.
    pub bounds: Bounds3f,
    /// Per-voxel maxima, x fastest.
    voxels: Vec<Float>,
    /// Resolution per axis.
    pub res: [i32; 3],
}

impl MajorantGrid {
    /// A grid of zeros over `bounds` at resolution `res` (each at least 1).
    pub fn new(bounds: Bounds3f, res: [i32; 3]) -> Self {
        let res = res.map(|r| r.max(1));
        MajorantGrid {
            bounds,
            voxels: vec![0.0; (res[0] * res[1] * res[2]) as usize],
            res,
        }
    }

    #[inline]
    fn index(&self, x: i32, y: i32, z: i32) -> usize {
        (x + self.res[0] * (y + self.res[1] * z)) as usize
    }

    /// The maximum density stored for a voxel.
    #[inline]
    pub fn lookup(&self, x: i32, y: i32, z: i32) -> Float {
        self.voxels[self.index(x, y, z)]
    }

    /// Stores a voxel's maximum density.
    #[inline]
    pub fn set(&mut self, x: i32, y: i32, z: i32, v: Float) {
        let i = self.index(x, y, z);
        self.voxels[i] = v;
    }

    /// A voxel's region in the `[0, 1]³` parametrisation of the bounds.
    pub fn voxel_bounds(&self, x: i32, y: i32, z: i32) -> Bounds3f {
        let r = self.res.map(|r| r as Float);
        Bounds3f::new(
            Point3f::new(x as Float / r[0], y as Float / r[1], z as Float / r[2]),
            Point3f::new(
                (x + 1) as Float / r[0],
                (y + 1) as Float / r[1],
                (z + 1) as Float / r[2],
            ),
        )
    }

    /// Fills every voxel with `f(voxel bounds in [0, 1]³)`, slices of
    /// constant z in parallel (each voxel's value depends on it alone).
    pub fn fill(&mut self, f: impl Fn(&Bounds3f) -> Float + Sync) {
        use rayon::prelude::*;
        let [rx, ry, _] = self.res;
        let slice = (rx * ry) as usize;
        let this = MajorantGrid {
            bounds: self.bounds,
            voxels: Vec::new(),
            res: self.res,
        };
        self.voxels
            .par_chunks_mut(slice)
            .enumerate()
            .for_each(|(z, out)| {
                for y in 0..ry {
                    for x in 0..rx {
                        let b = this.voxel_bounds(x, y, z as i32);
                        out[(x + rx * y) as usize] = f(&b);
                    }
                }
            });
    }
}

/// The single segment of a homogeneous medium (pbrt-v4
/// `HomogeneousMajorantIterator`).
#[derive(Clone, Copy, Debug)]
pub struct HomogeneousMajorantIterator {
    seg: Option<RayMajorantSegment>,
}

impl HomogeneousMajorantIterator {
    /// An iterator with no segment (a ray that misses the medium).
    #[inline]
    pub fn empty() -> Self {
        HomogeneousMajorantIterator { seg: None }
    }

    /// The segment `[t_min, t_max]` with majorant `sigma_maj`.
    #[inline]
    pub fn new(t_min: Float, t_max: Float, sigma_maj: SampledSpectrum) -> Self {
        HomogeneousMajorantIterator {
            seg: Some(RayMajorantSegment {
                t_min,
                t_max,
                sigma_maj,
            }),
        }
    }
}

impl Iterator for HomogeneousMajorantIterator {
    type Item = RayMajorantSegment;
    #[inline]
    fn next(&mut self) -> Option<RayMajorantSegment> {
        self.seg.take()
    }
}

/// Walks a ray through a [`MajorantGrid`] voxel by voxel (pbrt-v4
/// `DDAMajorantIterator`), giving each voxel's stretch of the ray with the
/// voxel's maximum density times `sigma_t`.
#[derive(Clone, Debug)]
pub struct DdaMajorantIterator<'a> {
    sigma_t: SampledSpectrum,
    t_min: Float,
    t_max: Float,
    grid: Option<&'a MajorantGrid>,
    next_crossing_t: [Float; 3],
    delta_t: [Float; 3],
    step: [i32; 3],
    voxel_limit: [i32; 3],
    voxel: [i32; 3],
    /// The current voxel's index into the grid's values, and what a step
    /// along each axis adds to it.
    index: i32,
    index_step: [i32; 3],
}

impl<'a> DdaMajorantIterator<'a> {
    /// An iterator with no segments (a ray that misses the medium).
    pub fn empty() -> Self {
        DdaMajorantIterator {
            sigma_t: SampledSpectrum::new(0.0),
            t_min: Float::INFINITY,
            t_max: -Float::INFINITY,
            grid: None,
            next_crossing_t: [0.0; 3],
            delta_t: [0.0; 3],
            step: [0; 3],
            voxel_limit: [0; 3],
            voxel: [0; 3],
            index: 0,
            index_step: [0; 3],
        }
    }

    /// Sets up the walk of `ray` (in the grid's medium space) over
    /// `[t_min, t_max]`, which must lie inside the grid's bounds.
    pub fn new(
        ray: &Ray,
        t_min: Float,
        t_max: Float,
        grid: &'a MajorantGrid,
        sigma_t: SampledSpectrum,
    ) -> Self {
        let diag = grid.bounds.diagonal();
        let o = grid.bounds.offset(ray.o);
        let mut d = Vector3f::new(ray.d.x / diag.x, ray.d.y / diag.y, ray.d.z / diag.z);
        let mut it = DdaMajorantIterator {
            sigma_t,
            t_min,
            t_max,
            grid: Some(grid),
            next_crossing_t: [0.0; 3],
            delta_t: [0.0; 3],
            step: [0; 3],
            voxel_limit: [0; 3],
            voxel: [0; 3],
            index: 0,
            index_step: [0; 3],
        };
        for axis in 0..3 {
            let res = grid.res[axis];
            let g = o[axis] + d[axis] * t_min;
            // Clamped in floating point, then truncated (NaN gives 0).
            it.voxel[axis] = (g * res as Float).clamp(0.0, (res - 1) as Float) as i32;
            it.delta_t[axis] = 1.0 / (d[axis].abs() * res as Float);
            if d[axis] == 0.0 {
                // −0 counts as a positive direction.
                d[axis] = 0.0;
            }
            if d[axis] >= 0.0 {
                let next = (it.voxel[axis] + 1) as Float / res as Float;
                it.next_crossing_t[axis] = t_min + (next - g) / d[axis];
                it.step[axis] = 1;
                it.voxel_limit[axis] = res;
            } else {
                let next = it.voxel[axis] as Float / res as Float;
                it.next_crossing_t[axis] = t_min + (next - g) / d[axis];
                it.step[axis] = -1;
                it.voxel_limit[axis] = -1;
            }
        }
        let strides = [1, grid.res[0], grid.res[0] * grid.res[1]];
        it.index = it.voxel[0] + strides[1] * it.voxel[1] + strides[2] * it.voxel[2];
        it.index_step = [0, 1, 2].map(|a| it.step[a] * strides[a]);
        it
    }
}

impl<'a> DdaMajorantIterator<'a> {
    /// The walk of a rendering-space `ray` over `[0, t_max]` through
    /// `grid`, whose bounds are in the medium space `medium_from_render`
    /// maps to (empty when the ray misses them): what every grid medium's
    /// `SampleRay` does in pbrt-v4.
    #[inline]
    pub fn through_grid(
        ray: &Ray,
        t_max: Float,
        medium_from_render: &Transform,
        grid: &'a MajorantGrid,
        sigma_t: SampledSpectrum,
    ) -> Self {
        let (ray, t_max) = medium_from_render.apply_ray(ray, t_max);
        match grid.bounds.intersect_p(ray.o, ray.d, t_max) {
            Some((t0, t1)) => DdaMajorantIterator::new(&ray, t0, t1, grid, sigma_t),
            None => DdaMajorantIterator::empty(),
        }
    }
}

impl Iterator for DdaMajorantIterator<'_> {
    type Item = RayMajorantSegment;

    #[inline]
    fn next(&mut self) -> Option<RayMajorantSegment> {
        // Also ends a walk whose times became NaN.
        if !(self.t_min < self.t_max) {
            return None;
        }
        let grid = self.grid?;
        let c = &self.next_crossing_t;
        // The axis whose voxel boundary comes first.
        let bits = (((c[0] < c[1]) as usize) << 2)
            + (((c[0] < c[2]) as usize) << 1)
            + ((c[1] < c[2]) as usize);
        const CMP_TO_AXIS: [usize; 8] = [2, 1, 2, 1, 2, 2, 0, 0];
        let axis = CMP_TO_AXIS[bits];
        let t_exit = self.t_max.min(c[axis]);
        let density = grid.voxels.get(self.index as usize).copied().unwrap_or(0.0);
        let seg = RayMajorantSegment {
            t_min: self.t_min,
            t_max: t_exit,
            sigma_maj: self.sigma_t * density,
        };
        self.t_min = t_exit;
        if self.next_crossing_t[axis] > self.t_max {
            self.t_min = self.t_max;
        }
        self.voxel[axis] += self.step[axis];
        self.index += self.index_step[axis];
        if self.voxel[axis] == self.voxel_limit[axis] {
            self.t_min = self.t_max;
        }
        self.next_crossing_t[axis] += self.delta_t[axis];
        Some(seg)
    }
}
