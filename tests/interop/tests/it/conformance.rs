//! `odc conformance`'s checks against python-canopen's `LocalNode` (python/slave.py), an
//! independent and partial slave: the report must fail exactly the checks whose service
//! LocalNode does not implement (each explained in tests/interop/README.md by
//! python-canopen's code) and pass or find not applicable the rest. This shows that the
//! tester can fail, and does not fail falsely.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::Path;
use std::time::Duration;

use odc::transport::Bus as _;
use odc_conformance::{Options, Outcome};
use odc_tests_interop::{Peer, python};

/// The checks LocalNode fails, per device file; README.md says why for each.
const EXPECTED: &[(&str, &[&str])] = &[
    (
        "eds/lexium-mdrive.eds",
        &[
            "entries.limits",
            "entries.reset-application",
            "entries.reset-communication",
            "entries.save-signature",
            "entries.load-signature",
            "entries.load-defaults",
            "nmt.boot-up",
            "nmt.sdo-states",
            "nmt.pdo-states",
            "nmt.guarding",
            "nmt.life-guarding",
            "pdo.mapping-rules",
            "pdo.mapping-while-valid",
            "pdo.transmission-type",
            "pdo.inhibit-time",
            "emcy.history",
            "lss.inquire",
            "cia402.state-machine",
            "cia402.fault",
            "cia402.quick-stop",
            "cia402.modes",
        ],
    ),
    // Its TPDOs are event-driven without a timer (nmt.pdo-states has nothing to miss), and
    // the file says LSS_Supported=0 (LocalNode's silence passes).
    (
        "eds/lxm23a.eds",
        &[
            "entries.limits",
            "entries.reset-application",
            "entries.reset-communication",
            "entries.save-signature",
            "entries.load-signature",
            "entries.load-defaults",
            "nmt.boot-up",
            "nmt.sdo-states",
            "nmt.guarding",
            "nmt.life-guarding",
            "pdo.mapping-rules",
            "pdo.mapping-while-valid",
            "pdo.transmission-type",
            "pdo.inhibit-time",
            "emcy.history",
            "cia402.state-machine",
            "cia402.modes",
        ],
    ),
];

#[test]
#[cfg_attr(
    odc_interop_no_python,
    ignore = "needs python3 with canopen and python-can: set ODC_INTEROP_PYTHON (tests/interop/README.md)"
)]
fn conformance_of_python_canopen_local_node() {
    let python = python();
    let mut mismatches = Vec::new();
    for (file, expected) in EXPECTED {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(file);
        let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
        let device = loaded.device().unwrap();
        let mut peer = Peer::start(
            &python,
            "slave.py",
            &["--eds", path.to_str().unwrap(), "--node", "5", "--max-seconds", "300"],
        );
        // As a master waits for a node: LocalNode's boot-up once it serves.
        let deadline = peer.bus.now() + odc::time::Duration::from_secs(10);
        loop {
            match peer.bus.recv(deadline).unwrap() {
                Some(f) if f.is_data(0x705) && f.bytes() == [0] => break,
                Some(_) => {}
                None => panic!("{file}: no boot-up from slave.py"),
            }
        }
        let node = odc::cob::NodeId::new(5).unwrap();
        // python-can's periodic send thread keeps LocalNode's heartbeat; a loaded machine delays
        // it more than odc's node: 40 ms of tolerance instead of 20.
        let options =
            Options { restore_defaults: true, timing_tolerance_ms: 40, ..Options::default() };
        let report = odc_conformance::run(device, node, &mut peer.bus, &options);
        peer.finish(Duration::from_secs(10));
        println!("{file}:\n{}", report.summary());
        let failed = report.failed();
        if failed != *expected {
            mismatches.push(format!("{file}: failed {failed:?}, expected {expected:?}"));
        }
        let passed = report.checks.iter().filter(|c| matches!(c.outcome, Outcome::Pass { .. }));
        assert!(passed.count() >= 8, "{file}: the tester passes what LocalNode implements");
    }
    assert!(mismatches.is_empty(), "{}", mismatches.join("\n"));
}
