"""python-canopen as the master of several nodes on one bus (`odc simulate A@1 B@2 ...`).

The bus is the simulator's 16-byte records (`--bus tcp`, socketbus.py) or python-can's own
`socketcand` interface (`--bus socketcand`, against `odc simulate --socketcand`). Every node:
NMT reset (to all) and its boot-up, SDO uploads of 0x1000 and 0x1018:01 against the file,
a heartbeat of 100 ms written and read back over SDO, TPDO 1 mapped with `pdo.save()`
(transmission type 1), NMT start (to all) and its operational heartbeats, one SYNC and the
TPDO against an SDO upload of the mapped object, NMT stop (to all) and the stopped heartbeat.
Prints one JSON line, the last of stdout; the Rust test decides.
"""

import argparse
import json
import logging
import sys
import time

import can
import canopen

from node import INT_TYPES, Capture, mappable
from socketbus import SocketBus


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--connect", required=True, help="HOST:PORT of odc simulate")
    ap.add_argument("--bus", choices=["tcp", "socketcand"], default="tcp")
    ap.add_argument("--channel", default="can0", help="the socketcand bus")
    ap.add_argument("--node", action="append", required=True, help="ID=EDS")
    args = ap.parse_args()
    logging.basicConfig(level=logging.ERROR, stream=sys.stderr)
    if args.bus == "socketcand":
        host, port = args.connect.rsplit(":", 1)
        bus = can.Bus(interface="socketcand", channel=args.channel, host=host, port=int(port))
    else:
        bus = SocketBus(args.connect)
    network = canopen.Network(bus)
    network.connect()
    nodes = {}
    for spec in args.node:
        node_id, eds = spec.split("=", 1)
        node = network.add_node(int(node_id), eds)
        node.sdo.RESPONSE_TIMEOUT = 1.0
        nodes[int(node_id)] = node
    cap = Capture(network, [0x700 + i for i in nodes] + [0x180 + i for i in nodes])
    report = {"nodes": {}, "errors": []}
    per = {i: report["nodes"].setdefault(str(i), {}) for i in nodes}

    def step(name, f):
        try:
            f()
        except Exception as ex:  # reported; the Rust test fails on it
            report["errors"].append(f"{name}: {type(ex).__name__}: {ex}")

    def boot_ups():
        t0 = time.monotonic()
        network.nmt.send_command(0x81)
        for i in nodes:
            got = cap.wait(0x700 + i, t0, 1, 2.0)
            per[i]["boot_up"] = bool(got) and got[0][1] == b"\0"

    def sdo():
        for i, node in nodes.items():
            od = node.object_dictionary
            per[i]["device_type"] = node.sdo[0x1000].raw
            per[i]["device_type_in_file"] = od[0x1000].default
            per[i]["vendor_id"] = node.sdo[0x1018][1].raw
            per[i]["vendor_id_in_file"] = od[0x1018][1].default
            node.sdo[0x1017].raw = 100
            per[i]["heartbeat_ms"] = node.sdo[0x1017].raw

    def tpdo():
        for i, node in nodes.items():
            readable = mappable(node.object_dictionary, writable=False)
            if not readable:
                continue
            v = readable[0]
            node.tpdo.read()
            t = node.tpdo[1]
            t.clear()
            t.add_variable(v.index, v.subindex)
            t.trans_type = 1
            t.enabled = True
            t.save()
            per[i]["tpdo_object"] = f"0x{v.index:04X}:{v.subindex:02X}"
            per[i]["tpdo_bytes"] = INT_TYPES[v.data_type]

    def operational():
        t0 = time.monotonic()
        network.nmt.send_command(0x01)
        time.sleep(1.05)
        for i in nodes:
            beats = cap.since(0x700 + i, t0)
            per[i]["heartbeats_operational"] = sum(1 for _, d in beats if d == b"\x05")

    def sync():
        expected = {}
        for i, node in nodes.items():
            if "tpdo_object" in per[i]:
                index, sub = (int(x, 16) for x in per[i]["tpdo_object"].split(":"))
                expected[i] = node.sdo.upload(index, sub)[: per[i]["tpdo_bytes"]]
        t0 = time.monotonic()
        network.sync.transmit()
        for i, want in expected.items():
            got = cap.wait(0x180 + i, t0, 1, 1.0)
            per[i]["tpdo"] = got[0][1].hex() if got else None
            per[i]["tpdo_sdo"] = want.hex()

    def stopped():
        t0 = time.monotonic()
        network.nmt.send_command(0x02)
        for i in nodes:
            got = cap.wait(0x700 + i, t0, 2, 1.0)
            per[i]["stopped"] = bool(got) and got[-1][1] == b"\x04"

    for name, f in [("boot_ups", boot_ups), ("sdo", sdo), ("tpdo", tpdo),
                    ("operational", operational), ("sync", sync), ("stopped", stopped)]:
        step(name, f)
    network.disconnect()
    print(json.dumps(report))


if __name__ == "__main__":
    main()
