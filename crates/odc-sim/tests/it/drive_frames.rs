//! A simulated CiA 402 drive driven by SDO frames: the controlword sequence of CiA 402-2
//! (shutdown, switch on, enable operation, quick stop, disable voltage, then a fault reset
//! path) as SDO downloads to 0x6040, the statusword uploaded from 0x6041 after each, with the
//! state coding the standard gives (mask 0x6F). The same sequence on the generated dictionary
//! of the same file (which implements `DriveObjects` itself) gives the same frames.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::Path;

use odc::can::CanFrame;
use odc::cia402::{Drive, DriveObjects};
use odc::sdo::Server;
use odc::slave::ObjectDictionary;
use odc_sim::SimDevice;

mod lxm23a {
    odc_macros::include_device!("../../eds/lxm23a.eds", role = "slave");
}

const NODE: odc::cob::NodeId = odc::node_id!(5);

fn download_cw(cw: u16) -> CanFrame {
    let [lo, hi] = cw.to_le_bytes();
    // Expedited download of 2 bytes (0x2B) to 0x6040:00.
    CanFrame::new(0x605, [0x2B, 0x40, 0x60, 0x00, lo, hi, 0, 0]).unwrap()
}

fn upload_sw() -> CanFrame {
    CanFrame::new(0x605, [0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0]).unwrap()
}

/// (controlword, statusword state coding under mask 0x6F) per CiA 402-2.
const SEQUENCE: [(u16, u16); 6] = [
    (0x0006, 0x21), // shutdown: ready to switch on
    (0x0007, 0x23), // switch on: switched on
    (0x000F, 0x27), // enable operation: operation enabled
    (0x0002, 0x07), // quick stop: quick stop active
    (0x0000, 0x40), // disable voltage: switch on disabled
    (0x0006, 0x21), // shutdown again
];

fn statusword(answer: &CanFrame) -> u16 {
    assert_eq!(answer.data()[..4], [0x4B, 0x41, 0x60, 0x00], "{answer:02X?}");
    u16::from_le_bytes([answer.data()[4], answer.data()[5]])
}

#[test]
fn controlword_frames_walk_the_state_machine() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../eds/lxm23a.eds");
    let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
    let mut sim = SimDevice::new(loaded.device().unwrap(), NODE);
    let mut out = Vec::new();
    sim.start(0, &mut |f| out.push(f));
    assert_eq!(out, [CanFrame::from_slice(0x705, &[0]).unwrap()], "boot-up");

    // The generated dictionary with odc's Drive and Server, as a firmware would run them.
    let mut generated = lxm23a::slave::Dictionary::new(NODE);
    let mut server = Server::<64>::new(NODE);
    let mut drive = Drive::new();
    drive.start(&mut generated);

    let mut exchange = |frame: CanFrame| {
        out.clear();
        sim.handle(&frame, 0, &mut |f| out.push(f));
        let theirs = server.handle(&mut generated, &frame, odc::time::Instant::from_millis(0));
        drive.update(&mut generated);
        assert_eq!(out.first().copied(), theirs, "model and generated answer {frame:02X?}");
        theirs.unwrap()
    };
    let first = statusword(&exchange(upload_sw()));
    assert_eq!(first & 0x6F, 0x40, "switch on disabled after boot-up: {first:#06x}");
    for (cw, coding) in SEQUENCE {
        let ack = exchange(download_cw(cw));
        assert_eq!(ack.data()[..4], [0x60, 0x40, 0x60, 0x00], "download acknowledged");
        let sw = statusword(&exchange(upload_sw()));
        assert_eq!(sw & 0x6F, coding, "after controlword {cw:#06x}: statusword {sw:#06x}");
        assert!(sw & 0x0200 != 0, "remote (bit 9)");
    }
    // Both dictionaries hold the same drive objects.
    assert_eq!(generated.controlword(), odc::cia402::Controlword(0x0006));
    assert_eq!(sim.dictionary().controlword(), generated.controlword());
    let mut a = [0u8; 4];
    let mut b = [0u8; 4];
    for (index, sub) in [(0x6041, 0), (0x6061, 0), (0x6064, 0)] {
        let x = sim.dictionary().read(index, sub, &mut a).map(|n| a[..n].to_vec());
        let y = generated.read(index, sub, &mut b).map(|n| b[..n].to_vec());
        assert_eq!(x, y, "{index:04X}:{sub:02X}");
    }
}

/// An expedited SDO download of `value` (1, 2 or 4 bytes) to `index:sub` and the answer.
fn download(sim: &mut SimDevice, now: u64, index: u16, sub: u8, value: &[u8]) -> CanFrame {
    let n = value.len() as u8;
    let [lo, hi] = index.to_le_bytes();
    let mut data = [0x23 | (4 - n) << 2, lo, hi, sub, 0, 0, 0, 0];
    data[4..4 + value.len()].copy_from_slice(value);
    let mut out = Vec::new();
    sim.handle(&CanFrame::new(0x605, data).unwrap(), now, &mut |f| out.push(f));
    out.pop().unwrap()
}

/// The simulated LXM23A lists homing (bit 5) but not CSV (bit 8) in 0x6502 (0xEF): a CSV
/// request is refused with 0x06090030 (CiA 402-2 object 0x6060); homing with method 35
/// (CiA 402-2 homing mode, "homing on current position") completes: statusword bits 10 and
/// 12, 0x6064 the home offset 0x607C.
#[test]
fn the_simulated_drive_refuses_unlisted_modes_and_completes_homing() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../eds/lxm23a.eds");
    let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
    let mut sim = SimDevice::new(loaded.device().unwrap(), NODE);
    sim.start(0, &mut |_| {});
    let refused = download(&mut sim, 1, 0x6060, 0, &[9]);
    assert_eq!(refused.data(), [0x80, 0x60, 0x60, 0x00, 0x30, 0x00, 0x09, 0x06]);
    assert_eq!(download(&mut sim, 1, 0x6060, 0, &[6]).data()[0], 0x60);
    assert_eq!(download(&mut sim, 1, 0x6098, 0, &[35]).data()[0], 0x60);
    assert_eq!(download(&mut sim, 1, 0x607C, 0, &1500i32.to_le_bytes()).data()[0], 0x60);
    for cw in [0x0006u16, 0x0007, 0x000F, 0x001F] {
        assert_eq!(download(&mut sim, 2, 0x6040, 0, &cw.to_le_bytes()).data()[0], 0x60);
    }
    sim.poll(10, &mut |_| {});
    let od = sim.dictionary();
    let sw = od.get::<u16>(0x6041, 0).unwrap();
    assert_eq!(sw & 0x6F, 0x27, "operation enabled: {sw:#06x}");
    assert_eq!(sw & (1 << 12 | 1 << 10 | 1 << 13), 1 << 12 | 1 << 10, "homed: {sw:#06x}");
    assert_eq!(od.get::<i32>(0x6064, 0), Ok(1500));
    assert_eq!(od.get::<i8>(0x6061, 0), Ok(6));
}

/// The statusword's state coding (mask 0x6F) of the simulated drive.
fn state(sim: &mut SimDevice, now: u64) -> u16 {
    let mut out = Vec::new();
    sim.handle(&upload_sw(), now, &mut |f| out.push(f));
    statusword(&out[0]) & 0x6F
}

/// The simulated MDrive, with the abort connection option code 0x6007 = 1 (CiA 402-2
/// 6.5.1): a heartbeat it consumes (0x1016) that stops is a fault, transitions 13 and 14 to
/// "fault" (0x08); a fault reset (controlword bit 7 rising) is transition 15 to "switch on
/// disabled". With 0x6007 = 0 (its default) the same loss leaves it enabled; with 2
/// (disable voltage) it is in "switch on disabled" (9); with 3 (quick stop) in "quick stop
/// active" (11), where quick stop option code 6 (0x605A) keeps it.
#[test]
fn a_lost_heartbeat_faults_the_drive_as_0x6007_says() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../eds/lexium-mdrive.eds");
    let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
    for option in [1i16, 0, 2, 3] {
        let mut sim = SimDevice::new(loaded.device().unwrap(), NODE);
        sim.start(0, &mut |_| {});
        assert_eq!(download(&mut sim, 0, 0x6007, 0, &option.to_le_bytes()).data()[0], 0x60);
        assert_eq!(download(&mut sim, 0, 0x605A, 0, &6i16.to_le_bytes()).data()[0], 0x60);
        // Consume node 0x7E's heartbeat, 100 ms (CiA 301 0x1016: node << 16 | time).
        let entry = 0x007E_0064u32.to_le_bytes();
        assert_eq!(download(&mut sim, 0, 0x1016, 1, &entry).data()[0], 0x60);
        for cw in [0x06u16, 0x07, 0x0F] {
            download(&mut sim, 0, 0x6040, 0, &cw.to_le_bytes());
        }
        assert_eq!(state(&mut sim, 0), 0x27, "operation enabled");
        sim.handle(&CanFrame::from_slice(0x77E, &[0x05]).unwrap(), 10, &mut |_| {});
        for t in (20..=300).step_by(10) {
            sim.poll(t, &mut |_| {});
        }
        match option {
            0 => assert_eq!(state(&mut sim, 300), 0x27, "0x6007 = 0: no action"),
            2 => assert_eq!(state(&mut sim, 300) & 0x4F, 0x40, "2: 9, switch on disabled"),
            3 => assert_eq!(state(&mut sim, 300), 0x07, "3: 11, quick stop active"),
            _ => {}
        }
        if option != 1 {
            continue;
        }
        assert_eq!(state(&mut sim, 300) & 0x4F, 0x08, "fault");
        download(&mut sim, 300, 0x6040, 0, &0x00u16.to_le_bytes());
        assert_eq!(state(&mut sim, 300) & 0x4F, 0x08, "still fault without the reset");
        download(&mut sim, 300, 0x6040, 0, &0x80u16.to_le_bytes());
        assert_eq!(state(&mut sim, 300) & 0x4F, 0x40, "15: switch on disabled");
    }
}

/// Transition 16 (quick stop active to operation enabled) with quick stop option code 6
/// written over SDO while the drive runs (0x605A, CiA 402-2 6.5.2): the drive stays in
/// "quick stop active" (0x07) and enable operation takes it back. With the default 2 the
/// quick stop ends in "switch on disabled" (12).
#[test]
fn quick_stop_option_written_over_sdo_allows_transition_16() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../eds/lexium-mdrive.eds");
    let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
    let mut sim = SimDevice::new(loaded.device().unwrap(), NODE);
    sim.start(0, &mut |_| {});
    for cw in [0x06u16, 0x07, 0x0F, 0x02] {
        download(&mut sim, 0, 0x6040, 0, &cw.to_le_bytes());
    }
    sim.poll(10, &mut |_| {});
    assert_eq!(state(&mut sim, 10) & 0x4F, 0x40, "option 2: 12 to switch on disabled");
    assert_eq!(download(&mut sim, 10, 0x605A, 0, &6i16.to_le_bytes()).data()[0], 0x60);
    for cw in [0x06u16, 0x07, 0x0F, 0x02] {
        download(&mut sim, 10, 0x6040, 0, &cw.to_le_bytes());
    }
    sim.poll(20, &mut |_| {});
    assert_eq!(state(&mut sim, 20), 0x07, "option 6: quick stop active");
    download(&mut sim, 20, 0x6040, 0, &0x0Fu16.to_le_bytes());
    assert_eq!(state(&mut sim, 20), 0x27, "16: operation enabled");
}
