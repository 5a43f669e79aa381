//! The objects CiA 301 §7.5.2 requires of every CANopen device (0x1000 device type, 0x1001
//! error register, 0x1018 identity), made for a model read from an EtherCAT ESI that lacks
//! them. An ESI device without a CoE dictionary (most I/O terminals) has no objects but its
//! PDO entries; written as an EDS it would describe a CANopen device without them (C205), and
//! a master reading 0x1000 and 0x1018 at boot would refuse it. What they hold comes from the
//! ESI: the device type from `<Profile>` (`ProfileNo` in bits 0–15, `AddInfo` in 16–31, as
//! CiA 301 lays out 0x1000), the identity from `<Type>` (vendor, product code, revision).

use odc_model::{
    Access, DataType, Device, Direction, Format, Object, ObjectKind, Pdo, Span, Spanned, SubObject,
    Value,
};

/// Adds to an ESI device the mandatory objects it lacks; returns their indexes (none for a
/// device read from an EDS or DCF, whose missing objects are the file's to fix).
pub fn add_mandatory_objects(device: &mut Device) -> Vec<u16> {
    if device.format != Some(Format::Esi) {
        return Vec::new();
    }
    let mut added = Vec::new();
    let info = &device.device_info;
    let number = |v: &Option<Spanned<u32>>| v.as_ref().map_or(0, |s| s.value);
    let identity = [
        (1, "Vendor-ID", number(&info.vendor_number)),
        (2, "Product code", number(&info.product_number)),
        (3, "Revision number", number(&info.revision_number)),
    ];
    let device_type = device.ethercat.as_ref().and_then(|ec| ec.profiles.first()).map_or(0, |p| {
        (p.profile_no.unwrap_or(0) & 0xFFFF) | (p.add_info.unwrap_or(0) & 0xFFFF) << 16
    });
    let mut identity_record =
        Object::new(0x1018, "Identity object", ObjectKind::Record, Span::DUMMY);
    identity_record.subs.insert(0, sub(0, "Number of entries", DataType::Unsigned8, 3));
    for (i, name, value) in identity {
        identity_record.subs.insert(i, sub(i, name, DataType::Unsigned32, u64::from(value)));
    }
    let mandatory = [
        var(0x1000, "Device type", DataType::Unsigned32, device_type),
        var(0x1001, "Error register", DataType::Unsigned8, 0),
        identity_record,
    ];
    for object in mandatory {
        let index = object.index;
        if let std::collections::btree_map::Entry::Vacant(slot) = device.objects.entry(index) {
            slot.insert(object);
            added.push(index);
        }
    }
    added
}

fn sub(index: u8, name: &str, data_type: DataType, value: u64) -> SubObject {
    let mut s = SubObject::new(index, name, data_type, Access::Ro);
    s.default = Some(Spanned::synthetic(Value::Unsigned(value)));
    s
}

fn var(index: u16, name: &str, data_type: DataType, value: u32) -> Object {
    let mut o = Object::new(index, name, ObjectKind::Var, Span::DUMMY);
    o.subs.insert(0, sub(0, name, data_type, u64::from(value)));
    o
}

/// The PDOs whose direction an EDS cannot say: an EDS gives a PDO's direction by the index of
/// its mapping object alone (0x1600–0x17FF receive, 0x1A00–0x1BFF transmit, CiA 306 §4.5.2),
/// and an ESI may number a TxPdo 0x1600. Written as EDS, such a PDO changes direction.
pub fn pdo_directions_by_index(device: &Device) -> Vec<&Pdo> {
    device
        .pdos
        .iter()
        .filter(|p| match p.direction {
            Direction::Rx => !(0x1600..=0x17FF).contains(&p.mapping_index),
            Direction::Tx => !(0x1A00..=0x1BFF).contains(&p.mapping_index),
        })
        .collect()
}

/// The device an EDS written from `device` describes, for checking it before it is written:
/// a CANopen device (format EDS, so the CiA 301 rules that do not apply to EtherCAT do), with
/// each PDO in the direction its mapping index gives ([`pdo_directions_by_index`]).
pub fn as_canopen(device: &Device) -> Device {
    let mut canopen = device.clone();
    canopen.format = Some(Format::Eds);
    for pdo in &mut canopen.pdos {
        if (0x1600..=0x17FF).contains(&pdo.mapping_index) {
            pdo.direction = Direction::Rx;
        } else if (0x1A00..=0x1BFF).contains(&pdo.mapping_index) {
            pdo.direction = Direction::Tx;
        }
    }
    canopen
}

#[cfg(test)]
mod tests {
    use super::*;
    use odc_model::ethercat::{EtherCat, Profile};

    fn esi_terminal() -> Device {
        let mut d = Device { format: Some(Format::Esi), ..Device::default() };
        d.device_info.vendor_number = Some(Spanned::synthetic(2));
        d.device_info.product_number = Some(Spanned::synthetic(0x0BB8_3052));
        d.device_info.revision_number = Some(Spanned::synthetic(0x0011_0000));
        let profile =
            Profile { profile_no: Some(5001), add_info: Some(0x0102), ..Profile::default() };
        d.ethercat = Some(Box::new(EtherCat { profiles: vec![profile], ..EtherCat::default() }));
        d
    }

    fn default_of(d: &Device, index: u16, sub: u8) -> Option<Value> {
        d.sub(index, sub)?.default.as_ref().map(|v| v.value.clone())
    }

    #[test]
    fn an_esi_device_gets_device_type_error_register_and_identity_from_its_esi() {
        let mut d = esi_terminal();
        assert_eq!(add_mandatory_objects(&mut d), [0x1000, 0x1001, 0x1018]);
        // 0x1000: ProfileNo 5001 = 0x1389 in bits 0-15, AddInfo 0x0102 in bits 16-31.
        assert_eq!(default_of(&d, 0x1000, 0), Some(Value::Unsigned(0x0102_1389)));
        assert_eq!(default_of(&d, 0x1001, 0), Some(Value::Unsigned(0)));
        assert_eq!(default_of(&d, 0x1018, 0), Some(Value::Unsigned(3)));
        assert_eq!(default_of(&d, 0x1018, 1), Some(Value::Unsigned(2)));
        assert_eq!(default_of(&d, 0x1018, 2), Some(Value::Unsigned(0x0BB8_3052)));
        assert_eq!(default_of(&d, 0x1018, 3), Some(Value::Unsigned(0x0011_0000)));
        // Once there, nothing more is added; an object the ESI has is never replaced.
        assert!(add_mandatory_objects(&mut d).is_empty());
    }

    #[test]
    fn an_eds_device_is_left_as_its_file_says() {
        let mut d = Device { format: Some(Format::Eds), ..Device::default() };
        assert!(add_mandatory_objects(&mut d).is_empty());
        assert!(d.objects.is_empty());
    }
}
