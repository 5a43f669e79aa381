//! The async master against the runtime's own node over the dictionary generated from
//! eds/lxm23a.eds, with its CiA 402 drive, on tokio's paused clock: boot-up, heartbeat
//! consumer, NMT, the generated PDO plans, the CiA 402 axis on a SYNC cycle, LSS.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, missing_docs)]

mod lxm23a {
    odc_macros::include_device!("../../eds/lxm23a.eds", role = "both");
}

use std::sync::{Arc, Mutex};

use lxm23a::slave::Dictionary;
use odc::asynch::axis::Axis;
use odc::asynch::tokio::TokioClock;
use odc::asynch::{CanRx, CanTx, Clock, Master};
use odc::can::CanFrame;
use odc::cia402::{self, Driver, ModeOfOperation, SupportedModes};
use odc::cob::NodeId;
use odc::master::Event;
use odc::nmt::{NmtCommand, NmtState};
use odc::node::Node;
use odc::time::Duration;
use tokio::sync::mpsc;

const NODE: NodeId = odc::node_id!(5);

#[derive(Debug)]
struct Closed;

struct Tx(mpsc::UnboundedSender<CanFrame>);
impl CanTx for Tx {
    type Error = Closed;
    async fn send(&mut self, f: &CanFrame) -> Result<(), Closed> {
        self.0.send(*f).map_err(|_| Closed)
    }
}

struct Rx(mpsc::UnboundedReceiver<CanFrame>);
impl CanRx for Rx {
    type Error = Closed;
    async fn recv(&mut self) -> Result<CanFrame, Closed> {
        self.0.recv().await.ok_or(Closed)
    }
}

/// The device: the node (with LSS) over the generated dictionary and a CiA 402 drive that
/// moves one millisecond of profile velocity per millisecond tick; a frame in is answered at
/// once.
struct Device {
    node: Node<64>,
    od: Dictionary,
    drive: cia402::Drive,
}

fn device(clock: TokioClock) -> (Tx, Rx, Arc<Mutex<Device>>) {
    let (to_dev, mut from_master) = mpsc::unbounded_channel::<CanFrame>();
    let (to_master, from_dev) = mpsc::unbounded_channel();
    let mut d = Device {
        node: Node::new(NODE).with_lss(None, 0),
        od: Dictionary::new(NODE),
        drive: cia402::Drive::new(),
    };
    let mut out = Vec::new();
    d.drive.start(&mut d.od);
    d.node.start(&mut d.od, clock.now(), &mut |f| out.push(f));
    for f in out {
        to_master.send(f).unwrap();
    }
    let dev = Arc::new(Mutex::new(d));
    let shared = dev.clone();
    tokio::spawn(async move {
        let mut tick = tokio::time::interval(std::time::Duration::from_millis(1));
        loop {
            let mut out = Vec::new();
            tokio::select! {
                f = from_master.recv() => {
                    let Some(f) = f else { return };
                    let mut d = shared.lock().unwrap();
                    let d = &mut *d;
                    d.node.handle(&mut d.od, &f, clock.now(), &mut |f| out.push(f));
                    d.drive.update(&mut d.od);
                }
                _ = tick.tick() => {
                    let mut d = shared.lock().unwrap();
                    let d = &mut *d;
                    if d.node.state() == NmtState::Operational {
                        d.drive.step(&mut d.od, Duration::from_millis(1));
                        d.drive.update(&mut d.od);
                    }
                    d.node.poll(&mut d.od, clock.now(), &mut |f| out.push(f));
                }
            }
            for f in out {
                if to_master.send(f).is_err() {
                    return;
                }
            }
        }
    });
    (Tx(to_dev), Rx(from_dev), dev)
}

#[tokio::test(start_paused = true)]
async fn a_drive_boots_is_watched_configured_and_moves_on_the_cycle() {
    let clock = TokioClock::new();
    let (tx, rx, dev) = device(clock);
    let m = Master::new(clock);
    let test = async {
        assert_eq!(m.next_event().await.unwrap(), Event::BootUp { node: NODE });
        assert_eq!(m.state(NODE), Some(NmtState::PreOperational));
        // Heartbeat every 10 ms, consumed with 30 ms.
        m.write(NODE, &lxm23a::od::PRODUCER_HEARTBEAT_TIME, 10).await.unwrap();
        m.watch_heartbeat(NODE, Duration::from_millis(30));
        m.execute(NODE, &lxm23a::master::rpdo2(NODE)).await.unwrap();
        m.execute(NODE, &lxm23a::master::tpdo2(NODE)).await.unwrap();
        m.write(NODE, &lxm23a::od::PROFILE_VELOCITY, 1_000_000).await.unwrap();
        let supported = m.upload(NODE, 0x6502, 0).await.unwrap();
        let supported = SupportedModes(u32::from_le_bytes(supported.try_into().unwrap()));
        m.nmt(NmtCommand::Start, NODE).unwrap();
        assert_eq!(
            m.next_event().await.unwrap(),
            Event::State { node: NODE, state: NmtState::Operational }
        );

        let axis = Axis::with_pdos::<_, lxm23a::cia402::Pdos>(&m, NODE, Driver::new(supported))
            .await
            .unwrap();
        let done = std::sync::atomic::AtomicBool::new(false);
        let cycle = async {
            let mut c = m.cycle(Duration::from_millis(10));
            while !done.load(std::sync::atomic::Ordering::Relaxed) {
                c.tick().await;
                axis.cycle(&m).unwrap();
                m.sync().unwrap();
            }
            (c.ticks(), c.missed())
        };
        let jobs = async {
            axis.enable().await.unwrap();
            axis.set_mode(&m, ModeOfOperation::ProfilePosition).await.unwrap();
            let t0 = m.now();
            axis.move_to(100_000).await.unwrap();
            let took = m.now() - t0;
            done.store(true, std::sync::atomic::Ordering::Relaxed);
            took
        };
        let ((ticks, missed), took) = tokio::join!(cycle, jobs);
        assert_eq!(missed, 0);
        assert!(ticks > 10, "{ticks} cycles");
        // 100 000 at 1 000 000 per second: 100 ms of motion, and the cycles around it.
        assert!(took >= Duration::from_millis(100) && took < Duration::from_millis(200), "{took}");
        assert_eq!(axis.inputs().position, Some(100_000));
        assert_eq!(m.read(NODE, &lxm23a::od::POSITION_ACTUAL_VALUE).await.unwrap(), 100_000);
        // The TPDO is in the master's slot, typed.
        let cob = <lxm23a::cia402::Pdos as cia402::DrivePdos>::status_cob_id(NODE);
        assert!(m.latest_frame(cob).1 > 0);

        // Heartbeats stop: the consumer reports the node lost, once.
        m.write(NODE, &lxm23a::od::PRODUCER_HEARTBEAT_TIME, 0).await.unwrap();
        let lost_at = loop {
            match m.next_event().await.unwrap() {
                Event::HeartbeatLost { node } => break (node, m.now()),
                Event::Emcy { .. } | Event::Other(_) => {}
                e => panic!("unexpected {e:?}"),
            }
        };
        assert_eq!(lost_at.0, NODE);
        let heard = m.last_heard(NODE).unwrap();
        assert!(lost_at.1 - heard > Duration::from_millis(30), "lost too early");

        // LSS: the node answers with its node-ID and takes another.
        let lss = m.lss().unwrap();
        assert!(m.lss().is_err(), "a second LSS master at once");
        lss.switch_global(true).unwrap();
        assert_eq!(lss.inquire_node_id().await.unwrap(), Some(NODE));
        lss.configure_node_id(NodeId::new(7)).await.unwrap();
        let identity = lss.inquire_identity().await.unwrap();
        assert_eq!(
            identity.vendor,
            m.read(NODE, &lxm23a::od::identity_object::VENDOR_ID).await.unwrap()
        );
        lss.switch_global(false).unwrap();
        drop(lss);
        assert_eq!(dev.lock().unwrap().node.next_node_id(), NodeId::new(7));
    };
    tokio::select! {
        r = m.run(tx, rx) => panic!("bus ended: {r:?}"),
        () = test => {}
    }
}
