//! [`SubObjects`]: the sub-objects of one object, ordered by sub-index.
//!
//! Why not a `BTreeMap<u8, SubObject>` (what this used to be): a sub-object is a large value
//! (about 400 bytes then, 168 since its rare fields are boxed, see [`SubObject`]: typed values,
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
//!
//! **Implied sub-objects** ([`SubObjects::set_implied`]): an EDS object with `CompactSubObj=n`
//! has sub-objects `1..=n` that are copies of one template named by number, and a CANopen
//! master's DCF declares up to a few thousand. They are kept as the template and the count and
//! made the first time something reads past the sub-objects written out (at most once; a
//! look-up of one written out, [`SubObjects::len`] and [`SubObjects::contains_key`] do not make
//! them). Changing one through `&mut self` makes only that one. Every method answers as if all
//! had been there from the start. This is what python-canopen does with a compact array (it
//! makes a member when it is asked for), and it keeps the cost off a parse whose user reads a
//! few objects: making them all took a third of the parse time of a master's DCF.

use std::fmt;
use std::ops::{Bound, Index, RangeBounds};
use std::sync::OnceLock;

use serde::{Serialize, Serializer};

use crate::Name;
use crate::device::SubObject;

/// The sub-objects of an object by sub-index, in sub-index order; see the [module
/// docs](self) for why this is a sorted vector.
#[derive(Clone, Default)]
pub struct SubObjects {
    /// Sorted by key, keys unique: all the sub-objects, or, while `implied` is set, those
    /// written out (which replace implied ones at the same sub-index).
    items: Vec<(u8, SubObject)>,
    /// Sub-objects implied by a template and not made yet.
    implied: Option<Box<Implied>>,
}

/// Sub-objects `1..=count`, each a copy of `template` numbered and named by
/// [`implied_name`]`(stem, sub_index)`.
#[derive(Clone)]
struct Implied {
    template: SubObject,
    count: u8,
    stem: Name,
    /// All the sub-objects (these and the ones written out), made on the first read that needs
    /// them; from then on, a change goes to this vector (see [`SubObjects::items_mut`]).
    all: OnceLock<Vec<Pair>>,
}

/// The name of the implied sub-object `n` of an object named `stem` (CiA 306 `CompactSubObj`):
/// the object's name followed by the sub-index in decimal.
pub fn implied_name(stem: &str, n: u8) -> Name {
    Namer::new(stem).name(n)
}

/// Makes implied names, thousands in a CANopen master's DCF: the text is put together in a
/// buffer that holds the stem once, and each name is made from it in one go (inline when it
/// fits in 24 bytes, else one allocation of its size). Appending to a `Name` calls out of line
/// at each step.
struct Namer {
    buf: String,
    stem: usize,
}

impl Namer {
    fn new(stem: &str) -> Self {
        let mut buf = String::with_capacity(stem.len() + 3);
        buf.push_str(stem);
        Namer { buf, stem: stem.len() }
    }

    fn name(&mut self, n: u8) -> Name {
        self.buf.truncate(self.stem);
        self.buf.push_str(decimal(n));
        Name::new(&self.buf)
    }
}

/// The decimal digits of `n`, without leading zeros, from a table made at compile time (a
/// compact object names thousands of implied sub-objects by number).
fn decimal(n: u8) -> &'static str {
    /// "000" to "255", three digits each.
    const TABLE: [u8; 768] = {
        let mut t = [0u8; 768];
        let mut i = 0;
        while i < 256 {
            t[3 * i] = b'0' + (i / 100) as u8;
            t[3 * i + 1] = b'0' + (i / 10 % 10) as u8;
            t[3 * i + 2] = b'0' + (i % 10) as u8;
            i += 1;
        }
        t
    };
    const DIGITS: &str = match std::str::from_utf8(&TABLE) {
        Ok(s) => s,
        Err(_) => panic!("ASCII digits are UTF-8"),
    };
    let skip = usize::from(n < 100) + usize::from(n < 10);
    let at = 3 * usize::from(n);
    DIGITS.get(at + skip..at + 3).unwrap_or_default()
}

impl Implied {
    fn keys(&self) -> std::ops::RangeInclusive<u8> {
        1..=self.count
    }

    /// The implied sub-object `i`.
    fn make(&self, i: u8) -> SubObject {
        let mut s = self.template.clone();
        s.sub_index = i;
        s.name = implied_name(&self.stem, i);
        s
    }

    /// All the sub-objects: the implied ones, replaced by `written` where it has the same
    /// sub-index, in order.
    fn merge(&self, written: &[Pair]) -> Vec<Pair> {
        let mut out = Vec::with_capacity(usize::from(self.count) + written.len());
        let (before, rest) = written.split_at(written.partition_point(|p| p.0 < 1));
        let (within, after) = rest.split_at(rest.partition_point(|p| p.0 <= self.count));
        out.extend_from_slice(before);
        // Clones of the template written straight into the vector, then numbered and named in
        // place: making each whole first and moving it in copied its 160 bytes twice.
        let first = out.len();
        out.extend(self.keys().map(|i| (i, self.template.clone())));
        let mut names = Namer::new(&self.stem);
        for (i, s) in &mut out[first..] {
            s.sub_index = *i;
            s.name = names.name(*i);
        }
        for w in within {
            // `within` has sub-indexes 1..=count, and `out[first..]` holds those in order.
            out[first + usize::from(w.0) - 1] = w.clone();
        }
        out.extend_from_slice(after);
        out
    }
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
        SubObjects { items: Vec::new(), implied: None }
    }

    /// No sub-objects, with room for `n` without reallocating.
    pub fn with_capacity(n: usize) -> Self {
        SubObjects { items: Vec::with_capacity(n), implied: None }
    }

    /// Puts at `1..=count` copies of `template`, each with its sub-index and the name
    /// [`implied_name`]`(stem, sub_index)` (an EDS `CompactSubObj`), replacing what is there;
    /// they are made when first read (see the [module docs](self)).
    pub fn set_implied(&mut self, template: SubObject, count: u8, stem: &str) {
        let items = self.items_mut();
        items.retain(|p| !(1..=count).contains(&p.0));
        if count > 0 {
            let all = OnceLock::new();
            self.implied = Some(Box::new(Implied { template, count, stem: Name::from(stem), all }));
        }
    }

    /// Whether `f` holds for some sub-object, where `f` does not read the sub-index or the
    /// name: asks it of the implied sub-objects' template once, without making them.
    pub fn any_ignoring_names(&self, f: impl Fn(&SubObject) -> bool) -> bool {
        self.items.iter().any(|p| f(&p.1)) || self.implied.as_ref().is_some_and(|m| f(&m.template))
    }

    /// All the sub-objects, sorted (implied ones made if they are not yet).
    fn all(&self) -> &[Pair] {
        match &self.implied {
            None => &self.items,
            Some(m) => m.all.get_or_init(|| m.merge(&self.items)),
        }
    }

    /// The vector of all the sub-objects, to change (implied ones made into it first).
    fn items_mut(&mut self) -> &mut Vec<Pair> {
        if let Some(mut m) = self.implied.take() {
            self.items = match m.all.take() {
                Some(all) => all,
                None => m.merge(&self.items),
            };
        }
        &mut self.items
    }

    /// The index in `items` of `sub`, making it there first if it is an implied sub-object not
    /// written out; `Err` where `sub` would go if there is none.
    fn find_or_make(&mut self, sub: u8) -> Result<usize, usize> {
        if self.implied.as_ref().is_some_and(|m| m.all.get().is_some()) {
            // All made already: changes go to that vector from now on (merging again after each
            // change would make them all again each time).
            self.items_mut();
        }
        let found = self.find(sub);
        let Some(m) = &self.implied else { return found };
        match found {
            Err(i) if m.keys().contains(&sub) => {
                self.items.insert(i, (sub, m.make(sub)));
                Ok(i)
            }
            found => found,
        }
    }

    /// Makes room for exactly `n` more (a VAR's one sub-object takes the room of one, not of
    /// the four a growing vector starts with).
    pub fn reserve_exact(&mut self, n: usize) {
        self.items.reserve_exact(n);
    }

    /// How many sub-objects there are.
    pub fn len(&self) -> usize {
        match &self.implied {
            None => self.items.len(),
            Some(m) => {
                let written = self.items.len();
                let lo = self.items.partition_point(|p| p.0 < 1);
                let hi = self.items.partition_point(|p| p.0 <= m.count);
                written + usize::from(m.count) - (hi - lo)
            }
        }
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty() && self.implied.is_none()
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
        match self.find(*sub) {
            Ok(i) => Some(&self.items[i].1),
            Err(_) if self.implied.as_ref().is_some_and(|m| m.keys().contains(sub)) => {
                let all = self.all();
                all.binary_search_by_key(sub, |p| p.0).ok().map(|i| &all[i].1)
            }
            Err(_) => None,
        }
    }

    /// The sub-object at `sub`, mutable.
    pub fn get_mut(&mut self, sub: &u8) -> Option<&mut SubObject> {
        self.find_or_make(*sub).ok().map(|i| &mut self.items[i].1)
    }

    /// Whether there is a sub-object at `sub`.
    pub fn contains_key(&self, sub: &u8) -> bool {
        self.find(*sub).is_ok() || self.implied.as_ref().is_some_and(|m| m.keys().contains(sub))
    }

    /// Puts `value` at `sub`; returns the sub-object it replaces.
    pub fn insert(&mut self, sub: u8, value: SubObject) -> Option<SubObject> {
        match self.find_or_make(sub) {
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
        if self.contains_key(sub) {
            self.items_mut();
        }
        self.find(*sub).ok().map(|i| self.items.remove(i).1)
    }

    /// The slot of `sub`, for [`Entry::or_insert`].
    pub fn entry(&mut self, sub: u8) -> Entry<'_> {
        Entry { map: self, sub }
    }

    /// The sub-object with the lowest sub-index.
    pub fn first_key_value(&self) -> Option<(&u8, &SubObject)> {
        self.all().first().map(pair_ref)
    }

    /// The sub-object with the highest sub-index.
    pub fn last_key_value(&self) -> Option<(&u8, &SubObject)> {
        self.all().last().map(pair_ref)
    }

    /// `(sub_index, sub_object)` pairs in sub-index order.
    pub fn iter(&self) -> Iter<'_> {
        self.all().iter().map(pair_ref as fn(&Pair) -> (&u8, &SubObject))
    }

    /// `(sub_index, sub_object)` pairs in sub-index order, mutable.
    pub fn iter_mut(&mut self) -> IterMut<'_> {
        self.items_mut().iter_mut().map(pair_mut as fn(&mut Pair) -> (&u8, &mut SubObject))
    }

    /// The sub-indexes, ascending.
    pub fn keys(&self) -> Keys<'_> {
        self.all().iter().map((|p| &p.0) as fn(&Pair) -> &u8)
    }

    /// The sub-objects in sub-index order.
    pub fn values(&self) -> Values<'_> {
        self.all().iter().map((|p| &p.1) as fn(&Pair) -> &SubObject)
    }

    /// The sub-objects in sub-index order, mutable.
    pub fn values_mut(&mut self) -> ValuesMut<'_> {
        self.items_mut().iter_mut().map((|p| &mut p.1) as fn(&mut Pair) -> &mut SubObject)
    }

    /// The pairs whose sub-index lies in `range`, in order.
    pub fn range(&self, range: impl RangeBounds<u8>) -> Iter<'_> {
        let all = self.all();
        let lo = match range.start_bound() {
            Bound::Included(&s) => all.partition_point(|p| p.0 < s),
            Bound::Excluded(&s) => all.partition_point(|p| p.0 <= s),
            Bound::Unbounded => 0,
        };
        let hi = match range.end_bound() {
            Bound::Included(&e) => all.partition_point(|p| p.0 <= e),
            Bound::Excluded(&e) => all.partition_point(|p| p.0 < e),
            Bound::Unbounded => all.len(),
        };
        all[lo..hi.max(lo)].iter().map(pair_ref as fn(&Pair) -> (&u8, &SubObject))
    }
}

impl PartialEq for SubObjects {
    /// Equal when they hold the same sub-objects, made or still implied.
    fn eq(&self, other: &Self) -> bool {
        self.all() == other.all()
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
        let found = self.map.find_or_make(self.sub);
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
        let items = self.items_mut();
        let old = items.len();
        items.extend(iter);
        self.normalize_from(old.saturating_sub(1));
    }
}

impl FromIterator<(u8, SubObject)> for SubObjects {
    /// As for a map: sorted by sub-index, and for a repeated sub-index the last value wins.
    fn from_iter<I: IntoIterator<Item = (u8, SubObject)>>(iter: I) -> Self {
        let mut m = SubObjects { items: iter.into_iter().collect(), implied: None };
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
    fn into_iter(mut self) -> IntoIter {
        self.items_mut();
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
        s.collect_map(self.iter().map(|(k, v)| (format!("0x{k:02X}"), v)))
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
    fn debug_and_serde_output_as_the_map_with_hex_keys() {
        let m: SubObjects = [(1, sub(1, "b")), (0, sub(0, "a"))].into_iter().collect();
        let b: BTreeMap<u8, SubObject> = m.clone().into_iter().collect();
        assert_eq!(format!("{m:?}"), format!("{b:?}"));
        // Serialised with hex keys, as device files write sub-indexes.
        let hex: BTreeMap<String, &SubObject> =
            b.iter().map(|(k, v)| (format!("0x{k:02X}"), v)).collect();
        assert_eq!(serde_json::to_string(&m).ok(), serde_json::to_string(&hex).ok());
    }

    #[test]
    fn implied_names() {
        assert_eq!(implied_name("Obj", 0), "Obj0");
        assert_eq!(implied_name("Obj", 7), "Obj7");
        assert_eq!(implied_name("Obj", 10), "Obj10");
        assert_eq!(implied_name("Obj", 99), "Obj99");
        assert_eq!(implied_name("Obj", 100), "Obj100");
        assert_eq!(implied_name("", 255), "255");
        // Past the 24 bytes of an inline name.
        let long = "Expected software identification";
        assert_eq!(implied_name(long, 17), format!("{long}17"));
        for n in 0..=255u8 {
            assert_eq!(decimal(n), n.to_string());
        }
    }

    /// What one step of [`implied_behaves_as_if_made_at_once`] does.
    #[derive(Clone, Debug)]
    enum Op {
        Insert(u8),
        Rename(u8),
        Entry(u8),
        Remove(u8),
        Imply(u8),
        Read(u8),
        Extend(Vec<u8>),
        RenameAll,
    }

    fn op() -> impl proptest::strategy::Strategy<Value = Op> {
        use proptest::prelude::*;
        // Small sub-indexes, so that operations meet the implied ones.
        let k = 0u8..12;
        prop_oneof![
            k.clone().prop_map(Op::Insert),
            k.clone().prop_map(Op::Rename),
            k.clone().prop_map(Op::Entry),
            k.clone().prop_map(Op::Remove),
            (0u8..10).prop_map(Op::Imply),
            k.clone().prop_map(Op::Read),
            proptest::collection::vec(k, 0..4).prop_map(Op::Extend),
            Just(Op::RenameAll),
        ]
    }

    proptest::proptest! {
        /// Sub-objects implied by `set_implied` behave, through every method, as the map does
        /// when they are all inserted at once.
        #[test]
        fn implied_behaves_as_if_made_at_once(ops in proptest::collection::vec(op(), 0..24)) {
            let template = sub(0, "template");
            let mut m = SubObjects::new();
            let mut b: BTreeMap<u8, SubObject> = BTreeMap::new();
            for op in ops {
                match op {
                    Op::Insert(k) => {
                        assert_eq!(m.insert(k, sub(k, "new")), b.insert(k, sub(k, "new")));
                    }
                    Op::Rename(k) => {
                        if let Some(s) = m.get_mut(&k) { s.name.push('!') }
                        if let Some(s) = b.get_mut(&k) { s.name.push('!') }
                    }
                    Op::Entry(k) => {
                        m.entry(k).or_insert(sub(k, "e")).name.push('?');
                        b.entry(k).or_insert(sub(k, "e")).name.push('?');
                    }
                    Op::Remove(k) => assert_eq!(m.remove(&k), b.remove(&k)),
                    Op::Imply(n) => {
                        m.set_implied(template.clone(), n, "Stem");
                        for i in 1..=n {
                            let mut s = template.clone();
                            s.sub_index = i;
                            s.name = implied_name("Stem", i);
                            b.insert(i, s);
                        }
                    }
                    Op::Read(k) => {
                        assert_eq!(m.get(&k), b.get(&k));
                        assert!(m.range(k..).eq(b.range(k..)));
                    }
                    Op::Extend(ks) => {
                        m.extend(ks.iter().map(|&k| (k, sub(k, "x"))));
                        b.extend(ks.iter().map(|&k| (k, sub(k, "x"))));
                    }
                    Op::RenameAll => {
                        m.values_mut().for_each(|s| s.name.push('*'));
                        b.values_mut().for_each(|s| s.name.push('*'));
                    }
                }
                // The cheap answers first: they must not need the sub-objects made.
                assert_eq!(m.len(), b.len());
                assert_eq!(m.is_empty(), b.is_empty());
                for k in 0..12 {
                    assert_eq!(m.contains_key(&k), b.contains_key(&k));
                }
                let eager: SubObjects = b.clone().into_iter().collect();
                assert!(m == eager && m.clone() == eager);
                assert!(m.iter().eq(b.iter()));
                assert_eq!(m.first_key_value(), b.first_key_value());
                assert_eq!(m.last_key_value(), b.last_key_value());
            }
            assert!(m.into_iter().eq(b));
        }
    }

    /// The parse-time questions are answered without making the implied sub-objects.
    #[test]
    fn implied_are_made_only_when_read() {
        let mut m = SubObjects::new();
        m.insert(0, sub(0, "count"));
        m.set_implied(sub(0, "t"), 200, "Long enough to be allocated ");
        assert_eq!(m.len(), 201);
        assert!(m.contains_key(&200) && !m.contains_key(&201));
        assert_eq!(m.get(&0).map(|s| s.name.as_str()), Some("count"));
        if let Some(s) = m.get_mut(&7) {
            s.name.push('!');
        }
        assert!(m.any_ignoring_names(|s| s.name == "t"));
        let made = |m: &SubObjects| m.implied.as_ref().is_some_and(|i| i.all.get().is_some());
        assert!(!made(&m) && m.items.len() == 2);
        assert_eq!(m[&7].name, "Long enough to be allocated 7!");
        assert!(!made(&m));
        assert_eq!(m[&8].name, "Long enough to be allocated 8");
        assert!(made(&m));
        // Once all are made, a change goes to them: nothing is made a second time.
        if let Some(s) = m.get_mut(&9) {
            s.name.push('?');
        }
        assert!(m.implied.is_none() && m.items.len() == 201);
        assert_eq!(
            (m[&7].name.as_str(), m[&9].name.as_str()),
            ("Long enough to be allocated 7!", "Long enough to be allocated 9?")
        );
    }
}
