//! Sync managers: sizes against their PDOs, control bytes, addresses and the 0x1C00 type
//! object (T605, T606, T614, T615, T618, T627).

use super::*;

rule!(
    T605,
    "T605",
    "esi-sm-pdo-size",
    "etg",
    Error,
    Deny,
    sm_pdo_size,
    "the default PDOs of a sync manager do not fit its MinSize..MaxSize",
    "A process-data sync manager is as long as the PDOs assigned to it (their bits packed, \
     rounded up to bytes). <Sm MinSize MaxSize> bound that length (ETG.2000); the ESC area \
     behind it is no larger. When the default PDO set (the PDOs whose Sm attribute names the \
     sync manager) is longer than MaxSize or shorter than MinSize, a master that uses the \
     defaults configures a length the device refuses (AL status 0x001D/0x001E invalid \
     output/input configuration). Fix: correct MinSize/MaxSize, or the PDOs' Sm attributes."
);

pub(super) fn sm_pdo_size(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    for sm in &ec.sync_managers {
        if direction_of(&sm.usage).is_none() || assigned(dev, sm.number).next().is_none() {
            continue;
        }
        let bytes = assigned_bytes(dev, sm.number);
        let n = sm.number;
        let problem = match (sm.min_size, sm.max_size) {
            (_, Some(max)) if bytes > u64::from(max) => format!(
                "the default PDOs of SM {n} ({}) take {bytes} bytes; MaxSize is {max}",
                usage_name(&sm.usage)
            ),
            (Some(min), _) if bytes < u64::from(min) => format!(
                "the default PDOs of SM {n} ({}) take {bytes} bytes; MinSize is {min}",
                usage_name(&sm.usage)
            ),
            _ => continue,
        };
        ctx.report_device(sm.span, problem);
    }
}

rule!(
    T627,
    "T627",
    "esi-sm-default-size",
    "etg",
    Warning,
    Warn,
    sm_default_size,
    "a process-data sync manager's DefaultSize differs from the size of its default PDOs",
    "A process-data sync manager is as long as the PDOs assigned to it (ETG.1000.6 §5.6.7.4: \
     their bits packed, rounded up to bytes). <Sm DefaultSize> is written into the SII's sync \
     manager category (ETG.2010), and a master that sizes the sync manager from it, rather than \
     from the PDOs, configures a length the device's mapping does not have; the device then \
     refuses SAFE-OP with AL status 0x001D/0x001E (invalid output/input configuration). A \
     sync manager with a DefaultSize and no default PDO at all is the common case: a master \
     maps nothing but enables a sized area. Modular devices are not checked (their PDOs come \
     with the modules). Fix: make DefaultSize the default PDOs' size (0 when none)."
);

pub(super) fn sm_default_size(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    if is_modular(ec) {
        return;
    }
    for sm in &ec.sync_managers {
        let Some(default) = sm.default_size.filter(|_| direction_of(&sm.usage).is_some()) else {
            continue;
        };
        let bytes = assigned_bytes(dev, sm.number);
        if bytes == u64::from(default) || sm.virtual_sm {
            continue;
        }
        let pdos = match assigned(dev, sm.number).count() {
            0 => "it has no default PDO".to_string(),
            n => format!("its {n} default PDO(s) take {bytes} bytes"),
        };
        ctx.report_device(
            sm.span,
            format!(
                "SM {} ({}) has DefaultSize {default}; {pdos}",
                sm.number,
                usage_name(&sm.usage)
            ),
        );
    }
}

rule!(
    T606,
    "T606",
    "esi-sm-size-range",
    "etg",
    Error,
    Deny,
    sm_size_range,
    "a sync manager's MinSize, DefaultSize and MaxSize are not in order",
    "<Sm MinSize DefaultSize MaxSize> give the smallest, the default and the largest length of \
     a sync manager in bytes (ETG.2000); they must satisfy MinSize ≤ DefaultSize ≤ MaxSize. \
     A master takes the default for mailboxes and checks process-data lengths against the \
     bounds, so inverted bounds make every length invalid. Fix: correct the attributes."
);

pub(super) fn sm_size_range(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    for sm in &ec.sync_managers {
        let n = sm.number;
        let problem = match (sm.min_size, sm.default_size, sm.max_size) {
            (Some(min), _, Some(max)) if min > max => {
                format!("SM {n}: MinSize {min} is larger than MaxSize {max}")
            }
            (Some(min), Some(def), _) if def < min => {
                format!("SM {n}: DefaultSize {def} is smaller than MinSize {min}")
            }
            (_, Some(def), Some(max)) if def > max => {
                format!("SM {n}: DefaultSize {def} is larger than MaxSize {max}")
            }
            _ => continue,
        };
        ctx.report_device(sm.span, problem);
    }
}

rule!(
    T614,
    "T614",
    "esi-sm-control-byte",
    "etg",
    Error,
    Deny,
    sm_control_byte,
    "a sync manager's ControlByte disagrees with its type",
    "The ControlByte of an <Sm> is written to the ESC's sync manager control register (0x0804 + \
     8n, ETG.1000.4): bits 0–1 are the mode (00 buffered, 10 mailbox), bits 2–3 the direction \
     (00 the master reads, 01 the master writes). MBoxOut needs mailbox mode and master writes \
     (0x26 is usual), MBoxIn mailbox mode and master reads (0x22), Outputs master writes (0x64, \
     0x24), Inputs master reads (0x20, 0x00); process data may use either mode. Modes 01/11 and \
     directions 10/11 are reserved. With a wrong ControlByte the ESC moves the data the wrong way \
     or never hands a buffer over. Fix: correct the ControlByte."
);

pub(super) fn sm_control_byte(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    for sm in &ec.sync_managers {
        let Some(cb) = sm.control_byte.as_ref() else { continue };
        let (mode, dir) = (cb.value & 0x3, (cb.value >> 2) & 0x3);
        let problem = if mode & 1 != 0 || dir & 2 != 0 {
            Some("sets a reserved mode or direction".to_string())
        } else {
            let (want_mode, want_dir) = match sm.usage {
                SmUsage::MBoxOut => (Some(2), 1),
                SmUsage::MBoxIn => (Some(2), 0),
                SmUsage::Outputs => (None, 1),
                SmUsage::Inputs => (None, 0),
                _ => continue,
            };
            if dir != want_dir {
                Some(format!(
                    "says the master {} but {} data flow the other way",
                    if dir == 1 { "writes" } else { "reads" },
                    usage_name(&sm.usage)
                ))
            } else if want_mode.is_some_and(|m| m != mode) {
                Some("is buffered mode, but a mailbox needs mailbox mode".to_string())
            } else {
                None
            }
        };
        if let Some(why) = problem {
            ctx.report_device(
                first_span([cb.span, sm.span]),
                format!(
                    "SM {} ({}): ControlByte 0x{:02X} {why}",
                    sm.number,
                    usage_name(&sm.usage),
                    cb.value
                ),
            );
        }
    }
}

/// Sync managers that start below this address point at ESC registers (the digital I/O
/// outputs 0x0F00–0x0F03, inputs 0x1000–0x1003), not at three-buffer memory.
pub(super) const DIGITAL_IO_END: u16 = 0x1004;

/// The ESC memory a sync manager occupies by default: its length (DefaultSize, or the default
/// PDOs' bytes when larger; a mailbox without DefaultSize its MinSize), three times over for a
/// buffered process-data sync manager.
pub(super) fn sm_area(dev: &Device, sm: &SyncManager) -> Option<(u32, u32)> {
    let start = u32::from(sm.start_address.as_ref()?.value);
    let len = if direction_of(&sm.usage).is_some() {
        u64::from(sm.default_size.unwrap_or(0)).max(assigned_bytes(dev, sm.number))
    } else {
        u64::from(sm.default_size.or(sm.min_size).unwrap_or(0))
    };
    let buffered = sm.control_byte.as_ref().is_none_or(|c| c.value & 0x3 == 0);
    let len = if buffered && !is_mailbox(&sm.usage) { len * 3 } else { len };
    let len = u32::try_from(len).ok()?;
    (len > 0).then_some((start, start.saturating_add(len)))
}

rule!(
    T615,
    "T615",
    "esi-sm-overlap",
    "etg",
    Warning,
    Warn,
    sm_address,
    "the memory areas of two enabled sync managers overlap",
    "Each sync manager guards an area of ESC memory from StartAddress on (ETG.1000.4): a \
     mailbox or single-buffered sync manager occupies its length, a buffered (3-buffer) one \
     three times its length. Two enabled sync managers must not share memory, or they corrupt \
     each other's data. The length taken is the default one: DefaultSize, or the default PDOs' \
     size when larger (for a mailbox without DefaultSize, MinSize). (Addresses below 0x1000 are not reported: simple digital terminals point a \
     sync manager at the ESC's digital I/O register 0x0F00.) Fix: correct StartAddress or the \
     sizes."
);

pub(super) fn sm_address(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    let mut areas: Vec<(&SyncManager, u32, u32)> = Vec::new();
    for sm in ec.sync_managers.iter().filter(|sm| !sm.virtual_sm) {
        let Some(start) = sm.start_address.as_ref() else { continue };
        if !sm.enable || start.value < DIGITAL_IO_END {
            continue;
        }
        let Some((a, b)) = sm_area(dev, sm) else { continue };
        if let Some((other, c, d)) = areas.iter().find(|(_, c, d)| a < *d && *c < b) {
            ctx.report_device(
                first_span([start.span, sm.span]),
                format!(
                    "SM {} (0x{a:04X}..0x{b:04X}) overlaps SM {} (0x{c:04X}..0x{d:04X})",
                    sm.number, other.number
                ),
            )
            .labels
            .push(Label {
                span: other.span,
                message: "this one".into(),
                primary: false,
            });
        }
        areas.push((sm, a, b));
    }
}

rule!(
    T618,
    "T618",
    "esi-sm-type-object",
    "etg",
    Warning,
    Warn,
    sm_type_object,
    "object 0x1C00 (sync manager types) disagrees with the <Sm> elements",
    "Sub-index n of 0x1C00 (sync manager communication type, ETG.1000.6 §5.6.7.4.5) gives the \
     type of SM n−1: 1 mailbox out, 2 mailbox in, 3 outputs, 4 inputs, 0 unused. Masters that \
     configure a device from its dictionary (SDO information, PdoUpload) read it, those that \
     use the ESI read the <Sm> elements; when the two disagree the device is configured \
     differently depending on the master. Fix: make 0x1C00's default values match the <Sm> \
     types."
);

pub(super) fn sm_type_object(dev: &Device, ctx: &mut Ctx) {
    let Some(ec) = ec(dev) else { return };
    if !has_dictionary(dev) || ec.sync_managers.is_empty() {
        return;
    }
    // One odc synthesised holds the `Sm` elements' types: nothing to compare.
    let Some(o) = crate::util::object(dev, 0x1C00) else { return };
    let Some(count) = initial_u64(dev, 0x1C00, 0) else { return };
    for sub in 1..=count.min(32) as u8 {
        let Some(s) = o.sub(sub) else { continue };
        let Some(v) = s.initial_value() else { continue };
        let Some(code) = v.value.as_u64() else { continue };
        let n = usize::from(sub - 1);
        let want = match ec.sync_managers.get(n).map(|sm| &sm.usage) {
            Some(SmUsage::MBoxOut) => 1,
            Some(SmUsage::MBoxIn) => 2,
            Some(SmUsage::Outputs) => 3,
            Some(SmUsage::Inputs) => 4,
            // The ESC may have more sync managers than the ESI describes.
            None | Some(_) => continue,
        };
        if code != want {
            let what = ec.sync_managers.get(n).map_or("", |sm| usage_name(&sm.usage));
            let d = ctx.report(
                0x1C00,
                Some(sub),
                first_span([v.span, s.span, o.span]),
                format!(
                    "0x1C00:{sub:02X} says type {code} for SM {n}, which is of type {what} ({want})"
                ),
            );
            if let Some(sm) = ec.sync_managers.get(n) {
                d.labels.push(Label {
                    span: sm.span,
                    message: format!("SM {n} defined here"),
                    primary: false,
                });
            }
        }
    }
}
