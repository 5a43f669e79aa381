//! [`SubObjects`]: the sub-objects of one object, ordered by sub-index.
//!
//! Why not a `BTreeMap<u8, SubObject>` (what this used to be): a sub-object is a large value
//! (about 400 bytes then, 160 since its rare fields are boxed, see [`SubObject`]: typed values,
//! a name, spans), and most objects have one (a VAR) or a
//! handful. A B-tree allocates a node of eleven slots (several kilobytes, past the allocator's
//! fast size classes) for a single sub-object, moves every value through its bulk-build and
//! drop iterators, and those moves and allocations were a third of the time of parsing an EDS.
//! A vector sorted by key allocates exactly what is needed, is built by appending (files list
//! sub-objects in order) and drops in place. Sub-indexes are 8-bit, so a look-up is a binary
//! search over at most 256 entries.
//!
//! The methods are those of `BTreeMap<u8, SubObject>` that the model's users need, with the
//! same meaning (a later insert of a key replaces; iteration in key order; `Debug` and `serde`
//! output as a map), so code written against the map reads the same.

use std::fmt;
use std::ops::{Bound, Index, RangeBounds};

use serde::{Serialize, Serializer};

use crate::device::SubObject;

/// The sub-objects of an object by sub-index, in sub-index order; see the [module
/// docs](self) for why this is a sorted vector.
#[derive(Clone, Default, PartialEq)]
pub struct SubObjects {
    /// Sorted by key, keys unique.
    items: Vec<(u8, SubObject)>,
}

type Pair = (u8, SubObject);

/// Iterator over `(&sub_index, &sub_object)` in sub-index order.
pub type Iter<'a> =
    std::iter::Map<std::slice::Iter<'a, Pair>, fn(&'a Pair) -> (&'a u8, &'a SubObject)>;
/// Iterator over `(&sub_index, &mut sub_object)` in sub-index order.
pub type IterMut<'a> =
    std::iter::Map<std::slice::IterMut<'a, Pair>, fn(&'a mut Pair) -> (&'a u8, &'a mut SubObject)>;
/// Iterator over the sub-indexes, ascending.
pub type Keys<'a> = std::iter::Map<std::slice::Iter<'a, Pair>, fn(&'a Pair) -> &'a u8>;
/// Iterator over the sub-objects in sub-index order.
pub type Values<'a> = std::iter::Map<std::slice::Iter<'a, Pair>, fn(&'a Pair) -> &'a SubObject>;
/// Iterator over the sub-objects in sub-index order, mutable.
pub type ValuesMut<'a> =
    std::iter::Map<std::slice::IterMut<'a, Pair>, fn(&'a mut Pair) -> &'a mut SubObject>;
/// Owning iterator over `(sub_index, sub_object)` in sub-index order.
pub type IntoIter = std::vec::IntoIter<Pair>;

fn pair_ref(p: &Pair) -> (&u8, &SubObject) {
    (&p.0, &p.1)
}
fn pair_mut(p: &mut Pair) -> (&u8, &mut SubObject) {
    (&p.0, &mut p.1)
}

impl SubObjects {
    /// No sub-objects.
    pub const fn new() -> Self {
        SubObjects { items: Vec::new() }
    }

    /// No sub-objects, with room for `n` without reallocating.
    pub fn with_capacity(n: usize) -> Self {
        SubObjects { items: Vec::with_capacity(n) }
    }

    /// Makes room for exactly `n` more (a VAR's one sub-object takes the room of one, not of
    /// the four a growing vector starts with).
    pub fn reserve_exact(&mut self, n: usize) {
        self.items.reserve_exact(n);
    }

    /// How many sub-objects there are.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    fn find(&self, sub: u8) -> Result<usize, usize> {
        // Files list sub-objects in order, so the last one is the usual answer when building.
        match self.items.last() {
            Some(&(k, _)) if k < sub => Err(self.items.len()),
            _ => self.items.binary_search_by_key(&sub, |p| p.0),
        }
    }

    /// The sub-object at `sub`.
    pub fn get(&self, sub: &u8) -> Option<&SubObject> {
        self.find(*sub).ok().map(|i| &self.items[i].1)
    }

    /// The sub-object at `sub`, mutable.
    pub fn get_mut(&mut self, sub: &u8) -> Option<&mut SubObject> {
        self.find(*sub).ok().map(|i| &mut self.items[i].1)
    }

    /// Whether there is a sub-object at `sub`.
    pub fn contains_key(&self, sub: &u8) -> bool {
        self.find(*sub).is_ok()
    }

    /// Puts `value` at `sub`; returns the sub-object it replaces.
    pub fn insert(&mut self, sub: u8, value: SubObject) -> Option<SubObject> {
        match self.find(sub) {
            Ok(i) => Some(std::mem::replace(&mut self.items[i].1, value)),
            Err(i) if i == self.items.len() => {
                self.items.push((sub, value));
                None
            }
            Err(i) => {
                self.items.insert(i, (sub, value));
                None
            }
        }
    }

    /// Takes the sub-object at `sub` out.
    pub fn remove(&mut self, sub: &u8) -> Option<SubObject> {
        self.find(*sub).ok().map(|i| self.items.remove(i).1)
    }

    /// The slot of `sub`, for [`Entry::or_insert`].
    pub fn entry(&mut self, sub: u8) -> Entry<'_> {
        Entry { map: self, sub }
    }

    /// The sub-object with the lowest sub-index.
    pub fn first_key_value(&self) -> Option<(&u8, &SubObject)> {
        self.items.first().map(pair_ref)
    }

    /// The sub-object with the highest sub-index.
    pub fn last_key_value(&self) -> Option<(&u8, &SubObject)> {
        self.items.last().map(pair_ref)
    }

    /// `(sub_index, sub_object)` pairs in sub-index order.
    pub fn iter(&self) -> Iter<'_> {
        self.items.iter().map(pair_ref as fn(&Pair) -> (&u8, &SubObject))
    }

    /// `(sub_index, sub_object)` pairs in sub-index order, mutable.
    pub fn iter_mut(&mut self) -> IterMut<'_> {
        self.items.iter_mut().map(pair_mut as fn(&mut Pair) -> (&u8, &mut SubObject))
    }

    /// The sub-indexes, ascending.
    pub fn keys(&self) -> Keys<'_> {
        self.items.iter().map((|p| &p.0) as fn(&Pair) -> &u8)
    }

    /// The sub-objects in sub-index order.
    pub fn values(&self) -> Values<'_> {
        self.items.iter().map((|p| &p.1) as fn(&Pair) -> &SubObject)
    }

    /// The sub-objects in sub-index order, mutable.
    pub fn values_mut(&mut self) -> ValuesMut<'_> {
        self.items.iter_mut().map((|p| &mut p.1) as fn(&mut Pair) -> &mut SubObject)
    }

    /// The pairs whose sub-index lies in `range`, in order.
    pub fn range(&self, range: impl RangeBounds<u8>) -> Iter<'_> {
        let lo = match range.start_bound() {
            Bound::Included(&s) => self.items.partition_point(|p| p.0 < s),
            Bound::Excluded(&s) => self.items.partition_point(|p| p.0 <= s),
            Bound::Unbounded => 0,
        };
        let hi = match range.end_bound() {
            Bound::Included(&e) => self.items.partition_point(|p| p.0 <= e),
            Bound::Excluded(&e) => self.items.partition_point(|p| p.0 < e),
            Bound::Unbounded => self.items.len(),
        };
        self.items[lo..hi.max(lo)].iter().map(pair_ref as fn(&Pair) -> (&u8, &SubObject))
    }
}

/// A slot of [`SubObjects`], from [`SubObjects::entry`].
pub struct Entry<'a> {
    map: &'a mut SubObjects,
    sub: u8,
}

impl<'a> Entry<'a> {
    /// The sub-object there, after putting `value` there if the slot was empty.
    pub fn or_insert(self, value: SubObject) -> &'a mut SubObject {
        self.or_insert_with(|| value)
    }

    /// The sub-object there, after putting `make()` there if the slot was empty.
    pub fn or_insert_with(self, make: impl FnOnce() -> SubObject) -> &'a mut SubObject {
        let found = self.map.find(self.sub);
        let items = &mut self.map.items;
        let i = match found {
            Ok(i) => i,
            Err(i) if i == items.len() => {
                items.push((self.sub, make()));
                i
            }
            Err(i) => {
                items.insert(i, (self.sub, make()));
                i
            }
        };
        &mut self.map.items[i].1
    }
}

impl Index<&u8> for SubObjects {
    type Output = SubObject;
    /// Panics when there is no sub-object at `sub`, as `BTreeMap` does.
    fn index(&self, sub: &u8) -> &SubObject {
        #[allow(clippy::expect_used)] // the documented contract of `Index`, as for a map
        self.get(sub).expect("no sub-object at this sub-index")
    }
}

impl Extend<(u8, SubObject)> for SubObjects {
    /// As for a map: each pair is inserted in turn, a repeated sub-index replaces.
    fn extend<I: IntoIterator<Item = (u8, SubObject)>>(&mut self, iter: I) {
        // Appended as they come (written straight into the vector: a sub-object is large, and
        // a compact object's implied ones are thousands in a master's DCF), then put in order
        // only when they did not come in order.
        let old = self.items.len();
        self.items.extend(iter);
        self.normalize_from(old.saturating_sub(1));
    }
}

impl FromIterator<(u8, SubObject)> for SubObjects {
    /// As for a map: sorted by sub-index, and for a repeated sub-index the last value wins.
    fn from_iter<I: IntoIterator<Item = (u8, SubObject)>>(iter: I) -> Self {
        let mut m = SubObjects { items: iter.into_iter().collect() };
        m.normalize_from(0);
        m
    }
}

impl SubObjects {
    /// Restores "sorted by key, keys unique" when only `items[from..]` may break it, keeping
    /// the last of equal keys (the later insert, as a map would).
    fn normalize_from(&mut self, from: usize) {
        let tail = self.items.get(from..).unwrap_or_default();
        if tail.is_sorted_by(|a, b| a.0 < b.0) {
            return;
        }
        // Stable: equal keys keep their order, so the last of them is the one kept.
        self.items.sort_by_key(|p| p.0);
        let items = std::mem::take(&mut self.items);
        let mut out: Vec<Pair> = Vec::with_capacity(items.len());
        for p in items {
            match out.last_mut() {
                Some(last) if last.0 == p.0 => *last = p,
                _ => out.push(p),
            }
        }
        self.items = out;
    }
}

impl IntoIterator for SubObjects {
    type Item = (u8, SubObject);
    type IntoIter = IntoIter;
    fn into_iter(self) -> IntoIter {
        self.items.into_iter()
    }
}

impl<'a> IntoIterator for &'a SubObjects {
    type Item = (&'a u8, &'a SubObject);
    type IntoIter = Iter<'a>;
    fn into_iter(self) -> Iter<'a> {
        self.iter()
    }
}

impl<'a> IntoIterator for &'a mut SubObjects {
    type Item = (&'a u8, &'a mut SubObject);
    type IntoIter = IterMut<'a>;
    fn into_iter(self) -> IterMut<'a> {
        self.iter_mut()
    }
}

impl fmt::Debug for SubObjects {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_map().entries(self.iter()).finish()
    }
}

impl Serialize for SubObjects {
    /// A map from sub-index to sub-object, as the `BTreeMap` it replaces.
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_map(self.iter())
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use super::*;
    use crate::{Access, DataType};

    fn sub(i: u8, name: &str) -> SubObject {
        SubObject::new(i, name, DataType::Unsigned8, Access::Ro)
    }

    /// Every operation agrees with a `BTreeMap` given the same sequence.
    #[test]
    fn behaves_as_a_btreemap() {
        let ops: &[(u8, &str)] =
            &[(3, "a"), (1, "b"), (3, "c"), (0, "d"), (200, "e"), (2, "f"), (1, "g")];
        let mut m = SubObjects::new();
        let mut b = BTreeMap::new();
        for &(k, n) in ops {
            assert_eq!(m.insert(k, sub(k, n)), b.insert(k, sub(k, n)));
            assert!(m.iter().eq(b.iter()));
        }
        assert_eq!(m.len(), b.len());
        assert!(m.keys().eq(b.keys()));
        assert_eq!(m.keys().next_back(), b.keys().next_back());
        assert!(m.values().eq(b.values()));
        assert!(m.range(1..).eq(b.range(1..)));
        assert!(m.range(..=2).eq(b.range(..=2)));
        assert!(m.range(4..100).eq(b.range(4..100)));
        assert!(m.range((Bound::Excluded(0), Bound::Excluded(200))).eq(b.range(1..200)));
        assert_eq!(m.get(&3).map(|s| s.name.as_str()), Some("c"));
        assert_eq!(m.get(&4), None);
        assert_eq!(m.remove(&2), b.remove(&2));
        assert_eq!(m.remove(&2), None);
        assert!(m.contains_key(&200) && !m.contains_key(&2));
        m.entry(5).or_insert(sub(5, "h")).name.push('!');
        m.entry(5).or_insert(sub(5, "x")).name.push('?');
        assert_eq!(m[&5].name, "h!?");
        assert_eq!(m.first_key_value().map(|(k, _)| *k), Some(0));
        assert_eq!(m.last_key_value().map(|(k, _)| *k), Some(200));
        for s in m.values_mut() {
            s.name.clear();
        }
        assert!(m.values().all(|s| s.name.is_empty()));
    }

    #[test]
    fn collect_sorts_and_the_last_repeat_wins() {
        let m: SubObjects =
            [(2, sub(2, "x")), (0, sub(0, "a")), (2, sub(2, "y")), (1, sub(1, "b"))]
                .into_iter()
                .collect();
        let names: Vec<_> = m.iter().map(|(k, s)| (*k, s.name.as_str())).collect();
        assert_eq!(names, [(0, "a"), (1, "b"), (2, "y")]);
    }

    /// `extend` inserts in turn, as the map's does: in order, out of order, repeated keys.
    #[test]
    fn extend_behaves_as_a_btreemap() {
        let batches: &[&[(u8, &str)]] =
            &[&[(1, "a"), (2, "b")], &[(3, "c"), (9, "d")], &[(5, "e"), (3, "f"), (5, "g")], &[]];
        let mut m = SubObjects::new();
        let mut b = BTreeMap::new();
        for batch in batches {
            m.extend(batch.iter().map(|&(k, n)| (k, sub(k, n))));
            b.extend(batch.iter().map(|&(k, n)| (k, sub(k, n))));
            assert!(m.iter().eq(b.iter()));
        }
    }

    #[test]
    fn debug_and_serde_output_as_the_map() {
        let m: SubObjects = [(1, sub(1, "b")), (0, sub(0, "a"))].into_iter().collect();
        let b: BTreeMap<u8, SubObject> = m.clone().into_iter().collect();
        assert_eq!(format!("{m:?}"), format!("{b:?}"));
        assert_eq!(serde_json::to_string(&m).ok(), serde_json::to_string(&b).ok());
    }
}
