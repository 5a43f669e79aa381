//! `odc::master::Master` against odc's own node (`odc::node::Node` serving the dictionary
//! generated from `eds/lxm23a.eds`) on the in-memory bus: NMT and node states, heartbeat
//! consumer, node guarding, SDO with generated descriptors and aborts, plans, PDOs with generated structs,
//! SYNC with counter, EMCY, and LSS fastscan. Expected frames and values are CiA 301/305's.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::thread::{self, JoinHandle};
use std::time::Instant;

use odc::can::CanFrame;
use odc::cia402::Controlword;
use odc::emcy::EmcyCode;
use odc::lss::Identity;
use odc::master::{Dir, Error, Event, Master};
use odc::nmt::{NmtCommand, NmtState};
use odc::node::Node;
use odc::transport::Bus;
use odc::transport::mem::{MemBus, MemPort};
use odc::{SdoAbort, sdo::SdoError};
use odc_tests_generated::lxm23a::{self, od, pdo, slave};

const NODE: odc::cob::NodeId = odc::node_id!(1);

/// The drive: the generated dictionary served by a node in a thread, until `stop`.
struct Device {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl Device {
    fn spawn(port: MemPort, node_id: Option<odc::cob::NodeId>, lss: Option<Identity>) -> Device {
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let thread = thread::spawn(move || {
            let mut port = port;
            let start = Instant::now();
            let now_us = || u64::try_from(start.elapsed().as_micros()).unwrap();
            let mut node: Node<64> = match node_id {
                Some(n) => Node::new(n),
                None => Node::unconfigured(),
            };
            if let Some(id) = lss {
                node = node.with_lss(Some(id), 0);
            }
            let mut dict = slave::Dictionary::new(node_id);
            let mut out = Vec::new();
            node.start(&mut dict, odc::time::Instant::from_micros(now_us()), &mut |f| out.push(f));
            while !flag.load(Ordering::Relaxed) {
                for f in out.drain(..) {
                    if port.send(&f).is_err() {
                        return;
                    }
                }
                let deadline = port.now() + odc::time::Duration::from_millis(1);
                let events = match port.recv(deadline) {
                    Ok(Some(f)) => node.handle(
                        &mut dict,
                        &f,
                        odc::time::Instant::from_micros(now_us()),
                        &mut |f| out.push(f),
                    ),
                    Ok(None) => {
                        node.poll(&mut dict, odc::time::Instant::from_micros(now_us()), &mut |f| {
                            out.push(f)
                        })
                    }
                    Err(_) => return,
                };
                if events.reset.is_some() {
                    dict = slave::Dictionary::new(node.next_node_id());
                    node.start(&mut dict, odc::time::Instant::from_micros(now_us()), &mut |f| {
                        out.push(f)
                    });
                }
            }
        });
        Device { stop, thread: Some(thread) }
    }

    fn stop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            t.join().unwrap();
        }
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        self.stop();
    }
}

fn setup() -> (Master<MemPort>, Device, MemPort) {
    let bus = MemBus::new();
    let master = Master::new(bus.port()).with_timeout(odc::time::Duration::from_millis(500));
    let spy = bus.port();
    let device = Device::spawn(bus.port(), Some(NODE), None);
    (master, device, spy)
}

#[test]
fn boot_up_sdo_and_aborts() {
    let (mut m, _device, _spy) = setup();
    m.wait_boot_up(NODE).unwrap();
    assert_eq!(m.state(NODE), Some(NmtState::PreOperational));
    // 0x1000 of eds/lxm23a.eds: 0x04020192 (the manual's object 1000h: CiA 402 servo drive).
    assert_eq!(m.read(NODE, &od::DEVICE_TYPE).unwrap(), 0x0402_0192);
    m.write(NODE, &od::PROFILE_VELOCITY, 12_345).unwrap();
    assert_eq!(m.read(NODE, &od::PROFILE_VELOCITY).unwrap(), 12_345);
    // Untyped, and the server's aborts come back as values.
    assert_eq!(m.upload(NODE, 0x6081, 0).unwrap(), 12_345u32.to_le_bytes());
    // Block transfer (CiA 301 7.2.4.3.9ff, with CRC) both ways.
    m.download_block(NODE, 0x6081, 0, &777u32.to_le_bytes()).unwrap();
    assert_eq!(m.upload_block(NODE, 0x6081, 0).unwrap(), 777u32.to_le_bytes());
    match m.upload(NODE, 0x2FFF, 0) {
        Err(Error::Sdo { node: NODE, index: 0x2FFF, sub: 0, error: SdoError::Remote(a) }) => {
            assert_eq!(a, SdoAbort::NoSuchObject);
        }
        other => panic!("{other:?}"),
    }
    match m.download(NODE, 0x1000, 0, &[0, 0, 0, 0]) {
        Err(Error::Sdo { error: SdoError::Remote(a), .. }) => {
            assert_eq!(a, SdoAbort::WriteOfReadOnly)
        }
        other => panic!("{other:?}"),
    }
    // A node that is not there: a timeout, not a hang, that says nothing came from it.
    match m.upload(odc::node_id!(9), 0x1000, 0) {
        Err(e @ Error::Timeout { node: Some(node), heard: false, .. }) if node.get() == 9 => {
            let text = e.to_string();
            assert!(text.contains("nothing at all from node 9 within 500 ms"), "{text}");
            assert!(text.contains("SDO response for 0x1000:00"), "{text}");
        }
        other => panic!("{other:?}"),
    }
}

/// #33 item 4: a stopped node (CiA 301 §7.3.2.2: no SDO in "stopped") that sends its
/// heartbeat is alive but silent on SDO, and the timeout says so, unlike an absent node's.
#[test]
fn a_timeout_tells_a_silent_node_from_an_absent_one() {
    let (mut m, _device, _spy) = setup();
    m.wait_boot_up(NODE).unwrap();
    m.write(NODE, &od::PRODUCER_HEARTBEAT_TIME, 20).unwrap();
    m.nmt(NmtCommand::Stop, NODE).unwrap();
    m.wait_state(NODE, NmtState::Stopped).unwrap();
    match m.upload(NODE, 0x1000, 0) {
        Err(e @ Error::Timeout { heard: true, state: Some(NmtState::Stopped), .. }) => {
            let text = e.to_string();
            assert!(text.contains("node 1 is alive"), "{text}");
            assert!(text.contains("stopped, where it serves no SDO"), "{text}");
        }
        other => panic!("{other:?}"),
    }
    // Master errors print which node and what was waited for, not a Debug dump.
    let e = m.wait_boot_up(odc::node_id!(9)).unwrap_err();
    assert_eq!(format!("{e:?}"), e.to_string(), "Debug is the Display text");
    assert_eq!(
        e.to_string(),
        "timeout: nothing at all from node 9 within 500 ms (waiting for the boot-up message): \
         is it on the bus, with this node-ID and bit rate?"
    );
}

#[test]
fn a_plan_pdos_and_node_states() {
    let (mut m, _device, _spy) = setup();
    m.wait_boot_up(NODE).unwrap();
    // The generated plans for RPDO2 (controlword, target position) and TPDO2 (statusword,
    // position actual value), then TPDO2 synchronous (transmission type 1) and a heartbeat.
    m.execute(NODE, &lxm23a::master::rpdo2(NODE)).unwrap();
    m.execute(NODE, &lxm23a::master::tpdo2(NODE)).unwrap();
    m.write(NODE, &od::transmit_pdo_parameter_obj_1801::TRANSMISSION_TYPE, 1).unwrap();
    m.write(NODE, &od::PRODUCER_HEARTBEAT_TIME, 20).unwrap();
    m.nmt(NmtCommand::Start, NODE).unwrap();
    m.wait_state(NODE, NmtState::Operational).unwrap();
    assert_eq!(m.state(NODE), Some(NmtState::Operational));
    // An RPDO struct in, the dictionary changed.
    let cw = Controlword::SHUTDOWN;
    m.send_pdo(
        odc::cob::CobId(pdo::Rpdo2::cob_id(NODE)),
        &pdo::Rpdo2 { controlword: cw, target_position: -7 },
    )
    .unwrap();
    assert_eq!(m.read(NODE, &od::TARGET_POSITION).unwrap(), -7);
    assert_eq!(m.read(NODE, &od::CONTROLWORD).unwrap().bits(), cw.bits());
    // A SYNC, and the TPDO struct out.
    m.sync().unwrap();
    let t: pdo::Tpdo2 = m.recv_pdo(odc::cob::CobId(pdo::Tpdo2::cob_id(NODE))).unwrap();
    assert_eq!(t.position_actual_value, m.read(NODE, &od::POSITION_ACTUAL_VALUE).unwrap());
    // A plan write the device refuses: which write, and why.
    let bad = [odc::plan::SdoWrite::u32(0x1000, 0, 1)];
    match m.execute(NODE, &bad) {
        Err(Error::Plan {
            step: 0, error: SdoError::Remote(SdoAbort::WriteOfReadOnly), ..
        }) => {}
        other => panic!("{other:?}"),
    }
    // NMT stop: the heartbeat says stopped.
    m.nmt_all(NmtCommand::Stop).unwrap();
    m.wait_state(NODE, NmtState::Stopped).unwrap();
}

#[test]
fn a_lost_heartbeat_is_an_event() {
    let (mut m, mut device, _spy) = setup();
    m.wait_boot_up(NODE).unwrap();
    m.write(NODE, &od::PRODUCER_HEARTBEAT_TIME, 10).unwrap();
    m.watch_heartbeat(NODE, odc::time::Duration::from_millis(60));
    // Heartbeats come; no loss while they do.
    let until = m.now() + odc::time::Duration::from_millis(150);
    while let Some(e) = m.poll(until).unwrap() {
        assert_ne!(e, Event::HeartbeatLost { node: NODE }, "lost while beating");
    }
    device.stop();
    let until = m.now() + odc::time::Duration::from_millis(300);
    let mut lost = 0;
    while let Some(e) = m.poll(until).unwrap() {
        if e == (Event::HeartbeatLost { node: NODE }) {
            lost += 1;
        }
    }
    assert_eq!(lost, 1, "one event per loss");
}

#[test]
fn node_guarding_from_the_master() {
    let (mut m, mut device, _spy) = setup();
    m.wait_boot_up(NODE).unwrap();
    // The node watches the master with guard time 20 ms × life time factor 3 (CiA 301
    // 0x100C, 0x100D); the master guards it every 20 ms, with the same life time.
    m.download(NODE, 0x100C, 0, &20u16.to_le_bytes()).unwrap();
    m.download(NODE, 0x100D, 0, &[3]).unwrap();
    m.guard(NODE, odc::time::Duration::from_millis(20), 3).unwrap();
    let until = m.now() + odc::time::Duration::from_millis(200);
    while let Some(e) = m.poll(until).unwrap() {
        assert_ne!(e, Event::GuardingLost { node: NODE }, "lost while answering");
    }
    let st = m.guarding(NODE).unwrap();
    assert!(st.requests >= 9 && st.answers + 1 >= st.requests, "{st:?}");
    assert_eq!(st.toggle_errors, 0, "the node's toggle bit alternates");
    assert_eq!(st.state, Some(NmtState::PreOperational));
    // The master stops guarding: the node reports the life-guarding loss (EMCY 0x8130).
    m.unguard(NODE);
    let until = m.now() + odc::time::Duration::from_millis(200);
    let mut emcy = None;
    while let Some(e) = m.poll(until).unwrap() {
        if let Event::Emcy { node: NODE, emcy: frame } = e {
            emcy = Some(frame.code);
        }
    }
    assert_eq!(emcy, Some(EmcyCode(0x8130)));
    // Guarded again, then the node goes away: one loss event.
    m.guard(NODE, odc::time::Duration::from_millis(20), 3).unwrap();
    let until = m.now() + odc::time::Duration::from_millis(60);
    while m.poll(until).unwrap().is_some() {}
    device.stop();
    let until = m.now() + odc::time::Duration::from_millis(200);
    let mut lost = 0;
    while let Some(e) = m.poll(until).unwrap() {
        if e == (Event::GuardingLost { node: NODE }) {
            lost += 1;
        }
    }
    assert_eq!(lost, 1, "one event per loss");
    assert!(m.guarding(NODE).unwrap().lost);
}

#[test]
fn a_heartbeat_with_an_undefined_state_is_handed_out() {
    let bus = MemBus::new();
    let mut m = Master::new(bus.port()).with_timeout(odc::time::Duration::from_millis(100));
    let mut device = bus.port();
    let heartbeat = |byte: u8| CanFrame::from_slice(0x704, &[byte]).unwrap();
    // Pre-operational (0x7F) twice: one state event; 0x55 is no CiA 301 state.
    for byte in [0x7F, 0x7F, 0x55] {
        device.send(&heartbeat(byte)).unwrap();
    }
    let until = m.now() + odc::time::Duration::from_millis(40);
    let mut events = Vec::new();
    while let Some(e) = m.poll(until).unwrap() {
        events.push(e);
    }
    assert_eq!(
        events,
        [
            Event::State { node: odc::node_id!(4), state: NmtState::PreOperational },
            Event::Other(heartbeat(0x55))
        ]
    );
}

#[test]
fn sync_producer_with_counter_and_emcy() {
    let bus = MemBus::new();
    let mut m = Master::new(bus.port()).with_timeout(odc::time::Duration::from_millis(100));
    let mut device = bus.port();
    let (tx, rx) = mpsc::channel();
    m.observe(move |dir, f| {
        if dir == Dir::Sent && f.id() == 0x080 {
            let _ = tx.send(f.bytes().to_vec());
        }
    });
    m.set_sync_counter(Some(3)).unwrap();
    assert!(m.set_sync_counter(Some(1)).is_err(), "CiA 301: overflow 2..=240");
    m.set_sync_counter(Some(3)).unwrap();
    m.set_sync_period(Some(odc::time::Duration::from_millis(5)));
    let until = m.now() + odc::time::Duration::from_millis(60);
    // An EMCY from node 4 meanwhile: 0x8130 (heartbeat or life guarding), register 0x11.
    device.send(&CanFrame::from_slice(0x084, &[0x30, 0x81, 0x11, 4, 0, 0, 0, 0]).unwrap()).unwrap();
    let mut emcy = None;
    while let Some(e) = m.poll(until).unwrap() {
        if let Event::Emcy { node, emcy: frame } = e {
            emcy = Some((node, frame));
        }
    }
    let (node, frame) = emcy.expect("the EMCY as an event");
    assert_eq!((node.get(), frame.code, frame.register.0), (4, EmcyCode::HEARTBEAT, 0x11));
    assert_eq!(frame.code.description(), Some("Life guard error or heartbeat error"));
    let counters: Vec<Vec<u8>> = rx.try_iter().collect();
    // About 12 SYNCs in 60 ms at 5 ms; the counter runs 1, 2, 3, 1, ...
    assert!(counters.len() >= 8, "{counters:?}");
    for (k, c) in counters.iter().enumerate() {
        assert_eq!(c, &[(k % 3) as u8 + 1], "SYNC {k}");
    }
}

#[test]
fn lss_fastscan_then_a_node_id() {
    let bus = MemBus::new();
    let mut m = Master::new(bus.port()).with_timeout(odc::time::Duration::from_millis(500));
    let identity = Identity {
        vendor: 0x0000_01DD,
        product: 0x6000,
        revision: 0x0200_0001,
        serial: 0x1234_5678,
    };
    // An unconfigured device (node-ID 255): no boot-up until it has a node-ID.
    let _device = Device::spawn(bus.port(), None, Some(identity));
    std::thread::sleep(std::time::Duration::from_millis(20));
    let mut lss = m.lss().with_timeout(odc::time::Duration::from_millis(20));
    assert!(lss.any_unconfigured().unwrap());
    assert_eq!(lss.fastscan().unwrap(), Some(identity));
    // Found, it is in configuration state: it answers inquiries and takes a node-ID.
    assert_eq!(lss.inquire_identity().unwrap(), identity);
    assert_eq!(lss.inquire_node_id().unwrap(), None);
    lss.configure_node_id(Some(odc::node_id!(9))).unwrap();
    lss.switch_global(false).unwrap();
    // Reset communication: it boots as node 9.
    m.nmt_all(NmtCommand::ResetCommunication).unwrap();
    m.wait_boot_up(odc::node_id!(9)).unwrap();
    assert_eq!(m.read(odc::node_id!(9), &od::DEVICE_TYPE).unwrap(), 0x0402_0192);
    // Nobody unconfigured any more; a fastscan finds nothing.
    let mut lss = m.lss().with_timeout(odc::time::Duration::from_millis(20));
    assert!(!lss.any_unconfigured().unwrap());
    assert_eq!(lss.fastscan().unwrap(), None);
    // Selective switch by its address, then store: this node does not support it (CiA 305
    // error 1), which comes back as a value.
    lss.switch_selective(identity).unwrap();
    match lss.store() {
        Err(Error::Lss(odc::master::lss::LssError::Store { error: 1, .. })) => {}
        other => panic!("{other:?}"),
    }
}
