"""python-canopen's SDO client in block mode against odc's server (tests/interop/tests/it/block.rs).

Block-uploads every object of --read, block-downloads the given bytes to every object of
--write and block-uploads them back, with `SdoClient.open(..., block_transfer=True)` (CRC
requested, as python-canopen does by default). Prints one JSON line: for each address the
hex it read, or the abort code / error it got. The Rust test compares and decides.
"""

import argparse
import json
import logging
import sys

import canopen
from canopen.sdo.exceptions import SdoAbortedError, SdoCommunicationError

from socketbus import open_network


def parse_addr(text):
    index, sub = text.split(":")
    return int(index, 16), int(sub, 16)


def block_read(node, index, sub):
    try:
        with node.sdo.open(index, sub, "rb", block_transfer=True) as f:
            return {"hex": f.read().hex()}
    except SdoAbortedError as e:
        return {"abort": e.code}
    except SdoCommunicationError as e:
        return {"error": str(e)}


def block_write(node, index, sub, data):
    try:
        with node.sdo.open(index, sub, "wb", size=len(data), block_transfer=True) as f:
            f.write(data)
        return {"ok": True}
    except SdoAbortedError as e:
        return {"abort": e.code}
    except SdoCommunicationError as e:
        return {"error": str(e)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--connect", required=True, help="HOST:PORT of the Rust test")
    ap.add_argument("--node", type=int, default=5)
    ap.add_argument("--read", default="", help="comma-separated IIII:SS (hex)")
    ap.add_argument("--write", default="", help="comma-separated IIII:SS=HEX")
    ap.add_argument("--max-seconds", type=float, default=120.0)
    args = ap.parse_args()
    logging.basicConfig(level=logging.ERROR, stream=sys.stderr)
    network = open_network(args.connect, args.max_seconds)
    # No dictionary: block transfer by address needs none.
    node = canopen.RemoteNode(args.node, canopen.ObjectDictionary())
    network.add_node(node)
    node.sdo.RESPONSE_TIMEOUT = 2.0
    out = {"read": {}, "written": {}, "read_back": {}}
    try:
        for a in filter(None, args.read.split(",")):
            out["read"][a] = block_read(node, *parse_addr(a))
        for w in filter(None, args.write.split(",")):
            a, hexdata = w.split("=")
            index, sub = parse_addr(a)
            out["written"][a] = block_write(node, index, sub, bytes.fromhex(hexdata))
            out["read_back"][a] = block_read(node, index, sub)
    finally:
        network.disconnect()
    print(json.dumps(out))


if __name__ == "__main__":
    main()
