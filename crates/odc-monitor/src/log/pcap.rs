//! pcap and pcapng captures of a SocketCAN interface (Wireshark, tcpdump, scapy), through the
//! `pcap-file` crate. Packets of link type 227 (`LINKTYPE_CAN_SOCKETCAN`) are read; others
//! are counted as problems. The packet, after tcpdump.org's link-type page: CAN-ID and flags
//! u32 in network byte order (bit 31 extended, bit 30 remote, bit 29 error frame), payload
//! length u8, FD flags u8 (0x01 bit rate switch, 0x02 error state indicator, 0x04 a CAN FD
//! frame), two reserved bytes, the data. A frame is CAN FD when the FD-frame flag is set,
//! its length is over 8, or the packet is 72 bytes long (`struct canfd_frame`).

use std::time::Duration;

use pcap_file::DataLink;
use pcap_file::pcap::PcapReader;
use pcap_file::pcapng::blocks::interface_description::InterfaceDescriptionOption;
use pcap_file::pcapng::{Block, PcapNgReader};

use super::{Entry, Location, Log, Problem, classic, fd};

/// Reads a pcap or pcapng capture into `log`.
pub fn read(bytes: &[u8], log: &mut Log) {
    if bytes.starts_with(&[0x0A, 0x0D, 0x0D, 0x0A]) {
        pcapng(bytes, log);
    } else {
        pcap(bytes, log);
    }
}

fn problem(log: &mut Log, n: usize, message: String) {
    log.problems.push(Problem { at: Location::Packet(n), message });
}

fn pcap(bytes: &[u8], log: &mut Log) {
    let mut reader = match PcapReader::new(bytes) {
        Ok(r) => r,
        Err(e) => return problem(log, 0, format!("not a pcap file: {e}")),
    };
    let link = reader.header().datalink;
    if link != DataLink::CAN_SOCKETCAN {
        return problem(log, 0, format!("link type {link:?}: SocketCAN captures are 227"));
    }
    let mut n = 0;
    while let Some(packet) = reader.next_packet() {
        n += 1;
        match packet {
            Ok(p) => push(log, n, p.timestamp, &p.data),
            Err(e) => return problem(log, n, format!("packet cut short: {e}")),
        }
    }
}

fn pcapng(bytes: &[u8], log: &mut Log) {
    let mut reader = match PcapNgReader::new(bytes) {
        Ok(r) => r,
        Err(e) => return problem(log, 0, format!("not a pcapng file: {e}")),
    };
    let mut n = 0;
    while let Some(block) = reader.next_block() {
        let (interface, timestamp, data): (u32, Duration, Vec<u8>) = match block {
            Ok(Block::EnhancedPacket(p)) => (p.interface_id, p.timestamp, p.data.into_owned()),
            Ok(Block::SimplePacket(p)) => (0, Duration::ZERO, p.data.into_owned()),
            Ok(_) => continue,
            Err(e) => return problem(log, n + 1, format!("block cut short: {e}")),
        };
        n += 1;
        let idb = reader.interfaces().get(interface as usize);
        match idb.map(|i| (i.linktype, resolution(&i.options))) {
            Some((DataLink::CAN_SOCKETCAN, ticks)) => {
                // pcap-file gives the raw count as nanoseconds; the interface says its unit.
                let seconds = timestamp.as_nanos() as f64 * ticks;
                push(log, n, Duration::try_from_secs_f64(seconds).unwrap_or_default(), &data);
            }
            other => problem(
                log,
                n,
                format!(
                    "link type {:?}: SocketCAN captures are 227",
                    other.map(|(link, _)| u32::from(link))
                ),
            ),
        }
    }
}

/// Seconds per timestamp tick of an interface (`if_tsresol`: 10^-n, or 2^-n with the top
/// bit set; 10^-6 without the option).
fn resolution(options: &[InterfaceDescriptionOption<'_>]) -> f64 {
    let resol = options.iter().find_map(|o| match o {
        InterfaceDescriptionOption::IfTsResol(r) => Some(*r),
        _ => None,
    });
    match resol {
        Some(r) if r & 0x80 != 0 => 2f64.powi(-i32::from(r & 0x7F)),
        Some(r) => 10f64.powi(-i32::from(r)),
        None => 1e-6,
    }
}

/// One SocketCAN packet as an entry, or a problem.
fn push(log: &mut Log, n: usize, timestamp: Duration, data: &[u8]) {
    let (Some(word), Some(&len), Some(&flags)) = (data.get(..4), data.get(4), data.get(5)) else {
        return problem(log, n, format!("a SocketCAN packet of {} bytes", data.len()));
    };
    let word = u32::from_be_bytes([word[0], word[1], word[2], word[3]]);
    if word & 0x2000_0000 != 0 {
        // An error frame: no CAN frame to decode.
        return;
    }
    let (extended, remote) = (word & 0x8000_0000 != 0, word & 0x4000_0000 != 0);
    let id = word & if extended { 0x1FFF_FFFF } else { 0x7FF };
    let is_fd = flags & 0x04 != 0 || len > 8 || data.len() == 72;
    let payload = data.get(8..8 + usize::from(len));
    let result = match payload {
        None if !remote => {
            Err(format!("length {len} but {} data bytes", data.len().saturating_sub(8)))
        }
        _ if is_fd => fd(id, extended, flags & 1 != 0, flags & 2 != 0, payload.unwrap_or(&[])),
        _ => classic(id, extended, remote, len, if remote { &[] } else { payload.unwrap_or(&[]) }),
    };
    match result {
        Ok(frame) => log.entries.push(Entry { time: Some(timestamp.as_secs_f64()), frame }),
        Err(message) => problem(log, n, message),
    }
}
