//! pbrt-v4's watertight ray–triangle test for several rays at once: one
//! triangle against the lanes of a ray packet (the packet traversal's
//! leaves), each lane computing what [`intersect_prepared_triangle`]
//! computes for its ray, operation for operation, so that hits, distances
//! and barycentrics are the same bits.
//!
//! [`intersect_prepared_triangle`]: super::triangle::intersect_prepared_triangle

use super::triangle::TriangleRay;
use crate::simd::F32Lanes;
use rpbrt_geometry::float::{gamma, Float};
use rpbrt_geometry::tuple::Point3f;

/// The [`TriangleRay`]s of up to `L::N` rays in lanes: origins, the
/// permutation as masks, and the shear.
#[derive(Clone, Copy)]
pub struct TriangleRayLanes<L: F32Lanes> {
    o: [L; 3],
    /// `pick[k]`: where the ray's permutation takes component `k` from
    /// x, and from y (from z where neither).
    pick: [[L::Mask; 2]; 3],
    sx: L,
    sy: L,
    sz: L,
}

/// A hit of lanes [`TriangleRayLanes::intersect`] found: the mask of the
/// lanes whose ray hits, and for those the barycentrics and distance.
#[derive(Clone, Copy)]
pub struct LaneHits<L: F32Lanes> {
    /// The lanes that hit.
    pub mask: L::Mask,
    /// The barycentric coordinates.
    pub b: [L; 3],
    /// The hit distance.
    pub t: L,
}

impl<L: F32Lanes> TriangleRayLanes<L> {
    /// The lanes of `trs` (at most `L::N`; lanes beyond them repeat the
    /// first ray and must be left out of the active mask).
    #[inline(always)]
    pub fn new(trs: &[TriangleRay]) -> Self {
        debug_assert!(!trs.is_empty() && trs.len() <= L::N);
        let mut o = [[0.0 as Float; crate::simd::MAX_LANES]; 3];
        let mut s = [[0.0 as Float; crate::simd::MAX_LANES]; 3];
        let mut from = [[0u32; 2]; 3];
        for i in 0..L::N {
            let tr = trs.get(i).unwrap_or(&trs[0]);
            for (row, &v) in o.iter_mut().zip(&tr.o) {
                row[i] = v;
            }
            s[0][i] = tr.sx;
            s[1][i] = tr.sy;
            s[2][i] = tr.sz;
            for (f, &p) in from.iter_mut().zip(&tr.perm) {
                f[0] |= u32::from(p == 0) << i;
                f[1] |= u32::from(p == 1) << i;
            }
        }
        TriangleRayLanes {
            o: [L::load(&o[0]), L::load(&o[1]), L::load(&o[2])],
            pick: [
                [L::from_bits(from[0][0]), L::from_bits(from[0][1])],
                [L::from_bits(from[1][0]), L::from_bits(from[1][1])],
                [L::from_bits(from[2][0]), L::from_bits(from[2][1])],
            ],
            sx: L::load(&s[0]),
            sy: L::load(&s[1]),
            sz: L::load(&s[2]),
        }
    }

    /// `p − o` per lane, permuted (the scalar `relative`: subtracted,
    /// then picked).
    #[inline(always)]
    fn relative(&self, p: Point3f) -> [L; 3] {
        let d = [
            L::splat(p.x).sub(self.o[0]),
            L::splat(p.y).sub(self.o[1]),
            L::splat(p.z).sub(self.o[2]),
        ];
        let mut r = [d[2]; 3];
        for (k, rk) in r.iter_mut().enumerate() {
            let yz = L::select(self.pick[k][1], d[1], d[2]);
            *rk = L::select(self.pick[k][0], d[0], yz);
        }
        r
    }

    /// The triangle `p0 p1 p2` (nondegenerate) against the lanes in
    /// `active`, each within `(0, t_max)` of its lane: the scalar test's
    /// operations in its order, every branch a mask.
    #[inline(always)]
    pub fn intersect(
        &self,
        active: L::Mask,
        t_max: L,
        p0: Point3f,
        p1: Point3f,
        p2: Point3f,
    ) -> LaneHits<L> {
        let zero = L::splat(0.0);
        let mut q = [self.relative(p0), self.relative(p1), self.relative(p2)];
        for v in q.iter_mut() {
            v[0] = v[0].add(self.sx.mul(v[2]));
            v[1] = v[1].add(self.sy.mul(v[2]));
        }
        let [q0, q1, q2] = q;
        let e0 = L::difference_of_products(q1[0], q2[1], q1[1], q2[0]);
        let e1 = L::difference_of_products(q2[0], q0[1], q2[1], q0[0]);
        let e2 = L::difference_of_products(q0[0], q1[1], q0[1], q1[0]);
        let any_neg = L::or(L::or(e0.lt(zero), e1.lt(zero)), e2.lt(zero));
        let any_pos = L::or(L::or(e0.gt(zero), e1.gt(zero)), e2.gt(zero));
        let det = e0.add(e1).add(e2);
        let mut reject = L::or(L::and(any_neg, any_pos), L::or(det.eq(zero), det.is_nan()));

        let z = [q0[2].mul(self.sz), q1[2].mul(self.sz), q2[2].mul(self.sz)];
        let t_scaled = e0.mul(z[0]).add(e1.mul(z[1])).add(e2.mul(z[2]));
        let bound = t_max.mul(det);
        let behind_neg = L::and(det.lt(zero), L::or(t_scaled.ge(zero), t_scaled.lt(bound)));
        let behind_pos = L::and(det.gt(zero), L::or(t_scaled.le(zero), t_scaled.gt(bound)));
        reject = L::or(reject, L::or(behind_neg, behind_pos));
        let inv_det = L::splat(1.0).div(det);
        let b = [e0.mul(inv_det), e1.mul(inv_det), e2.mul(inv_det)];
        let t = t_scaled.mul(inv_det);
        reject = L::or(reject, t.is_nan());

        // The conservative bound on t (book section 6.8.7).
        let max_zt = z[0].abs().max(z[1].abs()).max(z[2].abs());
        let delta_z = L::splat(gamma(3)).mul(max_zt);
        let max_xt = q0[0].abs().max(q1[0].abs()).max(q2[0].abs());
        let max_yt = q0[1].abs().max(q1[1].abs()).max(q2[1].abs());
        let g5 = L::splat(gamma(5));
        let delta_x = g5.mul(max_xt.add(max_zt));
        let delta_y = g5.mul(max_yt.add(max_zt));
        let delta_e = L::splat(2.0).mul(
            L::splat(gamma(2))
                .mul(max_xt)
                .mul(max_yt)
                .add(delta_y.mul(max_xt))
                .add(delta_x.mul(max_yt)),
        );
        let max_e = e0.abs().max(e1.abs()).max(e2.abs());
        let delta_t = L::splat(3.0)
            .mul(
                L::splat(gamma(3))
                    .mul(max_e)
                    .mul(max_zt)
                    .add(delta_e.mul(max_zt))
                    .add(delta_z.mul(max_e)),
            )
            .mul(inv_det.abs());
        reject = L::or(reject, t.le(delta_t));
        LaneHits {
            mask: L::and(active, L::not(reject)),
            b,
            t,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;
    use crate::shape::triangle::{intersect_prepared_triangle, triangle_is_nondegenerate};
    use crate::simd::{dispatch, Kernel, SimdLevel};
    use rpbrt_geometry::ray::Ray;
    use rpbrt_geometry::tuple::Vector3f;

    /// Every ray of `rays` (in groups of the width) against `tri` with
    /// `t_max`, in lanes: per ray, the hit's barycentrics and distance
    /// as bits, or `None`.
    struct Lanes<'a> {
        rays: &'a [(Ray, Float)],
        tri: [Point3f; 3],
    }

    impl Kernel for Lanes<'_> {
        type Output = Vec<Option<[u32; 4]>>;
        // Lane i of four stored rows: indexing reads best.
        #[allow(clippy::needless_range_loop)]
        fn run<L: F32Lanes>(self) -> Self::Output {
            let mut out = Vec::new();
            for group in self.rays.chunks(L::N) {
                let trs: Vec<TriangleRay> =
                    group.iter().map(|(r, _)| TriangleRay::new(r)).collect();
                let lanes = TriangleRayLanes::<L>::new(&trs);
                let mut t_max = [0.0 as Float; crate::simd::MAX_LANES];
                for (i, (_, t)) in group.iter().enumerate() {
                    t_max[i] = *t;
                }
                let active = L::from_bits((1u32 << group.len()) - 1);
                let [p0, p1, p2] = self.tri;
                let h = lanes.intersect(active, L::load(&t_max), p0, p1, p2);
                let mut v = [[0.0 as Float; crate::simd::MAX_LANES]; 4];
                for (row, x) in v.iter_mut().zip([h.b[0], h.b[1], h.b[2], h.t]) {
                    x.store(row);
                }
                let bits = L::bits(h.mask);
                for i in 0..group.len() {
                    out.push((bits >> i & 1 == 1).then(|| [0, 1, 2, 3].map(|k| v[k][i].to_bits())));
                }
            }
            out
        }
    }

    fn point(rng: &mut Rng, scale: Float) -> Point3f {
        let mut c = || (rng.uniform_float() - 0.5) * scale;
        Point3f::new(c(), c(), c())
    }

    /// The lane test gives the scalar test's hits, barycentrics and
    /// distances bit for bit at every width: random triangles (small,
    /// huge, thin) against rays aimed at their vertices, edges and
    /// insides and at random, with finite and infinite bounds, directions
    /// along an axis included.
    #[test]
    fn lanes_match_the_scalar_test_at_every_width() {
        let mut rng = Rng::with_sequence(29);
        let mut hits = 0;
        let mut checked = 0;
        for k in 0..300 {
            let scale = [1.0, 1e-3, 1e4][k % 3];
            let tri = [
                point(&mut rng, scale),
                point(&mut rng, scale),
                point(&mut rng, scale),
            ];
            if !triangle_is_nondegenerate(tri[0], tri[1], tri[2]) {
                continue;
            }
            let mut rays = Vec::new();
            for j in 0..48 {
                let o = point(&mut rng, 4.0 * scale);
                // Barycentric targets: inside, on an edge, at a vertex,
                // or outside.
                let (u, v) = match j % 4 {
                    0 => (rng.uniform_float(), rng.uniform_float() * 0.5),
                    1 => (rng.uniform_float(), 0.0),
                    2 => (1.0, 0.0),
                    _ => (
                        rng.uniform_float() * 3.0 - 1.0,
                        rng.uniform_float() * 3.0 - 1.0,
                    ),
                };
                let target = tri[0] + (tri[1] - tri[0]) * u + (tri[2] - tri[0]) * v;
                let mut d: Vector3f = target - o;
                if j % 7 == 0 {
                    // Along an axis: zero components.
                    d = Vector3f::new(0.0, 0.0, if d.z < 0.0 { -1.0 } else { 1.0 });
                }
                if j % 11 == 0 {
                    d = -d;
                }
                let t_max = match j % 3 {
                    0 => Float::INFINITY,
                    1 => 1.0,
                    _ => rng.uniform_float() * 2.0,
                };
                rays.push((Ray::new(o, d), t_max));
            }
            let want: Vec<Option<[u32; 4]>> = rays
                .iter()
                .map(|(r, t)| {
                    intersect_prepared_triangle(&TriangleRay::new(r), *t, tri[0], tri[1], tri[2])
                        .map(|(b0, b1, b2, t)| [b0, b1, b2, t].map(Float::to_bits))
                })
                .collect();
            hits += want.iter().filter(|w| w.is_some()).count();
            for level in SimdLevel::available() {
                let got = dispatch(level, Lanes { rays: &rays, tri });
                assert_eq!(got, want, "{level:?}: triangle {tri:?}");
                checked += 1;
            }
        }
        // The rays aimed inside mostly hit: the comparison covers hits.
        assert!(hits > 3000, "{hits} hits");
        assert!(checked > 0);
    }
}
