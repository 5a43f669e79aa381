"""The odc Python package: what each function gives for small files written here, whose every
value the test states."""

import json
import os

import pytest

import odc

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))

EDS = """\
[FileInfo]
FileName=t.eds
EDSVersion=4.0

[DeviceInfo]
VendorName=Acme
VendorNumber=0x1234
ProductName=Widget
ProductNumber=0x42
RevisionNumber=0x00010002
BaudRate_250=1
BaudRate_500=1
NrOfRXPDO=1
NrOfTXPDO=0
LSS_Supported=1

[DummyUsage]
Dummy0001=0
Dummy0002=1
Dummy0003=0
Dummy0004=0
Dummy0005=1
Dummy0006=0
Dummy0007=0

[Comments]
Lines=2
Line1=first
Line2=second

[MandatoryObjects]
SupportedObjects=3
1=0x1000
2=0x1001
3=0x1018

[OptionalObjects]
SupportedObjects=4
1=0x1003
2=0x1400
3=0x1600
4=0x1017

[ManufacturerObjects]
SupportedObjects=2
1=0x2000
2=0x2001

[1000]
ParameterName=Device type
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0x00020191
PDOMapping=0

[1001]
ParameterName=Error register
ObjectType=0x7
DataType=0x0005
AccessType=ro
DefaultValue=0
PDOMapping=1

[1003]
ParameterName=Pre-defined error field
ObjectType=0x8
DataType=0x0007
AccessType=ro
CompactSubObj=4
PDOMapping=0

[1017]
ParameterName=Producer heartbeat time
ObjectType=0x7
DataType=0x0006
AccessType=rw
DefaultValue=010
PDOMapping=0

[1018]
ParameterName=Identity object
ObjectType=0x9
SubNumber=2

[1018sub0]
ParameterName=Number of entries
ObjectType=0x7
DataType=0x0005
AccessType=ro
DefaultValue=1
PDOMapping=0

[1018sub1]
ParameterName=Vendor-ID
ObjectType=0x7
DataType=0x0007
AccessType=ro
DefaultValue=0x1234
PDOMapping=0

[1400]
ParameterName=RPDO 1 communication
ObjectType=0x9
SubNumber=3

[1400sub0]
ParameterName=Highest sub-index
ObjectType=0x7
DataType=0x0005
AccessType=ro
DefaultValue=2
PDOMapping=0

[1400sub1]
ParameterName=COB-ID
ObjectType=0x7
DataType=0x0007
AccessType=rw
DefaultValue=$NODEID+0x200
PDOMapping=0

[1400sub2]
ParameterName=Transmission type
ObjectType=0x7
DataType=0x0005
AccessType=rw
DefaultValue=255
PDOMapping=0

[1600]
ParameterName=RPDO 1 mapping
ObjectType=0x9
SubNumber=2

[1600sub0]
ParameterName=Number of mapped objects
ObjectType=0x7
DataType=0x0005
AccessType=rw
DefaultValue=1
PDOMapping=0

[1600sub1]
ParameterName=Mapped object 1
ObjectType=0x7
DataType=0x0007
AccessType=rw
DefaultValue=0x20000010
PDOMapping=0

[2000]
ParameterName=Speed
ObjectType=0x7
DataType=0x0003
AccessType=rww
LowLimit=-100
HighLimit=0x64
DefaultValue=0xFFFF
PDOMapping=1
Unit=rpm
Factor=0.5

[2001]
ParameterName=Gain
ObjectType=0x7
DataType=0x0008
AccessType=rw
DefaultValue=1.2
PDOMapping=0
"""


@pytest.fixture
def eds(tmp_path):
    path = tmp_path / "t.eds"
    path.write_text(EDS)
    return str(path)


def test_load_gives_objects_types_access_defaults_limits(eds):
    dev = odc.load(eds)
    assert dev.format == "eds"
    assert sorted(dev.objects) == [0x1000, 0x1001, 0x1003, 0x1017, 0x1018, 0x1400, 0x1600,
                                   0x2000, 0x2001]
    speed = dev.objects[0x2000]
    assert (speed.name, speed.kind) == ("Speed", "VAR")
    var = speed.subs[0]
    assert (var.data_type, var.data_type_name, var.access) == (0x0003, "INTEGER16", "rww")
    assert var.pdo_mapping is True
    # 0xFFFF as INTEGER16 is the bit pattern of -1; 0x64 is 100.
    assert (var.default, var.low_limit, var.high_limit) == (-1, -100, 100)
    assert var.default_raw == "0xFFFF"
    assert var.extra == {"Unit": "rpm", "Factor": "0.5"}
    # Leading zero: octal, as CiA 306 reads C numbers.
    assert dev.objects[0x1017].subs[0].default == 8
    # A REAL32 as the float written, not the widened single.
    assert dev.objects[0x2001].subs[0].default == 1.2
    assert dev[0x1018][1].default == 0x1234


def test_load_keeps_nodeid_symbolic(eds):
    cob = odc.load(eds).objects[0x1400].subs[1]
    assert cob.default == odc.NodeIdPlus(0x200)
    assert cob.default.resolve(5) == 0x205
    assert cob.default_raw == "$NODEID+0x200"


def test_load_compact_sub_objects(eds):
    arr = odc.load(eds).objects[0x1003]
    assert arr.kind == "ARRAY"
    assert sorted(arr.subs) == [0, 1, 2, 3, 4]
    assert arr.subs[0].default == 4
    assert arr.subs[3].name == "Pre-defined error field3"
    assert arr.subs[3].data_type == 0x0007


def test_load_identity_pdos_comments(eds):
    dev = odc.load(eds)
    ident = dev.identity
    assert (ident.vendor_name, ident.vendor_number, ident.product_name) == ("Acme", 0x1234,
                                                                             "Widget")
    assert (ident.product_number, ident.revision_number) == (0x42, 0x00010002)
    assert ident.baud_rates == [250, 500]
    assert ident.lss_supported is True
    assert dev.comments == ["first", "second"]
    assert dev.dummy_usage == [2, 5]
    (pdo,) = dev.pdos
    assert (pdo.direction, pdo.mapping_index, pdo.comm_index) == ("rx", 0x1600, 0x1400)
    assert pdo.cob_id == odc.NodeIdPlus(0x200)
    assert pdo.transmission_type == 255
    (entry,) = pdo.entries
    assert (entry.index, entry.sub, entry.bits) == (0x2000, 0, 16)


def test_check_gives_diagnostics_with_places(tmp_path):
    path = tmp_path / "bad.eds"
    path.write_text(EDS.replace("DefaultValue=0xFFFF", "DefaultValue=fast"))
    diags = odc.check(str(path))
    (bad,) = [d for d in diags if d["code"] == "F107"]
    assert bad["severity"] == "error"
    assert "fast" in bad["message"]
    assert bad["file"] == str(path)
    line = EDS.splitlines().index("DefaultValue=0xFFFF") + 1
    assert (bad["line"], bad["column"]) == (line, len("DefaultValue=") + 1)
    assert set(bad) >= {"code", "severity", "message", "file", "line", "column"}


def test_load_refuses_errors_unless_allowed(tmp_path):
    path = tmp_path / "bad.eds"
    path.write_text(EDS.replace("DefaultValue=0xFFFF", "DefaultValue=fast"))
    with pytest.raises(odc.Refused) as refused:
        odc.load(str(path))
    assert isinstance(refused.value, ValueError)
    assert [d["code"] for d in refused.value.diagnostics] == ["F107"]
    dev = odc.load(str(path), allow=["F107"])
    assert dev.objects[0x2000].subs[0].default == odc.Invalid("fast")


def test_missing_file_is_oserror():
    with pytest.raises(FileNotFoundError):
        odc.load("/nonexistent/device.eds")


def test_convert_round_trips_through_xdd(eds, tmp_path):
    xdd = odc.convert(eds, "xdd")
    assert "<ISO15745ProfileContainer" in xdd
    back = tmp_path / "t.xdd"
    back.write_text(xdd)
    assert odc.load(str(back)).objects[0x2000].subs[0].default == -1
    changes = odc.diff(eds, str(back), ignore_comments=True)
    assert [c for c in changes if c["in"] in ("object", "sub")] == []
    with pytest.raises(ValueError):
        odc.convert(eds, "json")


def test_diff_names_the_change(eds, tmp_path):
    other = tmp_path / "u.eds"
    other.write_text(EDS.replace("HighLimit=0x64", "HighLimit=200"))
    changes = odc.diff(eds, str(other))
    assert len(changes) == 1
    (c,) = changes
    assert (c["index"], c["field"], c["change"]) == (0x2000, "high limit", "changed")
    assert json.dumps(changes)


def test_doc_renders_both_formats(eds):
    md = odc.doc(eds, "md")
    assert "Widget" in md and "0x2000" in md.upper().replace("0X", "0x")
    assert odc.doc(eds).lstrip().lower().startswith("<!doctype html")


def test_repository_device_loads():
    dev = odc.load(os.path.join(ROOT, "eds", "lxm23a.eds"))
    assert dev.objects[0x1000].subs[0].default == 0x04020192
