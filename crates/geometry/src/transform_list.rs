//! A list of transformations stored compactly: affine ones without their
//! matrices' last rows.
//!
//! Scenes of many placed copies (a million object instances) hold one
//! transformation and its inverse per copy; nearly all are affine, whose
//! matrices end in the row (0, 0, 0, 1). Kept without it, a pair takes 96
//! bytes instead of 128, and gives back, bit for bit, the transformation
//! it was made from.

use crate::float::Float;
use crate::transform::{SquareMatrix4, Transform};

/// Transformations in order, each read back bit for bit as pushed. While
/// every one pushed is affine (both matrices' last rows are (0, 0, 0, 1)
/// to the bit, `+0`s), they are kept without those rows, 96 bytes each;
/// the first that is not turns the list into whole transformations.
#[derive(Clone, Debug)]
pub struct TransformList(Stored);

#[derive(Clone, Debug)]
enum Stored {
    /// All affine: without the matrices' last rows.
    Affine(Vec<AffinePair>),
    /// Some not affine: whole.
    Full(Vec<Transform>),
}

impl Default for TransformList {
    fn default() -> TransformList {
        TransformList(Stored::Affine(Vec::new()))
    }
}

/// An affine transformation and its inverse without their last rows.
#[derive(Clone, Copy, Debug)]
struct AffinePair {
    m: [[Float; 4]; 3],
    m_inv: [[Float; 4]; 3],
}

impl AffinePair {
    const LAST_ROW: [Float; 4] = [0.0, 0.0, 0.0, 1.0];

    /// `t` without its last rows, when they are (0, 0, 0, 1) to the bit.
    fn of(t: &Transform) -> Option<AffinePair> {
        let (m, mi) = (&t.matrix().m, &t.inverse_matrix().m);
        let last = |row: &[Float; 4]| {
            row.iter()
                .zip(AffinePair::LAST_ROW)
                .all(|(a, b)| a.to_bits() == b.to_bits())
        };
        (last(&m[3]) && last(&mi[3])).then(|| AffinePair {
            m: [m[0], m[1], m[2]],
            m_inv: [mi[0], mi[1], mi[2]],
        })
    }

    #[inline]
    fn transform(&self) -> Transform {
        let full =
            |r: &[[Float; 4]; 3]| SquareMatrix4::new([r[0], r[1], r[2], AffinePair::LAST_ROW]);
        Transform::from_matrices(full(&self.m), full(&self.m_inv))
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

    /// Bytes each transformation takes now (96 while all are affine, 128
    /// after).
    pub fn bytes_each(&self) -> usize {
        match &self.0 {
            Stored::Affine(_) => std::mem::size_of::<AffinePair>(),
            Stored::Full(_) => std::mem::size_of::<Transform>(),
        }
    }

    /// Transformation `i`, bit for bit as pushed. Panics past the end.
    #[inline]
    pub fn get(&self, i: usize) -> Transform {
        match &self.0 {
            Stored::Affine(v) => v[i].transform(),
            Stored::Full(v) => v[i],
        }
    }

    /// Appends `t`.
    pub fn push(&mut self, t: Transform) {
        if let Stored::Affine(v) = &mut self.0 {
            match AffinePair::of(&t) {
                Some(a) => return v.push(a),
                None => {
                    // The first that is not affine: every one whole from
                    // here on.
                    let mut full = Vec::with_capacity(v.capacity());
                    full.extend(v.iter().map(AffinePair::transform));
                    self.0 = Stored::Full(full);
                }
            }
        }
        if let Stored::Full(v) = &mut self.0 {
            v.push(t);
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

    #[test]
    fn affine_transformations_come_back_bit_for_bit_in_96_bytes() {
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
        assert_eq!(list.bytes_each(), 96);
        assert_eq!(list.len(), ts.len());
        for (i, t) in ts.iter().enumerate() {
            assert!(same(&list.get(i), t), "{i}");
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
