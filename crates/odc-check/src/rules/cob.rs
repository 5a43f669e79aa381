//! C401–C410: COB-IDs and the communication objects (CiA 301 §7.3, §7.5.2).

use odc_model::{Device, Label, Object, Spanned, SubObject, Value};

use super::rule;
use crate::Ctx;
use crate::util::{NODE_IDS, first_span, idx, initial_u64, is_canopen, nodes_text, pdos, show};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// Receive PDO n (from 1).
    Rpdo(u16),
    /// Transmit PDO n (from 1).
    Tpdo(u16),
    Emcy,
    Sync,
    Time,
    /// SDO server n (from 1), client → server (sub 1).
    SdoRx(u16),
    /// SDO server n, server → client (sub 2).
    SdoTx(u16),
}

impl Kind {
    fn name(self) -> String {
        match self {
            Kind::Rpdo(n) => format!("RPDO{n}"),
            Kind::Tpdo(n) => format!("TPDO{n}"),
            Kind::Emcy => "EMCY".into(),
            Kind::Sync => "SYNC".into(),
            Kind::Time => "TIME".into(),
            Kind::SdoRx(n) => format!("SDO server {n} (client→server)"),
            Kind::SdoTx(n) => format!("SDO server {n} (server→client)"),
        }
    }

    /// Whether bit 31 marks the COB-ID invalid (the service unused).
    fn has_valid_bit(self) -> bool {
        !matches!(self, Kind::Sync | Kind::Time)
    }
}

/// A COB-ID the device's dictionary holds.
struct Cob<'a> {
    kind: Kind,
    object: &'a Object,
    sub: &'a SubObject,
    value: &'a Spanned<Value>,
}

impl Cob<'_> {
    fn span(&self) -> odc_model::Span {
        first_span([self.value.span, self.sub.span, self.object.span])
    }

    fn sub_index(&self) -> Option<u8> {
        self.object.kind.has_subs().then_some(self.sub.sub_index)
    }

    fn at(&self) -> String {
        if self.object.kind.has_subs() {
            format!("0x{:04X}:{:02X}", self.object.index, self.sub.sub_index)
        } else {
            idx(self.object.index)
        }
    }

    /// The COB-ID for each node-ID it depends on: `[(0, v)]` for a fixed value.
    fn resolved(&self) -> impl Iterator<Item = (u8, u32)> {
        // A fixed value is the value at node-ID 0; one that is no number resolves to nothing.
        let (nodes, base) = match self.value.value {
            Value::NodeIdPlus(k) => (NODE_IDS, Some(i128::from(k))),
            ref v => (0..=0, v.as_i128(0)),
        };
        nodes.filter_map(move |n| {
            let v = u32::try_from(base? + i128::from(n)).ok()?;
            Some((n, v))
        })
    }

    /// Whether the service is in use (bit 31 clear), for every node-ID.
    fn is_valid(&self) -> bool {
        !self.kind.has_valid_bit() || self.resolved().all(|(_, v)| v & 0x8000_0000 == 0)
    }
}

fn cobs(dev: &Device) -> Vec<Cob<'_>> {
    let mut out = Vec::new();
    let mut push = |kind, index: u16, sub: u8| {
        if let Some(o) = dev.objects.get(&index)
            && let Some(s) = o.sub(sub)
            && let Some(v) = s.initial_value()
        {
            out.push(Cob { kind, object: o, sub: s, value: v });
        }
    };
    for &i in dev.objects.keys() {
        match i {
            0x1005 => push(Kind::Sync, i, 0),
            0x1012 => push(Kind::Time, i, 0),
            0x1014 => push(Kind::Emcy, i, 0),
            0x1200..=0x127F => {
                push(Kind::SdoRx(i - 0x1200 + 1), i, 1);
                push(Kind::SdoTx(i - 0x1200 + 1), i, 2);
            }
            0x1400..=0x15FF => push(Kind::Rpdo(i - 0x1400 + 1), i, 1),
            0x1800..=0x19FF => push(Kind::Tpdo(i - 0x1800 + 1), i, 1),
            _ => {}
        }
    }
    out
}

/// CiA 301 Table 67: CAN-IDs no PDO, SYNC, TIME or EMCY may use.
fn restricted(can_id: u32) -> bool {
    matches!(
        can_id,
        0x000..=0x07F
            | 0x101..=0x180
            | 0x581..=0x5FF
            | 0x601..=0x67F
            | 0x6E0..=0x6FF
            | 0x701..=0x7FF
    )
}

rule!(
    C401,
    "C401",
    "restricted-cob-id",
    "cia301",
    Error,
    Deny,
    restricted_cob_id,
    "a PDO, SYNC, TIME or EMCY COB-ID uses a CAN-ID that CiA 301 restricts",
    "CiA 301 §7.3.5 (Table 67) reserves CAN-IDs for NMT (0x000), LSS and the default SDO, \
     NMT error control and other services: 0x001–0x07F, 0x101–0x180, 0x581–0x5FF, \
     0x601–0x67F, 0x6E0–0x6FF, 0x701–0x77F and 0x780–0x7FF. A PDO, SYNC, TIME or EMCY object \
     configured with one of them collides with those services; CANopenNode refuses such \
     configurations (CO_IS_RESTRICTED_CAN_ID). `$NODEID`-relative COB-IDs are checked for every \
     node-ID 1..=127; invalid COB-IDs (bit 31 set) are not checked. Fix: choose a CAN-ID \
     outside the restricted ranges (the predefined connection set uses 0x180–0x57F + node-ID)."
);

fn restricted_cob_id(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    for c in cobs(dev) {
        if matches!(c.kind, Kind::SdoRx(_) | Kind::SdoTx(_)) || !c.is_valid() {
            continue;
        }
        let restricted_at = |&(_, v): &(u8, u32)| v & (1 << 29) == 0 && restricted(v & 0x7FF);
        let Some((node, example)) = c.resolved().find(restricted_at) else { continue };
        let bad: Vec<u8> = c.resolved().filter(restricted_at).map(|(n, _)| n).collect();
        let what = if c.value.value.is_node_relative() {
            format!(
                "resolves to a restricted CAN-ID for {} (0x{:03X} at node-ID {node})",
                nodes_text(&bad),
                example & 0x7FF
            )
        } else {
            format!("is the restricted CAN-ID 0x{:03X}", example & 0x7FF)
        };
        ctx.report(
            c.object.index,
            c.sub_index(),
            c.span(),
            format!("{} COB-ID {} {what}", c.kind.name(), c.at()),
        );
    }
}

rule!(
    C402,
    "C402",
    "cob-id-reserved-bits",
    "cia301",
    Error,
    Deny,
    cob_id_reserved_bits,
    "a COB-ID sets bits that must be zero",
    "A COB-ID is a CAN-ID plus flags: bit 31 valid/invalid (or SYNC/TIME consumer), bit 30 RTR, \
     SYNC/TIME producer or SDO dynamic, bit 29 frame format (0: 11-bit, 1: 29-bit). With an \
     11-bit CAN-ID (bit 29 clear) bits 11–28 must be zero; in the EMCY COB-ID 0x1014 bit 30 is \
     reserved (CiA 301 §7.5.2.31). Devices reject such values (CANopenNode CO_Emergency.c, \
     CO_SYNC.c). A value like 0x4000_0181 written as 0x40181 is the usual cause. Fix: clear the \
     bits, or set bit 29 if a 29-bit identifier was meant."
);

fn cob_id_reserved_bits(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    for c in cobs(dev) {
        let bad = c.resolved().find_map(|(_, v)| {
            if v & (1 << 29) == 0 && (v >> 11) & 0x3_FFFF != 0 {
                Some(format!("0x{v:08X} has bits 11–28 set with an 11-bit CAN-ID"))
            } else if c.kind == Kind::Emcy && v & (1 << 30) != 0 {
                Some(format!("0x{v:08X} sets the reserved bit 30"))
            } else {
                None
            }
        });
        if let Some(why) = bad {
            ctx.report(
                c.object.index,
                c.sub_index(),
                c.span(),
                format!("{} COB-ID {}: {why}", c.kind.name(), c.at()),
            );
        }
    }
}

rule!(
    C403,
    "C403",
    "cob-id-not-predefined",
    "cia301",
    Note,
    Warn,
    cob_id_not_predefined,
    "a default PDO or EMCY COB-ID differs from the predefined connection set",
    "CiA 301 §7.3.4 defines default COB-IDs: EMCY $NODEID+0x80, TPDO1–4 $NODEID+0x180/0x280/\
     0x380/0x480, RPDO1–4 $NODEID+0x200/0x300/0x400/0x500; PDOs from the fifth on have no \
     default and are invalid (bit 31 set) until configured. A file may deviate on purpose (a \
     fixed COB-ID, a PDO 5 enabled by default); this note makes the deviation visible, since \
     masters that assume the predefined set will not see the PDO. Allow it per object when \
     intended."
);

fn cob_id_not_predefined(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    for c in cobs(dev) {
        let expected: Option<i64> = match c.kind {
            Kind::Emcy => Some(0x80),
            Kind::Tpdo(n) if n <= 4 => Some(0x180 + 0x100 * i64::from(n - 1)),
            Kind::Rpdo(n) if n <= 4 => Some(0x200 + 0x100 * i64::from(n - 1)),
            Kind::Tpdo(_) | Kind::Rpdo(_) => None,
            _ => continue,
        };
        if !c.is_valid() {
            continue;
        }
        let message = match (expected, &c.value.value) {
            (Some(e), Value::NodeIdPlus(k)) if k & 0x7FF == e => continue,
            (Some(e), v) => format!(
                "{} COB-ID {} is {}, not the predefined $NODEID+0x{e:X}",
                c.kind.name(),
                c.at(),
                show_cob(v)
            ),
            (None, v) => format!(
                "{} COB-ID {} is valid by default ({}); PDOs past the fourth have no predefined \
                 COB-ID",
                c.kind.name(),
                c.at(),
                show_cob(v)
            ),
        };
        ctx.report(c.object.index, c.sub_index(), c.span(), message);
    }
}

rule!(
    C404,
    "C404",
    "duplicate-cob-id",
    "cia301",
    Error,
    Deny,
    duplicate_cob_id,
    "two of the device's own PDOs, EMCY or SDO channels use the same COB-ID",
    "Each CAN-ID has one producer on the bus, and one device must not use one CAN-ID for two \
     services: two TPDOs with one COB-ID collide on the bus; an RPDO sharing a TPDO's COB-ID \
     receives the device's own frames; an SDO channel sharing a PDO's loses frames to it. Only \
     valid COB-IDs (bit 31 clear) of the same form (both `$NODEID`-relative or both fixed) are \
     compared. Fix: give each service its own CAN-ID."
);

fn duplicate_cob_id(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    let mut seen: Vec<(bool, i64, String, odc_model::Span)> = Vec::new();
    for c in cobs(dev) {
        if matches!(c.kind, Kind::Sync | Kind::Time) || !c.is_valid() {
            continue;
        }
        let (relative, v) = match c.value.value {
            Value::NodeIdPlus(k) => (true, k),
            ref v => match v.as_i128(0).and_then(|i| i64::try_from(i).ok()) {
                Some(v) => (false, v),
                None => continue,
            },
        };
        // Compare the identifier and its format (bits 0–29), not the flags.
        let key = v & 0x3FFF_FFFF;
        let what = format!("{} ({})", c.kind.name(), c.at());
        if let Some((_, _, first, first_span_)) =
            seen.iter().find(|(r, k, _, _)| *r == relative && *k == key)
        {
            let (first, first_span_) = (first.clone(), *first_span_);
            ctx.report(
                c.object.index,
                c.sub_index(),
                c.span(),
                format!("{what} uses COB-ID {}, as {first} does", show_cob(&c.value.value)),
            )
            .labels
            .push(Label {
                span: first_span_,
                message: format!("{first} here"),
                primary: false,
            });
        } else {
            seen.push((relative, key, what, c.span()));
        }
    }
}

rule!(
    C405,
    "C405",
    "sync-objects",
    "cia301",
    Warning,
    Warn,
    sync_objects,
    "SYNC is used but its communication objects are incomplete",
    "A device that has synchronous PDOs (transmission type 0–240) consumes SYNC and needs the \
     COB-ID SYNC object 0x1005; a SYNC producer (0x1005 bit 30 set) also needs the \
     communication cycle period 0x1006; 0x1006 without 0x1005 is meaningless (CiA 301 \
     §7.5.2.6–7). Without them a master cannot configure or check SYNC. Fix: add the missing \
     objects."
);

fn sync_objects(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    let has_1005 = dev.objects.contains_key(&0x1005);
    if !has_1005 {
        if let Some(p) = pdos(dev).iter().find(|p| p.transmission_type.is_some_and(|t| t <= 240)) {
            let comm = p.comm_index.unwrap_or(p.mapping_index);
            let span = dev.objects.get(&comm).map_or(p.span, |o| o.span);
            ctx.report(
                comm,
                Some(2),
                span,
                format!(
                    "{} is synchronous (transmission type {}) but there is no COB-ID SYNC object \
                     0x1005",
                    idx(comm),
                    p.transmission_type.unwrap_or_default()
                ),
            );
        }
        if let Some(o) = dev.objects.get(&0x1006) {
            ctx.report(0x1006, None, o.span, "0x1006 (cycle period) is defined without 0x1005");
        }
    } else if initial_u64(dev, 0x1005, 0).is_some_and(|v| v & (1 << 30) != 0)
        && !dev.objects.contains_key(&0x1006)
        && let Some(o) = dev.objects.get(&0x1005)
    {
        ctx.report(
            0x1005,
            None,
            o.span,
            "0x1005 makes the device SYNC producer but 0x1006 is missing",
        );
    }
}

rule!(
    C406,
    "C406",
    "emcy-object",
    "cia301",
    Warning,
    Warn,
    emcy_object,
    "EMCY objects are present without the COB-ID EMCY object 0x1014",
    "The pre-defined error field 0x1003 and the inhibit time EMCY 0x1015 belong to the EMCY \
     producer, whose CAN-ID is configured in 0x1014 (CiA 301 §7.5.2.31–33). A device that has \
     them but not 0x1014 leaves masters unable to know or change where its emergency messages go. \
     Fix: add 0x1014 (default $NODEID+0x80)."
);

fn emcy_object(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) || dev.objects.contains_key(&0x1014) {
        return;
    }
    for index in [0x1003, 0x1015] {
        if let Some(o) = dev.objects.get(&index) {
            ctx.report(index, None, o.span, format!("{} is defined but 0x1014 is not", idx(index)));
        }
    }
}

rule!(
    C407,
    "C407",
    "no-error-control",
    "cia301",
    Warning,
    Warn,
    no_error_control,
    "neither heartbeat (0x1017) nor node guarding (0x100C/0x100D) is supported",
    "CiA 301 §7.2.8.3 requires every device to support an error-control protocol: the \
     heartbeat producer (0x1017 producer heartbeat time) or node guarding (0x100C guard time \
     together with 0x100D life time factor). Without one, a master cannot notice that the device \
     left the bus. Node guarding needs both of its objects. Fix: add 0x1017 (preferred; node \
     guarding is not recommended for new designs)."
);

fn no_error_control(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    let has = |i| dev.objects.contains_key(&i);
    if has(0x1017) {
        return;
    }
    match (dev.objects.get(&0x100C), dev.objects.get(&0x100D)) {
        (Some(_), Some(_)) => {}
        (Some(o), None) | (None, Some(o)) => {
            let other = if o.index == 0x100C { 0x100D } else { 0x100C };
            ctx.report(
                o.index,
                None,
                o.span,
                format!("node guarding needs {} as well as {}", idx(other), idx(o.index)),
            );
        }
        (None, None) => {
            let span = dev.objects.values().next().map_or(odc_model::Span::DUMMY, |o| o.span);
            ctx.report_device(
                span,
                "the device has neither heartbeat (0x1017) nor node guarding (0x100C/0x100D)",
            );
        }
    }
}

rule!(
    C408,
    "C408",
    "sdo-server-cob-id",
    "cia301",
    Warning,
    Warn,
    sdo_server_cob_id,
    "the default SDO server's COB-IDs are not $NODEID+0x600 / $NODEID+0x580",
    "The first SDO server (0x1200) always uses CAN-ID 0x600 + node-ID for client→server and \
     0x580 + node-ID for server→client (CiA 301 §7.3.4, §7.5.2.39); its sub 1 and sub 2 are \
     read-only and say so. A file with other values there describes a device no master can \
     reach with the default SDO. Fix: DefaultValue=$NODEID+0x600 (sub 1) and \
     $NODEID+0x580 (sub 2)."
);

fn sdo_server_cob_id(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    let node = dev.commissioning.as_ref().and_then(|c| c.node_id.as_ref()).map(|n| n.value);
    for c in cobs(dev) {
        let base = match c.kind {
            Kind::SdoRx(1) => 0x600,
            Kind::SdoTx(1) => 0x580,
            _ => continue,
        };
        let ok = match c.value.value {
            Value::NodeIdPlus(k) => k == base,
            ref v => node.is_some_and(|n| v.as_i128(0) == Some(i128::from(base + i64::from(n)))),
        };
        if !ok {
            ctx.report(
                c.object.index,
                c.sub_index(),
                c.span(),
                format!(
                    "{} COB-ID {} is {}, not $NODEID+0x{base:X}",
                    c.kind.name(),
                    c.at(),
                    show_cob(&c.value.value)
                ),
            );
        }
    }
}

/// A COB-ID for messages: fixed values in hex.
fn show_cob(v: &Value) -> String {
    match v {
        Value::Unsigned(u) => format!("0x{u:X}"),
        other => show(other),
    }
}

rule!(
    C409,
    "C409",
    "heartbeat-and-guarding",
    "cia301",
    Warning,
    Warn,
    heartbeat_and_guarding,
    "both heartbeat and node guarding are configured",
    "CiA 301 §7.2.8.3 lets a device use one error-control protocol at a time: the heartbeat \
     producer (0x1017 producer heartbeat time non-zero) or node guarding (0x100C guard time × \
     0x100D life time factor non-zero), never both; a device with both configured by default \
     answers guarding requests and sends heartbeats, and masters disagree about which one \
     supervises it (dcfgen refuses the combination). Only the initial values (ParameterValue \
     over DefaultValue) count: supporting both objects is fine. Fix: set 0x1017 or 0x100C/0x100D \
     to 0 (heartbeat is preferred for new designs)."
);

fn heartbeat_and_guarding(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    let hb = initial_u64(dev, 0x1017, 0).unwrap_or(0);
    let guard = initial_u64(dev, 0x100C, 0).unwrap_or(0);
    let life = initial_u64(dev, 0x100D, 0).unwrap_or(0);
    if hb == 0 || guard == 0 || life == 0 {
        return;
    }
    let span = |i| {
        dev.objects.get(&i).map_or(odc_model::Span::DUMMY, |o| {
            let v = o.var().and_then(|s| s.initial_value().map(|v| v.span));
            first_span([v.unwrap_or(odc_model::Span::DUMMY), o.span])
        })
    };
    ctx.report(
        0x1017,
        None,
        span(0x1017),
        format!(
            "heartbeat producer time 0x1017 = {hb} ms and node guarding (0x100C = {guard} ms × \
             0x100D = {life}) are both configured"
        ),
    )
    .labels
    .push(Label { span: span(0x100C), message: "guard time here".into(), primary: false });
}

rule!(
    C410,
    "C410",
    "heartbeat-consumer-entry",
    "cia301",
    Warning,
    Warn,
    heartbeat_consumer_entry,
    "a consumer heartbeat time entry (0x1016) is malformed or duplicated",
    "Each sub-object 1..=127 of 0x1016 (consumer heartbeat time, CiA 301 §7.5.2.26) is an \
     UNSIGNED32: bits 0–15 the heartbeat time in ms, bits 16–23 the node-ID of the producer, \
     bits 24–31 reserved (0). An entry with a non-zero time must name a node-ID 1..=127 (others \
     never match a heartbeat, so the supervision is silently off), and no two entries with a \
     non-zero time may name the same node: CiA 301 makes the device refuse such a \
     configuration (SDO abort 0x0604 0043), so a DCF that holds it cannot be downloaded. Entries \
     with time 0 are unused and not checked, except for their reserved bits. Fix: correct the \
     node-ID, clear bits 24–31, or remove the duplicate."
);

fn heartbeat_consumer_entry(dev: &Device, ctx: &mut Ctx) {
    if !is_canopen(dev) {
        return;
    }
    let Some(o) = dev.objects.get(&0x1016) else { return };
    let mut seen: Vec<(u64, u8, odc_model::Span)> = Vec::new();
    for s in o.subs.values().filter(|s| s.sub_index != 0) {
        let Some(v) = s.initial_value() else { continue };
        let Value::Unsigned(raw) = v.value else { continue };
        let span = first_span([v.span, s.span, o.span]);
        let at = format!("0x1016:{:02X}", s.sub_index);
        let sub = o.kind.has_subs().then_some(s.sub_index);
        let node = (raw >> 16) & 0xFF;
        let time = raw & 0xFFFF;
        if raw >> 24 != 0 {
            ctx.report(
                0x1016,
                sub,
                span,
                format!("{at} = 0x{raw:08X} sets the reserved bits 24–31"),
            );
        } else if time != 0 && !(1..=127).contains(&node) {
            ctx.report(
                0x1016,
                sub,
                span,
                format!("{at} = 0x{raw:08X} watches node-ID {node}, which is not 1..=127"),
            );
        } else if time != 0 {
            if let Some(&(_, first, first_span_)) = seen.iter().find(|(n, _, _)| *n == node) {
                ctx.report(
                    0x1016,
                    sub,
                    span,
                    format!(
                        "{at} = 0x{raw:08X} watches node-ID {node}, as 0x1016:{first:02X} does"
                    ),
                )
                .labels
                .push(Label {
                    span: first_span_,
                    message: format!("0x1016:{first:02X} here"),
                    primary: false,
                });
            } else {
                seen.push((node, s.sub_index, span));
            }
        }
    }
}
