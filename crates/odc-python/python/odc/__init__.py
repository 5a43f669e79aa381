"""odc: CANopen (EDS, DCF, XDD/XDC) and EtherCAT (ESI) device files, read and checked by odc.

>>> import odc
>>> dev = odc.load("eds/lxm23a.eds")
>>> dev.objects[0x1018].subs[1].default

Every function takes the rule levels of the ``odc`` command line as keyword arguments:
``allow``, ``warn`` and ``deny`` (lists of rule codes, names or groups: ``-A``, ``-W``,
``-D``), ``strict`` (warnings become errors), ``config`` (an ``odc.toml``) and ``device``
(``PRODUCT[:REVISION]`` or a name, for an ESI with several devices).

``odc.canopen.import_od(path, node_id=None)`` gives a python-canopen ``ObjectDictionary``
built from odc's model (``pip install odc[canopen]``).
"""

import json as _json

from ._errors import Refused
from ._odc import (
    Device,
    Identity,
    Invalid,
    NodeIdPlus,
    Object,
    Pdo,
    PdoEntry,
    SubObject,
    __version__,
    check,
    convert,
    doc,
    load,
)
from ._odc import diff_json as _diff_json

__all__ = [
    "Device",
    "Identity",
    "Invalid",
    "NodeIdPlus",
    "Object",
    "Pdo",
    "PdoEntry",
    "Refused",
    "SubObject",
    "check",
    "convert",
    "diff",
    "doc",
    "load",
]


def diff(a, b, *, ignore_names=False, ignore_comments=False, ignore_defaults=False,
         device_a=None, device_b=None):
    """What changed between two device files (any formats), as ``odc diff --format json``:
    a list of dicts (``in``, ``index``, ``sub``, ``change``, ``field``, ``a``, ``b``); empty
    when they are equal."""
    return _json.loads(_diff_json(
        a, b, ignore_names=ignore_names, ignore_comments=ignore_comments,
        ignore_defaults=ignore_defaults, device_a=device_a, device_b=device_b))
