"""SOEM (through pysoem) reads the dictionary of the first device `odc simulate FILE.xml
--interface IFACE` serves by SDO Information (`slave.od`: Get OD List, then Get Object
Description and Get Entry Description per object, the replies reassembled from their
fragments by SOEM). Reads the plan (JSON: the interface) on stdin and prints one JSON line of
what it found as the last line of stdout; the Rust test decides.
"""

from soem_report import report


def text(name):
    return name.decode("utf-8", "replace") if isinstance(name, bytes) else name


def main():
    report(run, {"objects": []})


def run(master, plan, out):
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


if __name__ == "__main__":
    main()
