"""SOEM (pysoem) on one line of simulated devices: the default bring-up of SOEM's own
simple_test, per device where SOEM keeps it per device.

Reads a plan (JSON) on stdin: `iface`, `count` (the devices on the line) and `cycles`. Does
config_init, config_map (which requests SAFE-OP of each device), waits for SAFE-OP, requests
OP with process data running, then runs `cycles` cycles and counts the working counters.
Prints one JSON line: per device its identity, sizes, and the AL state and AL status code
after SAFE-OP and after OP; for the line the expected and the counted working counters, or
the exception that stopped it. Run by soem.py inside the network namespace of the wire.
"""

import json
import sys
import time

import pysoem


def main():
    plan = json.load(sys.stdin)
    out = {"devices": [], "errors": []}
    master = pysoem.Master()
    master.open(plan["iface"])
    try:
        run(master, plan, out)
    except Exception as e:  # the report says where it stopped; soem.py classifies
        out["errors"].append(f"{type(e).__name__}: {e}")
    finally:
        master.close()
    print(json.dumps(out))


def states(master, out, key):
    """Each device's AL state and AL status code, read from the line now."""
    master.read_state()
    for k, slave in enumerate(master.slaves):
        out["devices"][k][key] = [slave.state, slave.al_status]


def run(master, plan, out):
    out["stage"] = "config_init"
    found = master.config_init()
    out["found"] = found
    for slave in master.slaves:
        out["devices"].append(
            {"name": slave.name, "identity": [slave.man, slave.id, slave.rev]}
        )
    if found != plan["count"]:
        return
    out["stage"] = "config_map"
    out["io_map_size"] = master.config_map()
    for k, slave in enumerate(master.slaves):
        out["devices"][k]["sizes"] = [len(slave.output), len(slave.input)]
    # The working counter of the LRW by ETG.1000.4: each device that is written adds 2, each
    # that is read adds 1 (SOEM's own expectation is master.expected_wkc).
    out["etg_wkc"] = sum(
        2 * (len(s.output) > 0) + (len(s.input) > 0) for s in master.slaves
    )
    out["stage"] = "safe_op"
    out["safe_op"] = master.state_check(pysoem.SAFEOP_STATE, 2_000_000) == pysoem.SAFEOP_STATE
    states(master, out, "after_safe_op")
    if not out["safe_op"]:
        return
    out["stage"] = "op"
    out["expected_wkc"] = master.expected_wkc
    master.state = pysoem.OP_STATE
    master.send_processdata()
    master.receive_processdata(20_000)
    master.write_state()
    reached = False
    for _ in range(400):
        master.send_processdata()
        master.receive_processdata(20_000)
        if master.state_check(pysoem.OP_STATE, 5000) == pysoem.OP_STATE:
            reached = True
            break
    out["op"] = reached
    states(master, out, "after_op")
    if not reached:
        return
    out["stage"] = "cycles"
    cycles(master, plan.get("cycles", 1000), out)
    out["stage"] = "done"
    master.state = pysoem.INIT_STATE
    master.write_state()


def cycles(master, n, out):
    """`n` cycles whose frame came back; one that did not within 20 ms (a loaded machine) is
    counted as lost and the cycle repeated, up to `n` losses. SOEM returns EC_NOFRAME (-1)
    for a frame that did not come back; a frame that came back with working counter 0 (no
    device counted it) is a wrong counter, not a lost frame."""
    good, lost, wrong = 0, 0, []
    while good + len(wrong) < n and lost < n:
        master.send_processdata()
        wkc = master.receive_processdata(20_000)
        if wkc == master.expected_wkc:
            good += 1
        elif wkc < 0:
            lost += 1
        else:
            wrong.append(wkc)
        time.sleep(0.0002)
    out["cycles_with_expected_wkc"] = good
    out["other_wkc"] = sorted(set(wrong))
    out["cycles_with_other_wkc"] = len(wrong)
    out["frames_lost"] = lost


if __name__ == "__main__":
    main()
