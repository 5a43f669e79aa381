"""SOEM (pysoem) and a line of devices with fewer than 8 bits of process data each, which
SOEM packs into shared bytes of its logical image (config_map's bit positions, programmed
into each device's FMMUs with start and stop bits).

Reads a plan (JSON) on stdin: `iface`; `inputs`, per device the SDO writes (index, sub,
hex) that set what the device puts into its inputs; `outputs`, the whole output image (hex)
to send; `reads`, the objects to read back from every device in OP. Reports, as one JSON line
on stdout: each device's FMMU 0 and 1 (ETG.1000.4 Table 57: logical start, length, start bit,
stop bit), its slice of the input image, and the reads. The Rust test decides
(crates/odc-cli/tests/simulate_soem.rs).
"""

import time

import pysoem

from soem_report import report


def fmmu(raw):
    """Logical start, length, logical start bit, logical stop bit of one FMMU entry."""
    return [int.from_bytes(raw[0:4], "little"), int.from_bytes(raw[4:6], "little"), raw[6], raw[7]]


def main():
    report(run, {"devices": []})


def run(master, plan, out):
    out["found"] = master.config_init()
    out["io_map_size"] = master.config_map()
    for slave in master.slaves:
        raw = slave._fprd(0x0600, 32)
        out["devices"].append({"fmmu": [fmmu(raw[0:16]), fmmu(raw[16:32])]})
    out["safe_op"] = master.state_check(pysoem.SAFEOP_STATE, 2_000_000) == pysoem.SAFEOP_STATE
    for slave, writes in zip(master.slaves, plan["inputs"]):
        for index, sub, data in writes:
            slave.sdo_write(index, sub, bytes.fromhex(data))
    # Each device's output pointer is its first FMMU's first logical byte: devices that
    # share a byte share it in the image, so each is given its slice of the whole image.
    image = bytes.fromhex(plan["outputs"])
    base = out["devices"][0]["fmmu"][0][0]
    for slave, dev in zip(master.slaves, out["devices"]):
        start = dev["fmmu"][0][0] - base
        slave.output = image[start:start + len(slave.output)]
    master.state = pysoem.OP_STATE
    master.write_state()
    out["op"] = False
    for _ in range(400):
        master.send_processdata()
        master.receive_processdata(20_000)
        if master.state_check(pysoem.OP_STATE, 5000) == pysoem.OP_STATE:
            out["op"] = True
            break
    # Cycles enough for every device to have taken its outputs and given its inputs.
    wkcs = []
    for _ in range(100):
        master.send_processdata()
        wkcs.append(master.receive_processdata(20_000))
        time.sleep(0.001)
    out["expected_wkc"] = master.expected_wkc
    out["last_wkc"] = wkcs[-1]
    for slave, dev in zip(master.slaves, out["devices"]):
        dev["input"] = bytes(slave.input).hex()
        dev["reads"] = [[i, s, bytes(slave.sdo_read(i, s)).hex()] for i, s in plan["reads"]]
    master.state = pysoem.INIT_STATE
    master.write_state()


if __name__ == "__main__":
    main()
