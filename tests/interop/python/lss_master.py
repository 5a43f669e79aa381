"""python-canopen's LssMaster (`network.lss`) against odc's LssSlave (tests/interop/tests/it/lss.rs).

One session on a slave without node-ID: identify non-configured, fastscan, inquire the address
and node-ID, configure node-ID, bit timing (a supported and an unsupported index), store,
activate bit timing, back to waiting (the slave then resets its communication: boot-up at the
new node-ID); identify remote slave; switch state selective with the address fastscan found,
a second node-ID, store, waiting, NMT reset communication (boot-up at the second node-ID); a
fastscan that must find nobody. Prints one JSON line of what it saw; the Rust test decides.
"""

import argparse
import json
import logging
import queue
import sys
import time

import canopen
from canopen.lss import LssError

from socketbus import open_network


def attempt(f, *args):
    try:
        r = f(*args)
        return {"ok": r if r is not None else True}
    except LssError as e:
        return {"error": str(e)}


def next_response(lss):
    try:
        return lss.responses.get(timeout=1.0)[0]
    except queue.Empty:
        return None


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--connect", required=True, help="HOST:PORT of the Rust test")
    ap.add_argument("--new-node", type=int, required=True)
    ap.add_argument("--second-node", type=int, required=True)
    ap.add_argument("--bit-timing", type=int, default=2)
    ap.add_argument("--max-seconds", type=float, default=120.0)
    args = ap.parse_args()
    logging.basicConfig(level=logging.ERROR, stream=sys.stderr)
    network = open_network(args.connect, args.max_seconds)
    bootups = []
    # Boot-up messages only: a heartbeat on the same CAN-ID has the state byte instead of 0.
    def on_nmt_error_control(cob, data, ts):
        if data == b"\x00":
            bootups.append([cob - 0x700, data.hex()])

    for n in range(1, 128):
        network.subscribe(0x700 + n, on_nmt_error_control)
    lss = network.lss
    # Fastscan waits this long for every bit that is set; the socket answers in microseconds.
    lss.RESPONSE_TIMEOUT = 0.2
    out = {}
    try:
        lss.send_identify_non_configured_remote_slave()
        out["non_configured"] = next_response(lss)
        found, ids = lss.fast_scan()
        out["fastscan"] = [found, ids]
        out["node_id_before"] = attempt(lss.inquire_node_id)
        out["inquire"] = [attempt(lss.inquire_lss_address, cs) for cs in (0x5A, 0x5B, 0x5C, 0x5D)]
        out["configure_node_id"] = attempt(lss.configure_node_id, args.new_node)
        out["configure_bit_timing"] = attempt(lss.configure_bit_timing, args.bit_timing)
        out["configure_bit_timing_5"] = attempt(lss.configure_bit_timing, 5)
        out["store"] = attempt(lss.store_configuration)
        lss.activate_bit_timing(10)
        lss.send_switch_state_global(lss.WAITING_STATE)
        time.sleep(0.3)
        out["bootups_after_waiting"] = list(bootups)
        if found:
            lss.send_identify_remote_slave(ids[0], ids[1], ids[2], ids[2], ids[3], ids[3])
            out["identify_remote"] = next_response(lss)
            out["selective"] = attempt(lss.send_switch_state_selective, *ids)
        out["node_id_now"] = attempt(lss.inquire_node_id)
        out["configure_second"] = attempt(lss.configure_node_id, args.second_node)
        out["store_second"] = attempt(lss.store_configuration)
        lss.send_switch_state_global(lss.WAITING_STATE)
        time.sleep(0.3)
        out["bootups_before_reset"] = list(bootups)
        network.send_message(0, bytes([0x82, args.new_node]))
        time.sleep(0.3)
        out["bootups"] = list(bootups)
        out["fastscan_configured"] = lss.fast_scan()[0]
    finally:
        network.disconnect()
    print(json.dumps(out))


if __name__ == "__main__":
    main()
