#!/usr/bin/env python3
"""Writes SOES's object list (objectlist.c) and storage (utypes.h) for the objects of a
device, from `odc dump --format json FILE`: the same objects, sub-objects, types, access,
PDO mapping flags and defaults as the dictionary odc generates for the firmware example.

    odc dump --format json esi/servoone.xml | objects.py OUTDIR [--no-names]

With --no-names every object and entry is named by one empty string: SOES without the names
its SDO Information serves (a reference row; odc's example serves SDO Information with the
ESI's names, from the generated `slave::DESCRIPTION`).

SOES's conventions (its applications' slave_objectlist.c): an `_objd` array per object, an
`acName` string per object and sub-object, a constant entry served from its `value` field
(no storage), an entry that is written or mapped into a PDO pointing at its field of `Obj`;
PDO mapping and assignment objects writable in PRE-OP only (ATYPE_RWpre), as odc's stack
allows them.
"""
import json
import re
import sys

DTYPE = {
    "Boolean": ("DTYPE_BOOLEAN", "uint8_t"),
    "Integer8": ("DTYPE_INTEGER8", "int8_t"),
    "Integer16": ("DTYPE_INTEGER16", "int16_t"),
    "Integer32": ("DTYPE_INTEGER32", "int32_t"),
    "Unsigned8": ("DTYPE_UNSIGNED8", "uint8_t"),
    "Unsigned16": ("DTYPE_UNSIGNED16", "uint16_t"),
    "Unsigned32": ("DTYPE_UNSIGNED32", "uint32_t"),
    "VisibleString": ("DTYPE_VISIBLE_STRING", "char"),
}
OTYPE = {"Var": "OTYPE_VAR", "Record": "OTYPE_RECORD", "Array": "OTYPE_ARRAY"}


NO_NAMES = "--no-names" in sys.argv


def c_string(s):
    if NO_NAMES:
        return '""'
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'


def default(sub):
    d = sub.get("default") or {}
    for key in ("unsigned", "signed", "integer"):
        if key in d:
            return int(d[key]) & 0xFFFFFFFF
    return 0


def add_name(names, symbol, text):
    if NO_NAMES:
        names.append(f"#define {symbol} acNone")
    else:
        names.append(f"static const char {symbol}[] = {c_string(text)};")


def main():
    out = sys.argv[1]
    model = json.load(sys.stdin)
    names = ['static const char acNone[] = "";'] if NO_NAMES else []
    arrays, fields, listing = [], [], []
    for obj in sorted(model["objects"].values(), key=lambda o: int(o["index"], 16)):
        index = int(obj["index"], 16)
        subs = sorted(obj["subs"].values(), key=lambda s: int(s["sub_index"], 16))
        kind = obj["kind"]
        add_name(names, f"acName{index:04X}", obj["name"])
        rows = []
        for sub in subs:
            n = int(sub["sub_index"], 16)
            dtype, ctype = DTYPE[sub["data_type"]]
            bits = sub["bit_size"]
            if kind == "Var":
                name = f"acName{index:04X}"
            else:
                name = f"acName{index:04X}_{n:02X}"
                add_name(names, name, sub["name"])
            pdo_config = 0x1600 <= index <= 0x1BFF or index in (0x1C12, 0x1C13)
            access = {"ro": "ATYPE_RO", "rw": "ATYPE_RWpre" if pdo_config else "ATYPE_RW"}
            atype = access.get(sub["access"], "ATYPE_RW")
            mapping = sub["pdo_mapping"]
            if mapping in ("rx", "both"):
                atype += " | ATYPE_RXPDO"
            if mapping in ("tx", "both"):
                atype += " | ATYPE_TXPDO"
            field = f"o{index:04X}_{n:02X}"
            stored = sub["access"] != "ro" or mapping != "no" or dtype == "DTYPE_VISIBLE_STRING"
            if dtype == "DTYPE_VISIBLE_STRING":
                fields.append(f"   char {field}[{bits // 8}];")
                data = f"Obj.{field}"
            elif stored:
                fields.append(f"   {ctype} {field};")
                data = f"&Obj.{field}"
            else:
                data = "NULL"
            value = default(sub)
            rows.append(f"  {{0x{n:02X}, {dtype}, {bits}, {atype}, {name}, 0x{value:X}, {data}}},")
        arrays.append(f"const _objd SDO{index:04X}[] =\n{{\n" + "\n".join(rows) + "\n};")
        max_sub = max(int(s["sub_index"], 16) for s in subs) if kind != "Var" else 0
        listing.append(
            f"  {{0x{index:04X}, {OTYPE[kind]}, {max_sub}, 0, acName{index:04X}, SDO{index:04X}}},"
        )
    listing.append("  {0xffff, 0xff, 0xff, 0xff, NULL, NULL}")
    head = f"/* Written by tests/slave-size/soes/objects.py from `odc dump`: {len(listing) - 1} objects. */\n"
    with open(f"{out}/objectlist.c", "w") as f:
        f.write(head + '#include "esc_coe.h"\n#include "utypes.h"\n#include <stddef.h>\n\n')
        f.write("\n".join(names) + "\n\n" + "\n".join(arrays) + "\n\n")
        f.write("const _objectlist SDOobjects[] =\n{\n" + "\n".join(listing) + "\n};\n")
    with open(f"{out}/utypes.h", "w") as f:
        f.write(head + '#ifndef __UTYPES_H__\n#define __UTYPES_H__\n#include "cc.h"\n\n')
        f.write("typedef struct\n{\n" + "\n".join(fields) + "\n} _Objects;\n\n")
        f.write("extern _Objects Obj;\n\n#endif\n")


if __name__ == "__main__":
    main()
