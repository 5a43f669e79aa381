//! D501–D507: CiA 402 drives (CiA 402-2; over EtherCAT ETG.6010).
//!
//! Which devices are CiA 402 drives, and their axes, is [`odc_analysis::cia402`]'s rule (0x1000
//! decides when it has a value; else an ESI `Profile` that says `ProfileNo` 402, for the whole
//! device or per channel).
//!
//! A multi-axis device repeats the profile area every 0x800 indexes (axis n at
//! 0x6000 + n·0x800); each axis is checked on its own.

use odc_model::{DataType, Device, Direction, Object, Span, SubObject};

use super::rule;
use crate::Ctx;
use crate::util::{first_span, idx, initial_u64};

/// The index offsets of the axes to check: the device's CiA 402 axes
/// ([`odc_analysis::cia402::axes`]: the one rule the generator and the data sheet use too;
/// 0x1000 decides when it has a value, the ESI profile when it has none). Devices whose ESI
/// has no dictionary (its objects are only the PDO entries) are not checked.
fn axes(dev: &Device) -> Vec<u16> {
    if dev.ethercat.as_deref().is_some_and(|e| e.dictionary_synthesised) {
        return Vec::new();
    }
    odc_analysis::cia402::axes(dev)
}

/// Where and why the device counts as a 402 drive: the value of 0x1000 when it has one, else
/// the ESI profile that says 402.
fn why_402(dev: &Device) -> (Span, String) {
    let device_type = dev.sub(0x1000, 0).and_then(|s| {
        let v = s.initial_value()?;
        let n = v.value.as_u64()?;
        Some((first_span([v.span, s.span]), n))
    });
    if let Some((span, n)) = device_type
        && n & 0xFFFF == 402
    {
        return (span, format!("0x1000 is 0x{n:08X}: device profile 402 in bits 0–15"));
    }
    let profile = dev.ethercat.as_deref().and_then(|e| {
        e.profiles
            .iter()
            .find(|p| p.profile_no == Some(402) || p.channel_profiles.contains(&Some(402)))
    });
    match profile {
        Some(p) if p.profile_no == Some(402) => {
            (p.span, "the ESI's <Profile> says <ProfileNo>402</ProfileNo>".to_string())
        }
        Some(p) => {
            (p.span, "a <ChannelInfo> of the ESI's <Profile> says ProfileNo 402".to_string())
        }
        None => {
            let span = dev.objects.get(&0x1000).map_or(Span::DUMMY, |o| o.span);
            (span, "0x1000 says device profile 402".to_string())
        }
    }
}

fn axis_text(base: u16) -> String {
    if base == 0 {
        String::new()
    } else {
        format!(" (axis {})", base / odc_analysis::cia402::AXIS_OFFSET + 1)
    }
}

/// The VAR-like value of an object (sub 0).
fn var(o: &Object) -> Option<&SubObject> {
    o.var().or_else(|| o.sub(0))
}

rule!(
    D501,
    "D501",
    "cia402-controlword-statusword",
    "cia402",
    Error,
    Deny,
    controlword_statusword,
    "a CiA 402 drive lacks the controlword 0x6040 or the statusword 0x6041",
    "Every CiA 402 axis is driven through its state machine: the master writes the controlword \
     0x6040 and reads the statusword 0x6041 (CiA 402-2 §8). A device that says profile 402 (in \
     0x1000, or in an ESI's Profile/ProfileNo) but lacks one of them cannot be enabled by any \
     402 master (python-canopen's BaseNode402, ros2_canopen, the ETG.6010 state machine of \
     EtherCAT masters). For multi-axis devices each axis has its own pair at +0x800·n. Fix: \
     add the objects, or correct 0x1000 / ProfileNo."
);

fn controlword_statusword(dev: &Device, ctx: &mut Ctx) {
    for base in axes(dev) {
        for (index, what) in [(0x6040 + base, "controlword"), (0x6041 + base, "statusword")] {
            if !dev.objects.contains_key(&index) {
                let (span, why) = why_402(dev);
                ctx.report(
                    index,
                    None,
                    span,
                    format!("CiA 402 drive{} has no {what} {}", axis_text(base), idx(index)),
                )
                .notes
                .push(format!("it is a CiA 402 drive because {why}"));
            }
        }
    }
}

/// The data types CiA 402 gives its core objects.
const TYPES: &[(u16, DataType, &str)] = &[
    (0x6040, DataType::Unsigned16, "controlword"),
    (0x6041, DataType::Unsigned16, "statusword"),
    (0x6060, DataType::Integer8, "modes of operation"),
    (0x6061, DataType::Integer8, "modes of operation display"),
    (0x6064, DataType::Integer32, "position actual value"),
    (0x606C, DataType::Integer32, "velocity actual value"),
    (0x6071, DataType::Integer16, "target torque"),
    (0x6077, DataType::Integer16, "torque actual value"),
    (0x607A, DataType::Integer32, "target position"),
    (0x60FF, DataType::Integer32, "target velocity"),
    (0x6502, DataType::Unsigned32, "supported drive modes"),
];

rule!(
    D502,
    "D502",
    "cia402-object-type",
    "cia402",
    Error,
    Deny,
    object_type,
    "a CiA 402 core object does not have the data type CiA 402 gives it",
    "CiA 402-2 fixes the data types of its core objects: controlword 0x6040 and statusword \
     0x6041 UNSIGNED16; modes of operation 0x6060 and its display 0x6061 INTEGER8; target and \
     actual position 0x607A/0x6064 and velocity 0x60FF/0x606C INTEGER32; target and actual \
     torque 0x6071/0x6077 INTEGER16; supported drive modes 0x6502 UNSIGNED32. Masters map and \
     access them with these sizes; another type breaks PDO layouts and SDO transfers. Fix: \
     correct the DataType."
);

fn object_type(dev: &Device, ctx: &mut Ctx) {
    for base in axes(dev) {
        for &(index, dt, what) in TYPES {
            let Some(o) = dev.objects.get(&(index + base)) else { continue };
            let Some(s) = var(o) else { continue };
            if s.data_type != dt {
                ctx.report(
                    o.index,
                    None,
                    first_span([s.data_type_span, s.span, o.span]),
                    format!(
                        "{} ({what}){} is {}; CiA 402 makes it {}",
                        idx(o.index),
                        axis_text(base),
                        s.data_type.name(),
                        dt.name()
                    ),
                );
            }
        }
    }
}

/// Reports `index` when it exists and cannot be mapped in `dir`.
fn check_mappable(dev: &Device, ctx: &mut Ctx, index: u16, dir: Direction, why: &str) {
    let Some(o) = dev.objects.get(&index) else { return };
    let Some(s) = var(o) else { return };
    if !s.pdo_mapping.allows(s.access, dir) {
        let pdo = if dir == Direction::Rx { "an RPDO" } else { "a TPDO" };
        ctx.report(
            index,
            None,
            first_span([s.span, o.span]),
            format!(
                "{} cannot be mapped into {pdo} (PDOMapping {:?}, access {}); {why}",
                idx(index),
                s.pdo_mapping,
                s.access.as_str()
            ),
        );
    }
}

rule!(
    D503,
    "D503",
    "cia402-pdo-mappable",
    "cia402",
    Warning,
    Warn,
    pdo_mappable,
    "the controlword is not RPDO-mappable or the statusword not TPDO-mappable",
    "A CiA 402 drive is run cyclically: the controlword 0x6040 travels in an RPDO (access rww or \
     rw, PDOMapping=1) and the statusword 0x6041 in a TPDO (ro/rwr/rw, PDOMapping=1) — the \
     \"minimum PDO set\" python-canopen's BaseNode402 warns about. Without that, the state \
     machine can only be driven by SDO, far too slowly for cyclic modes. Fix: make them \
     mappable in those directions."
);

fn pdo_mappable(dev: &Device, ctx: &mut Ctx) {
    for base in axes(dev) {
        check_mappable(dev, ctx, 0x6040 + base, Direction::Rx, "the controlword is an output");
        check_mappable(dev, ctx, 0x6041 + base, Direction::Tx, "the statusword is an input");
    }
}

/// The modes of 0x6502: bit, name, objects the mode needs.
const MODES: &[(u32, &str, &[u16])] = &[
    (0, "profile position (pp)", &[0x607A, 0x6081, 0x6083]),
    (1, "velocity (vl)", &[0x6042]),
    (2, "profile velocity (pv)", &[0x60FF]),
    (3, "profile torque (tq)", &[0x6071]),
    (5, "homing (hm)", &[0x6098, 0x6099]),
    (6, "interpolated position (ip)", &[0x60C1]),
    (7, "cyclic synchronous position (csp)", &[0x607A, 0x6064]),
    (8, "cyclic synchronous velocity (csv)", &[0x60FF, 0x606C]),
    (9, "cyclic synchronous torque (cst)", &[0x6071, 0x6077]),
];

fn supported_modes(dev: &Device, base: u16) -> Option<u64> {
    initial_u64(dev, 0x6502 + base, 0)
}

rule!(
    D504,
    "D504",
    "cia402-mode-objects",
    "cia402",
    Warning,
    Warn,
    mode_objects,
    "0x6502 announces a mode of operation whose objects are missing",
    "Supported drive modes 0x6502 has one bit per mode (bit 0 pp, 1 vl, 2 pv, 3 tq, 5 hm, 6 ip, \
     7 csp, 8 csv, 9 cst). Each mode needs its objects (CiA 402-2): pp the target position \
     0x607A, profile velocity 0x6081 and acceleration 0x6083; vl 0x6042; pv the target \
     velocity 0x60FF; tq the target torque 0x6071; hm the homing method 0x6098 and speeds \
     0x6099; ip the interpolation data 0x60C1; csp 0x607A and 0x6064; csv 0x60FF and 0x606C; \
     cst 0x6071 and 0x6077. A master that selects an announced mode fails on the missing \
     object. Fix: add the objects or clear the bit in 0x6502's default."
);

fn mode_objects(dev: &Device, ctx: &mut Ctx) {
    for base in axes(dev) {
        let Some(modes) = supported_modes(dev, base) else { continue };
        let Some(o) = dev.objects.get(&(0x6502 + base)) else { continue };
        let span = var(o).map_or(o.span, |s| first_span([s.span, o.span]));
        for &(bit, name, needs) in MODES {
            if modes & (1 << bit) == 0 {
                continue;
            }
            let missing: Vec<String> = needs
                .iter()
                .filter(|&&i| !dev.objects.contains_key(&(i + base)))
                .map(|&i| idx(i + base))
                .collect();
            if !missing.is_empty() {
                ctx.report(
                    o.index,
                    None,
                    span,
                    format!(
                        "{} announces {name}{} but {} missing",
                        idx(o.index),
                        axis_text(base),
                        if missing.len() == 1 {
                            format!("{} is", missing[0])
                        } else {
                            format!("{} are", missing.join(", "))
                        }
                    ),
                );
            }
        }
    }
}

rule!(
    D505,
    "D505",
    "cia402-cyclic-mappable",
    "cia402",
    Warning,
    Warn,
    cyclic_mappable,
    "a cyclic synchronous mode's setpoint is not RPDO-mappable or its actual value not TPDO-mappable",
    "In the cyclic synchronous modes the master sends a setpoint every cycle and reads back the \
     actual value (CiA 402-2 §§ on csp/csv/cst; ETG.6010): csp needs the target position \
     0x607A in an RPDO and the position actual value 0x6064 in a TPDO; csv 0x60FF and 0x606C; \
     cst 0x6071 and 0x6077. If 0x6502 announces the mode but the objects cannot be mapped that \
     way, the mode is unusable. Fix: PDOMapping=1 with rww/rw on the setpoint and ro/rwr/rw on \
     the actual value."
);

fn cyclic_mappable(dev: &Device, ctx: &mut Ctx) {
    for base in axes(dev) {
        let Some(modes) = supported_modes(dev, base) else { continue };
        for (bit, setpoint, actual, mode) in
            [(7, 0x607A, 0x6064, "csp"), (8, 0x60FF, 0x606C, "csv"), (9, 0x6071, 0x6077, "cst")]
        {
            if modes & (1 << bit) == 0 {
                continue;
            }
            let why_rx = format!("{mode} sends it every cycle");
            let why_tx = format!("{mode} reads it every cycle");
            check_mappable(dev, ctx, setpoint + base, Direction::Rx, &why_rx);
            check_mappable(dev, ctx, actual + base, Direction::Tx, &why_tx);
        }
    }
}

rule!(
    D506,
    "D506",
    "cia402-modes-of-operation",
    "cia402",
    Warning,
    Warn,
    modes_of_operation,
    "a drive with several modes lacks modes of operation 0x6060 or its display 0x6061",
    "A drive that supports more than one mode (more than one bit in 0x6502) is switched between \
     them by writing modes of operation 0x6060 and confirms the switch in modes of operation \
     display 0x6061 (CiA 402-2). Without them a master cannot select a mode. Fix: add both \
     objects (INTEGER8, 0x6060 rww, 0x6061 ro, both PDO-mappable)."
);

fn modes_of_operation(dev: &Device, ctx: &mut Ctx) {
    for base in axes(dev) {
        let Some(modes) = supported_modes(dev, base) else { continue };
        if (modes & 0x3FF).count_ones() < 2 {
            continue;
        }
        let Some(o) = dev.objects.get(&(0x6502 + base)) else { continue };
        for index in [0x6060 + base, 0x6061 + base] {
            if !dev.objects.contains_key(&index) {
                ctx.report(
                    index,
                    None,
                    o.span,
                    format!(
                        "{} announces {} modes but {} is missing",
                        idx(o.index),
                        (modes & 0x3FF).count_ones(),
                        idx(index)
                    ),
                );
            }
        }
    }
}

rule!(
    D507,
    "D507",
    "cia402-axis-offset",
    "cia402",
    Warning,
    Warn,
    axis_offset,
    "an object of a further axis differs in type from the first axis's",
    "A multi-axis CiA 402 device repeats the profile objects of the first axis \
     (0x6000–0x67FF) for axis n at +0x800·n (CiA 402-2 §5; ros2_canopen get_channel_index). \
     The copies are the same objects, so they have the same data type; a difference usually \
     means a typo in an index or a wrong offset. Fix: align the data type with the first \
     axis's object, or move the object to its intended index."
);

fn axis_offset(dev: &Device, ctx: &mut Ctx) {
    for base in axes(dev).into_iter().filter(|&b| b != 0) {
        for (&index, o) in dev.objects.range(0x6000 + base..=0x67FF + base) {
            // The core objects' types are checked per axis by D502.
            if TYPES.iter().any(|t| t.0 == index - base) {
                continue;
            }
            let Some(first) = dev.objects.get(&(index - base)) else { continue };
            let (Some(s), Some(f)) = (var(o), var(first)) else { continue };
            if o.kind.has_subs() || first.kind.has_subs() || s.data_type == f.data_type {
                continue;
            }
            ctx.report(
                index,
                None,
                first_span([s.data_type_span, s.span, o.span]),
                format!(
                    "{}{} is {} but {} of the first axis is {}",
                    idx(index),
                    axis_text(base),
                    s.data_type.name(),
                    idx(index - base),
                    f.data_type.name()
                ),
            );
        }
    }
}
