"""python-canopen's LocalNode as the slave of odc's SDO client (tests/interop/tests/it/python.rs).

Serves the device file on the Rust test's socket until the test closes it, then prints its data
store (what SDO downloads changed) as one JSON line on stdout.
"""

import argparse
import json
import logging
import sys
import time

import canopen

from socketbus import SocketBus


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--connect", required=True, help="HOST:PORT of the Rust test")
    ap.add_argument("--eds", required=True)
    ap.add_argument("--node", type=int, default=5)
    ap.add_argument("--max-seconds", type=float, default=120.0)
    args = ap.parse_args()
    logging.basicConfig(level=logging.ERROR, stream=sys.stderr)

    bus = SocketBus(args.connect)
    network = canopen.Network(bus)
    network.connect()
    node = canopen.LocalNode(args.node, args.eds)
    network.add_node(node)
    # The boot-up message (CiA 301 NMT error control, 0x700 + node, one byte 0): the Rust test
    # waits for it before its first request, as a master waits for a node to boot.
    network.send_message(0x700 + args.node, b"\x00")
    end = time.monotonic() + args.max_seconds
    try:
        while not bus.closed_by_peer.is_set() and time.monotonic() < end:
            time.sleep(0.02)
    finally:
        network.disconnect()
    store = {
        f"0x{index:04X}:{sub:02X}": data.hex()
        for index, subs in sorted(node.data_store.items())
        for sub, data in sorted(subs.items())
    }
    print(json.dumps({"data_store": store, "timed_out": not bus.closed_by_peer.is_set()}))


if __name__ == "__main__":
    main()
