//! Light samples that are zero before they are taken.
//!
//! pbrt-v4's light samplers pick lights by conservative importance, so a
//! shading point often picks a triangle emitter whose samples cannot
//! contribute: the point lies behind a one-sided emitter (every sample's
//! `L` is zero), or the emitter lies wholly on the far side of a
//! reflection-only BSDF (every sample's `f` is zero). pbrt-v4 samples the
//! light anyway (spherical triangle sampling, the costliest step of a path
//! vertex) and then discards the sample. [`LightCull`] recognises these
//! cases from the triangle's vertices first, with margins far above
//! floating-point rounding, so that skipping them leaves every pixel
//! exactly as it was (the sampler's dimensions are drawn either way).

use rpbrt_geometry::{dot, Float, Point3f, Vector3f};

use super::Light;
use crate::shape::Shape;

/// Relative margin of the tests: sampled points and directions, and the
/// tests' own single-precision dot products, carry relative errors of a
/// few 1e-7; cases within 1e-4 (relative to the coordinates' magnitudes)
/// of the boundary are left to the full computation.
const MARGIN: Float = 1e-4;

/// What a triangle emitter's culling tests need.
#[derive(Clone, Copy, Debug)]
pub struct LightCull {
    /// The triangle's vertices.
    v: [Point3f; 3],
    /// The emitting side's normal (the oriented normal every sample gets)
    /// for a one-sided emitter whose orientation is the same everywhere;
    /// zero otherwise.
    n: Vector3f,
    /// min over the vertices of dot(n, v).
    n_min: Float,
    /// The margin's part that depends on the vertices: `2·MARGIN` times the
    /// largest |x| + |y| + |z| of a vertex (|q − p| is at most that of q
    /// plus that of p).
    tol_v: Float,
}

/// |x| + |y| + |z|.
#[inline(always)]
fn l1(q: Point3f) -> Float {
    q.x.abs() + q.y.abs() + q.z.abs()
}

impl LightCull {
    /// The tests for `light`: diffuse area lights on triangles only.
    pub fn for_light(light: &Light) -> Option<LightCull> {
        let Light::DiffuseArea(l) = light else {
            return None;
        };
        let Shape::Triangle(tri) = &l.shape else {
            return None;
        };
        let v = tri.vertex_positions();
        if !v.iter().all(|p| p.is_finite()) {
            return None;
        }
        let n = if l.two_sided {
            None
        } else {
            tri.uniform_oriented_normal()
        }
        .map_or(Vector3f::default(), Vector3f::from);
        let n_min = v
            .iter()
            .map(|&q| dot(n, Vector3f::from(q)))
            .fold(Float::INFINITY, Float::min);
        let tol_v = 2.0 * MARGIN * v.iter().map(|&q| l1(q)).fold(0.0, Float::max);
        tol_v
            .is_finite()
            .then_some(LightCull { v, n, n_min, tol_v })
    }

    /// The margin at `p`.
    #[inline(always)]
    fn tolerance(&self, p: Point3f) -> Float {
        self.tol_v + 2.0 * MARGIN * l1(p)
    }

    /// True when `p` lies clearly behind a one-sided emitter: every
    /// sample's emitted radiance toward `p` is zero.
    #[inline]
    pub fn faces_away_from(&self, p: Point3f) -> bool {
        // Radiance leaves toward p where dot(n, p − q) ≥ 0; here every q of
        // the triangle has dot(n, q − p) > 0. (Zero n: never.)
        self.n != Vector3f::default()
            && self.n_min - dot(self.n, Vector3f::from(p)) > self.tolerance(p)
    }

    /// True when the whole triangle lies clearly on the other side of the
    /// plane through `p` with normal `z` (unit length) than a direction
    /// whose component along `z` is `wo_z`: every direction from `p` to the
    /// triangle has the opposite sign along `z`, so a BSDF that is zero
    /// across hemispheres, with shading normal `z`, gives zero. A zero
    /// `wo_z` counts as culled too (BSDFs return zero for grazing ωo).
    #[inline]
    pub fn behind(&self, p: Point3f, z: Vector3f, wo_z: Float) -> bool {
        if wo_z == 0.0 {
            return true;
        }
        let dp = dot(z, Vector3f::from(p));
        let d = self.v.map(|q| dot(z, Vector3f::from(q)) - dp);
        let tol = self.tolerance(p);
        if wo_z > 0.0 {
            d[0].max(d[1]).max(d[2]) < -tol
        } else {
            d[0].min(d[1]).min(d[2]) > tol
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::{AreaEmission, DiffuseAreaLight, LightSampleContext};
    use crate::rng::Rng;
    use crate::shape::{ShapeMethods, Triangle, TriangleMesh};
    use crate::spectrum::{SampledWavelengths, Spectrum};
    use rpbrt_geometry::{cross, Normal3f, Point2f, Point3fi, Transform};

    /// Whenever a test culls, no sample of the light contributes: each
    /// sample is rejected (zero emission toward the point) or, for the
    /// hemisphere test, arrives from the side of the shading plane opposite
    /// to ωo. Random triangles (one- and two-sided, with vertex normals
    /// agreeing with the face or not, reversed orientation) and points,
    /// many of them near the triangle's plane so that the margins matter;
    /// both tests must also fire often.
    #[test]
    fn culled_light_samples_never_contribute() {
        let mut rng = Rng::with_sequence(9);
        let mut r = move |lo: Float, hi: Float| lo + (hi - lo) * rng.uniform_float();
        let lambda = SampledWavelengths::sample_visible(0.5);
        let (mut faces, mut behind, mut samples) = (0, 0, 0);
        for case in 0..300 {
            let v: Vec<Point3f> = (0..3)
                .map(|_| Point3f::new(r(-1.0, 1.0), r(-1.0, 1.0), r(-1.0, 1.0)))
                .collect();
            let nf = cross(v[1] - v[0], v[2] - v[0]).normalize();
            let normals = match case % 4 {
                0 => vec![],
                1 => vec![Normal3f::from(nf); 3],
                2 => vec![Normal3f::from(-nf); 3],
                _ => (0..3)
                    .map(|_| Normal3f::new(r(-1.0, 1.0), r(-1.0, 1.0), r(-1.0, 1.0)))
                    .collect(),
            };
            let Ok((mesh, _)) = TriangleMesh::new(
                &Transform::default(),
                case % 3 == 0,
                vec![0, 1, 2],
                v.clone(),
                vec![],
                normals,
                vec![],
                vec![],
            ) else {
                continue;
            };
            let tri = Triangle::new(mesh, 0);
            let area = tri.area();
            let light = Light::DiffuseArea(Box::new(
                DiffuseAreaLight {
                    shape: Shape::Triangle(tri),
                    area,
                    emission: AreaEmission::Spectrum(Spectrum::Constant(1.0)),
                    scale: 1.0,
                    two_sided: case % 5 == 0,
                    alpha: None,
                    medium_inside: None,
                    medium_outside: None,
                    sampled_triangle: None,
                }
                .with_cache(),
            ));
            let Some(cull) = LightCull::for_light(&light) else {
                continue;
            };
            for k in 0..60 {
                // Near the plane (offsets down to 1e-6) or anywhere.
                let p = if k % 2 == 0 {
                    let b = [r(0.0, 1.0), r(0.0, 1.0)];
                    let q = v[0] + (v[1] - v[0]) * b[0] + (v[2] - v[0]) * b[1];
                    let off = 10f32.powf(r(-6.0, 0.0)) * if k % 4 == 0 { 1.0 } else { -1.0 };
                    q + nf * off
                } else {
                    Point3f::new(r(-2.0, 2.0), r(-2.0, 2.0), r(-2.0, 2.0))
                };
                let z = if k % 3 == 0 {
                    nf
                } else {
                    Vector3f::new(r(-1.0, 1.0), r(-1.0, 1.0), r(-1.0, 1.0)).normalize()
                };
                let wo_z = if k % 5 < 2 { -1.0 } else { 1.0 };
                let fa = cull.faces_away_from(p);
                let bh = cull.behind(p, z, wo_z);
                faces += fa as usize;
                behind += bh as usize;
                if !(fa || bh) {
                    continue;
                }
                let ctx = LightSampleContext {
                    pi: Point3fi::from(p),
                    n: Normal3f::from(z),
                    ns: Normal3f::from(z),
                };
                for j in 0..32 {
                    let u = Point2f::new(r(0.0, 1.0), (j as Float + r(0.0, 1.0)) / 32.0);
                    let Some(ls) = light.sample_li(&ctx, u, &lambda, true) else {
                        continue;
                    };
                    samples += 1;
                    assert!(!fa, "case {case}/{k}: sample from a light facing away");
                    let wi_z = dot(ls.wi, z);
                    assert!(wi_z * wo_z <= 0.0, "case {case}/{k}: wi on ωo's side");
                }
            }
        }
        assert!(
            faces > 1000 && behind > 1000 && samples > 10_000,
            "{faces} {behind} {samples}"
        );
    }
}
