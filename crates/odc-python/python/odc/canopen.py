"""python-canopen's ``ObjectDictionary`` built from odc's reader.

``odc.canopen.import_od`` takes what ``canopen.import_od`` takes and returns the same classes
(``ObjectDictionary``, ``ODVariable``, ``ODRecord``, ``ODArray``), so a python-canopen user
swaps one import::

    import odc.canopen
    od = odc.canopen.import_od("device.eds", node_id=5)
    node = canopen.RemoteNode(5, od)

The objects come from odc's model, which reads every corpus file python-canopen reads and more
(duplicate keys and sections, octal and hex-REAL literals, XDD/XDC files); where the two read a
file differently, odc follows CiA 306 (tests/interop/README.md lists each class). What odc has
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

from . import Invalid, NodeIdPlus, load

__all__ = ["import_od", "build"]

logger = logging.getLogger(__name__)

# Only the front-end's rules decide whether a file can be read: a python-canopen user loads
# files that break CiA 301 or 402; those rules warn (od.odc_diagnostics, and the log).
_NOT_GATING = ("cia301", "cia402", "etg")
# A value that does not read as its type (F107), does not fit it (F108), an unknown AccessType
# (F115): python-canopen reads such a file and drops the value (logged); so does this importer,
# with a warning in od.odc_diagnostics instead of odc's refusal. `deny=["F107"]` refuses.
_WARN_ONLY = ("F107", "F108", "F115")

_SUFFIXES = (".eds", ".dcf", ".xdd", ".xdc")

# Data types whose values are integers on python-canopen's side.
_TIME_TYPES = (0x0C, 0x0D)


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
    device = load(name, allow=list(allow), warn=warn, deny=list(deny), strict=strict, data=data)
    for d in device.diagnostics:
        # Logged as python-canopen logs what it skips in a file: a problem reading the file
        # (front-end codes, F…) as a warning; what the CiA rules say of its content as info.
        reading = d["code"].startswith("F")
        level = logging.WARNING if reading and d["severity"] != "note" else logging.INFO
        place = f"{d['file']}:{d['line']}:{d['column']}: " if d["line"] is not None else ""
        logger.log(level, "%s%s[%s] %s", place, d["severity"], d["code"], d["message"])
    return build(device, node_id)


def build(device, node_id=None):
    """The ``ObjectDictionary`` of an ``odc.Device`` (from :func:`odc.load`)."""
    od = ObjectDictionary()
    od.odc_diagnostics = device.diagnostics
    od.comments = "\n".join(device.comments)
    if device.baud_rate is not None:
        od.bitrate = device.baud_rate * 1000
    if node_id is None:
        node_id = device.node_id
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
    for index, obj in device.objects.items():
        kind = obj.kind
        if kind == "ARRAY":
            entry = ODArray(obj.name, index)
        elif kind in ("RECORD", "DEFSTRUCT"):
            entry = ODRecord(obj.name, index)
        else:
            sub = obj.subs.get(0)
            if sub is None:
                continue
            var = _variable(obj.name, index, 0, sub, node_id)
            var.storage_location = obj.extra.get("StorageLocation")
            od.add_object(var)
            continue
        entry.storage_location = obj.extra.get("StorageLocation")
        for sub_index, sub in obj.subs.items():
            entry.add_member(_variable(sub.name, index, sub_index, sub, node_id))
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
# variable is made by copying them and setting the file's, which takes a third of the time
# __init__ does (it dominated the import). Containers (value_descriptions, bit_definitions, any
# a later python-canopen adds) are made anew for each variable.
_FRESH = ODVariable("", 0, 0).__dict__
_SCALARS = {k: v for k, v in _FRESH.items() if not isinstance(v, (dict, list, set))}
_CONTAINERS = tuple((k, type(v)) for k, v in _FRESH.items() if isinstance(v, (dict, list, set)))
_new = object.__new__


def _value(v, data_type, node_id):
    """A model value as python-canopen holds it."""
    if v is None:
        return None
    if isinstance(v, (NodeIdPlus, Invalid)):
        if isinstance(v, Invalid) or node_id is None:
            return None
        return v.resolve(node_id)
    if data_type in _TIME_TYPES and isinstance(v, tuple):
        ms, days = v
        return ms | (days << 32)
    return v


def _variable(name, index, sub_index, sub, node_id):
    data_type = sub.data_type
    extra = sub.extra
    low, high = sub.low_limit, sub.high_limit
    d = dict(_SCALARS)
    for key, kind in _CONTAINERS:
        d[key] = kind()
    d["name"] = name
    d["index"] = index
    d["subindex"] = sub_index
    d["data_type"] = data_type
    d["access_type"] = sub.access
    d["pdo_mappable"] = sub.pdo_mapping
    d["storage_location"] = extra.get("StorageLocation")
    if low is not None:
        d["min"] = _value(low, data_type, node_id)
    if high is not None:
        d["max"] = _value(high, data_type, node_id)
    default = sub.default
    if default is not None:
        raw = sub.default_raw
        d["default_raw"] = raw if raw is not None else _raw(default)
        d["relative"] = isinstance(default, NodeIdPlus)
        d["default"] = _value(default, data_type, node_id)
    value = sub.parameter_value
    if value is not None:
        raw = sub.parameter_value_raw
        d["value_raw"] = raw if raw is not None else _raw(value)
        d["value"] = _value(value, data_type, node_id)
    if extra:
        factor = extra.get("Factor")
        if factor is not None:
            try:
                d["factor"] = float(factor)
            except ValueError:
                pass
        description = extra.get("Description")
        if description is not None:
            d["description"] = description
        unit = extra.get("Unit")
        if unit is not None:
            d["unit"] = unit
    var = _new(ODVariable)
    var.__dict__ = d
    return var


def _raw(v):
    """The text of a value the file implies without writing it (CompactSubObj members)."""
    if isinstance(v, NodeIdPlus):
        return f"$NODEID+0x{v.offset:X}"
    if isinstance(v, Invalid):
        return v.text
    if isinstance(v, bytes):
        return v.hex().upper()
    if isinstance(v, bool):
        return str(int(v))
    if isinstance(v, int):
        return f"0x{v:X}" if v >= 0 else str(v)
    return str(v)

