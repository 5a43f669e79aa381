//! A CiA 402 drive (CiA 402-2 6.2 and 6.4): the state machine's transitions by controlword,
//! the modes of operation 0x6502 lists and no others, 0x6061 following 0x6060. Over SDO, in
//! pre-operational; the drive passes through "operation enabled", so run it where an enabled
//! drive is safe.

use std::fmt::Display;
use std::time::Duration;

use odc::transport::Bus;
use odc_analysis::cia402::{MODES, is_cia402};

use crate::session::{SdoFail, Session, le};
use crate::{Group, Outcome};

/// States by their statusword mask and value (CiA 402-2 Table 30).
const STATES: [(&str, u16, u16); 6] = [
    ("switch on disabled", 0x4F, 0x40),
    ("ready to switch on", 0x6F, 0x21),
    ("switched on", 0x6F, 0x23),
    ("operation enabled", 0x6F, 0x27),
    ("quick stop active", 0x6F, 0x07),
    ("fault", 0x4F, 0x08),
];

fn state_of(sw: u16) -> &'static str {
    STATES.iter().find(|(_, m, v)| sw & m == *v).map_or("not ready to switch on", |s| s.0)
}

/// The statusword once it shows one of `want`, waiting up to 500 ms.
fn wait_state<B: Bus>(s: &mut Session<'_, B>, want: &[&str]) -> Result<u16, String>
where
    B::Error: Display,
{
    let mut sw = 0;
    for _ in 0..25 {
        sw = s.read(0x6041, 0).map(|b| le(&b) as u16).map_err(|e| format!("0x6041: {e}"))?;
        if want.contains(&state_of(sw)) {
            return Ok(sw);
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    Err(format!("statusword 0x{sw:04X} ({}), not {}", state_of(sw), want.join(" or ")))
}

pub(crate) fn run<B: Bus>(s: &mut Session<'_, B>)
where
    B::Error: Display,
{
    let drive = is_cia402(s.dev);
    s.check(
        "cia402.state-machine",
        Group::Cia402,
        "CiA 402-2 6.2.1 (Figure 12, Tables 30 and 31)",
        "transitions 2 to 12 by controlword, each to the state Table 31 names",
        |s| {
            if !drive {
                return Outcome::na("not a CiA 402 drive (0x1000, 0x6040/0x6041)");
            }
            if s.sub(0x6040, 0).is_none() || s.sub(0x6041, 0).is_none() {
                return Outcome::na("the file has no 0x6040 and 0x6041");
            }
            let old = s.read(0x6040, 0).ok();
            const SOD: &[&str] = &["switch on disabled"];
            const RTSO: &[&str] = &["ready to switch on"];
            const SO: &[&str] = &["switched on"];
            const OE: &[&str] = &["operation enabled"];
            // Every transition the controlword makes (CiA 402-2 Table 31), 2 to 12; 13 and 14
            // are the drive's own (a fault) and 15 leaves it: cia402.fault; 16: quick-stop.
            let steps: [(&str, u16, &[&str]); 24] = [
                ("15 fault reset", 0x80, &["switch on disabled", "not ready to switch on"]),
                ("disable voltage", 0x00, SOD),
                ("2 shutdown", 0x06, RTSO),
                ("7 quick stop", 0x02, SOD),
                ("2 shutdown", 0x06, RTSO),
                ("3 switch on", 0x07, SO),
                ("4 enable operation", 0x0F, OE),
                ("5 disable operation", 0x07, SO),
                ("6 shutdown", 0x06, RTSO),
                ("3 switch on", 0x07, SO),
                ("10 disable voltage", 0x00, SOD),
                ("2 shutdown", 0x06, RTSO),
                ("3 switch on", 0x07, SO),
                ("4 enable operation", 0x0F, OE),
                ("8 shutdown", 0x06, RTSO),
                ("3 switch on", 0x07, SO),
                ("4 enable operation", 0x0F, OE),
                ("9 disable voltage", 0x00, SOD),
                ("2 shutdown", 0x06, RTSO),
                ("3 switch on", 0x07, SO),
                ("4 enable operation", 0x0F, OE),
                ("11 quick stop", 0x02, &["quick stop active", "switch on disabled"]),
                ("12 disable voltage", 0x00, SOD),
                ("disable voltage", 0x00, SOD),
            ];
            let mut seen = Vec::new();
            let mut outcome = None;
            for (what, cw, want) in steps {
                if let Err(e) = s.write(0x6040, 0, &cw.to_le_bytes()) {
                    outcome = Some(Outcome::fail(format!("{what} (0x{cw:04X}): {e}")));
                    break;
                }
                match wait_state(s, want) {
                    Ok(sw) => seen.push(format!("{what}: 0x{sw:04X}")),
                    Err(e) => {
                        outcome = Some(Outcome::fail(format!("{what} (0x{cw:04X}): {e}")));
                        break;
                    }
                }
            }
            let _ = s.write(0x6040, 0, &[0, 0]);
            if let Some(old) = old {
                let _ = s.write(0x6040, 0, &old);
            }
            outcome.unwrap_or_else(|| Outcome::pass(seen.join(", ")))
        },
    );
    s.check(
        "cia402.fault",
        Group::Cia402,
        "CiA 402-2 6.2.1 (Table 31: 13, 14, 15), 6.5.1 (0x6007); CiA 301 7.5.2.33 (0x1016)",
        "with 0x6007 = 1, a heartbeat the drive consumes that stops is a fault (13, 14 from \
         operation enabled to fault); a fault reset takes it to switch on disabled (15)",
        |s| {
            if !drive {
                return Outcome::na("not a CiA 402 drive (0x1000, 0x6040/0x6041)");
            }
            for (i, sub) in [(0x6007, 0), (0x1016, 1), (0x6040, 0)] {
                if !s.sub(i, sub).is_some_and(|so| so.access.writable()) {
                    return Outcome::na(format!(
                        "no writable 0x{i:04X}:{sub:02X} in the file: no fault to provoke"
                    ));
                }
            }
            // The consumer entry (node << 16 | 100 ms) within the file's limits of 0x1016:01.
            let entry = u32::from(heartbeat_producer(s.node.get())) << 16 | 100;
            let high = s
                .sub(0x1016, 1)
                .and_then(|so| so.high_limit.as_ref())
                .and_then(|l| l.value.as_i128(s.node.get()));
            if high.is_some_and(|h| i128::from(entry) > h) {
                return Outcome::na(format!(
                    "the file's HighLimit of 0x1016:01 refuses the consumer entry 0x{entry:08X} \
                     (node-ID in bits 16-23, CiA 301 7.5.2.33): no heartbeat to lose"
                ));
            }
            let old: Vec<_> = [(0x6007u16, 0u8), (0x1016, 1), (0x6040, 0)]
                .into_iter()
                .filter_map(|(i, sub)| Some((i, sub, s.read(i, sub).ok()?)))
                .collect();
            let outcome = fault_path(s);
            let _ = s.write(0x6040, 0, &[0, 0]);
            for (i, sub, v) in old {
                let _ = s.write(i, sub, &v);
            }
            outcome
        },
    );
    s.check(
        "cia402.quick-stop",
        Group::Cia402,
        "CiA 402-2 6.2.1 (Table 31: 11, 16), 6.5.2 (0x605A)",
        "with quick stop option code 6 the drive stays in quick stop active after a quick \
         stop, and enable operation takes it back to operation enabled (16)",
        |s| {
            if !drive {
                return Outcome::na("not a CiA 402 drive (0x1000, 0x6040/0x6041)");
            }
            for i in [0x605A, 0x6040] {
                if !s.sub(i, 0).is_some_and(|so| so.access.writable()) {
                    return Outcome::na(format!("no writable 0x{i:04X} in the file"));
                }
            }
            let (Ok(old_option), Ok(old_cw)) = (s.read(0x605A, 0), s.read(0x6040, 0)) else {
                return Outcome::fail("0x605A or 0x6040 does not read");
            };
            if let Err(e) = s.write(0x605A, 0, &6i16.to_le_bytes()) {
                // CiA 402 leaves the supported codes to the device: 6 may be refused.
                return match e {
                    SdoFail::Abort(c) => Outcome::na(format!("0x605A = 6 refused (0x{c:08X})")),
                    e => Outcome::fail(format!("0x605A = 6: {e}")),
                };
            }
            let steps: [(&str, u16, &[&str]); 6] = [
                ("disable voltage", 0x00, &["switch on disabled"]),
                ("2 shutdown", 0x06, &["ready to switch on"]),
                ("3 switch on", 0x07, &["switched on"]),
                ("4 enable operation", 0x0F, &["operation enabled"]),
                ("11 quick stop", 0x02, &["quick stop active"]),
                ("16 enable operation", 0x0F, &["operation enabled"]),
            ];
            let outcome = walk(s, &steps);
            let _ = s.write(0x6040, 0, &[0, 0]);
            let _ = s.write(0x605A, 0, &old_option);
            let _ = s.write(0x6040, 0, &old_cw);
            outcome
        },
    );
    s.check(
        "cia402.modes",
        Group::Cia402,
        "CiA 402-2 6.4.1-6.4.3 (0x6060, 0x6061, 0x6502)",
        "each mode 0x6502 lists is taken (0x6061 follows 0x6060); the others are refused",
        |s| {
            if !drive {
                return Outcome::na("not a CiA 402 drive (0x1000, 0x6040/0x6041)");
            }
            match s.sub(0x6060, 0) {
                Some(so) if so.access.writable() && s.sub(0x6061, 0).is_some() => {}
                _ => return Outcome::na("the file has no writable 0x6060 and 0x6061"),
            }
            let supported = if s.sub(0x6502, 0).is_some() {
                match s.read_u32(0x6502, 0) {
                    Ok(v) => Some(v),
                    Err(e) => return Outcome::fail(format!("0x6502: {e}")),
                }
            } else {
                None
            };
            let old = match s.read(0x6060, 0) {
                Ok(v) => v,
                Err(e) => return Outcome::fail(format!("0x6060: {e}")),
            };
            let mut problems = Vec::new();
            let (mut taken, mut refused) = (Vec::new(), Vec::new());
            for m in MODES {
                let listed = supported.is_none_or(|bits| bits & (1 << m.bit) != 0);
                let r = s.write(0x6060, 0, &m.value.to_le_bytes());
                std::thread::sleep(Duration::from_millis(30));
                let display = s.read(0x6061, 0).ok().and_then(|b| b.first().copied());
                let follows = display == Some(m.value as u8);
                match (listed, r) {
                    (true, Ok(())) if follows => taken.push(m.value),
                    (true, Ok(())) => {
                        problems.push(format!("mode {} taken, 0x6061 shows {display:?}", m.value))
                    }
                    (true, Err(e)) => problems.push(format!("mode {} (listed): {e}", m.value)),
                    (false, Err(SdoFail::Abort(_))) => refused.push(m.value),
                    (false, Err(e)) => problems.push(format!("mode {} (not listed): {e}", m.value)),
                    (false, Ok(())) if follows => {
                        problems.push(format!("mode {} not listed in 0x6502, taken", m.value));
                    }
                    (false, Ok(())) => refused.push(m.value),
                }
            }
            let _ = s.write(0x6060, 0, &old);
            if problems.is_empty() {
                Outcome::pass(format!("taken {taken:?}, refused {refused:?}"))
            } else {
                Outcome::fail(problems.join("; "))
            }
        },
    );
}

/// Each step's controlword, then the statusword until it shows one of the step's states.
fn walk<B: Bus>(s: &mut Session<'_, B>, steps: &[(&str, u16, &[&str])]) -> Outcome
where
    B::Error: Display,
{
    let mut seen = Vec::new();
    for &(what, cw, want) in steps {
        if let Err(e) = s.write(0x6040, 0, &cw.to_le_bytes()) {
            return Outcome::fail(format!("{what} (0x{cw:04X}): {e}"));
        }
        match wait_state(s, want) {
            Ok(sw) => seen.push(format!("{what}: 0x{sw:04X}")),
            Err(e) => return Outcome::fail(format!("{what} (0x{cw:04X}): {e}")),
        }
    }
    Outcome::pass(seen.join(", "))
}

/// The node-ID whose heartbeat the drive is told to consume: one that is not the device's.
fn heartbeat_producer(node: u8) -> u8 {
    if node == 0x7E { 0x7D } else { 0x7E }
}

/// Operation enabled, 0x6007 = 1, a consumed heartbeat (100 ms) that comes once and stops:
/// the drive must reach "fault" (13, 14), stay there, and leave it by a fault reset (15).
fn fault_path<B: Bus>(s: &mut Session<'_, B>) -> Outcome
where
    B::Error: Display,
{
    let enable: [(&str, u16, &[&str]); 4] = [
        ("disable voltage", 0x00, &["switch on disabled"]),
        ("2 shutdown", 0x06, &["ready to switch on"]),
        ("3 switch on", 0x07, &["switched on"]),
        ("4 enable operation", 0x0F, &["operation enabled"]),
    ];
    if let o @ Outcome::Fail { .. } = walk(s, &enable) {
        return o;
    }
    let producer = heartbeat_producer(s.node.get());
    let entry = u32::from(producer) << 16 | 100;
    for (i, sub, v) in
        [(0x6007u16, 0u8, 1i16.to_le_bytes().to_vec()), (0x1016, 1, entry.to_le_bytes().to_vec())]
    {
        if let Err(e) = s.write(i, sub, &v) {
            return Outcome::fail(format!("0x{i:04X}:{sub:02X}: {e}"));
        }
    }
    // One heartbeat (pre-operational) starts the watch; none after it.
    if let Err(e) = s.send(0x700 + u32::from(producer), &[0x7F]) {
        return Outcome::fail(e);
    }
    s.listen(400);
    let faulted = match wait_state(s, &["fault"]) {
        Ok(sw) => format!("13, 14: 0x{sw:04X} 400 ms after the last heartbeat of node {producer}"),
        Err(e) => return Outcome::fail(format!("heartbeat of node {producer} lost: {e}")),
    };
    // The consumer stops watching; a fault reset is a rising edge of bit 7.
    let _ = s.write(0x1016, 1, &0u32.to_le_bytes());
    let reset: [(&str, u16, &[&str]); 2] =
        [("disable voltage", 0x00, &["fault"]), ("15 fault reset", 0x80, &["switch on disabled"])];
    match walk(s, &reset) {
        Outcome::Pass { detail } => Outcome::pass(format!("{faulted}, {detail}")),
        o => o,
    }
}
