"""SOEM (through pysoem) as the EtherCAT master of devices odc simulates (`odc simulate
FILE.xml --interface IFACE`, on the other end of a veth pair).

Reads a plan (JSON) on stdin: the interface, and per device the SDO writes to make in PRE-OP
(a PDO mapping and assignment, as a configuration tool would), the objects to read, the
writes to read back, the accesses that must abort, and the outputs to send in OP. Does what
any SOEM application does (config_init, config_map, SAFE-OP, OP, cyclic process data) and
prints one JSON line of what it found as the last line of stdout; the Rust test decides.
"""

import time

import pysoem

from soem_report import report


def hexb(b):
    return bytes(b).hex()


def main():
    report(run, {"devices": []})


def run(master, plan, out):
    found = master.config_init()
    out["found"] = found
    if found <= 0:
        return
    for k, slave in enumerate(master.slaves):
        out["devices"].append(
            {"name": slave.name, "vendor": slave.man, "product": slave.id, "revision": slave.rev}
        )
        want = plan["devices"][k] if k < len(plan["devices"]) else {}
        writes = want.get("preop_writes", [])

        def configure(_pos, slave=slave, writes=writes):
            for index, sub, data in writes:
                slave.sdo_write(index, sub, bytes.fromhex(data))

        slave.config_func = configure
    out["io_map_size"] = master.config_map()
    for k, slave in enumerate(master.slaves):
        out["devices"][k]["inputs_len"] = len(slave.input)
        out["devices"][k]["outputs_len"] = len(slave.output)
    out["safe_op"] = master.state_check(pysoem.SAFEOP_STATE, 500_000) == pysoem.SAFEOP_STATE
    sdo(master, plan, out)
    master.state = pysoem.OP_STATE
    master.write_state()
    reached = False
    for _ in range(200):
        master.send_processdata()
        master.receive_processdata(20_000)
        if master.state_check(pysoem.OP_STATE, 5000) == pysoem.OP_STATE:
            reached = True
            break
    out["op"] = reached
    exchange(master, plan, out)
    master.state = pysoem.INIT_STATE
    master.write_state()


def sdo(master, plan, out):
    """Reads, writes read back, and the accesses that must abort, per device."""
    for k, slave in enumerate(master.slaves):
        want = plan["devices"][k] if k < len(plan["devices"]) else {}
        dev = out["devices"][k]
        dev["reads"] = [[i, s, hexb(slave.sdo_read(i, s))] for i, s in want.get("reads", [])]
        dev["written"] = []
        for i, s, data in want.get("writes", []):
            slave.sdo_write(i, s, bytes.fromhex(data))
            dev["written"].append([i, s, hexb(slave.sdo_read(i, s))])
        dev["aborts"] = []
        for i, s, data in want.get("aborts", []):
            try:
                if data is None:
                    slave.sdo_read(i, s)
                else:
                    slave.sdo_write(i, s, bytes.fromhex(data))
                dev["aborts"].append([i, s, None])
            except pysoem.SdoError as e:
                dev["aborts"].append([i, s, e.abort_code])


def exchange(master, plan, out):
    """Cyclic process data: the plan's outputs out, the inputs and working counters in."""
    cycles = plan.get("cycles", 1000)
    for k, slave in enumerate(master.slaves):
        want = plan["devices"][k] if k < len(plan["devices"]) else {}
        if want.get("outputs"):
            slave.output = bytes.fromhex(want["outputs"])
    # Until `cycles` frames have come back; a frame that does not within 20 ms (a loaded
    # machine) is counted as lost and the cycle repeated.
    good, lost, wrong = 0, 0, []
    while good + len(wrong) < cycles and lost < cycles:
        master.send_processdata()
        wkc = master.receive_processdata(20_000)
        if wkc == master.expected_wkc:
            good += 1
        elif wkc <= 0:
            lost += 1
        else:
            wrong.append(wkc)
        time.sleep(0.0005)
    out["cycles"] = cycles
    out["expected_wkc"] = master.expected_wkc
    out["cycles_with_expected_wkc"] = good
    out["cycles_with_other_wkc"] = wrong
    out["frames_lost"] = lost
    for k, slave in enumerate(master.slaves):
        out["devices"][k]["inputs"] = hexb(slave.input)


if __name__ == "__main__":
    main()
