//! The names and object codes of a generated dictionary, for EtherCAT's SDO Information
//! (ETG.1000.6 §5.6.3): what Get OD List, Get Object Description and Get Entry Description
//! serve beyond what the [`Table`](super::Table)'s rows already hold.
//!
//! Generated code writes one `slave::DESCRIPTION` for an EtherCAT device beside its `TABLE`.
//! It is data a firmware pays for only when it names it (the stack's
//! `Config::describe`): otherwise the linker drops it. Compact, because it sits in flash:
//! the names are one string pool with a 2-byte end per name (no `&str` of 8 bytes each), the
//! data type, bit length and access of an entry are read from its row, and an entry adds 3
//! bytes (its name's end and its flags), an object 6. An entry named as its object (a VAR)
//! keeps no copy of the name.

use super::Row;

/// An object of a [`Description`]: where its rows start in the table, its highest sub-index
/// and its object code (ETG.1000.6 Table 44: 7 VAR, 8 ARRAY, 9 RECORD).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ObjectRow {
    /// The position of the object's first row in the table.
    pub row: u16,
    /// The highest sub-index of the object (as its file describes it).
    pub max_sub: u8,
    /// The object code.
    pub code: u8,
}

/// Bits of an entry's flags in a [`Description`]: the lists and access bits of ETG.1000.6
/// Table 48 that the row does not carry.
pub mod entry_flag {
    /// Mappable into an RxPDO.
    pub const RX: u8 = 1 << 0;
    /// Mappable into a TxPDO.
    pub const TX: u8 = 1 << 1;
    /// Backup parameter (`Flags/Backup`).
    pub const BACKUP: u8 = 1 << 2;
    /// Setting (`Flags/Setting`).
    pub const SETTING: u8 = 1 << 3;
    /// The entry's name is its object's (a VAR's, mostly): the pool holds it once, and the
    /// entry's own name there is empty.
    pub const OBJECT_NAME: u8 = 1 << 4;
}

/// The descriptions SDO Information serves for a dictionary of [`Row`]s: objects in index
/// order, names in one pool.
#[derive(Clone, Copy, Debug)]
pub struct Description<'a> {
    rows: &'a [Row],
    objects: &'a [ObjectRow],
    flags: &'a [u8],
    ends: &'a [u16],
    names: &'a str,
}

impl<'a> Description<'a> {
    /// The description of the dictionary of `rows` (a generated `TABLE.rows()`): `objects`
    /// one per distinct index of the rows, in order; `flags` one per row ([`entry_flag`]); `ends`
    /// the end in `names` of each object's name, then of each row's. A description whose
    /// parts do not match answers less (no panic): what it cannot find is absent.
    pub const fn new(
        rows: &'a [Row],
        objects: &'a [ObjectRow],
        flags: &'a [u8],
        ends: &'a [u16],
        names: &'a str,
    ) -> Self {
        Description { rows, objects, flags, ends, names }
    }

    /// The rows it describes (the dictionary's table's).
    pub fn rows(&self) -> &'a [Row] {
        self.rows
    }

    /// The number of objects.
    pub fn objects(&self) -> usize {
        self.objects.len()
    }

    /// Name number `i` of the pool: objects' first, then rows'.
    fn name(&self, i: usize) -> &'a str {
        let start = match i.checked_sub(1) {
            Some(p) => self.ends.get(p).copied().unwrap_or(0),
            None => 0,
        };
        let end = self.ends.get(i).copied().unwrap_or(0);
        self.names.get(usize::from(start)..usize::from(end)).unwrap_or("")
    }

    /// The name of object number `pos` (in index order).
    pub fn object_name(&self, pos: usize) -> &'a str {
        self.name(pos)
    }

    /// The name of the entry at row `row`.
    pub fn entry_name(&self, row: usize) -> &'a str {
        if self.entry_flags(row) & entry_flag::OBJECT_NAME != 0 {
            // The object whose rows begin at or before `row`: the last such.
            let pos = self.objects.partition_point(|o| usize::from(o.row) <= row);
            return self.name(pos.saturating_sub(1));
        }
        self.name(self.objects.len() + row)
    }

    /// The flags ([`entry_flag`]) of the entry at row `row`.
    pub fn entry_flags(&self, row: usize) -> u8 {
        self.flags.get(row).copied().unwrap_or(0)
    }
}

#[cfg(feature = "subdevice")]
mod serve {
    use super::{Description, ObjectRow};
    use crate::ethercat::subdevice::{Describe, EntryDescription, ObjectDescription};
    use crate::slave::search;
    use crate::slave::table::RowLike;
    use crate::{Access, DataType};

    /// ETG.1000.6 Table 48: read in PRE-OP, SAFE-OP, OP (bits 0–2), write in them (3–5),
    /// RxPDO and TxPDO mappable (6, 7), backup (8), setting (9).
    fn access_word(access: Access, flags: u8) -> u16 {
        let read = if access.readable() { 0x0007 } else { 0 };
        let write = if access.writable() { 0x0038 } else { 0 };
        read | write | u16::from(flags & 0x0F) << 6
    }

    /// The bit length of a value of type `dt` stored in `len` bytes: 1 for a BOOLEAN, else
    /// its storage's (every other type's `DataType::bits` is its storage's, a test below
    /// says so; a string's is its capacity), without `bits`' table of every type.
    pub(super) fn bits(dt: DataType, len: usize) -> u16 {
        match dt {
            DataType::Boolean => 1,
            _ => u16::try_from(len * 8).unwrap_or(u16::MAX),
        }
    }

    impl Description<'_> {
        fn index_of(&self, o: &ObjectRow) -> Option<u16> {
            Some(self.rows.get(usize::from(o.row))?.addr().index)
        }
    }

    impl Describe for Description<'_> {
        fn object_at(&self, pos: usize) -> Option<ObjectDescription<'_>> {
            let o = self.objects.get(pos)?;
            let first = usize::from(o.row);
            let index = self.index_of(o)?;
            let rows = self.rows.get(first..)?;
            let own = rows.iter().take_while(|r| r.addr().index == index);
            // The lists besides "all": bit 2 RxPDO, 3 TxPDO, 4 backup, 5 settings.
            let flags = self.flags.get(first..).unwrap_or(&[]);
            let lists = own.zip(flags).fold(0u8, |l, (_, f)| l | (f & 0x0F) << 2);
            // A VAR's type is its value's; an ARRAY's or RECORD's its first entry's (after
            // sub-index 0), else sub-index 0's.
            let mut typed = rows.first()?;
            if o.code != 7
                && typed.addr().sub == 0
                && let Some(next) = rows.get(1).filter(|r| r.addr().index == index)
            {
                typed = next;
            }
            let data_type = typed.data_type();
            Some(ObjectDescription {
                index,
                data_type: data_type as u16,
                max_sub: o.max_sub,
                code: o.code,
                name: self.object_name(pos),
                lists,
            })
        }

        fn object(&self, index: u16) -> Option<ObjectDescription<'_>> {
            let pos = self.objects.binary_search_by_key(&Some(index), |o| self.index_of(o)).ok()?;
            self.object_at(pos)
        }

        fn entry(&self, index: u16, sub: u8) -> Option<EntryDescription<'_>> {
            // The dictionary's own search, linked already.
            let pos = search(self.rows, RowLike::search_key, index, sub).ok()?;
            let row = self.rows.get(pos)?;
            let flags = self.entry_flags(pos);
            let data_type = row.data_type();
            Some(EntryDescription {
                data_type: data_type as u16,
                bits: bits(data_type, row.slot().len()),
                access: access_word(row.access(), flags),
                name: self.entry_name(pos),
            })
        }
    }
}

#[cfg(all(test, feature = "subdevice"))]
mod tests {
    use super::{Description, ObjectRow, entry_flag};
    use crate::ethercat::subdevice::{Describe, EntryDescription, ObjectDescription};
    use crate::slave::{Table, row};
    use crate::{Access, Entry, VisibleString};

    const NAME: Entry<VisibleString<6>> =
        Entry::new(0x1008, 0, "Device name", Access::Const, false);
    const COUNT: Entry<u8> = Entry::new(0x1600, 0, "Count", Access::Rw, false);
    const FIRST: Entry<u32> = Entry::new(0x1600, 1, "First", Access::Rw, false);
    const CONTROL: Entry<u16> = Entry::new(0x7000, 0, "Control", Access::Rww, true);
    static TABLE: Table<4> = Table::new([row!(NAME), row!(COUNT), row!(FIRST), row!(CONTROL)]);
    // Objects 0x1008 (VAR), 0x1600 (RECORD up to sub 2, of which the table has 0 and 1),
    // 0x7000 (VAR, RxPDO mappable, backup).
    static DESCRIPTION: Description<'static> = Description::new(
        TABLE.rows(),
        &[
            ObjectRow { row: 0, max_sub: 0, code: 7 },
            ObjectRow { row: 1, max_sub: 2, code: 9 },
            ObjectRow { row: 3, max_sub: 0, code: 7 },
        ],
        &[entry_flag::OBJECT_NAME, 0, 0, entry_flag::RX | entry_flag::BACKUP],
        &[4, 11, 18, 18, 23, 28, 33],
        "NameMappingControlCountFirstValue",
    );

    #[test]
    fn objects_from_rows_and_names_from_the_pool() {
        let d: &dyn Describe = &DESCRIPTION;
        let mapping = ObjectDescription {
            index: 0x1600,
            data_type: 0x0007,
            max_sub: 2,
            code: 9,
            name: "Mapping",
            lists: 0,
        };
        assert_eq!(d.object_at(1), Some(mapping));
        assert_eq!(d.object(0x1600), Some(mapping));
        let name = d.object(0x1008).unwrap();
        assert_eq!((name.data_type, name.code, name.name), (0x0009, 7, "Name"));
        // RxPDO list (bit 2) and backup list (bit 4).
        assert_eq!(d.object(0x7000).map(|o| (o.name, o.lists)), Some(("Control", 0b1_0100)));
        assert_eq!(d.object_at(3), None);
        assert_eq!(d.object(0x1601), None);
    }

    #[test]
    fn entries_with_type_bits_and_access_of_their_rows() {
        let d: &dyn Describe = &DESCRIPTION;
        // Read in every state (0x07), no write: const.
        let name = EntryDescription { data_type: 0x0009, bits: 48, access: 0x0007, name: "Name" };
        assert_eq!(d.entry(0x1008, 0), Some(name));
        let first = EntryDescription { data_type: 0x0007, bits: 32, access: 0x003F, name: "First" };
        assert_eq!(d.entry(0x1600, 1), Some(first));
        assert_eq!(d.entry(0x1600, 0).map(|e| (e.bits, e.name)), Some((8, "Count")));
        // rww, RxPDO mappable (bit 6), backup (bit 8).
        assert_eq!(d.entry(0x7000, 0).map(|e| (e.access, e.name)), Some((0x017F, "Value")));
        assert_eq!(d.entry(0x1600, 2), None);
        assert_eq!(d.entry(0x1601, 0), None);
    }

    #[test]
    fn bit_lengths_are_the_types() {
        use crate::{
            Domain, I24, I40, I48, I56, ObjValue, OctetString, TimeDifference, TimeOfDay, U24, U40,
            U48, U56,
        };
        fn bits_of<T: ObjValue>() -> (Option<u32>, u16) {
            (T::DATA_TYPE.bits(), super::serve::bits(T::DATA_TYPE, T::MAX_LEN))
        }
        // Every type with a bit length in CiA 301: the same from its storage.
        let fixed = [
            bits_of::<bool>(),
            bits_of::<i8>(),
            bits_of::<i16>(),
            bits_of::<i32>(),
            bits_of::<i64>(),
            bits_of::<u8>(),
            bits_of::<u16>(),
            bits_of::<u32>(),
            bits_of::<u64>(),
            bits_of::<f32>(),
            bits_of::<f64>(),
            bits_of::<I24>(),
            bits_of::<I40>(),
            bits_of::<I48>(),
            bits_of::<I56>(),
            bits_of::<U24>(),
            bits_of::<U40>(),
            bits_of::<U48>(),
            bits_of::<U56>(),
            bits_of::<TimeOfDay>(),
            bits_of::<TimeDifference>(),
        ];
        let want =
            [1, 8, 16, 32, 64, 8, 16, 32, 64, 32, 64, 24, 40, 48, 56, 24, 40, 48, 56, 48, 48];
        for ((table, stored), want) in fixed.into_iter().zip(want) {
            assert_eq!((table, stored), (Some(want), want as u16));
        }
        // Strings and domains: their capacity.
        assert_eq!(bits_of::<VisibleString<6>>(), (None, 48));
        assert_eq!(bits_of::<OctetString<3>>(), (None, 24));
        assert_eq!(bits_of::<Domain>(), (None, 0));
    }

    #[test]
    fn parts_that_do_not_match_answer_less() {
        let short = Description::new(
            TABLE.rows(),
            &[ObjectRow { row: 9, max_sub: 0, code: 7 }],
            &[],
            &[40],
            "x",
        );
        assert_eq!(short.object_at(0), None);
        assert_eq!(short.entry_name(0), "");
        assert_eq!(short.object_name(0), "");
        assert_eq!(short.entry(0x1008, 0).map(|e| (e.access, e.name)), Some((7, "")));
    }
}
