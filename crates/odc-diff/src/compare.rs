//! The comparison: each part of the model, side by side.

use std::collections::{BTreeMap, BTreeSet};

use odc_model::ethercat::EtherCat;
use odc_model::{Device, Direction, Object, Pdo, Spanned, SubObject, Value};

use crate::{Change, Options, Place, What};

/// The differences between `a` and `b`, ordered by place (identity, file, capabilities, objects
/// by index with their sub-objects, PDOs, images, comments).
pub fn diff(a: &Device, b: &Device, opts: &Options) -> Vec<Change> {
    let mut d = Diff { out: Vec::new(), opts: *opts };
    d.identity(a, b);
    if !opts.ignore_comments {
        d.file(a, b);
    }
    d.capabilities(a, b);
    d.objects(a, b);
    d.pdos(a, b);
    d.images(a, b);
    if !opts.ignore_comments {
        d.field(Place::Comments, "comments", a.comments.join("\n"), b.comments.join("\n"));
    }
    // Stable: within a place, the fields keep the order they are compared in.
    d.out.sort_by_key(|c| order(&c.place));
    for c in &mut d.out {
        if let Place::Object { index } | Place::Sub { index, .. } = c.place {
            c.odc = match (odc_made(a, index), odc_made(b, index)) {
                (true, true) => Some("a, b"),
                (true, false) => Some("a"),
                (false, true) => Some("b"),
                (false, false) => None,
            };
        }
    }
    d.out
}

/// Whether object `index` of `dev` is odc's rather than the file's: synthesised by the ESI
/// front-end, or the file's with defaults odc filled in (`EtherCat::esi_defaults`).
fn odc_made(dev: &Device, index: u16) -> bool {
    dev.objects.get(&index).is_some_and(|o| o.origin.is_esi_synthesised())
        || dev.esi_default(index).is_some()
}

/// Where a place comes in the output: an object's own changes, then its sub-objects'.
fn order(p: &Place) -> (u8, u32, u16) {
    match *p {
        Place::Identity => (0, 0, 0),
        Place::File => (1, 0, 0),
        Place::Capabilities => (2, 0, 0),
        Place::Object { index } => (3, u32::from(index), 0),
        Place::Sub { index, sub } => (3, u32::from(index), u16::from(sub) + 1),
        Place::Pdo { mapping_index } => (4, u32::from(mapping_index), 0),
        Place::Image { direction } => (5, u32::from(direction != "outputs"), 0),
        Place::Comments => (6, 0, 0),
    }
}

struct Diff {
    out: Vec<Change>,
    opts: Options,
}

fn opt<T: ToString>(v: Option<&Spanned<T>>) -> String {
    v.map_or(String::new(), |v| v.value.to_string())
}

fn hex32(v: Option<&Spanned<u32>>) -> String {
    v.map_or(String::new(), |v| format!("0x{:08X}", v.value))
}

fn value(v: Option<&Spanned<Value>>) -> String {
    plain(v.map(|v| &v.value))
}

/// A value in CiA 306 form, so that `0x0A` and `10` compare equal.
fn plain(v: Option<&Value>) -> String {
    v.map_or(String::new(), odc_analysis::value_text)
}

impl Diff {
    fn push(&mut self, place: Place, what: What) {
        self.out.push(Change { place, what, odc: None });
    }

    /// A change of `field` when the two texts differ.
    fn field(&mut self, place: Place, field: &str, a: String, b: String) {
        if a != b {
            self.push(place, What::Changed { field: field.to_owned(), a, b });
        }
    }

    fn identity(&mut self, a: &Device, b: &Device) {
        let (x, y) = (&a.device_info, &b.device_info);
        let p = || Place::Identity;
        self.field(
            p(),
            "vendor ID",
            hex32(x.vendor_number.as_ref()),
            hex32(y.vendor_number.as_ref()),
        );
        self.field(
            p(),
            "product code",
            hex32(x.product_number.as_ref()),
            hex32(y.product_number.as_ref()),
        );
        self.field(
            p(),
            "revision",
            hex32(x.revision_number.as_ref()),
            hex32(y.revision_number.as_ref()),
        );
        self.field(p(), "order code", opt(x.order_code.as_ref()), opt(y.order_code.as_ref()));
        if !self.opts.ignore_names {
            self.field(
                p(),
                "vendor name",
                opt(x.vendor_name.as_ref()),
                opt(y.vendor_name.as_ref()),
            );
            self.field(
                p(),
                "product name",
                opt(x.product_name.as_ref()),
                opt(y.product_name.as_ref()),
            );
        }
        let format =
            |d: &Device| d.format.map_or(String::new(), |f| format!("{f:?}").to_uppercase());
        self.field(p(), "format", format(a), format(b));
    }

    fn file(&mut self, a: &Device, b: &Device) {
        let (x, y) = (&a.file_info, &b.file_info);
        let p = || Place::File;
        self.field(p(), "file name", opt(x.file_name.as_ref()), opt(y.file_name.as_ref()));
        self.field(p(), "file version", opt(x.file_version.as_ref()), opt(y.file_version.as_ref()));
        self.field(
            p(),
            "file revision",
            opt(x.file_revision.as_ref()),
            opt(y.file_revision.as_ref()),
        );
        self.field(p(), "EDS version", opt(x.eds_version.as_ref()), opt(y.eds_version.as_ref()));
        self.field(p(), "description", opt(x.description.as_ref()), opt(y.description.as_ref()));
        self.field(p(), "created by", opt(x.created_by.as_ref()), opt(y.created_by.as_ref()));
        self.field(
            p(),
            "creation date",
            opt(x.creation_date.as_ref()),
            opt(y.creation_date.as_ref()),
        );
        self.field(
            p(),
            "creation time",
            opt(x.creation_time.as_ref()),
            opt(y.creation_time.as_ref()),
        );
        self.field(p(), "modified by", opt(x.modified_by.as_ref()), opt(y.modified_by.as_ref()));
        self.field(
            p(),
            "modification date",
            opt(x.modification_date.as_ref()),
            opt(y.modification_date.as_ref()),
        );
        self.field(
            p(),
            "modification time",
            opt(x.modification_time.as_ref()),
            opt(y.modification_time.as_ref()),
        );
    }

    fn capabilities(&mut self, a: &Device, b: &Device) {
        let (x, y) = (&a.device_info, &b.device_info);
        let p = || Place::Capabilities;
        let rates = |v: &[u32]| v.iter().map(u32::to_string).collect::<Vec<_>>().join(", ");
        self.field(p(), "bit rates", rates(&x.baud_rates), rates(&y.baud_rates));
        self.field(
            p(),
            "simple boot-up master",
            opt(x.simple_boot_up_master.as_ref()),
            opt(y.simple_boot_up_master.as_ref()),
        );
        self.field(
            p(),
            "simple boot-up slave",
            opt(x.simple_boot_up_slave.as_ref()),
            opt(y.simple_boot_up_slave.as_ref()),
        );
        self.field(p(), "granularity", opt(x.granularity.as_ref()), opt(y.granularity.as_ref()));
        self.field(
            p(),
            "dynamic channels",
            opt(x.dynamic_channels_supported.as_ref()),
            opt(y.dynamic_channels_supported.as_ref()),
        );
        self.field(
            p(),
            "group messaging",
            opt(x.group_messaging.as_ref()),
            opt(y.group_messaging.as_ref()),
        );
        self.field(p(), "receive PDOs", opt(x.nr_of_rx_pdo.as_ref()), opt(y.nr_of_rx_pdo.as_ref()));
        self.field(
            p(),
            "transmit PDOs",
            opt(x.nr_of_tx_pdo.as_ref()),
            opt(y.nr_of_tx_pdo.as_ref()),
        );
        self.field(p(), "LSS", opt(x.lss_supported.as_ref()), opt(y.lss_supported.as_ref()));
        self.field(p(), "CompactPDO", opt(x.compact_pdo.as_ref()), opt(y.compact_pdo.as_ref()));
        let (ex, ey) = (a.ethercat.as_deref(), b.ethercat.as_deref());
        let sms = |e: Option<&EtherCat>| -> BTreeMap<u8, String> {
            e.map(|e| e.sync_managers.iter().map(|s| (s.number, s.summary())).collect())
                .unwrap_or_default()
        };
        let (sx, sy) = (sms(ex), sms(ey));
        for n in sx.keys().chain(sy.keys()).collect::<BTreeSet<_>>() {
            let name = format!("SM{n}");
            self.field(
                p(),
                &name,
                sx.get(n).cloned().unwrap_or_default(),
                sy.get(n).cloned().unwrap_or_default(),
            );
        }
        let fmmus = |e: Option<&EtherCat>| {
            e.map(|e| {
                e.fmmus.iter().map(|f| f.usage.as_str().to_owned()).collect::<Vec<_>>().join(", ")
            })
            .unwrap_or_default()
        };
        self.field(p(), "FMMUs", fmmus(ex), fmmus(ey));
        let mailbox = |e: Option<&EtherCat>| {
            e.and_then(|e| e.mailbox.as_ref()).map(|m| m.protocols().join(", ")).unwrap_or_default()
        };
        self.field(p(), "mailbox", mailbox(ex), mailbox(ey));
        let dc = |e: Option<&EtherCat>| {
            e.and_then(|e| e.dc.as_ref())
                .map(|dc| {
                    dc.op_modes.iter().map(|m| m.name.as_str()).collect::<Vec<_>>().join(", ")
                })
                .unwrap_or_default()
        };
        self.field(p(), "DC modes", dc(ex), dc(ey));
    }

    fn objects(&mut self, a: &Device, b: &Device) {
        let indexes: BTreeSet<u16> = a.objects.keys().chain(b.objects.keys()).copied().collect();
        for index in indexes {
            let place = Place::Object { index };
            match (a.objects.get(&index), b.objects.get(&index)) {
                (Some(x), None) => self.push(place, What::Removed { text: describe(x) }),
                (None, Some(y)) => self.push(place, What::Added { text: describe(y) }),
                (Some(x), Some(y)) => self.object(x, y),
                (None, None) => {}
            }
        }
    }

    fn object(&mut self, x: &Object, y: &Object) {
        let index = x.index;
        let place = || Place::Object { index };
        if !self.opts.ignore_names {
            self.field(place(), "name", x.name.clone(), y.name.clone());
        }
        self.field(place(), "object code", x.kind.name().to_owned(), y.kind.name().to_owned());
        if !self.opts.ignore_comments {
            self.field(
                place(),
                "denotation",
                opt(x.denotation.as_ref()),
                opt(y.denotation.as_ref()),
            );
        }
        self.field(
            place(),
            "object flags",
            flags(x.obj_flags.as_ref()),
            flags(y.obj_flags.as_ref()),
        );
        let var = !x.kind.has_subs() && !y.kind.has_subs();
        let subs: BTreeSet<u8> = x.subs.keys().chain(y.subs.keys()).copied().collect();
        for sub in subs {
            let place = if var { Place::Object { index } } else { Place::Sub { index, sub } };
            match (x.sub(sub), y.sub(sub)) {
                (Some(s), None) => self.push(place, What::Removed { text: describe_sub(s) }),
                (None, Some(s)) => self.push(place, What::Added { text: describe_sub(s) }),
                (Some(s), Some(t)) => self.sub(place, s, t, var),
                (None, None) => {}
            }
        }
    }

    fn sub(&mut self, place: Place, x: &SubObject, y: &SubObject, var: bool) {
        let p = || place.clone();
        if !var && !self.opts.ignore_names {
            self.field(p(), "name", x.name.to_string(), y.name.to_string());
        }
        self.field(
            p(),
            "data type",
            x.data_type.name().into_owned(),
            y.data_type.name().into_owned(),
        );
        self.field(p(), "access", x.access.as_str().to_owned(), y.access.as_str().to_owned());
        self.field(p(), "PDO mapping", directions(x).to_owned(), directions(y).to_owned());
        if !self.opts.ignore_defaults {
            self.field(p(), "default", value(x.default.as_ref()), value(y.default.as_ref()));
            self.field(
                p(),
                "value",
                value(x.parameter_value.as_ref()),
                value(y.parameter_value.as_ref()),
            );
        }
        self.field(p(), "low limit", value(x.low_limit.as_deref()), value(y.low_limit.as_deref()));
        self.field(
            p(),
            "high limit",
            value(x.high_limit.as_deref()),
            value(y.high_limit.as_deref()),
        );
        if !self.opts.ignore_comments {
            self.field(
                p(),
                "denotation",
                opt(x.rare().denotation.as_ref()),
                opt(y.rare().denotation.as_ref()),
            );
        }
        self.field(
            p(),
            "object flags",
            flags(x.rare().obj_flags.as_ref()),
            flags(y.rare().obj_flags.as_ref()),
        );
    }

    fn pdos(&mut self, a: &Device, b: &Device) {
        let (px, py) = (pdos_by_index(a), pdos_by_index(b));
        for index in px.keys().chain(py.keys()).collect::<BTreeSet<_>>() {
            let place = Place::Pdo { mapping_index: *index };
            match (px.get(index), py.get(index)) {
                (Some(x), None) => self.push(place, What::Removed { text: describe_pdo(x) }),
                (None, Some(y)) => self.push(place, What::Added { text: describe_pdo(y) }),
                (Some(x), Some(y)) => {
                    let p = || place.clone();
                    if !self.opts.ignore_names {
                        self.field(p(), "name", x.name.clone(), y.name.clone());
                    }
                    self.field(p(), "entries", entries(x), entries(y));
                    self.field(p(), "COB-ID", plain(x.cob_id.as_ref()), plain(y.cob_id.as_ref()));
                    let o = |v: Option<u16>| v.map_or(String::new(), |v| v.to_string());
                    self.field(
                        p(),
                        "transmission type",
                        o(x.transmission_type.map(u16::from)),
                        o(y.transmission_type.map(u16::from)),
                    );
                    self.field(p(), "inhibit time", o(x.inhibit_time), o(y.inhibit_time));
                    self.field(p(), "event timer", o(x.event_timer), o(y.event_timer));
                    self.field(
                        p(),
                        "sync manager",
                        o(x.sync_manager.map(u16::from)),
                        o(y.sync_manager.map(u16::from)),
                    );
                    self.field(p(), "fixed", x.fixed.to_string(), y.fixed.to_string());
                }
                (None, None) => {}
            }
        }
    }

    fn images(&mut self, a: &Device, b: &Device) {
        if a.ethercat.is_none() && b.ethercat.is_none() {
            return;
        }
        let images = |d: &Device| {
            d.ethercat
                .as_ref()
                .and_then(|_| odc_analysis::image::default_images(d).ok())
                .map(|(o, i)| [image_text(d, &o), image_text(d, &i)])
                .unwrap_or_default()
        };
        let (ix, iy) = (images(a), images(b));
        for (k, direction) in ["outputs", "inputs"].into_iter().enumerate() {
            let (x, y) =
                (ix.get(k).cloned().unwrap_or_default(), iy.get(k).cloned().unwrap_or_default());
            self.field(Place::Image { direction }, "layout", x, y);
        }
    }
}

/// Which PDOs a sub-object may be mapped into, by meaning: an EDS's `PDOMapping=1` on a
/// read-only entry and an XDD's `PDOmapping="TPDO"` are both "TPDO".
fn directions(s: &SubObject) -> &'static str {
    match (s.pdo_mapping, s.pdo_mapping.directions(s.access)) {
        (odc_model::PdoMapping::No, _) => "no",
        (_, "") => "none allowed",
        (_, d) => d,
    }
}

fn pdos_by_index(d: &Device) -> BTreeMap<u16, &Pdo> {
    d.pdos.iter().map(|p| (p.mapping_index, p)).collect()
}

fn flags(v: Option<&Spanned<u32>>) -> String {
    v.map_or(String::new(), |v| format!("0x{:X}", v.value))
}

fn describe(o: &Object) -> String {
    let kind = o.kind.name();
    match o.var() {
        Some(s) => format!("{kind} \"{}\" {} {}", o.name, s.data_type.name(), s.access.as_str()),
        None => format!("{kind} \"{}\", {} sub-objects", o.name, o.subs.len()),
    }
}

fn describe_sub(s: &SubObject) -> String {
    format!("\"{}\" {} {}", s.name, s.data_type.name(), s.access.as_str())
}

fn entries(p: &Pdo) -> String {
    p.entries
        .iter()
        .map(|e| format!("0x{:04X}:{:02X}/{}", e.index, e.sub, e.bits))
        .collect::<Vec<_>>()
        .join(" ")
}

fn describe_pdo(p: &Pdo) -> String {
    let dir = match p.direction {
        Direction::Rx => "RPDO",
        Direction::Tx => "TPDO",
    };
    let bits: u32 = p.entries.iter().map(|e| u32::from(e.bits)).sum();
    format!("{dir} \"{}\": {} ({bits} bits)", p.name, entries(p))
}

fn image_text(d: &Device, image: &odc_analysis::image::Image) -> String {
    let mut parts = Vec::new();
    for seg in &image.segments {
        let pdos: Vec<String> = seg
            .pdos
            .iter()
            .filter_map(|&i| d.pdos.get(i).map(|p| format!("0x{:04X}", p.mapping_index)))
            .collect();
        parts.push(format!("SM{}: {} bytes [{}]", seg.sm, seg.bytes, pdos.join(" ")));
    }
    parts.join("; ")
}
