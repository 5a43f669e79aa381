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
            // are the drive's own (a fault), 15 only from a fault.
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
