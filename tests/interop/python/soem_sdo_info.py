"""SOEM (through pysoem) reads the dictionary of the first device `odc simulate FILE.xml
--interface IFACE` serves by SDO Information (`slave.od`: Get OD List, then Get Object
Description and Get Entry Description per object, the replies reassembled from their
fragments by SOEM). Reads the plan (JSON: the interface) on stdin and prints one JSON line of
what it found as the last line of stdout; the Rust test decides.
"""

import json
import sys

import pysoem


def text(name):
    return name.decode("utf-8", "replace") if isinstance(name, bytes) else name


def main():
    plan = json.load(sys.stdin)
    out = {"errors": [], "objects": []}
    master = pysoem.Master()
    master.open(plan["iface"])
    try:
        out["found"] = master.config_init()
        if out["found"] > 0:
            for o in master.slaves[0].od:
                entries = [[text(e.name), e.data_type, e.bit_length, e.obj_access] for e in o.entries]
                out["objects"].append(
                    {
                        "index": o.index,
                        "code": o.object_code,
                        "data_type": o.data_type,
                        "name": text(o.name),
                        "bits": o.bit_length,
                        "access": o.obj_access,
                        "entries": entries,
                    }
                )
    except Exception as e:  # the report says what failed; the Rust test fails on it
        out["errors"].append(f"{type(e).__name__}: {e}")
    finally:
        master.close()
    print(json.dumps(out))


if __name__ == "__main__":
    main()
