//! [`EntityList`]: the description's lists of shapes, kept in chunks.
//!
//! A scene of a few hundred thousand shapes holds a few hundred bytes of
//! entity each. In one `Vec`, every doubling would copy all of them (and
//! touch that many fresh pages); in chunks, pushing never moves an entity,
//! and taking them from the end frees each chunk as it empties, so the
//! render objects made from them reuse its memory.

use std::ops::Index;

/// The most bytes a chunk holds: under the C allocator's threshold for
/// giving a block pages of its own (128 KiB), so a freed chunk's memory
/// is reused by the allocations that follow instead of going back to the
/// system. The first chunks are smaller, so a short list stays small.
const MAX_CHUNK_BYTES: usize = 64 << 10;

/// A list of entities in order, grown and emptied a chunk at a time.
#[derive(Clone, Debug)]
pub struct EntityList<T> {
    /// Full chunks, then the last one, which may have room.
    chunks: Vec<Vec<T>>,
    /// The number of entities in all chunks.
    len: usize,
}

impl<T> Default for EntityList<T> {
    fn default() -> Self {
        EntityList::new()
    }
}

impl<T> EntityList<T> {
    /// No entities.
    pub const fn new() -> Self {
        EntityList {
            chunks: Vec::new(),
            len: 0,
        }
    }

    /// The number of entities.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The most entities a chunk holds.
    const MAX_CHUNK: usize = {
        let size = std::mem::size_of::<T>();
        if size == 0 || size >= MAX_CHUNK_BYTES {
            1
        } else {
            MAX_CHUNK_BYTES / size
        }
    };

    /// Appends `entity`, moving none of those already there.
    pub fn push(&mut self, entity: T) {
        match self.chunks.last_mut() {
            Some(last) if last.len() < last.capacity() => last.push(entity),
            _ => {
                let capacity = self.len.clamp(4, Self::MAX_CHUNK.max(4));
                let mut chunk = Vec::with_capacity(capacity);
                chunk.push(entity);
                self.chunks.push(chunk);
            }
        }
        self.len += 1;
    }

    /// Removes the last entity and returns it (`None` when empty); a chunk
    /// that empties is freed at once.
    pub fn pop(&mut self) -> Option<T> {
        let last = self.chunks.last_mut()?;
        let entity = last.pop();
        if last.is_empty() {
            self.chunks.pop();
        }
        if entity.is_some() {
            self.len -= 1;
        }
        entity
    }

    /// The entity at `i`, if there is one.
    pub fn get(&self, mut i: usize) -> Option<&T> {
        for chunk in &self.chunks {
            if i < chunk.len() {
                return chunk.get(i);
            }
            i -= chunk.len();
        }
        None
    }

    /// The entities in order.
    pub fn iter(&self) -> impl DoubleEndedIterator<Item = &T> + Clone {
        self.chunks.iter().flatten()
    }
}

impl<T> Index<usize> for EntityList<T> {
    type Output = T;

    fn index(&self, i: usize) -> &T {
        match self.get(i) {
            Some(entity) => entity,
            None => panic!("entity {i} of a list of {}", self.len),
        }
    }
}

impl<'a, T> IntoIterator for &'a EntityList<T> {
    type Item = &'a T;
    type IntoIter = std::iter::Flatten<std::slice::Iter<'a, Vec<T>>>;

    fn into_iter(self) -> Self::IntoIter {
        self.chunks.iter().flatten()
    }
}

impl<T> FromIterator<T> for EntityList<T> {
    fn from_iter<I: IntoIterator<Item = T>>(iter: I) -> Self {
        let mut list = EntityList::new();
        for entity in iter {
            list.push(entity);
        }
        list
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pushed_entities_come_back_in_order_and_from_the_end() {
        for n in [0, 1, 3, 4, 5, 8191, 8192, 8193, 20_000] {
            let list: EntityList<usize> = (0..n).collect();
            assert_eq!(list.len(), n);
            assert_eq!(list.is_empty(), n == 0);
            assert!(list.iter().copied().eq(0..n));
            assert!((&list).into_iter().rev().copied().eq((0..n).rev()));
            for i in (0..n).step_by(97) {
                assert_eq!(list[i], i);
            }
            assert_eq!(list.get(n), None);
            // No chunk beyond the largest, and none empty.
            assert!(list
                .chunks
                .iter()
                .all(|c| !c.is_empty() && c.capacity() <= EntityList::<usize>::MAX_CHUNK));

            let mut list = list;
            let mut back = Vec::new();
            while let Some(x) = list.pop() {
                back.push(x);
                assert_eq!(list.len(), n - back.len());
                assert!(list.chunks.iter().all(|c| !c.is_empty()));
            }
            assert!(back.into_iter().eq((0..n).rev()));
            assert!(list.is_empty() && list.chunks.is_empty());
            // Pushing after popping appends where the list now ends.
            list.push(7);
            list.push(8);
            assert!(list.iter().copied().eq([7, 8]));
        }
    }

    #[test]
    fn pushing_moves_no_entity() {
        let mut list = EntityList::new();
        list.push(0u64);
        let first: *const u64 = &list[0];
        for i in 1..10_000 {
            list.push(i);
        }
        assert!(std::ptr::eq(first, &list[0]));
    }
}
