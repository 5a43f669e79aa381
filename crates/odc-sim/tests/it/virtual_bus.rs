//! The virtual bus with two TCP clients and the simulated LXM23A (node 5): each client sees
//! the other's frames and the device's answers, never its own frames.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::Path;
use std::thread;

use odc::can::CanFrame;
use odc::sdo::Bus;
use odc::transport::tcp::TcpCan;
use odc_sim::{SimDevice, VirtualBus};

/// The next frame within 5 s, or `None`.
fn next(bus: &mut TcpCan) -> Option<CanFrame> {
    let deadline = bus.now() + odc::time::Duration::from_millis(5000);
    bus.recv(deadline).unwrap()
}

/// Nothing more within 200 ms.
fn quiet(bus: &mut TcpCan) -> bool {
    let deadline = bus.now() + odc::time::Duration::from_millis(200);
    bus.recv(deadline).unwrap().is_none()
}

#[test]
fn clients_see_each_other_and_the_device() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../eds/lxm23a.eds");
    let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
    let mut device = SimDevice::new(loaded.device().unwrap(), odc::node_id!(5));
    assert!(device.is_drive());
    let bus = VirtualBus::bind("127.0.0.1:0").unwrap();
    let addr = bus.local_addr();
    let stop = bus.stop_handle();
    let runner = thread::spawn(move || {
        bus.run(&mut device, &mut |_| {});
        device
    });
    let mut a = TcpCan::connect(addr).unwrap();
    let mut b = TcpCan::connect(addr).unwrap();
    // Until B is on the bus, A's frames do not reach it: A repeats a frame until B has it.
    let hello = CanFrame::from_slice(0x123, &[1, 2, 3]).unwrap();
    let mut tries = 0;
    loop {
        a.send(&hello).unwrap();
        let deadline = b.now() + odc::time::Duration::from_millis(100);
        if b.recv(deadline).unwrap() == Some(hello) {
            break;
        }
        tries += 1;
        assert!(tries < 50, "B never saw A's frame");
    }
    while !quiet(&mut b) {}

    // A uploads 0x1000 (device type) from node 5: A gets the answer, B the request and answer.
    let request = CanFrame::new(0x605, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]).unwrap();
    // 0x1000 of eds/lxm23a.eds: 0x04020192 (the manual's object 1000h).
    let answer = CanFrame::new(0x585, [0x43, 0x00, 0x10, 0x00, 0x92, 0x01, 0x02, 0x04]).unwrap();
    a.send(&request).unwrap();
    assert_eq!(next(&mut a), Some(answer));
    assert_eq!(next(&mut b), Some(request));
    assert_eq!(next(&mut b), Some(answer));
    assert!(quiet(&mut a), "A must not get its own request back");

    // B's frame reaches A; the device does not answer a PDO it has no use for.
    let pdo = CanFrame::from_slice(0x181, &[0xAA, 0xBB]).unwrap();
    b.send(&pdo).unwrap();
    assert_eq!(next(&mut a), Some(pdo));
    assert!(quiet(&mut b));

    // NMT reset node (0x000: 0x81, node 5): both see the command (B) and the boot-up.
    let reset = CanFrame::from_slice(0x000, &[0x81, 5]).unwrap();
    let boot_up = CanFrame::from_slice(0x705, &[0]).unwrap();
    a.send(&reset).unwrap();
    assert_eq!(next(&mut a), Some(boot_up));
    assert_eq!(next(&mut b), Some(reset));
    assert_eq!(next(&mut b), Some(boot_up));

    // The drive answers its statusword over SDO: "switch on disabled" after the boot-up.
    a.send(&CanFrame::new(0x605, [0x40, 0x41, 0x60, 0x00, 0, 0, 0, 0]).unwrap()).unwrap();
    let sw = next(&mut a).unwrap();
    assert_eq!(sw.data()[..4], [0x4B, 0x41, 0x60, 0x00]);
    assert_eq!(u16::from_le_bytes([sw.data()[4], sw.data()[5]]) & 0x6F, 0x40);

    stop.stop();
    let device = runner.join().unwrap();
    assert_eq!(device.node_id(), Some(odc::node_id!(5)));
}

/// The same device loop on a plain [`Bus`] (what `--can` runs on SocketCAN): here one end of
/// a TCP link, the test's master on the other.
#[test]
fn device_loop_on_any_bus() {
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};

    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../eds/lenze-e94aycca.eds");
    let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
    let mut device = SimDevice::new(loaded.device().unwrap(), odc::node_id!(9));
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let mut master = TcpCan::connect(listener.local_addr().unwrap()).unwrap();
    let mut link = TcpCan::new(listener.accept().unwrap().0).unwrap();
    let stop = Arc::new(AtomicBool::new(false));
    let stopped = Arc::clone(&stop);
    let runner = thread::spawn(move || {
        odc_sim::run_on_bus(&mut link, &mut device, 10, || stopped.load(Ordering::Relaxed))
    });
    assert_eq!(next(&mut master), Some(CanFrame::from_slice(0x709, &[0]).unwrap()), "boot-up");
    master.send(&CanFrame::new(0x609, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]).unwrap()).unwrap();
    let answer = next(&mut master).unwrap();
    assert_eq!((answer.id(), answer.data()[0]), (0x589, 0x43), "{answer:02X?}");
    stop.store(true, Ordering::Relaxed);
    runner.join().unwrap().unwrap();
}

/// NMT reset communication restores 0x1000–0x1FFF and keeps the application's values; reset
/// node restores both (CiA 301 §7.3.2.2.1).
#[test]
fn resets_restore_their_areas() {
    use odc::slave::ObjectDictionary;
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../eds/lxm23a.eds");
    let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
    let mut device = SimDevice::new(loaded.device().unwrap(), odc::node_id!(5));
    let mut out = Vec::new();
    device.start(0, &mut |f| out.push(f));
    // Expedited SDO download of `data` (1–4 bytes) to `index`:00.
    let write = |d: &mut SimDevice, index: u16, data: &[u8]| {
        let mut out = Vec::new();
        let [lo, hi] = index.to_le_bytes();
        let mut frame = [0x23 | ((4 - data.len() as u8) << 2), lo, hi, 0, 0, 0, 0, 0];
        frame[4..4 + data.len()].copy_from_slice(data);
        d.handle(&CanFrame::new(0x605, frame).unwrap(), 0, &mut |f| out.push(f));
        assert_eq!(out[0].data()[0], 0x60, "{index:04X}: {:02X?}", out[0]);
    };
    let read = |d: &SimDevice, index: u16| {
        let mut b = [0u8; 4];
        d.dictionary().read(index, 0, &mut b).unwrap();
        u32::from_le_bytes(b)
    };
    let (heartbeat, target) = (read(&device, 0x1017), read(&device, 0x607A));
    write(&mut device, 0x1017, &500u16.to_le_bytes()); // producer heartbeat time
    write(&mut device, 0x607A, &1234i32.to_le_bytes()); // target position
    out.clear();
    device.handle(&CanFrame::from_slice(0, &[0x82, 5]).unwrap(), 0, &mut |f| out.push(f));
    assert_eq!(out, [CanFrame::from_slice(0x705, &[0]).unwrap()]);
    assert_eq!((read(&device, 0x1017), read(&device, 0x607A)), (heartbeat, 1234));
    write(&mut device, 0x1017, &500u16.to_le_bytes());
    device.handle(&CanFrame::from_slice(0, &[0x81, 0]).unwrap(), 0, &mut |f| out.push(f));
    assert_eq!((read(&device, 0x1017), read(&device, 0x607A)), (heartbeat, target));
    assert_ne!(heartbeat, 500);
}

/// Two devices on one bus served as socketcand (`VirtualBus::bind_socketcand`, `run_all`),
/// with odc's socketcand client: NMT reset of all nodes gives both boot-ups, each answers
/// SDO on its own node-ID only; the server greets, refuses another bus and answers unknown
/// commands as socketcand does.
#[test]
fn socketcand_bus_with_two_devices() {
    use odc::transport::socketcand::Socketcand;
    use std::io::{Read, Write};

    let load = |file: &str, id: u8| {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(file);
        let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
        SimDevice::new(loaded.device().unwrap(), odc::cob::NodeId::new(id))
    };
    let mut devices = vec![load("eds/lxm23a.eds", 5), load("eds/lenze-e94aycca.eds", 9)];
    let bus = VirtualBus::bind_socketcand("127.0.0.1:0", "can0").unwrap();
    assert_eq!(bus.channel(), Some("can0"));
    let addr = bus.local_addr();
    let stop = bus.stop_handle();
    let runner = thread::spawn(move || {
        bus.run_all(&mut devices, &mut |_| {});
        devices
    });

    // The handshake as text: the greeting alone, another bus refused and the connection closed.
    let mut raw = std::net::TcpStream::connect(addr).unwrap();
    raw.set_read_timeout(Some(std::time::Duration::from_secs(5))).unwrap();
    let mut buf = [0u8; 256];
    let n = raw.read(&mut buf).unwrap();
    assert_eq!(&buf[..n], b"< hi >");
    raw.write_all(b"< rawmode >").unwrap();
    let n = raw.read(&mut buf).unwrap();
    assert_eq!(&buf[..n], b"< error unknown command >");
    raw.write_all(b"< open vcan7 >").unwrap();
    let n = raw.read(&mut buf).unwrap();
    assert_eq!(&buf[..n], b"< error could not open bus >");
    assert_eq!(raw.read(&mut buf).unwrap(), 0, "the server closes after refusing a bus");

    let mut a = Socketcand::connect(addr, "can0").unwrap();
    let next = |bus: &mut Socketcand| {
        let deadline = bus.now() + odc::time::Duration::from_millis(5000);
        bus.recv(deadline).unwrap()
    };
    a.send(&CanFrame::from_slice(0x000, &[0x81, 0]).unwrap()).unwrap();
    let mut boot_ups = [next(&mut a), next(&mut a)].map(|f| f.map(|f| (f.id(), f.data()[0])));
    boot_ups.sort();
    assert_eq!(boot_ups, [Some((0x705, 0)), Some((0x709, 0))]);
    for node in [5u32, 9] {
        a.send(&CanFrame::new(0x600 + node, [0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0]).unwrap())
            .unwrap();
        let answer = next(&mut a).unwrap();
        assert_eq!((answer.id(), answer.data()[0]), (0x580 + node, 0x43), "{answer:02X?}");
    }
    // A 29-bit frame crosses the bus to another socketcand client.
    let mut b = Socketcand::connect(addr, "can0").unwrap();
    std::thread::sleep(odc_sim::socketcand::RAW_HOLD * 2);
    let ext = CanFrame::extended(0x18FF_0001, &[1, 2]).unwrap();
    a.send(&ext).unwrap();
    assert_eq!(next(&mut b), Some(ext));

    stop.stop();
    let devices = runner.join().unwrap();
    assert_eq!(devices.len(), 2);
}
