"""python-canopen as the NMT master of an odc `node::Node` (tests/interop/tests/it/node.rs).

Loads the device file into a `canopen.RemoteNode` and drives the node the Rust test runs on the
loopback socket: NMT (reset, states and what the node answers in each), heartbeat written over
SDO, PDOs configured with `pdo.save()` (transmission types 1, 5, 254 with an event timer, a
remap, an RPDO), node guarding with python-canopen's guarding, EMCY through its EMCY consumer.
Every frame the node sends is recorded with the time it arrived. Prints one JSON line (counts
and what was seen) as the last line of stdout; the Rust test decides.
"""

import argparse
import json
import logging
import sys
import threading
import time
from collections import defaultdict

import canopen
from canopen import objectdictionary as odm
from canopen.objectdictionary import datatypes as dt
from canopen.sdo.exceptions import SdoAbortedError, SdoCommunicationError

from socketbus import open_bus

INT_TYPES = {
    dt.INTEGER8: 1, dt.INTEGER16: 2, dt.INTEGER32: 4,
    dt.UNSIGNED8: 1, dt.UNSIGNED16: 2, dt.UNSIGNED32: 4,
}


class Capture:
    """Every frame from the node, by CAN-ID, with its arrival time."""

    def __init__(self, network, ids):
        self.lock = threading.Lock()
        self.frames = defaultdict(list)
        for can_id in ids:
            network.subscribe(can_id, self.on_frame)

    def on_frame(self, can_id, data, _timestamp):
        with self.lock:
            self.frames[can_id].append((time.monotonic(), bytes(data)))

    def since(self, can_id, t0):
        with self.lock:
            return [(t, d) for t, d in self.frames[can_id] if t >= t0]

    def wait(self, can_id, t0, count, timeout):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            got = self.since(can_id, t0)
            if len(got) >= count:
                return got
            time.sleep(0.005)
        return self.since(can_id, t0)


def variables(od):
    for obj in od.values():
        if isinstance(obj, odm.ODVariable):
            yield obj
        else:
            yield from obj.values()


def mappable(od, writable, flagged=True):
    """Integer objects the file lets a PDO map (`flagged`; else any at 0x2000 and up),
    application objects first."""
    found = []
    for var in variables(od):
        if var.index < 0x1000 or var.data_type not in INT_TYPES:
            continue
        if flagged and not var.pdo_mappable:
            continue
        if not flagged and var.index < 0x2000:
            continue
        if writable and not var.writable:
            continue
        if not writable and not var.readable:
            continue
        # CiA 306: rww maps into RPDOs only, rwr and ro into TPDOs only (the node checks it).
        access = getattr(var, "access_type", "rw")
        if writable and access in ("rwr", "ro", "const"):
            continue
        if not writable and access in ("rww", "wo"):
            continue
        found.append(var)
    found.sort(key=lambda v: (v.index < 0x2000, v.index, v.subindex))
    return found


def in_limits(var, value):
    lo = var.min if var.min is not None else -(1 << 63)
    hi = var.max if var.max is not None else (1 << 64)
    return lo <= value <= hi


class Run:
    def __init__(self, network, node, node_id):
        self.network = network
        self.node = node
        self.id = node_id
        self.report = {"errors": []}
        self.cap = Capture(
            network,
            [0x700 + node_id, 0x80 + node_id] + [base + node_id for base in (0x180, 0x280, 0x380, 0x480)],
        )

    def err(self, what):
        self.report["errors"].append(what)

    def nmt(self, command, settle=0.05):
        self.node.nmt.send_command(command)
        time.sleep(settle)

    def sdo_answers(self):
        try:
            self.node.sdo.upload(0x1000, 0)
            return True
        except SdoCommunicationError:
            return False

    def tpdo_frames(self, seconds):
        t0 = time.monotonic()
        time.sleep(seconds)
        return sum(len(self.cap.since(base + self.id, t0)) for base in (0x180, 0x280, 0x380, 0x480))

    def nmt_states(self):
        r = self.report
        hb = 0x700 + self.id
        boots = 0
        for command in (0x81, 0x82):  # reset node, reset communication
            t0 = time.monotonic()
            self.node.nmt.send_command(command)
            got = self.cap.wait(hb, t0, 1, 3.0)
            if got and got[0][1] == b"\x00":
                boots += 1
            else:
                self.err(f"no boot-up after NMT 0x{command:02X}: {got}")
        r["bootups"] = boots
        r["sdo_preop"] = self.sdo_answers()
        r["tpdo_preop"] = self.tpdo_frames(0.2)
        self.nmt(0x02)
        r["sdo_stopped"] = self.sdo_answers()
        self.nmt(0x01)
        r["sdo_op"] = self.sdo_answers()
        self.nmt(0x80)
        r["sdo_preop_again"] = self.sdo_answers()

    def heartbeat(self):
        r = self.report
        hb = 0x700 + self.id
        if 0x1017 not in self.node.object_dictionary:
            r["heartbeat"] = None
            return
        self.node.sdo[0x1017].raw = 100
        t0 = time.monotonic()
        time.sleep(1.02)
        got = self.cap.since(hb, t0)
        r["heartbeat_preop"] = len(got)
        r["heartbeat_states_preop"] = sorted({d[0] for _, d in got})
        gaps = [b[0] - a[0] for a, b in zip(got, got[1:])]
        r["heartbeat_period_ms"] = round(1000 * sorted(gaps)[len(gaps) // 2]) if gaps else None
        self.nmt(0x01, settle=0.0)
        t1 = time.monotonic()
        time.sleep(0.35)
        got = [d[0] for t, d in self.cap.since(hb, t1)]
        r["heartbeat_states_op"] = sorted(set(got))
        # python-canopen's own view of the state, from the heartbeat.
        r["python_state_op"] = self.node.nmt.state
        self.nmt(0x80)
        self.node.sdo[0x1017].raw = 0

    def configure(self, pdo, variables, trans_type, event_timer=None):
        """`pdo.save()`; where the file makes the COB-ID read-only (save() writes it and
        fails), the same settings by SDO in pre-operational, COB-ID left alone."""
        pdo.clear()
        for v in variables:
            pdo.add_variable(v.index, v.subindex)
        pdo.trans_type = trans_type
        pdo.enabled = True
        if 3 in pdo.com_record and pdo.com_record[3].writable:
            pdo.inhibit_time = 0
        if event_timer is not None:
            pdo.event_timer = event_timer
        if pdo.com_record[1].writable:
            pdo.save()
            return "save"
        self.nmt(0x80)
        pdo.com_record[2].raw = trans_type
        if event_timer is not None:
            pdo.com_record[5].raw = event_timer
        pdo.map_array[0].raw = 0
        for sub, v in enumerate(variables, start=1):
            pdo.map_array[sub].raw = v.index << 16 | v.subindex << 8 | 8 * INT_TYPES[v.data_type]
        pdo.map_array[0].raw = len(variables)
        return "sdo"

    def tpdo(self):
        r = self.report
        od = self.node.object_dictionary
        readable = mappable(od, writable=False)
        r["tpdo_mappable_in_eds"] = bool(readable)
        if not readable:
            # The file flags no object as mappable (Lenze E94AYCCA): CiA 301 has the node
            # refuse any mapping entry (0x06040041); the PDO checks cannot run.
            others = mappable(od, writable=False, flagged=False)
            r["unflagged_mapping_refused"] = self.refuses_mapping(0x1A00, others)
            return
        if not readable:
            self.err("no readable integer object to map")
            return
        a = readable[0]
        b = next((v for v in readable[1:] if INT_TYPES[v.data_type] != INT_TYPES[a.data_type]), None)
        self.node.tpdo.read()
        t = self.node.tpdo[1]
        cob = 0x180 + self.id
        t.cob_id = cob
        how = set()

        def save(variables, trans_type, event_timer=None):
            how.add(self.configure(t, variables, trans_type, event_timer))
            self.nmt(0x01)

        self.nmt(0x80)
        save([a], 1)
        t0 = time.monotonic()
        for _ in range(10):
            self.network.sync.transmit()
            time.sleep(0.02)
        time.sleep(0.05)
        r["type1_per_10_syncs"] = len(self.cap.since(cob, t0))
        save([a], 5)
        t0 = time.monotonic()
        for _ in range(20):
            self.network.sync.transmit()
            time.sleep(0.02)
        time.sleep(0.05)
        r["type5_per_20_syncs"] = len(self.cap.since(cob, t0))
        r["event_timer"] = 5 in t.com_record
        if r["event_timer"]:
            save([a], 254, event_timer=50)
            t0 = time.monotonic()
            time.sleep(1.0)
            r["type254_50ms_per_second"] = len(self.cap.since(cob, t0))
        # Remap: one object, then two; length and content on the wire against SDO uploads.
        lengths, contents_ok = [], []
        for mapping in ([a], [a, b] if b else [a]):
            save(mapping, 1)
            expected = b"".join(self.node.sdo.upload(v.index, v.subindex)[: INT_TYPES[v.data_type]] for v in mapping)
            t0 = time.monotonic()
            self.network.sync.transmit()
            got = self.cap.wait(cob, t0, 1, 1.0)
            if not got:
                self.err(f"no TPDO after remap to {[hex(v.index) for v in mapping]}")
                continue
            lengths.append(len(got[0][1]))
            contents_ok.append(got[0][1] == expected)
            if got[0][1] != expected:
                self.err(f"TPDO {got[0][1].hex()} != SDO {expected.hex()}")
        r["remap_lengths"] = lengths
        r["remap_content_ok"] = contents_ok
        r["tpdo_objects"] = [f"0x{v.index:04X}:{v.subindex:02X}" for v in ([a, b] if b else [a])]
        r["tpdo_configured_by"] = sorted(how)
        self.nmt(0x80)
        # Back to no transmission (type 1 waits for a SYNC that no later step sends, or
        # disabled where the COB-ID is writable), so later steps see only what they cause.
        self.configure(t, [a], 1)
        if t.com_record[1].writable:
            t.enabled = False
            t.save()

    def refuses_mapping(self, mapping, candidates):
        """Whether the node refuses to map the first of `candidates` into `mapping`:1."""
        if not candidates:
            return None
        v = candidates[0]
        entry = (v.index << 16 | v.subindex << 8 | INT_TYPES[v.data_type] * 8).to_bytes(4, "little")
        # CiA 301 7.5.2.36/38: the PDO invalid (COB-ID bit 31) and its mapping disabled first.
        comm = mapping - 0x200
        cob = int.from_bytes(self.node.sdo.upload(comm, 1), "little")
        try:
            self.node.sdo.download(comm, 1, (cob | 0x80000000).to_bytes(4, "little"))
            self.node.sdo.download(mapping, 0, b"\0")
            self.node.sdo.download(mapping, 1, entry)
        except SdoAbortedError as e:
            return e.code == 0x06040041
        finally:
            self.node.sdo.download(comm, 1, cob.to_bytes(4, "little"))
        return False

    def rpdo_and_emcy(self):
        r = self.report
        od = self.node.object_dictionary
        if not mappable(od, writable=False) and not mappable(od, writable=True):
            # As in tpdo(): nothing flagged mappable, so no RPDO (nor its EMCY) to test.
            return
        candidates = (
            [v for v in mappable(od, writable=True) if v.index >= 0x2000]
            or mappable(od, writable=True)
            or mappable(od, writable=True, flagged=False)
        )
        r["rpdo_mappable_in_eds"] = bool(mappable(od, writable=True))
        target = None
        for v in candidates:
            signed = v.data_type in (dt.INTEGER8, dt.INTEGER16, dt.INTEGER32)
            try:
                raw = self.node.sdo.upload(v.index, v.subindex)
            except (SdoAbortedError, SdoCommunicationError):
                continue
            current = int.from_bytes(raw[: INT_TYPES[v.data_type]], "little", signed=signed)
            for value in (current + 1, current - 1, 1, 0):
                if value != current and in_limits(v, value) and value >= 0:
                    target = (v, value)
                    break
            if target:
                break
        if not target:
            self.err("no writable mappable integer object for the RPDO")
            return
        v, value = target
        self.node.rpdo.read()
        rp = self.node.rpdo[1]
        rp.cob_id = 0x200 + self.id
        r["rpdo_configured_by"] = self.configure(rp, [v], 255)
        self.nmt(0x01)
        rp.map[0].raw = value
        rp.transmit()
        time.sleep(0.1)
        back = self.node.sdo.upload(v.index, v.subindex)
        size = INT_TYPES[v.data_type]
        signed = v.data_type in (dt.INTEGER8, dt.INTEGER16, dt.INTEGER32)
        r["rpdo_object"] = f"0x{v.index:04X}:{v.subindex:02X}"
        r["rpdo_written"] = int.from_bytes(back[:size], "little", signed=signed) == value
        # EMCY: an RPDO one byte shorter than its mapping is not processed (CiA 301: 0x8210).
        # Read from the consumer's log: the node answers faster than emcy.wait() starts.
        seen = len(self.node.emcy.log)
        self.network.send_message(0x200 + self.id, bytes(size - 1))
        e = None
        end = time.monotonic() + 2
        while e is None and time.monotonic() < end:
            e = next((x for x in self.node.emcy.log[seen:] if x.code == 0x8210), None)
            time.sleep(0.01)
        if e is None:
            self.err("no EMCY 0x8210")
            r["emcy"] = None
        else:
            r["emcy"] = {"code": e.code, "register": e.register, "desc": e.get_desc(), "active": len(self.node.emcy.active)}
        if 0x1003 in od:
            try:
                r["history_0x1003"] = [self.node.sdo[0x1003][0].raw, self.node.sdo[0x1003][1].raw]
                self.node.sdo[0x1003][0].raw = 0
                r["history_cleared"] = self.node.sdo[0x1003][0].raw == 0
            except (SdoAbortedError, SdoCommunicationError) as ex:
                self.err(f"0x1003: {ex}")
        self.nmt(0x80)

    def guarding(self):
        r = self.report
        hb = 0x700 + self.id
        od = self.node.object_dictionary
        r["life_guarding"] = 0x100C in od and 0x100D in od
        if r["life_guarding"]:
            self.node.sdo[0x100C].raw = 100
            self.node.sdo[0x100D].raw = 3
        t0 = time.monotonic()
        self.node.nmt.start_node_guarding(0.1)
        time.sleep(1.02)
        r["python_state_guarded"] = self.node.nmt.state
        self.node.nmt.stop_node_guarding()
        time.sleep(0.05)
        got = [d for _, d in self.cap.since(hb, t0)]
        r["guarding_answers"] = len(got)
        r["guarding_states"] = sorted({d[0] & 0x7F for d in got})
        r["guarding_toggles_ok"] = all((x[0] ^ y[0]) & 0x80 for x, y in zip(got, got[1:]))
        # Life time 300 ms: the Rust side reports the loss.
        time.sleep(0.6)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--connect", required=True,
                    help="HOST:PORT of the Rust test, or slcan:PATH (socketbus.open_bus)")
    ap.add_argument("--eds", required=True)
    ap.add_argument("--node", type=int, default=5)
    ap.add_argument("--device", default="")
    args = ap.parse_args()
    logging.basicConfig(level=logging.ERROR, stream=sys.stderr)
    bus = open_bus(args.connect)
    network = canopen.Network(bus)
    network.connect()
    node = network.add_node(args.node, args.eds)
    node.sdo.RESPONSE_TIMEOUT = 0.5
    run = Run(network, node, args.node)
    steps = (run.nmt_states, run.heartbeat, run.tpdo, run.rpdo_and_emcy, run.guarding)
    for step in steps:
        try:
            step()
        except Exception as ex:  # reported, the Rust test fails on it
            run.err(f"{step.__name__}: {type(ex).__name__}: {ex}")
    network.disconnect()
    print(json.dumps(run.report))


if __name__ == "__main__":
    main()
