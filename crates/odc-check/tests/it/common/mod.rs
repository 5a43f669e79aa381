//! Builders for test devices: `dev().var(0x6040, "Controlword", Unsigned16, Rww).mappable()`.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]
#![allow(dead_code, missing_docs)]

use odc_check::{Config, check};
use odc_model::ethercat::{
    CoE, Dc, DcOpMode, EsiDataType, EsiSubItem, EtherCat, Mailbox, SmUsage, SyncManager,
};
use odc_model::{
    Access, DataType, Device, Direction, Format, Object, ObjectKind, ObjectList, ObjectLists, Pdo,
    PdoEntry, PdoMapping, Sources, Spanned, SubObject, Value, diag,
};

pub use odc_model::Access::*;
pub use odc_model::DataType::*;

pub struct Dev {
    pub device: Device,
    last: Option<(u16, u8)>,
}

/// An empty CANopen (EDS) device.
pub fn dev() -> Dev {
    let device = Device { format: Some(Format::Eds), ..Device::default() };
    Dev { device, last: None }
}

/// A CANopen device with the mandatory objects and heartbeat, that passes every rule.
pub fn base() -> Dev {
    dev()
        .var(0x1000, "Device type", Unsigned32, Ro)
        .default(u(0x0001_0191))
        .var(0x1001, "Error register", Unsigned8, Ro)
        .mappable()
        .var(0x1017, "Producer heartbeat time", Unsigned16, Rw)
        .default(u(0))
        .record(
            0x1018,
            "Identity",
            &[
                (1, "Vendor-ID", Unsigned32, Ro, Some(u(0x1234))),
                (2, "Product code", Unsigned32, Ro, Some(u(0x42))),
                (3, "Revision number", Unsigned32, Ro, Some(u(0x0001_0000))),
            ],
        )
}

pub fn u(v: u64) -> Value {
    Value::Unsigned(v)
}
pub fn i(v: i64) -> Value {
    Value::Signed(v)
}
pub fn node(v: i64) -> Value {
    Value::NodeIdPlus(v)
}

type SubSpec = (u8, &'static str, DataType, Access, Option<Value>);

impl Dev {
    fn object(&mut self, index: u16, name: &str, kind: ObjectKind) {
        self.device.objects.insert(index, Object::new(index, name, kind, odc_model::Span::DUMMY));
    }

    /// A VAR object.
    pub fn var(mut self, index: u16, name: &str, dt: DataType, access: Access) -> Dev {
        self.object(index, name, ObjectKind::Var);
        self.sub_of(index, 0, name, dt, access)
    }

    /// A RECORD with sub 0 (UNSIGNED8, default = highest sub) and the given subs; SubNumber set.
    pub fn record(self, index: u16, name: &str, subs: &[SubSpec]) -> Dev {
        self.structured(index, name, ObjectKind::Record, subs)
    }

    /// An ARRAY, like [`Dev::record`].
    pub fn array(self, index: u16, name: &str, subs: &[SubSpec]) -> Dev {
        self.structured(index, name, ObjectKind::Array, subs)
    }

    fn structured(mut self, index: u16, name: &str, kind: ObjectKind, subs: &[SubSpec]) -> Dev {
        self.object(index, name, kind);
        let highest = subs.iter().map(|s| s.0).max().unwrap_or(0);
        self = self
            .sub_of(index, 0, "Highest sub-index supported", Unsigned8, Ro)
            .default(u(u64::from(highest)));
        for (sub, name, dt, access, default) in subs.iter().cloned() {
            self = self.sub_of(index, sub, name, dt, access);
            if let Some(d) = default {
                self = self.default(d);
            }
        }
        if let Some(o) = self.device.objects.get_mut(&index) {
            o.sub_number = Some(Spanned::synthetic(o.subs.len() as u16));
        }
        self
    }

    /// Adds a sub-object to object `index` (which must exist).
    pub fn sub_of(mut self, index: u16, sub: u8, name: &str, dt: DataType, access: Access) -> Dev {
        if let Some(o) = self.device.objects.get_mut(&index) {
            o.subs.insert(sub, SubObject::new(sub, name, dt, access));
        }
        self.last = Some((index, sub));
        self
    }

    /// Adds a sub-object to the last object.
    pub fn sub(self, sub: u8, name: &str, dt: DataType, access: Access) -> Dev {
        let index = self.last.map_or(0, |l| l.0);
        self.sub_of(index, sub, name, dt, access)
    }

    fn last_sub(&mut self) -> &mut SubObject {
        let (i, s) = self.last.unwrap_or_default();
        self.device.objects.get_mut(&i).and_then(|o| o.subs.get_mut(&s)).unwrap()
    }

    pub fn last_object(&mut self) -> &mut Object {
        let (i, _) = self.last.unwrap_or_default();
        self.device.objects.get_mut(&i).unwrap()
    }

    /// Selects a sub-object for the value setters.
    pub fn at(mut self, index: u16, sub: u8) -> Dev {
        self.last = Some((index, sub));
        self
    }

    pub fn mappable(mut self) -> Dev {
        self.last_sub().pdo_mapping = PdoMapping::Yes;
        self
    }
    pub fn mapping(mut self, m: PdoMapping) -> Dev {
        self.last_sub().pdo_mapping = m;
        self
    }
    pub fn default(mut self, v: Value) -> Dev {
        self.last_sub().default = Some(Spanned::synthetic(v));
        self
    }
    pub fn low(mut self, v: Value) -> Dev {
        self.last_sub().low_limit = Some(Box::new(Spanned::synthetic(v)));
        self
    }
    pub fn high(mut self, v: Value) -> Dev {
        self.last_sub().high_limit = Some(Box::new(Spanned::synthetic(v)));
        self
    }
    pub fn param(mut self, v: Value) -> Dev {
        self.last_sub().parameter_value = Some(Spanned::synthetic(v));
        self
    }
    pub fn data_type(mut self, dt: DataType) -> Dev {
        self.last_sub().data_type = dt;
        self
    }
    pub fn sub_number(mut self, n: u16) -> Dev {
        self.last_object().sub_number = Some(Spanned::synthetic(n));
        self
    }
    pub fn no_sub_number(mut self) -> Dev {
        self.last_object().sub_number = None;
        self
    }
    pub fn compact(mut self, n: u8) -> Dev {
        self.last_object().compact_sub_obj = Some(Spanned::synthetic(n));
        self
    }
    pub fn remove(mut self, index: u16) -> Dev {
        self.device.objects.remove(&index);
        self
    }
    pub fn remove_sub(mut self, index: u16, sub: u8) -> Dev {
        if let Some(o) = self.device.objects.get_mut(&index) {
            o.subs.remove(&sub);
        }
        self
    }
    pub fn with(mut self, f: impl FnOnce(&mut Device)) -> Dev {
        f(&mut self.device);
        self
    }

    /// A default PDO: communication object (COB-ID, transmission type) and mapping object with
    /// the given entries (`0xIIIISSLL`). `n` counts from 1; `tx` chooses TPDO.
    pub fn pdo(self, tx: bool, n: u16, cob_id: Value, entries: &[u32]) -> Dev {
        let (comm, map) = if tx { (0x1800, 0x1A00) } else { (0x1400, 0x1600) };
        let comm = comm + n - 1;
        let map = map + n - 1;
        let dev = self.record(
            comm,
            if tx { "TPDO communication" } else { "RPDO communication" },
            &[
                (1, "COB-ID", Unsigned32, Rw, Some(cob_id)),
                (2, "Transmission type", Unsigned8, Rw, Some(u(0xFE))),
            ],
        );
        let subs: Vec<SubSpec> = (1..=8u8)
            .map(|k| {
                let v = entries.get(usize::from(k) - 1).map_or(0, |&e| u64::from(e));
                (k, "Mapped object", Unsigned32, Rw, Some(u(v)))
            })
            .collect();
        let mut dev = dev.record(map, if tx { "TPDO mapping" } else { "RPDO mapping" }, &subs);
        dev = dev.at(map, 0).default(u(entries.len() as u64));
        dev
    }

    /// Fills the three object lists from the objects, correctly.
    pub fn lists(mut self) -> Dev {
        let mut m = ObjectList::default();
        let mut o = ObjectList::default();
        let mut f = ObjectList::default();
        for &i in self.device.objects.keys() {
            let list = match i {
                0x1000 | 0x1001 | 0x1018 => &mut m,
                0x2000..=0x5FFF => &mut f,
                _ => &mut o,
            };
            list.entries.push(Spanned::synthetic(i));
        }
        for l in [&mut m, &mut o, &mut f] {
            l.supported_objects = Some(Spanned::synthetic(l.entries.len() as u16));
        }
        self.device.object_lists =
            ObjectLists { mandatory: Some(m), optional: Some(o), manufacturer: Some(f) };
        self
    }

    pub fn esi(mut self) -> Dev {
        self.device.format = Some(Format::Esi);
        self
    }

    /// Edits the EtherCAT part (created empty if absent).
    pub fn ethercat(mut self, f: impl FnOnce(&mut EtherCat)) -> Dev {
        f(self.device.ethercat.get_or_insert_with(Default::default));
        self
    }

    /// Adds an ESI PDO.
    pub fn esi_pdo(mut self, pdo: Pdo) -> Dev {
        self.device.pdos.push(pdo);
        self
    }

    /// Edits the ESI PDO with this index.
    pub fn edit_pdo(mut self, index: u16, f: impl FnOnce(&mut Pdo)) -> Dev {
        if let Some(p) = self.device.pdos.iter_mut().find(|p| p.mapping_index == index) {
            f(p);
        }
        self
    }

    /// Edits sync manager `n`.
    pub fn edit_sm(self, n: usize, f: impl FnOnce(&mut SyncManager)) -> Dev {
        self.ethercat(|e| {
            if let Some(sm) = e.sync_managers.get_mut(n) {
                f(sm);
            }
        })
    }

    pub fn build(self) -> Device {
        self.device
    }
}

/// An ESI sync manager.
pub fn sm(number: u8, usage: SmUsage, start: u16, control: u8, size: Option<u32>) -> SyncManager {
    SyncManager {
        number,
        usage,
        min_size: None,
        max_size: None,
        default_size: size,
        start_address: Some(Spanned::synthetic(start)),
        control_byte: Some(Spanned::synthetic(control)),
        enable: true,
        virtual_sm: false,
        op_only: false,
        span: odc_model::Span::DUMMY,
    }
}

/// An ESI PDO with entries `(index, sub, bits)`, assigned to sync manager `sm`.
pub fn esi_pdo(dir: Direction, index: u16, sm: Option<u8>, entries: &[(u16, u8, u16)]) -> Pdo {
    Pdo {
        direction: dir,
        mapping_index: index,
        comm_index: None,
        name: format!("PDO {index:04X}"),
        cob_id: None,
        transmission_type: None,
        inhibit_time: None,
        event_timer: None,
        sync_start: None,
        entries: entries
            .iter()
            .map(|&(index, sub, bits)| PdoEntry {
                index,
                sub,
                bits,
                name: None,
                data_type: None,
                span: odc_model::Span::DUMMY,
            })
            .collect(),
        sync_manager: sm,
        fixed: false,
        mandatory: false,
        excludes: Vec::new(),
        span: odc_model::Span::DUMMY,
    }
}

/// A DC operation mode.
pub fn op_mode(name: &str, assign_activate: u32) -> DcOpMode {
    DcOpMode { name: name.into(), assign_activate: Some(assign_activate), ..DcOpMode::default() }
}

/// An EtherCAT I/O device with a dictionary, mailbox (CoE), four sync managers, one RxPDO
/// (0x1600 on SM 2) and one TxPDO (0x1A00 on SM 3) plus two optional PDOs that exclude each
/// other, the assignment objects 0x1C12/0x1C13, 0x1C00 and two DC modes; it passes every rule.
pub fn esi_io() -> Dev {
    base()
        .esi()
        .var(0x6000, "Input", Unsigned16, Ro)
        .mapping(PdoMapping::Tx)
        .var(0x7000, "Output", Unsigned16, Rw)
        .mapping(PdoMapping::Rx)
        .var(0x7001, "Output 2", Unsigned32, Rw)
        .mapping(PdoMapping::Rx)
        .array(
            0x1C00,
            "Sync manager type",
            &[
                (1, "SM 0", Unsigned8, Ro, Some(u(1))),
                (2, "SM 1", Unsigned8, Ro, Some(u(2))),
                (3, "SM 2", Unsigned8, Ro, Some(u(3))),
                (4, "SM 3", Unsigned8, Ro, Some(u(4))),
            ],
        )
        .array(0x1C12, "RxPDO assign", &[(1, "SubIndex 001", Unsigned16, Rw, Some(u(0x1600)))])
        .array(0x1C13, "TxPDO assign", &[(1, "SubIndex 001", Unsigned16, Rw, Some(u(0x1A00)))])
        .esi_pdo(esi_pdo(Direction::Rx, 0x1600, Some(2), &[(0x7000, 0, 16)]))
        .esi_pdo(esi_pdo(Direction::Tx, 0x1A00, Some(3), &[(0x6000, 0, 16)]))
        .esi_pdo(Pdo {
            excludes: vec![0x1602],
            ..esi_pdo(Direction::Rx, 0x1601, None, &[(0x7001, 0, 32)])
        })
        .esi_pdo(Pdo {
            excludes: vec![0x1601],
            ..esi_pdo(Direction::Rx, 0x1602, None, &[(0x7000, 0, 16), (0x7001, 0, 32)])
        })
        .ethercat(|e| {
            e.sync_managers = vec![
                sm(0, SmUsage::MBoxOut, 0x1000, 0x26, Some(128)),
                sm(1, SmUsage::MBoxIn, 0x1080, 0x22, Some(128)),
                SyncManager {
                    min_size: Some(1),
                    max_size: Some(8),
                    ..sm(2, SmUsage::Outputs, 0x1100, 0x64, None)
                },
                sm(3, SmUsage::Inputs, 0x1180, 0x20, None),
            ];
            e.mailbox = Some(Mailbox { coe: Some(CoE::default()), ..Mailbox::default() });
            e.data_types = vec![EsiDataType {
                name: "DT1018".into(),
                bit_size: Some(144),
                sub_items: [(0, "SubIndex 000", 8), (1, "Vendor ID", 32), (2, "Product code", 32)]
                    .iter()
                    .zip([0, 16, 48])
                    .map(|(&(idx, name, bits), off)| EsiSubItem {
                        sub_idx: Some(idx),
                        name: name.into(),
                        type_name: if bits == 8 { "USINT" } else { "UDINT" }.into(),
                        bit_size: Some(bits),
                        bit_offset: Some(off),
                        ..EsiSubItem::default()
                    })
                    .collect(),
                ..EsiDataType::default()
            }];
            e.dc = Some(Dc {
                op_modes: vec![op_mode("FreeRun", 0), op_mode("DcSync", 0x300)],
                span: odc_model::Span::DUMMY,
            });
        })
}

/// Every rule on, the ones that are off by default at warning level.
pub fn all_rules_on() -> Config {
    let mut c = Config::in_registry(odc_check::rules());
    c.set_level("all", odc_check::Level::Warn).unwrap();
    c
}

/// Checks with the default configuration and renders the short form.
pub fn run(dev: Dev) -> String {
    run_with(dev, &Config::in_registry(odc_check::rules()))
}

pub fn run_with(dev: Dev, config: &Config) -> String {
    let device = dev.build();
    let diags = check(&device, config);
    diag::render_short(&Sources::new(), &diags)
}
