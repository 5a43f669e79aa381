"""Records a CiA 402 session with python-can's own logger: a second connection to the Rust
test's virtual bus (socketbus.py) hands every frame to `can.Logger(PATH)` (a `.log` path:
CanutilsLogWriter, candump's `-l` format), while python-canopen drives node 5: NMT, profile
position mode over SDO, the power state machine and a move over the default RPDOs (0x205
controlword, 0x305 controlword + target position), SYNCs, reads of the statusword and the
position. crates/odc-cli/tests/monitor_logs.rs compares `odc monitor --log PATH` with the
live `odc monitor --tcp` of the same session."""

import argparse
import struct
import sys
import time

import can
import canopen

from socketbus import SocketBus, open_network


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--connect", required=True, help="HOST:PORT of the Rust test")
    ap.add_argument("--eds", required=True)
    ap.add_argument("--log", required=True, help="the candump -l file to write")
    args = ap.parse_args()
    # The recorder first, so that it sees the whole session.
    recorder = SocketBus(args.connect)
    logger = can.Logger(args.log)
    notifier = can.Notifier(recorder, [logger])
    time.sleep(0.2)
    network = open_network(args.connect, 60)
    node = canopen.RemoteNode(5, args.eds)
    network.add_node(node)
    node.sdo.RESPONSE_TIMEOUT = 2.0

    def pdo(cob, data):
        network.send_message(cob, data)
        time.sleep(0.05)

    node.nmt.send_command(0x80)  # pre-operational
    time.sleep(0.05)
    node.sdo[0x6060].raw = 1  # profile position
    node.nmt.send_command(0x01)  # operational
    time.sleep(0.05)
    for word in (0x06, 0x07, 0x0F):  # shutdown, switch on, enable operation
        pdo(0x205, struct.pack("<H", word))
    pdo(0x305, struct.pack("<Hi", 0x1F, 1000))  # new set-point: 1000
    pdo(0x305, struct.pack("<Hi", 0x0F, 1000))
    for _ in range(5):
        pdo(0x80, b"")
    status = node.sdo[0x6041].raw
    position = node.sdo[0x6064].raw
    mode = node.sdo[0x6061].raw
    pdo(0x205, struct.pack("<H", 0x06))  # shutdown
    node.nmt.send_command(0x80)
    time.sleep(0.3)
    network.disconnect()
    notifier.stop()
    logger.stop()
    recorder.shutdown()
    print(f"statusword 0x{status:04X}, position {position}, mode {mode}", file=sys.stderr)


if __name__ == "__main__":
    main()
