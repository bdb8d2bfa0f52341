//! The description's object instances (`ObjectInstance`), kept compactly:
//! a scene may hold millions. Per instance, the index of its object's name
//! and its transformation in a [`TransformList`] (48 bytes when affine:
//! its inverse alone), which the created scene's instance set takes over
//! as they are.

use std::collections::HashMap;
use std::sync::Arc;

use rpbrt_geometry::{AnimatedTransform, Transform, TransformList};
use rpbrt_parser::FileLoc;

use super::entities::InstanceTransform;

/// The `ObjectInstance`s of a scene, in order.
#[derive(Clone, Debug, Default)]
pub struct InstanceList {
    /// The names instanced, each once, in order of first use, with where
    /// that first use was (errors about a name point there).
    pub(super) names: Vec<(Arc<str>, FileLoc)>,
    /// Each name's index in `names`.
    index: HashMap<Arc<str>, u32>,
    /// Per instance: its name's index in `names`.
    pub(super) name_of: Vec<u32>,
    /// Per instance: from instance space (the definition's render space)
    /// to render space; the identity in an animated instance's place.
    pub(super) fixed: TransformList,
    /// The animated instances, in order: their index and transformation.
    pub(super) animated: Vec<(u32, Box<AnimatedTransform>)>,
}

impl InstanceList {
    /// No instances.
    pub fn new() -> InstanceList {
        InstanceList::default()
    }

    /// The number of instances.
    pub fn len(&self) -> usize {
        self.name_of.len()
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.name_of.is_empty()
    }

    /// Appends an instance of the object `name`, placed by `t`; `loc` is
    /// where the directive was (kept for the name's first instance).
    /// Returns the bytes it added, for the memory budget.
    pub fn push(&mut self, name: &str, loc: &FileLoc, t: InstanceTransform) -> usize {
        let mut bytes = std::mem::size_of::<u32>();
        // Consecutive instances mostly share their object: one comparison
        // before the hash.
        let k = match self.name_of.last() {
            Some(&k) if *self.names[k as usize].0 == *name => k,
            _ => match self.index.get(name) {
                Some(&k) => k,
                None => {
                    let k = self.names.len() as u32;
                    let shared: Arc<str> = Arc::from(name);
                    self.names.push((shared.clone(), loc.clone()));
                    self.index.insert(shared, k);
                    bytes += 64 + name.len();
                    k
                }
            },
        };
        let i = self.name_of.len() as u32;
        self.name_of.push(k);
        match t {
            InstanceTransform::Fixed(t) => self.fixed.push(t),
            InstanceTransform::Animated(a) => {
                bytes += std::mem::size_of::<AnimatedTransform>() + 16;
                self.fixed.push(Transform::default());
                self.animated.push((i, a));
            }
        }
        bytes + self.fixed.bytes_each()
    }

    /// Instance `i`: its object's name and its transformation.
    pub fn get(&self, i: usize) -> (&Arc<str>, InstanceTransform) {
        let name = &self.names[self.name_of[i] as usize].0;
        let t = match self.animated.binary_search_by_key(&(i as u32), |(k, _)| *k) {
            Ok(j) => InstanceTransform::Animated(self.animated[j].1.clone()),
            Err(_) => InstanceTransform::Fixed(self.fixed.get(i)),
        };
        (name, t)
    }

    /// The names instanced, each once, with where each was first
    /// instanced.
    pub fn names(&self) -> impl Iterator<Item = (&Arc<str>, &FileLoc)> {
        self.names.iter().map(|(n, l)| (n, l))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rpbrt_geometry::Vector3f;

    #[test]
    fn instances_come_back_in_order_with_their_names_and_transformations() {
        let loc = |line| FileLoc::new(Arc::from("s.pbrt"), line, 1);
        let t = |x| Transform::translate(Vector3f::new(x, 0.0, 0.0));
        let moving = AnimatedTransform::new(t(1.0), 0.0, t(2.0), 1.0);
        let mut list = InstanceList::new();
        list.push("a", &loc(1), InstanceTransform::Fixed(t(0.0)));
        list.push("b", &loc(2), InstanceTransform::Fixed(t(1.0)));
        list.push(
            "a",
            &loc(3),
            InstanceTransform::Animated(Box::new(moving.clone())),
        );
        list.push("a", &loc(4), InstanceTransform::Fixed(t(3.0)));
        list.push("b", &loc(5), InstanceTransform::Fixed(t(4.0)));
        assert_eq!(list.len(), 5);
        let names: Vec<_> = list.names().map(|(n, l)| (n.to_string(), l.line)).collect();
        assert_eq!(names, [("a".to_string(), 1), ("b".to_string(), 2)]);
        let expect = [
            ("a", InstanceTransform::Fixed(t(0.0))),
            ("b", InstanceTransform::Fixed(t(1.0))),
            ("a", InstanceTransform::Animated(Box::new(moving))),
            ("a", InstanceTransform::Fixed(t(3.0))),
            ("b", InstanceTransform::Fixed(t(4.0))),
        ];
        for (i, (name, xf)) in expect.into_iter().enumerate() {
            let (n, x) = list.get(i);
            assert_eq!((&**n, x), (name, xf), "{i}");
        }
    }
}
