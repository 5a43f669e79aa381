//! The checks against odc's own node: `odc simulate`'s device (odc-sim on a virtual CAN bus
//! over TCP, in this process) for each device file of `eds/`.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::Path;

use odc::cob::NodeId;
use odc::transport::tcp::TcpCan;
use odc_conformance::{Options, Report};
use odc_sim::{SimDevice, VirtualBus};

/// Runs the checks on `file` simulated at node 5.
pub fn conformance(file: &str, options: &Options) -> Report {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(file);
    let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
    let device = loaded.device().unwrap().clone();
    let node = NodeId::new(5).unwrap();
    let bus = VirtualBus::bind("127.0.0.1:0").unwrap();
    let addr = bus.local_addr();
    let stop = bus.stop_handle();
    let served = device.clone();
    let sim = std::thread::spawn(move || {
        let mut dev = SimDevice::new(&served, node);
        bus.run(&mut dev, &mut |_| {});
    });
    let link = TcpCan::connect(addr).unwrap();
    let report = odc_conformance::run(&device, node, link, options);
    stop.stop();
    sim.join().unwrap();
    eprint!("{}", report.summary());
    report
}

#[test]
fn lxm23a() {
    let opts = Options { restore_defaults: true, ..Options::default() };
    let r = conformance("eds/lxm23a.eds", &opts);
    assert!(r.checks.len() > 20);
}
