//! Emergency messages (CiA 301 7.2.7, 7.5.2.8, 7.5.2.29): the EMCY COB-ID, the error history
//! 0x1003, and an EMCY's layout (raised by an RPDO shorter than its mapping, 0x8210).

use std::fmt::Display;

use odc::nmt::NmtCommand;
use odc::transport::Bus;

use crate::session::{SdoFail, Session, le};
use crate::{Group, Outcome};

pub(crate) fn run<B: Bus>(s: &mut Session<'_, B>)
where
    B::Error: Display,
{
    s.check(
        "emcy.cob-id",
        Group::Emcy,
        "CiA 301 7.5.2.29",
        "0x1014 is valid and the file's (by default 0x80 + node-ID, the pre-defined connection set)",
        |s| {
            let Some(so) = s.sub(0x1014, 0) else {
                return Outcome::na("the file has no 0x1014");
            };
            let want = s
                .default_bytes(so)
                .map_or(s.node.emcy().raw(), |b| crate::session::le(&b) as u32);
            match s.read_u32(0x1014, 0) {
                Ok(v) if v == want => Outcome::pass(format!("0x{v:08X}")),
                Ok(v) => Outcome::fail(format!("0x1014 is 0x{v:08X}, not 0x{want:08X}")),
                Err(e) => Outcome::fail(format!("0x1014: {e}")),
            }
        },
    );
    s.check(
        "emcy.history",
        Group::Emcy,
        "CiA 301 7.5.2.8",
        "0x1003:00 counts the errors; writing 0 clears them, another value is refused \
         (0x06090030)",
        |s| {
            let Some(so) = s.sub(0x1003, 0) else {
                return Outcome::na("the file has no 0x1003");
            };
            if !so.access.writable() {
                return Outcome::na("0x1003:00 is not writable in the file");
            }
            let mut problems = Vec::new();
            if let Err(e) = s.write(0x1003, 0, &[0]) {
                problems.push(format!("0x1003:00 = 0: {e}"));
            }
            match s.read(0x1003, 0) {
                Ok(v) if v == [0] => {}
                Ok(v) => problems.push(format!("0x1003:00 reads {v:02X?} after clearing")),
                Err(e) => problems.push(format!("0x1003:00: {e}")),
            }
            match s.write(0x1003, 0, &[1]) {
                Err(SdoFail::Abort(0x0609_0030)) => {}
                Err(e) => problems.push(format!("0x1003:00 = 1: {e}, not 0x06090030")),
                Ok(()) => problems.push("0x1003:00 = 1 accepted".into()),
            }
            if problems.is_empty() {
                Outcome::pass("cleared by 0, 1 refused")
            } else {
                Outcome::fail(problems.join("; "))
            }
        },
    );
    s.check(
        "emcy.layout",
        Group::Emcy,
        "CiA 301 7.2.7.3.1, 7.2.2.2 (0x8210)",
        "an RPDO one byte short raises an 8-byte EMCY 0x8210 whose register is 0x1001 (generic \
         and communication bits) and whose code 0x1003:01 records",
        |s| layout(s),
    );
}

/// The first valid RPDO that maps at least one byte: its CAN-ID and length in bytes.
fn rpdo<B: Bus>(s: &mut Session<'_, B>) -> Option<(u32, usize)>
where
    B::Error: Display,
{
    for i in 0..512u16 {
        let (comm, map) = (0x1400 + i, 0x1600 + i);
        if s.sub(comm, 1).is_none() || s.sub(map, 0).is_none() {
            continue;
        }
        let Ok(cob) = s.read_u32(comm, 1) else { continue };
        if cob & 0x8000_0000 != 0 {
            continue;
        }
        let count = s.read(map, 0).ok().and_then(|b| b.first().copied()).unwrap_or(0);
        let bits: u32 = (1..=count).filter_map(|k| s.read_u32(map, k).ok()).map(|e| e & 0xFF).sum();
        if bits >= 8 {
            return Some((cob & 0x7FF, bits.div_ceil(8) as usize));
        }
    }
    None
}

fn layout<B: Bus>(s: &mut Session<'_, B>) -> Outcome
where
    B::Error: Display,
{
    let Some((id, len)) = rpdo(s) else {
        return Outcome::na("no valid RPDO that maps a byte or more");
    };
    // Read before the RPDO: frames that come during an SDO transfer are not in `listen`'s.
    let emcy_id = s.emcy_id();
    let _ = s.nmt(NmtCommand::Start);
    s.listen(30);
    let short = vec![0u8; len - 1];
    if let Err(e) = s.send(id, &short) {
        return Outcome::fail(e);
    }
    let frames = s.listen(300);
    let _ = s.nmt(NmtCommand::EnterPreOperational);
    let Some((_, f)) = frames.iter().find(|(_, f)| f.is_data(emcy_id)) else {
        return Outcome::na(format!(
            "no EMCY after an RPDO of {} bytes on 0x{id:03X} (mapped {len}): CiA 301 leaves \
             that EMCY optional, so there is none to check",
            len - 1
        ));
    };
    let b = f.bytes().to_vec();
    let mut problems = Vec::new();
    if b.len() != 8 {
        problems.push(format!("{} bytes, not 8", b.len()));
    }
    let code = le(b.get(..2).unwrap_or(&[]));
    let register = b.get(2).copied().unwrap_or(0);
    if code != 0x8210 {
        problems.push(format!("code 0x{code:04X}, not 0x8210"));
    }
    if register & 0x11 != 0x11 {
        problems.push(format!(
            "register 0x{register:02X}: generic (bit 0) and communication (bit 4) wanted"
        ));
    }
    match s.read(0x1001, 0) {
        Ok(r) if r == [register] => {}
        Ok(r) => problems.push(format!("0x1001 reads {r:02X?}, the EMCY said 0x{register:02X}")),
        Err(e) => problems.push(format!("0x1001: {e}")),
    }
    if s.sub(0x1003, 1).is_some() {
        match s.read_u32(0x1003, 1) {
            Ok(v) if u64::from(v & 0xFFFF) == code => {}
            Ok(v) => problems.push(format!("0x1003:01 is 0x{v:08X}, the EMCY code 0x{code:04X}")),
            Err(e) => problems.push(format!("0x1003:01: {e}")),
        }
        let _ = s.write(0x1003, 0, &[0]);
    }
    if problems.is_empty() {
        Outcome::pass(format!("EMCY {b:02X?}"))
    } else {
        Outcome::fail(problems.join("; "))
    }
}
