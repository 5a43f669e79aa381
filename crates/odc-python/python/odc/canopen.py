"""python-canopen's ``ObjectDictionary`` built from odc's reader.

``odc.canopen.import_od`` takes what ``canopen.import_od`` takes and returns the same classes
(``ObjectDictionary``, ``ODVariable``, ``ODRecord``, ``ODArray``), so a python-canopen user
swaps one import::

    import odc.canopen
    od = odc.canopen.import_od("device.eds", node_id=5)
    node = canopen.RemoteNode(5, od)

The objects come from odc's model, which reads every corpus file python-canopen reads and more
(duplicate keys and sections, octal and hex-REAL literals, XDD/XDC files); where the two read a
file differently, tests/interop/README.md gives each class and why odc reads it so. What odc has
to say about the file is in ``od.odc_diagnostics`` (dicts, as :func:`odc.check` gives them).

Values as python-canopen has them: ``default`` and ``value`` resolved with ``node_id`` when the
file writes ``$NODEID`` (``relative`` set, ``None`` without a node-ID), ``default_raw`` and
``value_raw`` the text of the file, TIME_OF_DAY and TIME_DIFFERENCE as the 48-bit integer of
their wire form.
"""

import logging
import os

import canopen.objectdictionary as _cod
from canopen.objectdictionary import ODArray, ODRecord, ODVariable, ObjectDictionary

from ._odc import load_canopen

__all__ = ["import_od"]

logger = logging.getLogger(__name__)

# Only the front-end's rules decide whether a file can be read: a python-canopen user loads
# files that break CiA 301 or 402; those rules warn (od.odc_diagnostics, and the log).
_NOT_GATING = ("cia301", "cia402", "etg")
# A value that does not read as its type (F107), does not fit it (F108), an unknown AccessType
# (F115): python-canopen reads such a file and drops the value (logged); so does this importer,
# with a warning in od.odc_diagnostics instead of odc's refusal. `deny=["F107"]` refuses.
_WARN_ONLY = ("F107", "F108", "F115")

_SUFFIXES = (".eds", ".dcf", ".xdd", ".xdc")


def import_od(source, node_id=None, *, allow=(), warn=(), deny=(), strict=False):
    """Parse an EDS, DCF, XDD or XDC file (or an EPF, through python-canopen) into a
    python-canopen ``ObjectDictionary``.

    :param source: a path, a file-like object with a ``name`` (its suffix gives the format),
        or ``None`` for an empty dictionary.
    :param node_id: the node-ID that ``$NODEID`` values are resolved with; when ``None``, a
        DCF's ``[DeviceComissioning] NodeID``.
    :param allow, warn, deny, strict: rule levels, as for :func:`odc.load`.
    :raises odc.Refused: when the file cannot be read as a device description (a diagnostic
        at error level); ``ValueError`` for an unknown format; ``OSError`` when it cannot be
        read.
    """
    if source is None:
        return ObjectDictionary()
    data = None
    if hasattr(source, "read"):
        name = source.name
        text = source.read()
        data = text.encode("utf-8") if isinstance(text, str) else bytes(text)
    elif hasattr(source, "tag"):
        return _cod.import_od(source, node_id)
    else:
        name = os.fspath(source)
    suffix = name[name.rfind("."):].lower() if "." in name else ""
    if suffix == ".epf":
        return _cod.import_od(source, node_id)
    if suffix not in _SUFFIXES:
        raise ValueError(
            f"Cannot import from the {suffix[1:]!r} format; "
            f"supported formats: eds, dcf, xdd, xdc, epf")
    named = set(allow) | set(deny)
    warn = [code for code in _NOT_GATING + _WARN_ONLY if code not in named] + list(warn)
    device, objects, node_id = load_canopen(name, node_id=node_id, allow=list(allow), warn=warn,
                                            deny=list(deny), strict=strict, data=data,
                                            template=_SCALARS, containers=_CONTAINERS,
                                            cls=ODVariable, new=object.__new__)
    for d in device.diagnostics:
        # Logged as python-canopen logs what it skips in a file: a problem reading the file
        # (front-end codes, F…) as a warning; what the CiA rules say of its content as info.
        reading = d["code"].startswith("F")
        level = logging.WARNING if reading and d["severity"] != "note" else logging.INFO
        place = f"{d['file']}:{d['line']}:{d['column']}: " if d["line"] is not None else ""
        logger.log(level, "%s%s[%s] %s", place, d["severity"], d["code"], d["message"])
    return _build(device, objects, node_id)


def _build(device, objects, node_id):
    """The ``ObjectDictionary`` of what ``load_canopen`` read."""
    od = ObjectDictionary()
    od.odc_diagnostics = device.diagnostics
    od.comments = "\n".join(device.comments)
    if device.baud_rate is not None:
        od.bitrate = device.baud_rate * 1000
    od.node_id = node_id
    _identity(od.device_information, device.identity)
    for i in device.dummy_usage:
        # python-canopen's Dummy0001..Dummy0007 objects (the data types a PDO may map as gap
        # fillers), so that mapping entries naming them resolve as they do there.
        if 1 <= i <= 7:
            var = ODVariable(f"Dummy{i:04d}", i, 0)
            var.data_type = i
            var.access_type = "const"
            od.add_object(var)
    for index, kind, name, storage_location, members in objects:
        if kind == "ARRAY":
            entry = ODArray(name, index)
        elif kind in ("RECORD", "DEFSTRUCT"):
            entry = ODRecord(name, index)
        else:
            if members:
                od.add_object(members[0])
            continue
        entry.storage_location = storage_location
        for var in members:
            entry.add_member(var)
        od.add_object(entry)
    return od


def _identity(info, identity):
    info.allowed_baudrates = {rate * 1000 for rate in identity.baud_rates}
    info.vendor_name = identity.vendor_name
    info.vendor_number = identity.vendor_number
    info.product_name = identity.product_name
    info.product_number = identity.product_number
    info.revision_number = identity.revision_number
    info.order_code = identity.order_code
    info.simple_boot_up_master = identity.simple_boot_up_master
    info.simple_boot_up_slave = identity.simple_boot_up_slave
    info.granularity = identity.granularity
    info.dynamic_channels_supported = identity.dynamic_channels_supported
    info.group_messaging = identity.group_messaging
    info.nr_of_RXPDO = identity.nr_of_rx_pdo
    info.nr_of_TXPDO = identity.nr_of_tx_pdo
    info.LSS_supported = identity.lss_supported


# The attributes a fresh ODVariable has, as this python-canopen sets them in __init__: a
# variable is made from a copy of them and the file's (a dict odc made, src/canopen.rs), not
# through __init__ and one attribute at a time, which was most of the import's time.
# Containers (value_descriptions, bit_definitions, any a later python-canopen adds) are made
# anew for each variable.
_FRESH = ODVariable("", 0, 0).__dict__
_SCALARS = {k: v for k, v in _FRESH.items() if not isinstance(v, (dict, list, set))}
_CONTAINERS = tuple((k, type(v)) for k, v in _FRESH.items() if isinstance(v, (dict, list, set)))
