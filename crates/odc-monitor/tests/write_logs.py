"""Writes the frames of tests/logs.rs with other tools' writers, into the directory given:
python-can's `can.Logger` (frames.log: CanutilsLogWriter, candump -l; frames.asc: ASCWriter;
frames.blf: BLFWriter) and scapy (frames.pcap, frames.pcapng: link type 227). The frames are
those of FRAMES in tests/logs.rs: keep the two lists equal."""

import os
import sys

import can
from scapy.layers.can import CAN, CANFD
from scapy.utils import PcapNgWriter, wrpcap

T0 = 1700000000.0

# (seconds after T0, id, extended, remote, fd, brs, dlc, data)
FRAMES = [
    (0.0, 0x185, False, False, False, False, 2, bytes([0x40, 0x06])),
    (0.1, 0x701, False, True, False, False, 1, b""),
    (0.2, 0x12345678, True, False, False, False, 2, bytes([0x01, 0x02])),
    (0.3, 0x123, False, False, True, True, 12, bytes(range(12))),
    (0.4, 0x7FF, False, False, False, False, 0, b""),
    (0.5, 0x605, False, False, False, False, 8, bytes([0x40, 0x00, 0x10, 0, 0, 0, 0, 0])),
]


def python_can(out):
    for name in ("frames.log", "frames.asc", "frames.blf"):
        logger = can.Logger(os.path.join(out, name))
        for t, ident, ext, rtr, fd, brs, dlc, data in FRAMES:
            logger.on_message_received(
                can.Message(timestamp=T0 + t, arbitration_id=ident, is_extended_id=ext,
                            is_remote_frame=rtr, is_fd=fd, bitrate_switch=brs, dlc=dlc,
                            data=data, channel="can0"))
        logger.stop()


def scapy(out):
    packets = []
    for t, ident, ext, rtr, fd, brs, dlc, data in FRAMES:
        flags = (["extended"] if ext else []) + (["remote_transmission_request"] if rtr else [])
        if fd:
            p = CANFD(identifier=ident, flags=flags, fd_flags=1 if brs else 0, data=data)
        else:
            p = CAN(identifier=ident, flags=flags, length=dlc, data=data)
        p.time = T0 + t
        packets.append(p)
    wrpcap(os.path.join(out, "frames.pcap"), packets)
    with PcapNgWriter(os.path.join(out, "frames.pcapng")) as w:
        for p in packets:
            w.write(p)


if __name__ == "__main__":
    python_can(sys.argv[1])
    scapy(sys.argv[1])
