//! Devices built in Rust, for the snapshot and name tests.
// Each test binary uses some of them.
#![allow(dead_code)]

use odc_model::{
    Access, DataType, Device, Object, ObjectKind, PdoMapping, Span, Spanned, SubObject, Value,
};

fn object(index: u16, name: &str, kind: ObjectKind, subs: Vec<SubObject>) -> Object {
    let mut object = Object::new(index, name, kind, Span::DUMMY);
    object.subs = subs.into_iter().map(|s| (s.sub_index, s)).collect();
    object
}

fn sub(sub: u8, name: &str, dt: DataType, access: Access, default: Option<Value>) -> SubObject {
    let mut s = SubObject::new(sub, name, dt, access);
    s.default = default.map(Spanned::synthetic);
    s
}

fn var(index: u16, name: &str, dt: DataType, access: Access, default: Option<Value>) -> Object {
    object(index, name, ObjectKind::Var, vec![sub(0, name, dt, access, default)])
}

fn mappable(mut o: Object) -> Object {
    for s in o.subs.values_mut() {
        s.pdo_mapping = PdoMapping::Yes;
    }
    o
}

fn insert(dev: &mut Device, o: Object) {
    dev.objects.insert(o.index, o);
}

fn u(v: u64) -> Option<Value> {
    Some(Value::Unsigned(v))
}

/// A small CiA 402 drive: identity, one RPDO with a dummy gap, one TPDO, a node-relative
/// COB-ID, limits, a string.
pub fn drive() -> Device {
    use Access::*;
    use DataType::*;
    let mut dev = Device::default();
    dev.device_info.product_name = Some(Spanned::synthetic("Mini Drive".to_string()));
    insert(&mut dev, var(0x1000, "Device type", Unsigned32, Ro, u(0x0002_0192)));
    insert(
        &mut dev,
        var(
            0x1008,
            "Manufacturer device name",
            VisibleString,
            Const,
            Some(Value::Text("MD1".into())),
        ),
    );
    insert(&mut dev, var(0x1014, "COB-ID EMCY", Unsigned32, Rw, Some(Value::NodeIdPlus(0x80))));
    insert(
        &mut dev,
        object(
            0x1018,
            "Identity object",
            ObjectKind::Record,
            vec![
                sub(0, "Number of entries", Unsigned8, Ro, u(2)),
                sub(1, "Vendor ID", Unsigned32, Ro, u(0x1DD)),
                sub(2, "Product code", Unsigned32, Ro, u(0x6000)),
            ],
        ),
    );
    insert(
        &mut dev,
        object(
            0x1400,
            "Receive PDO parameter",
            ObjectKind::Record,
            vec![
                sub(0, "Largest sub-index supported", Unsigned8, Ro, u(2)),
                sub(1, "COB-ID used by PDO", Unsigned32, Rw, Some(Value::NodeIdPlus(0x200))),
                sub(2, "Transmission type", Unsigned8, Rw, u(255)),
            ],
        ),
    );
    insert(
        &mut dev,
        object(
            0x1600,
            "Receive PDO mapping",
            ObjectKind::Record,
            vec![
                sub(0, "Number of mapped objects", Unsigned8, Rw, u(3)),
                sub(1, "Mapping entry 1", Unsigned32, Rw, u(0x6040_0010)),
                sub(2, "Mapping entry 2", Unsigned32, Rw, u(0x0005_0008)),
                sub(3, "Mapping entry 3", Unsigned32, Rw, u(0x607A_0020)),
            ],
        ),
    );
    insert(
        &mut dev,
        object(
            0x1800,
            "Transmit PDO parameter",
            ObjectKind::Record,
            vec![
                sub(0, "Largest sub-index supported", Unsigned8, Ro, u(5)),
                sub(1, "COB-ID used by PDO", Unsigned32, Rw, Some(Value::NodeIdPlus(0x180))),
                sub(2, "Transmission type", Unsigned8, Rw, u(1)),
                sub(3, "Inhibit time", Unsigned16, Rw, u(100)),
                sub(5, "Event timer", Unsigned16, Rw, u(0)),
            ],
        ),
    );
    insert(
        &mut dev,
        object(
            0x1A00,
            "Transmit PDO mapping",
            ObjectKind::Record,
            vec![
                sub(0, "Number of mapped objects", Unsigned8, Rw, u(3)),
                sub(1, "Mapping entry 1", Unsigned32, Rw, u(0x6041_0010)),
                sub(2, "Mapping entry 2", Unsigned32, Rw, u(0x6061_0008)),
                sub(3, "Mapping entry 3", Unsigned32, Rw, u(0x6064_0020)),
            ],
        ),
    );
    insert(&mut dev, mappable(var(0x6040, "Controlword", Unsigned16, Rww, u(0))));
    insert(&mut dev, mappable(var(0x6041, "Statusword", Unsigned16, Ro, None)));
    insert(
        &mut dev,
        mappable(var(0x6060, "Modes of operation", Integer8, Rww, Some(Value::Signed(1)))),
    );
    insert(&mut dev, mappable(var(0x6061, "Modes of operation display", Integer8, Ro, None)));
    insert(&mut dev, mappable(var(0x6064, "Position actual value", Integer32, Ro, None)));
    let mut target =
        mappable(var(0x607A, "Target position", Integer32, Rww, Some(Value::Signed(0))));
    if let Some(s) = target.subs.get_mut(&0) {
        s.low_limit = Some(Box::new(Spanned::synthetic(Value::Signed(-100_000))));
        s.high_limit = Some(Box::new(Spanned::synthetic(Value::Signed(100_000))));
    }
    insert(&mut dev, target);
    insert(&mut dev, var(0x6502, "Supported drive modes", Unsigned32, Ro, u(0x0000_0085)));
    insert(&mut dev, var(0x2000, "type", Real32, Wo, Some(Value::Real32(1.5f32.to_bits()))));
    dev.pdos = odc_model::pdo::resolve_canopen_pdos(&dev);
    dev
}

/// A drive whose names collide the way real files' do: a vendor object with a standard
/// object's name (0x2064), a starred internal twin in the profile (0x6063, as Lexium 23A
/// writes it), and a trade name the camel-case rule would split (0x2301). Its TPDO maps the
/// vendor object before the standard one.
pub fn twins() -> Device {
    use Access::*;
    use DataType::*;
    let mut dev = Device::default();
    dev.device_info.product_name = Some(Spanned::synthetic("Twins".to_string()));
    insert(&mut dev, var(0x1000, "Device type", Unsigned32, Ro, u(0x0002_0192)));
    insert(
        &mut dev,
        object(
            0x1800,
            "Transmit PDO parameter",
            ObjectKind::Record,
            vec![
                sub(0, "Largest sub-index supported", Unsigned8, Ro, u(2)),
                sub(1, "COB-ID used by PDO", Unsigned32, Rw, Some(Value::NodeIdPlus(0x180))),
                sub(2, "Transmission type", Unsigned8, Rw, u(1)),
            ],
        ),
    );
    insert(
        &mut dev,
        object(
            0x1A00,
            "Transmit PDO mapping",
            ObjectKind::Record,
            vec![
                sub(0, "Number of mapped objects", Unsigned8, Rw, u(2)),
                sub(1, "Mapping entry 1", Unsigned32, Rw, u(0x2064_0020)),
                sub(2, "Mapping entry 2", Unsigned32, Rw, u(0x6064_0020)),
            ],
        ),
    );
    insert(&mut dev, mappable(var(0x2064, "Position actual value", Integer32, Ro, None)));
    insert(&mut dev, var(0x2301, "CANopen baud rate P3-01", Unsigned16, Rw, u(0)));
    insert(&mut dev, mappable(var(0x6040, "Controlword", Unsigned16, Rww, u(0))));
    insert(&mut dev, mappable(var(0x6041, "Statusword", Unsigned16, Ro, None)));
    insert(&mut dev, mappable(var(0x6063, "Position actual value*", Integer32, Ro, None)));
    insert(&mut dev, mappable(var(0x6064, "Position actual value", Integer32, Ro, None)));
    dev.pdos = odc_model::pdo::resolve_canopen_pdos(&dev);
    dev
}
