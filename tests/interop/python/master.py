"""python-canopen as the master of an odc-generated slave (tests/interop/tests/it/python.rs).

Connects to the Rust test's socket, loads the same device file into a `canopen.RemoteNode` and
checks, object by object, what the slave answers. Prints one JSON line (counts, the PDO
mappings it saved, disagreements) as the last line of stdout; the Rust test decides.

Which side is right when they disagree is decided per CiA 301 in the Rust test and in
tests/interop/README.md; this script only reports.
"""

import argparse
import json
import logging
import struct
import sys
import threading

import canopen
from canopen import objectdictionary as odm
from canopen.objectdictionary import datatypes as dt
from canopen.sdo.exceptions import SdoAbortedError, SdoCommunicationError

from socketbus import open_network

INT_RANGE = {
    dt.BOOLEAN: (0, 1, 1),
    dt.INTEGER8: (-(1 << 7), (1 << 7) - 1, 1),
    dt.INTEGER16: (-(1 << 15), (1 << 15) - 1, 2),
    dt.INTEGER24: (-(1 << 23), (1 << 23) - 1, 3),
    dt.INTEGER32: (-(1 << 31), (1 << 31) - 1, 4),
    dt.INTEGER40: (-(1 << 39), (1 << 39) - 1, 5),
    dt.INTEGER48: (-(1 << 47), (1 << 47) - 1, 6),
    dt.INTEGER56: (-(1 << 55), (1 << 55) - 1, 7),
    dt.INTEGER64: (-(1 << 63), (1 << 63) - 1, 8),
    dt.UNSIGNED8: (0, (1 << 8) - 1, 1),
    dt.UNSIGNED16: (0, (1 << 16) - 1, 2),
    dt.UNSIGNED24: (0, (1 << 24) - 1, 3),
    dt.UNSIGNED32: (0, (1 << 32) - 1, 4),
    dt.UNSIGNED40: (0, (1 << 40) - 1, 5),
    dt.UNSIGNED48: (0, (1 << 48) - 1, 6),
    dt.UNSIGNED56: (0, (1 << 56) - 1, 7),
    dt.UNSIGNED64: (0, (1 << 64) - 1, 8),
}

ABORT_READ_ONLY = 0x06010002
ABORT_WRITE_ONLY = 0x06010001
ABORT_NO_OBJECT = 0x06020000
ABORT_NO_SUB = 0x06090011
ABORTS_TOO_HIGH = (0x06090031, 0x06090030)
ABORTS_TOO_LOW = (0x06090032, 0x06090030)


def int_bytes(value, data_type):
    lo, hi, size = INT_RANGE[data_type]
    return (value & ((1 << (8 * size)) - 1)).to_bytes(size, "little")


def is_dummy(var):
    """python-canopen adds the [DummyUsage] data types 0x0001-0x0007 to its dictionary as
    const objects; the device file has no such sections."""
    return var.index < 0x0020 and var.name.startswith("Dummy")


def variables(od):
    for obj in od.values():
        if isinstance(obj, odm.ODVariable):
            yield obj
        else:
            yield from obj.values()


def addr(var):
    return f"0x{var.index:04X}:{var.subindex:02X}"


class Run:
    def __init__(self, node, device):
        self.node = node
        self.sdo = node.sdo
        self.out = {
            "device": device,
            "read": 0,
            "read_without_default": 0,
            "written": 0,
            "aborts": 0,
            "abort_codes": {},
            "pdo_compared": 0,
            "saved": [],
            "skipped": {},
            "settled": {},
            "disagreements": [],
        }

    def disagree(self, kind, var_or_addr, **detail):
        where = var_or_addr if isinstance(var_or_addr, str) else addr(var_or_addr)
        self.out["disagreements"].append({"kind": kind, "addr": where, **detail})

    def settle(self, why, where):
        """A difference with python-canopen decided per CiA 301/306 (see README.md)."""
        self.out["settled"].setdefault(why, []).append(where)

    def skip(self, why):
        self.out["skipped"][why] = self.out["skipped"].get(why, 0) + 1

    def expect_abort(self, what, codes, action, where):
        """Runs `action`, which must end in an abort with one of `codes`."""
        try:
            action()
        except SdoAbortedError as e:
            if e.code in codes:
                self.out["aborts"] += 1
                key = f"0x{e.code:08X}"
                self.out["abort_codes"][key] = self.out["abort_codes"].get(key, 0) + 1
                return True
            self.disagree(what, where, got=f"0x{e.code:08X}", want=[f"0x{c:08X}" for c in codes])
            return False
        except SdoCommunicationError as e:
            self.disagree(what, where, got=str(e))
            return False
        self.disagree(what, where, got="no abort", want=[f"0x{c:08X}" for c in codes])
        return False

    def upload(self, var):
        return self.sdo.upload(var.index, var.subindex)

    # --- 1. every readable object against the device file's default ---------------------------
    def expected(self, var):
        default = var.value if var.value is not None else var.default
        if default is None:
            return None
        return var.encode_raw(default)

    def read_all(self):
        for var in variables(self.node.object_dictionary):
            if is_dummy(var):
                # CiA 306: [DummyUsage] says which data types may fill PDO gaps; the objects of
                # the device are those of its object lists, which do not hold 0x0001-0x0007.
                # odc serves the file's objects and answers 0x06020000, python-canopen
                # invented the object.
                if self.expect_abort("dummy data type", (ABORT_NO_OBJECT,),
                                     lambda v=var: self.upload(v), addr(var)):
                    self.settle("DummyUsage index is no object (python-canopen lists it)", addr(var))
                continue
            if not var.readable:
                self.expect_abort("read of write-only", (ABORT_WRITE_ONLY,),
                                  lambda v=var: self.upload(v), addr(var))
                continue
            try:
                data = self.upload(var)
            except (SdoAbortedError, SdoCommunicationError) as e:
                self.disagree("read failed", var, got=str(e))
                continue
            self.out["read"] += 1
            try:
                want = self.expected(var)
            except (ValueError, TypeError) as e:
                self.disagree("default does not encode (python-canopen)", var, got=str(e))
                continue
            if want is None:
                # No default in the file: odc's slave starts such entries at zero.
                self.out["read_without_default"] += 1
                continue
            if var.data_type == dt.VISIBLE_STRING:
                same = var.decode_raw(data) == var.decode_raw(want)
            else:
                same = bytes(data) == bytes(want)
            if not same:
                self.disagree("read differs from default", var, got=data.hex(), want=want.hex())

    # --- 2. in-limit downloads, read back ----------------------------------------------------
    def new_value(self, var, current):
        t = var.data_type
        if t in INT_RANGE:
            lo, hi, _ = INT_RANGE[t]
            lo = lo if var.min is None else max(lo, var.min)
            hi = hi if var.max is None else min(hi, var.max)
            cur = int.from_bytes(current, "little", signed=t in dt.SIGNED_TYPES)
            for v in (cur + 1, cur - 1, lo, hi, (lo + hi) // 2):
                if lo <= v <= hi and v != cur:
                    return int_bytes(v, t)
            return None
        if t == dt.REAL32:
            return struct.pack("<f", struct.unpack("<f", current)[0] + 1.5)
        if t == dt.REAL64:
            return struct.pack("<d", struct.unpack("<d", current)[0] + 1.5)
        if t == dt.VISIBLE_STRING:
            if not current:
                return None
            return ("odc" * 100)[: len(current)].encode("ascii")
        if t == dt.OCTET_STRING:
            return bytes(b ^ 0xFF for b in current) if current else None
        return None

    def write_all(self):
        for var in variables(self.node.object_dictionary):
            if not var.writable or is_dummy(var):
                continue
            if not var.readable:
                self.skip("write-only (cannot read back)")
                continue
            try:
                current = bytes(self.upload(var))
            except SdoAbortedError:
                continue  # reported by read_all
            new = self.new_value(var, current)
            if new is None:
                self.skip(f"no other in-limit value (type 0x{var.data_type:02X})")
                continue
            try:
                self.sdo.download(var.index, var.subindex, new)
                back = bytes(self.upload(var))
            except (SdoAbortedError, SdoCommunicationError) as e:
                why = cia301_refusal(var, current, new, getattr(e, "code", 0))
                if why:
                    self.skip(why)
                    continue
                self.disagree("in-limit write refused", var, value=new.hex(), got=str(e))
                continue
            if back != new:
                self.disagree("read-back differs", var, got=back.hex(), want=new.hex())
            else:
                self.out["written"] += 1
            try:
                self.sdo.download(var.index, var.subindex, current)
            except SdoAbortedError as e:
                self.disagree("restore refused", var, got=str(e))

    # --- 3. aborts ------------------------------------------------------------------------------
    def out_of_range(self):
        for var in variables(self.node.object_dictionary):
            t = var.data_type
            if not var.writable or t not in INT_RANGE or t == dt.BOOLEAN:
                continue
            lo, hi, _ = INT_RANGE[t]
            d = lambda b, v=var: self.sdo.download(v.index, v.subindex, b)
            if var.max is not None and var.max < hi:
                self.expect_abort("above HighLimit", ABORTS_TOO_HIGH,
                                  lambda b=int_bytes(var.max + 1, t): d(b), addr(var))
            if var.min is not None and var.min > lo:
                self.expect_abort("below LowLimit", ABORTS_TOO_LOW,
                                  lambda b=int_bytes(var.min - 1, t): d(b), addr(var))

    def read_only(self):
        for var in variables(self.node.object_dictionary):
            if var.writable or is_dummy(var):
                continue
            size = INT_RANGE.get(var.data_type, (0, 0, 4))[2]
            self.expect_abort("write of read-only", (ABORT_READ_ONLY,),
                              lambda v=var, n=size: self.sdo.download(v.index, v.subindex, bytes(n)),
                              addr(var))

    def missing(self):
        od = self.node.object_dictionary
        absent = [i for i in (0x1FFF, 0x2FFF, 0x3FFF, 0x5FFF, 0x6FFF, 0x9FFF) if i not in od][:3]
        for index in absent:
            where = f"0x{index:04X}:00"
            self.expect_abort("read of missing object", (ABORT_NO_OBJECT,),
                              lambda i=index: self.sdo.upload(i, 0), where)
            self.expect_abort("write of missing object", (ABORT_NO_OBJECT,),
                              lambda i=index: self.sdo.download(i, 0, b"\x01"), where)
        for obj in od.values():
            if isinstance(obj, (odm.ODRecord, odm.ODArray)):
                top = max(obj.subindices) if obj.subindices else 0
                if top < 0xFE:
                    where = f"0x{obj.index:04X}:{top + 1:02X}"
                    self.expect_abort("read of missing sub-index", (ABORT_NO_SUB,),
                                      lambda i=obj.index, s=top + 1: self.sdo.upload(i, s), where)

    # --- 4. PDO configuration -----------------------------------------------------------------
    @staticmethod
    def describe(m):
        return {
            "cob_id": m.cob_id,
            "enabled": m.enabled,
            "trans_type": m.trans_type,
            "map": [(v.index, v.subindex, v.length) for v in m.map],
        }

    def pdos(self):
        for kind, maps in (("tpdo", self.node.tpdo), ("rpdo", self.node.rpdo)):
            for n, m in maps.map.items():
                where = f"{kind}{n} 0x{m.com_record.od.index:04X}"
                try:
                    m.read()
                    over_sdo = self.describe(m)
                except (SdoAbortedError, SdoCommunicationError, KeyError, TypeError) as e:
                    self.disagree("pdo read failed", where, got=repr(e))
                    continue
                try:
                    m.read(from_od=True)
                    from_file = self.describe(m)
                except TypeError:
                    # The file gives no DefaultValue for a PDO parameter; python-canopen's
                    # read(from_od=True) then computes with None. CiA 306 makes DefaultValue
                    # optional; odc's slave starts such entries at zero (or the LowLimit), and
                    # node.tpdo/rpdo.read() over SDO above worked.
                    self.settle("PDO parameter without DefaultValue (python-canopen from_od)", where)
                    self.out["pdo_read_sdo_only"] = self.out.get("pdo_read_sdo_only", 0) + 1
                    continue
                if over_sdo != from_file:
                    self.disagree("pdo differs from device file", where,
                                  got=over_sdo, want=from_file)
                else:
                    self.out["pdo_compared"] += 1

    def mappable(self, direction):
        """Objects python-canopen may map, one byte to four, readable for TPDOs."""
        out = []
        for var in variables(self.node.object_dictionary):
            if not var.pdo_mappable or var.data_type not in INT_RANGE or is_dummy(var):
                continue
            if 0x1400 <= var.index < 0x1C00:
                continue
            if len(var) > 32 or len(var) < 8:
                continue
            if direction == "tpdo" and not var.readable:
                continue
            if direction == "rpdo" and not var.writable:
                continue
            out.append(var)
        return out

    def save_one(self, kind, maps):
        od = self.node.object_dictionary
        candidates = self.mappable(kind)
        for n, m in maps.map.items():
            map_index = m.map_array.od.index
            sub0 = od[map_index][0] if 0 in od[map_index].subindices else None
            if sub0 is None or not sub0.writable or len(od[map_index].subindices) < 3:
                self.skip(f"{kind} mapping count read-only or no entries")
                continue
            comm = od[m.com_record.od.index]
            if 1 not in comm.subindices or not comm[1].writable:
                # python-canopen's save() always rewrites the COB-ID (invalid, then valid);
                # a file with a read-only COB-ID (fixed identifier) cannot be saved that way.
                self.skip(f"{kind} COB-ID read-only")
                continue
            try:
                m.read()
            except (SdoAbortedError, SdoCommunicationError):
                continue
            old = [(v.index, v.subindex) for v in m.map]
            new = [v for v in candidates if (v.index, v.subindex) not in old][:2]
            if not new and old:
                continue
            if not new:
                # Nothing in the file may be mapped (Lenze): save() still rewrites the
                # communication parameters, with another transmission type.
                self.skip(f"{kind} no PDO-mappable object: saved an empty mapping")
            m.clear()
            for v in new:
                m.add_variable(v.index, v.subindex)
            m.enabled = True
            m.trans_type = 1 if 2 in comm.subindices and comm[2].writable else m.trans_type
            try:
                m.save()
            except (SdoAbortedError, SdoCommunicationError) as e:
                self.disagree("pdo save failed", f"{kind}{n}", got=str(e))
                return
            count = self.sdo.upload(map_index, 0)[0]
            entries = [int.from_bytes(self.sdo.upload(map_index, s), "little")
                       for s in range(1, count + 1)]
            want = [v.index << 16 | v.subindex << 8 | len(v) for v in new]
            if entries != want:
                self.disagree("pdo save read-back differs", f"{kind}{n}", got=entries, want=want)
            self.out["saved"].append({
                "kind": kind,
                "map_index": map_index,
                "comm_index": m.com_record.od.index,
                "entries": entries,
                "cob_id": m.cob_id,
                "trans_type": m.trans_type,
            })
            return

    def save(self):
        self.save_one("tpdo", self.node.tpdo)
        self.save_one("rpdo", self.node.rpdo)


def cia301_refusal(var, current, new, code):
    """Why a node that follows CiA 301 refuses a write a bare dictionary takes (odc's node in
    `odc simulate` does; its bare SDO server and python-canopen's LocalNode store any value in
    limits), or None."""
    le = lambda b: int.from_bytes(b[:4].ljust(4, b"\0"), "little")
    at = (var.index, var.subindex)
    if at == (0x1003, 0) and code == 0x06090030 and le(new) != 0:
        return "0x1003:00 takes only 0, which clears the error history (CiA 301 7.5.2.4)"
    pdo_cob = (0x1400 <= var.index <= 0x15FF or 0x1800 <= var.index <= 0x19FF) and var.subindex == 1
    if pdo_cob and code == 0x06090030:
        old, want = le(current), le(new)
        if old >> 31 == 0 and want >> 31 == 0 and old & 0x3FFFFFFF != want & 0x3FFFFFFF:
            return "a valid PDO's CAN-ID changes only while it is invalid (CiA 301 7.5.2.35/37)"
    if var.index == 0x1016 and var.subindex > 0 and code == 0x06040043:
        return "two heartbeat consumer entries for one node (CiA 301 7.5.2.14)"
    if var.index in (0x1010, 0x1011) and code == 0x08000020 and new not in (b"save", b"load"):
        return "store/restore take only their signatures 'save'/'load' (CiA 301, 0x1010/0x1011)"
    mapping = 0x1600 <= var.index <= 0x17FF or 0x1A00 <= var.index <= 0x1BFF
    if mapping and code in (0x06020000, 0x06040041, 0x06040042):
        return "a PDO mapping names a mappable object of the dictionary (CiA 301 PDO mapping)"
    if mapping and code == 0x06010000:
        return ("a PDO's mapping changes only while the PDO is invalid (COB-ID bit 31), its "
                "entries only while sub 0 is 0 (CiA 301 7.5.2.36/38)")
    if var.index == 0x6060 and code == 0x06090030:
        return "0x6060 takes only the modes 0x6502 lists (CiA 402)"
    return None

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--connect", required=True,
                    help="HOST:PORT of the Rust test, or slcan:PATH (socketbus.open_bus)")
    ap.add_argument("--eds", required=True)
    ap.add_argument("--node", type=int, default=5)
    ap.add_argument("--device", default="")
    ap.add_argument("--max-seconds", type=float, default=200.0)
    ap.add_argument("--boot-up", action="store_true",
                    help="first reset the node (NMT 0x81) and wait for its boot-up message")
    args = ap.parse_args()
    logging.basicConfig(level=logging.ERROR, stream=sys.stderr)
    network = open_network(args.connect, args.max_seconds)
    node = canopen.RemoteNode(args.node, args.eds)
    network.add_node(node)
    node.sdo.RESPONSE_TIMEOUT = 2.0
    run = Run(node, args.device or args.eds)
    try:
        if args.boot_up:
            # Listen before sending: NmtBase.wait_for_bootup only sees a boot-up that comes
            # after it was called, and a fast node answers before that.
            booted = threading.Event()
            network.subscribe(0x700 + args.node,
                              lambda _id, data, _t: booted.set() if bytes(data) == b"\0" else None)
            node.nmt.send_command(0x81)
            run.out["boot_up"] = booted.wait(10)
        run.read_all()
        run.write_all()
        run.out_of_range()
        run.read_only()
        run.missing()
        run.pdos()
        run.save()
    finally:
        network.disconnect()
    print(json.dumps(run.out))


if __name__ == "__main__":
    main()
