//! Several [`SimDevice`]s on one bus. On a real bus every node receives every frame but its
//! own; simulated devices share one process and one transport, so the frames one device sends
//! are handed to the others here (and their answers, in turn), and every frame any device sent
//! goes out to the transport for the clients.

use std::collections::VecDeque;

use odc::can::CanFrame;

use crate::SimDevice;

/// Frames handed between the devices for one outside event, at most: a guard against two
/// devices that answer each other forever (each PDO triggering the other's); past it the
/// rest is dropped and counted in [`Routed::dropped`].
pub const MAX_ROUTED: usize = 4096;

/// What one call did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Routed {
    /// Frames the devices sent.
    pub sent: usize,
    /// Frames dropped after [`MAX_ROUTED`].
    pub dropped: usize,
}

/// Boots every device (its boot-up), then hands each boot-up to the others. Every frame the
/// devices send goes to `out`.
pub fn start_all(devices: &mut [SimDevice], now_ms: u64, out: &mut impl FnMut(CanFrame)) -> Routed {
    let mut queue = VecDeque::new();
    for (i, d) in devices.iter_mut().enumerate() {
        d.start(now_ms, &mut |f| queue.push_back((Some(i), f)));
    }
    route(devices, queue, now_ms, out)
}

/// A frame from outside (a client of the bus): to every device, and what they send to the
/// others and to `out`.
pub fn handle_all(
    devices: &mut [SimDevice],
    frame: &CanFrame,
    now_ms: u64,
    out: &mut impl FnMut(CanFrame),
) -> Routed {
    let mut queue = VecDeque::new();
    queue.push_back((None, *frame));
    route(devices, queue, now_ms, out)
}

/// Every device's timer tick, and what they send to the others and to `out`.
pub fn poll_all(devices: &mut [SimDevice], now_ms: u64, out: &mut impl FnMut(CanFrame)) -> Routed {
    let mut queue = VecDeque::new();
    for (i, d) in devices.iter_mut().enumerate() {
        d.poll(now_ms, &mut |f| queue.push_back((Some(i), f)));
    }
    route(devices, queue, now_ms, out)
}

/// Delivers queued frames (with the device that sent each, `None` from outside) to every
/// other device, in order, queueing what they send in turn; a device's frames go to `out`.
fn route(
    devices: &mut [SimDevice],
    mut queue: VecDeque<(Option<usize>, CanFrame)>,
    now_ms: u64,
    out: &mut impl FnMut(CanFrame),
) -> Routed {
    let mut routed = Routed::default();
    let mut handed = 0usize;
    while let Some((from, frame)) = queue.pop_front() {
        if from.is_some() {
            routed.sent += 1;
            out(frame);
        }
        if handed >= MAX_ROUTED {
            routed.dropped += queue.len();
            // The sent frames still reach the bus; only their delivery to devices stops.
            for (from, frame) in queue.drain(..) {
                if from.is_some() {
                    routed.sent += 1;
                    out(frame);
                }
            }
            break;
        }
        for (i, d) in devices.iter_mut().enumerate() {
            if Some(i) != from {
                handed += 1;
                d.handle(&frame, now_ms, &mut |f| queue.push_back((Some(i), f)));
            }
        }
    }
    routed
}

#[cfg(test)]
mod tests {
    use super::*;

    fn device(file: &str, id: u8) -> SimDevice {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").join(file);
        let loaded = odc_pipeline::load(&path, &odc_pipeline::Options::new()).unwrap();
        SimDevice::new(loaded.device().unwrap(), odc::cob::NodeId::new(id))
    }

    /// An expedited SDO download of a u16 or u32 from outside; the answer must be a success.
    fn write(devices: &mut [SimDevice], node: u32, index: u16, sub: u8, value: &[u8]) {
        let [lo, hi] = index.to_le_bytes();
        let size_bits = (4 - value.len() as u8) << 2;
        let mut data = [0x23 | size_bits, lo, hi, sub, 0, 0, 0, 0];
        data[4..4 + value.len()].copy_from_slice(value);
        let mut out = Vec::new();
        handle_all(devices, &CanFrame::new(0x600 + node, data).unwrap(), 0, &mut |f| out.push(f));
        assert_eq!(out.len(), 1, "{out:02X?}");
        assert_eq!((out[0].id(), out[0].data()[0]), (0x580 + node, 0x60), "{out:02X?}");
    }

    /// Node 9 watches node 5's heartbeat (0x1016): it sees node 5's heartbeats only because
    /// they are handed over here, and when node 5 stops producing them, node 9 reports the
    /// loss with EMCY 0x8130 (CiA 301 §7.2.8.3.2.2; watching starts at the first heartbeat).
    #[test]
    fn one_device_hears_another() {
        let mut devices = [device("eds/lxm23a.eds", 5), device("eds/lenze-e94aycca.eds", 9)];
        let mut out = Vec::new();
        start_all(&mut devices, 0, &mut |f| out.push(f));
        let boot_ups: Vec<u32> = out.iter().map(CanFrame::id).collect();
        assert_eq!(boot_ups, [0x705, 0x709]);
        write(&mut devices, 5, 0x1017, 0, &20u16.to_le_bytes());
        write(&mut devices, 9, 0x1016, 1, &((5u32 << 16) | 100).to_le_bytes());
        let mut sent = Vec::new();
        for ms in (10..=300).step_by(10) {
            poll_all(&mut devices, ms, &mut |f| sent.push((ms, f)));
        }
        assert!(sent.iter().filter(|(_, f)| f.id() == 0x705).count() >= 10, "{sent:02X?}");
        assert!(!sent.iter().any(|(_, f)| f.id() == 0x089), "{sent:02X?}");
        write(&mut devices, 5, 0x1017, 0, &0u16.to_le_bytes());
        sent.clear();
        for ms in (310..=600).step_by(10) {
            poll_all(&mut devices, ms, &mut |f| sent.push((ms, f)));
        }
        let emcy = sent.iter().find(|(_, f)| f.id() == 0x089).map(|(_, f)| f.data());
        assert_eq!(emcy.map(|d| u16::from_le_bytes([d[0], d[1]])), Some(0x8130), "{sent:02X?}");
    }

    /// A frame from outside that both devices answer: both answers go out, in device order.
    #[test]
    fn routing_reports_what_it_sent() {
        let mut devices = [device("eds/lxm23a.eds", 5), device("eds/lenze-e94aycca.eds", 9)];
        start_all(&mut devices, 0, &mut |_| {});
        // NMT reset communication of all nodes: both boot again, and each boot-up is handed
        // to the other device (which ignores it).
        let mut out = Vec::new();
        let r =
            handle_all(&mut devices, &CanFrame::from_slice(0, &[0x82, 0]).unwrap(), 0, &mut |f| {
                out.push(f)
            });
        assert_eq!(r, Routed { sent: 2, dropped: 0 });
        assert_eq!(out.iter().map(CanFrame::id).collect::<Vec<_>>(), [0x705, 0x709]);
    }
}
