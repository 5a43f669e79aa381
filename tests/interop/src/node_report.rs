//! What `python/node.py` reports of an odc node, and the checks of that report: shared by the
//! test that runs `odc::node::Node` itself (`tests/it/node.rs`) and the one that runs it in
//! `odc simulate` (`crates/odc-cli/tests/simulate.rs`), where only the bus is seen.

use odc::node::Events;
use serde_json::Value;

/// What the node reported to the application during a session.
#[derive(Debug, Default)]
pub struct Seen {
    /// Reset events.
    pub resets: usize,
    /// Life-guarding losses.
    pub life_guarding_lost: usize,
    /// RPDOs written.
    pub rpdos: usize,
    /// PDO errors.
    pub pdo_errors: Vec<String>,
}

impl Seen {
    /// Counts what one call of the node returned.
    pub fn note(&mut self, ev: &Events) {
        self.resets += usize::from(ev.reset.is_some());
        self.life_guarding_lost += usize::from(ev.life_guarding_lost);
        self.rpdos += ev.rpdo.count_ones() as usize;
        if let Some(e) = ev.pdo_error {
            self.pdo_errors.push(format!("{e:?}"));
        }
    }
}

/// A report's number; -1 when it is none.
pub fn int(v: &Value) -> i64 {
    v.as_i64().unwrap_or(-1)
}

/// Checks one device's report (and what the node told its application, where the test runs
/// the node itself); the failures, as text.
pub fn check(r: &Value, seen: Option<&Seen>) -> Vec<String> {
    let mut bad = Vec::new();
    let mut want = |ok: bool, what: String| {
        if !ok {
            bad.push(what);
        }
    };
    for e in r["errors"].as_array().into_iter().flatten() {
        want(false, format!("python: {e}"));
    }
    if let Some(seen) = seen {
        want(seen.pdo_errors.is_empty(), format!("node PDO errors {:?}", seen.pdo_errors));
    }
    // NMT.
    want(int(&r["bootups"]) == 2, format!("boot-ups after the two resets: {}", r["bootups"]));
    for (k, v) in
        [("sdo_preop", true), ("sdo_stopped", false), ("sdo_op", true), ("sdo_preop_again", true)]
    {
        want(r[k] == v, format!("{k} = {}", r[k]));
    }
    want(int(&r["tpdo_preop"]) == 0, format!("TPDOs in pre-operational: {}", r["tpdo_preop"]));
    // A file that flags no object PDOMapping=1 (Lenze E94AYCCA): CiA 301 has the node refuse
    // every mapping entry (0x06040041), so there is no PDO, and no short-RPDO EMCY, to test.
    if r["tpdo_mappable_in_eds"] == false {
        want(
            r["unflagged_mapping_refused"] == true,
            format!("mapping an unflagged object: refused {}", r["unflagged_mapping_refused"]),
        );
        bad.extend(guarding(r, seen));
        return bad;
    }
    // Heartbeat 100 ms over SDO, counted for 1.02 s.
    let hb = int(&r["heartbeat_preop"]);
    want((9..=11).contains(&hb), format!("heartbeats in 1.02 s at 100 ms: {hb}"));
    let period = int(&r["heartbeat_period_ms"]);
    want((90..=110).contains(&period), format!("heartbeat period {period} ms"));
    want(
        r["heartbeat_states_preop"] == serde_json::json!([0x7F]),
        format!("pre-op states {}", r["heartbeat_states_preop"]),
    );
    want(
        r["heartbeat_states_op"] == serde_json::json!([0x05]),
        format!("op states {}", r["heartbeat_states_op"]),
    );
    want(r["python_state_op"] == "OPERATIONAL", format!("python's state {}", r["python_state_op"]));
    // TPDO types.
    want(
        int(&r["type1_per_10_syncs"]) == 10,
        format!("type 1: {} per 10 SYNCs", r["type1_per_10_syncs"]),
    );
    want(
        int(&r["type5_per_20_syncs"]) == 4,
        format!("type 5: {} per 20 SYNCs", r["type5_per_20_syncs"]),
    );
    // A file without 0x1800:05 (maxon EPOS4) has no event timer to set.
    if r["event_timer"] != false {
        let ev = int(&r["type254_50ms_per_second"]);
        want((18..=22).contains(&ev), format!("type 254, 50 ms: {ev} per second"));
    }
    let lengths: Vec<i64> = r["remap_lengths"].as_array().into_iter().flatten().map(int).collect();
    want(lengths.len() == 2 && lengths[0] < lengths[1], format!("remap lengths {lengths:?}"));
    want(
        r["remap_content_ok"]
            .as_array()
            .is_some_and(|a| a.len() == 2 && a.iter().all(|v| v == true)),
        format!("remap content {}", r["remap_content_ok"]),
    );
    // RPDO and EMCY.
    want(
        r["rpdo_written"] == true,
        format!("RPDO into {}: {}", r["rpdo_object"], r["rpdo_written"]),
    );
    want(int(&r["emcy"]["code"]) == 0x8210, format!("EMCY {}", r["emcy"]));
    // Error register: generic (bit 0) and communication (bit 4), CiA 301 7.5.2.2.
    want(int(&r["emcy"]["register"]) & 0x11 == 0x11, format!("EMCY register {}", r["emcy"]));
    if let Some(h) = r["history_0x1003"].as_array() {
        want(
            h.len() == 2 && int(&h[0]) >= 1 && int(&h[1]) & 0xFFFF == 0x8210,
            format!("0x1003 {h:?}"),
        );
        want(r["history_cleared"] == true, "0x1003:0 = 0 did not clear".into());
    }
    bad.extend(guarding(r, seen));
    bad
}

/// Node guarding at 100 ms for 1.02 s, in pre-operational; the failures.
fn guarding(r: &Value, seen: Option<&Seen>) -> Vec<String> {
    let mut bad = Vec::new();
    let mut want = |ok: bool, what: String| {
        if !ok {
            bad.push(what);
        }
    };
    let g = int(&r["guarding_answers"]);
    want((9..=11).contains(&g), format!("guarding answers {g}"));
    want(
        r["guarding_states"] == serde_json::json!([0x7F]),
        format!("guarding states {}", r["guarding_states"]),
    );
    want(r["guarding_toggles_ok"] == true, "guarding toggle did not alternate".into());
    want(
        r["python_state_guarded"] == "PRE-OPERATIONAL",
        format!("python's state {}", r["python_state_guarded"]),
    );
    if r["life_guarding"] == true
        && let Some(seen) = seen
    {
        want(
            seen.life_guarding_lost == 1,
            format!("life-guarding losses {}", seen.life_guarding_lost),
        );
    }
    bad
}
