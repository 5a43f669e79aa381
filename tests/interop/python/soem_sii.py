"""SOEM (through pysoem) reads the SII EEPROM of devices odc simulates (`odc simulate FILE.xml
--interface IFACE`, on the other end of a veth pair), as any SOEM application's config_init does.

Reads a plan (JSON) on stdin: the interface, and per device how many bytes of EEPROM to read.
Prints one JSON line: per device what SOEM made of the SII in config_init (name, identity) and
the EEPROM's bytes as read word by word over the ESC's EEPROM interface; the Rust test decides.
"""

from soem_report import report


def main():
    report(run, {"devices": []})


def run(master, plan, out):
    out["found"] = master.config_init()
    for k, slave in enumerate(master.slaves):
        size = plan["devices"][k]["bytes"] if k < len(plan["devices"]) else 0
        image = bytearray()
        # eeprom_read answers 4 bytes (2 words) from a word address.
        for word in range(0, size // 2, 2):
            image += slave.eeprom_read(word, 20_000)
        name = slave.name
        if isinstance(name, bytes):
            name = name.decode("latin-1")
        out["devices"].append(
            {
                "name": name,
                "identity": [slave.man, slave.id, slave.rev],
                "eeprom": bytes(image[:size]).hex(),
            }
        )


if __name__ == "__main__":
    main()
