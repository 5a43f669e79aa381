//! Every entry of the file (CiA 301 7.4, 7.5.2.13/14; CiA 310's object dictionary tests):
//! it exists, its SDO size is its type's, read-only refuses a write and write-only a read,
//! limits refuse values outside them, the values after the resets (and after 0x1011 "load")
//! are the file's defaults, and 0x1010/0x1011 want their signatures.

use std::fmt::Display;

use odc::nmt::NmtCommand;
use odc::transport::Bus;
use odc_model::{Access, SubObject, ValueClass};

use crate::session::{SdoFail, Session};
use crate::{Group, Outcome};

const NO_OBJECT: u32 = 0x0602_0000;
const NO_SUB: u32 = 0x0609_0011;

/// "load" as CiA 301 7.5.2.13/14 write them (ASCII, lowest byte first).
pub(crate) const LOAD: [u8; 4] = *b"load";

/// How many application entries the reset checks change.
const RESET_SAMPLE: usize = 16;

type Entry<'d> = (u16, u8, &'d SubObject);

fn all<'d>(s: &Session<'d, impl Bus>) -> Vec<Entry<'d>> {
    s.dev
        .objects
        .values()
        .flat_map(|o| o.subs.values().map(move |sub| (o.index, sub.sub_index, sub)))
        .collect()
}

fn name(index: u16, sub: u8) -> String {
    format!("0x{index:04X}:{sub:02X}")
}

pub(crate) fn run<B: Bus>(s: &mut Session<'_, B>)
where
    B::Error: Display,
{
    // One pass of reads gives the exists, size and write-only checks; the values read are
    // what the access and limit checks write back.
    let entries = all(s);
    let mut values: Vec<(Entry<'_>, Result<Vec<u8>, SdoFail>)> = Vec::new();
    s.check(
        "entries.exist",
        Group::Entries,
        "CiA 301 7.4.1, CiA 306 4.6",
        "every entry of the file answers an SDO upload (write-only ones: 0x06010001)",
        |s| {
            let mut problems = Vec::new();
            // Another abort says the entry is there (0x060A0023 for a value the device does
            // not have yet, 0x06010001 for write-only): counted, shown in the detail.
            let mut other_aborts = std::collections::BTreeMap::<u32, usize>::new();
            for e @ (index, sub, _) in entries.iter().copied() {
                let r = s.read(index, sub);
                match &r {
                    Err(SdoFail::Abort(c @ (NO_OBJECT | NO_SUB))) => {
                        problems.push(format!("{} missing (0x{c:08X})", name(index, sub)));
                    }
                    Err(SdoFail::Abort(c)) => *other_aborts.entry(*c).or_default() += 1,
                    Err(err) => problems.push(format!("{}: {err}", name(index, sub))),
                    Ok(_) => {}
                }
                values.push((e, r));
            }
            match Outcome::from_problems(&problems, entries.len(), "entries") {
                Outcome::Pass { mut detail } if !other_aborts.is_empty() => {
                    let list: Vec<String> =
                        other_aborts.iter().map(|(c, n)| format!("0x{c:08X} × {n}")).collect();
                    detail += &format!(" (aborts that say it exists: {})", list.join(", "));
                    Outcome::pass(detail)
                }
                o => o,
            }
        },
    );
    let read: Vec<_> = values.iter().filter_map(|(e, r)| Some((*e, r.as_ref().ok()?))).collect();
    s.check(
        "entries.size",
        Group::Entries,
        "CiA 301 7.4.7.1, 7.2.4.3.3",
        "the size of each upload is the size of the entry's data type",
        |_| {
            let mut problems = Vec::new();
            let mut checked = 0;
            for ((index, sub, so), bytes) in &read {
                let Some(bits) = so.data_type.bit_size() else { continue };
                if so.access == Access::Wo {
                    continue;
                }
                checked += 1;
                let want = bits.div_ceil(8) as usize;
                if bytes.len() != want {
                    problems.push(format!(
                        "{} {}: {} bytes, not {want}",
                        name(*index, *sub),
                        so.data_type.name(),
                        bytes.len()
                    ));
                }
            }
            Outcome::from_problems(&problems, checked, "entries of a fixed-size type read")
        },
    );
    s.check(
        "entries.write-only",
        Group::Entries,
        "CiA 301 7.2.4.3.17 (0x06010001)",
        "a write-only entry refuses an upload with 0x06010001",
        |_| {
            let mut problems = Vec::new();
            let mut checked = 0;
            for ((index, sub, so), r) in &values {
                if so.access != Access::Wo {
                    continue;
                }
                checked += 1;
                match r {
                    Err(SdoFail::Abort(0x0601_0001)) => {}
                    Err(e) => problems.push(format!("{}: {e}", name(*index, *sub))),
                    Ok(b) => {
                        problems.push(format!("{}: read {} bytes", name(*index, *sub), b.len()))
                    }
                }
            }
            Outcome::from_problems(&problems, checked, "write-only entries")
        },
    );
    s.check(
        "entries.read-only",
        Group::Entries,
        "CiA 301 7.2.4.3.17 (0x06010002)",
        "a read-only or const entry refuses a download (of the value it holds) with 0x06010002",
        |s| {
            let mut problems = Vec::new();
            let mut checked = 0;
            for ((index, sub, so), bytes) in &read {
                if so.access.writable() {
                    continue;
                }
                checked += 1;
                match s.write(*index, *sub, bytes) {
                    Err(SdoFail::Abort(0x0601_0002)) => {}
                    Err(e) => problems.push(format!("{}: {e}", name(*index, *sub))),
                    Ok(()) => problems.push(format!("{}: accepted", name(*index, *sub))),
                }
            }
            Outcome::from_problems(&problems, checked, "read-only entries")
        },
    );
    s.check(
        "entries.limits",
        Group::Entries,
        "CiA 301 7.2.4.3.17 (0x06090031, 0x06090032), CiA 306 4.6.3",
        "a value past HighLimit/LowLimit is refused (0x06090031/0x06090032, or 0x06090030)",
        |s| limits(s, &values),
    );
    s.check(
        "entries.reset-application",
        Group::Entries,
        "CiA 301 7.3.2.2.1 (reset node)",
        "after NMT reset node every writable entry holds the file's default",
        |s| reset_defaults(s, NmtCommand::ResetNode),
    );
    s.check(
        "entries.reset-communication",
        Group::Entries,
        "CiA 301 7.3.2.2.1 (reset communication)",
        "after NMT reset communication the communication area (0x1000-0x1FFF) holds the file's \
         defaults and the application area keeps its values",
        |s| reset_defaults(s, NmtCommand::ResetCommunication),
    );
    for (id, index, title) in [
        (
            "entries.save-signature",
            0x1010,
            "0x1010:01 refuses a value other than \"save\" (0x08000020)",
        ),
        (
            "entries.load-signature",
            0x1011,
            "0x1011:01 refuses a value other than \"load\" (0x08000020)",
        ),
    ] {
        s.check(id, Group::Entries, "CiA 301 7.5.2.13, 7.5.2.14", title, |s| {
            let Some(so) = s.sub(index, 1) else {
                return Outcome::na(format!("the file has no 0x{index:04X}:01"));
            };
            if !so.access.writable() {
                return Outcome::na(format!("0x{index:04X}:01 is not writable in the file"));
            }
            match s.write(index, 1, b"nope") {
                Err(SdoFail::Abort(0x0800_0020)) => Outcome::pass("refused with 0x08000020"),
                Err(e) => Outcome::fail(format!("\"nope\": {e}, not 0x08000020")),
                Ok(()) => Outcome::fail("the wrong signature \"nope\" was accepted"),
            }
        });
    }
    s.check(
        "entries.load-defaults",
        Group::Entries,
        "CiA 301 7.5.2.14",
        "after 0x1011:01 \"load\" and reset node every writable entry holds the file's default",
        |s| {
            if s.sub(0x1011, 1).is_none() {
                return Outcome::na("the file has no 0x1011:01");
            }
            if !s.opt.restore_defaults {
                return Outcome::na(
                    "it restores the factory defaults, losing the parameters the device has \
                     stored: run with --restore-defaults",
                );
            }
            if let Err(e) = s.write(0x1011, 1, &LOAD) {
                return Outcome::fail(format!("0x1011:01 \"load\": {e}"));
            }
            reset_defaults(s, NmtCommand::ResetNode)
        },
    );
}

/// An integer value of the entry's type, or `None` outside its range.
fn int_bytes(so: &SubObject, v: i128) -> Option<Vec<u8>> {
    let (signed, bits) = match so.data_type.class() {
        ValueClass::Unsigned(b) => (false, b),
        ValueClass::Signed(b) => (true, b),
        _ => return None,
    };
    let (lo, hi) = if signed {
        (-(1i128 << (bits - 1)), (1i128 << (bits - 1)) - 1)
    } else {
        (0, (1i128 << bits) - 1)
    };
    if v < lo || v > hi {
        return None;
    }
    Some(v.to_le_bytes().get(..bits.div_ceil(8) as usize)?.to_vec())
}

fn limits<B: Bus>(
    s: &mut Session<'_, B>,
    values: &[(Entry<'_>, Result<Vec<u8>, SdoFail>)],
) -> Outcome
where
    B::Error: Display,
{
    let node = s.node.get();
    let mut problems = Vec::new();
    let mut checked = 0;
    for ((index, sub, so), r) in values {
        if !so.access.writable() {
            continue;
        }
        let prev = match r {
            Ok(b) => Some(b.clone()),
            Err(_) => s.default_bytes(so),
        };
        let high = so.high_limit.as_ref().and_then(|l| l.value.as_i128(node));
        let low = so.low_limit.as_ref().and_then(|l| l.value.as_i128(node));
        for (limit, step, want, what) in
            [(high, 1, 0x0609_0031, "HighLimit + 1"), (low, -1, 0x0609_0032, "LowLimit - 1")]
        {
            let Some(bytes) = limit.and_then(|l| int_bytes(so, l + step)) else { continue };
            checked += 1;
            // A PDO mapping's count past its limit may also be "too long" (CiA 301 7.5.2.36).
            let mapping = matches!(index, 0x1600..=0x17FF | 0x1A00..=0x1BFF) && *sub == 0;
            match s.write(*index, *sub, &bytes) {
                Err(SdoFail::Abort(c))
                    if c == want || c == 0x0609_0030 || (mapping && c == 0x0604_0042) => {}
                Err(e) => problems.push(format!("{} {what}: {e}", name(*index, *sub))),
                Ok(()) => {
                    problems.push(format!("{} {what}: accepted", name(*index, *sub)));
                    if let Some(p) = &prev {
                        let _ = s.write(*index, *sub, p);
                    }
                }
            }
        }
    }
    Outcome::from_problems(&problems, checked, "limits")
}

/// A value of the entry's type other than its default, within its limits.
fn changed(s: &Session<'_, impl Bus>, so: &SubObject) -> Option<Vec<u8>> {
    let node = s.node.get();
    let d = so.initial_value()?.value.as_i128(node)?;
    let high = so.high_limit.as_ref().and_then(|l| l.value.as_i128(node));
    let low = so.low_limit.as_ref().and_then(|l| l.value.as_i128(node));
    [d + 1, d - 1]
        .into_iter()
        .filter(|v| high.is_none_or(|h| *v <= h) && low.is_none_or(|l| *v >= l))
        .find_map(|v| int_bytes(so, v))
}

/// Whether an entry is one the reset checks compare: read-write with a value in the file.
fn compared(s: &Session<'_, impl Bus>, so: &SubObject) -> bool {
    matches!(so.access, Access::Rw | Access::Rwr | Access::Rww) && s.default_bytes(so).is_some()
}

/// Changes a sample of entries, resets, and compares every read-write entry with its
/// default (for reset communication: the communication area; the application entries
/// changed must keep their values). What still differs afterwards is written back.
fn reset_defaults<B: Bus>(s: &mut Session<'_, B>, reset: NmtCommand) -> Outcome
where
    B::Error: Display,
{
    let comm_only = reset == NmtCommand::ResetCommunication;
    let entries = all(s);
    // The sample: parameters of the application area (not process data: nothing a PDO maps,
    // so no controlword), and the heartbeat consumer entries 0x1016 of the communication area,
    // whose value plus one names node 0 and so watches nobody (CiA 301 7.5.2.14).
    let mut written: Vec<(Entry<'_>, Vec<u8>, Vec<u8>)> = Vec::new();
    let sample = entries
        .iter()
        .copied()
        .filter(|(i, sub, so)| {
            let parameter = (0x2000..=0x9FFF).contains(i) && !so.pdo_mapping.is_mappable();
            (parameter || (*i == 0x1016 && *sub > 0)) && compared(s, so)
        })
        .take(RESET_SAMPLE)
        .collect::<Vec<_>>();
    for e @ (index, sub, so) in sample {
        let Some(new) = changed(s, so) else { continue };
        let Ok(old) = s.read(index, sub) else { continue };
        if s.write(index, sub, &new).is_ok() {
            written.push((e, old, new));
        }
    }
    if let Err(e) = s.reset(reset) {
        restore(s, &written);
        return Outcome::fail(e);
    }
    let mut problems = Vec::new();
    let mut checked = 0;
    for (index, sub, so) in entries {
        let kept = comm_only && !(0x1000..=0x1FFF).contains(&index);
        if !compared(s, so)
            || (kept && !written.iter().any(|((i, b, _), ..)| (*i, *b) == (index, sub)))
        {
            continue;
        }
        let want = if kept {
            written.iter().find(|((i, b, _), ..)| (*i, *b) == (index, sub)).map(|w| w.2.clone())
        } else {
            s.default_bytes(so)
        };
        let Some(want) = want else { continue };
        checked += 1;
        match s.read(index, sub) {
            Ok(got) if got == want => {}
            Ok(got) => problems.push(format!(
                "{} is {:02X?}, {} {want:02X?}",
                name(index, sub),
                got,
                if kept { "was written as" } else { "the file's default is" }
            )),
            Err(e) => problems.push(format!("{}: {e}", name(index, sub))),
        }
    }
    restore(s, &written);
    let n = written.len();
    let out = Outcome::from_problems(&problems, checked, "read-write entries with a default");
    match out {
        Outcome::Pass { detail } => Outcome::pass(format!("{detail} ({n} changed before)")),
        Outcome::Fail { reason, frames } => Outcome::Fail {
            reason: format!(
                "{reason} ({n} changed before; a device with saved parameters shows those)"
            ),
            frames,
        },
        na => na,
    }
}

/// Writes back what the device holds that differs from what it held before the check.
fn restore<B: Bus>(s: &mut Session<'_, B>, written: &[(Entry<'_>, Vec<u8>, Vec<u8>)])
where
    B::Error: Display,
{
    for ((index, sub, _), old, _) in written {
        if s.read(*index, *sub).as_ref() != Ok(old) {
            let _ = s.write(*index, *sub, old);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use odc_model::DataType;

    fn sub(dt: DataType) -> SubObject {
        SubObject::new(0, "x", dt, Access::Rw)
    }

    #[test]
    fn integers_in_the_bytes_of_their_type() {
        assert_eq!(int_bytes(&sub(DataType::Unsigned8), 255), Some(vec![0xFF]));
        assert_eq!(int_bytes(&sub(DataType::Unsigned8), 256), None, "past UNSIGNED8");
        assert_eq!(int_bytes(&sub(DataType::Unsigned8), -1), None);
        assert_eq!(int_bytes(&sub(DataType::Integer16), -2), Some(vec![0xFE, 0xFF]));
        assert_eq!(int_bytes(&sub(DataType::Integer16), 32768), None);
        assert_eq!(int_bytes(&sub(DataType::Unsigned24), 0x12_3456), Some(vec![0x56, 0x34, 0x12]));
        assert_eq!(int_bytes(&sub(DataType::VisibleString), 1), None, "not a number");
    }
}
