"""A python-can bus that exchanges CAN frames with the odc interop tests over loopback TCP.

Wire format (tests/interop/README.md): every frame is one 16-byte record, the layout of Linux
SocketCAN's `struct can_frame` in little-endian:

    bytes 0-3   CAN identifier, u32 little-endian; bit 31 = 29-bit (extended) identifier,
                bit 30 = remote frame
    byte  4     data length, 0-8
    bytes 5-7   zero
    bytes 8-15  data, zero-padded

The Rust side listens on 127.0.0.1 and the Python side connects; nothing leaves the machine.
"""

import select
import socket
import struct
import threading
import time

import can

FRAME = struct.Struct("<IB3x8s")
EXTENDED = 0x8000_0000
REMOTE = 0x4000_0000


def encode(msg: can.Message) -> bytes:
    can_id = msg.arbitration_id
    if msg.is_extended_id:
        can_id |= EXTENDED
    if msg.is_remote_frame:
        can_id |= REMOTE
    return FRAME.pack(can_id, msg.dlc, bytes(msg.data).ljust(8, b"\0"))


def decode(record: bytes) -> can.Message:
    can_id, dlc, data = FRAME.unpack(record)
    return can.Message(
        arbitration_id=can_id & 0x1FFF_FFFF,
        is_extended_id=bool(can_id & EXTENDED),
        is_remote_frame=bool(can_id & REMOTE),
        dlc=dlc,
        data=data[: min(dlc, 8)],
        timestamp=time.time(),
    )


class SocketBus(can.BusABC):
    """`channel` is "HOST:PORT" of the Rust test's listener."""

    def __init__(self, channel: str, **kwargs):
        host, port = channel.rsplit(":", 1)
        self._sock = socket.create_connection((host, int(port)), timeout=10)
        self._sock.settimeout(None)
        self._sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._buf = bytearray()
        self._send_lock = threading.Lock()
        self.closed_by_peer = threading.Event()
        self.channel_info = f"odc loopback socket {channel}"
        super().__init__(channel=channel, **kwargs)

    def send(self, msg: can.Message, timeout=None) -> None:
        with self._send_lock:
            self._sock.sendall(encode(msg))

    def _recv_internal(self, timeout):
        deadline = None if timeout is None else time.monotonic() + timeout
        while len(self._buf) < FRAME.size:
            if self.closed_by_peer.is_set():
                # Nothing will come any more; do not spin the notifier thread.
                time.sleep(0.05 if timeout is None else min(timeout, 0.05))
                return None, False
            wait = None if deadline is None else max(0.0, deadline - time.monotonic())
            ready, _, _ = select.select([self._sock], [], [], wait)
            if not ready:
                return None, False
            chunk = self._sock.recv(4096)
            if not chunk:
                self.closed_by_peer.set()
                return None, False
            self._buf.extend(chunk)
        record = bytes(self._buf[: FRAME.size])
        del self._buf[: FRAME.size]
        return decode(record), False

    def shutdown(self) -> None:
        super().shutdown()
        try:
            self._sock.close()
        except OSError:
            pass


def open_bus(address):
    """The python-can bus at `address`: "HOST:PORT" of the Rust test's listener, or
    "slcan:PATH", python-can's own `slcan` interface on a serial port or pseudo-terminal
    (`odc simulate --slcan pty` prints the path)."""
    if address.startswith("slcan:"):
        return can.Bus(interface="slcan", channel=address[len("slcan:"):], bitrate=500000,
                       sleep_after_open=0)
    return SocketBus(address)


def open_network(address, max_seconds):
    """A python-canopen network on the bus at `address`, connected, under a watchdog that ends
    the process (exit 3) after `max_seconds`, should the Rust side vanish without closing
    the socket."""
    import os

    import canopen

    watchdog = threading.Timer(max_seconds, lambda: os._exit(3))
    watchdog.daemon = True
    watchdog.start()
    network = canopen.Network(open_bus(address))
    network.connect()
    return network
