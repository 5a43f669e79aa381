//! The CiA 402 driver on the master runtime against the simulated drives of `odc simulate`
//! (`odc_sim::VirtualBus` serving `odc_sim::SimDevice` on a loopback TCP port, as the command
//! does), with the process data of the generated `cia402::Pdos`: enable, a profile-position
//! move, a cyclic synchronous position stream where 0x6502 allows it (refused where it does
//! not), and the whole exchange decoded by `odc monitor`'s decoder with the device file.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::Path;
use std::sync::{Arc, Mutex};

use odc::can::CanFrame;
use odc::cia402::{DrivePdos, Driver, DriverError, ModeOfOperation, SupportedModes};
use odc::master::{Error, Master, axis::Axis};
use odc::nmt::NmtCommand;
use odc::transport::tcp::TcpCan;
use odc_tests_generated::{lexium_mdrive, lxm23a};

const NODE: odc::cob::NodeId = odc::node_id!(5);

fn model(file: &str) -> odc_model::Device {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(file);
    odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap().devices.remove(0)
}

/// What a session showed: frames seen by the master, the positions reached.
struct Session {
    frames: Vec<CanFrame>,
    moved_to: i32,
    streamed_to: Option<i32>,
    csp: Result<(), DriverError>,
}

fn session<P: DrivePdos>(file: &str, plans: &[&[odc::plan::SdoWrite]], velocity: u32) -> Session {
    let device = model(file);
    let hub = odc_sim::VirtualBus::bind("127.0.0.1:0").unwrap();
    let addr = hub.local_addr();
    let stop = hub.stop_handle();
    let sim = std::thread::spawn(move || {
        let mut dev = odc_sim::SimDevice::new(&device, NODE);
        hub.run(&mut dev, &mut |_| {});
    });
    let mut m = Master::new(TcpCan::connect(addr).unwrap())
        .with_timeout(odc::time::Duration::from_millis(2000));
    let seen = Arc::new(Mutex::new(Vec::new()));
    let log = seen.clone();
    m.observe(move |_, f| log.lock().unwrap().push(*f));
    // Reset the node to see it boot (it booted before the master connected).
    m.nmt(NmtCommand::ResetNode, NODE).unwrap();
    m.wait_boot_up(NODE).unwrap();
    for plan in plans {
        m.execute(NODE, plan).unwrap();
    }
    m.download(NODE, 0x6081, 0, &velocity.to_le_bytes()).unwrap();
    let modes =
        SupportedModes(u32::from_le_bytes(m.upload(NODE, 0x6502, 0).unwrap().try_into().unwrap()));
    m.nmt(NmtCommand::Start, NODE).unwrap();
    let mut axis = Axis::with_pdos::<P>(&mut m, NODE, Driver::new(modes)).unwrap();
    axis.enable().unwrap();
    axis.set_mode(ModeOfOperation::ProfilePosition).unwrap();
    axis.move_to(20_000).unwrap();
    let moved_to = axis.inputs().position.unwrap();
    // csp: 200 set-points, 50 units apart, one per cycle.
    let csp = match axis.set_mode(ModeOfOperation::CyclicSyncPosition) {
        Ok(()) => {
            for k in 1..=200 {
                axis.driver.stream_position(20_000 + k * 50).unwrap();
                axis.cycle().unwrap();
            }
            Ok(())
        }
        Err(Error::Drive { error, .. }) => Err(error),
        Err(e) => panic!("{file}: {e}"),
    };
    // Two more cycles for the last set-point to come back in the TPDO.
    let streamed_to = csp.is_ok().then(|| {
        axis.cycle().unwrap();
        axis.cycle().unwrap();
        axis.inputs().position.unwrap()
    });
    m.nmt(NmtCommand::Stop, NODE).unwrap();
    drop(m);
    stop.stop();
    sim.join().unwrap();
    let frames = seen.lock().unwrap().clone();
    Session { frames, moved_to, streamed_to, csp }
}

/// Every frame decoded with the device file: none unknown; the kinds counted.
fn decoded(file: &str, frames: &[CanFrame]) -> (std::collections::BTreeMap<String, usize>, String) {
    let mut d = odc_monitor::Decoder::new(vec![(NODE.get(), model(file))]);
    let mut kinds = std::collections::BTreeMap::new();
    let mut text = String::new();
    for f in frames {
        let r = d.decode(f, None);
        assert_ne!(r.kind, "unknown", "{file}: {r}");
        *kinds.entry(r.kind.clone()).or_insert(0) += 1;
        text.push_str(&format!("{r}\n"));
    }
    (kinds, text)
}

#[test]
fn lxm23a_moves_and_streams_csp() {
    let s = session::<lxm23a::cia402::Pdos>(
        "eds/lxm23a.eds",
        &[&lxm23a::master::rpdo2(NODE), &lxm23a::master::tpdo2(NODE)],
        1_000_000,
    );
    assert_eq!(s.moved_to, 20_000);
    assert_eq!(s.csp, Ok(()));
    assert_eq!(s.streamed_to, Some(30_000), "the last set-point, 20000 + 200 x 50");
    let (kinds, text) = decoded("eds/lxm23a.eds", &s.frames);
    println!("lxm23a: {} frames {kinds:?}", s.frames.len());
    assert!(kinds["RPDO2"] >= 200 && kinds["TPDO2"] > 0 && kinds["SYNC"] >= 200, "{kinds:?}");
    // The monitor names what went by.
    for want in [
        "Controlword = 31 (0x1F) (EnableOperation), Target position = 20000",
        "Statusword",
        "Position actual value = 30000",
        "write confirmed 0x6060:00 Modes of operation = 8",
        "heartbeat node 5: boot-up",
    ] {
        assert!(text.contains(want), "lxm23a: no `{want}` in the decoded exchange:\n{text}");
    }
}

#[test]
fn lexium_mdrive_moves_and_refuses_csp() {
    let s = session::<lexium_mdrive::cia402::Pdos>(
        "eds/lexium-mdrive.eds",
        &[&lexium_mdrive::master::plan(NODE)],
        512_000,
    );
    assert_eq!(s.moved_to, 20_000);
    // 0x6502 = 0x25 (pp, pv, hm): no csp, refused before anything is written.
    assert_eq!(s.csp, Err(DriverError::ModeNotSupported(ModeOfOperation::CyclicSyncPosition)));
    let (kinds, text) = decoded("eds/lexium-mdrive.eds", &s.frames);
    println!("lexium-mdrive: {} frames {kinds:?}", s.frames.len());
    assert!(text.contains("Target position = 20000"), "{text}");
    assert!(!text.contains("Modes of operation = 8"), "csp must not be written");
}
