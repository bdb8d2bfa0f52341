//! Animated transformations (book section 3.11; pbrt-v4
//! `AnimatedTransform`): two keyframe transforms decomposed into
//! translation, rotation and scale, interpolated over the shutter interval.

use crate::bounds::Bounds3f;
use crate::float::*;
use crate::quaternion::Quaternion;
use crate::ray::Ray;
use crate::transform::{SquareMatrix4, Transform};
use crate::tuple::*;

/// The translation, rotation and scale-shear parts of a transformation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Decomposition {
    /// Translation.
    pub t: Vector3f,
    /// Rotation.
    pub r: Quaternion,
    /// The remaining scale (and shear) matrix.
    pub s: SquareMatrix4,
}

/// Splits `m` into T·R·S by polar decomposition (iterated averaging of the
/// matrix with its inverse transpose).
pub fn decompose(m: &SquareMatrix4) -> Decomposition {
    let t = Vector3f::new(m.m[0][3], m.m[1][3], m.m[2][3]);
    let mut mm = *m;
    for i in 0..3 {
        mm.m[i][3] = 0.0;
        mm.m[3][i] = 0.0;
    }
    mm.m[3][3] = 1.0;
    if mm == SquareMatrix4::identity() {
        // A translation (most animated shapes): what the iteration below
        // finds, without its inverses (the identity is its own inverse,
        // bit for bit).
        let q = Quaternion::from_transform(&Transform::default()).normalize();
        return Decomposition {
            t,
            r: q,
            s: SquareMatrix4::identity(),
        };
    }
    let mut r = mm;
    for _ in 0..100 {
        let rit = match r.transpose().inverse() {
            Some(x) => x,
            None => break,
        };
        let mut rnext = SquareMatrix4::identity();
        let mut norm: Float = 0.0;
        for i in 0..4 {
            for j in 0..4 {
                rnext.m[i][j] = 0.5 * (r.m[i][j] + rit.m[i][j]);
            }
        }
        for i in 0..3 {
            let n = (rnext.m[i][0] - r.m[i][0]).abs()
                + (rnext.m[i][1] - r.m[i][1]).abs()
                + (rnext.m[i][2] - r.m[i][2]).abs();
            norm = norm.max(n);
        }
        r = rnext;
        if norm <= 0.0001 {
            break;
        }
    }
    let rt = Transform::from_matrices(r, r.transpose());
    let q = Quaternion::from_transform(&rt).normalize();
    let s = r
        .inverse()
        .map(|ri| ri * mm)
        .unwrap_or_else(SquareMatrix4::identity);
    Decomposition { t, r: q, s }
}

/// A transformation that varies over time between two keyframes.
///
/// Stored compactly: a pair of translations (what `ActiveTransform`
/// lines around `Translate` give every moving shape of a scene) is kept
/// as its two offsets, 36 bytes in all, since everything about it (the
/// keyframes, their decompositions, the interpolation) follows from them
/// bit for bit; any other pair keeps its keyframes and decompositions
/// behind one pointer.
#[derive(Clone, Debug, PartialEq)]
pub struct AnimatedTransform {
    /// Start of the animation.
    pub start_time: Float,
    /// End of the animation.
    pub end_time: Float,
    keys: Keys,
}

#[derive(Clone, Debug, PartialEq)]
enum Keys {
    /// Both keyframes are, to the bit, `Transform::translate` of these
    /// offsets (the start's, then the end's). Their decompositions are
    /// the offsets with no rotation and unit scale, and the interpolation
    /// is the translation by the interpolated offset.
    Translations([Vector3f; 2]),
    /// Any other pair of keyframes.
    General(Box<GeneralKeys>),
}

#[derive(Clone, Debug, PartialEq)]
struct GeneralKeys {
    start: Transform,
    end: Transform,
    actually_animated: bool,
    d0: Decomposition,
    d1: Decomposition,
    has_rotation: bool,
}

/// `r`, the union of the boxes of `b` at the ends of a straight motion,
/// padded for the rounding of the interpolation in between.
fn padded(r: Bounds3f, b: &Bounds3f) -> Bounds3f {
    let magnitude = [r.p_min, r.p_max]
        .iter()
        .flat_map(|p| [p.x.abs(), p.y.abs(), p.z.abs()])
        .fold(0.0, Float::max);
    r.expand(1e-6 * ((b.p_max - b.p_min).length() + magnitude))
}

/// The offset of `t` when `t` is, to the bit, the translation by it.
fn translation_offset(t: &Transform) -> Option<Vector3f> {
    let m = t.matrix();
    let d = Vector3f::new(m.m[0][3], m.m[1][3], m.m[2][3]);
    Transform::translate(d).same_bits(t).then_some(d)
}

impl AnimatedTransform {
    /// A transformation fixed over time.
    pub fn fixed(t: Transform) -> Self {
        AnimatedTransform::new(t, 0.0, t, 1.0)
    }

    /// Interpolates between `start` at `start_time` and `end` at `end_time`.
    pub fn new(start: Transform, start_time: Float, end: Transform, end_time: Float) -> Self {
        if let (Some(a), Some(b)) = (translation_offset(&start), translation_offset(&end)) {
            return AnimatedTransform {
                start_time,
                end_time,
                keys: Keys::Translations([a, b]),
            };
        }
        AnimatedTransform::general(start, start_time, end, end_time)
    }

    /// [`AnimatedTransform::new`] keeping the keyframes and their
    /// decompositions whatever they are.
    fn general(start: Transform, start_time: Float, end: Transform, end_time: Float) -> Self {
        let actually_animated = start != end;
        let d0 = decompose(start.matrix());
        let mut d1 = decompose(end.matrix());
        // Take the shortest path between the rotations.
        if d0.r.dot(d1.r) < 0.0 {
            d1.r = -d1.r;
        }
        let has_rotation = d0.r.dot(d1.r) < 0.9995;
        AnimatedTransform {
            start_time,
            end_time,
            keys: Keys::General(Box::new(GeneralKeys {
                start,
                end,
                actually_animated,
                d0,
                d1,
                has_rotation,
            })),
        }
    }

    /// True when the two keyframes differ.
    #[inline]
    pub fn is_animated(&self) -> bool {
        match &self.keys {
            Keys::Translations([a, b]) => a != b,
            Keys::General(g) => g.actually_animated,
        }
    }

    /// The transformation at `start_time`.
    #[inline]
    pub fn start_transform(&self) -> Transform {
        match &self.keys {
            Keys::Translations([a, _]) => Transform::translate(*a),
            Keys::General(g) => g.start,
        }
    }

    /// The transformation at `end_time`.
    #[inline]
    pub fn end_transform(&self) -> Transform {
        match &self.keys {
            Keys::Translations([_, b]) => Transform::translate(*b),
            Keys::General(g) => g.end,
        }
    }

    /// The transformation at `time` (clamped to the keyframe interval).
    pub fn interpolate(&self, time: Float) -> Transform {
        if !self.is_animated() || time <= self.start_time {
            return self.start_transform();
        }
        if time >= self.end_time {
            return self.end_transform();
        }
        let dt = (time - self.start_time) / (self.end_time - self.start_time);
        self.at_fraction(dt)
    }

    /// The offset of the transformation at `time` when both keyframes are
    /// translations (then [`AnimatedTransform::interpolate`] gives, bit
    /// for bit, the translation by this offset); `None` for any other
    /// keyframes.
    #[inline]
    pub fn translation_at(&self, time: Float) -> Option<Vector3f> {
        let Keys::Translations([a, b]) = &self.keys else {
            return None;
        };
        Some(if a == b || time <= self.start_time {
            *a
        } else if time >= self.end_time {
            *b
        } else {
            let dt = (time - self.start_time) / (self.end_time - self.start_time);
            Vector3f::lerp(dt, *a, *b)
        })
    }

    /// The decompositions' interpolation at `dt` of the keyframe interval
    /// (0 at its start, 1 at its end).
    fn at_fraction(&self, dt: Float) -> Transform {
        let g = match &self.keys {
            Keys::Translations([a, b]) => {
                // What the composition below gives, bit for bit: a
                // rotation with a +0 vector part is the identity matrix
                // (whatever the interpolated real part), and products with
                // the identity are exact (tested), so this is the
                // translation alone, without its four matrix products and
                // an inverse (per ray, for a ray meeting a moving shape).
                return Transform::translate(Vector3f::lerp(dt, *a, *b));
            }
            Keys::General(g) => g,
        };
        let trans = Vector3f::lerp(dt, g.d0.t, g.d1.t);
        let rotate = Quaternion::slerp(dt, g.d0.r, g.d1.r);
        let mut scale = SquareMatrix4::identity();
        for i in 0..3 {
            for j in 0..3 {
                scale.m[i][j] = lerp(dt, g.d0.s.m[i][j], g.d1.s.m[i][j]);
            }
        }
        let st = Transform::from_matrix(scale).unwrap_or_default();
        Transform::translate(trans) * rotate.to_transform() * st
    }

    /// Applies the transformation at `time` to a point.
    #[inline]
    pub fn apply_point(&self, p: Point3f, time: Float) -> Point3f {
        self.interpolate(time).apply_point(p)
    }
    /// Applies the transformation at `time` to a vector.
    #[inline]
    pub fn apply_vector(&self, v: Vector3f, time: Float) -> Vector3f {
        self.interpolate(time).apply_vector(v)
    }
    /// Applies the transformation at `time` to a normal.
    #[inline]
    pub fn apply_normal(&self, n: Normal3f, time: Float) -> Normal3f {
        self.interpolate(time).apply_normal(n)
    }
    /// Applies the transformation at the ray's time to the ray.
    #[inline]
    pub fn apply_ray(&self, r: &Ray, t_max: Float) -> (Ray, Float) {
        self.interpolate(r.time).apply_ray(r, t_max)
    }
    /// Applies the inverse of the transformation at the ray's time.
    #[inline]
    pub fn apply_inverse_ray(&self, r: &Ray, t_max: Float) -> (Ray, Float) {
        self.interpolate(r.time).apply_inverse_ray(r, t_max)
    }

    /// A box bounding where `b` goes over the whole animation interval.
    ///
    /// The keyframe interval is cut into pieces; on each piece every corner
    /// of the box moves no faster than a bound `L` on its speed (from the
    /// translation, the rotation's angular speed and the scale change), so
    /// within a piece of length `h` it stays within `L·h/2` of one of the
    /// piece's endpoint positions. The union of the padded endpoint boxes is
    /// therefore conservative, and tight as the pieces shrink.
    ///
    /// When the keyframes share their rotation (translation and scale
    /// animated: the common case), every point moves along a straight
    /// line, affine in time, so the boxes of the two ends bound the motion
    /// (pbrt-v4 takes that union whenever its `hasRotation` is false).
    pub fn motion_bounds(&self, b: &Bounds3f) -> Bounds3f {
        if b.is_empty() {
            return *b;
        }
        if !self.is_animated() {
            return self.start_transform().apply_bounds(b);
        }
        if let Keys::Translations([a, c]) = &self.keys {
            // What the union below gives for translations, by the offsets
            // alone: a translated corner is the corner plus the offset
            // (the matrix's other products are by 1 and 0, exact), and
            // rounding keeps the corners' order, so the box's corners move
            // to the box's corners. The ends of the interpolation are
            // `lerp`'s own, which at 1 need not be the end offset's bits.
            let offsets = [
                *a,
                *c,
                Vector3f::lerp(0.0, *a, *c),
                Vector3f::lerp(1.0, *a, *c),
            ];
            let r = offsets.iter().fold(Bounds3f::empty(), |r, o| {
                r.union(&Bounds3f {
                    p_min: b.p_min + *o,
                    p_max: b.p_max + *o,
                })
            });
            return padded(r, b);
        }
        let rotating = match &self.keys {
            Keys::General(g) if g.d0.r != g.d1.r => Some(g),
            _ => None,
        };
        let Some(g) = rotating else {
            // The keyframes themselves and the decompositions' ends (which
            // the interpolation uses inside the interval and may differ
            // from the keyframes in the last bits), padded for the
            // rounding of the interpolation in between.
            let r = self
                .start_transform()
                .apply_bounds(b)
                .union(&self.end_transform().apply_bounds(b))
                .union(&self.at_fraction(0.0).apply_bounds(b))
                .union(&self.at_fraction(1.0).apply_bounds(b));
            return padded(r, b);
        };
        let delta = (self.end_time - self.start_time).max(Float::MIN_POSITIVE);
        let theta = g.d0.r.angle_between(g.d1.r) * 2.0;
        let omega = if g.has_rotation || theta > 0.0 {
            theta / delta
        } else {
            0.0
        };
        let trans_speed = (g.d1.t - g.d0.t).length() / delta;
        let mut speed: Float = 0.0;
        for c in 0..8 {
            let p = Vector3f::from(b.corner(c));
            let sp0 = mat3_apply(&g.d0.s, p);
            let sp1 = mat3_apply(&g.d1.s, p);
            let s =
                trans_speed + omega * sp0.length().max(sp1.length()) + (sp1 - sp0).length() / delta;
            speed = speed.max(s);
        }
        const PIECES: usize = 64;
        let h = delta / PIECES as Float;
        let pad = speed * h / 2.0 * (1.0 + 1e-3) + 1e-6 * (b.p_max - b.p_min).length();
        let mut r = Bounds3f::empty();
        for i in 0..=PIECES {
            let t = if i == PIECES {
                self.end_time
            } else {
                self.start_time + i as Float * h
            };
            let xf = self.interpolate(t);
            r = r.union(&xf.apply_bounds(b));
        }
        r.expand(pad)
    }

    /// Bounds of the motion of a single point.
    pub fn bound_point_motion(&self, p: Point3f) -> Bounds3f {
        self.motion_bounds(&Bounds3f::from_point(p))
    }
}

fn mat3_apply(m: &SquareMatrix4, v: Vector3f) -> Vector3f {
    Vector3f::new(
        m.m[0][0] * v.x + m.m[0][1] * v.y + m.m[0][2] * v.z,
        m.m[1][0] * v.x + m.m[1][1] * v.y + m.m[1][2] * v.z,
        m.m[2][0] * v.x + m.m[2][1] * v.y + m.m[2][2] * v.z,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mat_close(a: &Transform, b: &Transform, eps: Float) -> bool {
        a.matrix()
            .m
            .iter()
            .flatten()
            .zip(b.matrix().m.iter().flatten())
            .all(|(x, y)| (x - y).abs() < eps)
    }

    #[test]
    fn decomposition_recomposes() {
        let t = Transform::translate(Vector3f::new(1.0, -2.0, 3.0))
            * Transform::rotate(40.0, Vector3f::new(1.0, 2.0, 0.5))
            * Transform::scale(2.0, 0.5, 1.5);
        let d = decompose(t.matrix());
        let re =
            Transform::translate(d.t) * d.r.to_transform() * Transform::from_matrix(d.s).unwrap();
        assert!(mat_close(&t, &re, 1e-4));
    }

    #[test]
    fn interpolation_endpoints_and_midpoint() {
        let a = Transform::translate(Vector3f::new(0.0, 0.0, 0.0));
        let b = Transform::translate(Vector3f::new(2.0, 0.0, 0.0)) * Transform::rotate_z(90.0);
        let at = AnimatedTransform::new(a, 0.0, b, 1.0);
        assert!(at.is_animated());
        assert!(mat_close(&at.interpolate(0.0), &a, 1e-5));
        assert!(mat_close(&at.interpolate(1.0), &b, 1e-5));
        let mid = at.interpolate(0.5);
        let p = mid.apply_point(Point3f::new(1.0, 0.0, 0.0));
        let s = 0.5f32.sqrt();
        assert!((p - Point3f::new(1.0 + s, s, 0.0)).length() < 1e-4, "{p:?}");
        assert!(!AnimatedTransform::fixed(a).is_animated());
    }

    /// `translation_at` is the offset of `interpolate`'s translation at
    /// every time, inside the keyframes' interval and out, and `None` for
    /// other keyframes.
    #[test]
    fn translation_at_is_the_interpolated_offset() {
        let a = Transform::translate(Vector3f::new(0.3, -17.25, 4.0e3));
        let b = Transform::translate(Vector3f::new(-0.1, -17.5, 4.1e3));
        for (at, start, end) in [
            (AnimatedTransform::new(a, 0.25, b, 0.75), 0.25, 0.75),
            (AnimatedTransform::new(a, 0.0, a, 1.0), 0.0, 1.0),
        ] {
            for k in -4..=36 {
                let time = start + (end - start) * (k as Float / 32.0);
                let off = at.translation_at(time).expect("translation keys");
                let m = *at.interpolate(time).matrix();
                for (i, o) in [off.x, off.y, off.z].into_iter().enumerate() {
                    assert_eq!(o.to_bits(), m.m[i][3].to_bits(), "time {time}");
                }
                for i in 0..3 {
                    for j in 0..3 {
                        assert_eq!(m.m[i][j], if i == j { 1.0 } else { 0.0 });
                    }
                }
            }
        }
        let rotated = Transform::rotate(30.0, Vector3f::new(0.0, 0.0, 1.0));
        assert!(AnimatedTransform::new(a, 0.0, rotated, 1.0)
            .translation_at(0.5)
            .is_none());
    }

    /// The translations' motion bounds, from the offsets alone, are what
    /// the keyframes' and the interpolation ends' transformed boxes give
    /// (fixed-seed boxes and offsets over many magnitudes).
    #[test]
    fn translations_motion_bounds_as_transformed_boxes() {
        let mut state = 0x3c6e_f372_fe94_f82bu64;
        let mut next = || crate::float::spread_value(&mut state, 30, -12);
        for _ in 0..3000 {
            let mut v = || Vector3f::new(next(), next(), next());
            let (a, c) = (v(), v());
            let (p, q) = (Point3f::from(v()), Point3f::from(v()));
            let b = Bounds3f::new(p, q);
            let at =
                AnimatedTransform::new(Transform::translate(a), 0.0, Transform::translate(c), 1.0);
            assert!(matches!(at.keys, Keys::Translations(_)));
            let r = at
                .start_transform()
                .apply_bounds(&b)
                .union(&at.end_transform().apply_bounds(&b))
                .union(&at.at_fraction(0.0).apply_bounds(&b))
                .union(&at.at_fraction(1.0).apply_bounds(&b));
            let want = padded(r, &b);
            let got = at.motion_bounds(&b);
            assert!(
                got.p_min == want.p_min && got.p_max == want.p_max,
                "{got:?} against {want:?}"
            );
        }
    }

    /// Translation keyframes interpolate without the composition, with the
    /// composition's bits (fixed-seed offsets of both signs and many
    /// magnitudes, at many times).
    #[test]
    fn translations_interpolate_as_the_composition_does() {
        let mut state = 0x6a09_e667_f3bc_c909u64;
        let mut next = || crate::float::spread_value(&mut state, 24, -8);
        for _ in 0..2000 {
            let a = Transform::translate(Vector3f::new(next(), next(), next()));
            let b = Transform::translate(Vector3f::new(next(), next(), next()));
            let at = AnimatedTransform::new(a, 0.0, b, 1.0);
            assert!(matches!(at.keys, Keys::Translations(_)));
            let general = AnimatedTransform::general(a, 0.0, b, 1.0);
            // Times in [0, 1], where `interpolate` takes them: the ends,
            // sixteenths and arbitrary floats.
            for k in 0..=32 {
                let dt = if k <= 16 {
                    k as Float / 16.0
                } else {
                    next().abs().fract()
                };
                let (f, g) = (at.at_fraction(dt), general.at_fraction(dt));
                let pairs = [
                    (f.matrix(), g.matrix()),
                    (f.inverse_matrix(), g.inverse_matrix()),
                ];
                for (a, b) in pairs {
                    for (x, y) in a.m.iter().flatten().zip(b.m.iter().flatten()) {
                        assert_eq!(x.to_bits(), y.to_bits(), "dt {dt}: {f:?} against {g:?}");
                    }
                }
            }
        }
        // The interpolated scale's diagonal, (1 − dt)·1 + dt·1, is exactly 1
        // for every float dt in [0, 1] (1 − dt is within 2^-25 of its true
        // value, and the sum rounds back to 1); checked here for every
        // dt = k/2^20 and the floats next to them.
        for k in 0..=(1u32 << 20) {
            let dt = k as Float / (1u32 << 20) as Float;
            for d in [
                dt,
                crate::float::next_float_up(dt).min(1.0),
                crate::float::next_float_down(dt).max(0.0),
            ] {
                assert_eq!(lerp(d, 1.0, 1.0), 1.0, "{d}");
            }
        }
        // A scale or a rotation in either keyframe takes the composition.
        let general = |a: Transform, b: Transform| {
            matches!(
                AnimatedTransform::new(a, 0.0, b, 1.0).keys,
                Keys::General(_)
            )
        };
        let s = Transform::scale(2.0, 1.0, 1.0);
        assert!(general(s, Transform::identity()));
        let r = Transform::rotate(10.0, Vector3f::new(0.0, 1.0, 0.0));
        assert!(general(Transform::identity(), r));
        // So does a translation matrix whose inverse is not, to the bit,
        // the negated offset's.
        let t = Transform::translate(Vector3f::new(1.0, 2.0, 3.0));
        let mut inv = *t.inverse_matrix();
        inv.m[0][3] = -0.999_999_9;
        let odd = Transform::from_matrices(*t.matrix(), inv);
        assert!(general(odd, t));
        assert!(!general(t, t));
        // The compact pair answers as the general one does.
        let (a, b) = (t, Transform::translate(Vector3f::new(-0.0, 2.5, 3.0)));
        let (at, g) = (
            AnimatedTransform::new(a, 0.25, b, 0.75),
            AnimatedTransform::general(a, 0.25, b, 0.75),
        );
        assert!(at.start_transform().same_bits(&g.start_transform()));
        assert!(at.end_transform().same_bits(&g.end_transform()));
        assert_eq!(at.is_animated(), g.is_animated());
        for time in [0.0, 0.25, 0.3, 0.5, 0.75, 1.0] {
            assert!(
                at.interpolate(time).same_bits(&g.interpolate(time)),
                "{time}"
            );
        }
        let bx = Bounds3f::new(Point3f::new(-1.0, -0.5, -0.2), Point3f::new(1.0, 0.5, 2.0));
        assert_eq!(at.motion_bounds(&bx), g.motion_bounds(&bx));
        let still = AnimatedTransform::new(a, 0.0, a, 1.0);
        assert!(!still.is_animated());
        assert!(still.interpolate(0.5).same_bits(&a));
    }

    /// A translation's decomposition skips the iteration; it must be what
    /// the iteration gives.
    #[test]
    fn translation_decomposes_as_the_iteration_does() {
        let m = *Transform::translate(Vector3f::new(1.5, -2.0, 7.25)).matrix();
        let d = decompose(&m);
        let rt = Transform::from_matrices(SquareMatrix4::identity(), SquareMatrix4::identity());
        assert_eq!(d.r, Quaternion::from_transform(&rt).normalize());
        let id = SquareMatrix4::identity();
        assert_eq!(id.transpose().inverse(), Some(id));
        assert_eq!(id.inverse().map(|ri| ri * id), Some(id));
        assert_eq!(d.s, id);
        assert_eq!(d.t, Vector3f::new(1.5, -2.0, 7.25));
    }

    #[test]
    fn motion_bounds_contain_motion() {
        let a =
            Transform::translate(Vector3f::new(0.0, 1.0, 0.0)) * Transform::scale(1.0, 2.0, 1.0);
        let b = Transform::translate(Vector3f::new(3.0, 0.0, -1.0))
            * Transform::rotate(170.0, Vector3f::new(0.3, 1.0, 0.2))
            * Transform::scale(0.5, 1.0, 3.0);
        let at = AnimatedTransform::new(a, 0.0, b, 1.0);
        let bx = Bounds3f::new(Point3f::new(-1.0, -0.5, -0.2), Point3f::new(1.0, 0.5, 2.0));
        let mb = at.motion_bounds(&bx);
        for i in 0..=1000 {
            let t = i as Float / 1000.0;
            let xf = at.interpolate(t);
            for c in 0..8 {
                assert!(mb.inside(xf.apply_point(bx.corner(c))), "t={t} c={c}");
            }
        }
        // And not absurdly loose: within 10% of the sampled bounds' size.
        let mut sampled = Bounds3f::empty();
        for i in 0..=1000 {
            sampled = sampled.union(&at.interpolate(i as Float / 1000.0).apply_bounds(&bx));
        }
        assert!(mb.diagonal().length() < sampled.diagonal().length() * 1.1);
    }

    /// Translation and scale animated, the rotation shared: the bounds of
    /// the ends (padded by rounding only) hold every interpolated box.
    #[test]
    fn motion_bounds_of_straight_motion() {
        let a =
            Transform::translate(Vector3f::new(10.0, 1.0, -4.0)) * Transform::scale(2.0, 1.0, 1.0);
        let b =
            Transform::translate(Vector3f::new(10.5, -2.0, -4.0)) * Transform::scale(1.0, 2.0, 0.5);
        let at = AnimatedTransform::new(a, 0.0, b, 1.0);
        let Keys::General(g) = &at.keys else {
            panic!("scales are general")
        };
        assert_eq!(g.d0.r, g.d1.r, "the straight-motion case");
        let bx = Bounds3f::new(Point3f::new(-1.0, -0.5, -0.2), Point3f::new(1.0, 0.5, 2.0));
        let mb = at.motion_bounds(&bx);
        let ends = a.apply_bounds(&bx).union(&b.apply_bounds(&bx));
        for i in 0..=1000 {
            let xf = at.interpolate(i as Float / 1000.0);
            for c in 0..8 {
                assert!(mb.inside(xf.apply_point(bx.corner(c))), "t={i} c={c}");
            }
        }
        assert!((mb.diagonal() - ends.diagonal()).length() < 1e-3);
        // Pure translation, as a scene's `ActiveTransform` lines give it.
        let a = Transform::translate(Vector3f::new(3.0, 4.0, 5.0));
        let b = Transform::translate(Vector3f::new(3.25, 4.0, 4.5));
        let at = AnimatedTransform::new(a, 0.0, b, 1.0);
        let mb = at.motion_bounds(&bx);
        for i in 0..=1000 {
            let xf = at.interpolate(i as Float / 1000.0);
            for c in 0..8 {
                assert!(mb.inside(xf.apply_point(bx.corner(c))), "t={i} c={c}");
            }
        }
        let ends = a.apply_bounds(&bx).union(&b.apply_bounds(&bx));
        assert!((mb.diagonal() - ends.diagonal()).length() < 1e-4);
    }
}
