//! NMT and error control (CiA 301 7.2.8): boot-up after the resets, SDO in every state but
//! stopped, PDOs only in operational, the heartbeat period, node guarding and life guarding.

use std::fmt::Display;

use odc::nmt::NmtCommand;
use odc::transport::Bus;

use crate::session::{Session, le};
use crate::{Group, Outcome};

/// The heartbeat period and guard time the checks set, in ms.
const PERIOD_MS: u64 = 100;
/// The life time factor the guarding check sets.
const LIFE_TIME_FACTOR: u8 = 3;

/// The valid TPDOs of the device: their CAN-IDs, and whether one sends within 300 ms of
/// operational with a SYNC every 50 ms.
pub(crate) fn tpdos<B: Bus>(s: &mut Session<'_, B>) -> (Vec<u32>, bool)
where
    B::Error: Display,
{
    let mut ids = Vec::new();
    let mut sends = false;
    for i in 0..512u16 {
        let comm = 0x1800 + i;
        if s.sub(comm, 1).is_none() {
            continue;
        }
        let Ok(cob) = s.read_u32(comm, 1) else { continue };
        if cob & 0x8000_0000 != 0 {
            continue;
        }
        ids.push(cob & 0x7FF);
        let map = 0x1A00 + i;
        let mapped = s.read(map, 0).ok().and_then(|b| b.first().copied()).unwrap_or(0);
        let ty = s.read(comm, 2).ok().and_then(|b| b.first().copied()).unwrap_or(255);
        let timer = if s.sub(comm, 5).is_some() { s.read_u32(comm, 5).unwrap_or(0) } else { 0 };
        // Within the 300 ms of operational (6 SYNCs): cyclic every 1-5 SYNCs, or an event
        // timer of at most 250 ms. Acyclic (0) and RTR-only types send on an event only.
        sends |= mapped > 0 && ((1..=5).contains(&ty) || (ty >= 254 && (1..=250).contains(&timer)));
    }
    (ids, sends)
}

pub(crate) fn run<B: Bus>(s: &mut Session<'_, B>)
where
    B::Error: Display,
{
    s.check(
        "nmt.boot-up",
        Group::Nmt,
        "CiA 301 7.2.8.3.3, 7.3.2.2.1",
        "reset node and reset communication each end in a boot-up message",
        |s| {
            for c in [NmtCommand::ResetNode, NmtCommand::ResetCommunication] {
                if let Err(e) = s.reset(c) {
                    return Outcome::fail(e);
                }
            }
            Outcome::pass("two boot-ups")
        },
    );
    s.check(
        "nmt.sdo-states",
        Group::Nmt,
        "CiA 301 7.3.2.2.2 (Table 51)",
        "SDO is served in pre-operational and operational, not in stopped",
        |s| {
            let mut problems = Vec::new();
            for (c, served) in [
                (None, true),
                (Some(NmtCommand::Start), true),
                (Some(NmtCommand::Stop), false),
                (Some(NmtCommand::EnterPreOperational), true),
            ] {
                if let Some(c) = c
                    && let Err(e) = s.nmt(c)
                {
                    return Outcome::fail(e);
                }
                let state = c.map_or("pre-operational".into(), |c| format!("after {c:?}"));
                match (s.read(0x1000, 0), served) {
                    (Ok(_), true) => {}
                    (Err(crate::session::SdoFail::Timeout), false) => {}
                    (Ok(_), false) => problems.push(format!("{state}: SDO answered")),
                    (Err(e), _) => problems.push(format!("{state}: {e}")),
                }
            }
            if problems.is_empty() {
                Outcome::pass("served in pre-operational and operational, silent in stopped")
            } else {
                Outcome::fail(problems.join("; "))
            }
        },
    );
    s.check(
        "nmt.pdo-states",
        Group::Nmt,
        "CiA 301 7.3.2.2.2 (Table 51)",
        "PDOs only in operational (SYNC every 50 ms, counted from 100 ms after each NMT command)",
        |s| {
            let (ids, sends) = tpdos(s);
            if ids.is_empty() {
                return Outcome::na("no valid TPDO");
            }
            let mut problems = Vec::new();
            let mut seen_operational = 0;
            for (c, allowed) in [
                (NmtCommand::EnterPreOperational, false),
                (NmtCommand::Start, true),
                (NmtCommand::Stop, false),
                (NmtCommand::EnterPreOperational, false),
            ] {
                // No SYNC across the command, and 100 ms for what the node sent before it
                // (a PDO answering the last SYNC) to arrive: only then are PDOs counted.
                s.master.set_sync_period(None);
                if let Err(e) = s.nmt(c) {
                    return Outcome::fail(e);
                }
                s.listen(100);
                s.master.set_sync_period(Some(odc::time::Duration::from_millis(50)));
                let pdos =
                    s.listen(300).iter().filter(|(_, f)| ids.iter().any(|i| f.is_data(*i))).count();
                if allowed {
                    seen_operational = pdos;
                } else if pdos > 0 {
                    problems.push(format!("{pdos} PDOs after {c:?}"));
                }
            }
            s.master.set_sync_period(None);
            if sends && seen_operational == 0 {
                problems.push("no PDO in operational (a TPDO sends on SYNC or a timer)".into());
            }
            if problems.is_empty() {
                Outcome::pass(format!(
                    "{seen_operational} PDOs in 300 ms of operational, none else"
                ))
            } else {
                Outcome::fail(problems.join("; "))
            }
        },
    );
    s.check(
        "nmt.heartbeat",
        Group::Nmt,
        "CiA 301 7.2.8.3.2, 7.5.2.34",
        "0x1017 = 100 ms gives a heartbeat every 100 ms (within the tolerance), state 0x7F",
        |s| {
            let Some(so) = s.sub(0x1017, 0) else {
                return Outcome::na("the file has no 0x1017");
            };
            if !so.access.writable() {
                return Outcome::na("0x1017 is not writable in the file");
            }
            let old = match s.read(0x1017, 0) {
                Ok(v) => v,
                Err(e) => return Outcome::fail(format!("0x1017: {e}")),
            };
            if let Err(e) = s.write(0x1017, 0, &(PERIOD_MS as u16).to_le_bytes()) {
                return Outcome::fail(format!("0x1017 = {PERIOD_MS}: {e}"));
            }
            let id = s.node.error_control().raw();
            let beats: Vec<(u64, Vec<u8>)> = s
                .listen(1050)
                .into_iter()
                .filter(|(_, f)| f.is_data(id))
                .map(|(t, f)| (t, f.bytes().to_vec()))
                .collect();
            let _ = s.write(0x1017, 0, &old);
            let tol = s.opt.timing_tolerance_ms;
            let gaps: Vec<u64> = beats.windows(2).map(|w| w[1].0 - w[0].0).collect();
            let bad_gap = gaps.iter().find(|g| g.abs_diff(PERIOD_MS) > tol);
            let bad_state = beats.iter().find(|(_, b)| b.as_slice() != [0x7F]);
            if beats.len() < 9 || beats.len() > 11 {
                Outcome::fail(format!("{} heartbeats in 1050 ms, not 9-11", beats.len()))
            } else if let Some(g) = bad_gap {
                Outcome::fail(format!("a gap of {g} ms (tolerance {PERIOD_MS} ± {tol} ms)"))
            } else if let Some((_, b)) = bad_state {
                Outcome::fail(format!("a heartbeat {b:02X?}, not [7F] in pre-operational"))
            } else {
                let (lo, hi) = (gaps.iter().min(), gaps.iter().max());
                Outcome::pass(format!(
                    "{} heartbeats, gaps {}-{} ms",
                    beats.len(),
                    lo.unwrap_or(&0),
                    hi.unwrap_or(&0)
                ))
            }
        },
    );
    // Guarding sets 0x100C/0x100D (and 0x1017 = 0); life guarding goes on from there and
    // restores them.
    let mut saved: Option<Vec<(u16, Vec<u8>)>> = None;
    s.check(
        "nmt.guarding",
        Group::Nmt,
        "CiA 301 7.2.8.3.1",
        "node guarding at 100 ms: an answer to every request, state 0x7F, the toggle bit \
         alternating from the master's guarding service",
        |s| {
            for i in [0x100C, 0x100D] {
                match s.sub(i, 0) {
                    None => return Outcome::na(format!("the file has no 0x{i:04X}")),
                    Some(so) if !so.access.writable() => {
                        return Outcome::na(format!("0x{i:04X} is not writable in the file"));
                    }
                    Some(_) => {}
                }
            }
            let mut old = Vec::new();
            for i in [0x100C, 0x100D, 0x1017] {
                if s.sub(i, 0).is_some()
                    && let Ok(v) = s.read(i, 0)
                {
                    old.push((i, v));
                }
            }
            saved = Some(old);
            let writes: [(u16, Vec<u8>); 3] = [
                (0x1017, 0u16.to_le_bytes().to_vec()),
                (0x100C, (PERIOD_MS as u16).to_le_bytes().to_vec()),
                (0x100D, vec![LIFE_TIME_FACTOR]),
            ];
            for (i, v) in writes {
                if (i != 0x1017 || s.sub(i, 0).is_some())
                    && let Err(e) = s.write(i, 0, &v)
                {
                    return Outcome::fail(format!("0x{i:04X}: {e}"));
                }
            }
            let node = s.node;
            if let Err(e) =
                s.master.guard(node, odc::time::Duration::from_millis(PERIOD_MS), LIFE_TIME_FACTOR)
            {
                return Outcome::fail(e.to_string());
            }
            s.listen(1050);
            let Some(st) = s.master.guarding(node) else {
                return Outcome::fail("the master's guarding went away");
            };
            if st.answers + 1 < st.requests || st.toggle_errors > 0 || st.lost {
                Outcome::fail(format!(
                    "{} requests, {} answers, {} toggle errors{}",
                    st.requests,
                    st.answers,
                    st.toggle_errors,
                    if st.lost { ", lost" } else { "" }
                ))
            } else if st.state != Some(odc::nmt::NmtState::PreOperational) {
                Outcome::fail(format!("answers report {:?}, not pre-operational", st.state))
            } else {
                Outcome::pass(format!("{} requests, {} answers", st.requests, st.answers))
            }
        },
    );
    s.check(
        "nmt.life-guarding",
        Group::Nmt,
        "CiA 301 7.2.8.3.1, 7.2.7.1 (EMCY 0x8130)",
        "when the guarding stops, the node reports the life-guarding loss (EMCY 0x8130) within \
         guard time × life time factor",
        |s| {
            let Some(old) = saved.take() else {
                return Outcome::na("node guarding was not set up (see nmt.guarding)");
            };
            let node = s.node;
            if s.sub(0x1014, 0).is_none() {
                // Guarding stops here all the same; the values of before come back.
                s.master.unguard(node);
                for (i, v) in old {
                    let _ = s.write(i, 0, &v);
                }
                return Outcome::na("the file has no 0x1014: the node sends no EMCY");
            }
            let emcy = s.emcy_id();
            s.master.unguard(node);
            let life = PERIOD_MS * u64::from(LIFE_TIME_FACTOR);
            let frames = s.listen(life + 300);
            let loss = frames
                .iter()
                .find(|(_, f)| f.is_data(emcy) && le(f.bytes().get(..2).unwrap_or(&[])) == 0x8130);
            // One more request clears the loss; then the values of before.
            let _ =
                s.master.guard(node, odc::time::Duration::from_millis(PERIOD_MS), LIFE_TIME_FACTOR);
            s.listen(PERIOD_MS / 2);
            s.master.unguard(node);
            for (i, v) in old {
                let _ = s.write(i, 0, &v);
            }
            match loss {
                Some((t, _)) => Outcome::pass(format!("EMCY 0x8130 at {t} ms")),
                None => Outcome::fail(format!("no EMCY 0x8130 within {} ms", life + 300)),
            }
        },
    );
}
