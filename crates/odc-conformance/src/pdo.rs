//! PDOs (CiA 301 7.2.2, 7.5.2.35-38): the mapping rules, writing a mapping while the PDO is
//! valid, the transmission types, the event timer, the inhibit time, and the SYNC counter with a
//! TPDO's start value. The TPDO tested is the first one whose
//! COB-ID and mapping the file makes writable; everything is written back.

use std::fmt::Display;

use odc::nmt::NmtCommand;
use odc::transport::Bus;
use odc_model::{Direction, SubObject};

use crate::session::{SdoFail, Session, le};
use crate::{Group, Outcome};

/// A TPDO and what it held before the checks.
struct Tpdo {
    comm: u16,
    map: u16,
    cob: u32,
    count: u8,
    entries: Vec<Vec<u8>>,
}

/// The first TPDO whose COB-ID and mapping count the file makes writable, read from the
/// device.
fn find<B: Bus>(s: &mut Session<'_, B>) -> Option<Tpdo>
where
    B::Error: Display,
{
    for i in 0..512u16 {
        let (comm, map) = (0x1800 + i, 0x1A00 + i);
        let writable = |s: &Session<'_, B>, index, sub| {
            s.sub(index, sub).is_some_and(|so: &SubObject| so.access.writable())
        };
        if !writable(s, comm, 1) || !writable(s, map, 0) {
            continue;
        }
        let Ok(cob) = s.read_u32(comm, 1) else { continue };
        let Ok(count) = s.read(map, 0) else { continue };
        let count = count.first().copied().unwrap_or(0);
        let entries = (1..=count).filter_map(|k| s.read(map, k).ok()).collect();
        return Some(Tpdo { comm, map, cob, count, entries });
    }
    None
}

/// Writes a TPDO back as it was: invalid, mapping, count, COB-ID.
fn restore<B: Bus>(s: &mut Session<'_, B>, t: &Tpdo)
where
    B::Error: Display,
{
    let _ = s.write(t.comm, 1, &(t.cob | 0x8000_0000).to_le_bytes());
    let _ = s.write(t.map, 0, &[0]);
    for (k, e) in (1u8..).zip(&t.entries) {
        let _ = s.write(t.map, k, e);
    }
    let _ = s.write(t.map, 0, &[t.count]);
    let _ = s.write(t.comm, 1, &t.cob.to_le_bytes());
}

/// Whether the device is a SYNC producer (0x1005 bit 30, CiA 301 7.5.2.5).
fn producer<B: Bus>(s: &mut Session<'_, B>) -> bool
where
    B::Error: Display,
{
    s.sub(0x1005, 0).is_some() && s.read_u32(0x1005, 0).is_ok_and(|v| v & 0x4000_0000 != 0)
}

fn entry(index: u16, sub: u8, bits: u32) -> [u8; 4] {
    (u32::from(index) << 16 | u32::from(sub) << 8 | (bits & 0xFF)).to_le_bytes()
}

fn expect(r: Result<(), SdoFail>, want: u32, what: &str, problems: &mut Vec<String>) {
    match r {
        Err(SdoFail::Abort(c)) if c == want => {}
        Err(e) => problems.push(format!("{what}: {e}, not 0x{want:08X}")),
        Ok(()) => problems.push(format!("{what}: accepted, not 0x{want:08X}")),
    }
}

pub(crate) fn run<B: Bus>(s: &mut Session<'_, B>)
where
    B::Error: Display,
{
    let tpdo = find(s);
    let none = "no TPDO whose COB-ID and mapping the file makes writable";
    s.check(
        "pdo.mapping-rules",
        Group::Pdo,
        "CiA 301 7.5.2.36 (0x06020000, 0x06040041, 0x06040042)",
        "a mapping that names a missing object, an object not mappable, or more than 64 bits is \
         refused",
        |s| {
            let Some(t) = &tpdo else { return Outcome::na(none) };
            let (comm, map) = (t.comm, t.map);
            if let Err(e) = s.write(comm, 1, &(t.cob | 0x8000_0000).to_le_bytes()) {
                return Outcome::fail(format!("0x{comm:04X}:01 invalid: {e}"));
            }
            if let Err(e) = s.write(map, 0, &[0]) {
                restore(s, t);
                return Outcome::fail(format!("0x{map:04X}:00 = 0: {e}"));
            }
            let mut problems = Vec::new();
            let mut skipped = Vec::new();
            let missing = (0x2000..=0x5FFFu16).find(|i| !s.dev.objects.contains_key(i));
            if let Some(i) = missing {
                let r = s.write(map, 1, &entry(i, 0, 8));
                expect(r, 0x0602_0000, &format!("0x{i:04X} (not in the file)"), &mut problems);
            }
            let not_mappable = s
                .dev
                .objects
                .values()
                .flat_map(|o| o.subs.values().map(move |so| (o.index, so)))
                .find(|(_, so)| {
                    so.access.readable()
                        && so.data_type.bit_size().is_some()
                        && !so.pdo_mapping.allows(so.access, Direction::Tx)
                });
            match not_mappable {
                Some((i, so)) => {
                    let bits = so.data_type.bit_size().unwrap_or(8);
                    let r = s.write(map, 1, &entry(i, so.sub_index, bits));
                    let what = format!("0x{i:04X}:{:02X} (not mappable)", so.sub_index);
                    expect(r, 0x0604_0041, &what, &mut problems);
                }
                None => skipped.push("no entry that is not mappable"),
            }
            // Too long: the widest mappable entry, as often as it takes to pass 64 bits.
            let subs = s.dev.objects.get(&map).map_or(0, |o| o.subs.len().saturating_sub(1));
            let widest = s
                .dev
                .objects
                .values()
                .flat_map(|o| o.subs.values().map(move |so| (o.index, so)))
                .filter(|(_, so)| so.pdo_mapping.allows(so.access, Direction::Tx))
                .filter_map(|(i, so)| Some((i, so.sub_index, so.data_type.bit_size()?)))
                .filter(|(_, _, b)| (8..=64).contains(b))
                .max_by_key(|(_, _, b)| *b);
            match widest {
                Some((i, sub, bits)) if (64 / bits + 1) as usize <= subs => {
                    let n = (64 / bits + 1) as u8;
                    let mut refused = false;
                    for k in 1..=n {
                        match s.write(map, k, &entry(i, sub, bits)) {
                            Err(SdoFail::Abort(0x0604_0042)) => {
                                refused = true;
                                break;
                            }
                            Err(e) => {
                                problems.push(format!("0x{map:04X}:{k:02X} = 0x{i:04X}: {e}"));
                                refused = true;
                                break;
                            }
                            Ok(()) => {}
                        }
                    }
                    if !refused {
                        let what =
                            format!("{n} × 0x{i:04X}:{sub:02X} ({} bits)", u32::from(n) * bits);
                        expect(s.write(map, 0, &[n]), 0x0604_0042, &what, &mut problems);
                    }
                }
                _ => skipped.push("no mappable entry wide enough to pass 64 bits in the subs"),
            }
            restore(s, t);
            if problems.is_empty() {
                let mut d = format!("on 0x{map:04X}");
                if !skipped.is_empty() {
                    d += &format!(" ({})", skipped.join("; "));
                }
                Outcome::pass(d)
            } else {
                Outcome::fail(problems.join("; "))
            }
        },
    );
    s.check(
        "pdo.mapping-while-valid",
        Group::Pdo,
        "CiA 301 7.5.2.36",
        "a write of the mapping count while the PDO is valid (COB-ID bit 31 clear) is refused",
        |s| {
            let Some(t) = &tpdo else { return Outcome::na(none) };
            // Read again: the restore of pdo.mapping-rules fails where the device refuses the
            // COB-ID it had (a file's COB-ID 0, NMT's CAN-ID), leaving the PDO invalid.
            let cob = match s.read_u32(t.comm, 1) {
                Ok(c) => c,
                Err(e) => return Outcome::fail(format!("0x{:04X}:01: {e}", t.comm)),
            };
            if cob & 0x8000_0000 != 0 {
                return Outcome::na(format!(
                    "0x{:04X}:01 is not valid on the device (0x{cob:08X})",
                    t.comm
                ));
            }
            match s.write(t.map, 0, &[t.count]) {
                Err(SdoFail::Abort(c)) => Outcome::pass(format!("refused with 0x{c:08X}")),
                Err(e) => Outcome::fail(e.to_string()),
                Ok(()) => {
                    restore(s, t);
                    Outcome::fail(format!("0x{:04X}:00 = {} accepted while valid", t.map, t.count))
                }
            }
        },
    );
    s.check(
        "pdo.transmission-type",
        Group::Pdo,
        "CiA 301 7.2.2.2, 7.5.2.35",
        "transmission type 1 sends one PDO per SYNC; type 254 with a 100 ms event timer one \
         every 100 ms (where the file has 0x18xx:05)",
        |s| {
            let Some(t) = &tpdo else { return Outcome::na(none) };
            if t.cob & 0x8000_0000 != 0 || t.count == 0 {
                return Outcome::na(format!("0x{:04X} is not valid or maps nothing", t.comm));
            }
            let comm = t.comm;
            let Ok(old_type) = s.read(comm, 2) else {
                return Outcome::na(format!("0x{comm:04X}:02 does not read"));
            };
            if producer(s) {
                return Outcome::na(
                    "the device produces SYNC itself (0x1005 bit 30): its SYNCs and the \
                     tester's would both count",
                );
            }
            let id = t.cob & 0x7FF;
            let mut problems = Vec::new();
            let mut detail = Vec::new();
            if let Err(e) = s.write(comm, 2, &[1]) {
                return Outcome::fail(format!("0x{comm:04X}:02 = 1: {e}"));
            }
            let _ = s.nmt(NmtCommand::Start);
            s.listen(50);
            let mut n = 0;
            for _ in 0..10 {
                let _ = s.master.sync();
                n += s.listen(30).iter().filter(|(_, f)| f.is_data(id)).count();
            }
            // The answer to the last SYNC may come after its window.
            n += s.listen(100).iter().filter(|(_, f)| f.is_data(id)).count();
            if n == 10 {
                detail.push("type 1: 10 PDOs for 10 SYNCs".to_string());
            } else {
                problems.push(format!("type 1: {n} PDOs for 10 SYNCs"));
            }
            let timer = s.sub(comm, 5).is_some_and(|so| so.access.writable());
            if timer {
                let old_timer = s.read(comm, 5).unwrap_or_else(|_| vec![0, 0]);
                let _ = s.nmt(NmtCommand::EnterPreOperational);
                let set =
                    s.write(comm, 2, &[254]).and_then(|()| s.write(comm, 5, &100u16.to_le_bytes()));
                if let Err(e) = set {
                    problems.push(format!("type 254, event timer 100: {e}"));
                } else {
                    let _ = s.nmt(NmtCommand::Start);
                    // The inhibit time (0x18xx:03, 100 µs) spaces them further where longer.
                    let inhibit_ms = if s.sub(comm, 3).is_some() {
                        s.read(comm, 3).map_or(0, |b| le(&b) / 10)
                    } else {
                        0
                    };
                    let period = inhibit_ms.max(100);
                    let (lo, hi) = (1000 / period - 1, 1050 / period + 2);
                    let frames = s.listen(1050);
                    let n = frames.iter().filter(|(_, f)| f.is_data(id)).count() as u64;
                    let what =
                        format!("event timer 100 ms, inhibit {inhibit_ms} ms: {n} PDOs in 1050 ms");
                    if (lo..=hi).contains(&n) {
                        detail.push(what);
                    } else {
                        problems.push(format!("{what}, not {lo}-{hi}"));
                    }
                }
                let _ = s.nmt(NmtCommand::EnterPreOperational);
                let _ = s.write(comm, 5, &old_timer);
            }
            let _ = s.nmt(NmtCommand::EnterPreOperational);
            let _ = s.write(comm, 2, &old_type);
            if problems.is_empty() {
                Outcome::pass(format!("0x{comm:04X}: {}", detail.join("; ")))
            } else {
                Outcome::fail(format!("0x{comm:04X}: {}", problems.join("; ")))
            }
        },
    );
    s.check(
        "pdo.inhibit-time",
        Group::Pdo,
        "CiA 301 7.2.2.4, 7.5.2.35",
        "an inhibit time of 100 ms holds back a TPDO whose event timer asks for one every 20 ms",
        |s| {
            let Some(t) = &tpdo else { return Outcome::na(none) };
            let comm = t.comm;
            let writable = |s: &Session<'_, B>, sub| s.sub(comm, sub).is_some_and(|so| so.access.writable());
            if !(writable(s, 2) && writable(s, 3) && writable(s, 5)) || t.count == 0 {
                return Outcome::na(format!(
                    "0x{comm:04X} has no writable type, inhibit time and event timer, or maps nothing"
                ));
            }
            let old: Vec<(u8, Vec<u8>)> =
                [2u8, 3, 5].iter().filter_map(|&k| Some((k, s.read(comm, k).ok()?))).collect();
            let id = t.cob & 0x7FF;
            // The inhibit time may change only while the PDO is not valid (CiA 301 7.5.2.35).
            let setup = s
                .write(comm, 1, &(t.cob | 0x8000_0000).to_le_bytes())
                .and_then(|()| s.write(comm, 2, &[254]))
                .and_then(|()| s.write(comm, 3, &1000u16.to_le_bytes()))
                .and_then(|()| s.write(comm, 5, &20u16.to_le_bytes()))
                .and_then(|()| s.write(comm, 1, &(t.cob & !0x8000_0000).to_le_bytes()));
            let out = match setup {
                Err(e) => Outcome::fail(format!("setting up 0x{comm:04X}: {e}")),
                Ok(()) => {
                    let _ = s.nmt(NmtCommand::Start);
                    let times: Vec<u64> =
                        s.listen(1050).iter().filter(|(_, f)| f.is_data(id)).map(|(t, _)| *t).collect();
                    let _ = s.nmt(NmtCommand::EnterPreOperational);
                    let min_gap = times.windows(2).map(|w| w[1] - w[0]).min();
                    let tol = s.opt.timing_tolerance_ms;
                    match min_gap {
                        _ if times.len() < 5 => Outcome::fail(format!(
                            "{} PDOs in 1050 ms (event timer 20 ms, inhibit 100 ms)",
                            times.len()
                        )),
                        Some(g) if g + tol < 100 => Outcome::fail(format!(
                            "{} PDOs in 1050 ms, a gap of {g} ms under the 100 ms inhibit time \
                             (tolerance {tol} ms)",
                            times.len()
                        )),
                        g => Outcome::pass(format!(
                            "{} PDOs in 1050 ms, gaps from {} ms",
                            times.len(),
                            g.unwrap_or(0)
                        )),
                    }
                }
            };
            let _ = s.write(comm, 1, &(t.cob | 0x8000_0000).to_le_bytes());
            for (k, v) in old {
                let _ = s.write(comm, k, &v);
            }
            let _ = s.write(comm, 1, &t.cob.to_le_bytes());
            out
        },
    );
    s.check(
        "pdo.sync-start",
        Group::Pdo,
        "CiA 301 7.2.5.2, 7.5.2.22, 7.5.2.35 (SYNC counter, start value)",
        "with SYNCs counting to 10 (0x1019), a type 2 TPDO with start value 3 is sent after the \
         SYNCs counted 3, 5, 7 and 9",
        |s| {
            let Some(t) = &tpdo else { return Outcome::na(none) };
            let comm = t.comm;
            let writable = |s: &Session<'_, B>, i, sub| s.sub(i, sub).is_some_and(|so| so.access.writable());
            if !(writable(s, 0x1019, 0) && writable(s, comm, 2) && writable(s, comm, 6))
                || t.count == 0
            {
                return Outcome::na(format!(
                    "the file has no writable 0x1019 and 0x{comm:04X}:02/06, or 0x{comm:04X} maps nothing"
                ));
            }
            if producer(s) {
                return Outcome::na(
                    "the device produces SYNC itself (0x1005 bit 30): its SYNCs and the \
                     tester's would both count",
                );
            }
            let old_overflow = s.read(0x1019, 0).ok();
            let old: Vec<(u8, Vec<u8>)> =
                [2u8, 6].iter().filter_map(|&k| Some((k, s.read(comm, k).ok()?))).collect();
            let id = t.cob & 0x7FF;
            let setup = s
                .write(comm, 1, &(t.cob | 0x8000_0000).to_le_bytes())
                .and_then(|()| s.write(0x1019, 0, &[10]))
                .and_then(|()| s.write(comm, 2, &[2]))
                .and_then(|()| s.write(comm, 6, &[3]))
                .and_then(|()| s.write(comm, 1, &(t.cob & !0x8000_0000).to_le_bytes()));
            let out = match setup {
                Err(e) => Outcome::fail(format!("setting up 0x1019 and 0x{comm:04X}: {e}")),
                Ok(()) => {
                    let _ = s.master.set_sync_counter(Some(10));
                    let _ = s.nmt(NmtCommand::Start);
                    s.listen(50);
                    let mut after = Vec::new();
                    for counter in 1..=10u8 {
                        let _ = s.master.sync();
                        if s.listen(40).iter().any(|(_, f)| f.is_data(id)) {
                            after.push(counter);
                        }
                    }
                    let _ = s.nmt(NmtCommand::EnterPreOperational);
                    let _ = s.master.set_sync_counter(None);
                    if after == [3, 5, 7, 9] {
                        Outcome::pass("PDOs after the SYNCs counted 3, 5, 7, 9")
                    } else {
                        Outcome::fail(format!(
                            "PDOs after the SYNCs counted {after:?}, not [3, 5, 7, 9]"
                        ))
                    }
                }
            };
            let _ = s.write(comm, 1, &(t.cob | 0x8000_0000).to_le_bytes());
            for (k, v) in old {
                let _ = s.write(comm, k, &v);
            }
            if let Some(v) = old_overflow {
                let _ = s.write(0x1019, 0, &v);
            }
            let _ = s.write(comm, 1, &t.cob.to_le_bytes());
            out
        },
    );
}
