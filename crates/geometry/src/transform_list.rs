//! A list of transformations stored compactly: affine ones by their
//! inverse matrices alone, without the last rows.
//!
//! Scenes of many placed copies (a million object instances) hold one
//! transformation per copy; nearly all are affine, whose matrices end in
//! the row (0, 0, 0, 1). What a copy needs most often is the inverse (each
//! ray that meets the copy's bounds is taken into its space); the forward
//! matrix only maps the copy's bounds, once, and the hits found on it. So
//! an affine transformation is kept as its inverse's first three rows (48
//! bytes instead of a pair's 128), read back bit for bit, and the forward
//! matrix is recomputed from it where asked for (in double precision,
//! rounded once: within an ulp or two of the matrix it was made from,
//! which pbrt's composed pairs are of each other's inverse too).

use crate::float::Float;
use crate::transform::{SquareMatrix4, Transform};

/// Transformations in order. An affine one (both matrices' last rows
/// (0, 0, 0, 1) to the bit, `+0`s, with a finite, invertible inverse)
/// reads back with its inverse bit for bit and its forward matrix
/// recomputed from it; any other, bit for bit. While every one pushed is
/// affine, each is kept as its inverse without the last row, 48 bytes;
/// the first that is not turns the list into whole transformations (128
/// bytes each). What a transformation reads back as depends on it alone,
/// not on the others in the list.
#[derive(Clone, Debug)]
pub struct TransformList(Stored);

#[derive(Clone, Debug)]
enum Stored {
    /// All affine: their inverses without the last rows.
    Affine(Vec<AffineInverse>),
    /// Some not affine: whole.
    Full(Vec<Transform>),
}

impl Default for TransformList {
    fn default() -> TransformList {
        TransformList(Stored::Affine(Vec::new()))
    }
}

/// The inverse of an affine transformation without its last row.
#[derive(Clone, Copy, Debug)]
struct AffineInverse {
    m_inv: [[Float; 4]; 3],
}

impl AffineInverse {
    const LAST_ROW: [Float; 4] = [0.0, 0.0, 0.0, 1.0];

    /// `t`'s inverse without its last row, when both of `t`'s matrices end
    /// in (0, 0, 0, 1) to the bit and the inverse can be inverted back.
    fn of(t: &Transform) -> Option<AffineInverse> {
        let (m, mi) = (&t.matrix().m, &t.inverse_matrix().m);
        let last = |row: &[Float; 4]| {
            row.iter()
                .zip(AffineInverse::LAST_ROW)
                .all(|(a, b)| a.to_bits() == b.to_bits())
        };
        let a = AffineInverse {
            m_inv: [mi[0], mi[1], mi[2]],
        };
        (last(&m[3]) && last(&mi[3]) && a.forward().is_some()).then_some(a)
    }

    /// The inverse matrix, whole.
    #[inline]
    fn matrix(&self) -> SquareMatrix4 {
        let r = &self.m_inv;
        SquareMatrix4::new([r[0], r[1], r[2], AffineInverse::LAST_ROW])
    }

    /// The forward matrix: the inverse of the stored one, computed in
    /// double precision (the 3×3 part by its adjugate, then the
    /// translation) and rounded once; `None` when it is singular or the
    /// result not finite.
    fn forward(&self) -> Option<SquareMatrix4> {
        let a = self.m_inv.map(|row| row.map(f64::from));
        let cof = |r0: usize, r1: usize, c0: usize, c1: usize| {
            a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0]
        };
        // Adjugate (transposed cofactors) of the 3×3 part.
        let adj = [
            [cof(1, 2, 1, 2), -cof(0, 2, 1, 2), cof(0, 1, 1, 2)],
            [-cof(1, 2, 0, 2), cof(0, 2, 0, 2), -cof(0, 1, 0, 2)],
            [cof(1, 2, 0, 1), -cof(0, 2, 0, 1), cof(0, 1, 0, 1)],
        ];
        let det = a[0][0] * adj[0][0] + a[0][1] * adj[1][0] + a[0][2] * adj[2][0];
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let mut m = [[0.0 as Float; 4]; 4];
        for i in 0..3 {
            // `+ 0.0` makes zeros positive (a cofactor's negation gives
            // `-0.0`), as composed matrices have them.
            let inv = adj[i].map(|v| v / det + 0.0);
            let t = 0.0 - (inv[0] * a[0][3] + inv[1] * a[1][3] + inv[2] * a[2][3]);
            m[i] = [
                inv[0] as Float,
                inv[1] as Float,
                inv[2] as Float,
                t as Float,
            ];
        }
        m[3] = AffineInverse::LAST_ROW;
        m.iter()
            .flatten()
            .all(|v| v.is_finite())
            .then_some(SquareMatrix4::new(m))
    }

    #[inline]
    fn transform(&self) -> Transform {
        // `of` checked that the forward matrix exists.
        let m = self.forward().unwrap_or_default();
        Transform::from_matrices(m, self.matrix())
    }
}

impl TransformList {
    /// An empty list.
    pub fn new() -> TransformList {
        TransformList::default()
    }

    /// The number of transformations.
    pub fn len(&self) -> usize {
        match &self.0 {
            Stored::Affine(v) => v.len(),
            Stored::Full(v) => v.len(),
        }
    }

    /// True when the list is empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Bytes each transformation takes now (48 while all are affine, 128
    /// after).
    pub fn bytes_each(&self) -> usize {
        match &self.0 {
            Stored::Affine(_) => std::mem::size_of::<AffineInverse>(),
            Stored::Full(_) => std::mem::size_of::<Transform>(),
        }
    }

    /// Transformation `i`: its inverse matrix bit for bit as pushed, its
    /// forward one too once the list is whole, else recomputed from the
    /// inverse (see the module's documentation). Panics past the end.
    #[inline]
    pub fn get(&self, i: usize) -> Transform {
        match &self.0 {
            Stored::Affine(v) => v[i].transform(),
            Stored::Full(v) => v[i],
        }
    }

    /// The inverse of transformation `i`'s matrix, bit for bit as pushed
    /// (what takes rays into the space it places). Panics past the end.
    #[inline]
    pub fn inverse_matrix(&self, i: usize) -> SquareMatrix4 {
        match &self.0 {
            Stored::Affine(v) => v[i].matrix(),
            Stored::Full(v) => *v[i].inverse_matrix(),
        }
    }

    /// Appends `t`.
    pub fn push(&mut self, t: Transform) {
        let affine = AffineInverse::of(&t);
        if let Stored::Affine(v) = &mut self.0 {
            match affine {
                Some(a) => return v.push(a),
                None => {
                    // The first that is not affine: every one whole from
                    // here on.
                    let mut full = Vec::with_capacity(v.capacity());
                    full.extend(v.iter().map(AffineInverse::transform));
                    self.0 = Stored::Full(full);
                }
            }
        }
        if let Stored::Full(v) = &mut self.0 {
            // An affine one reads back as in an affine list (its forward
            // matrix recomputed), whatever came before it.
            v.push(affine.map_or(t, |a| a.transform()));
        }
    }

    /// Keeps the transformations whose index `keep` accepts, in order.
    pub fn retain_indices(&mut self, mut keep: impl FnMut(usize) -> bool) {
        let mut i = 0;
        let mut next = || {
            i += 1;
            keep(i - 1)
        };
        match &mut self.0 {
            Stored::Affine(v) => v.retain(|_| next()),
            Stored::Full(v) => v.retain(|_| next()),
        }
    }

    /// Room for `n` more.
    pub fn reserve_exact(&mut self, n: usize) {
        match &mut self.0 {
            Stored::Affine(v) => v.reserve_exact(n),
            Stored::Full(v) => v.reserve_exact(n),
        }
    }

    /// Gives back the room reserved beyond the transformations.
    pub fn shrink_to_fit(&mut self) {
        match &mut self.0 {
            Stored::Affine(v) => v.shrink_to_fit(),
            Stored::Full(v) => v.shrink_to_fit(),
        }
    }

    /// Reverses the order.
    pub fn reverse(&mut self) {
        match &mut self.0 {
            Stored::Affine(v) => v.reverse(),
            Stored::Full(v) => v.reverse(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tuple::Vector3f;

    fn same(a: &Transform, b: &Transform) -> bool {
        a.same_bits(b)
    }

    /// Every entry of `a` within `rel` of `b`'s, relative to the largest
    /// entry of `b`'s row.
    fn close(a: &SquareMatrix4, b: &SquareMatrix4, rel: Float) -> bool {
        a.m.iter().zip(&b.m).all(|(ra, rb)| {
            let scale = rb.iter().fold(0.0 as Float, |s, v| s.max(v.abs()));
            ra.iter().zip(rb).all(|(x, y)| (x - y).abs() <= rel * scale)
        })
    }

    #[test]
    fn affine_transformations_keep_their_inverses_bit_for_bit_in_48_bytes() {
        let mut list = TransformList::new();
        let ts: Vec<Transform> = (0..50)
            .map(|k| {
                let k = k as Float;
                Transform::translate(Vector3f::new(k * 0.37, -k, 1e-3 * k))
                    * Transform::rotate(k * 7.3, Vector3f::new(0.2, 1.0, -0.4))
                    * Transform::scale(1.0 + k, 0.5, -2.0)
            })
            .collect();
        for t in &ts {
            list.push(*t);
        }
        assert_eq!(list.bytes_each(), 48);
        assert_eq!(list.len(), ts.len());
        for (i, t) in ts.iter().enumerate() {
            let got = list.get(i);
            assert_eq!(list.inverse_matrix(i), *t.inverse_matrix(), "{i}");
            assert_eq!(got.inverse_matrix(), t.inverse_matrix(), "{i}");
            // The forward matrix recomputed: within a few ulps of the one
            // composed beside the inverse.
            assert!(close(got.matrix(), t.matrix(), 4e-6), "{i}: {got:?} {t:?}");
        }
        // Translations and scales by powers of two invert exactly.
        let exact =
            Transform::translate(Vector3f::new(3.5, -2.0, 0.25)) * Transform::scale(2.0, 0.5, -4.0);
        list.push(exact);
        assert!(same(&list.get(ts.len()), &exact));
    }

    #[test]
    fn a_singular_or_infinite_inverse_keeps_the_list_whole() {
        for t in [
            Transform::scale(0.0, 1.0, 1.0),
            Transform::scale(1e-39, 1.0, 1.0),
        ] {
            let mut list = TransformList::new();
            let a = Transform::translate(Vector3f::new(1.0, 2.0, 3.0));
            list.push(a);
            list.push(t);
            assert_eq!(list.bytes_each(), 128, "{t:?}");
            assert!(same(&list.get(0), &a));
            assert!(same(&list.get(1), &t));
        }
    }

    #[test]
    fn a_projective_one_turns_the_list_whole_and_keeps_every_bit() {
        let mut list = TransformList::new();
        let a = Transform::translate(Vector3f::new(1.0, 2.0, 3.0));
        let p = Transform::perspective(60.0, 0.01, 1000.0).expect("a valid projection");
        // A last row of -0.0 is not (0, 0, 0, 1) to the bit: kept whole.
        let mut m = *a.matrix();
        m.m[3][0] = -0.0;
        let negative_zero = Transform::from_matrices(m, *a.inverse_matrix());
        list.push(a);
        list.push(p);
        list.push(negative_zero);
        list.push(a);
        assert_eq!(list.bytes_each(), 128);
        for (i, t) in [a, p, negative_zero, a].iter().enumerate() {
            assert!(same(&list.get(i), t), "{i}");
        }
        // An affine transformation whose forward matrix is recomputed
        // reads back the same in an affine list and in a whole one.
        let r = Transform::rotate(33.0, Vector3f::new(0.3, 1.0, -0.2));
        let mut affine = TransformList::new();
        affine.push(r);
        list.push(r);
        assert_eq!(affine.bytes_each(), 48);
        assert!(same(&affine.get(0), &list.get(4)));
        assert_eq!(list.get(4).inverse_matrix(), r.inverse_matrix());
    }

    #[test]
    fn retain_and_reverse_keep_the_order_of_what_is_left() {
        for projective in [false, true] {
            let mut list = TransformList::new();
            let ts: Vec<Transform> = (0..10)
                .map(|k| Transform::translate(Vector3f::new(k as Float, 0.0, 0.0)))
                .collect();
            for t in &ts {
                list.push(*t);
            }
            if projective {
                list.push(Transform::perspective(45.0, 0.1, 10.0).expect("valid"));
            }
            list.retain_indices(|i| i >= 10 || i % 3 != 1);
            list.reverse();
            let kept: Vec<usize> = (0..10).filter(|i| i % 3 != 1).rev().collect();
            let offset = usize::from(projective);
            assert_eq!(list.len(), kept.len() + offset);
            for (j, &i) in kept.iter().enumerate() {
                assert!(same(&list.get(j + offset), &ts[i]), "{projective} {j}");
            }
        }
    }
}
