extern crate std;
use std::{format, vec, vec::Vec};

use super::*;
use crate::cia402::Controlword;
use crate::{Access, DataType, DefaultValue, VisibleString};

fn find(keys: &[u32], index: u16, sub: u8) -> Result<usize, SdoAbort> {
    search(keys, |&k| k, index, sub)
}

#[test]
fn find_by_key() {
    let keys = [key(0x1000, 0), key(0x1018, 0), key(0x1018, 2), key(0x6040, 0)];
    assert!(keys.windows(2).all(|w| w[0] < w[1]));
    assert_eq!(find(&keys, 0x1000, 0), Ok(0));
    assert_eq!(find(&keys, 0x1018, 2), Ok(2));
    assert_eq!(find(&keys, 0x6040, 0), Ok(3));
    assert_eq!(find(&keys, 0x1018, 1), Err(SdoAbort::NoSuchSub));
    assert_eq!(find(&keys, 0x1018, 9), Err(SdoAbort::NoSuchSub));
    assert_eq!(find(&keys, 0x1000, 1), Err(SdoAbort::NoSuchSub));
    assert_eq!(find(&keys, 0x0FFF, 0xFF), Err(SdoAbort::NoSuchObject));
    assert_eq!(find(&keys, 0x2000, 0), Err(SdoAbort::NoSuchObject));
    assert_eq!(find(&keys, 0x7000, 0), Err(SdoAbort::NoSuchObject));
    assert_eq!(find(&[], 0x7000, 0), Err(SdoAbort::NoSuchObject));
}

/// A dictionary as generated code lays it out.
mod od {
    use crate::cia402::Controlword;
    use crate::{Access, DefaultValue, Entry, VisibleString};

    pub const DEVICE_TYPE: Entry<u32> = Entry::new(0x1000, 0, "Device type", Access::Ro, false)
        .with_default(DefaultValue::Value(0x0002_0192));
    pub const COB_ID_EMCY: Entry<u32> = Entry::new(0x1014, 0, "COB-ID EMCY", Access::Rw, false)
        .with_default(DefaultValue::NodeIdPlus(0x80));
    pub const NAME: Entry<VisibleString<8>> =
        Entry::new(0x1008, 0, "Device name", Access::Const, false).with_default(
            DefaultValue::Value(match VisibleString::new("odc") {
                Some(s) => s,
                None => VisibleString::EMPTY,
            }),
        );
    pub const PASSWORD: Entry<u16> = Entry::new(0x2000, 1, "Password", Access::Wo, false);
    pub const PASSWORD_U8: Entry<u8> = Entry::new(0x2000, 1, "Password", Access::Wo, false);
    pub const SPEED: Entry<u16> =
        Entry::new(0x2000, 2, "Speed", Access::Rw, false).with_limits(Some(1), Some(9));
    pub const BAD_LIMITS: Entry<u16> =
        Entry::new(0x2000, 3, "Bad", Access::Rw, false).with_limits(Some(9), Some(1));
    pub const CONTROLWORD: Entry<Controlword> =
        Entry::new(0x6040, 0, "Controlword", Access::Rww, true);
    pub const LABEL: Entry<VisibleString<4>> = Entry::new(0x2001, 0, "Label", Access::Rw, false);
    pub const OFFSET: Entry<i8> =
        Entry::new(0x6041, 0, "Offset", Access::Rw, false).with_limits(None, Some(-4));
}

const LAYOUT: Table<9> = Table::new([
    row!(od::DEVICE_TYPE),
    row!(od::NAME),
    row!(od::COB_ID_EMCY),
    row!(od::PASSWORD),
    row!(od::SPEED),
    row!(od::BAD_LIMITS),
    row!(od::LABEL),
    row!(od::CONTROLWORD),
    row!(od::OFFSET),
]);
static TABLE: Table<9> = LAYOUT;

fn dictionary(node_id: u8) -> [u8; LAYOUT.size()] {
    let mut values = [0; LAYOUT.size()];
    TABLE.init(&mut values, crate::cob::NodeId::new(node_id));
    values
}

#[test]
fn layout_and_initial_values() {
    assert_eq!(LAYOUT.size(), 4 + 8 + 4 + 2 + 2 + 2 + 4 + 2 + 1);
    assert_eq!(TABLE.len(), 9);
    let addrs: Vec<_> = TABLE.rows().iter().map(|r| (r.addr().index, r.addr().sub)).collect();
    assert_eq!(addrs[..3], [(0x1000, 0), (0x1008, 0), (0x1014, 0)]);
    assert_eq!(TABLE.rows()[7].data_type(), DataType::Unsigned16);
    assert_eq!(TABLE.rows()[3].access(), Access::Wo);
    let values = dictionary(5);
    assert_eq!(TABLE.get(&values, &od::DEVICE_TYPE), Ok(0x0002_0192));
    assert_eq!(TABLE.get(&values, &od::COB_ID_EMCY), Ok(0x85));
    assert_eq!(TABLE.get(&values, &od::NAME).map(|s| s.len()), Ok(3));
    // Without default, zero moved into the limits.
    assert_eq!(TABLE.get(&values, &od::SPEED), Ok(1));
    assert_eq!(TABLE.get(&values, &od::OFFSET), Ok(-4));
    assert_eq!(TABLE.get(&values, &od::CONTROLWORD), Ok(Controlword::from(0)));
    assert_ne!(values, dictionary(6));
}

#[test]
fn reads() {
    let values = dictionary(5);
    let mut buf = [0u8; 8];
    assert_eq!(TABLE.read(&values, 0x1000, 0, &mut buf), Ok(4));
    assert_eq!(buf[..4], [0x92, 0x01, 0x02, 0x00]);
    assert_eq!(TABLE.read(&values, 0x1008, 0, &mut buf), Ok(3));
    assert_eq!(&buf[..3], b"odc");
    assert_eq!(TABLE.read(&values, 0x1000, 0, &mut buf[..3]), Err(SdoAbort::TooShort));
    assert_eq!(TABLE.read(&values, 0x2000, 1, &mut buf), Err(SdoAbort::ReadOfWriteOnly));
    assert_eq!(TABLE.read(&values, 0x2000, 4, &mut buf), Err(SdoAbort::NoSuchSub));
    assert_eq!(TABLE.read(&values, 0x1000, 1, &mut buf), Err(SdoAbort::NoSuchSub));
    assert_eq!(TABLE.read(&values, 0x3000, 0, &mut buf), Err(SdoAbort::NoSuchObject));
}

#[test]
fn writes() {
    let mut values = dictionary(5);
    let mut w = |index, sub, data: &[u8]| TABLE.write(&mut values, index, sub, data, &mut ());
    assert_eq!(w(0x1000, 0, &[0; 4]), Err(SdoAbort::WriteOfReadOnly));
    assert_eq!(w(0x1008, 0, b"x"), Err(SdoAbort::WriteOfReadOnly));
    assert_eq!(w(0x3000, 0, &[0]), Err(SdoAbort::NoSuchObject));
    assert_eq!(w(0x2000, 9, &[0]), Err(SdoAbort::NoSuchSub));
    assert_eq!(w(0x2000, 2, &[7, 0]), Ok(()));
    assert_eq!(w(0x2000, 2, &[0, 0]), Err(SdoAbort::ValueTooLow));
    assert_eq!(w(0x2000, 2, &[10, 0]), Err(SdoAbort::ValueTooHigh));
    assert_eq!(w(0x2000, 2, &[5]), Err(SdoAbort::TooShort));
    assert_eq!(w(0x2000, 2, &[5, 0, 0]), Err(SdoAbort::TooLong));
    assert_eq!(w(0x2000, 3, &[5, 0]), Err(SdoAbort::MaxLessThanMin));
    assert_eq!(w(0x2000, 1, &[0x34, 0x12]), Ok(()));
    assert_eq!(w(0x6040, 0, &[0x0F, 0]), Ok(()));
    assert_eq!(TABLE.get(&values, &od::SPEED), Ok(7));
    assert_eq!(TABLE.get(&values, &od::PASSWORD), Ok(0x1234));
    assert_eq!(TABLE.get(&values, &od::CONTROLWORD), Ok(Controlword::from(0x0F)));
}

#[test]
fn strings_keep_their_length() {
    let mut values = dictionary(5);
    let mut buf = [0u8; 8];
    // Padding zeros are no part of the value, even past the capacity.
    assert_eq!(TABLE.write(&mut values, 0x2001, 0, b"ab\0\0\0\0", &mut ()), Ok(()));
    assert_eq!(TABLE.read(&values, 0x2001, 0, &mut buf), Ok(2));
    assert_eq!(TABLE.write(&mut values, 0x2001, 0, b"abcd", &mut ()), Ok(()));
    assert_eq!(TABLE.read(&values, 0x2001, 0, &mut buf), Ok(4));
    assert_eq!(TABLE.write(&mut values, 0x2001, 0, b"x", &mut ()), Ok(()));
    assert_eq!(TABLE.read(&values, 0x2001, 0, &mut buf), Ok(1));
    assert_eq!(&buf[..1], b"x");
    assert_eq!(TABLE.write(&mut values, 0x2001, 0, b"abcde", &mut ()), Err(SdoAbort::TooLong));
    assert_eq!(TABLE.write(&mut values, 0x2001, 0, b"a\nb", &mut ()), Err(SdoAbort::InvalidValue));
    assert_eq!(TABLE.get(&values, &od::LABEL).map(|s| s.len()), Ok(1));
}

#[test]
fn hook_sees_checked_writes_and_may_veto() {
    #[derive(Default)]
    struct Hook {
        before: Vec<(ObjectAddr, Vec<u8>)>,
        after: Vec<ObjectAddr>,
        veto: bool,
    }
    impl WriteHook for Hook {
        fn before_write(&mut self, addr: ObjectAddr, data: &[u8]) -> Result<(), SdoAbort> {
            self.before.push((addr, data.to_vec()));
            if self.veto { Err(SdoAbort::DeviceState) } else { Ok(()) }
        }
        fn after_write(&mut self, addr: ObjectAddr) {
            self.after.push(addr);
        }
    }
    let mut values = dictionary(5);
    let mut hook = Hook::default();
    assert_eq!(TABLE.write(&mut values, 0x2000, 2, &[0, 0], &mut hook), Err(SdoAbort::ValueTooLow));
    assert!(hook.before.is_empty());
    assert_eq!(TABLE.write(&mut values, 0x2000, 2, &[3, 0], &mut hook), Ok(()));
    assert_eq!(hook.before, [(ObjectAddr::new(0x2000, 2), vec![3, 0])]);
    assert_eq!(hook.after, [ObjectAddr::new(0x2000, 2)]);
    hook.veto = true;
    assert_eq!(TABLE.write(&mut values, 0x2000, 2, &[4, 0], &mut hook), Err(SdoAbort::DeviceState));
    assert_eq!(hook.after.len(), 1);
    assert_eq!(TABLE.get(&values, &od::SPEED), Ok(3));
}

#[test]
fn typed_access() {
    let mut values = dictionary(5);
    // The firmware sets what SDO may not write.
    assert_eq!(TABLE.set(&mut values, &od::DEVICE_TYPE, 7), Ok(()));
    assert_eq!(TABLE.get(&values, &od::DEVICE_TYPE), Ok(7));
    let name = VisibleString::<8>::new("ab").unwrap();
    assert_eq!(TABLE.set(&mut values, &od::NAME, name), Ok(()));
    let mut buf = [0u8; 8];
    assert_eq!(TABLE.read(&values, 0x1008, 0, &mut buf), Ok(2));
    // A descriptor of another dictionary.
    let other: crate::Entry<u32> = crate::Entry::new(0x6040, 0, "", Access::Rw, false);
    assert_eq!(TABLE.get(&values, &other), Err(SdoAbort::LengthMismatch));
    let missing: crate::Entry<u32> = crate::Entry::new(0x1001, 0, "", Access::Rw, false);
    assert_eq!(TABLE.set(&mut values, &missing, 1), Err(SdoAbort::NoSuchObject));
}

#[test]
fn debug_shows_addresses_and_typed_values() {
    struct D([u8; LAYOUT.size()]);
    impl core::fmt::Debug for D {
        fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
            TABLE.fmt_values(&self.0, f)
        }
    }
    let text = format!("{:?}", D(dictionary(5)));
    assert!(text.starts_with("{0x1000:00: 131474, 0x1008:00: \"odc\", 0x1014:00: 133,"), "{text}");
    assert!(
        text.ends_with("0x2000:02: 1, 0x2000:03: 9, 0x2001:00: \"\", 0x6040:00: 0, 0x6041:00: -4}"),
        "{text}"
    );
}

#[test]
fn initial_values() {
    let e: Entry<u32> =
        Entry::new(0x1014, 0, "", Access::Rw, false).with_default(DefaultValue::NodeIdPlus(0x80));
    assert_eq!(initial(&e, NodeId::new(5), 0), 0x85);
    let e: Entry<u8> =
        Entry::new(1, 0, "", Access::Rw, false).with_default(DefaultValue::NodeIdPlus(0xF0));
    assert_eq!(initial(&e, NodeId::new(0x20), 7), 7);
    // Without default, zero moves into the limits.
    let e: Entry<u32> = Entry::new(1, 0, "", Access::Rw, false).with_limits(Some(1), Some(3));
    assert_eq!(initial(&e, NodeId::new(5), 0), 1);
    let e: Entry<i8> = Entry::new(1, 0, "", Access::Rw, false).with_limits(None, Some(-4));
    assert_eq!(initial(&e, NodeId::new(5), 0), -4);
    let e: Entry<u8> = Entry::new(1, 0, "", Access::Rw, false).with_limits(Some(0), Some(9));
    assert_eq!(initial(&e, NodeId::new(5), 0), 0);
}

#[test]
fn rows_keep_every_access_right() {
    for access in [Access::Ro, Access::Wo, Access::Rw, Access::Rwr, Access::Rww, Access::Const] {
        const SPEC: crate::slave::SpecRef = crate::slave::SpecRef::new(&od::PASSWORD_U8.spec());
        let entry: Entry<u8> = Entry::new(0xFFFF, 0xFF, "", access, false);
        let row = Row::new(&entry, &SPEC);
        assert_eq!((row.access(), row.addr()), (access, ObjectAddr::new(0xFFFF, 0xFF)));
        assert_eq!(row.data_type(), DataType::Unsigned8);
    }
}

/// A row keeps offsets past 16 bits (bits 16–19 live beside the access right and the mapping flag): a value stored
/// behind a 70,000-byte string reads back, and the access rights stay apart from the offset.
#[test]
fn rows_reach_past_64_kib() {
    const BIG: Entry<crate::OctetString<70_000>> = Entry::new(0x2000, 0, "", Access::Ro, false);
    const SMALL: Entry<u32> = Entry::new(0x2001, 0, "", Access::Rw, true);
    const TABLE: Table<2> = Table::new([crate::slave::row!(BIG), crate::slave::row!(SMALL)]);
    assert_eq!(TABLE.size(), 70_004);
    let mut values = vec![0u8; TABLE.size()];
    TABLE.write(&mut values, 0x2001, 0, &0x1234_5678u32.to_le_bytes(), &mut ()).unwrap();
    assert_eq!(values[70_000..], 0x1234_5678u32.to_le_bytes());
    let mut buf = [0u8; 4];
    assert_eq!(TABLE.read(&values, 0x2001, 0, &mut buf), Ok(4));
    assert_eq!(u32::from_le_bytes(buf), 0x1234_5678);
    assert_eq!(TABLE.access(0x2000, 0), Some(Access::Ro));
    assert_eq!(TABLE.access(0x2001, 0), Some(Access::Rw));
    assert_eq!(TABLE.write(&mut values, 0x2000, 0, &[0], &mut ()), Err(SdoAbort::WriteOfReadOnly));
    // The offset's high bits leave the mapping flag alone: BIG is not mappable, SMALL is.
    assert_eq!(TABLE.pdo_mappable(0x2000, 0, true), Err(SdoAbort::NotMappable));
    assert_eq!(TABLE.pdo_mappable(0x2001, 0, true), Ok(32));
}

/// CiA 301 §7.5.2.36/38: a mapping entry names an object the file lets map in that
/// direction (`PDOMapping=1`; CiA 306 access: `rww` into RPDOs, `ro` into TPDOs), with its
/// size; the node refuses the others with 0x06040041 or 0x06020000.
#[test]
fn pdo_mappable_follows_the_flag_and_the_direction() {
    // 0x6040 controlword: rww, PDOMapping=1, 16 bits.
    assert_eq!(TABLE.pdo_mappable(0x6040, 0, false), Ok(16));
    assert_eq!(TABLE.pdo_mappable(0x6040, 0, true), Err(SdoAbort::NotMappable));
    // 0x2000:2 is rw but its file says PDOMapping=0.
    assert_eq!(TABLE.pdo_mappable(0x2000, 2, false), Err(SdoAbort::NotMappable));
    assert_eq!(TABLE.pdo_mappable(0x2000, 9, true), Err(SdoAbort::NoSuchSub));
    assert_eq!(TABLE.pdo_mappable(0x3000, 0, true), Err(SdoAbort::NoSuchObject));
    // The flag bit does not change the access.
    assert_eq!(TABLE.access(0x6040, 0), Some(Access::Rww));
}

/// Rows of an imaged dictionary (`row_limits!`, `row_unlimited!`): the same checks on a
/// download as [`row!`]'s, and no initial value written by [`Table::init`] (the generated
/// `INITIAL` image holds it).
#[test]
fn limits_and_unlimited_rows() {
    const IMAGED: Table<3> =
        Table::new([row_unlimited!(od::NAME), row_limits!(od::SPEED), row_unlimited!(od::LABEL)]);
    let mut values = [0u8; IMAGED.size()];
    IMAGED.init(&mut values, None);
    // NAME's default "odc" is not written: the image, not the rows, holds it.
    assert_eq!(values, [0u8; 8 + 2 + 4]);
    let hook = &mut ();
    // The limits of SPEED (1..=9) are checked, its length too.
    assert_eq!(IMAGED.write(&mut values, 0x2000, 2, &[10, 0], hook), Err(SdoAbort::ValueTooHigh));
    assert_eq!(IMAGED.write(&mut values, 0x2000, 2, &[0, 0], hook), Err(SdoAbort::ValueTooLow));
    assert_eq!(IMAGED.write(&mut values, 0x2000, 2, &[5], hook), Err(SdoAbort::TooShort));
    assert_eq!(IMAGED.write(&mut values, 0x2000, 2, &[5, 0], hook), Ok(()));
    // LABEL (VisibleString<4>, no limits): decoding alone decides.
    assert_eq!(IMAGED.write(&mut values, 0x2001, 0, b"abcde", hook), Err(SdoAbort::TooLong));
    assert_eq!(IMAGED.write(&mut values, 0x2001, 0, b"a\tb", hook), Err(SdoAbort::InvalidValue));
    assert_eq!(IMAGED.write(&mut values, 0x2001, 0, b"ab", hook), Ok(()));
    let mut buf = [0u8; 8];
    assert_eq!(IMAGED.read(&values, 0x2001, 0, &mut buf), Ok(2));
    assert_eq!(&buf[..2], b"ab");
    assert_eq!(IMAGED.read(&values, 0x2000, 2, &mut buf), Ok(2));
    assert_eq!(&buf[..2], &[5, 0]);
    // Types and lengths as `row!` gives them.
    let types: Vec<_> = IMAGED.rows().iter().map(Row::data_type).collect();
    assert_eq!(types, [DataType::VisibleString, DataType::Unsigned16, DataType::VisibleString]);
}

/// `$NODEID` defaults written over an image: the sum where it fits the type (as
/// `DefaultValue::resolve` decides), the image's value where it does not or without node-ID.
#[test]
fn node_id_defaults_over_an_image() {
    const DEFAULTS: [NodeIdDefault; 4] = [
        // UNSIGNED32 at 0: 0x180 + id.
        NodeIdDefault::new(0, 4, false, 0x180),
        // UNSIGNED8 at 4: 0xF0 + id fits for id <= 15 only.
        NodeIdDefault::new(4, 1, false, 0xF0),
        // INTEGER8 at 5: 0x70 + id fits for id <= 15 only (0x7F is the largest).
        NodeIdDefault::new(5, 1, true, 0x70),
        // UNSIGNED24 at 6: 0xFF_FFF0 + id, fits for id <= 15.
        NodeIdDefault::new(6, 3, false, 0xFF_FFF0),
    ];
    let image = [0xAA; 9];
    let mut values = image;
    NodeIdDefault::apply(&DEFAULTS, &mut values, None);
    assert_eq!(values, image);
    NodeIdDefault::apply(&DEFAULTS, &mut values, crate::cob::NodeId::new(5));
    assert_eq!(values, [0x85, 0x01, 0, 0, 0xF5, 0x75, 0xF5, 0xFF, 0xFF]);
    let mut values = image;
    NodeIdDefault::apply(&DEFAULTS, &mut values, crate::cob::NodeId::new(16));
    // 0x190; 0x100, 0x80 and 0x100_0000 do not fit: the image's bytes stay.
    assert_eq!(values, [0x90, 0x01, 0, 0, 0xAA, 0xAA, 0xAA, 0xAA, 0xAA]);
}
